"""Numerical search helpers shared by the texture fit and the combination with lines."""

from __future__ import annotations

import numpy as np
import scipy.optimize as opt

__all__ = ["minimize", "hessian"]


def minimize(fun, starts, step):
    """Nelder-Mead from each start; the best result."""
    best = None
    for x0 in starts:
        x0 = np.asarray(x0, dtype=np.float64)
        simplex = np.vstack([x0, x0 + np.diag(np.broadcast_to(step, x0.shape))])
        res = opt.minimize(fun, x0, method="Nelder-Mead",
                           options={"initial_simplex": simplex, "xatol": 2e-3, "fatol": 1e-4,
                                    "maxfev": 300})
        if best is None or res.fun < best.fun:
            best = res
    return best


def hessian(fun, x: np.ndarray, step: np.ndarray) -> np.ndarray:
    """Central finite-difference Hessian of ``fun`` at ``x``."""
    n = len(x)
    f0 = fun(x)
    hess = np.zeros((n, n))
    for i in range(n):
        ei = np.zeros(n)
        ei[i] = step[i]
        hess[i, i] = (fun(x + ei) - 2 * f0 + fun(x - ei)) / step[i] ** 2
        for j in range(i):
            ej = np.zeros(n)
            ej[j] = step[j]
            hess[i, j] = hess[j, i] = (fun(x + ei + ej) - fun(x + ei - ej) - fun(x - ei + ej)
                                       + fun(x - ei - ej)) / (4 * step[i] * step[j])
    return hess
