"""Does an output repeat more than its photo (issue 41)? Every method at its defaults from a
256 crop of large photos (box-averaged by 2) to 512, one seed (512 -> 1024 took about 25 min a
photo on the shared machine at load 12): ``metrics.repetition_peak``, the luminance
autocorrelation's largest peak at a shift of 24 px or more, of the output against the photo's.
Methods predicted (``texsynth.budget.forecast``) above ``MAX_SECONDS`` are left out and said so.
"""

from __future__ import annotations

import time

import numpy as np

import texsynth
from texsynth.budget import forecast
from texsynth.io import read_photo
from texsynth.metrics import repetition_peak

from ..context import SHARED_TEXTURES, fmt

ORDER = 46
TITLE = "Repetition of every method: the autocorrelation's largest peak beyond 24 px (issue 41)"
#: (photo below shared/textures/large, kind)
PHOTOS = (("torcs-data/rock_face_vegetation.png", "structured"),
          ("ufoai-textures/brick_wall.png", "regular"))
SIDE, OUT, SEED = 256, 512, 0
#: The goal: the output's peak at most the photo's plus this.
MARGIN = 0.1
#: Methods predicted slower than this (seconds, this machine) are left out.
MAX_SECONDS = 150.0


def _crop(rel: str, side: int) -> np.ndarray:
    """The centre ``side`` x ``side`` of the photo box-averaged by 2 (its grain at a 1024
    output's scale)."""
    photo = read_photo(SHARED_TEXTURES / "large" / rel)[:, :, :3].astype(np.float32)
    h, w = photo.shape[0] // 2 * 2, photo.shape[1] // 2 * 2
    photo = photo[:h, :w].reshape(h // 2, 2, w // 2, 2, 3).mean(axis=(1, 3))
    y, x = (photo.shape[0] - side) // 2, (photo.shape[1] - side) // 2
    return np.ascontiguousarray(photo[y:y + side, x:x + side])


def run(ctx) -> str:
    if not (SHARED_TEXTURES / "large").exists():
        return "Skipped: ../shared/textures/large is absent."
    side, out = (128, 256) if ctx.quick else (SIDE, OUT)
    names = [m.name for m in texsynth.registry.methods()]
    rows, skipped, failing = [], {}, set()
    for rel, kind in PHOTOS[:1] if ctx.quick else PHOTOS:
        photo = _crop(rel, side)
        own = repetition_peak(photo)
        for name in names:
            predicted = forecast(name, photo.shape, out, out)[0]
            if predicted > MAX_SECONDS:
                skipped[name] = max(skipped.get(name, 0.0), predicted)
                continue
            start = time.perf_counter()
            image = texsynth.synthesize(photo, out, out, method=name, seed=SEED)
            seconds = time.perf_counter() - start
            peak = repetition_peak(image)
            ok = peak <= own + MARGIN
            if not ok:
                failing.add(name)
            rows.append(f"| {rel} | {kind} | `{name}` | {fmt(own, 2)} | {fmt(peak, 2)} | "
                        f"{'yes' if ok else '**no**'} | {seconds:.0f} |")
            print(rel, name, own, peak, seconds, flush=True)
    left_out = ", ".join(f"`{k}` (predicted {v:.0f} s)" for k, v in skipped.items())
    return "\n".join([
        f"Each photo box-averaged by 2 and its centre {side} x {side} cropped, synthesized to "
        f"{out} x {out} by every method at its defaults, seed {SEED}. Peak: "
        "`texsynth.metrics.repetition_peak`, the largest local maximum of the luminance's "
        "(linear, zero-padded) autocorrelation at a shift of 24 px or more, up to half the "
        "image across and down: about 1 for a texture laid side by side. Goal: the output's "
        f"at most the photo's own + {MARGIN}.",
        "",
        "| photo | kind | method | photo's peak | output's peak | goal met | seconds |",
        "|---|---|---|---|---|---|---|",
        *rows,
        "",
        f"Failing: {', '.join(f'`{n}`' for n in sorted(failing)) or 'none'}. "
        f"Left out (predicted above {MAX_SECONDS:.0f} s): {left_out or 'none'}.",
    ])
