"""Numerical search helpers shared by the texture fit and the combination with lines.

Independent evaluations (a grid of hypotheses, the points of a finite-difference Hessian, the
starts of a search) run side by side on the shared pool (``texsynth.blocks.parallel``): the
criteria spend their time in numpy, which releases the interpreter lock, so a photo's estimate
uses every core. Results do not depend on it (each evaluation is the same pure function; results
are gathered in order).
"""

from __future__ import annotations

import numpy as np
import scipy.optimize as opt

from ..blocks import parallel

__all__ = ["evaluate", "minimize", "hessian"]


def evaluate(fun, points) -> list[float]:
    """fun at each of ``points``, in order."""
    return parallel.run(fun, points)


def _nelder_mead(fun, x0, step, xatol, fatol):
    x0 = np.asarray(x0, dtype=np.float64)
    simplex = np.vstack([x0, x0 + np.diag(np.broadcast_to(step, x0.shape))])
    return opt.minimize(fun, x0, method="Nelder-Mead",
                        options={"initial_simplex": simplex, "xatol": xatol, "fatol": fatol,
                                 "maxfev": 300})


def minimize(fun, starts, step, xatol: float = 2e-3, fatol: float = 1e-4):
    """Nelder-Mead from each start; the best result (the first of equals). It stops once the
    simplex is within ``xatol`` of its best vertex and its values within ``fatol``: a search
    that needs the minimum's value and not where it lies may take wider tolerances."""
    results = parallel.run(lambda x0: _nelder_mead(fun, x0, step, xatol, fatol), starts)
    best = results[0]
    for res in results[1:]:
        if res.fun < best.fun:
            best = res
    return best


def hessian(fun, x: np.ndarray, step: np.ndarray) -> np.ndarray:
    """Central finite-difference Hessian of ``fun`` at ``x``."""
    n = len(x)
    e = np.diag(np.asarray(step, dtype=np.float64) * np.ones(n))
    pairs = [(i, j) for i in range(n) for j in range(i)]
    points = [x] + [x + s * e[i] for i in range(n) for s in (1, -1)] + [
        x + si * e[i] + sj * e[j] for i, j in pairs for si, sj in ((1, 1), (1, -1), (-1, 1),
                                                                     (-1, -1))]
    values = evaluate(fun, points)
    f0, diagonal, mixed = values[0], values[1:1 + 2 * n], values[1 + 2 * n:]
    hess = np.zeros((n, n))
    for i in range(n):
        hess[i, i] = (diagonal[2 * i] - 2 * f0 + diagonal[2 * i + 1]) / step[i] ** 2
    for k, (i, j) in enumerate(pairs):
        a, b, c, d = mixed[4 * k:4 * k + 4]
        hess[i, j] = hess[j, i] = (a - b - c + d) / (4 * step[i] * step[j])
    return hess
