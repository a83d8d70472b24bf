"""Synthesize a material's colour map and make its other maps follow, with the core alone.

    python examples/synthesize_maps.py COLOUR [OTHER ...] [--width 1024] [--height 1024]
        [--method multiscale_mrf] [--seed 0] [--out out]

COLOUR is synthesized with a method that copies exemplar pixels (``multiscale_mrf`` or
``efros_leung``); its position map is applied to every OTHER map (normal, roughness, height...,
PNG or OpenEXR, the same size as COLOUR), so all of them follow the same synthesis and tile.
Writes into --out: each result under its input's name (PNG stays PNG at the input's bit depth of
8 or 16, EXR stays exact float) and ``positions.png``, the position map pictured (x red, y green).
No Blender needed: numpy, scipy and OpenEXR (for EXR files).
"""

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import texsynth  # noqa: E402
from texsynth import io  # noqa: E402


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("colour", type=Path)
    parser.add_argument("others", type=Path, nargs="*")
    parser.add_argument("--width", type=int, default=1024)
    parser.add_argument("--height", type=int, default=1024)
    parser.add_argument("--method", default="multiscale_mrf",
                        choices=[m.name for m in texsynth.methods() if m.positions])
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", type=Path, default=Path("out"))
    args = parser.parse_args(argv)

    colour = io.read_image(args.colour)
    others = [(path, io.read_image(path)) for path in args.others]
    for path, image in others:  # check everything before the long work
        if image.shape[:2] != colour.shape[:2]:
            parser.error(f"{path} is {image.shape[1]} x {image.shape[0]}, not "
                         f"{colour.shape[1]} x {colour.shape[0]} like {args.colour}")

    shown = []

    def progress(fraction, message):
        line = f"{fraction:4.0%} {message}"
        if not shown or shown[-1] != line:
            shown.append(line)
            print(f"\r{line:70.70s}", end="", flush=True)

    result, positions = texsynth.synthesize_positions(
        colour, args.width, args.height, method=args.method, seed=args.seed, progress=progress)
    print()
    args.out.mkdir(parents=True, exist_ok=True)
    for path, image in [(args.colour, result)] + [
            (path, texsynth.apply_positions(positions, image)) for path, image in others]:
        target = args.out / path.name
        if path.suffix.lower() == ".exr":
            io.write_exr(target, image)
        else:
            io.write_png(target, image, bits=16 if _is_16_bit(path) else 8)
        print(f"wrote {target}")
    io.write_png(args.out / "positions.png", texsynth.positions_image(positions, colour.shape))
    print(f"wrote {args.out / 'positions.png'}")


def _is_16_bit(path: Path) -> bool:
    """A PNG's bit depth, from its header (byte 24)."""
    with open(path, "rb") as f:
        head = f.read(25)
    return head[:8] == b"\x89PNG\r\n\x1a\n" and head[24] == 16


if __name__ == "__main__":
    main()
