"""The material section's heal cases alone (issue 43): both measures and the time per case.

    TEXSYNTH_SHARED_TEXTURES=/path/to/shared/textures nice -n 15 python -m benchmarks.heal_cases \\
        [--look DIR] [NAME ...]

NAME: run only the cases whose tag (photo_blemish, as ``brick_wall_sign``) contains it;
``--look DIR``: the photo beside the healed region (192 px around the mask, shown 2x) as PNGs.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
from scipy.ndimage import binary_dilation

from benchmarks.sections import material
from benchmarks.sections.tileable import centre_crop
from texsynth.material import heal


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*")
    parser.add_argument("--look", type=Path)
    parser.add_argument("--seed", type=int, default=material.SEED, help="heal's seed")
    args = parser.parse_args()
    side, rng, within = 512, np.random.default_rng(material.SEED), 0
    for rel in material.HEAL_PHOTOS:
        truth = centre_crop(rel, side)
        for name, colour, footprint in material.blemishes(side, rng):  # the section's draws
            tag = f"{Path(rel).stem}_{name.split()[0]}"
            if args.names and not any(n in tag for n in args.names):
                continue
            blemished = np.where(footprint[:, :, None], colour, truth).astype(np.float32)
            mask = binary_dilation(footprint, iterations=3)
            start = time.perf_counter()
            healed = heal(blemished, mask, seed=args.seed)
            seconds = time.perf_counter() - start
            g = material.region_gradient_ratio(healed, truth, mask)
            b = material.boundary_seam_ratio(healed, truth, mask)
            good = 0.9 <= g <= 1.1 and 0.8 <= b <= 1.2
            within += good
            print(f"{tag:32s} gradient {g:.2f} seam {b:.2f} {seconds:6.1f} s "
                  f"{'within' if good else 'OUT'}", flush=True)
            if args.look:
                from PIL import Image

                ys, xs = np.nonzero(mask)
                top = int(np.clip(ys.mean() - 96, 0, side - 192))
                left = int(np.clip(xs.mean() - 96, 0, side - 192))
                crop = np.s_[top:top + 192, left:left + 192]
                pair = np.concatenate([truth[crop], healed[crop]], axis=1)
                args.look.mkdir(parents=True, exist_ok=True)
                Image.fromarray((np.clip(pair, 0, 1) * 255).astype(np.uint8)).resize(
                    (768, 384), Image.NEAREST).save(args.look / f"{tag}.png")
    print(f"within both goals: {within}")


if __name__ == "__main__":
    main()
