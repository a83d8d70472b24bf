"""Plane orientation on real photos, and on photos as phones store them (issue 27).

Beside the plane section's rendered conditions (``estimate.py``), four things a phone photo
brings:

- *real frontal photos* of man-made surfaces (the shared large photos of a brick wall, concrete
  pavers and granite setts; truth: slant about 0), with the focal length a phone's main camera
  writes into its EXIF (26 mm equivalent on the photo's diagonal) and with it unknown;
- *rendered views of real photos*: the same three photos as textures on the rendered plane
  (``benchmarks/plane_renders.py``), slant >= 20 deg, perspective;
- *JPEG views*: every view here, and half the man-made views of the plane section, saved by
  Pillow at quality 70, 85 and 95 and estimated again (a refusal is a failure);
- *coverage*: how often the stated normal uncertainty s covers the true error e. s is the RMS
  of the normal's two error components, so for Gaussian errors e <= sqrt(ln 5) s = 1.27 s on
  80 % of views (the same model as the confidence, P(e <= 8 deg) = 1 - exp(-(8 / s)^2)).
"""

from __future__ import annotations

import io
import math
import time
from collections import defaultdict

import numpy as np
from PIL import Image

from benchmarks import manmade, plane_renders
from benchmarks.context import SHARED_TEXTURES
from benchmarks.sections.estimate import exif_jpeg, score
from texsynth import plane
from texsynth.io import read_photo
from texsynth.plane.lines import RIDGE_SIDE
from texsynth.plane.spectra import block_factor

ORDER = 71
TITLE = "Plane orientation on real photos and JPEGs (issue 27)"

REAL = ("ufoai-textures/brick_wall.png", "nexuiz-textures/concrete_pavers.png",
        "0ad-data/granite_setts_grass.png")
PHONE_MM = 26.0           # a phone's main camera, 35 mm equivalent
QUALITIES = (70, 85, 95)
TEXTURE_SIDE = 1024       # real photos are block-averaged to this side before rendering
#: Rows of a photo that are not its surface, cut before it is rendered as a texture (the brick
#: wall's coping above and ground below would repeat as bands across the plane).
SURFACE = {"ufoai-textures/brick_wall.png": slice(60, 980)}
COVER_80 = math.sqrt(math.log(5.0))  # e <= 1.27 s on 80 % of views for Gaussian errors
#: The phone set renders the real-photo views at this many times plane_renders' 320 x 256
#: (1600 x 1280, 2 MP), from the full-resolution photos.
PHONE_SCALE = 5
PHONE_12MP = (4032, 3024)  # a 12 MP phone photo, for the line detector's reading of it


def _detector_size(width: int, height: int) -> str:
    """The size at which the line detector reads a ``width`` x ``height`` photo (block means
    at up to ``RIDGE_SIDE``)."""
    k = block_factor((height, width), RIDGE_SIDE)
    return f"{width // k} x {height // k}"


PHONE = f"real photos, {plane_renders.WIDTH * PHONE_SCALE} x {plane_renders.HEIGHT * PHONE_SCALE}"


def _phone_note(views, phone) -> str:
    """What the phone set is, and how much it magnifies the photos."""
    pixels = {v.texture: [] for v in phone}  # photo pixels per screen pixel at the plane origin
    for v in phone:
        pixels[v.texture].append(1.0 / v.texel_px)
    ranges = "; ".join(f"{name.split('@')[0].split('/')[-1]} {min(p):.2f}-{max(p):.2f}"
                       for name, p in pixels.items())
    return (f"**Phone set**: the real-photo views again, same cameras and scenes, rendered at "
            f"{phone[0].width} x {phone[0].height} ({PHONE_SCALE} x the {views[0].width} x "
            f"{views[0].height} views; a 12 MP photo is read by the line detector at "
            f"{_detector_size(*PHONE_12MP)}, this at "
            f"{_detector_size(phone[0].width, phone[0].height)}) "
            f"from the full photos (the setts at 2048 px). Photo pixels "
            f"per screen pixel at the plane's origin: {ranges}. Under 1 is a magnified photo: "
            "its joints are softer than a phone photo of the same scene would show them.")


def _phone_views(views, photos, real) -> tuple[list, dict]:
    """The same scenes as ``views`` at PHONE_SCALE times the resolution, the texture rendered from
    the full photo (its surface rows), and those textures by name."""
    full = {f"{name}@full": photo[SURFACE.get(name, slice(None))] for name, photo in photos.items()}
    return [v.enlarged(PHONE_SCALE, f"{v.texture}@full",
                       full[f"{v.texture}@full"].shape[1] / real[v.texture].shape[1])
            for v in views], full


def _phone_focal(image) -> float:
    h, w = image.shape[:2]
    return PHONE_MM / math.hypot(36.0, 24.0) * math.hypot(w, h)


def _jpeg(photo, quality: int) -> np.ndarray:
    buffer = io.BytesIO()
    Image.fromarray((np.clip(photo, 0, 1) * 255 + 0.5).astype(np.uint8)).save(
        buffer, "JPEG", quality=quality)
    return np.asarray(Image.open(buffer), np.float32) / 255


def _reduced(image: np.ndarray) -> np.ndarray:
    k = max(1, math.ceil(max(image.shape[:2]) / TEXTURE_SIDE))
    h, w = (image.shape[0] // k) * k, (image.shape[1] // k) * k
    return image[:h, :w, :3].reshape(h // k, k, w // k, k, 3).mean(axis=(1, 3))


def _frontal(photos) -> list[str]:
    lines = ["**Real frontal photos** (truth: slant about 0; goal: slant <= 5 deg at confidence "
             ">= 0.5):", "",
             "| photo | size | focal length | slant | slant sigma | confidence | line families "
             "| verdict |", "|---|---|---|---:|---:|---:|---:|---|"]
    for name, image in photos.items():
        crops = {f"{image.shape[1]} x {image.shape[0]}": image}
        h, w = image.shape[:2]
        if min(h, w) > 1024:
            crops["1024 crop"] = image[(h - 1024) // 2:(h + 1024) // 2,
                                       (w - 1024) // 2:(w + 1024) // 2]
        for size, crop in crops.items():
            for label, focal in ((f"phone EXIF ({PHONE_MM:.0f} mm eq.)", _phone_focal(crop)),
                                 ("unknown", None)):
                r = plane.estimate_plane(crop, focal_px=focal)
                lines.append(f"| {name} | {size} | {label} | {r.slant:.1f} | "
                             f"{r.slant_uncertainty:.1f} | {r.confidence:.2f} | "
                             f"{r.line_families} | {plane.verdict(r).summary} |")
    return lines


#: Held-out regular photos (never tuned on), for the phone-style frontal pieces.
HELD_OUT = ("openarena/stone_blocks_dark.png", "extremetuxracer/pave01.png")
PHONE_PIECE = (4000, 3000)  # a piece of the photo enlarged as a phone writes it (issue 42)
PIECE_SHARES = (1.0, 0.6, 0.35)  # pieces' widths, shares of the widest 4:3 piece the photo has


def _phone_pieces(name: str, photo) -> list[tuple[str, object]]:
    """4:3 pieces of a frontal photo, enlarged to 4000 x 3000 (bicubic), saved as JPEG quality
    88 with FocalLengthIn35mmFilm 26, as the path of each and its piece's box."""
    rgb = np.atleast_3d(photo)[:, :, :3]
    image = Image.fromarray((np.clip(np.broadcast_to(rgb, (*rgb.shape[:2], 3)), 0, 1) * 255
                             + 0.5).astype(np.uint8))
    rng = np.random.default_rng(42)
    h, w = photo.shape[:2]
    widest = min(w, h * 4 // 3)
    out = []
    for i, share in enumerate(PIECE_SHARES):
        pw = int(widest * share) // 4 * 4
        ph = pw * 3 // 4
        x0, y0 = int(rng.integers(0, w - pw + 1)), int(rng.integers(0, h - ph + 1))
        path = plane_renders.CACHE / f"phone_{name.replace('/', '_')}_{i}.jpg"
        if not path.exists():
            exif = Image.Exif()
            exif.get_ifd(0x8769)[0xA405] = round(PHONE_MM)
            path.parent.mkdir(parents=True, exist_ok=True)
            image.crop((x0, y0, x0 + pw, y0 + ph)).resize(PHONE_PIECE, Image.BICUBIC).save(
                path, quality=88, exif=exif)
        out.append((path, f"{pw} x {ph} at {x0},{y0}"))
    return out


def _frontal_pieces(names) -> list[str]:
    """The zero-click path on frontal phone photos of man-made surfaces (issue 42): every piece
    read with the EXIF's focal length and with none; the confidence table over them."""
    rows, scored = [], []
    for name in names:
        photo = read_photo(SHARED_TEXTURES / ("large" if name in REAL else "") / name)
        pieces = _phone_pieces(name, photo)
        for label in ("EXIF", "unknown"):
            got = []
            for path, _ in pieces:
                image = np.asarray(Image.open(path), np.float32) / 255
                focal = plane.focal_px_from_file(path) if label == "EXIF" else None
                r = plane.estimate_plane(image, focal_px=focal)
                got.append(r)
                scored.append((r.slant, r.confidence))  # truth: frontal, error = slant
            rows.append(f"| {name}{' (held out)' if name in HELD_OUT else ''} | {label} | "
                        + ", ".join(f"{r.slant:.1f}" for r in got) + " | "
                        + ", ".join(f"{r.confidence:.2f}" for r in got) + " |")
    e, c = np.array(scored).T
    wrong = int(np.sum((e > 10) & (c >= 0.5)))
    lines = ["", f"**Frontal phone photos** (issue 42): {len(PIECE_SHARES)} 4:3 pieces of each "
             "regular photo (widths " + ", ".join(f"{x:g}" for x in PIECE_SHARES)
             + " of the widest), enlarged to 4000 x 3000, JPEG quality 88, EXIF "
             f"FocalLengthIn35mmFilm {PHONE_MM:.0f}; truth: slant about 0. Goal: none off by "
             f"more than 10 deg at confidence >= 0.5. **{wrong} of {len(e)}** estimates are "
             "(the pieces' slants and confidences in order):", "",
             "| photo | focal length | slant (deg) | confidence |", "|---|---|---|---|", *rows,
             "", "**Confidence on these real photos** (all pieces and both conditions):", "",
             "| confidence | estimates | median slant | off by more than 10 deg |",
             "|---|---:|---:|---:|"]
    for lo, hi in ((0.0, 0.25), (0.25, 0.5), (0.5, 0.75), (0.75, 0.9), (0.9, 1.01)):
        inside = (c >= lo) & (c < hi)
        med = f"{np.median(e[inside]):.1f}" if inside.any() else "-"
        lines.append(f"| {lo:.2f}-{min(hi, 1.0):.2f} | {int(inside.sum())} | {med} | "
                     f"{int(np.sum(inside & (e > 10)))} |")
    return lines


def _coverage(scored) -> str:
    e = np.array([s["error"] for s in scored])
    s = np.array([s["uncertainty"] for s in scored])
    if len(e) == 0:
        return "-"
    return f"{np.mean(e <= COVER_80 * s) * 100:.0f} % ({len(e)} views)"


def run(ctx) -> str:
    start = time.perf_counter()
    large = SHARED_TEXTURES / "large"
    photos = {name: read_photo(large / name)[:, :, :3] for name in REAL}
    shared = {t.name: t.image for t in ctx.textures}
    made = {n: t for n, (t, _) in manmade.textures().items()}
    real = {name: _reduced(image[SURFACE.get(name, slice(None))])
            for name, image in photos.items()}
    views_real = plane_renders.make_views(list(real), 4 if ctx.quick else 8, seed=27)
    views_phone, full = _phone_views(views_real, photos, real)
    # Subsets of the plane section's own views (same draws, so the same cached renders).
    views_shared = plane_renders.make_views(list(shared), 2)[::3]  # both projections
    views_made = plane_renders.make_views(list(made), 3 if ctx.quick else 6, seed=16)[::2]
    families = {"real photos": views_real, PHONE: views_phone, "shared textures": views_shared,
                "man-made (procedural)": views_made}
    everything = [v for views in families.values() for v in views]
    rendered = dict(zip([v.key() for v in everything], plane_renders.render_views(
        everything, {**shared, **made, **real, **full}), strict=True))
    render_s = time.perf_counter() - start

    scores = defaultdict(list)  # (family, condition) -> [(view, score)]
    jpeg = defaultdict(list)    # (family, quality) -> [error or None (refused)]
    for family, views in families.items():
        for view in views:
            photo = rendered[view.key()]
            calls = {"ortho": None} if view.focal_px is None else {
                "exif": plane.focal_px_from_file(exif_jpeg(view, photo)), "unknown": None}
            for condition, focal in calls.items():
                tic = time.process_time()
                result = plane.estimate_plane(photo, focal_px=focal)
                scores[family, condition].append(
                    (view, {**score(view, result), "cpu": time.process_time() - tic}))
            if family == "shared textures":
                continue
            for quality in QUALITIES:
                try:
                    result = plane.estimate_plane(_jpeg(photo, quality))
                    jpeg[family, quality].append(score(view, result)["error"])
                except ValueError:
                    jpeg[family, quality].append(None)

    lines = [f"Real photos: {', '.join(REAL)} (shared large photos, reduced to "
             f"{TEXTURE_SIDE} px for rendering; the brick wall's coping and ground rows cut "
             f"off there). {len(everything)} views rendered or read from "
             f"the cache in {render_s:.0f} s: {len(views_real)} of the real photos at "
             f"{plane_renders.WIDTH} x {plane_renders.HEIGHT}, the same {len(views_phone)} at "
             f"phone resolution, {len(views_shared)} of the shared textures and "
             f"{len(views_made)} procedural man-made ones (every 3rd and every 2nd view of the "
             "plane section).", "", _phone_note(views_real, views_phone), ""]
    lines += _frontal(photos)
    lines += _frontal_pieces([n for n in REAL] + list(HELD_OUT))

    lines += ["", "**Rendered views of real photos**, slant >= 20 deg (goals, at phone "
              "resolution: median normal error <= 2 deg with the focal length from EXIF, <= 4 "
              f"deg with it unknown; {plane_renders.WIDTH} x {plane_renders.HEIGHT} is a "
              "low-resolution condition), and CPU seconds per estimate:", "",
              "| condition | views | median | p90 | within 5 deg | line families (median) "
              "| CPU s (median) |", "|---|---:|---:|---:|---:|---:|---:|"]
    for condition in ("exif", "unknown", "ortho"):
        for family in ("real photos", PHONE):
            got = [s for v, s in scores[family, condition] if v.slant >= 20]
            if not got:
                continue
            size = f"{families[family][0].width} x {families[family][0].height}"
            e = np.array([s["error"] for s in got])
            lines.append(f"| {condition}, {size} | {len(e)} | {np.median(e):.1f} | "
                         f"{np.percentile(e, 90):.1f} | {np.mean(e <= 5) * 100:.0f} % | "
                         f"{np.median([s['families'] for s in got]):.0f} | "
                         f"{np.median([s['cpu'] for s in got]):.2f} |")

    lines += ["", "**JPEG views** (Pillow, focal length unknown; goal: no refusal at quality "
              "70 to 95). Median normal error at slant >= 20 deg beside the PNG render's:", "",
              "| family | PNG | " + " | ".join(f"JPEG q{q}" for q in QUALITIES) + " | refused |",
              "|---|---:|" + "---:|" * len(QUALITIES) + "---:|"]
    for family in ("real photos", PHONE, "man-made (procedural)"):
        views = families[family]
        steep = [i for i, v in enumerate(views) if v.slant >= 20]
        png = {v.key(): s["error"] for cond in ("unknown", "ortho")
               for v, s in scores[family, cond]}
        cells, refused = [], 0
        for quality in QUALITIES:
            errors = jpeg[family, quality]
            refused += sum(e is None for e in errors)
            kept = [errors[i] for i in steep if errors[i] is not None]
            cells.append(f"{np.median(kept):.1f}" if kept else "-")
        base = np.median([png[views[i].key()] for i in steep])
        lines.append(f"| {family} | {base:.1f} | " + " | ".join(cells)
                     + f" | {refused} of {len(views) * len(QUALITIES)} |")

    sure = [s for family in ("real photos", PHONE) for v, s in scores[family, "exif"]
            if v.slant >= 20 and s["confidence"] >= 0.9]
    lines += ["", f"**Confidently wrong** on the rendered views of real photos (perspective, slant "
              f">= 20 deg, focal length from EXIF, both resolutions; goal: at most 5 % of those "
              f"at confidence >= 0.9 off by more than 10 deg): {sum(s['error'] > 10 for s in sure)}"
              f" of {len(sure)}."]
    lines += ["", f"**Coverage**: views whose normal error is within {COVER_80:.2f} x the stated "
              "normal sigma (the 80 % radius; goal >= 80 % on stochastic textures), all slants:",
              "", "| family | " + " | ".join(("EXIF", "unknown", "orthographic")) + " |",
              "|---|---:|---:|---:|"]
    for family in families:
        lines.append(f"| {family} | " + " | ".join(
            _coverage([s for _, s in scores[family, c]]) for c in ("exif", "unknown", "ortho"))
            + " |")
    lines += ["", f"Section wall time {time.perf_counter() - start:.0f} s."]
    return "\n".join(lines)
