"""The stones between the joints, output over photo: what the eye sees on setts and bricks.

A regular photo (granite setts, a brick wall) is stones separated by joints (grass, mortar). An
artist sees at once a joint that ends inside a stone (a stub), a stone pieced from two halves
that do not line up, and a stone larger than any in the photo. Each shows in the stones' shapes:

- the joints (``PHOTOS``): on setts, pixels darker than their surroundings (the luminance
  under its grey closing by a square wider than a joint: grass and soil), on bricks, pixels
  less red than the bricks (grey mortar); a majority vote over a small box cleans the mask;
  the output, made of the photo's pixels, is read with the same rule;
- the stones are the 4-connected components of the rest (joint specks under ``min_area``, a
  16th of the photo's median stone, count as stone), those touching the border left out (cut
  off); a periodic output is read tiled 2 x 2, each stone counted once (its centre in the
  middle copy), and one reaching the tiled border runs on around the torus: merged;
- each stone's solidity is its area over that of its convex hull (pixel corners): 1 for a
  square sett, lower with a stub cutting into it or two halves out of line;
- figures (weighted by area, so specks of grain do not count): the median area of the whole
  stones and their mean solidity (output over photo), the share of stone area in merged stones
  (over ``LARGE`` times the photo's 99th percentile: joints missing, stones run together) and
  in broken ones (solidity under ``SOLID``), photo and output.

Ratios are output over photo: 1 is the photo's, the further either way the worse; the shares
are read beside the photo's. Checked on the photo's own crops against the whole (``--self``:
median area 0.94-0.97, solidity 0.98-1.04, merged 0; the broken share varies 0.08-0.43 between
quarters of the setts photo, so it is read only far from the photo's). With about 36 stones in
a 2048 output of the 12 MP setts, one missing joint moves the merged share by a tenth or more:
read it over seeds.

    .venv/bin/python -m benchmarks.stones --self setts bricks
    .venv/bin/python -m benchmarks.stones out.npy --photo setts
    .venv/bin/python -m benchmarks.stones out.npy --source photo.npy --scale 1.95
"""

from __future__ import annotations

import argparse

import numpy as np
from scipy import ndimage
from scipy.spatial import ConvexHull

from texsynth.io import read_photo

from .context import SHARED_TEXTURES

#: Each photo's joints: (file, kind, size, threshold) at the photo's own scale. "dark": the
#: luminance (a ``size // 6`` box mean) under its closing by a ``size`` square by more than
#: the threshold (grass and soil between setts); "grey": red minus blue under the threshold
#: (mortar between red bricks), a 3-pixel box mean.
PHOTOS = {"setts": ("0ad-data/granite_setts_grass.png", "dark", 41, 0.12),
          "bricks": ("ufoai-textures/brick_wall.png", "grey", 3, 0.06)}
#: Solidity under which a stone counts as broken (a stub or two halves out of line).
SOLID = 0.85
#: Area, over the photo's 99th percentile, beyond which a stone counts as merged.
LARGE = 1.5


def photo(key: str) -> np.ndarray:
    return np.ascontiguousarray(read_photo(SHARED_TEXTURES / "large" / PHOTOS[key][0])[:, :, :3],
                                np.float32)


def joints(image: np.ndarray, kind: str, size: int, threshold: float,
           wrap: bool = False) -> np.ndarray:
    """(H, W) True on the joints (see ``PHOTOS``), a majority vote over a box of ``size // 6``
    (at least 3) pixels; ``wrap``: the image is periodic."""
    mode = "wrap" if wrap else "reflect"
    box = max(3, size // 6)
    if kind == "dark":
        lum = ndimage.uniform_filter(image.mean(axis=2), box, mode=mode)
        mask = ndimage.grey_closing(lum, size=(size, size), mode=mode) - lum > threshold
    else:
        mask = ndimage.uniform_filter(image[:, :, 0] - image[:, :, 2], box, mode=mode) < threshold
    return ndimage.uniform_filter(mask.astype(np.float32), box, mode=mode) > 0.5


def stones(mask: np.ndarray, min_area: int) -> np.ndarray:
    """(area, solidity, centre row, centre col, touches the border) of each stone of at least
    ``min_area`` pixels."""
    specks, _ = ndimage.label(mask)
    size = np.bincount(specks.ravel())
    size[0] = min_area
    label, n = ndimage.label(~mask | (size < min_area)[specks])  # specks of grain: stone
    h, w = mask.shape
    out = []
    for k, sl in enumerate(ndimage.find_objects(label), start=1):
        own = label[sl] == k
        area = int(own.sum())
        if area < min_area:
            continue
        edge = sl[0].start == 0 or sl[1].start == 0 or sl[0].stop == h or sl[1].stop == w
        r, c = np.nonzero(own)
        corners = np.concatenate([np.stack([r + dr, c + dc], axis=1)
                                  for dr in (0, 1) for dc in (0, 1)])
        hull = ConvexHull(corners).volume
        out.append((area, area / hull, r.mean() + sl[0].start, c.mean() + sl[1].start, edge))
    return np.array(out, float).reshape(-1, 5)


def figures(image: np.ndarray, joint: tuple, min_area: int, periodic: bool,
            large: float = np.inf) -> dict:
    """The stones' figures of one image (see the module notes); ``large``: the area over which
    a stone counts as merged."""
    if periodic:  # the torus: tiled 2 x 2, each stone once (its centre in the middle copy)
        h, w = image.shape[:2]
        s = stones(joints(np.tile(image, (2, 2, 1)), *joint, wrap=True), min_area)
        s = s[(s[:, 2] >= h / 2) & (s[:, 2] < 3 * h / 2) & (s[:, 3] >= w / 2)
              & (s[:, 3] < 3 * w / 2)]
        s[s[:, 4] > 0, 0] = np.inf  # reaching the tiled border: running on around the torus
        share = np.minimum(s[:, 0], h * w)  # its area in one copy at most
    else:  # stones cut by the border are left out
        s = stones(joints(image, *joint), min_area)
        s = s[s[:, 4] == 0]
        share = s[:, 0]
    area, solidity = s[:, 0], s[:, 1]
    whole = area <= large
    order = np.argsort(area[whole])
    cum = np.cumsum(area[whole][order]) / max(area[whole].sum(), 1)

    def quantile(q):  # area-weighted; nan without a whole stone
        return float(area[whole][order][min(whole.sum() - 1, np.searchsorted(cum, q))]) \
            if whole.any() else np.nan
    return {"stones": int(whole.sum()), "median area": quantile(0.5), "p99 area": quantile(0.99),
            "merged": float(share[~whole].sum() / share.sum()),
            "solidity": float((solidity * share)[whole].sum() / max(share[whole].sum(), 1))
            if whole.any() else np.nan,
            "broken": float(share[whole & (solidity < SOLID)].sum() / share.sum())}


def compare(photo_image: np.ndarray, output: np.ndarray, joint: tuple,
            periodic: bool = True) -> dict:
    """``output``'s figures over the photo's (merged and broken: the two shares);
    ``joint``: (kind, size, threshold) as in ``PHOTOS``, at the photo's scale."""
    ref = figures(photo_image, joint, 1, False)
    min_area = int(ref["median area"] / 16)
    ref = figures(photo_image, joint, min_area, False)
    got = figures(output, joint, min_area, periodic, LARGE * ref["p99 area"])
    return {"stones": got["stones"], "median area": got["median area"] / ref["median area"],
            "solidity": got["solidity"] / ref["solidity"],
            "merged": (ref["merged"], got["merged"]), "broken": (ref["broken"], got["broken"])}


def line(name: str, r: dict) -> str:
    return (f"| {name} | {r['stones']} | {r['median area']:.2f} | {r['solidity']:.3f} | "
            f"{r['merged'][0]:.3f} / {r['merged'][1]:.3f} | "
            f"{r['broken'][0]:.3f} / {r['broken'][1]:.3f} |")


HEAD = ("| image | stones | median area | solidity | merged photo / out | broken photo / out |\n"
        "|---|---|---|---|---|---|")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("outputs", nargs="*", help=".npy or image files of outputs")
    parser.add_argument("--photo", choices=sorted(PHOTOS), default="setts")
    parser.add_argument("--source", help="the exemplar (.npy or image) instead of the photo")
    parser.add_argument("--scale", type=float, default=1.0,
                        help="the source's pixels per photo pixel (the joints' sizes scale)")
    parser.add_argument("--self", dest="own", nargs="*", choices=sorted(PHOTOS),
                        help="the photo's quarters and centre against the whole")
    args = parser.parse_args()
    print(HEAD)
    for key in args.own or ():
        image, joint = photo(key), PHOTOS[key][1:]
        h, w = image.shape[:2]
        crops = {"top left": image[:h // 2, :w // 2], "bottom right": image[h // 2:, w // 2:],
                 "centre": image[h // 4:3 * h // 4, w // 4:3 * w // 4]}
        for name, crop in crops.items():
            print(line(f"{key} {name}", compare(image, crop, joint, False)), flush=True)
    if args.outputs:
        ref = (np.load(args.source) if args.source and args.source.endswith(".npy")
               else read_photo(args.source)[:, :, :3] if args.source else photo(args.photo))
        kind, size, threshold = PHOTOS[args.photo][1:]
        joint = (kind, max(3, round(size * args.scale)), threshold)
        for path in args.outputs:
            out = np.load(path) if path.endswith(".npy") else read_photo(path)[:, :, :3]
            print(line(path, compare(ref, out, joint)), flush=True)


if __name__ == "__main__":
    main()
