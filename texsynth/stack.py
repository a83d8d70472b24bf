"""Consistent synthesis of a stack of registered maps or views, guided by a support view.

Paper 002 (Neubeck, Zalesny, Van Gool), sections 2.3 and 3.2. A stack holds V registered images
of one sample (the maps of a material, or the views of a BTF). The support view A is synthesized
first by the single-view algorithm (section 3.1, ``multiscale_mrf``). Every other view B is then
synthesized from pairs (A, B) of the same input pixel, only B's values changing, with the
distance of section 3.2:

    dist(i, j, p, q) = sum_(u,v in N) w(i+u, j+v) ||B(i+u, j+v) - B_in(p+u, q+v)||^2
                       + c (1 - w(i+u, j+v)) ||A(i+u, j+v) - A_in(p+u, q+v)||^2,

A the synthesized support, w the confidences of B (eq. 1-2), ``c`` = 0.25. The relaxation is the
one of section 3.1 (``texsynth.algorithms.multiscale_mrf``: confidences, batches, multigrid,
periodic output), with this distance.

``mode="column"`` is the alternative of section 2.3 that the paper argues against: whole stack
columns copied through the support's position map (``apply_positions``); exact, fast, seams.

Deviations, one line each:
- the A term also compares the centre pixel (u, v) = (0, 0), weighted c (1 - w(i, j)), so that
  B follows the support at the pixel itself and not only around it;
- candidates are the continuations of B's placed neighbours and the random ones (section 3.1),
  plus the support's position at (i, j) and the continuations of its neighbours' positions:
  without them nothing proposes the columns A already chose (every w is 0 at the start);
- views with different channel counts are compared with zero-padded channels (no effect on the
  distances).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .positions import apply_positions
from .progress import Progress
from .registry import get
from .search import Rows, best_candidate, disk_offsets, exemplar_neighbours

__all__ = ["synthesize_stack", "validate_stack", "C_SUPPORT"]

#: Weight c of the support term (section 3.2: "c = 0.25 over all experiments").
C_SUPPORT = 0.25


def validate_stack(stack, support: int) -> list[np.ndarray]:
    """The views as float32 (H, W, C) arrays of one size, or ``ValueError`` saying what is wrong."""
    from . import validate_exemplar  # here: the package imports this module first

    if isinstance(stack, np.ndarray):
        if stack.ndim not in (3, 4):
            raise ValueError(f"a stack array must be (V, H, W) or (V, H, W, C), got {stack.shape}")
        views = list(stack)
    elif isinstance(stack, (list, tuple)):
        views = list(stack)
    else:
        raise ValueError(f"stack must be an array (V, H, W, C) or a list of images, "
                         f"got {type(stack).__name__}")
    if len(views) == 0:
        raise ValueError("the stack holds no views")
    if isinstance(support, bool) or not isinstance(support, (int, np.integer)) \
            or not -len(views) <= support < len(views):
        raise ValueError(f"support must be a view index from 0 to {len(views) - 1}, "
                         f"got {support!r}")
    out = []
    for v, image in enumerate(views):
        try:
            out.append(validate_exemplar(image))
        except ValueError as e:
            raise ValueError(f"view {v}: {e}") from None
    sizes = {a.shape[:2] for a in out}
    if len(sizes) > 1:
        listed = ", ".join(f"{a.shape[1]} x {a.shape[0]}" for a in out)
        raise ValueError(f"every view of a stack must have the same size (registered maps of "
                         f"one sample); got {listed}")
    return out


def synthesize_stack(
    stack,
    width: int,
    height: int,
    support: int = 0,
    method: str = "multiscale_mrf",
    seed: int = 0,
    progress: Callable[[float, str], object] | None = None,
    mode: str = "guided",
    c: float = C_SUPPORT,
    **params,
):
    """Synthesize every view of ``stack`` consistently, each periodic.

    Parameters
    ----------
    stack : array (V, H, W[, C]) or list of (H, W[, C]) images of one size
        Registered maps or views of one sample; channel counts may differ in a list.
    support : int
        Index of the support view, synthesized first with ``method``.
    method : str
        A method with position maps (``multiscale_mrf``, ``efros_leung``) for the support.
    mode : "guided" or "column"
        ``guided``: each other view synthesized with the section 3.2 distance (``multiscale_mrf``
        parameters among ``params`` apply to it); ``column``: the support's position map copied to
        every view.
    c : float
        Weight of the support term in the guided distance, 0 to 1.

    Returns
    -------
    float32 (V, height, width, C) for an array stack, a list of (height, width, C_v) for a list.
    """
    from . import synthesize_positions  # here: the package imports this module first

    if mode not in ("guided", "column"):
        raise ValueError(f"mode must be 'guided' or 'column', got {mode!r}")
    if not 0.0 <= c <= 1.0:
        raise ValueError(f"c must be between 0 and 1, got {c}")
    views = validate_stack(stack, support)
    support = support % len(views)
    mrf = get("multiscale_mrf")
    mrf_params = mrf.resolve({k: v for k, v in params.items()
                              if k in {p.name for p in mrf.params}})
    if mode == "guided":
        _check_memory(views, support, width, height, mrf_params)
    report = Progress(progress)
    share = 1.0 / len(views) if mode == "guided" else 1.0
    image_a, positions = synthesize_positions(views[support], width, height, method, seed,
                                              report.span(0.0, share), **params)
    out = [None] * len(views)
    out[support] = image_a
    others = [v for v in range(len(views)) if v != support]
    for n, v in enumerate(others):
        if mode == "column":
            out[v] = apply_positions(positions, views[v])
            continue
        rng = np.random.default_rng([int(seed), v])
        span = report.span(share * (n + 1), share * (n + 2))
        flat = guided_mrf(views[support], views[v], image_a, positions, rng, span, c,
                          **mrf_params)
        h, w = views[v].shape[:2]
        out[v] = views[v].reshape(h * w, -1)[flat]
    report(1.0, "stack: done")
    if isinstance(stack, np.ndarray):
        return np.stack(out)
    return out


def _check_memory(views, support, width, height, params) -> None:
    """``ValueError`` before any work when the largest guided view's exemplar table (K (C_B + 1)
    + (K + 1) (C_A + 1) floats a pixel), maps and batch exceed ``texsynth.memory_budget()``."""
    from . import memory_budget

    h, w = views[support].shape[:2]
    k = len(disk_offsets(params["radius"]))
    c_a = views[support].shape[2]
    c_b = max((v.shape[2] for i, v in enumerate(views) if i != support), default=0)
    table = h * w * 4 * (k * (c_b + 1) + (k + 1) * (c_a + 1))
    maps = width * height * (4 * c_a + 4 + 2 + 4 + 4 + 4 * c_b)
    batch = width * height / (params["radius"] + 1) ** 2 * (k + 1) * (40 + 4 * c_a)
    need, budget = table + maps + batch, memory_budget()
    if need > budget:
        raise ValueError(f"guided synthesis of {width} x {height} needs about "
                         f"{need / 2**30:.1f} GiB, over the budget of {budget / 2**30:.1f} GiB "
                         "(set TEXSYNTH_MEMORY_BUDGET to raise it, or use mode='column')")


class _GuidedLevel:
    """Section 3.2's distance as one dot product per candidate, like ``multiscale_mrf._Level``:
    each exemplar pixel p has a row [X_B, Q_B, X_A, Q_A] (its neighbours' B and A values at this
    level's step and their squared norms, or 0 and the maximal difference outside the exemplar);
    a visited output pixel has [-2 w O_B, w, -2 c (1 - w) O_A, c (1 - w)]. The A part has one
    more neighbour, the centre. Colours are centred on each view's exemplar mean."""

    CHUNK = 1024

    def __init__(self, in_a, in_b, out_a, pos_a, offsets, step, wrap, random_candidates, c):
        h, w = in_a.shape[:2]
        self.shape, self.n, self.wrap, self.c = (h, w), h * w, wrap, np.float32(c)
        self.offsets = offsets
        self.offsets_a = np.concatenate([np.zeros((1, 2), np.int32), offsets])
        self.random_candidates = random_candidates
        parts = []
        for image, offs in ((in_b, offsets), (in_a, self.offsets_a)):
            flat = image.reshape(h * w, -1)
            centred = image - flat.mean(axis=0)
            values, inside = exemplar_neighbours(centred, offs, step, wrap)
            dmax = np.float32((np.ptp(flat, axis=0).astype(np.float64) ** 2).sum())
            q = np.where(inside, (values * values).sum(axis=3), dmax)
            parts += [values.reshape(h * w, -1), q.reshape(h * w, -1)]
            if image is in_b:
                self.colours_b = Rows(centred.reshape(h * w, -1))
        table = np.zeros((h * w + 1, sum(p.shape[1] for p in parts)), np.float32)
        table[:-1] = np.concatenate(parts, axis=1)
        self.table = Rows(table)
        self.kb, self.cb = len(offsets), in_b.shape[2]
        self.ka, self.ca = len(self.offsets_a), in_a.shape[2]
        # The synthesized support on this level's grid, centred, and its positions.
        self.out_a = (out_a - in_a.reshape(h * w, -1).mean(axis=0)).astype(np.float32)
        self.pos_a = pos_a
        self.du = (step * offsets[:, 0]).astype(np.int32)
        self.dv = (step * offsets[:, 1]).astype(np.int32)

    def visit(self, source, confidence, rows, cols, rng):
        """One visit of the pixels (rows, cols) of B (none in another's neighbourhood)."""
        gh, gw = source.shape
        ra = (rows[:, None] + self.offsets_a[:, 0]) % gh
        ca = (cols[:, None] + self.offsets_a[:, 1]) % gw
        flat_a = ra * gw + ca  # (B, 1 + K): centre first, then the disk
        nb = source.ravel()[flat_a[:, 1:]]
        nw = confidence.ravel()[flat_a]
        oa = self.out_a.reshape(gh * gw, -1)[flat_a]
        pa = self.pos_a.ravel()[flat_a]
        current = source[rows, cols]
        extra = rng.integers(self.n, size=(len(rows), self.random_candidates))
        out = current.copy()
        for s in range(0, len(rows), self.CHUNK):
            sl = slice(s, s + self.CHUNK)
            out[sl] = self._best(nb[sl], nw[sl], oa[sl], pa[sl], current[sl], extra[sl])
        return out

    def _continue(self, positions, placed):
        h, w = self.shape
        pr, pc = np.divmod(positions, w)
        pr = pr - self.du
        pc = pc - self.dv
        if self.wrap:
            cand = (pr % h) * w + pc % w
            return np.where(placed, cand, self.n)
        ok = (pr >= 0) & (pr < h) & (pc >= 0) & (pc < w) & placed
        return np.where(ok, pr * w + pc, self.n)

    def _best(self, nb, nw, oa, pa, current, extra):
        none, b = self.n, len(nb)
        kb, cb, ka, ca = self.kb, self.cb, self.ka, self.ca
        w_b = nw[:, 1:]
        w_a = self.c * (1.0 - nw)
        z = np.empty((b, self.table.width), np.float32)
        z[:, :kb * cb] = np.multiply(self.colours_b[nb], (-2.0 * w_b)[:, :, None]).reshape(b, -1)
        z[:, kb * cb:kb * (cb + 1)] = w_b
        s = kb * (cb + 1)
        z[:, s:s + ka * ca] = np.multiply(oa, (-2.0 * w_a)[:, :, None]).reshape(b, -1)
        z[:, s + ka * ca:] = w_a

        cand = np.concatenate([
            self._continue(nb, w_b > 0),  # B's placed neighbours (Ashikhmin)
            pa[:, :1],  # the support's own column
            self._continue(pa[:, 1:], np.ones_like(w_b, bool)),  # the support's neighbours
            extra,
        ], axis=1)
        return best_candidate(self.table, cand, z, current, none)


def guided_mrf(in_a, in_b, out_a, positions_a, rng, progress, c=C_SUPPORT, radius=3, visits=4,
               random_candidates=2, levels=4, exemplar_tiles=False):
    """View B (flat exemplar indices, (height, width)) synthesized guided by the synthesized
    support ``out_a`` with position map ``positions_a`` (section 3.2 on section 3.1's multigrid).
    ``in_a``, ``in_b``: the input views (H, W, C_a), (H, W, C_b) of one size."""
    # Here, not at the top: importing the algorithms package registers every method.
    from .algorithms.multiscale_mrf import _random_positions, _relax, level_count

    h, w = in_a.shape[:2]
    height, width = out_a.shape[:2]
    offsets = disk_offsets(radius)
    n_levels = level_count(in_a.shape, width, height, radius, levels)
    shapes = [(-(-height // 2 ** lv), -(-width // 2 ** lv)) for lv in range(n_levels)]
    work = np.array([gh * gw for gh, gw in shapes], float)
    work /= work.sum()
    flat_a = (positions_a[:, :, 0] * w + positions_a[:, :, 1]).astype(np.int32)

    source = _random_positions(shapes[-1], h * w, rng)
    halves = np.zeros(shapes[-1], np.int16)
    for lv in reversed(range(n_levels)):
        if lv < n_levels - 1:
            coarse = source
            source = _random_positions(shapes[lv], h * w, rng)
            source[::2, ::2] = coarse
            halves = np.zeros(shapes[lv], np.int16)
            halves[::2, ::2] = visits  # confidence 0.5
        s = 2 ** lv
        level = _GuidedLevel(in_a, in_b, out_a[::s, ::s], flat_a[::s, ::s], offsets, s,
                             exemplar_tiles, random_candidates, c)
        start = work[lv + 1:].sum()
        _relax(level, source, halves, visits, rng, progress.span(start, start + work[lv]), lv)
    return source
