"""Issue 43: from a photo to a material. Delight against renders of a textured plane under
uneven light (the albedo is the truth), heal on photos with a pasted blemish (the photo under it
is the truth for the statistics), normal maps against Cycles renders of displaced surfaces (the
render's normal is the truth) and against game sets' normal maps (made from their colour: the
agreement with artists' tools), each beside the baseline users have.

The parts are functions in ``PARTS``, run in order; the pipeline's timing is a part of its own.
"""

from __future__ import annotations

import time

import numpy as np
from scipy.ndimage import binary_dilation, gaussian_filter, zoom

from benchmarks import material_renders
from benchmarks.context import SHARED_TEXTURES, fmt
from benchmarks.sections.tileable import centre_crop
from texsynth import metrics
from texsynth.blocks.color import linear_to_srgb, srgb_to_linear
from texsynth.blocks.periodic import tile_preview
from texsynth.io import read_photo
from texsynth.material import delight, derive_maps, heal

ORDER = 58
TITLE = "Photo to material"

SEED = 0
#: Textured planes of the delight measure (path below shared/textures), 512 crops.
DELIGHT_TEXTURES = ("pbr/dirtRoad_color.png", "pbr/rock_color.png", "pbr/bedRock_color.png",
                    "openarena/rust_floor.png", "openarena/stone_blocks_dark.png")
#: Photos the heal measure pastes a blemish on (512 crops).
HEAL_PHOTOS = ("large/torcs-data/gravel_pebbles.png", "large/torcs-data/grass_lawn.png",
               "large/ufoai-textures/gravelly_dirt_ground.png",
               "large/redeclipse-data/asphalt.png", "large/ufoai-textures/brick_wall.png",
               "large/nexuiz-textures/concrete_pavers.png")
#: The game sets (colour + DirectX normal) in shared/textures/pbr.
PBR = ("aztekWall", "bedRock", "brick", "dirtRoad", "grass", "rock")
#: The delight measure's scale: the light's frequencies are those below a Gaussian of this
#: share of the side (32 px at 512).
LIGHT_SCALE = 1 / 16
#: The finer edge of the shading band (pixels).
SHADING = 2.0
#: The baseline's low-pass widths (share of the side).
BASELINE_SIGMAS = (1 / 64, 1 / 16, 1 / 4)


# --- delight ----------------------------------------------------------------------------------

def _log_low(image, sigma):
    y = np.log(np.maximum(metrics.luminance(image), 1e-4))
    low = gaussian_filter(y, sigma, mode="reflect")
    return low - low.mean()


def delight_scores(result, albedo, photo, sigma) -> tuple[float, float, float]:
    """(the low-frequency residual of the light over the lit photo's, the high-pass detail's
    correlation with the albedo's, the shading band's). The residual: the standard deviation of
    the Gaussian low-pass (``sigma``) of log-luminance minus the albedo's; the detail: luminance
    minus its low-pass; the shading band: the luminance's low-pass at ``SHADING`` px minus the
    one at ``sigma`` (the surface's own shading, between its grain and the light); each
    correlated over all pixels."""
    truth = _log_low(albedo, sigma)
    residual = np.std(_log_low(result, sigma) - truth) / np.std(_log_low(photo, sigma) - truth)

    def bands(image):
        y = metrics.luminance(image)
        low = gaussian_filter(y, sigma, mode="reflect")
        return (y - low).ravel(), (gaussian_filter(y, SHADING, mode="reflect") - low).ravel()

    (d_r, s_r), (d_a, s_a) = bands(result), bands(albedo)
    return (float(residual), float(np.corrcoef(d_r, d_a)[0, 1]),
            float(np.corrcoef(s_r, s_a)[0, 1]))


def baseline_delight(photo, sigma) -> np.ndarray:
    """The photo divided by a plain Gaussian low-pass of its luminance (``sigma`` pixels), its
    mean level kept: what users do by hand (high-pass filter, divide blend mode)."""
    y = metrics.luminance(photo)
    low = gaussian_filter(y, sigma, mode="reflect")
    return (photo * (y.mean() / np.maximum(low, 1e-4))[:, :, None]).astype(np.float32)


def _lit(albedo, field, vignetted):
    side = albedo.shape[0]
    e = zoom(field, side / field.shape[0], order=3, mode="nearest")
    e = np.clip(e, 1e-3, None) * (material_renders.vignette((side, side)) if vignetted else 1)
    return np.clip(linear_to_srgb(srgb_to_linear(albedo) * e[:, :, None]), 0, 1).astype(
        np.float32)


def delight_part(ctx) -> str:
    side = 256 if ctx.quick else 512
    sigma = LIGHT_SCALE * side
    fields = material_renders.light_fields()
    lights = (("window", "window", False), ("spot + vignette", "spot", True),
              ("soft shadow", "shadow", False))
    textures = DELIGHT_TEXTURES[:2] if ctx.quick else DELIGHT_TEXTURES
    names = ["lit photo", "delight"] + [f"low-pass {round(s * side)} px" for s in
                                         BASELINE_SIGMAS]
    rows, scores, shown, seconds = [], {n: [] for n in names}, [], []
    for rel in textures:
        albedo = centre_crop(rel, side)
        for label, key, vignetted in lights:
            photo = _lit(albedo, fields[key], vignetted)
            start = time.perf_counter()
            ours = delight(photo)
            seconds.append(time.perf_counter() - start)
            results = [photo, ours] + [baseline_delight(photo, s * side)
                                       for s in BASELINE_SIGMAS]
            row = [delight_scores(r, albedo, photo, sigma) for r in results]
            for n, s in zip(names, row, strict=True):
                scores[n].append(s)
            rows.append(f"| {rel.split('/')[-1]} | {label} | " + " | ".join(
                f"{fmt(a, 2)} / {fmt(c, 3)} / {fmt(b, 2)}" for a, c, b in row) + " |")
            if len(shown) < 4 and (key == "shadow" or len(shown) < 2):
                shown.append([albedo, photo, ours, results[2]])
    sheet = ctx.contact_sheet("material_delight.png",
                              ["albedo (truth)", "lit photo", "delight", names[2]], shown,
                              cell=min(side, 256))
    lines = [
        "### Delight: a textured plane under uneven light",
        "",
        "Each photo is a texture's albedo (a 512 crop, its values as stored: sRGB) times the "
        "irradiance Cycles renders on a white Lambertian plane seen from above "
        "(`benchmarks/material_renders.py`: a window's ramp from an area light beyond the left "
        "edge, a spot light's pool with a cos^4 vignette, a wall's soft shadow under a 20 deg "
        "sun), applied in linear light; exact for a flat diffuse surface. The albedo is the "
        "truth. Each cell: the low-frequency residual of the light (the std of the Gaussian "
        f"low-pass, {round(sigma)} px, of log-luminance minus the albedo's, over the lit "
        "photo's; goal at most 0.30) / the high-pass detail's correlation with the albedo's "
        "(luminance minus that low-pass; goal at least 0.99) / the shading band's correlation "
        f"(the luminance's low-pass at {SHADING:g} px minus the one at {round(sigma)} px: the "
        "surface's own shading, between its grain and the light; the albedos are game "
        "textures, de-lit and tiling by design, so their own low frequencies are surface). "
        "The baseline divides by a "
        "Gaussian low-pass of the luminance of the width named.",
        "",
        "| texture | light | " + " | ".join(names) + " |",
        "|---|---|" + "---:|" * len(names),
        *rows,
        "",
        "| | " + " | ".join(names) + " |",
        "|---|" + "---:|" * len(names),
        "| median residual | " + " | ".join(
            fmt(np.median([v[0] for v in scores[n]]), 2) for n in names) + " |",
        "| worst residual | " + " | ".join(
            fmt(max(v[0] for v in scores[n]), 2) for n in names) + " |",
        "| median detail correlation | " + " | ".join(
            fmt(np.median([v[1] for v in scores[n]]), 3) for n in names) + " |",
        "| worst detail correlation | " + " | ".join(
            fmt(min(v[1] for v in scores[n]), 3) for n in names) + " |",
        "| median shading-band correlation | " + " | ".join(
            fmt(np.median([v[2] for v in scores[n]]), 2) for n in names) + " |",
        "| worst shading-band correlation | " + " | ".join(
            fmt(min(v[2] for v in scores[n]), 2) for n in names) + " |",
        "",
        f"delight took {fmt(np.median(seconds), 2)} s a 512 photo (median).",
        "",
        f"![albedo, lit photo, delight, the baseline]({sheet})",
        "",
    ]
    return "\n".join(lines)




# --- heal -------------------------------------------------------------------------------------

def blemishes(side: int, rng) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """(name, the blemish's colour (side, side, 3), its footprint (side, side) bool): a sign (a
    light rectangle with dark lettering), a cigarette butt (a pale stub with an orange tip)."""
    y, x = np.mgrid[:side, :side]
    out = []
    cy, cx = rng.integers(side // 3, 2 * side // 3, 2)
    sign = (np.abs(y - cy) < side // 10) & (np.abs(x - cx) < side // 6)
    colour = np.full((side, side, 3), (0.9, 0.88, 0.8), np.float32)
    letters = ((y // 6) % 3 == 0) & ((x // 4) % 2 == 0)
    colour[letters] = (0.1, 0.1, 0.15)
    out.append(("sign", colour, sign))
    cy, cx = rng.integers(side // 3, 2 * side // 3, 2)
    t = np.radians(rng.uniform(0, 180))
    u = (x - cx) * np.cos(t) + (y - cy) * np.sin(t)
    v = -(x - cx) * np.sin(t) + (y - cy) * np.cos(t)
    butt = (np.abs(u) < side / 14) & (np.abs(v) < side / 60 + 1)
    colour = np.where((u > side / 28)[:, :, None], np.float32([0.8, 0.5, 0.2]),
                      np.float32([0.95, 0.95, 0.92])).astype(np.float32)
    out.append(("cigarette butt", colour, butt))
    return out


def _pairs(mask: np.ndarray):
    """The neighbour pairs (right and down) with one pixel in the mask and one outside."""
    pairs = []
    for axis in (0, 1):
        a = mask[:-1] if axis == 0 else mask[:, :-1]
        b = mask[1:] if axis == 0 else mask[:, 1:]
        pairs.append(a != b)
    return pairs


def boundary_seam_ratio(image: np.ndarray, truth: np.ndarray, mask: np.ndarray) -> float:
    """Mean |luminance jump| across the mask's boundary in ``image`` over the same in ``truth``
    (the photo under the blemish): 1 when the boundary shows as the photo does there, above
    1.2 a visible edge, below 0.8 a soft one (two-sided, as the seam ratio)."""
    jumps = []
    for image_ in (image, truth):
        y = metrics.luminance(image_)
        across = _pairs(mask)
        jumps.append(np.concatenate([np.abs(np.diff(y, axis=0))[across[0]],
                                     np.abs(np.diff(y, axis=1))[across[1]]]).mean())
    return float(jumps[0] / jumps[1])


def region_gradient_ratio(image: np.ndarray, truth: np.ndarray, mask: np.ndarray) -> float:
    """Mean gradient magnitude (forward differences) inside the mask, image over truth."""
    inside = mask[:-1, :-1] & mask[1:, :-1] & mask[:-1, 1:]

    def gradient(a):
        y = metrics.luminance(a)
        return np.hypot(np.diff(y, axis=0)[:, :-1], np.diff(y, axis=1)[:-1])[inside].mean()

    return float(gradient(image) / gradient(truth))


def harmonic_fill(photo: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """The baseline: the masked region filled by Laplace's equation from its boundary (a smooth
    fill, as a content-unaware inpainting or a clone-free 'remove' brush)."""
    import scipy.sparse as sparse
    import scipy.sparse.linalg as sparse_linalg

    h, w = mask.shape
    index = -np.ones((h, w), np.int64)
    n = int(mask.sum())
    index[mask] = np.arange(n)
    pi, pj = np.nonzero(mask)
    rows, cols, vals = [np.arange(n)], [np.arange(n)], [np.zeros(n)]
    rhs = np.zeros((n, photo.shape[2]))
    for di, dj in ((1, 0), (-1, 0), (0, 1), (0, -1)):
        qi, qj = pi + di, pj + dj
        ok = (qi >= 0) & (qi < h) & (qj >= 0) & (qj < w)
        vals[0][ok] += 1
        k = index[qi[ok], qj[ok]]
        p = np.nonzero(ok)[0]
        rows.append(p[k >= 0])
        cols.append(k[k >= 0])
        vals.append(-np.ones(int((k >= 0).sum())))
        rhs[p[k < 0]] += photo[qi[ok][k < 0], qj[ok][k < 0]]
    a = sparse.csc_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                          shape=(n, n))
    out = photo.copy()
    out[mask] = sparse_linalg.splu(a).solve(rhs).astype(np.float32)
    return out


def heal_part(ctx) -> str:
    side = 256 if ctx.quick else 512
    rng = np.random.default_rng(SEED)
    photos = HEAL_PHOTOS[:2] if ctx.quick else HEAL_PHOTOS
    rows, ours, smooth, shown, seconds = [], [], [], [], []
    for rel in photos:
        truth = centre_crop(rel, side)
        for name, colour, footprint in blemishes(side, rng):
            blemished = np.where(footprint[:, :, None], colour, truth).astype(np.float32)
            mask = binary_dilation(footprint, iterations=3)  # painted a little wider
            start = time.perf_counter()
            healed = heal(blemished, mask, seed=SEED)
            seconds.append(time.perf_counter() - start)
            fill = harmonic_fill(blemished, mask)
            a = (region_gradient_ratio(healed, truth, mask),
                 boundary_seam_ratio(healed, truth, mask))
            b = (region_gradient_ratio(fill, truth, mask), boundary_seam_ratio(fill, truth, mask))
            ours.append(a)
            smooth.append(b)
            rows.append(f"| {rel.split('/')[-1]} | {name} | {int(mask.sum())} | {fmt(a[0], 2)} | "
                        f"{fmt(a[1], 2)} | {fmt(b[0], 2)} | {fmt(b[1], 2)} | "
                        f"{fmt(seconds[-1], 2)} |")
            if name == "sign" and len(shown) < 3:
                ys, xs = np.nonzero(mask)
                cy, cx = int(ys.mean()), int(xs.mean())
                top = int(np.clip(cy - 96, 0, side - 192))
                left = int(np.clip(cx - 96, 0, side - 192))
                crop = np.s_[top:top + 192, left:left + 192]
                shown.append([truth[crop], blemished[crop], healed[crop], fill[crop]])
    sheet = ctx.contact_sheet("material_heal.png",
                              ["photo (truth)", "with a blemish", "heal", "smooth fill"],
                              shown, cell=192)
    ours, smooth = np.array(ours), np.array(smooth)
    inside = ((ours[:, 0] >= 0.9) & (ours[:, 0] <= 1.1) & (ours[:, 1] >= 0.8)
              & (ours[:, 1] <= 1.2))
    lines = [
        "### Heal: a pasted blemish re-synthesized from the rest of the photo",
        "",
        f"A {side} crop of each photo with a blemish pasted on (a sign with lettering, a "
        "cigarette butt), the mask its footprint grown by 3 px (as painted); the photo under it "
        "is the truth for the statistics. Gradient ratio: the healed region's mean gradient "
        "over the truth's there (goal 0.9-1.1); boundary seam ratio: the mean luminance jump "
        "across the mask's boundary over the truth's across the same pixel pairs (goal "
        "0.8-1.2). The baseline is the smooth fill (Laplace's equation from the boundary).",
        "",
        "| photo | blemish | masked px | heal: gradient ratio | heal: boundary seam ratio | "
        "smooth fill: gradient ratio | smooth fill: boundary seam ratio | heal s |",
        "|---|---|---:|---:|---:|---:|---:|---:|",
        *rows,
        "",
        f"Heal within both goals on {int(inside.sum())} of {len(ours)}; gradient ratio "
        f"{fmt(ours[:, 0].min(), 2)}-{fmt(ours[:, 0].max(), 2)}, boundary seam ratio "
        f"{fmt(ours[:, 1].min(), 2)}-{fmt(ours[:, 1].max(), 2)} (the smooth fill: "
        f"{fmt(smooth[:, 0].min(), 2)}-{fmt(smooth[:, 0].max(), 2)} and "
        f"{fmt(smooth[:, 1].min(), 2)}-{fmt(smooth[:, 1].max(), 2)}).",
        "",
        f"![photo, blemish, heal, smooth fill]({sheet})",
        "",
    ]
    return "\n".join(lines)


# --- maps -------------------------------------------------------------------------------------

def _angles(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.degrees(np.arccos(np.clip((a * b).sum(axis=2), -1.0, 1.0)))


def baseline_normal(colour: np.ndarray, strength: float, blur: float) -> np.ndarray:
    """The plain luminance-gradient normal map (GIMP's normal map filter, Materialize's
    simplest): the luminance blurred by ``blur`` px, its gradient times ``strength``."""
    y = metrics.luminance(colour)
    y = gaussian_filter(y, blur, mode="wrap") if blur else y
    gy, gx = np.gradient(np.pad(y, 1, mode="wrap"))
    n = np.stack([-strength * gx[1:-1, 1:-1], strength * gy[1:-1, 1:-1], np.ones_like(y)], 2)
    return (n / np.linalg.norm(n, axis=2, keepdims=True)).astype(np.float32)


def tuned_baseline(colour, truth) -> tuple[float, float, float]:
    """(median angle, strength, blur) of the baseline at its best on the truth itself."""
    best = (np.inf, 0.0, 0.0)
    for blur in (0.0, 0.5, 1.0, 2.0, 3.0, 4.0):
        for strength in np.geomspace(0.5, 200, 28):
            m = float(np.median(_angles(baseline_normal(colour, strength, blur), truth)))
            best = min(best, (m, float(strength), blur))
    return best


def _normal_sets(ctx):
    """(name, role, colour sRGB-encoded, truth normal OpenGL)."""
    sets = []
    for name, (z, albedo, role) in material_renders.surfaces().items():
        colour, normal = material_renders.displaced(name, z, albedo)
        sets.append((name, f"render, {role}", np.clip(linear_to_srgb(colour), 0, 1).astype(
            np.float32), normal))
    for name in PBR[:2] if ctx.quick else PBR:
        colour = read_photo(SHARED_TEXTURES / "pbr" / f"{name}_color.png")[:, :, :3]
        normal = read_photo(SHARED_TEXTURES / "pbr" / f"{name}_normal.png")[:, :, :3] * 2 - 1
        normal[:, :, 1] *= -1  # DirectX (green down) -> OpenGL
        normal /= np.linalg.norm(normal, axis=2, keepdims=True)
        sets.append((name, "game set", colour.astype(np.float32), normal.astype(np.float32)))
    return sets


def maps_part(ctx) -> str:
    rows, shown, seconds, game = [], [], [], []
    for name, role, colour, truth in _normal_sets(ctx):
        flat = float(np.median(np.degrees(np.arccos(np.clip(truth[:, :, 2], -1, 1)))))
        base = tuned_baseline(colour, truth)
        start = time.perf_counter()
        maps = derive_maps(colour)
        seconds.append((colour.shape[0], time.perf_counter() - start))
        ours = float(np.median(_angles(maps.normal, truth)))
        if role == "game set":
            game.append(ours <= base[0] + 1.0)
        rows.append(f"| {name} | {role} | {colour.shape[1]} | {fmt(flat, 1)} | {fmt(base[0], 1)} "
                    f"(x{fmt(base[1], 1)}, blur {base[2]:g}) | **{fmt(ours, 1)}** | "
                    f"{fmt(metrics.seam_ratio(maps.normal), 2)} | "
                    f"{fmt(metrics.seam_ratio(truth), 2)} | {fmt(metrics.seam_ratio(colour), 2)} |")
        if name in ("cobbles", "ridges", "bricks", "rock"):
            side = min(colour.shape[0], 256)
            shown.append([tile_preview(colour[:side, :side]), tile_preview(
                (truth[:side, :side] + 1) / 2), tile_preview((maps.normal[:side, :side] + 1) / 2),
                tile_preview(np.repeat(maps.height[:side, :side, None], 3, 2)),
                tile_preview(np.repeat(maps.ao[:side, :side, None], 3, 2))])
    sheet = ctx.contact_sheet("material_maps.png",
                              ["colour", "truth normal", "derive_maps normal", "height", "ao"],
                              shown, cell=256)
    lines = [
        "### Maps: normals against known truth",
        "",
        "Renders: Cycles renders (`benchmarks/material_renders.py`) of periodic height fields "
        "displaced on a plane (3 x 3 tiles, the camera on the middle one: the render tiles), "
        "256 px, the colour under a white sky and a soft sun from above, the truth the shading "
        "normal Cycles sees (the Geometry node's normal emitted: the normal pass). Game sets: "
        "`shared/textures/pbr` (colour + a DirectX normal map made by the artist from the "
        "colour: agreement with the artists' tools, not physics). Median angle to the truth "
        "normal, degrees; the baseline is the plain luminance-gradient normal map with its "
        "strength and blur at their best on the truth itself (a grid of 28 x 6); "
        "`derive_maps` has fixed parameters (tuned on the game sets and the renders marked "
        "tune; the held-out renders were not looked at while tuning). Seam ratio: the derived "
        "normal map's (its luminance) across the wrap, beside the truth normal's and the "
        "colour's own: the plain ratio reads a joint on the wrap line as a seam (the bricks "
        "renders tile, yet their truth reads high) and the game sets' own edges as theirs, so "
        "the derived map's figure is read against the truth's, not against 1.",
        "",
        "| set | kind | side | flat map | tuned baseline | derive_maps | seam ratio | "
        "truth's seam ratio | colour's seam ratio |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|",
        *rows,
        "",
        f"derive_maps within the tuned baseline + 1 deg on {sum(game)} of {len(game)} game sets; "
        f"it took {fmt(np.median([s for n, s in seconds if n >= 1024] or [0]), 2)} s a "
        "1024 colour (median).",
        "",
        "Tiled 2 x 2 (the normal as RGB, (n + 1) / 2): colour | truth | derive_maps normal | "
        "height | AO.",
        "",
        f"![colour, truth normal, derived normal, height, ao]({sheet})",
        "",
    ]
    return "\n".join(lines)


PARTS = [delight_part, heal_part, maps_part]


def run(ctx) -> str:
    return "\n".join(part(ctx) for part in PARTS)
