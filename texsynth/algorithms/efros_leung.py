"""Efros-Leung non-parametric sampling, grown on a torus so the result tiles.

Forsyth & Ponce, section 11.3.4, Algorithm 11.6; Torralba, Isola & Freeman, section 28.4 (window
size effects); Efros & Leung, "Texture synthesis by non-parametric sampling", ICCV 1999.

    Choose a small square of pixels at random from the exemplar; insert it into the output.
    Until every output pixel has a value:
        for each unfilled pixel on the boundary of the filled region, most filled neighbours first:
            compare its window (``window`` x ``window``) with every exemplar window by
            Gaussian-weighted SSD over the filled pixels only (weights normalised over them);
            pick uniformly among the windows within (1 + ``epsilon``) of the best;
            copy that window's centre pixel.

Periodic output: output windows wrap around the canvas (toroidal), so the last pixels are matched
against wrapped context and the result tiles. Exemplar windows never wrap unless the exemplar is
declared tileable (``exemplar_tiles``). Colour channels are matched jointly and whole pixels are
copied, so the method also returns a position map (row, col into the exemplar).

Search: exact, not approximate (``texsynth.blocks.search.PatchMatrix.sample``). Every exemplar
window is a row of a matrix, so the weighted SSD of a batch of output windows against all of them
is a matrix product. It is first taken over the inner 7 x 7 offsets only, a lower bound of the full
SSD (every term is non-negative); the full SSD of the best-bounded window bounds the minimum from
above; only windows whose bound is within (1 + epsilon) of it are scored in full. The result is
the same as scoring every window in full (docs/BENCHMARKS.md: the speed-up over the
pixel-by-pixel search).

Deviations, one line each:
- boundary pixels are filled in batches so the search is a matrix product: a batch keeps, per
  2 x 2 cell of the torus, the pixel with the most filled neighbours, and drops any 8-neighbour of
  a better one; a pixel then sees the pixels filled before its batch but not the others of its
  batch (at least 2 pixels away), where the paper fills one pixel at a time;
- Gaussian sigma = window / 6.4 and a 3 x 3 seed, as in Efros & Leung's own code;
- stuck fallback (Efros & Leung's MaxErrThreshold): a pixel whose best match has an RMS
  difference above 0.3 of the exemplar's value range waits for more context; when every boundary
  pixel waits, the threshold grows by 10 % and they are tried again;
- a rounding tolerance (1e-5 of the terms' size) joins the (1 + epsilon) rule, so windows that
  match exactly are all candidates even when the best distance rounds to zero.

References
----------
Efros & Leung 1999, section 2; Forsyth & Ponce, section 11.3.4, Algorithm 11.6;
Torralba, Isola & Freeman, section 28.4.
"""

from __future__ import annotations

import numpy as np

from ..blocks.search import (
    PatchMatrix,
    gaussian_weights,
    sparse_subset,
    square_offsets,
    toroidal_gather,
)
from ..registry import Method, Param, register

__all__ = ["efros_leung", "METHOD"]

#: Efros & Leung's MaxErrThreshold: RMS match error, as a fraction of the exemplar's value range,
#: above which a pixel waits for more context.
MAX_ERROR = 0.3
#: Largest distance matrix computed at once (bytes): bounds the memory of a batch.
BATCH_BYTES = 64 << 20
SEED = 3
#: The boundary of the filled region: unfilled pixels with a filled 8-neighbour.
ADJACENT = square_offsets(3)
#: Pixels filled in one batch are at least this far apart (Chebyshev), so never 8-neighbours.
SPACING = 2


def efros_leung(exemplar, width, height, rng, progress, window=11, epsilon=0.1,
                exemplar_tiles=False):
    """Grow (height, width, C) on a torus pixel by pixel from the exemplar's best-matching
    windows, with its position map (see the module notes).

    Parameters
    ----------
    exemplar : float32 array (H, W, C)
        The sample, validated by ``texsynth.synthesize``.
    width, height : int
        The output size, larger or smaller than the exemplar.
    rng, progress : numpy.random.Generator, texsynth.progress.Progress
        The seeded generator and the progress reporter ``texsynth.synthesize`` makes.
    window : int
        Side of the square neighbourhood compared (odd); larger keeps larger structures.
    epsilon : float
        Candidates are the windows within (1 + epsilon) of the best match.
    exemplar_tiles : bool
        The exemplar itself tiles: its windows may wrap around its edges.

    Returns
    -------
    image : numpy.ndarray
        float32 (height, width, C), periodic; every pixel an exemplar pixel.
    positions : numpy.ndarray
        int32 (height, width, 2), the (row, col) of the exemplar pixel each one shows.

    References
    ----------
    Forsyth & Ponce, section 11.3.4, Algorithm 11.6; Efros & Leung 1999, section 2;
    Torralba, Isola & Freeman, section 28.4 (the window size).

    Examples
    --------
    Every output pixel is one of the exemplar's:

    >>> import numpy as np, texsynth
    >>> photo = np.random.default_rng(0).random((16, 16, 3), dtype=np.float32)
    >>> out = texsynth.synthesize(photo, 24, 20, method="efros_leung", seed=1, window=5)
    >>> out.shape, set(map(tuple, out.reshape(-1, 3))) <= set(map(tuple, photo.reshape(-1, 3)))
    ((20, 24, 3), True)
    """
    h, w, c = exemplar.shape
    if not exemplar_tiles and min(h, w) < window:
        raise ValueError(f"the exemplar ({w} x {h}) is smaller than the {window} x {window} "
                         "window; use a smaller window or a larger exemplar")
    offsets = square_offsets(window)
    gauss = gaussian_weights(offsets, window / 6.4)
    progress(0.0, "Efros-Leung: indexing exemplar windows")
    patches = PatchMatrix(exemplar, offsets, wrap=exemplar_tiles, batch_bytes=BATCH_BYTES)
    centres = patches.positions
    n_windows = len(centres)
    batch_max = max(1, BATCH_BYTES // (4 * n_windows))
    value_range = float(np.ptp(exemplar)) or 1.0
    threshold = c * (MAX_ERROR * value_range) ** 2

    out = np.zeros((height, width, c), np.float32)
    positions = np.zeros((height, width, 2), np.int32)
    filled = np.zeros((height, width), bool)
    count = np.zeros((height, width), np.int32)
    waiting = np.zeros((height, width), bool)
    # The boundary, as ascending flat indices, kept up to date as pixels fill: a batch's work is
    # the boundary's, never the canvas's (a 16384 x 16 output has 16k batches).
    boundary = np.zeros(0, np.int64)

    def fill(rows, cols, src):
        nonlocal boundary
        out[rows, cols] = exemplar[src[:, 0], src[:, 1]]
        positions[rows, cols] = src
        filled[rows, cols] = True
        rr = (rows[:, None] + offsets[None, :, 0]) % height
        cc = (cols[:, None] + offsets[None, :, 1]) % width
        np.add.at(count, (rr, cc), 1)
        waiting[rr, cc] = False
        near = ((rows[:, None] + ADJACENT[:, 0]) % height) * width \
            + (cols[:, None] + ADJACENT[:, 1]) % width
        boundary = np.union1d(boundary, near.ravel())
        boundary = boundary[~filled.ravel()[boundary]]

    # Seed: a random SEED x SEED exemplar square at a random place on the torus.
    s = min(SEED, h, w)
    p0, q0 = rng.integers(h - s + 1), rng.integers(w - s + 1)
    y0, x0 = rng.integers(height), rng.integers(width)
    du, dv = np.mgrid[0:s, 0:s].reshape(2, -1)
    flat, first = np.unique(((y0 + du) % height) * width + (x0 + dv) % width, return_index=True)
    fill(flat // width, flat % width, np.stack([p0 + du[first], q0 + dv[first]], axis=1))

    total = height * width
    done = int(filled.sum())
    while done < total:
        ready = boundary[~waiting.ravel()[boundary]]
        rows, cols = ready // width, ready % width
        if len(rows) == 0:
            threshold *= 1.1 ** 2
            waiting.ravel()[boundary] = False  # only boundary pixels ever wait
            continue
        priority = count[rows, cols] + rng.random(len(rows))
        keep = sparse_subset(rows, cols, priority, (height, width), SPACING, rng)
        rows, cols, priority = rows[keep], cols[keep], priority[keep]
        if len(rows) > batch_max:
            top = np.argsort(-priority, kind="stable")[:batch_max]
            rows, cols = rows[top], cols[top]

        neighbourhood = toroidal_gather(out, rows, cols, offsets)
        g = gauss * toroidal_gather(filled, rows, cols, offsets)
        g /= g.sum(axis=1, keepdims=True)
        pick, best = patches.sample(neighbourhood, g, epsilon, rng)
        ok = best <= threshold
        waiting[rows[~ok], cols[~ok]] = True
        fill(rows[ok], cols[ok], centres[pick[ok]])
        done += int(ok.sum())
        progress(done / total, f"Efros-Leung: {done} of {total} pixels")
    return out, positions


def _memory(shape, width, height, params):
    """The window matrix, one batch's work in ``PatchMatrix.sample`` (the float32 bounds, two
    masks and the kept pairs' indices, at most 9 bytes per pixel and window; the two gathers of
    a ``CHUNK`` of kept pairs' rows), the output and its bookkeeping. A batch holds at most
    ``BATCH_BYTES / 4`` distances, and at most a front's pixels: about half the boundary of the
    filled region (``SPACING`` apart), which grows until it meets itself across the shorter
    side, taken as ``2.5 min(width, height) + window`` (189 at most on a 96 x 80 output: 2.4
    times its shorter side; a strip grows through two fronts across it), with its
    neighbourhoods, weights and queries (three rows each); a fixed ``2 BATCH_BYTES`` read 13x
    the resident peak of a 96 x 96 run."""
    h, w, c = shape
    k = params["window"]
    windows = h * w if params["exemplar_tiles"] else max(1, h - k + 1) * max(1, w - k + 1)
    batch = min(max(1, BATCH_BYTES // (4 * windows)), int(2.5 * min(width, height)) + k)
    row = 4 * k * k * (c + 1)  # a window's row of the matrix, bytes
    return windows * row + batch * (9 * windows + 3 * row) + 2 * PatchMatrix.CHUNK * row \
        + width * height * (4 * c + 8 + 6)


def _cost(shape, width, height, params):
    """Seconds on the reference machine (``texsynth.budget``). Every output pixel's window against
    every exemplar window: the 7 x 7 lower bound's matrix product over (C + 1) planes (values and
    mask), plus per-pixel bookkeeping, plus a fixed cost per batch (numpy calls and a small
    matrix product: most of a run on a strip 8 or 16 pixels high, 8 to 16 pixels a batch).
    The pixel and batch terms refitted (issue 45: 2e-5 and 3e-4 had predicted 16384 x 16 from
    32 x 32 at 0.31-0.38 of its time, 192 x 192 at 0.36) on three shapes measured in one
    sitting (``benchmarks/sections/predictions.py``): 96 x 96 from 48 x 48, 192 x 192 from
    32 x 32, 16384 x 16 from 32 x 32, at 0.78-1.2 of each; the batch term 2.6e-3 (1e-3 had told
    the strip 0.51 of its quiet 31.7 s, the squares 0.67-0.82). Every term then scaled by 0.6
    (issue 45: the three rows read 0.56, 0.90, 0.59 and 0.61, 0.48, 0.67 of the predictions
    table's median seconds over cost, on two hosts). Refitted with BLAS on one thread (issue
    45: ``blocks.parallel.serial_blas``; a batch's small product had woken OpenBLAS's threads):
    solved on the same three shapes' quiet seconds on a 2026-12 host (0.23, 7.11, 0.70 s at
    speed 0.17), units 2.0e-10 -> 1.3e-10, pixel 4.8e-5 -> 9.3e-5, batch 1.6e-3 -> 5.8e-4."""
    h, w, c = shape
    k = params["window"]
    windows = h * w if params["exemplar_tiles"] else max(1, h - k + 1) * max(1, w - k + 1)
    units = width * height * windows * min(k, 7) ** 2 * (c + 1)
    return 0.05 + 1.3e-10 * units + 9.3e-5 * width * height + 5.8e-4 * _batches(
        windows, width, height)


def _batches(windows: int, width: int, height: int) -> float:
    """Batches of a run: the filled region grows from the seed by about one ring of pixels
    every 3 batches (two fronts a side apart once it has wrapped the shorter side), so about
    1.5 per pixel of the longer side (measured 1.0 to 1.9 on outputs from 64 x 64 to 16384 x
    16), and never fewer than the pixels over the largest batch."""
    largest = max(1, BATCH_BYTES // (4 * windows))
    return max(1.5 * max(width, height) + 30.0, width * height / largest)


METHOD = register(Method(
    name="efros_leung",
    label="Efros-Leung",
    description="Grow the texture pixel by pixel, copying the centre of a well-matching exemplar "
                "window (Efros & Leung 1999): keeps local structure; slow on large outputs",
    function=efros_leung,
    params=(
        Param("window", int, 11, "Side of the square neighbourhood compared (odd); larger "
              "keeps larger structures", 3, 41),
        Param("epsilon", float, 0.1, "Candidates are the windows within (1 + epsilon) of the "
              "best match", 0.0, 1.0),
        Param("exemplar_tiles", bool, False, "The exemplar itself tiles: its windows may wrap "
              "around its edges"),
    ),
    min_exemplar=3,
    memory=_memory,
    cost=_cost,
    positions=True,
))
