"""The guided distance of Neubeck, Zalesny & Van Gool 2004, section 3.2, on the multigrid.

View B of a stack is synthesized with the support view A already synthesized (its image
``out_a`` and position map): a candidate is scored on B's placed neighbours and, where B is
not yet confident, on A (see ``texsynth.stack`` for the distance and the deviations).
"""

from __future__ import annotations

import numpy as np

from ..blocks import multigrid
from ..blocks.multigrid import grid_shapes, level_count
from ..blocks.search import Rows, best_candidate, disk_offsets, neighbour_table

__all__ = ["guided_mrf", "C_SUPPORT"]

#: Weight c of the support term (section 3.2: "c = 0.25 over all experiments").
C_SUPPORT = 0.25


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
            dmax = np.float32((np.ptp(flat, axis=0).astype(np.float64) ** 2).sum())
            parts.append(neighbour_table(centred, offs, step, wrap, dmax))
            if image is in_b:
                self.colours_b = Rows(centred.reshape(h * w, -1))
        self.table = Rows(np.concatenate(parts, axis=1))  # the last row stays all zero
        self.kb, self.cb = len(offsets), in_b.shape[2]
        self.ka, self.ca = len(self.offsets_a), in_a.shape[2]
        # The synthesized support on this level's grid, centred, and its positions.
        self.out_a = (out_a - in_a.reshape(h * w, -1).mean(axis=0)).astype(np.float32)
        self.pos_a = pos_a
        self.du = (step * offsets[:, 0]).astype(np.int32)
        self.dv = (step * offsets[:, 1]).astype(np.int32)

    def visit(self, source, confidence, rows, cols, rng, tick):
        """One visit of the pixels (rows, cols) of B (none in another's neighbourhood);
        ``tick()`` after each chunk of ``CHUNK`` pixels."""
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
            tick()
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
    h, w = in_a.shape[:2]
    height, width = out_a.shape[:2]
    offsets = disk_offsets(radius)
    shapes = grid_shapes(width, height, level_count(in_a.shape, width, height, radius, levels))
    flat_a = (positions_a[:, :, 0] * w + positions_a[:, :, 1]).astype(np.int32)
    return multigrid.synthesize_positions(
        lambda lv, tick: _GuidedLevel(in_a, in_b, out_a[::2 ** lv, ::2 ** lv],
                                      flat_a[::2 ** lv, ::2 ** lv], offsets, 2 ** lv,
                                      exemplar_tiles, random_candidates, c),
        h * w, shapes, visits, rng, progress)
