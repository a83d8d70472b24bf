"""Progress reporting and cancellation shared by every method, and the time left from it."""

from __future__ import annotations

import time
from collections.abc import Callable

__all__ = ["Cancelled", "Progress", "TimeLeft"]


class Cancelled(Exception):
    """Raised by :func:`texsynth.synthesize` when the caller cancels; nothing is returned.

    Parameters
    ----------
    *args : object
        The message, as for any exception (``"cancelled by the caller"``).

    References
    ----------
    docs/ARCHITECTURE.md, Conventions, "Progress" (nothing half-made is returned).

    Examples
    --------
    >>> import numpy as np, texsynth
    >>> photo = np.random.default_rng(0).random((16, 16, 3), dtype=np.float32)
    >>> try:
    ...     texsynth.synthesize(photo, 16, 16, progress=lambda fraction, message: False)
    ... except texsynth.Cancelled as cancelled:
    ...     print(cancelled)
    cancelled by the caller
    """


class Progress:
    """Calls ``callback(fraction, message)``; a callback returning ``False`` (or raising
    :class:`Cancelled`) cancels the work.

    ``span(start, stop)`` gives a child whose 0..1 maps onto ``start..stop`` of this one, so a
    method can hand sub-steps their own scale (per channel, per level) without arithmetic.

    Parameters
    ----------
    callback : callable(fraction, message), optional
        Told the fraction done (0..1) and what is being done; None: nothing is reported.
    start, stop : float
        The part of the callback's 0..1 that this reporter's 0..1 covers.

    References
    ----------
    docs/ARCHITECTURE.md, Conventions, "Progress" (fractions follow the time).

    Examples
    --------
    >>> seen = []
    >>> half = Progress(lambda fraction, message: seen.append((fraction, message)), 0.5, 1.0)
    >>> half.span(0.0, 0.5)(0.5, "level 2")
    >>> seen
    [(0.625, 'level 2')]
    """

    def __init__(self, callback: Callable[[float, str], object] | None = None,
                 start: float = 0.0, stop: float = 1.0):
        self._callback = callback
        self._start = start
        self._stop = stop

    def __call__(self, fraction: float, message: str = "") -> None:
        if self._callback is None:
            return
        # the end exactly: start + (stop - start) can be an ulp past stop, and the next span's
        # first report, at stop, would then read as a step back
        f = self._stop if fraction >= 1.0 else \
            self._start + (self._stop - self._start) * max(fraction, 0.0)
        if self._callback(f, message) is False:
            raise Cancelled("cancelled by the caller")

    def span(self, start: float, stop: float) -> Progress:
        width = self._stop - self._start
        return Progress(self._callback, self._start + width * start, self._start + width * stop)


class TimeLeft:
    """Seconds still to go of a run that reports fractions done, from its start on ``clock``.

    Rule: seconds per whole run = (elapsed + PRIOR x predicted) / (fraction + PRIOR), the
    prediction counting as ``PRIOR`` of the run already seen; left = that x (1 - fraction).
    Without a prediction it is elapsed x (1 - f) / f, from ``MIN_FRACTION`` on; before the
    first fraction, the prediction counted down. Ours: an extrapolation that starts from the
    cost model (``texsynth.budget.forecast``) and moves to the observed rate as the run goes.

    Examples
    --------
    >>> now = [0.0]
    >>> left = TimeLeft(predicted=100.0, clock=lambda: now[0])
    >>> now[0] = 20.0
    >>> round(left.seconds(0.1))   # 10 % in 20 s: about 200 s in all, the prediction 100 s
    172
    >>> round(TimeLeft(clock=lambda: now[0]).seconds(0.1, now=40.0))   # 10 % in 20 s
    180
    """

    #: How much of the run the prediction counts as, already seen: 0.02 -> 0.01 (issue 40: with
    #: the fractions following the work, the prediction's spread across photos weighs more,
    #: composite 128 -> 256 predicted 3.6x its 1.6 s on the brick, where its segmentation finds
    #: fewer classes, read 1.48 at 10 % with 0.02, 1.29 with 0.01; no other run moved out).
    PRIOR = 0.01
    #: The fraction from which an estimate without a prediction is given.
    MIN_FRACTION = 0.01

    def __init__(self, predicted: float | None = None,
                 clock: Callable[[], float] = time.monotonic):
        self.predicted = predicted
        self.clock = clock
        self.start = clock()

    def restart(self) -> None:
        """The run starts now."""
        self.start = self.clock()

    def seconds(self, fraction: float, now: float | None = None) -> float | None:
        """Seconds left at ``fraction`` done (0..1), seen at ``now`` (default: the clock);
        None when there is nothing to go on yet, 0 when done."""
        f = min(max(float(fraction), 0.0), 1.0)
        elapsed = max((self.clock() if now is None else now) - self.start, 0.0)
        if f >= 1.0:
            return 0.0
        if self.predicted is None:
            return elapsed * (1.0 - f) / f if f >= self.MIN_FRACTION else None
        if f == 0.0:
            return max(self.predicted - elapsed, 0.0)
        return (elapsed + self.PRIOR * self.predicted) / (f + self.PRIOR) * (1.0 - f)

    def text(self, fraction: float, now: float | None = None) -> str:
        """The time left as the command line's bar and Blender's status line show it:
        ``"2:05 left"`` (``"1:02:05 left"`` past an hour), or "" while :meth:`seconds` has
        nothing to go on and once done.

        Examples
        --------
        >>> left = TimeLeft(predicted=125.0, clock=lambda: 0.0)
        >>> left.text(0.0), left.text(1.0)
        ('2:05 left', '')
        """
        seconds = self.seconds(fraction, now)
        if seconds is None or fraction >= 1.0:
            return ""
        h, rest = divmod(int(round(seconds)), 3600)
        clock = f"{h}:{rest // 60:02d}:{rest % 60:02d}" if h else f"{rest // 60}:{rest % 60:02d}"
        return f"{clock} left"
