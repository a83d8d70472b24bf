"""The multigrid relaxation of a position map with confidences (Paget & Longstaff 1998).

Shared by ``multiscale_mrf`` and the guided synthesis of ``texsynth.stack``, as described by
Neubeck, Zalesny & Van Gool 2004, section 3.1 (eq. 1-2, fig. 9). The output is a position map
``S``: per pixel, the flat index of the exemplar pixel it shows. A *level* object knows the
distance of its paper and answers ``level.visit(S, w, rows, cols, rng, tick)`` with the best
positions for the pixels (rows, cols), calling ``tick()`` after each chunk of pixels (where the
caller may cancel: a batch on a 4096 grid holds a million pixels); this module decides which
pixels are visited, when, and how the grids follow one another:

- Confidence: every visit adds 1/T to w(i, j) (eq. 1, T = ``visits``); a pixel is visited with
  probability proportional to 1 - w (eq. 2) and is final at w = 1.
- Multigrid (fig. 9): level l is the output decimated by 2^l with coordinates kept at full
  resolution. The coarsest grid starts from random positions; a finished level's pixels seed
  the even pixels of the next finer one with confidence 0.5, the others start random at 0.
- A caller may settle a finished level's map before it seeds the next (``settle``:
  ``multiscale_mrf`` slides its copied regions into phase there).

Deviations, one line each:
- visits are made in batches: each batch is a random lattice of pixels r + 1 apart (so no pixel
  of a batch is in another's neighbourhood, and the batch equals visiting them one after
  another), each lattice pixel taken with probability (1 - w) / max(1 - w); the paper draws one
  pixel at a time with probability (1 - w) / sum(1 - w), the same proportions;
- a side not divisible by 2^l gives a coarse grid of ceil(side / 2^l) points whose last row or
  column sits closer to the first; the finest level, where this does not arise, corrects it;
- the number of levels is capped so that the coarsest neighbourhood (2 r 2^l + 1) fits in the
  exemplar and its grid is at least 2 r + 1 points across;
- the random start uses every exemplar pixel equally often: each run of n grid pixels in reading
  order holds every one once (a grid larger than the exemplar), or n >= the grid's pixels are
  drawn without repeats (a camera photo).
"""

from __future__ import annotations

import functools
from collections.abc import Callable

import numpy as np

from ..progress import Progress

__all__ = ["level_count", "grid_shapes", "random_positions", "relax", "synthesize_positions"]


def level_count(exemplar_shape, width, height, radius, levels) -> int:
    """``levels`` capped so the coarsest neighbourhood fits the exemplar and the output grid."""
    side = min(exemplar_shape[:2])
    n = 1
    while (n < levels and 2 * radius * 2 ** n + 1 <= side
           and -(-min(width, height) // 2 ** n) >= 2 * radius + 1):
        n += 1
    return n


def grid_shapes(width: int, height: int, n_levels: int) -> list[tuple[int, int]]:
    """The (rows, cols) of each level's grid, finest first."""
    return [(-(-height // 2 ** lv), -(-width // 2 ** lv)) for lv in range(n_levels)]


def random_positions(shape, n, rng, pool=None, tick=None) -> np.ndarray:
    """Flat exemplar indices, each of the ``n`` exemplar pixels (or each of ``pool``'s) used
    equally often (up to rounding): a draw without repeats when there are more than pixels,
    else one permutation of them after another (``tick()`` after each), in reading order."""
    size = shape[0] * shape[1]
    m = n if pool is None else len(pool)
    if m >= size:  # a permutation of a 12 MP pool would take seconds
        pick = rng.choice(m, size, replace=False)
        return (pick if pool is None else pool[pick]).astype(np.int32).reshape(shape)
    pool = np.arange(n, dtype=np.int32) if pool is None else pool.astype(np.int32)
    out = np.empty(-(-size // m) * m, np.int32)
    for start in range(0, size, m):  # a 4096 grid from a 1024 photo: 16 rounds, not one of 16 M
        out[start:start + m] = rng.permutation(pool)
        if tick is not None:
            tick()
    return out[:size].reshape(shape)


def synthesize_positions(make_level: Callable[[int, Callable[[], None]], object], n: int, shapes,
                         visits: int | Callable[[int], int], rng: np.random.Generator,
                         progress: Progress,
                         pool: Callable[[int], np.ndarray | None] | None = None,
                         settle: Callable[..., np.ndarray] | None = None,
                         work: list[tuple[float, float]] | None = None) -> np.ndarray:
    """The finest level's position map (flat indices into the ``n`` exemplar pixels), relaxed
    coarse to fine; ``make_level(l, tick)`` builds level l's distance (fig. 9) and may
    call ``tick()`` on the way (where the caller may cancel); ``visits`` is T, or
    T per level as ``visits(l)``; ``pool(l)``, when given and not None, the exemplar positions
    level l draws its random start from (a level that searches a lattice of the exemplar);
    ``work``, each level's shares of the progress, (relaxation, settling) (any scale; default
    its grid pixels and none)."""
    n_levels = len(shapes)
    work = np.array([(gh * gw, 0.0) for gh, gw in shapes] if work is None else work, float)
    work /= work.sum()

    # Confidence w is counted in halves of a visit: w = halves / (2 T), final at 2 T.
    def pool_of(lv):
        return None if pool is None else pool(lv)

    source = random_positions(shapes[-1], n, rng, pool_of(n_levels - 1))
    halves = np.zeros(shapes[-1], np.int16)
    for lv in reversed(range(n_levels)):
        start = work[lv + 1:].sum()
        part = progress.span(start, start + work[lv, 0])
        t = visits(lv) if callable(visits) else visits
        building = functools.partial(part, 0.0, f"level {lv}: building")
        if lv < n_levels - 1:
            building()  # the random start draws from up to 12 M exemplar pixels
            coarse = source
            source = random_positions(shapes[lv], n, rng, pool_of(lv), building)
            source[::2, ::2] = coarse
            halves = np.zeros(shapes[lv], np.int16)
            halves[::2, ::2] = t  # confidence 0.5
        building()  # Esc is heard between the random start and the table, long steps at 4096
        level = None  # the finer level's tables are built after the coarser one's are freed
        level = make_level(lv, building)
        relax(level, source, halves, t, rng, part, lv)
        if settle is not None:
            settling = progress.span(start + work[lv, 0], start + work[lv].sum())
            source = settle(lv, level, source,
                            lambda f, s=settling, m=f"level {lv}: settling": s(f, m))
    return source


def relax(level, source, halves, visits, rng, progress, index) -> None:
    """Visit the pixels of one level, with probability proportional to 1 - w (eq. 2), until
    every confidence w reaches 1 (eq. 1). ``source`` and ``halves`` (0 to 2 T) are updated in
    place. A round's work is its visits': the confidences, the need left and its largest are
    kept up to date at the pixels visited (the count of pixels at each confidence gives the
    least), not made again over the grid (on a 512 x 512 grid a round visits 800 pixels)."""
    gh, gw = source.shape
    spacing = int(np.floor(np.sqrt((level.offsets ** 2).sum(axis=1).max()))) + 1
    full = 2 * visits
    remaining = int((full - halves).sum(dtype=np.int64))
    total = float(remaining)
    scale = np.float32(1.0 / full)
    confidence = halves * scale
    count = np.bincount(halves.ravel(), minlength=full + 1)  # pixels at each confidence
    least = int(np.flatnonzero(count)[0])
    label = f"level {index}: visiting"
    down, across = (spacing * np.arange(max(1, g // spacing)) for g in (gh, gw))
    while remaining:
        tick = functools.partial(progress, 1.0 - remaining / total, label)
        tick()
        # A lattice of pixels `spacing` apart, also across the wrap, at a random offset.
        ry = (rng.integers(gh) + down) % gh
        rx = (rng.integers(gw) + across) % gw
        lattice_need = full - halves[ry[:, None], rx]
        take = rng.random(lattice_need.shape) * (full - least) < lattice_need
        iy, ix = np.nonzero(take)
        if len(iy) == 0:
            continue
        rows, cols = ry[iy], rx[ix]
        source[rows, cols] = level.visit(source, confidence, rows, cols, rng, tick)
        was = halves[rows, cols]
        now = np.minimum(was + 2, full)
        halves[rows, cols] = now
        confidence[rows, cols] = now * scale
        remaining -= int(now.sum(dtype=np.int64) - was.sum(dtype=np.int64))
        count -= np.bincount(was, minlength=len(count))
        count += np.bincount(now, minlength=len(count))
        while remaining and not count[least]:
            least += 1
