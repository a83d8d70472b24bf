"""Production sizes (issue 18): every method and Resynthesizer on large photos, 1024 -> 2048,
and 4096 for the two fast methods; time, peak resident memory, quality, full-resolution crops.

Every run is its own subprocess (``python -m benchmarks.sections.production RUN ...``, through
``benchmarks.jobs``), which reports its own peak resident memory (``VmHWM``).
Efros-Leung is per pixel: it is timed on a small output from the same exemplar and its time
at the production size is predicted (linear in the output pixels, a lower bound:
measured growth is steeper), then refused, as the time budget would.

Runs are kept in ``build/production/<tree>/`` (``benchmarks.jobs.cache``), so an interrupted
section picks up where it stopped when re-run on the same library code.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

from texsynth import metrics
from texsynth.io import read_photo

from .. import jobs
from ..context import SHARED_TEXTURES

ORDER = 35
TITLE = "Production sizes: large photos, 2048 and 4096 outputs"
SEED = 0
LARGE = SHARED_TEXTURES / "large"
#: (file below shared/textures/large, category): one regular (bricks), one stochastic, one
#: structured (rock strata and cracks).
PHOTOS = (("ufoai-textures/brick_wall.png", "regular"),
          ("torcs-data/gravel_pebbles.png", "stochastic"),
          ("ufoai-textures/layered_grey_rock.png", "structured"))
EXEMPLAR = 1024  # photos larger than this are block-averaged down to it
SIDE = 2048
BIG = 4096
BIG_METHODS = ("heeger_bergen", "multiscale_mrf")
METHODS = ("heeger_bergen", "multiscale_mrf", "texture_optimization", "de_bonet", "cooccurrence",
           "composite")
PEER = "resynthesizer"
#: Efros-Leung is timed at this output side and predicted at ``SIDE``.
PROBE = 16
CROP = 512  # contact-sheet crops, full resolution
PATCH_SAMPLES = 200  # sampled output patches for the patch distance (each searched exactly)


def load(path: Path) -> np.ndarray:
    """The photo as float32 RGB, block-averaged to at most ``EXEMPLAR`` a side."""
    image = read_photo(path)[:, :, :3].astype(np.float32)
    f = max(1, min(image.shape[:2]) // EXEMPLAR)
    if f > 1:
        h, w = image.shape[0] // f, image.shape[1] // f
        image = image[:h * f, :w * f].reshape(h, f, w, f, 3).mean(axis=(1, 3))
    return np.ascontiguousarray(image, np.float32)


def _child(photo: str, method: str, side: int, out: str) -> None:
    """One run in this process: synthesize, save the output, print the wall time as JSON."""
    import texsynth

    from ..peers import resynthesizer

    exemplar = load(LARGE / photo)
    calls = []  # times of the progress calls: Esc is seen at the next one

    def progress(fraction, message):
        calls.append(time.perf_counter())

    start = time.perf_counter()
    if method == PEER:
        image = resynthesizer(exemplar, side, side, SEED)
    else:
        image = texsynth.synthesize(exemplar, side, side, method=method, seed=SEED,
                                    progress=progress)
    seconds = time.perf_counter() - start
    gap = float(np.diff([start, *calls, start + seconds]).max()) if method != PEER else None
    jobs.report(out, image, seconds=seconds, gap=gap)


def _run(photo: str, method: str, side: int, tmp: Path) -> dict:
    """A child run: its time, peak RSS (MiB) and output, or the error (kept in ``tmp``)."""
    return jobs.run("benchmarks.sections.production", [photo, method, str(side)],
                    tmp / f"{Path(photo).stem}_{method}_{side}")


def _predict_efros_leung(photo: str, tmp: Path) -> dict:
    probe = _run(photo, "efros_leung", PROBE, tmp)
    if "error" in probe:
        return probe
    return {"predicted": probe["seconds"] * (SIDE / PROBE) ** 2, "probe": probe["seconds"]}


def _gap(run: dict) -> str:
    """The longest wait between progress reports, or blank for the peer (no progress)."""
    return "" if run.get("gap") is None else f"{run['gap']:.1f}"


def _quality(exemplar, image) -> dict:
    patches = metrics.patch_distance(exemplar, image, samples=PATCH_SAMPLES)
    return {"seam": metrics.seam_ratio(image), "phase": metrics.seam_ratio_in_phase(image),
            "gradient": metrics.gradient_ratio(exemplar, image),
            "patch": patches["median"],
            "copy": patches["copy_share"],
            "structure": metrics.structure_distance(exemplar, image)}


def _crop(image: np.ndarray) -> np.ndarray:
    """A full-resolution ``CROP`` square across the wrap-around corner (the tiling seam runs
    through its middle)."""
    half = CROP // 2
    return np.roll(image, (half, half), axis=(0, 1))[:CROP, :CROP]


def run(ctx) -> str:
    if not LARGE.exists():
        return "Skipped: ../shared/textures/large is absent."
    names = [PEER, *METHODS]
    lines = [
        f"Exemplars: {len(PHOTOS)} photos of `../shared/textures/large` (MANIFEST.tsv there), "
        f"{EXEMPLAR} x {EXEMPLAR} RGB; outputs {SIDE} x {SIDE} (and {BIG} x {BIG} for "
        f"{', '.join(BIG_METHODS)} on the first photo); seed {SEED}, default parameters, one run "
        "each, every run in its own process. Time: wall clock; ratio: to Resynthesizer's time on "
        "the same photo in this run. Peak: the run's process's peak resident memory (VmHWM, MiB, "
        "interpreter and imports included, about 100 MiB). Seam: seam ratio (the mean step "
        "across the wrap over the mean step inside), in phase: the same wrap step over the "
        "steps of the lines at the same place in the texture's rhythm "
        "(`metrics.seam_ratio_in_phase`: on bricks the plain ratio reads 1.2-2 where the wrap "
        "falls on a mortar joint's edge though no seam shows), and gradient: the output's "
        "mean gradient over the photo's; all three read two-sided, between 0.9 and 1.1 is the "
        "target: a seam ratio "
        "of 0.5 is a soft line where the tiles meet, as far off as 1.5 (a visible step), and a "
        "gradient ratio under 0.9 is a blurred output, over 1.1 a noisier one. Patch: "
        f"median nearest-exemplar-patch distance of {PATCH_SAMPLES} sampled 8 x 8 patches (lower "
        "is closer to the photo; copy: share of verbatim patches); structure: coherence-"
        "histogram distance (0..1, lower keeps the photo's edges and lines); Esc: the longest "
        "interval between two progress reports (s), the longest a cancel can wait. The natural "
        "row is "
        "the photo's two halves against each other. Efros-Leung is timed at "
        f"{PROBE} x {PROBE} and predicted at {SIDE} (linear in pixels: a lower bound), not run.",
        "",
    ]
    table = ["| photo | method | size | time (s) | ratio | peak (MiB) | Esc (s) | seam | in phase "
             "| gradient | patch | copy | structure |", "|---" * 13 + "|"]
    sheets = []
    tmp = jobs.cache("production")
    for p, (photo, category) in enumerate(PHOTOS):
        exemplar = load(LARGE / photo)
        short = Path(photo).stem
        natural = metrics.self_distance(exemplar)
        table.append(f"| {short} ({category}) | natural | {EXEMPLAR} | | | | | | | | "
                     f"{natural['patch_distance']:.2f} | {natural['copy_share']:.2f} | "
                     f"{natural['structure_distance']:.3f} |")
        runs = ([(m, BIG) for m in BIG_METHODS] if p == 0 else []) + [(m, SIDE) for m in names]
        peer_time = None
        crops = {}
        for method, side in runs:
            print(f"   {short} {method} {side}", flush=True)
            r = _run(photo, method, side, tmp)
            if "error" in r:
                table.append(f"| {short} | {method} | {side} | failed: {r['error']} | | | | | | "
                             "| | | |")
                continue
            if method == PEER:
                peer_time = r["seconds"]
            q = _quality(exemplar, r["image"])
            ratio = f"{r['seconds'] / peer_time:.2f}" if peer_time and side == SIDE else ""
            if side == BIG:
                ratio = "(4096)"
            table.append(
                f"| {short} | {method} | {side} | {r['seconds']:.0f} | {ratio} | "
                f"{r['rss']:.0f} | {_gap(r)} | {q['seam']:.2f} | {q['phase']:.2f} | "
                f"{q['gradient']:.2f} | "
                f"{q['patch']:.2f} | "
                f"{q['copy']:.2f} | {q['structure']:.3f} |")
            if side == SIDE:
                crops[method] = _crop(r["image"])
        el = _predict_efros_leung(photo, tmp)
        if "error" in el:
            table.append(f"| {short} | efros_leung | {SIDE} | failed: {el['error']} "
                         "| | | | | | | | | |")
        else:
            ratio = f"{el['predicted'] / peer_time:.0f}" if peer_time else ""
            table.append(f"| {short} | efros_leung | {SIDE} | refused: predicted "
                         f"{el['predicted']:.0f} ({el['probe']:.1f} at {PROBE}) | {ratio} "
                         "| | | | | | | | |")
        row = [exemplar[:CROP, :CROP]] + [crops.get(m) for m in names]
        sheets.append((short, ctx.contact_sheet(f"production_{short}.png",
                                                ["photo", *names], [row], cell=CROP)))
    lines += table + [""]
    for short, path in sheets:
        lines += [f"![{short}: photo crop, then {', '.join(names)}]({path})", "",
                  f"{short}: {CROP} x {CROP} crops at full resolution: the photo's top-left "
                  f"corner, then each {SIDE} x {SIDE} output around its wrap-around corner (the "
                  f"tiling seam crosses the middle), in the order {', '.join(names)}.", ""]
    return "\n".join(lines)


if __name__ == "__main__" and sys.argv[1:2] == ["RUN"]:
    _child(sys.argv[2], sys.argv[3], int(sys.argv[4]), sys.argv[5])
