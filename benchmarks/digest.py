"""python -m benchmarks.digest [OUT.json]: SHA-256 of every method's output on fixed inputs.

A refactor that must not change behaviour runs this before and after and compares the files
(``python -m benchmarks.digest before.json`` ... ``python -m benchmarks.digest after.json``,
then ``diff``). Inputs are the bundled sample and two synthetic textures, so no ``../shared``
is needed; sizes are small so the whole run takes about a minute.
"""

from __future__ import annotations

import hashlib
import json
import sys
from pathlib import Path

import numpy as np

import texsynth
from texsynth.io import read_photo

REPO = Path(__file__).resolve().parents[1]


def _digest(*arrays) -> str:
    h = hashlib.sha256()
    for a in arrays:
        a = np.ascontiguousarray(a)
        h.update(str((a.dtype.str, a.shape)).encode())
        h.update(a.tobytes())
    return h.hexdigest()[:16]


def _textures() -> dict[str, np.ndarray]:
    rng = np.random.default_rng(7)
    y, x = np.mgrid[0:48, 0:48]
    stripes = (0.5 + 0.4 * np.sin(x * 0.7 + 0.3 * y))[:, :, None] + 0.05 * rng.random((48, 48, 1))
    blobs = rng.random((40, 56, 3)).astype(np.float32)
    return {"pool_water": read_photo(REPO / "samples" / "pool_water.png")[:48, :48],
            "stripes": stripes.astype(np.float32), "noise_rgb": blobs}


def digests() -> dict[str, str]:
    out = {}
    textures = _textures()
    for method in texsynth.methods():
        for name, exemplar in textures.items():
            if method.name == "efros_leung" and name != "stripes":
                continue
            image = texsynth.synthesize(exemplar, 40, 32, method=method.name, seed=3)
            out[f"{method.name}/{name}"] = _digest(image)
    hb = textures["pool_water"]
    out["heeger_bergen/steered_joint"] = _digest(texsynth.synthesize(
        hb, 40, 40, method="heeger_bergen", seed=1, steered=True, joint=True))
    image, positions = texsynth.synthesize_positions(hb, 40, 40, seed=2)
    out["positions/multiscale_mrf"] = _digest(image, positions)
    maps = [hb, hb[:, :, :1] * 0.5, 1.0 - hb]
    out["stack"] = _digest(*texsynth.synthesize_stack(maps, 40, 40, seed=4, support=0))
    out["stack/guided"] = _digest(*texsynth.synthesize_stack(maps, 40, 40, seed=4, support=1))
    co = texsynth.cooccurrence
    model = co.fit(hb, seed=5)
    out["cooccurrence/model"] = _digest(np.frombuffer(model.to_bytes(), np.uint8))
    out["cooccurrence/from_model"] = _digest(model.synthesize(33, 29, seed=6))
    result = texsynth.composite.compose(textures["pool_water"], 40, 40, seed=8)
    out["composite/api"] = _digest(result.image, result.labels)
    out["segment"] = _digest(texsynth.segmentation.segment(hb))
    plane = read_photo(REPO / "samples" / "pool_water.png")
    estimate = texsynth.estimate_plane(plane, focal_px=200.0)
    out["estimate_plane"] = _digest(np.array([estimate.slant, estimate.tilt, estimate.confidence]))
    out["rectify"] = _digest(texsynth.rectify(plane, estimate))
    return out


def main() -> None:
    result = digests()
    text = json.dumps(result, indent=1, sort_keys=True)
    if len(sys.argv) > 1:
        Path(sys.argv[1]).write_text(text + "\n")
    print(text)


if __name__ == "__main__":
    main()
