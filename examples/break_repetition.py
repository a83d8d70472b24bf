"""Precompute tiling and blending for any engine, with the core alone.

    python examples/break_repetition.py TEXTURE [--srgb] [--preview 3] [--seed 0] [--out out]

Writes into --out, under TEXTURE's stem:

* ``<stem>_tnb_gaussian.exr``: the Gaussianised texture (float, in [0, 1]; sample it with
  linear filtering and wrap-around);
* ``<stem>_tnb_table.exr``: the inverse table, one row per channel ``k`` (row 0 at the top):
  read row ``k`` at ``x = G_k`` (texel centres at ``(j + 0.5) / width``, clamped) and sum the
  rows' colours (``texsynth.norepeat.Gaussianized``);
* ``<stem>_tnb_preview.png``: ``--preview`` x ``--preview`` tiles' worth of the texture tiled
  and blended (``texsynth.norepeat.tile_and_blend``), which repeats nowhere.

``--srgb`` decodes an sRGB colour texture to linear first, as a renderer reads it (the table
then gives linear values; the preview is encoded back). Without it the values are taken as
they are (normal, roughness and other data maps). No Blender needed: numpy, scipy, OpenEXR.
"""

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np  # noqa: E402

from texsynth import io  # noqa: E402
from texsynth.blocks.color import linear_to_srgb, srgb_to_linear  # noqa: E402
from texsynth.norepeat import gaussianize, tile_and_blend  # noqa: E402


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("texture", type=Path)
    parser.add_argument("--srgb", action="store_true", help="decode sRGB colour to linear")
    parser.add_argument("--preview", type=int, default=3, help="tiles across the preview")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", type=Path, default=Path("out"))
    args = parser.parse_args(argv)

    values = io.read_photo(args.texture)
    if args.srgb:
        values = srgb_to_linear(values).astype(np.float32)
    g = gaussianize(values)
    h, w, c = g.gaussian.shape
    preview = tile_and_blend(g, args.preview * w, args.preview * h, seed=args.seed)
    if args.srgb:
        preview = linear_to_srgb(np.clip(preview, 0.0, 1.0))
    args.out.mkdir(parents=True, exist_ok=True)
    stem = args.out / args.texture.stem
    table = g.lut if c > 1 else np.repeat(g.lut, 3, axis=2)
    io.write_exr(f"{stem}_tnb_gaussian.exr", np.repeat(g.gaussian, 3, 2) if c == 1
                 else g.gaussian)
    io.write_exr(f"{stem}_tnb_table.exr", np.ascontiguousarray(table))
    io.write_png(f"{stem}_tnb_preview.png", np.clip(preview, 0.0, 1.0))
    print(f"wrote {stem}_tnb_gaussian.exr, {stem}_tnb_table.exr, {stem}_tnb_preview.png")


if __name__ == "__main__":
    main()
