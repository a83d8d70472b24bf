"""make_tileable on regular photos (issue 25, the part left open): the crossing of the band's
arms on the brick wall, the concrete pavers, the granite setts and the 12 MP photo, and what
the seam ratio measures when a photo's rhythm puts a joint on the wrap.

Runs make_tileable on every large photo at its own size and on the 12 MP photo, each in its own
process, through the photos section's runs (``photos.job``: the same child, the same cache,
wall time, peak resident memory and predictions made the same way). Beside the plain
``metrics.seam_ratio`` it reports ``metrics.seam_ratio_in_phase``, and it shows what each reads
on the photos' own interior lines: each photo rolled so that a random interior row and column
are the wrap (``CROSSES`` of them), which a good result should read like. About 2 minutes on a
quiet 2-core machine (12 MP: about 10 s); ``--quick``: the central 384 x 384 of two photos.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from texsynth import make_tileable, metrics
from texsynth.tileable import default_band

from .. import jobs
from . import photos

ORDER = 38
TITLE = "make_tileable on regular photos: the crossing, and the seam ratio in phase (issue 25)"
#: Random interior crosses per photo for the measures' own spread.
CROSSES = 30
#: Photos whose crossing is shown at full resolution.
SHEETS = (photos.BRICKS, "nexuiz-textures/concrete_pavers.png", photos.SETTS, photos.CAMERA)
#: Photos whose crossing is also shown for other seeds (run here, in this process): stones
#: about as large as the band, where one seed's crossing says little about the next one's.
SEEDED, SEEDS = (photos.SETTS, photos.CAMERA), (1, 2)


def _keys(quick: bool) -> tuple[str, ...]:
    if quick:
        return tuple(f"{p}@384x384" for p in (photos.BRICKS, "nexuiz-textures/concrete_pavers.png"))
    return (*(row["file"] for row in photos.manifest()), photos.CAMERA)


def _spread(image: np.ndarray, rng) -> tuple[float, float, float, float]:
    """5 and 95 % of the plain and the in-phase seam ratio over ``CROSSES`` random interior
    crosses of ``image`` (rolled so that they are the wrap)."""
    h, w = image.shape[:2]
    plain, phase = [], []
    for _ in range(CROSSES):
        rolled = np.roll(image, (int(rng.integers(h)), int(rng.integers(w))), axis=(0, 1))
        plain.append(metrics.seam_ratio(rolled))
        phase.append(metrics.seam_ratio_in_phase(rolled))
    return (*np.percentile(plain, [5, 95]), *np.percentile(phase, [5, 95]))


def run(ctx) -> str:
    if not photos.LARGE.exists():
        return "Skipped: ../shared/textures/large is absent."
    tmp = jobs.cache("photos-quick" if ctx.quick else "photos")
    photos.camera_photo()
    goals = photos.Goals()
    rng = np.random.default_rng(0)
    target = photos.TARGET
    table = ["| photo | band | time (s) | predicted s / ratio | peak RSS (MiB) | predicted MiB / "
             "ratio | photo: seam / in phase | its own lines: seam / in phase (5-95 %) | seam | "
             "seam in phase | band sharpness | gradient | kept |", "|---" * 13 + "|"]
    pictures = []
    for key in _keys(ctx.quick):
        image = photos.photo(key)
        h, w = image.shape[:2]
        band = default_band(image.shape)
        r = photos.job(tmp, {}, "tileable", key)
        own = (f"{metrics.seam_ratio(image):.2f} / {metrics.seam_ratio_in_phase(image):.2f}")
        spread = ("" if key.partition("@")[0] == photos.CAMERA else
                  "{:.2f}-{:.2f} / {:.2f}-{:.2f}".format(*_spread(image, rng)))
        head = f"| **{photos.label(key)}**, {w} x {h} | {band} |"
        if photos.cell(r):
            table.append(f"{head} {photos.cell(r)} | | | | {own} | {spread} | | | | | |")
            continue
        out = r["image"]
        t, m = photos.predictions(r, goals)
        table.append(
            f"{head} {r['seconds']:.1f} | {t} | "
            f"{goals.mark('peak RSS', r['rss'], 0, photos.PEAK_MIB, 0)} | {m} | {own} | "
            f"{spread} | {metrics.seam_ratio(out):.2f} | "
            f"{goals.mark('seam in phase', metrics.seam_ratio_in_phase(out), *target)} | "
            f"{goals.mark('band sharpness', metrics.band_sharpness(out, band), *target)} | "
            f"{goals.mark('gradient', metrics.gradient_ratio(image, out), *target)} | "
            f"{photos.unchanged(image, out):.2f} |")
        if key.partition("@")[0] in SHEETS:
            stem = Path(key.partition("@")[0]).stem
            sheet = ctx.contact_sheet(f"regular_{stem}.png", ["photo", "make_tileable"],
                                      [[photos.corner(image), photos.corner(out)]],
                                      cell=photos.VIEW)
            pictures += [f"![{photos.label(key)}: the photo and make_tileable around the wrap's "
                         f"corner]({sheet})", ""]
        if key.partition("@")[0] in SEEDED and not ctx.quick:
            stem = Path(key.partition("@")[0]).stem
            crops = [photos.corner(out)] + [photos.corner(make_tileable(image, seed=s))
                                             for s in SEEDS]
            sheet = ctx.contact_sheet(f"regular_{stem}_seeds.png",
                                      [f"seed {s}" for s in (photos.SEED, *SEEDS)], [crops],
                                      cell=photos.VIEW)
            pictures += [f"![{photos.label(key)}: make_tileable around the wrap's corner, seeds "
                         f"{photos.SEED}, {', '.join(map(str, SEEDS))}]({sheet})", ""]
    return "\n".join([
        "make_tileable (defaults, seed 0) on every large photo at its own size and on the 12 MP "
        "photo (see the photos section), each run in its own process: time, peak RSS and "
        "predictions as there. Seam: `metrics.seam_ratio`, shown, not rated (on bricks and "
        "setts it reads far from 1 across the photo's own lines: the column before); seam in "
        "phase: "
        "`metrics.seam_ratio_in_phase`, the jump across the wrap over the jumps across the "
        "photo's own lines at the same place in its rhythm (a joint on the wrap against joints, "
        "a wrap through bricks against lines through bricks; rows and columns each on their "
        "own). Its own lines: both measures on the photo rolled so that a random interior row "
        f"and column are the wrap ({CROSSES} such crosses, 5-95 %): what a result whose wrap "
        "is as good as the photo's own lines reads. The rated ones two-sided, goal 0.9-1.1.",
        "",
        f"Goals: ✓ met, ✗ not met. Met: {goals.summary()}.",
        "",
        *table,
        "",
        *pictures,
        f"Full-resolution {photos.VIEW} x {photos.VIEW} crops around the corner where four "
        "tiles meet (the wrap's two seams cross in the middle): the photo as it is, and "
        "make_tileable's result; for the setts and the 12 MP photo also the seeds "
        f"{', '.join(map(str, SEEDS))}: whether the crossing holds together (stones whole, "
        "joints continuous) changes from seed to seed, so a change to the crossing is judged "
        "on all three.",
        "",
    ])
