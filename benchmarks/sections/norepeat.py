"""Issue 28: a material that never repeats. ``texsynth.break_repetition`` (tiling and blending)
on a plane showing a photo 8 x 8 times, rendered with Cycles from above and at a grazing angle,
plain and after; the precomputation's time and memory on the large photos."""

from __future__ import annotations

import statistics
import time
import tracemalloc

import numpy as np

from benchmarks import norepeat_renders as renders
from benchmarks.context import SHARED_TEXTURES, fmt
from texsynth.blocks.color import srgb_to_linear
from texsynth.io import read_image
from texsynth.norepeat import gaussianize, predict_memory

ORDER = 80
TITLE = "No repetition (issue 28)"

#: (photo below shared/textures/large, kind)
PHOTOS = (("torcs-data/gravel_pebbles.png", "stochastic"),
          ("ufoai-textures/layered_grey_rock.png", "structured"),
          ("ufoai-textures/brick_wall.png", "regular"),
          ("0ad-data/granite_setts_grass.png", "regular"))
SIDE = 256  # the photo box-averaged to this side for the renders
SIZE, SAMPLES, TILES, GRAZING_TILES = 512, 16, 8, 16
GOALS = {"corr": 0.3, "wasserstein": 0.03, "gradient": (0.85, 1.15), "time": 2.0}


def _photo(rel):
    return read_image(SHARED_TEXTURES / "large" / rel)[:, :, :3].astype(np.float32)


def _box(photo, side):
    f = photo.shape[0] // side
    return photo[:side * f, :side * f].reshape(side, f, side, f, 3).mean(axis=(1, 3))


def _precompute(photo):
    """Seconds and tracemalloc peak of ``gaussianize`` on the photo's scene-linear values."""
    linear = srgb_to_linear(photo).astype(np.float32)
    tracemalloc.start()
    start = time.perf_counter()
    gaussianize(linear)
    seconds = time.perf_counter() - start
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return seconds, peak, predict_memory(linear.shape)


def _pair(photo, view, tiles, repeats):
    """Plain and after renders of one view, and the median render seconds of each: after the
    operator, the shader's Base Color is fed by the plain node and the new group node in turn
    (a warm-up render of each first), so that both see the same load."""
    import bpy

    tree = renders.scene(photo, tiles, SIZE, SAMPLES, view=view)
    plain_node = tree.nodes.active
    bpy.ops.texsynth.break_repetition()
    after_node = tree.nodes.active
    base = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeBsdfPrincipled") \
        .inputs["Base Color"]
    shots = {}
    for _ in range(repeats + 1):
        for name, node in (("plain", plain_node), ("after", after_node)):
            tree.links.new(node.outputs["Color"], base)
            image, seconds = renders.render()
            shots.setdefault(name, []).append((image, seconds))
    times = {k: statistics.median(s for _, s in v[1:]) if repeats else float("nan")
             for k, v in shots.items()}
    return shots["plain"][0][0], shots["after"][0][0], times["plain"], times["after"]


def run(ctx) -> str:
    if not (SHARED_TEXTURES / "large").exists():
        return "Skipped: ../shared/textures/large is absent."
    renders.extension()
    photos = PHOTOS[:2] if ctx.quick else PHOTOS
    repeats = 1 if ctx.quick else 2
    rows, cost_rows, pictures, readme = [], [], [], None
    for rel, kind in photos:
        full = _photo(rel)
        seconds, peak, predicted = _precompute(full)
        h, w = full.shape[:2]
        cost_rows.append(f"| {rel} | {w} x {h} | {seconds:.2f} | {peak / 2**20:.0f} | "
                         f"{predicted / 2**20:.0f} ({predicted / peak:.2f}x) |")
        photo = _box(full, SIDE)
        plain, after, t_plain, t_after = _pair(photo, "top", TILES, repeats)
        m = renders.measures(plain, after, SIZE // TILES)
        rows.append(f"| {rel} | {kind} | {fmt(m['corr_plain'], 2)} -> {fmt(m['corr_after'], 2)} "
                    f"| {fmt(m['wasserstein'], 4)} | {fmt(m['gradient_ratio'], 2)} | "
                    f"{t_plain:.1f} / {t_after:.1f} ({t_after / t_plain:.2f}x) |")
        plain_g, after_g, _, _ = _pair(photo, "grazing", GRAZING_TILES, 0)
        gap = np.ones((256, 6, 3), np.float32)
        pictures.append(np.concatenate([plain[:256, :256], gap, after[:256, :256], *(3 * [gap]),
                                        plain_g[128:384, 128:384], gap,
                                        after_g[128:384, 128:384]], axis=1))
        print(rel, m, t_plain, t_after, flush=True)
        if kind == "structured":
            readme = (plain, after)
    gap = np.ones((4, pictures[0].shape[1], 3), np.float32)
    sheet = np.concatenate([x for p in pictures for x in (p, gap)][:-1], axis=0)
    picture = ctx.save_jpeg("norepeat_renders.jpg", sheet)
    if readme is not None:  # the README's: the structured photo, plain and after, whole frames
        ctx.save_jpeg("norepeat_readme.jpg", np.concatenate(
            [readme[0], np.ones((SIZE, 8, 3), np.float32), readme[1]], axis=1))
    return "\n".join([
        f"Each photo box-averaged to {SIDE} x {SIDE} (so that a {SIZE}-pixel render of "
        f"{TILES} x {TILES} tiles, {SIZE // TILES} pixels a tile, resolves it; at full size a "
        "pixel would average hundreds of texels and the render's own sampling noise would "
        "swamp the figures) on a plane seen from above by an orthographic camera, Cycles on "
        f"the CPU (1 thread, {SAMPLES} samples, no denoising, box filter), Principled BSDF "
        "(roughness 1, no specular) lit by a sun 45 degrees high, Standard view; the photo "
        "repeated by a Mapping node in front of the Image Texture node, then "
        "`texsynth.break_repetition` (Tiling and Blending, default Scale and seed 0) on that "
        "node. Correlation: the rendered luminance's correlation coefficient with itself "
        "shifted by one tile (mean of x and y; goal: from about 1 to at most "
        f"{GOALS['corr']}). W1: the worst channel's Wasserstein distance between the two "
        f"renders' pixel values (goal at most {GOALS['wasserstein']}). Gradient: the after "
        "render's mean luminance gradient over the plain one's (goal 0.85-1.15). Render "
        f"seconds: median of {repeats} renders of each, plain and after in turn after a "
        f"warm-up render of each, plain / after (goal at most {GOALS['time']}x). "
        "`benchmarks/norepeat_renders.py` builds the scene.",
        "",
        "| photo | kind | correlation at the period, plain -> after | W1 | gradient | "
        "render s plain / after |",
        "|---|---|---|---|---|---|",
        *rows,
        "",
        f"![renders]({picture})",
        "",
        "Each row: plain and after from above (a quarter of the frame, 4 x 4 tiles), then plain "
        f"and after at a grazing angle (75 degrees from the normal, {GRAZING_TILES} x "
        f"{GRAZING_TILES} tiles on the plane, 50 mm, the frame's middle).",
        "",
        "The precomputation (`texsynth.norepeat.gaussianize`, RGB channels, 4096-entry tables) "
        "at the photos' full size: seconds (one run), tracemalloc's peak and the prediction "
        "that the operator checks against the memory budget.",
        "",
        "| photo | size | seconds | peak MiB | predicted MiB |",
        "|---|---|---|---|---|",
        *cost_rows,
    ])
