"""A phone photo to a material, on the command line (issue 43): `texsynth material` against
`texsynth tile` on the same 12 MP JPEG, each step's share, the maps' size and wrap.

The photo is :mod:`benchmarks.phone_photo`'s (granite setts seen at 30 degrees through a
26 mm-equivalent lens, a window's ramp and vignetting, JPEG with its EXIF focal length). Each
command runs in its own process under ``/usr/bin/time`` (wall and CPU seconds, peak resident
memory), tile, material, tile again, so that both see the same load on a shared machine; the
CPU time (user + system, every thread) is the fairer ratio there, the wall time what a user
waits. The steps' shares: the pipeline run once more in this process, each progress report
timed and given to the step whose span holds it (the spans are the steps' predicted times).
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from texsynth import metrics
from texsynth.io import read_photo
from texsynth.material import pipeline
from texsynth.plane import focal_px_from_file

from ..context import REPO
from ..phone_photo import phone_photo

ORDER = 59
TITLE = "Photo to material: a 12 MP phone JPEG to a 1024 material (issue 43)"
SIZE = 1024
GOAL_RATIO = 3.0  # material over tile, the same photo
SEAM = (0.8, 1.25)
PREDICTION = (1 / 1.5, 1.5)  # the told time and peak over the measured
#: The map rolled by this many pixels at a time along its diagonal: each roll puts two of its
#: own interior lines at the wrap, whose seam ratios say what a line with no seam reads there.
ROLL_STEP = 16


def interior_lines(image: np.ndarray) -> tuple[float, float]:
    """The 5th and 95th percentiles of the seam ratio of ``image``'s own interior lines (the
    image rolled by every ``ROLL_STEP`` pixels on both axes): the spread a seamless wrap's
    reading has on this image (on the setts' 1024 Color map at seed 0: about 0.86-1.28)."""
    ratios = [metrics.seam_ratio(np.roll(image, (k, k), axis=(0, 1)))
              for k in range(ROLL_STEP, min(image.shape[:2]), ROLL_STEP)]
    return float(np.percentile(ratios, 5)), float(np.percentile(ratios, 95))


def _told(line: str) -> tuple[float, float]:
    """(seconds, MiB) of the command's 'about 30 s, 1.1 GiB' (``budget.forecast_line``).

    >>> _told("30 s, 1.1 GiB"), _told("2 min, 873 MiB")
    ((30.0, 1126.4), (120.0, 873.0))
    """
    duration, memory = (part.split() for part in line.split(", "))
    seconds = float(duration[0]) * {"s": 1, "min": 60, "h": 3600, "days": 86400}[duration[1]]
    return seconds, float(memory[0]) * (1024 if memory[1] == "GiB" else 1)


def _timed(args: list[str]) -> dict:
    """Wall, CPU seconds and peak MiB of ``python -m texsynth ARGS`` (its stderr kept)."""
    with tempfile.NamedTemporaryFile("r", suffix=".txt") as out:
        proc = subprocess.run(["/usr/bin/time", "-o", out.name, "-f", "%e %U %S %M",
                               sys.executable, "-m", "texsynth", *args], cwd=REPO,
                              capture_output=True, text=True, check=False)
        if proc.returncode:
            raise RuntimeError(proc.stderr.strip().splitlines()[-1])
        wall, user, system, kib = Path(out.name).read_text().split()[-4:]
    return {"wall": float(wall), "cpu": float(user) + float(system), "mib": int(kib) / 1024,
            "stderr": proc.stderr}


def _steps(photo: np.ndarray, focal: float, side: int):
    """The material of one in-process run, and (wall, CPU) seconds per step from its timed
    progress reports (CPU: this process's, every thread)."""
    costs = pipeline.step_costs(photo.shape, (side, side), pipeline.STEPS, None, False,
                                 photo=photo)
    ends = np.cumsum([s for s, _ in costs.values()]) / sum(s for s, _ in costs.values())
    reports = []
    start = (time.perf_counter(), time.process_time())
    made = pipeline.photo_to_material(
        photo, size=(side, side), focal_px=focal,
        progress=lambda f, m: reports.append((time.perf_counter(), time.process_time(), f)))
    taken = {step: [0.0, 0.0] for step in costs}
    last = start
    for wall, cpu, fraction in reports:  # the time up to a report is the step's it is in
        step = list(costs)[min(int(np.searchsorted(ends, fraction - 1e-9)), len(costs) - 1)]
        taken[step][0] += wall - last[0]
        taken[step][1] += cpu - last[1]
        last = (wall, cpu)
    return made, taken


def run(ctx) -> str:
    path = phone_photo()
    photo = read_photo(path)
    focal = focal_px_from_file(path)
    h, w = photo.shape[:2]
    side = 512 if ctx.quick else SIZE
    with tempfile.TemporaryDirectory() as tmp:
        tile1 = _timed(["tile", str(path), "-o", f"{tmp}/tile.png"])
        made = _timed(["material", str(path), "-o", f"{tmp}/mat", "--size", str(side)])
        tile2 = _timed(["tile", str(path), "-o", f"{tmp}/tile2.png"])
    predicted = made["stderr"].split("predicted: about ")[1].split(" peak")[0]
    steps_told = [line for line in made["stderr"].splitlines()
                  if line.split(":")[0] in pipeline.STEPS]
    tile = {k: (tile1[k] + tile2[k]) / 2 for k in ("wall", "cpu")}
    ratio_wall, ratio_cpu = made["wall"] / tile["wall"], made["cpu"] / tile["cpu"]

    def mark(value, ok):
        return f"{value:.2f} {'✓' if ok else '✗'}"

    def within(ratio):
        return PREDICTION[0] <= ratio <= PREDICTION[1]

    told_s, told_mib = _told(predicted)
    told = (f"{predicted} ({mark(told_s / made['wall'], within(told_s / made['wall']))}, "
            f"{mark(told_mib / made['mib'], within(told_mib / made['mib']))})")

    lines = [
        f"The photo: {w} x {h} JPEG made by `benchmarks/phone_photo.py` (granite setts, "
        "0ad-data, CC-BY-SA-3.0, seen at 30 deg through a 26 mm-equivalent lens under a "
        "window's ramp and vignetting; EXIF focal length). Each command in its own process "
        "(`/usr/bin/time`: wall, CPU = user + system of every thread, peak resident memory), "
        "tile, material, tile again on a shared machine; the goal is the material in at most "
        f"{GOAL_RATIO:g}x the time of `texsynth tile` on the same photo.",
        "",
        "| command | wall s | CPU s | peak MiB | predicted (over wall, over peak) |",
        "|---|---:|---:|---:|---|",
        f"| `texsynth tile PHOTO` (two runs) | {tile1['wall']:.0f}, {tile2['wall']:.0f} | "
        f"{tile1['cpu']:.0f}, {tile2['cpu']:.0f} | {max(tile1['mib'], tile2['mib']):.0f} | |",
        f"| `texsynth material PHOTO --size {side}` | {made['wall']:.0f} | {made['cpu']:.0f} | "
        f"{made['mib']:.0f} | {told} |",
        "",
        f"Material over tile: wall {mark(ratio_wall, ratio_wall <= GOAL_RATIO)}, CPU "
        f"{mark(ratio_cpu, ratio_cpu <= GOAL_RATIO)} (goal: at most {GOAL_RATIO:g}).",
        "",
        "What each step said: " + "; ".join(f"`{line}`" for line in steps_told) + ".",
        "",
        f"Every map {side} x {side} and tiling, from one more run of the pipeline in this "
        "process (the same seed: the same maps as the command's, before their 8-bit "
        f"quantization, which makes a smooth map's seam ratio meaningless; luminance; goal "
        f"{SEAM[0]}-{SEAM[1]}); beside it, what the map's own interior lines read by the same "
        f"measure (the map rolled by every {ROLL_STEP} px on both axes, 5th-95th percentile: a "
        "seamless wrap reads within it, a seam above it) and the seam ratio in phase "
        "(`metrics.seam_ratio_in_phase`: the wrap against the lines at the same place in the "
        "setts' rhythm); and each step's time in that run (its progress reports timed, each "
        "given to the step whose span holds it):",
        "",
        "| map | size | seam ratio | interior lines 5-95% | in phase |",
        "|---|---|---:|---:|---:|",
    ]
    material, taken = _steps(photo, focal, side)
    images = {"Color": material.colour, "NormalGL": material.maps.normal * 0.5 + 0.5,
              "Displacement": material.maps.height, "Roughness": material.maps.roughness,
              "AmbientOcclusion": material.maps.ao}
    for suffix, image in images.items():
        seam = metrics.seam_ratio(image)
        low, high = interior_lines(image)
        lines.append(f"| {suffix} | {image.shape[1]} x {image.shape[0]} | "
                     f"{mark(seam, SEAM[0] <= seam <= SEAM[1])} | {low:.2f}-{high:.2f} | "
                     f"{metrics.seam_ratio_in_phase(image):.2f} |")
    total = sum(cpu for _, cpu in taken.values())
    lines += ["", "| step | wall s | CPU s | CPU share |", "|---|---:|---:|---:|"]
    lines += [f"| {step} | {wall:.1f} | {cpu:.1f} | {cpu / total:.0%} |"
              for step, (wall, cpu) in taken.items()]
    return "\n".join(lines)
