"""Consistent synthesis of a stack of registered maps or views, guided by a support view.

Neubeck, Zalesny & Van Gool 2004, sections 2.3 and 3.2. A stack holds V registered images
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

from .. import budget, validation
from ..algorithms import multiscale_mrf
from ..api import synthesize_positions
from ..blocks.parallel import serial_blas
from ..blocks.search import disk_offsets
from ..positions import apply_positions
from .guided import C_SUPPORT, guided_mrf

__all__ = ["synthesize_stack", "validate_stack", "C_SUPPORT"]


def validate_stack(stack, support: int) -> list[np.ndarray]:
    """The views as float32 (H, W, C) arrays of one size, or ``ValueError`` saying what is wrong."""
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
        out.append(validation.image(image, what=f"view {v}"))
    sizes = {a.shape[:2] for a in out}
    if len(sizes) > 1:
        listed = ", ".join(f"{a.shape[1]} x {a.shape[0]}" for a in out)
        raise ValueError(f"every view of a stack must have the same size (registered maps of "
                         f"one sample); got {listed}")
    return out


@serial_blas()
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
    width, height : int
        Output size of every view.
    support : int
        Index of the support view, synthesized first with ``method``.
    method : str
        A method with position maps (``multiscale_mrf``, ``efros_leung``) for the support.
    seed : int
        Same inputs and seed give bit-identical output.
    progress : callable(fraction, message), optional
        As for :func:`texsynth.synthesize`; returning ``False`` cancels.
    mode : "guided" or "column"
        ``guided``: each other view synthesized with the section 3.2 distance (``multiscale_mrf``
        parameters among ``params`` apply to it); ``column``: the support's position map copied to
        every view.
    c : float
        Weight of the support term in the guided distance, 0 to 1.
    **params
        The support method's parameters.

    Returns
    -------
    numpy.ndarray or list
        float32 (V, height, width, C) for an array stack, a list of (height, width, C_v) for a
        list.

    References
    ----------
    Neubeck, Zalesny & Van Gool 2004, section 3.2 (the guided distance, with the confidences
    of eq. 1-2) and section 2.3 (whole columns copied: ``mode="column"``).

    Examples
    --------
    >>> import numpy as np
    >>> colour = np.random.default_rng(0).random((16, 16, 3), dtype=np.float32)
    >>> maps = synthesize_stack(np.stack([colour, 1 - colour]), 24, 24, mode="column")
    >>> maps.shape, bool(np.allclose(maps[1], 1 - maps[0]))
    ((2, 24, 24, 3), True)
    """
    if mode not in ("guided", "column"):
        raise ValueError(f"mode must be 'guided' or 'column', got {mode!r}")
    c = validation.number(c, "c", 0.0, 1.0)
    width, height = validation.size(width, height)
    seed = validation.seed(seed)
    views = validate_stack(stack, support)
    support = support % len(views)
    mrf = multiscale_mrf.METHOD
    mrf_params = mrf.resolve({k: v for k, v in params.items()
                              if k in {p.name for p in mrf.params}})
    # the other views follow the support's joints through its positions: no feature channel
    guided_params = {k: v for k, v in mrf_params.items()
                     if k not in ("joint_width", "feature_weight")}
    if mode == "guided":
        # each guided view costs about one multiscale_mrf run (the support's is checked by
        # synthesize_positions)
        budget.admit(f"guided synthesis of {len(views)} maps of {width} x {height}",
                     peak=_memory(views, support, width, height, mrf_params),
                     seconds=len(views) * budget.predict(mrf, views[support].shape, width,
                                                         height, mrf_params),
                     memory_advice="use mode='column'", time_advice="mode='column'")
    _, report = budget.start(seed, progress)
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
        # huge or tiny values are compared at an exact power-of-two scale, as in synthesize
        a_in, b_in = validation.ordinary(views[support]), validation.ordinary(views[v])
        a_out = validation.ordinary(image_a, validation.magnitude_scale(views[support]))
        flat = guided_mrf(a_in, b_in, a_out, positions, rng, span, c, **guided_params)
        h, w = views[v].shape[:2]
        out[v] = views[v].reshape(h * w, -1)[flat]
    report(1.0, "stack: done")
    if isinstance(stack, np.ndarray):
        return np.stack(out)
    return out


def _memory(views, support, width, height, params) -> float:
    """Peak bytes of the largest guided view: its exemplar table (K (C_B + 1) + (K + 1)
    (C_A + 1) floats a pixel), maps and batch."""
    h, w = views[support].shape[:2]
    k = len(disk_offsets(params["radius"]))
    c_a = views[support].shape[2]
    c_b = max((v.shape[2] for i, v in enumerate(views) if i != support), default=0)
    table = h * w * 4 * (k * (c_b + 1) + (k + 1) * (c_a + 1))
    maps = width * height * (4 * c_a + 4 + 2 + 4 + 4 + 4 * c_b)
    batch = width * height / (params["radius"] + 1) ** 2 * (k + 1) * (40 + 4 * c_a)
    return table + maps + batch
