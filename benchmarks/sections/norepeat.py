"""Issue 28: a material that never repeats. ``texsynth.break_repetition`` (each mode: tiling and
blending, tile set) on a plane showing a photo 8 x 8 times, rendered with Cycles from above and
at a grazing angle, plain and after; the precomputations' time and memory on the large
photos."""

from __future__ import annotations

import statistics
import time
import tracemalloc

import numpy as np

from benchmarks import norepeat_renders as renders
from benchmarks.context import SHARED_TEXTURES, fmt
from texsynth.blocks.color import srgb_to_linear
from texsynth.io import read_photo
from texsynth.norepeat import (
    gaussianize,
    photo_use,
    predict_memory,
    predict_tiles_memory,
    repetition_peak,
    rotation_symmetry,
    wang_tiles,
)
from texsynth.norepeat.tiles import COLOURS

ORDER = 80
TITLE = "No repetition (issue 28)"

#: (photo below shared/textures/large, kind)
PHOTOS = (("torcs-data/gravel_pebbles.png", "stochastic"),
          ("ufoai-textures/layered_grey_rock.png", "structured"),
          ("ufoai-textures/brick_wall.png", "regular"),
          ("0ad-data/granite_setts_grass.png", "regular"))
SIDE = 256  # the photo box-averaged to this side for the renders
SIZE, SAMPLES, TILES, GRAZING_TILES = 512, 16, 8, 16
#: The peak's bound: at most 0.3, or the photo's own peak plus this where the photo itself
#: repeats (a brick wall's courses: any render of it repeats at the course period by nature).
OWN_MARGIN = 0.1
GOALS = {"corr": 0.3, "wasserstein": 0.03, "gradient": (0.85, 1.15), "time": 2.0,
         "anisotropy": (0.75, 1.33)}
#: The operator's modes, in the table's and the picture's order.
MODES = (("TILING_AND_BLENDING", "Tiling and Blending"), ("TILE_SET", "Tile Set"),
         ("HEX_TILING", "Hex Tiling"))


def read_large(rel):
    return read_photo(SHARED_TEXTURES / "large" / rel)[:, :, :3].astype(np.float32)


def box_average(photo, side):
    f = photo.shape[0] // side
    return photo[:side * f, :side * f].reshape(side, f, side, f, 3).mean(axis=(1, 3))


def drawn_use(photo, mode):
    """How much a mode shows of each photo pixel, for the like-with-like measures
    (``norepeat_renders.measures``' ``use``): Tile Set's ``texsynth.norepeat.photo_use`` of
    the tiles the operator cuts (defaults, seed 0); None (every pixel alike, as the plain
    render shows them) for Tiling and Blending and Hex Tiling, whose random offsets cover the
    whole periodic photo. On the brick wall the Tile Set never shows the outermost 16 rows
    (the dark ledge along the bottom, the cap along the top), which the plain render repeats
    every tile and which make most of its direction at 4 texels a pixel."""
    return photo_use(wang_tiles(photo)) if mode == "TILE_SET" else None


def _measured(function, *args, **kwargs):
    """Seconds and tracemalloc peak of one call."""
    tracemalloc.start()
    start = time.perf_counter()
    function(*args, **kwargs)
    seconds = time.perf_counter() - start
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return seconds, peak


def _precompute(photo):
    """(name, seconds, peak, predicted) of ``gaussianize`` on the photo's scene-linear values
    and of ``wang_tiles`` on its stored values (what each mode of the operator is given)."""
    linear = srgb_to_linear(photo).astype(np.float32)
    return [("gaussianize", *_measured(gaussianize, linear), predict_memory(linear.shape)),
            ("wang_tiles", *_measured(wang_tiles, photo), predict_tiles_memory(photo.shape))]


def _renders(photo, view, tiles, repeats):
    """Renders of one view, plain and after each mode, and the median render seconds of each:
    the operator runs once per mode on the plain node, then the shader's Base Color is fed by
    the plain node and each mode's group node in turn (a warm-up render of each first), so
    that all see the same load. Returns {name: (first image, seconds)}."""
    import bpy

    tree = renders.scene(photo, tiles, SIZE, SAMPLES, view=view)
    plain_node = tree.nodes.active
    nodes = {"plain": plain_node}
    for mode, _ in MODES:
        for n in tree.nodes:
            n.select = n == plain_node
        tree.nodes.active = plain_node
        assert bpy.ops.texsynth.break_repetition(mode=mode) == {"FINISHED"}
        nodes[mode] = tree.nodes.active
    base = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeBsdfPrincipled") \
        .inputs["Base Color"]
    shots = {}
    for _ in range(repeats + 1):
        for name, node in nodes.items():
            tree.links.new(node.outputs["Color"], base)
            shots.setdefault(name, []).append(renders.render())
    return {k: (v[0][0], statistics.median(s for _, s in v[1:]) if repeats else float("nan"))
            for k, v in shots.items()}


def _like(m, whole, key, digits):
    """A measure like with like, and in brackets against the whole plain render where that
    differs."""
    if m[key] == whole[key]:
        return fmt(m[key], digits)
    return f"{fmt(m[key], digits)} (whole plain: {fmt(whole[key], digits)})"


def run(ctx) -> str:
    if not (SHARED_TEXTURES / "large").exists():
        return "Skipped: ../shared/textures/large is absent."
    renders.extension()
    photos = PHOTOS[:2] if ctx.quick else PHOTOS
    repeats = 1 if ctx.quick else 2
    rows, cost_rows, pictures, readme, turns = [], [], [], {}, []
    for rel, kind in photos:
        full = read_large(rel)
        h, w = full.shape[:2]
        for name, seconds, peak, predicted in _precompute(full):
            cost_rows.append(f"| {rel} | {w} x {h} | `{name}` | {seconds:.2f} | "
                             f"{peak / 2**20:.0f} | {predicted / 2**20:.0f} "
                             f"({predicted / peak:.2f}x) |")
        photo = box_average(full, SIDE)
        turns.append(f"{rel.split('/')[-1]} {rotation_symmetry(photo)}")
        # the photo's own peak at the render's 24 px: SIDE / (SIZE / TILES) texels a pixel
        own = repetition_peak(photo, 24 * SIDE * TILES / SIZE)
        top = _renders(photo, "top", TILES, repeats)
        plain, t_plain = top["plain"]
        for mode, label in MODES:
            after, t_after = top[mode]
            m = renders.measures(plain, after, SIZE // TILES, drawn_use(photo, mode))
            whole = renders.measures(plain, after, SIZE // TILES)
            rows.append(f"| {rel} | {kind} | {label} | {fmt(m['corr_plain'], 2)} -> "
                        f"{fmt(m['corr_after'], 2)} | {fmt(m['peak_plain'], 2)} -> "
                        f"{fmt(m['peak_after'], 2)} ({fmt(own, 2)}; "
                        f"{fmt(max(GOALS['corr'], own + OWN_MARGIN), 2)}) | "
                        f"{_like(m, whole, 'anisotropy_ratio', 2)} | "
                        f"{_like(m, whole, 'wasserstein', 4)} | "
                        f"{fmt(m['gradient_ratio'], 2)} | {t_plain:.1f} / {t_after:.1f} "
                        f"({t_after / t_plain:.2f}x) |")
            print(rel, mode, m, t_plain, t_after, flush=True)
        grazing = _renders(photo, "grazing", GRAZING_TILES, 0)
        gap = np.ones((256, 6, 3), np.float32)
        names = ["plain"] + [mode for mode, _ in MODES]
        columns = [top[n][0][:256, :256] for n in names] + [None] \
            + [grazing[n][0][128:384, 128:384] for n in names]
        pictures.append(np.concatenate(
            [x for c in columns for x in ((3 * [gap]) if c is None else (c, gap))][:-1], axis=1))
        readme.setdefault(kind, (plain, top["TILING_AND_BLENDING"][0], top["TILE_SET"][0]))
    gap = np.ones((4, pictures[0].shape[1], 3), np.float32)
    sheet = np.concatenate([x for p in pictures for x in (p, gap)][:-1], axis=0)
    picture = ctx.save_jpeg("norepeat_renders.jpg", sheet)
    between = np.ones((SIZE, 8, 3), np.float32)
    if "structured" in readme:  # the README's: plain and tiled-and-blended, whole frames
        plain, blended, _ = readme["structured"]
        ctx.save_jpeg("norepeat_readme.jpg", np.concatenate([plain, between, blended], axis=1))
    if "regular" in readme:  # and the first regular photo, plain and tile set
        plain, _, tiled = readme["regular"]
        ctx.save_jpeg("norepeat_tiles_readme.jpg",
                      np.concatenate([plain, between, tiled], axis=1))
    return "\n".join([
        f"Each photo box-averaged to {SIDE} x {SIDE} (so that a {SIZE}-pixel render of "
        f"{TILES} x {TILES} tiles, {SIZE // TILES} pixels a tile, resolves it; at full size a "
        "pixel would average hundreds of texels and the render's own sampling noise would "
        "swamp the figures) on a plane seen from above by an orthographic camera, Cycles on "
        f"the CPU (1 thread, {SAMPLES} samples, no denoising, box filter), Principled BSDF "
        "(roughness 1, no specular) lit by a sun 45 degrees high, Standard view; the photo "
        "repeated by a Mapping node in front of the Image Texture node, then "
        "`texsynth.break_repetition` on that node, once per mode (default settings, seed 0; "
        f"Tile Set: {COLOURS} edge colours, its Scale from the tile side so texels keep their "
        "size; "
        "Hex Tiling: the photo's own turns, `texsynth.norepeat.rotation_symmetry`: "
        f"{', '.join(sorted(set(turns)))}). "
        "Correlation: the rendered luminance's correlation coefficient with itself "
        "shifted by one tile (mean of x and y). Peak: `texsynth.metrics.repetition_peak`, the "
        "rendered luminance autocorrelation's largest peak at EVERY shift of 24 px or more "
        "(a repeat at a Tile Set's cell, about half a photo tile, shows here and not at the tile), "
        "plain -> after, and in brackets the photo's own at the same distance on the surface "
        f"and the goal: at most {GOALS['corr']}, or the photo's own plus {OWN_MARGIN} where "
        "that is higher (a photo that repeats itself, a brick wall's courses, repeats so in "
        "any render of it). Anisotropy: the after render's structure-tensor "
        "anisotropy (`texsynth.metrics.anisotropy`) over the plain one's (goal "
        f"{GOALS['anisotropy'][0]}-{GOALS['anisotropy'][1]}: the photo's direction kept). "
        "W1: the worst channel's Wasserstein distance between the two renders' pixel values "
        f"(goal at most {GOALS['wasserstein']}). Both compare like with like: the plain "
        "render's pixels weighted by how much the mode shows of the photo texels each one "
        "shows (`drawn_use`: Tile Set's `texsynth.norepeat.photo_use`; Tiling and Blending "
        "and Hex Tiling show every texel alike), and in brackets, where that differs, "
        "against the whole plain render. "
        "A Tile Set's diamonds and middles are windows inside the photo, so it shows the "
        "photo's middle most and its outermost rows never: on the brick wall those are a dark "
        "ledge along the bottom and a cap along the top, which the plain render repeats every "
        "tile as stripes that make most of its direction at 4 texels a pixel (where the "
        "courses, 8 texels apart, are at 2 px); without them, the Tile Set keeps the wall's. "
        "Gradient: the after "
        "render's mean luminance gradient over the plain one's (goal 0.85-1.15). Render "
        f"seconds: median of {repeats} renders of each, plain and each mode in turn after a "
        f"warm-up render of each, plain / after (goal at most {GOALS['time']}x). "
        "`benchmarks/norepeat_renders.py` builds the scene.",
        "",
        "| photo | kind | mode | correlation at the period, plain -> after | peak at >= 24 px, "
        "plain -> after (photo; goal) | anisotropy after / plain | W1 | "
        "gradient | render s plain / after |",
        "|---|---|---|---|---|---|---|---|---|",
        *rows,
        "",
        f"![renders]({picture})",
        "",
        f"Each row: plain, {', '.join(label for _, label in MODES)} from above (a quarter of "
        f"the frame, 4 x 4 tiles), then the same {len(MODES) + 1} at a grazing angle (75 degrees "
        "from the normal, "
        f"{GRAZING_TILES} x {GRAZING_TILES} tiles on the plane, 50 mm, the frame's middle).",
        "",
        "The precomputations at the photos' full size (`texsynth.norepeat.gaussianize`: RGB "
        f"channels, 4096-entry tables; `texsynth.norepeat.wang_tiles`: {COLOURS} colours, "
        f"{COLOURS ** 4} tiles, gutter 8): seconds (one run, under tracemalloc), "
        "tracemalloc's peak and the prediction that the operator checks against the memory budget.",
        "",
        "| photo | size | precomputation | seconds | peak MiB | predicted MiB |",
        "|---|---|---|---|---|---|",
        *cost_rows,
    ])
