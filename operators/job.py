"""One synthesis, run in the caller's thread or in a worker thread (numpy only, never bpy)."""

import threading

from .. import texsynth


class Job:
    """Runs ``texsynth.synthesize`` and keeps its progress, result, error or cancellation.

    The main thread reads ``fraction``/``message`` while the worker runs and calls
    :meth:`cancel` to stop it: the progress callback then returns False, ``synthesize`` raises
    ``texsynth.Cancelled`` and no result is kept.
    """

    def __init__(self, exemplar, width, height, method, seed, params):
        self._call = (exemplar, width, height, method, seed, params)
        self._cancel = threading.Event()
        self._thread = None
        self.fraction = 0.0
        self.message = "Starting"
        self.result = None
        self.error = None
        self.cancelled = False

    def run(self) -> None:
        exemplar, width, height, method, seed, params = self._call
        try:
            self.result = texsynth.synthesize(exemplar, width, height, method=method, seed=seed,
                                              progress=self._progress, **params)
        except texsynth.Cancelled:
            self.cancelled = True
        except Exception as error:  # reported on the main thread, where bpy can be used
            self.error = error

    def start(self) -> None:
        self._thread = threading.Thread(target=self.run, name="texsynth", daemon=True)
        self._thread.start()

    def cancel(self) -> None:
        self._cancel.set()

    @property
    def done(self) -> bool:
        return self._thread is not None and not self._thread.is_alive()

    def _progress(self, fraction: float, message: str) -> bool:
        self.fraction, self.message = fraction, message
        return not self._cancel.is_set()
