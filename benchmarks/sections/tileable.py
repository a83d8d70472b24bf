"""Issue 17: make a photo itself tile (beside GIMP's Make Seamless and the Resynthesizer engine
filling the same band), texture optimisation on regular and structured textures (beside the
Resynthesizer engine and the multiscale MRF), and Heeger-Bergen's colours on pool_water.

The README's first picture is made by the photos section (photos at their own size).
"""

from __future__ import annotations

import shutil
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

import texsynth
from benchmarks import peers
from benchmarks.context import SAMPLE, SHARED_TEXTURES, fmt, timed
from texsynth import metrics
from texsynth.io import read_photo, write_png
from texsynth.tileable import default_band

ORDER = 55
TITLE = "Make a photo tile; texture optimisation; Heeger-Bergen's colours (issue 17)"

SEED = 0
LARGE = SHARED_TEXTURES / "large"
#: Photos made tileable: (path below shared/textures, licence note in MANIFEST).
PHOTOS = ("large/torcs-data/gravel_pebbles.png", "large/torcs-data/grass_lawn.png",
          "large/ufoai-textures/gravelly_dirt_ground.png", "large/redeclipse-data/asphalt.png",
          "large/torcs-data/rock_face_vegetation.png", "large/ufoai-textures/layered_grey_rock.png",
          "large/nexuiz-textures/jagged_rock_cliff.png", "large/ufoai-textures/brick_wall.png",
          "large/nexuiz-textures/concrete_pavers.png", "skimage/brick.png",
          "trigger-rally/clouds_cumulus.png")
TIMED_1024 = ("large/torcs-data/gravel_pebbles.png", "large/ufoai-textures/brick_wall.png",
              "large/nexuiz-textures/jagged_rock_cliff.png")
OFF_PALETTE = 0.12  # RGB distance from every exemplar colour that counts as a new colour


def centre_crop(rel, side):
    """The shared photo ``rel`` as RGB float32, its centre ``side`` x ``side`` (or all of it)."""
    image = read_photo(SHARED_TEXTURES / rel)[:, :, :3].astype(np.float32)
    if image.shape[2] == 1:
        image = np.repeat(image, 3, axis=2)
    h, w = image.shape[:2]
    top, left = max(0, (h - side) // 2), max(0, (w - side) // 2)
    return np.ascontiguousarray(image[top:top + side, left:left + side])


def _cross(shape, band):
    """The band across the wrap of the photo rolled by half its size (the cross through its
    middle), as make_tileable places it."""
    h, w = shape[:2]
    i = np.arange(h)[:, None]
    j = np.arange(w)[None, :]
    sh, sw = h // 2, w // 2
    return (((i >= sh - band // 2) & (i < sh - band // 2 + band))
            | ((j >= sw - band // 2) & (j < sw - band // 2 + band)))


def band_strips(image, band, margin=4):
    """The re-synthesized band, as one image: the horizontal arm of the rolled result and the
    vertical arm transposed, each with ``margin`` pixels of context either side."""
    h, w = image.shape[:2]
    rolled = np.roll(image, (h // 2, w // 2), axis=(0, 1))
    top, left = h // 2 - band // 2 - margin, w // 2 - band // 2 - margin
    across = rolled[top:top + band + 2 * margin]
    down = rolled[:, left:left + band + 2 * margin].transpose(1, 0, 2)
    return np.concatenate([across, down], axis=1)


def resynthesizer_band(photo, band):
    """The Resynthesizer engine filling the same band of the rolled photo from the rest of it,
    tiling flags on; rolled back."""
    import resynthesizer as rs
    from PIL import Image

    h, w = photo.shape[:2]
    rolled = np.roll(photo, (h // 2, w // 2), axis=(0, 1))
    mask = np.where(_cross(photo.shape, band), 255, 0).astype(np.uint8)
    params = rs.getDefaultParams()
    params.isMakeSeamlesslyTileableHorizontally = 1
    params.isMakeSeamlesslyTileableVertically = 1
    canvas = np.rint(np.clip(rolled, 0, 1) * 255).astype(np.uint8)
    out = rs.resynthesize(Image.fromarray(canvas), Image.fromarray(mask), params)
    return np.roll(np.asarray(out, np.float32) / 255.0, (-(h // 2), -(w // 2)), axis=(0, 1))


def gimp_make_seamless(photos):
    """GIMP 2.10's plug-in-make-seamless on every photo, in one batch run of gimp-console;
    None when GIMP is not installed. Returns (outputs, seconds for the whole batch)."""
    gimp = shutil.which("gimp-console-2.10") or shutil.which("gimp-console")
    if gimp is None:
        return None, None
    with tempfile.TemporaryDirectory(prefix="texsynth-gimp-") as tmp:
        commands = []
        for k, photo in enumerate(photos):
            src, dst = Path(tmp, f"in{k}.png"), Path(tmp, f"out{k}.png")
            write_png(src, photo)
            commands.append(
                f'(let* ((image (car (gimp-file-load RUN-NONINTERACTIVE "{src}" "{src}"))) '
                "(drawable (car (gimp-image-get-active-layer image)))) "
                "(plug-in-make-seamless RUN-NONINTERACTIVE image drawable) "
                f'(gimp-file-save RUN-NONINTERACTIVE image drawable "{dst}" "{dst}") '
                "(gimp-image-delete image))")
        args = [gimp, "-i", "-d", "-f"]
        for c in commands:
            args += ["-b", c]
        args += ["-b", "(gimp-quit 0)"]
        start = time.perf_counter()
        subprocess.run(args, check=True, capture_output=True, timeout=600)
        seconds = time.perf_counter() - start
        outs = [read_photo(Path(tmp, f"out{k}.png"))[:, :, :3].astype(np.float32)
                for k in range(len(photos))]
    return outs, seconds


def _get(q, key, field):
    return q.get(key, {}).get(field)


def _tile(a):
    return None if a is None else np.tile(a, (2, 2, 1))


def unchanged(photo, out):
    """Share of pixels equal to the photo's at 8-bit precision (GIMP's output is 8-bit)."""
    return float((np.rint(out * 255) == np.rint(photo * 255)).all(axis=2).mean())


def _make_tileable(ctx, side):
    names = [p for p in PHOTOS if (SHARED_TEXTURES / p).exists()]
    photos = [centre_crop(p, side) for p in names]
    gimp_outs, gimp_seconds = gimp_make_seamless(photos)
    has_rs = next(p for p in peers.peers() if p.name == "resynthesizer").missing is None
    tools = (("ours", "ours"), ("gimp", "GIMP"), ("rs", "Resynth."))
    figures = (("seam", "seam", 2), ("sharp", "band sharpness", 2), ("gradient", "gradient", 2),
               ("unchanged", "unchanged", 2), ("patch", "band patch d.", 3))
    lines = ["| photo | photo seam | band px | ours s | Resynth. s | "
             + " | ".join(f"{label} {what}" for _, what, _ in figures for _, label in tools)
             + " |", "|---" * (5 + 3 * len(figures)) + "|"]
    stats = {k: [] for k in ("ours", "gimp", "rs")}
    rows, ratio = [], []
    for k, (name, photo) in enumerate(zip(names, photos, strict=True)):
        band = default_band(photo.shape)
        t_ours, ours = timed(lambda p=photo: texsynth.make_tileable(p, seed=SEED))
        entry = {"ours": (ours, t_ours)}
        if gimp_outs is not None:
            entry["gimp"] = (gimp_outs[k], None)
        if has_rs:
            t_rs, rs_out = timed(lambda p=photo, b=band: resynthesizer_band(p, b))
            entry["rs"] = (rs_out, t_rs)
            ratio.append(t_ours / t_rs)
        q = {}
        for key, (out, seconds) in entry.items():
            q[key] = {"seam": metrics.seam_ratio(out), "unchanged": unchanged(photo, out),
                      "sharp": metrics.band_sharpness(out, band),
                      "gradient": metrics.gradient_ratio(photo, out),
                      "patch": metrics.patch_distance(photo, band_strips(out, band))["median"],
                      "seconds": seconds}
            stats[key].append(q[key])
        lines.append(
            f"| {Path(name).stem} | {metrics.seam_ratio(photo):.2f} | {band} | {t_ours:.2f} | "
            f"{fmt(_get(q, 'rs', 'seconds'), 2)} | "
            + " | ".join(fmt(_get(q, key, field), digits) for field, _, digits in figures
                         for key, _ in tools) + " |")
        rows.append([_tile(photo), _tile(entry.get("gimp", (None,))[0]),
                     _tile(entry.get("rs", (None,))[0]), _tile(ours)])
    columns = ["photo, tiled 2 x 2", "GIMP Make Seamless", "Resynthesizer, band",
               "make_tileable"]
    sheets = [ctx.contact_sheet(f"tileable_{i // 6}.png", columns, rows[i:i + 6], cell=256)
              for i in range(0, len(rows), 6)]
    return lines, sheets, stats, ratio, gimp_seconds, len(photos)


def _timing_1024():
    lines = ["| photo | band px | seconds | seam | unchanged |", "|---" * 5 + "|"]
    seconds = []
    for name in TIMED_1024:
        if not (SHARED_TEXTURES / name).exists():
            continue
        photo = centre_crop(name, 1024)
        t, out = timed(lambda p=photo: texsynth.make_tileable(p, seed=SEED))
        seconds.append(t)
        lines.append(f"| {Path(name).stem} | {default_band(photo.shape)} | {t:.2f} | "
                     f"{metrics.seam_ratio(out):.2f} | {unchanged(photo, out):.2f} |")
    return lines, seconds


def _texture_optimization(ctx, side, out_side):
    rs = next(p for p in peers.peers() if p.name == "resynthesizer")
    rs = rs if rs.missing is None else None
    textures = [t for t in ctx.textures if t.category in ("regular", "structured")]
    names = ["texture_optimization", "multiscale_mrf"] + (["resynthesizer"] if rs else [])
    quality = {n: [] for n in names}
    times = {n: [] for n in names}
    rows = []
    lines = ["| texture | category | TO structure d. | MRF structure d. | Resynth. structure d. | "
             "TO copy | MRF copy | Resynth. copy | TO patch d. | Resynth. patch d. | TO s | "
             "Resynth. s |", "|---" * 12 + "|"]
    for tex in textures:
        h, w = tex.image.shape[:2]
        top, left = max(0, (h - side) // 2), max(0, (w - side) // 2)
        ex = np.ascontiguousarray(tex.image[top:top + side, left:left + side, :3])
        outs = {}
        for n in names:
            run = (lambda ex=ex: rs.run(ex, out_side, out_side, SEED)) if n == "resynthesizer" \
                else (lambda ex=ex, n=n: texsynth.synthesize(ex, out_side, out_side, method=n,
                                                             seed=SEED))
            t, outs[n] = timed(run)
            times[n].append(t)
            quality[n].append({"category": tex.category, **metrics.quality(ex, outs[n])})
        q = {n: quality[n][-1] for n in names}
        lines.append(
            f"| {tex.short} | {tex.category} | "
            f"{q['texture_optimization']['structure_distance']:.3f} | "
            f"{q['multiscale_mrf']['structure_distance']:.3f} | "
            f"{fmt(_get(q, 'resynthesizer', 'structure_distance'))} | "
            f"{q['texture_optimization']['copy_share']:.2f} | "
            f"{q['multiscale_mrf']['copy_share']:.2f} | "
            f"{fmt(_get(q, 'resynthesizer', 'copy_share'), 2)} | "
            f"{q['texture_optimization']['patch_distance']:.3f} | "
            f"{fmt(_get(q, 'resynthesizer', 'patch_distance'))} | "
            f"{times['texture_optimization'][-1]:.2f} | "
            f"{fmt(times['resynthesizer'][-1] if rs else None, 2)} |")
        rows.append([ex] + [outs[n] for n in names])
    summary = {}
    for n in names:
        for cat in ("regular", "structured"):
            values = [x["structure_distance"] for x in quality[n] if x["category"] == cat]
            summary[(n, cat)] = statistics.median(values) if values else float("nan")
        summary[(n, "copy")] = float(np.mean([x["copy_share"] for x in quality[n]]))
        summary[(n, "patch")] = statistics.median(x["patch_distance"] for x in quality[n])
        summary[(n, "time")] = statistics.median(times[n])
    columns = ["exemplar", "texture_optimization", "multiscale_mrf"] + (
        ["Resynthesizer"] if rs else [])
    sheets = [ctx.contact_sheet(f"texture_optimization_{i // 7}.png", columns, rows[i:i + 7])
              for i in range(0, len(rows), 7)]
    return lines, sheets, summary, names


def _off_palette(exemplar, output):
    distance, _ = cKDTree(exemplar.reshape(-1, 3)).query(output.reshape(-1, 3))
    return float((distance > OFF_PALETTE).mean())


def _heeger_bergen_colour():
    ex = read_photo(SAMPLE)[:, :, :3].astype(np.float32)
    lines = ["| output | off-palette share | subband distance |", "|---" * 3 + "|"]
    for side in (256, 512):
        out = texsynth.synthesize(ex, side, side, method="heeger_bergen", seed=SEED)
        lines.append(f"| {side} x {side} | {100 * _off_palette(ex, out):.2f} % | "
                     f"{metrics.subband_distance(ex, out):.3f} |")
    return lines


def run(ctx) -> str:
    md = []
    if not SHARED_TEXTURES.exists():
        return "Needs ../shared/textures (the photos); skipped."
    side = 256 if ctx.quick else 512
    lines, sheets, stats, ratio, gimp_seconds, n = _make_tileable(ctx, side)
    timing, seconds = _timing_1024() if not ctx.quick else ([], [])

    def med(key, f):
        return statistics.median(x[f] for x in stats[key]) if stats[key] else float("nan")

    md += [
        "### make_tileable: the photo itself made to tile",
        "",
        f"The central {side} x {side} crop of {n} photos (the large ones and two that do not "
        "tile), each made to tile three ways: `texsynth.make_tileable` (defaults: band an "
        "eighth of the side, seed 0); GIMP 2.10's *Make Seamless* filter "
        "(plug-in-make-seamless, Debian's gimp, run in one gimp-console batch: "
        + (f"{gimp_seconds:.1f} s for all, GIMP's start-up included)" if gimp_seconds
           else "not installed: its columns are empty)")
        + "; and the Resynthesizer engine filling the same band of the photo rolled by half "
        "its size (the rest of the photo as its source, tiling flags on), rolled back. "
        "*Unchanged*: share of pixels equal to the photo's at 8 bits. *Band patch d.*: median "
        "nearest-photo-patch distance (metrics.patch_distance) of 8 x 8 patches of the band "
        "(both arms, 4 pixels of context either side): is what replaced the seam built from "
        "the photo?",
        "",
        "Seam ratio (the mean step across the wrap over the mean step inside), band sharpness "
        "(metrics.band_sharpness: the mean gradient in the middle of the band over that of the "
        "kept pixels) and gradient ratio (the result's mean gradient over the photo's) read "
        "two-sided: between 0.9 and 1.1 is the target. A seam ratio of 0.5 is a soft line where "
        "the tiles meet, as far off the target as 1.5 (a visible step): lower is not better. A "
        "band sharpness under 0.9 is a blurred cross.",
        "",
        f"Medians: seam ratio ours **{med('ours', 'seam'):.2f}**, GIMP "
        f"{fmt(med('gimp', 'seam'), 2)}, Resynthesizer {fmt(med('rs', 'seam'), 2)}; "
        f"band sharpness ours **{med('ours', 'sharp'):.2f}**, GIMP "
        f"{fmt(med('gimp', 'sharp'), 2)}, Resynthesizer {fmt(med('rs', 'sharp'), 2)}; "
        f"gradient ratio ours **{med('ours', 'gradient'):.2f}**, GIMP "
        f"{fmt(med('gimp', 'gradient'), 2)}, Resynthesizer {fmt(med('rs', 'gradient'), 2)}; "
        f"unchanged ours **{med('ours', 'unchanged'):.2f}**, GIMP "
        f"{fmt(med('gimp', 'unchanged'), 2)}, Resynthesizer {fmt(med('rs', 'unchanged'), 2)};"
        f" band patch distance ours **{med('ours', 'patch'):.3f}**, Resynthesizer "
        f"{fmt(med('rs', 'patch'))}, GIMP {fmt(med('gimp', 'patch'))}"
        + (f"; time ours / Resynthesizer {statistics.median(ratio):.2f}" if ratio else "")
        + ".",
        "", *lines, "",
        *[f"![make_tileable sheet {i}]({s})" for i, s in enumerate(sheets)],
        "",
        "Columns, each tiled 2 x 2 so the wrap shows: the photo | GIMP Make Seamless | "
        "Resynthesizer filling the band | make_tileable.",
        "",
    ]
    if timing:
        md += [f"1024 x 1024 photos (bare wall time, one run each): median "
               f"**{statistics.median(seconds):.2f} s** (goal: under 5 s).", "", *timing, ""]

    to_side, to_out = (64, 128) if ctx.quick else (128, 256)
    to_lines, to_sheets, summary, names = _texture_optimization(ctx, to_side, to_out)
    label = {"texture_optimization": "texture_optimization", "multiscale_mrf": "multiscale_mrf",
             "resynthesizer": "Resynthesizer engine"}
    md += ["### texture_optimization on regular and structured textures", "",
           f"The central {to_side} x {to_side} crop -> {to_out} x {to_out}, seed 0, defaults, "
           "as in the overview section; Resynthesizer as the overview drives it (the exemplar "
           "in its canvas' corner, a quarter of its output a verbatim copy, which its copy "
           "share includes).", "",
           "| method | structure d. regular (median) | structure d. structured (median) | "
           "copy share (mean) | patch d. (median) | time s (median) |", "|---" * 6 + "|"]
    for n in names:
        md.append(f"| {label[n]} | {summary[(n, 'regular')]:.3f} | "
                  f"{summary[(n, 'structured')]:.3f} | {summary[(n, 'copy')]:.3f} | "
                  f"{summary[(n, 'patch')]:.3f} | {summary[(n, 'time')]:.2f} |")
    md += ["", *to_lines, "", *[f"![texture optimisation {i}]({s})"
                                for i, s in enumerate(to_sheets)], "",
           "Columns: exemplar | texture_optimization | multiscale_mrf | Resynthesizer.", ""]

    md += ["### Heeger-Bergen's colours on pool_water", "",
           f"Share of output pixels farther than {OFF_PALETTE} (RGB, 0-1) from every colour of "
           "the bundled pool_water sample, seed 0. Before this change (commit 65c6871, PCA "
           "components synthesized one by one) the 256 x 256 output had 2.47 % such pixels "
           "(magenta specks) and subband distance 0.063; now the colours take sliced optimal "
           "transport steps towards the exemplar's joint colour distribution after every "
           "iteration.", "", *_heeger_bergen_colour(), ""]
    return "\n".join(md)
