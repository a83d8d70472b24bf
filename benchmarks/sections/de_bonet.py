"""De Bonet's parent-structure sampling (issue 7; Forsyth & Ponce, section 11.3.3, Algorithm 11.5).

Evidence: contact sheets exemplar | Heeger-Bergen | De Bonet on every texture with the harness's
patch and structure distances, a threshold sweep with the matcher's candidate counts, the
measurements behind the colour choice (joint colour vectors against PCA channels sampled apart),
and time + peak memory for 256 -> 512 RGB and the scaling to 4096^2, against plain Heeger-Bergen.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

import texsynth
from texsynth.algorithms import de_bonet as db
from texsynth.blocks.color import ColorPCA
from texsynth.blocks.periodic import periodic_component
from texsynth.blocks.pyramid import LaplacianPyramid
from texsynth.progress import Progress

ORDER = 45
TITLE = ("De Bonet: sampling each level conditioned on its parent structure "
         "(Forsyth & Ponce, Alg. 11.5)")

SEED = 0
SWEEP = (0.0, 0.25, 0.5, 1.0, 2.0)
SWEEP_TEXTURE = "pebbles01"
COLOUR_TEXTURES = ("green_leaves", "pink_marble", "terrain_warmup", "rock01")
TIMING_TEXTURE = "pebbles01"
DEFAULTS = texsynth.get_method("de_bonet").resolve({})


def _crop(image: np.ndarray, side: int) -> np.ndarray:
    return np.ascontiguousarray(image[:side, :side, :3])


def _pick(ctx, short):
    return next((t for t in ctx.textures if t.short == short), ctx.textures[0])


def _comparison(ctx, side):
    """Exemplar | HB | De Bonet per texture (one sheet per category) and the harness's
    distances; the exemplar is cropped to half the output side."""
    keys = ("patch_distance", "structure_distance", "subband_distance", "copy_share")
    sheets, table, wins = {}, [], {}
    for tex in ctx.textures:
        ex = _crop(tex.image, side // 2)
        hb = texsynth.synthesize(ex, side, side, seed=SEED)
        out = texsynth.synthesize(ex, side, side, method="de_bonet", seed=SEED)
        sheets.setdefault(tex.category, []).append([ex, hb, out])
        q_hb, q_db = ctx.quality(ex, hb), ctx.quality(ex, out)
        for k in keys[:3]:
            won = wins.setdefault((tex.category, k), [0, 0])
            won[0] += q_db[k] < q_hb[k]
            won[1] += 1
        table.append(f"| {tex.short} | {tex.category} | "
                     + " | ".join(f"{q_hb[k]:.3f} / {q_db[k]:.3f}" for k in keys) + " |")
    paths = {cat: ctx.contact_sheet(f"de_bonet_{cat}.png",
                                    ["exemplar", "Heeger-Bergen", "De Bonet"], rows, cell=side)
             for cat, rows in sheets.items()}
    summary = [f"| {cat} | {k.replace('_', ' ')} | {w} of {n} |"
               for (cat, k), (w, n) in sorted(wins.items())]
    return paths, table, summary


def _sweep(ctx, side):
    tex = _pick(ctx, SWEEP_TEXTURE)
    ex = _crop(tex.image, side // 2)
    images = [texsynth.synthesize(ex, side, side, method="de_bonet", seed=SEED,
                                  threshold=threshold) for threshold in SWEEP]
    path = ctx.contact_sheet("de_bonet_sweep.png", [f"threshold {t}" for t in SWEEP], [images],
                             cell=side)
    return tex.short, path


def _per_channel(ex, side, threshold):
    """The alternative colour rule: PCA channels, each sampled with its own choices."""
    pca = ColorPCA.fit(ex)
    comp = pca.forward(ex)
    levels = db.pyramid_depth(ex.shape, side, side, DEFAULTS["scales"])
    laplacian = LaplacianPyramid(ex.shape[:2], levels)
    po = LaplacianPyramid((side, side), levels)
    out = np.empty((side, side, 3), np.float32)
    rng = np.random.default_rng(SEED)
    for c in range(3):
        f = db.pyramid_features(periodic_component(comp[:, :, c:c + 1]), laplacian, 4)
        src = db.sample_pyramid(f, po.level_shapes, threshold, 3, rng, Progress())
        out[:, :, c] = po.synthesize(db.channel_levels(f, src, 0, 4))
    return np.clip(pca.inverse(out), ex.min(axis=(0, 1)), ex.max(axis=(0, 1)))


def _invented(ex, out):
    """Mean RGB distance from an output pixel to the nearest exemplar colour."""
    d, _ = cKDTree(ex.reshape(-1, 3)).query(out.reshape(-1, 3)[::3])
    return float(d.mean())


def _colour(ctx, side):
    lines = []
    for name in COLOUR_TEXTURES:
        tex = next((t for t in ctx.textures if t.short == name), None)
        if tex is None:
            continue
        ex = _crop(tex.image, side // 2)
        for threshold in (0.5, 1.0):
            joint = ctx.measure(lambda ex=ex, t=threshold: texsynth.synthesize(
                ex, side, side, method="de_bonet", seed=SEED, threshold=t), repeats=1)
            apart = ctx.measure(lambda ex=ex, t=threshold: _per_channel(ex, side, t), repeats=1)
            lines.append(f"| {tex.short} | {threshold} | {_invented(ex, joint.result):.4f} | "
                         f"{_invented(ex, apart.result):.4f} | {joint.median_s:.2f} | "
                         f"{apart.median_s:.2f} |")
    return lines


def _timing(ctx, sizes):
    """HB stops at 2048^2 here (its 4096^2 run is in the Scaling section)."""
    ex = _crop(_pick(ctx, TIMING_TEXTURE).image, 256)
    lines = []
    for side in sizes:
        repeats = 3 if side <= 1024 else 1
        hb = (ctx.measure(lambda s=side: texsynth.synthesize(ex, s, s, seed=SEED), repeats)
              if side <= 2048 else None)
        out = ctx.measure(lambda s=side: texsynth.synthesize(ex, s, s, method="de_bonet",
                                                             seed=SEED), repeats)
        estimate = db.METHOD.memory(ex.shape, side, side, DEFAULTS) / 2**20
        hb_cells = (f"{hb.median_s:.2f} | {hb.peak_mib:.0f}" if hb else "see Scaling | -")
        ratio = f"{out.median_s / hb.median_s:.2f}" if hb else "-"
        lines.append(f"| {ex.shape[0]} -> {side} | {hb_cells} | {out.median_s:.2f} | "
                     f"{out.peak_mib:.0f} | {estimate:.0f} | {ratio} |")
    return lines


def run(ctx) -> str:
    side = 128 if ctx.quick else 256
    sheets, table, summary = _comparison(ctx, side)
    sweep_name, sweep = _sweep(ctx, 128 if ctx.quick else 512)
    colour = [] if ctx.quick else _colour(ctx, 256)
    timing = _timing(ctx, (128, 256) if ctx.quick else (512, 1024, 2048, 4096))
    out = [
        "`texsynth.synthesize(..., method=\"de_bonet\")`, defaults ("
        + ", ".join(f"{k} {v}" for k, v in DEFAULTS.items())
        + "). The coarsest Laplacian level is copied from a random offset, or, where the "
        "output's is larger than the exemplar's, quilted from it on the torus (every level then "
        "drawing among coherent candidates first); every finer level copies, location by "
        "location, the values (Laplacian level and K steerable responses, all channels) of an "
        "exemplar location drawn uniformly among all whose parent structure (the coarser "
        "levels read at that position) is within the threshold, the nearest when none is.",
        "",
        f"### Exemplar | Heeger-Bergen | De Bonet ({side // 2} px exemplar crop -> {side}^2, "
        f"seed {SEED})",
        "",
        *[f"{cat}: ![{cat}]({path})\n" for cat, path in sheets.items()],
        "Harness distances, Heeger-Bergen / De Bonet (lower is closer to the exemplar; "
        "copy share: output patches that are verbatim exemplar copies):",
        "",
        "| texture | category | patch | structure | subband | copy share |",
        "|---|---|---|---|---|---|",
        *table,
        "",
        "Textures where De Bonet is closer than Heeger-Bergen:",
        "",
        "| category | distance | De Bonet closer |",
        "|---|---|---|",
        *summary,
        "",
        f"### Threshold ({sweep_name}, 2x its crop)",
        "",
        "The threshold is in units of the median distance between an exemplar parent structure "
        "and its nearest other one. 0 copies the exemplar (tiled); larger values mix more, and "
        "beyond about 1 the structure dissolves into texture noise.",
        "",
        f"![threshold sweep]({sweep})",
        "",
    ]
    if colour:
        out += [
            "### Colour: joint colour vectors or PCA channels apart",
            "",
            "Mean RGB distance from an output pixel to the nearest exemplar colour (invented "
            "colours), and time, 128 -> 256. Joint vectors (one choice per location copies all "
            "channels) are the method's rule.",
            "",
            "| texture | threshold | joint | PCA apart | joint s | PCA apart s |",
            "|---|---|---|---|---|---|",
            *colour,
            "",
        ]
    out += [
        "### Time and peak memory (RGB, one thread)",
        "",
        "The kd-tree's own nodes are not traced; the estimate is the method's `memory` "
        "function, checked against the budget before anything is allocated. Repeats: 3 up to "
        "1024^2, 1 above; Heeger-Bergen at 4096^2 is in the Scaling section.",
        "",
        "| size | HB s | HB MiB | De Bonet s | De Bonet MiB | estimate MiB | De Bonet / HB |",
        "|---|---|---|---|---|---|---|",
        *timing,
        "",
    ]
    return "\n".join(out)
