"""A log-log line plot drawn with numpy alone (the benchmark needs no plotting library).

Tick labels use a 3 x 5 pixel font of digits, '.' and 's'; series are told apart by colour,
and the caption in Markdown names them (:data:`COLOURS` lists the colour names in order).
"""

from __future__ import annotations

import math

import numpy as np

COLOURS = (("blue", (0.12, 0.47, 0.71)), ("orange", (1.0, 0.5, 0.05)),
           ("green", (0.17, 0.63, 0.17)), ("red", (0.84, 0.15, 0.16)),
           ("purple", (0.58, 0.4, 0.74)), ("brown", (0.55, 0.34, 0.29)),
           ("pink", (0.89, 0.47, 0.76)), ("grey", (0.5, 0.5, 0.5)))

_FONT = {  # 3 x 5 glyphs, rows top to bottom, 3 bits each
    "0": "111101101101111", "1": "010110010010111", "2": "111001111100111",
    "3": "111001111001111", "4": "101101111001001", "5": "111100111001111",
    "6": "111100111101111", "7": "111001010010010", "8": "111101111101111",
    "9": "111101111001111", ".": "000000000000010",
    "s": "000011010001110", " ": "000000000000000",
}


def _text(canvas: np.ndarray, y: int, x: int, text: str, scale: int = 2) -> None:
    for i, ch in enumerate(text):
        glyph = np.array([int(b) for b in _FONT[ch]], bool).reshape(5, 3)
        glyph = np.kron(glyph, np.ones((scale, scale), bool))
        top, left = y, x + i * 4 * scale
        region = canvas[top:top + glyph.shape[0], left:left + glyph.shape[1]]
        region[glyph[: region.shape[0], : region.shape[1]]] = 0.0


def _line(canvas: np.ndarray, p0, p1, colour, width: int = 2) -> None:
    n = int(max(abs(p1[0] - p0[0]), abs(p1[1] - p0[1]))) + 1
    ys = np.rint(np.linspace(p0[0], p1[0], n)).astype(int)
    xs = np.rint(np.linspace(p0[1], p1[1], n)).astype(int)
    for dy in range(-(width // 2), width - width // 2):
        for dx in range(-(width // 2), width - width // 2):
            canvas[np.clip(ys + dy, 0, canvas.shape[0] - 1),
                   np.clip(xs + dx, 0, canvas.shape[1] - 1)] = colour


def _label(value: float) -> str:
    return f"{value:.0f}" if value >= 1 else f"{value:g}"


def loglog(series: list[tuple[list[float], list[float]]], x_ticks: list[float],
           size: tuple[int, int] = (360, 560)) -> np.ndarray:
    """float32 (H, W, 3) image: each (xs, ys) series as a coloured polyline on log-log axes.

    X ticks are labelled with the given values; y ticks are the powers of ten in range, labelled
    in seconds. Points are marked with small squares.
    """
    h, w = size
    canvas = np.ones((h, w, 3), np.float32)
    left, right, top, bottom = 70, w - 15, 15, h - 40
    ys_all = [y for _, ys in series for y in ys if y > 0]
    lo_y = 10 ** math.floor(math.log10(min(ys_all)))
    hi_y = 10 ** math.ceil(math.log10(max(ys_all)))
    lo_x, hi_x = min(x_ticks), max(x_ticks)

    def to_px(x, y):
        fx = (math.log(x) - math.log(lo_x)) / max(math.log(hi_x) - math.log(lo_x), 1e-9)
        fy = (math.log(y) - math.log(lo_y)) / max(math.log(hi_y) - math.log(lo_y), 1e-9)
        return bottom - fy * (bottom - top), left + fx * (right - left)

    grid = (0.85, 0.85, 0.85)
    for x in x_ticks:
        _, px = to_px(x, lo_y)
        _line(canvas, (top, px), (bottom, px), grid, 1)
        text = _label(x)
        _text(canvas, bottom + 8, min(int(px) - len(text) * 4, w - len(text) * 8 - 2), text)
    decade = lo_y
    while decade <= hi_y * 1.0001:
        py, _ = to_px(lo_x, decade)
        _line(canvas, (py, left), (py, right), grid, 1)
        text = _label(decade) + "s"
        _text(canvas, int(py) - 5, left - 8 - len(text) * 8, text)
        decade *= 10
    _line(canvas, (top, left), (bottom, left), (0, 0, 0), 1)
    _line(canvas, (bottom, left), (bottom, right), (0, 0, 0), 1)
    for i, (xs, ys) in enumerate(series):
        colour = COLOURS[i % len(COLOURS)][1]
        points = [to_px(x, y) for x, y in zip(xs, ys, strict=True) if y > 0]
        for a, b in zip(points, points[1:], strict=False):
            _line(canvas, a, b, colour)
        for py, px in points:
            canvas[int(py) - 3:int(py) + 4, int(px) - 3:int(px) + 4] = colour
    return canvas
