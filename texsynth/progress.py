"""Progress reporting and cancellation shared by every method."""

from __future__ import annotations

from collections.abc import Callable

__all__ = ["Cancelled", "Progress"]


class Cancelled(Exception):
    """Raised by :func:`texsynth.synthesize` when the caller cancels; nothing is returned."""


class Progress:
    """Calls ``callback(fraction, message)``; a callback returning ``False`` (or raising
    :class:`Cancelled`) cancels the work.

    ``span(start, stop)`` gives a child whose 0..1 maps onto ``start..stop`` of this one, so a
    method can hand sub-steps their own scale (per channel, per level) without arithmetic.
    """

    def __init__(self, callback: Callable[[float, str], object] | None = None,
                 start: float = 0.0, stop: float = 1.0):
        self._callback = callback
        self._start = start
        self._stop = stop

    def __call__(self, fraction: float, message: str = "") -> None:
        if self._callback is None:
            return
        f = self._start + (self._stop - self._start) * min(max(fraction, 0.0), 1.0)
        if self._callback(f, message) is False:
            raise Cancelled("cancelled by the caller")

    def span(self, start: float, stop: float) -> Progress:
        width = self._stop - self._start
        return Progress(self._callback, self._start + width * start, self._start + width * stop)
