"""Render time of ``texsynth.break_repetition``'s node groups against the plain image, per
photo of the "No repetition" section, without its other figures (cheaper than the section).

    .venv/bin/python -m benchmarks.norepeat_cost [--size 512] [--repeats 3] [--mode MODE]
        [--set rotation=0] [--out folder] [--photos rel ...]

The section's scene (benchmarks/norepeat_renders.py, from above, 8 x 8 tiles, 16 samples, 1
thread); plain and after rendered in turn after a warm-up render of each. Prints the
warm-up renders' measures (correlation at the period, W1, gradient ratio: renders.measures),
the medians of the wall-clock seconds and of the process's CPU seconds (less swayed by a loaded
machine), their ratios after / plain and the load average.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

from benchmarks import norepeat_renders as renders
from benchmarks.sections import norepeat
from texsynth.io import write_png


def _times(photo, size, repeats, mode, props):
    import bpy

    tree = renders.scene(photo, norepeat.TILES, size, norepeat.SAMPLES)
    plain = tree.nodes.active
    bpy.ops.texsynth.break_repetition(mode=mode, **props)
    after = tree.nodes.active
    base = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeBsdfPrincipled") \
        .inputs["Base Color"]
    wall, cpu, shots = {"plain": [], "after": []}, {"plain": [], "after": []}, {}
    for r in range(repeats + 1):
        for name, node in (("plain", plain), ("after", after)):
            tree.links.new(node.outputs["Color"], base)
            if not r:  # the warm-up renders give the pictures
                shots[name] = renders.render()[0]
                continue
            start, start_cpu = time.perf_counter(), time.process_time()
            bpy.ops.render.render()
            wall[name].append(time.perf_counter() - start)
            cpu[name].append(time.process_time() - start_cpu)
    return ({k: statistics.median(v) for k, v in wall.items()},
            {k: statistics.median(v) for k, v in cpu.items()}, shots)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=norepeat.SIZE)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--mode", default="TILING_AND_BLENDING")
    parser.add_argument("--out", help="a folder for the renders (PNG)")
    parser.add_argument("--set", nargs="*", default=[], metavar="NAME=VALUE",
                        help="other operator settings, e.g. rotation=0")
    parser.add_argument("--photos", nargs="*", default=[rel for rel, _ in norepeat.PHOTOS])
    args = parser.parse_args(argv)
    renders.extension()
    for rel in args.photos:
        photo = norepeat.box_average(norepeat.read_large(rel), norepeat.SIDE)
        load = os.getloadavg()[0]
        props = {k: float(v) for k, v in (x.split("=") for x in args.set)}
        wall, cpu, shots = _times(photo, args.size, args.repeats, args.mode, props)
        m = renders.measures(shots["plain"], shots["after"], args.size // norepeat.TILES)
        if args.out:
            stem = rel.rsplit("/", 1)[-1].rsplit(".", 1)[0]
            for name, image in shots.items():
                write_png(f"{args.out}/{stem}_{args.mode.lower()}{''.join(args.set)}_{name}.png",
                          image)
        print(f"| {rel} | {args.mode} {' '.join(args.set)} | {m['corr_plain']:.2f} -> "
              f"{m['corr_after']:.2f} | "
              f"{m['wasserstein']:.4f} | {m['gradient_ratio']:.2f} | "
              f"{wall['plain']:.2f} / {wall['after']:.2f} "
              f"({wall['after'] / wall['plain']:.2f}x) | {cpu['plain']:.2f} / {cpu['after']:.2f} "
              f"({cpu['after'] / cpu['plain']:.2f}x) | {load:.1f} |", flush=True)


if __name__ == "__main__":
    main()
