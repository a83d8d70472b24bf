"""Photos as they come (issue 25): every method from a 12 MP photo and from a crop of it, and
make_tileable on the large photos at their own size and at 12 MP, beside GIMP's Make Seamless
and the Resynthesizer engine filling the same band; each figure beside its goal.

The 12 MP photo is made here, reproducibly (../shared holds no camera-sized photo): the central
2048 x 1536 of the 2048 x 2048 granite setts photo, bicubically upsampled to 4000 x 3000
(``scipy.ndimage.zoom``, order 3, per channel, clipped to [0, 1]), kept in
``build/photos/setts_4000x3000.npy``. Being upsampled, it is softer at the pixel level than a
real 12 MP photo.

Every run is its own subprocess (``benchmarks.jobs``: wall time, the process's own peak resident
memory, the library's predictions made in the same process just before the run), kept in
``build/photos/<tree>/``, so an interrupted section resumes where it stopped. Resynthesizer is
run up to 2048 x 2048 (``RESYNTH``: its band at 2048 takes about 4 min of one core, 20 min
of wall time on a loaded machine) with a time limit, and its 12 MP time is extrapolated, not
measured.

About 25 minutes on a quiet 2-core machine: the methods' 12 MP and crop runs about 10-12 (the
sum of their predicted times), Resynthesizer about 6, make_tileable at every size about 5, GIMP
about 2. ``--quick`` (small crops of the same photos, Efros-Leung refused by a 5 min budget):
about 4 minutes.

Also writes the README's first picture (docs/img/readme_make_tileable.jpg) from the
make_tileable run of ``README_PHOTO``; README.md's caption under it names the photo and its
licence.
"""

from __future__ import annotations

import csv
import re
import shutil
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from texsynth import metrics
from texsynth.io import read_photo
from texsynth.tileable import default_band

from .. import jobs, peers
from ..context import REPO, SHARED_TEXTURES
from .predictions import FLOOR_MIB, FLOOR_S
from .tileable import gimp_make_seamless, resynthesizer_band, unchanged

ORDER = 37
TITLE = "Photos as they come: a 12 MP photo and large photos at their own size (issue 25)"
SEED = 0
LARGE = SHARED_TEXTURES / "large"
SETTS = "0ad-data/granite_setts_grass.png"
#: Key of the 12 MP photo; ``key@HxW`` names a photo's central H x W (see :func:`photo`).
CAMERA = "camera"
CAMERA_SHAPE = (3000, 4000)
CAMERA_SOURCE = (1536, 2048)  # the setts photo's centre that is upsampled
CAMERA_FILE = REPO / "build" / "photos" / "setts_4000x3000.npy"
BRICKS = "ufoai-textures/brick_wall.png"
ROCK = "nexuiz-textures/jagged_rock_cliff.png"
#: The README's picture: the large photo with the most visible seam at its own size (most of
#: them are game textures that nearly tile already: seam ratio 0.9-1.25).
README_PHOTO = BRICKS
#: Photos the Resynthesizer engine fills the band of (one regular, one structured, the 2048).
RESYNTH = (BRICKS, ROCK, SETTS)
RESYNTH_LIMIT = 1800.0  # seconds; a run stopped there is reported as such
#: make_tileable pictures: the 12 MP photo, the 2048, and one photo of each category.
SHEETS = (CAMERA, SETTS, BRICKS, ROCK, "torcs-data/gravel_pebbles.png")
VIEW = 512  # side of the full-resolution crops in the pictures
README_VIEW = 640
#: Goals: (low, high) for two-sided figures.
TARGET = (0.9, 1.1)
PREDICTION = (1 / 1.5, 1.5)
PEAK_MIB = 4096.0
CAMERA_OVER_CROP = 1.5
OURS_OVER_RESYNTH = 0.25  # at 2048 x 2048


@dataclass(frozen=True)
class Plan:
    camera: str  # the large input of the methods
    crop: str  # its centre crop
    side: int  # the methods' output side
    photos: tuple[str, ...]  # make_tileable's inputs
    resynth: tuple[str, ...]  # those the Resynthesizer engine fills too
    sheets: tuple[str, ...]
    env: dict  # for the children: quick mode refuses Efros-Leung as the full sizes do


def manifest() -> list[dict]:
    with (LARGE / "MANIFEST.tsv").open() as f:
        return list(csv.DictReader(f, delimiter="\t"))


def plan(quick: bool) -> Plan:
    """Every large photo at its own size and the 12 MP photo; ``quick``: small crops of two."""
    if quick:
        small = tuple(f"{p}@384x384" for p in (BRICKS, ROCK))
        return Plan(f"{CAMERA}@600x800", f"{CAMERA}@256x256", 384,
                    (*small, f"{CAMERA}@600x800"), small, (*small, f"{CAMERA}@600x800"),
                    {"TEXSYNTH_TIME_BUDGET": "300"})
    photos = tuple(row["file"] for row in manifest())
    return Plan(CAMERA, f"{CAMERA}@1024x1024", 2048, (*photos, CAMERA),
                tuple(p for p in photos if p in RESYNTH), SHEETS, {})


def camera_photo() -> np.ndarray:
    """The 12 MP photo (made once, then read from ``CAMERA_FILE``)."""
    if not CAMERA_FILE.exists():
        from scipy.ndimage import zoom

        setts = read_photo(LARGE / SETTS)[:, :, :3].astype(np.float32)
        (h, w), (sh, sw) = CAMERA_SOURCE, setts.shape[:2]
        centre = setts[(sh - h) // 2:(sh - h) // 2 + h, (sw - w) // 2:(sw - w) // 2 + w]
        factor = CAMERA_SHAPE[0] / h  # = CAMERA_SHAPE[1] / w
        image = np.stack([np.clip(zoom(centre[:, :, c], factor, order=3), 0.0, 1.0)
                          for c in range(3)], axis=2).astype(np.float32)
        assert image.shape[:2] == CAMERA_SHAPE, image.shape
        CAMERA_FILE.parent.mkdir(parents=True, exist_ok=True)
        partial = CAMERA_FILE.with_name("partial.npy")
        np.save(partial, image)
        partial.replace(CAMERA_FILE)
    return np.load(CAMERA_FILE)


def photo(key: str) -> np.ndarray:
    """The photo a key names, float32 RGB: ``camera`` (the 12 MP photo) or a file below
    ``large/``, at its own size, or with ``@HxW`` its central H x W."""
    name, _, size = key.partition("@")
    image = camera_photo() if name == CAMERA else read_photo(LARGE / name)[:, :, :3]
    if size:
        (h, w), (ih, iw) = map(int, size.split("x")), image.shape[:2]
        image = image[(ih - h) // 2:(ih - h) // 2 + h, (iw - w) // 2:(iw - w) // 2 + w]
    return np.ascontiguousarray(image, np.float32)


def label(key: str) -> str:
    name, _, size = key.partition("@")
    short = "12 MP setts" if name == CAMERA else Path(name).stem
    return f"{short} (centre {size.replace('x', ' x ')})" if size else short


def _child(kind: str, key: str, extra: list[str], out: str) -> None:
    """One run in this process: its output, wall time, peak memory and the predictions."""
    import texsynth
    from texsynth import budget

    image = photo(key)
    figures = _predicted(kind, image, extra)  # before the run, as the command line makes them
    figures["factor"] = budget.machine_factor()  # the speed and load the predictions read
    figures["base"] = jobs.reset_peak()  # interpreter, imports, photo
    if kind == "synth":
        name, side = extra[0], int(extra[1])

        def work():
            return texsynth.synthesize(image, side, side, method=name, seed=SEED)
    elif kind == "tileable":
        def work():
            return texsynth.make_tileable(image, seed=SEED)
    elif kind == "resynth":
        def work():
            return resynthesizer_band(image, default_band(image.shape))
    else:  # GIMP's Make Seamless, its start-up included
        def work():
            return gimp_make_seamless([image])[0][0]
    start = time.perf_counter()
    try:
        result = work()
    except ValueError as error:  # refused before any work by the time or memory budget
        if "budget" not in str(error):
            raise
        jobs.report(out, None, refused=str(error), **figures)
        return
    jobs.report(out, result, seconds=time.perf_counter() - start, **figures)


def job(tmp: Path, env: dict, kind: str, key: str, *extra: str,
         timeout: float | None = None) -> dict:
    print(f"   {kind} {key} {' '.join(extra)}", flush=True)
    stem = "_".join([kind, re.sub(r"[^A-Za-z0-9_-]", "-", key), *extra])
    return jobs.run(__name__, [kind, key, *extra], tmp / stem, timeout, env)


def _predicted(kind: str, image: np.ndarray, extra: tuple) -> dict:
    """The library's predictions for a run, made in the run's own process just before it, given
    the photo as the command line, batches and operators give it (``budget.forecast`` counts
    the joints a method would measure, ``tileable.predict`` checks whether it already tiles).
    Made in the benchmark process instead, they read its machine factor and page price
    (``budget.page_seconds``), not the run's: a re-run from kept records, under load, moved the
    tiled 2048 setts' predicted time from 0.2 to 0.3 s."""
    from texsynth import budget, tileable

    if kind == "tileable":
        seconds, peak = tileable.predict(image.shape, photo=image)
    elif kind == "synth":
        side = int(extra[1])
        seconds, peak = budget.forecast(extra[0], image.shape, side, side, exemplar=image)
    else:
        return {}
    return {"predicted_s": seconds, "predicted_bytes": peak}


class Goals:
    """Figures beside their goals (✓ met, ✗ not met), counted for the summary."""

    def __init__(self):
        self.counts: dict[str, list[int]] = {}

    def mark(self, name: str, value: float, low: float, high: float, digits: int = 2) -> str:
        met = low <= value <= high
        count = self.counts.setdefault(name, [0, 0])
        count[0] += met
        count[1] += 1
        return f"{value:.{digits}f} {'✓' if met else '✗'}"

    def summary(self) -> str:
        return "; ".join(f"{name} {met}/{n}" for name, (met, n) in self.counts.items())


def corner(image: np.ndarray, side: int = VIEW) -> np.ndarray:
    """A full-resolution square around the corner where four tiles meet (the image rolled by
    half the square: the wrap's two seams cross in its middle)."""
    side = min(side, *image.shape[:2])
    return np.roll(image, (side // 2, side // 2), axis=(0, 1))[:side, :side]


def _centre(image: np.ndarray, side: int = VIEW) -> np.ndarray:
    h, w = image.shape[:2]
    side = min(side, h, w)
    return image[(h - side) // 2:(h - side) // 2 + side, (w - side) // 2:(w - side) // 2 + side]


def cell(r: dict) -> str | None:
    """The time cell of a run that did not finish: refused (with the message) or failed."""
    if "refused" in r:
        return f"refused: {r['refused']}"
    if "error" in r:
        return f"failed: {r['error']}"
    return None


def predictions(r: dict, goals: Goals) -> tuple[str, str]:
    """Predicted over measured time, predicted memory over the run's growth of resident memory
    (its peak less the process's size before the call); not rated under the predictions
    section's floors both ways (``FLOOR_S``, ``FLOOR_MIB``: a photo that already tiles)."""
    grown = max(r["rss"] - r["base"], 1.0)
    t = "brief" if max(r["predicted_s"], r["seconds"]) < FLOOR_S else \
        goals.mark("predicted time", r["predicted_s"] / r["seconds"], *PREDICTION)
    m = "small" if max(r["predicted_bytes"] / 2**20, grown) < FLOOR_MIB else \
        goals.mark("predicted memory", r["predicted_bytes"] / 2**20 / grown, *PREDICTION)
    seconds = r["predicted_s"]
    return (f"{seconds:.{1 if seconds < 10 else 0}f} / {t}",
            f"{r['predicted_bytes'] / 2**20:.0f} / {m}")


def _methods(ctx, p: Plan, tmp: Path, goals: Goals) -> list[str]:
    import texsynth

    big, small = photo(p.camera), photo(p.crop)
    table = ["| method | input | time (s) | 12 MP / crop time | peak RSS (MiB) | predicted s / "
             "ratio | predicted MiB / ratio | seam | seam in phase | gradient |", "|---" * 10 + "|"]
    pictures = []
    for method in texsynth.methods():
        runs = {key: job(tmp, p.env, "synth", key, method.name, str(p.side))
                for key in (p.camera, p.crop)}
        for key, exemplar in ((p.camera, big), (p.crop, small)):
            r = runs[key]
            head = f"| {method.name} | {label(key)} |"
            if cell(r):
                predicted = (f"{r['predicted_s']:.0f} | {r['predicted_bytes'] / 2**20:.0f}"
                             if "predicted_s" in r else " |")
                table.append(f"{head} {cell(r)} | | | {predicted} | | | |")
                continue
            other = runs[p.crop]
            ratio = (goals.mark("12 MP / crop time", r["seconds"] / other["seconds"], 0,
                                CAMERA_OVER_CROP) if key == p.camera and "seconds" in other
                     else "")
            t, m = predictions(r, goals)
            phase = metrics.seam_ratio_in_phase(r["image"])
            gradient = metrics.gradient_ratio(exemplar, r["image"])
            table.append(
                f"{head} {r['seconds']:.0f} | {ratio} | "
                f"{goals.mark('peak RSS (methods)', r['rss'], 0, PEAK_MIB, 0)} | {t} | {m} | "
                f"{metrics.seam_ratio(r['image']):.2f} | "
                f"{goals.mark('seam in phase (methods)', phase, *TARGET)} | "
                f"{goals.mark('gradient (methods)', gradient, *TARGET)} |")
        if any("image" in r for r in runs.values()):
            sheet = ctx.contact_sheet(
                f"photos_{method.name}.png", ["photo", "from 12 MP", "from crop"],
                [[_centre(big)] + [corner(runs[k]["image"]) if "image" in runs[k] else None
                                   for k in (p.camera, p.crop)]], cell=VIEW)
            pictures += [f"![{method.name}: photo, output from the 12 MP photo, output from the "
                         f"crop]({sheet})", ""]
    return [
        "### Every method from the 12 MP photo and from a crop of it",
        "",
        f"Each method (defaults, seed {SEED}) from {label(p.camera)} and from {label(p.crop)} "
        f"to {p.side} x {p.side}, each run in its own process. Time: wall clock; 12 MP / crop: "
        "its time from the 12 MP photo over that from the crop (goal: at most "
        f"{CAMERA_OVER_CROP}); peak RSS: the run's process's peak resident memory (VmHWM: "
        "interpreter, imports and the photo included; goal: at most 4 GiB); predicted: "
        "`texsynth.budget.forecast` given the photo, as the panel, the command line and "
        "batches call it, in the run's own process just before the run (at the machine "
        "factor it reads then, speed times load: `budget.machine_factor()`), beside their "
        "ratio to the measured time and to the growth of resident memory over the call "
        f"(goal: within 1.5x either way; not rated under {FLOOR_S:g} s or {FLOOR_MIB:.0f} MiB "
        "both ways, as in the predictions section). Seam: seam ratio, shown; seam in phase: "
        "`metrics.seam_ratio_in_phase`, rated (the setts' joints put the plain ratio off 1 "
        "where the wrap falls on a joint or through a stone); gradient: the "
        "output's mean gradient over the photo's (metrics.gradient_ratio); both rated two-sided, "
        "goal between 0.9 and 1.1 (under it a soft wrap or a blurred output, over it a step or "
        "a noisier output). A refused run shows the library's message.",
        "",
        *table,
        "",
        *pictures,
        f"Full-resolution {VIEW} x {VIEW} crops: the 12 MP photo's centre; each method's output "
        "from the 12 MP photo and from the crop, around the corner where four tiles meet (the "
        "wrap's seams cross in the middle).",
        "",
    ]


def _quality(image: np.ndarray, out: np.ndarray, band: int) -> dict:
    return {"seam": metrics.seam_ratio(out), "phase": metrics.seam_ratio_in_phase(out),
            "sharp": metrics.band_sharpness(out, band),
            "gradient": metrics.gradient_ratio(image, out), "kept": unchanged(image, out)}


def _extrapolated(times: dict[int, float]) -> str:
    """Resynthesizer's 12 MP time from its two largest measured sizes (power law in the
    pixels), or a plain note."""
    if len(times) < 2:
        return "not run at 12 MP"
    (a, ta), (b, tb) = sorted(times.items())[-2:]
    exponent = np.log(tb / ta) / np.log(b / a)
    seconds = tb * (CAMERA_SHAPE[0] * CAMERA_SHAPE[1] / b) ** exponent
    return (f"not run at 12 MP: from its measured times it grows as pixels^{exponent:.2f}, "
            f"so about {seconds / 60:.0f} min there")


def _tileable(ctx, p: Plan, tmp: Path, goals: Goals) -> list[str]:
    has_gimp = shutil.which("gimp-console-2.10") or shutil.which("gimp-console")
    rs = next(x for x in peers.peers() if x.name == "resynthesizer")
    table = ["| photo | tool | time (s) | ours / Resynth. time | peak RSS (MiB) | predicted s / "
             "ratio | predicted MiB / ratio | seam | seam in phase | band sharpness | gradient | "
             "kept |", "|---" * 12 + "|"]
    pictures, readme, rs_times, tiling = [], [], {}, 0
    for key in p.photos:
        image = photo(key)
        h, w = image.shape[:2]
        band = default_band(image.shape)
        runs = {"ours": job(tmp, p.env, "tileable", key)}
        if has_gimp:
            runs["GIMP"] = job(tmp, p.env, "gimp", key)
        if rs.missing is None and key in p.resynth:
            # The peer's runs do not depend on texsynth's code: kept across its versions.
            peer_runs = tmp.parent / "peers"
            peer_runs.mkdir(parents=True, exist_ok=True)
            runs["Resynth."] = job(peer_runs, p.env, "resynth", key, timeout=RESYNTH_LIMIT)
        phase = metrics.seam_ratio_in_phase(image)
        tiling += TARGET[0] <= phase <= TARGET[1]
        table.append(f"| **{label(key)}**, {w} x {h}, band {band} | photo as it is | | | | | | "
                     f"{metrics.seam_ratio(image):.2f} | {phase:.2f} | | | |")
        for tool, r in runs.items():
            if cell(r):
                table.append(f"| | {tool} | {cell(r)} | | | | | | | | | |")
                continue
            q = _quality(image, r["image"], band)
            ratio = ""
            if tool == "ours" and "seconds" in runs.get("Resynth.", {}):
                x = r["seconds"] / runs["Resynth."]["seconds"]
                ratio = (goals.mark("ours / Resynth. time at 2048", x, 0, OURS_OVER_RESYNTH)
                         if h * w == 2048 ** 2 else f"{x:.2f}")
            if tool == "Resynth.":
                rs_times[h * w] = r["seconds"]
            t, m = predictions(r, goals) if tool == "ours" else ("", "")
            peak = goals.mark("peak RSS (ours)", r["rss"], 0, PEAK_MIB, 0) if tool == "ours" else (
                f"{r['rss']:.0f}" if tool == "Resynth." else "")
            table.append(
                f"| | {tool} | {r['seconds']:.1f} | {ratio} | {peak} | {t} | {m} | "
                f"{q['seam']:.2f} | "
                + " | ".join(goals.mark(f"{name} ({tool})", q[f], *TARGET)
                             for f, name in (("phase", "seam in phase"),
                                             ("sharp", "band sharpness"),
                                             ("gradient", "gradient")))
                + f" | {q['kept']:.2f} |")
        if key.partition("@")[0] == README_PHOTO and "image" in runs["ours"]:
            readme = _readme_picture(ctx, key, image, runs["ours"]["image"])
        if key in p.sheets:
            cells = [corner(image)] + [corner(runs[t]["image"]) if "image" in runs.get(t, {})
                                        else None for t in ("GIMP", "Resynth.", "ours")]
            sheet = ctx.contact_sheet(f"photos_tileable_{Path(key.partition('@')[0]).stem}.png",
                                      ["photo", "GIMP", "Resynth.", "ours"], [cells], cell=VIEW)
            pictures += [f"![{label(key)}: photo, GIMP, Resynthesizer, make_tileable around "
                         f"the wrap's corner]({sheet})", "", f"{label(key)}, {w} x {h}.", ""]
    gimp_note = ("GIMP 2.10's *Make Seamless* (plug-in-make-seamless, Debian's gimp, one "
                 "gimp-console run per photo, its start-up of a few seconds included)"
                 if has_gimp else "GIMP's *Make Seamless*: not installed here (`apt-get install "
                 "gimp` failed), so its rows are absent")
    rs_note = (f"the Resynthesizer engine filling the same band of the photo rolled by half its "
               f"size, tiling flags on, on {', '.join(label(k) for k in p.resynth)} "
               f"({_extrapolated(rs_times)}; each run limited to {RESYNTH_LIMIT / 60:.0f} min)"
               if rs.missing is None else f"the Resynthesizer engine: {rs.missing}")
    md = [
        "### make_tileable at the photo's own size",
        "",
        f"{tiling} of the {len(p.photos)} photos already tile as they are (seam ratio in phase "
        "between 0.9 and 1.1: game textures made to tile at their own size); on them "
        "make_tileable should change nothing visible.",
        "",
        "Every large photo at its own size and the 12 MP photo made to tile by "
        f"`texsynth.make_tileable` (defaults: band `default_band`, seed {SEED}), beside "
        f"{gimp_note}, and {rs_note}. Peak RSS and predictions as above (predictions: "
        "`texsynth.tileable.predict` given the photo: one that already tiles is told the "
        "check and a copy). Seam: seam ratio, shown; seam in phase: "
        "`metrics.seam_ratio_in_phase`, rated (on pavers, bricks and setts the plain ratio reads "
        "high where the wrap falls on a joint's edge and low through the blocks, though no seam "
        "shows); band sharpness: "
        "`metrics.band_sharpness(out, band)` (the middle of the band's mean gradient over the "
        "kept pixels'); gradient: the result's mean gradient over the photo's; the rated three "
        "two-sided, goal between 0.9 and 1.1: a seam ratio of 0.5 is a soft line where the tiles "
        "meet, as far off as 1.5 (a step), and a sharpness under 0.9 a blurred cross. Kept: "
        "share of pixels equal to the photo's at 8 bits. Ours / Resynth.: goal at most "
        f"{OURS_OVER_RESYNTH} at 2048 x 2048.",
        "",
        *table,
        "",
        *pictures,
        f"Full-resolution {VIEW} x {VIEW} crops around the corner where four tiles meet: the "
        "photo as it is (its seams cross in the middle), GIMP, Resynthesizer filling the band, "
        "make_tileable.",
        "",
    ]
    return md + readme


def _readme_picture(ctx, key: str, image: np.ndarray, ours: np.ndarray) -> list[str]:
    """The README's first picture: the photo tiled 2 x 2 beside its make_tileable result tiled
    2 x 2, each a full-resolution view around the corner where the four tiles meet."""
    gap = np.ones((min(README_VIEW, *image.shape[:2]), 12, 3), np.float32)
    path = ctx.save_jpeg("readme_make_tileable.png", np.concatenate(
        [corner(image, README_VIEW), gap, corner(ours, README_VIEW)], axis=1))
    row = next(r for r in manifest() if r["file"] == README_PHOTO)
    h, w = image.shape[:2]
    return [f"The README's picture: {label(key)} ({w} x {h}; {row['source_package'].split()[0]}"
            f", {row['licence'].split()[0]}), the photo and its make_tileable result, each tiled "
            f"2 x 2 and shown at full resolution around the corner where the tiles meet "
            f"({min(README_VIEW, h, w)} x {min(README_VIEW, h, w)}):", "",
            f"![readme]({path})", ""]


def run(ctx) -> str:
    if not LARGE.exists():
        return "Skipped: ../shared/textures/large is absent."
    p = plan(ctx.quick)
    tmp = jobs.cache("photos-quick" if ctx.quick else "photos")
    camera_photo()  # made once, before the children read it
    goals = Goals()
    body = _methods(ctx, p, tmp, goals) + _tileable(ctx, p, tmp, goals)
    return "\n".join([
        f"The inputs as a user brings them: the {len(p.photos) - 1} photos of "
        "`../shared/textures/large` (MANIFEST.tsv there) at their own size, and a 12 MP photo "
        f"made reproducibly by the benchmark: the central {CAMERA_SOURCE[1]} x "
        f"{CAMERA_SOURCE[0]} of the 2048 x 2048 granite setts photo (0ad-data, CC-BY-SA-3.0), "
        f"bicubically upsampled to {CAMERA_SHAPE[1]} x {CAMERA_SHAPE[0]} (scipy.ndimage.zoom, "
        "order 3, per channel, clipped to [0, 1]); being upsampled it is softer at the pixel "
        "level than a real 12 MP photo."
        + (" Quick mode: small crops instead." if ctx.quick else ""),
        "",
        f"Goals beside each figure: ✓ met, ✗ not met. Met: {goals.summary()}.",
        "",
        *body,
    ])


if __name__ == "__main__" and sys.argv[1:2] == ["RUN"]:
    _child(sys.argv[2], sys.argv[3], sys.argv[4:-1], sys.argv[-1])
