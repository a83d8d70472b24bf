"""Plane slant and tilt against ground truth, as users bring photos (issues 6 and 16).

Forsyth & Ponce, Computer Vision: A Modern Approach, sec. 11.4.1, with straight-line families.
Two texture families are rendered on a plane with the bpy module (``benchmarks/plane_renders.py``:
Cycles, emission shader, random offset, rotation, slant in [0, 70), tilt, roll; orthographic,
35 mm and 50 mm): the shared texture set, and procedural man-made textures (``benchmarks/
manmade.py``: bricks, tiles, planks, a basket weave). Three conditions, as a photo arrives:

- *focal length from EXIF*: perspective views; each render is also written as a JPEG with the
  EXIF a phone writes (``FocalLength``, ``FocalLengthIn35mmFilm``, rounded to whole millimetres
  as the tag is stored) and ``texsynth.focal_px_from_file`` reads the focal length back;
- *focal length unknown*: the same perspective views, no focal length;
- *orthographic*: orthographic views, no focal length (tilt is then claimed only mod 180).

The peer is the textbook spectral second-moment estimate (``benchmarks/peers/moments.py``; tilt
mod 180 always). Errors are angles between true and estimated normals, modulo 180 deg of tilt
where the estimate does not claim the receding direction (``tilt_ambiguous_180``).
"""

from __future__ import annotations

import math
import os
import time
from collections import defaultdict
from pathlib import Path

import numpy as np
import scipy.ndimage as ndi
from PIL import Image

from benchmarks import manmade, plane_renders
from benchmarks.peers import moments
from texsynth import plane

ORDER = 70
TITLE = "Plane orientation from texture and lines (issues 6 and 16)"

CONDITIONS = ("exif", "unknown", "ortho")
LABELS = {"exif": "focal length from EXIF", "unknown": "focal length unknown (perspective)",
          "ortho": "orthographic"}
GOALS = {"exif": 3.0, "unknown": 4.0, "ortho": 6.0}
FAMILIES = ("shared textures", "man-made")
_DIAGONAL_35MM = math.hypot(36.0, 24.0)


def _angle(a, b) -> float:
    return math.degrees(math.acos(max(-1.0, min(1.0, float(np.dot(a, b))))))


def score(view, result) -> dict:
    truth = plane.normal_from_angles(view.slant, view.tilt)
    normal = np.asarray(result.normal)
    flipped = plane.normal_from_angles(result.slant, result.tilt + 180.0)
    claims = not result.tilt_ambiguous_180
    error = _angle(truth, normal) if claims else min(_angle(truth, normal),
                                                     _angle(truth, flipped))
    focal_error = None
    if result.focal_estimated and view.focal_px:
        focal_error = result.focal_px / view.focal_px - 1.0
    return {"error": error, "claims": claims,
            "receding_right": claims and _angle(truth, normal) <= _angle(truth, flipped),
            "focal_error": focal_error, "confidence": result.confidence,
            "uncertainty": result.normal_uncertainty, "families": result.line_families}


def exif_jpeg(view, photo) -> Path:
    """The render as a phone would store it: JPEG with FocalLength and its 35 mm equivalent."""
    path = plane_renders.CACHE / f"{view.key()}_exif.jpg"
    if not path.exists():
        h, w = photo.shape[:2]
        sensor_diagonal = math.hypot(plane_renders.SENSOR_MM, plane_renders.SENSOR_MM * h / w)
        exif = Image.Exif()
        ifd = exif.get_ifd(0x8769)
        ifd[0x920A] = float(view.lens_mm)  # FocalLength (mm)
        ifd[0xA405] = round(view.lens_mm * _DIAGONAL_35MM / sensor_diagonal)  # 35 mm equivalent
        pixels = (np.clip(photo, 0, 1) * 255 + 0.5).astype(np.uint8)
        Image.fromarray(pixels).save(path, quality=92, exif=exif)
    return path


def _stats(errors) -> str:
    e = np.asarray(errors, dtype=np.float64)
    if len(e) == 0:
        return "| 0 | | | | |"
    return (f"| {len(e)} | {np.median(e):.1f} | {np.percentile(e, 90):.1f} | "
            f"{np.mean(e <= 5) * 100:.0f} % | {np.mean(e <= 8) * 100:.0f} % |")


def _views(ctx):
    """(family, view, photo) for both texture families."""
    shared = {t.name: t.image for t in ctx.textures}
    made = manmade.textures()
    kinds = {name: kind for name, (_, kind) in made.items()}
    views_a = plane_renders.make_views(list(shared), 2)
    views_b = plane_renders.make_views(list(made), 3 if ctx.quick else 6, seed=16)
    photos = plane_renders.render_views(views_a + views_b,
                                        {**shared, **{n: t for n, (t, _) in made.items()}})
    family = [FAMILIES[0]] * len(views_a) + [FAMILIES[1]] * len(views_b)
    return list(zip(family, views_a + views_b, photos, strict=True)), kinds


def run(ctx) -> str:
    start = time.perf_counter()
    items, kinds = _views(ctx)
    render_s = time.perf_counter() - start
    scores = defaultdict(list)  # (family, condition, "texsynth" | "baseline") -> [(view, score)]
    seconds = []
    exif_focal = []
    for family, view, photo in items:
        base = score(view, moments.estimate(photo))
        if view.focal_px is None:
            calls = {"ortho": None}
        else:
            focal = plane.focal_px_from_file(exif_jpeg(view, photo))
            exif_focal.append(focal / view.focal_px - 1.0)
            calls = {"exif": focal, "unknown": None}
        for condition, focal in calls.items():
            tic = time.perf_counter()
            result = plane.estimate_plane(photo, focal_px=focal)
            seconds.append(time.perf_counter() - tic)
            scores[family, condition, "texsynth"].append((view, score(view, result)))
            scores[family, condition, "baseline"].append((view, base))

    def errors(family, condition, who, keep=lambda v: v.slant >= 20):
        return [s["error"] for v, s in scores[family, condition, who] if keep(v)]

    lines = [
        f"{len(items)} views: {sum(f == FAMILIES[0] for f, _, _ in items)} of the shared "
        f"textures, {sum(f == FAMILIES[1] for f, _, _ in items)} of {len(kinds)} man-made ones "
        f"({', '.join(sorted(set(kinds.values())))}); {plane_renders.WIDTH} x "
        f"{plane_renders.HEIGHT} px, Cycles {plane_renders.SAMPLES} samples (rendered or read from "
        f"`benchmarks/.cache/plane_renders` in {render_s:.0f} s). Focal length read back from the "
        f"EXIF JPEGs: error {np.median(np.abs(exif_focal)) * 100:.1f} % median, "
        f"{np.max(np.abs(exif_focal)) * 100:.1f} % at most (the 35 mm equivalent is stored in "
        f"whole millimetres). Mean time per estimate {np.mean(seconds):.2f} s.",
        "",
        "**Normal error at slant >= 20 deg** (degrees; goals: EXIF <= 3, unknown <= 4, "
        "orthographic <= 6, on both families):",
        "",
        "| family | condition | estimate | views | median | p90 | within 5 deg | within 8 deg |",
        "|---|---|---|---:|---:|---:|---:|---:|",
    ]
    for family in FAMILIES:
        for condition in CONDITIONS:
            for who in ("texsynth", "baseline"):
                label = "texsynth" if who == "texsynth" else "textbook moments (peer)"
                lines.append(f"| {family} | {LABELS[condition]} | {label} "
                             f"{_stats(errors(family, condition, who))}")

    lines += ["", "**Receding direction** on perspective views at slant >= 30 deg (goal >= 95 %"
              " right; a declined direction counts as not right):", ""]
    for family in FAMILIES:
        for condition in ("exif", "unknown"):
            got = [s for v, s in scores[family, condition, "texsynth"] if v.slant >= 30]
            if got:
                right = np.mean([s["receding_right"] for s in got]) * 100
                declined = np.mean([not s["claims"] for s in got]) * 100
                lines.append(f"- {family}, {LABELS[condition]}: {right:.0f} % right, "
                             f"{declined:.0f} % declined ({len(got)} views).")
    wrong = sum(s["claims"] for f in FAMILIES for _, s in scores[f, "ortho", "texsynth"])
    lines.append(f"- Orthographic views where a receding direction was (wrongly) claimed: {wrong}.")

    lines += ["", "**Focal length estimated** (focal length unknown, perspective views; goal: "
              "within 10 % on >= 70 % of views at slant >= 40 deg):", ""]
    for family in FAMILIES:
        for lo in (20, 40):
            got = [s for v, s in scores[family, "unknown", "texsynth"] if v.slant >= lo]
            est = np.abs([s["focal_error"] for s in got if s["focal_error"] is not None])
            if got:
                within = np.sum(est <= 0.1)
                lines.append(f"- {family}, slant >= {lo}: within 10 % on {within} of {len(got)} "
                             f"views ({within / len(got) * 100:.0f} %); estimated on {len(est)}"
                             + (f", median error {np.median(est) * 100:.0f} %" if len(est) else "")
                             + " (the others were judged orthographic).")

    lines += ["", "**By kind** (texsynth, median normal error at slant >= 20; views in brackets):",
              "", "| kind | " + " | ".join(LABELS[c] for c in CONDITIONS) + " | line families "
              "used (median) |", "|---|" + "---:|" * (len(CONDITIONS) + 1)]
    groups = {**{k: (FAMILIES[1], lambda v, k=k: kinds.get(v.texture) == k)
                 for k in sorted(set(kinds.values()))},
              "shared textures": (FAMILIES[0], lambda v: True)}
    for name, (family, member) in groups.items():
        cells, used = [], []
        for condition in CONDITIONS:
            got = [s for v, s in scores[family, condition, "texsynth"]
                   if member(v) and v.slant >= 20]
            used += [s["families"] for s in got]
            cells.append(f"{np.median([s['error'] for s in got]):.1f} ({len(got)})" if got
                         else "")
        lines.append(f"| {name} | " + " | ".join(cells) + f" | {np.median(used):.0f} |")

    lines += ["", "**Confidence** (texsynth, all conditions and views pooled): does it flag the "
              "bad estimates?", "", "| confidence | views | median error | p90 error | "
              "stated normal sigma |", "|---|---:|---:|---:|---:|"]
    pooled = [s for (_, _, who), got in scores.items() if who == "texsynth" for _, s in got]
    for lo, hi in ((0.0, 0.25), (0.25, 0.5), (0.5, 0.75), (0.75, 1.01)):
        got = [s for s in pooled if lo <= s["confidence"] < hi]
        if got:
            e = np.asarray([s["error"] for s in got])
            lines.append(f"| {lo:.2f}-{min(hi, 1.0):.2f} | {len(got)} | {np.median(e):.1f} | "
                         f"{np.percentile(e, 90):.1f} | "
                         f"{np.median([s['uncertainty'] for s in got]):.1f} |")
    sure = [s for s in pooled if s["confidence"] >= 0.9]
    given = [s for (_, c, who), got in scores.items() if who == "texsynth" and c == "exif"
             for v, s in got if v.slant >= 20 and s["confidence"] >= 0.9]
    lines += ["", f"**Confidently wrong** (goal: at most 5 % of the estimates at confidence >= "
              f"0.9 off by more than 10 deg): {sum(s['error'] > 10 for s in sure)} of "
              f"{len(sure)} pooled; {sum(s['error'] > 10 for s in given)} of {len(given)} with "
              "the focal length from EXIF at slant >= 20."]
    lines += ["", _rectangle(items), "", _own_anisotropy(ctx, scores), "", _no_cue(), "",
              _speed(items)]
    return "\n".join(lines)


def _square_corners(view, scale: int, rounded: bool):
    """Image corners (x right, y down) of the largest square on the view's plane, centred on its
    origin and turned 20 deg, that the image holds (half-side 0.45 down to 0.15 of the shorter
    image side, in plane units), for the view rendered ``scale`` times larger and (``rounded``)
    rounded to whole pixels there as a click places them; None when none fits."""
    turn = np.radians(20.0 + 90.0 * np.arange(4))
    w, h = view.width * scale, view.height * scale
    for share in (0.45, 0.35, 0.25, 0.15):
        half = share * min(w, h)
        x, y = plane.plane_to_image(half * np.stack([np.cos(turn), np.sin(turn)], axis=1),
                                    view.slant, view.tilt, view.focal_px * scale).T
        corners = np.stack([x + (w - 1) / 2, (h - 1) / 2 - y], axis=1)
        if np.isfinite(corners).all() and (corners >= 0).all() \
                and (corners <= [w - 1, h - 1]).all():
            return np.round(corners) if rounded else corners
    return None


def _rectangle(items) -> str:
    """The user's rectangle (issue 42): the largest square on each perspective view's plane
    (:func:`_square_corners`), its projected corners rounded to whole pixels, read by
    ``plane.from_rectangle`` with the focal length given and unknown, at the views' size and at
    the phone set's (5 times larger)."""
    out = []
    for scale, rounded in ((1, False), (1, True), (5, True)):
        given, unknown, focal, refused, views = [], [], [], 0, 0
        for _, view, _ in items:
            corners = None if view.focal_px is None else _square_corners(view, scale, rounded)
            if corners is None:
                continue
            views += 1
            truth = plane.normal_from_angles(view.slant, view.tilt)
            shape, f = (view.height * scale, view.width * scale), view.focal_px * scale
            given.append(_angle(truth, np.asarray(plane.from_rectangle(corners, shape, f).normal)))
            try:
                r = plane.from_rectangle(corners, shape)
            except ValueError:
                refused += 1
                continue
            unknown.append(_angle(truth, np.asarray(r.normal)))
            focal.append(abs(r.focal_px / f - 1.0) * 100)
        focal = np.array(focal)
        out.append(f"| {view.width * scale} x {view.height * scale}"
                   f"{'' if rounded else ', corners as projected'} | {views} | "
                   f"{np.median(given):.2f} | {np.max(given):.2f} | {np.median(unknown):.2f} | "
                   f"{np.max(unknown):.2f} | {np.median(focal):.1f} % | "
                   f"{np.mean(focal <= 5) * 100:.0f} % | {refused} |")
    return "\n".join(["**The rectangle** (issue 42; goals: normal within 2 deg with the focal "
                      "length given, focal length within 5 % when not): the largest square on "
                      "the plane of each perspective view, its projected corners as they are "
                      "and rounded to whole pixels as a click places them; refused: a pair of "
                      "sides parallel in the image (no vanishing point), the focal length not "
                      "given.", "",
                      "| image | views | normal error, focal given: median | max | focal "
                      "unknown: median | max | focal length error, median | within 5 % | "
                      "refused |", "|---|---:|---:|---:|---:|---:|---:|---:|---:|", *out])


def _own_anisotropy(ctx, scores) -> str:
    """The shared textures' own anisotropy: the isotropy slant read on each texture's own photo,
    seen frontally. Under orthography only isotropy gives the slant, so this bounds that figure."""
    frontal = {t.name: plane.estimate_plane(t.image, method="isotropy").slant
               for t in ctx.textures}
    got = [(frontal[v.texture], s["error"]) for v, s in scores[FAMILIES[0], "ortho", "texsynth"]
           if v.slant >= 20 and v.texture in frontal]
    if not got:
        return ""
    reads = np.asarray(list(frontal.values()))
    low = [e for f, e in got if f < 20]
    high = [e for f, e in got if f >= 20]
    return (f"**Own anisotropy** (the isotropy slant read on each of the {len(reads)} shared "
            f"textures' own photo, frontal): {np.median(reads):.1f} deg median, "
            f"{np.percentile(reads, 90):.1f} p90; {np.mean(reads >= 20) * 100:.0f} % read 20 deg "
            f"or more. Orthographic views at slant >= 20: median error "
            + (f"{np.median(low):.1f} ({len(low)} views)" if low else "- (0 views)")
            + " where the texture reads under 20 deg, "
            + (f"{np.median(high):.1f} ({len(high)} views)" if high else "- (0 views)")
            + " where it reads more.")


def _no_cue() -> str:
    """White noise has no plane cue: any slant explains it."""
    rng = np.random.default_rng(5)
    results = [plane.estimate_plane(rng.random((plane_renders.HEIGHT, plane_renders.WIDTH)))
               for _ in range(6)]
    conf = [r.confidence for r in results]
    slant = [r.slant for r in results]
    return (f"**No plane cue** (6 white-noise images, {plane_renders.WIDTH} x "
            f"{plane_renders.HEIGHT}): confidence {np.median(conf):.2f} median, {max(conf):.2f} "
            f"at most; stated slant {np.median(slant):.0f} deg median, normal sigma "
            f"{np.median([r.normal_uncertainty for r in results]):.0f} deg median.")


def _speed(items) -> str:
    """Seconds per estimate on a 12-megapixel photo (4000 x 3000, a render enlarged)."""
    family, view, photo = next(x for x in items if x[0] == FAMILIES[1] and x[1].slant > 30)
    big = np.stack([ndi.zoom(photo[:, :, c], (3000 / photo.shape[0], 4000 / photo.shape[1]),
                             order=1) for c in range(3)], axis=2).astype(np.float32)
    wall, cpu = [], []
    for _ in range(3):
        tic, tic_cpu = time.perf_counter(), time.process_time()
        plane.estimate_plane(big)
        wall.append(time.perf_counter() - tic)
        cpu.append(time.process_time() - tic_cpu)
    return (f"**Speed** (focal length unknown, a {big.shape[1]} x {big.shape[0]} float32 photo: "
            f"12 MP, 3 runs; goal < 2 s on 2 cores): {np.median(cpu):.2f} s of CPU time median, "
            f"{np.median(wall):.2f} s wall-clock on this shared machine (load average "
            f"{os.getloadavg()[0]:.1f}).")
