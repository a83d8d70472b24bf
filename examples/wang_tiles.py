"""Make a Wang tile set from a photo for any engine, with the core alone.

    python examples/wang_tiles.py PHOTO [MAP ...] [--colours 2] [--cells 8] [--seed 0] [--out out]

Writes into --out, under PHOTO's stem:

* ``<stem>_tiles_atlas.png``: the ``colours**4`` tiles (Cohen et al. 2003), each with its
  gutter, in a ``colours**2`` square grid (``texsynth.norepeat.WangTiles``);
* ``<stem>_tiles_<map stem>.png`` for each MAP (normal, roughness... of the photo's size): the
  same tiles cut from that map, by the atlas's position map;
* ``<stem>_tiles_preview.png``: ``--cells`` x ``--cells`` cells laid by hashed edge colours
  (``texsynth.norepeat.wang_tiling``), which tiles and repeats nowhere inside;
* ``<stem>_tiles.json``: the layout a shader needs: tile side, gutter, colours, atlas side and
  the slot formula.

Pixels are copied, never resampled: 8-bit photos and maps are written as they were read. No
Blender needed: numpy, scipy (and Pillow for JPEG photos).
"""

import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np  # noqa: E402

import texsynth  # noqa: E402
from texsynth import io  # noqa: E402
from texsynth.norepeat import wang_tiles, wang_tiling  # noqa: E402


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("photo", type=Path)
    parser.add_argument("maps", type=Path, nargs="*", help="other maps of the material")
    parser.add_argument("--colours", type=int, default=2, help="edge colours per direction")
    parser.add_argument("--cells", type=int, default=8, help="cells across the preview")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", type=Path, default=Path("out"))
    args = parser.parse_args(argv)

    photo = io.read_photo(args.photo)
    tiles = wang_tiles(photo, colours=args.colours, seed=args.seed)
    args.out.mkdir(parents=True, exist_ok=True)
    stem = args.out / f"{args.photo.stem}_tiles"
    written = [f"{stem}_atlas.png", f"{stem}_preview.png", f"{stem}.json"]
    io.write_png(written[0], np.clip(tiles.atlas, 0.0, 1.0))
    t = tiles.tile
    preview = wang_tiling(tiles, args.cells * t, args.cells * t, cells=args.cells, seed=args.seed)
    io.write_png(written[1], np.clip(preview, 0.0, 1.0))
    for path in args.maps:
        other = texsynth.apply_positions(tiles.positions, io.read_photo(path))
        written.append(f"{stem}_{path.stem}.png")
        io.write_png(written[-1], np.clip(other, 0.0, 1.0))
    layout = {"tile": t, "gutter": tiles.gutter, "colours": tiles.colours,
              "atlas": tiles.atlas.shape[0], "step": tiles.step,
              "slot": "row (n * colours + s) * step + gutter, col (w * colours + e) * step + "
                      "gutter (rows from the top)",
              "edges": "cell (X, Y), Y up: s = h(X, Y), n = h(X, Y + 1), w = v(X, Y), "
                       "e = v(X + 1, Y), each a hash of the lattice point and the seed"}
    Path(written[2]).write_text(json.dumps(layout, indent=1))
    print("wrote " + ", ".join(written))


if __name__ == "__main__":
    main()
