"""Long work for an operator: a :class:`Task` (numpy only, never bpy) and
:class:`JobOperator`.

``JobOperator.execute()`` runs the job synchronously: in background mode (``blender -b``, the
bpy module), from scripts and from the redo panel. ``invoke()`` (a panel's button) in the UI runs
it in a worker thread while a modal timer shows progress; Esc or right-click cancels. Every check
happens in ``prepare`` before anything is made, and ``make`` makes the new datablocks on the main
thread only after the work succeeded: on error or cancel the file is unchanged.
"""

import threading
import traceback

import bpy

from .. import texsynth
from ..texsynth.blocks.parallel import serial_blas
from ..texsynth.progress import TimeLeft
from . import output

POLL_SECONDS = 0.1


class Task:
    """Runs ``function(*args, progress=..., **kwargs)`` and keeps its progress, result, error or
    cancellation; ``predicted`` (seconds, ``texsynth.budget.forecast``) starts the time left.

    The main thread reads ``fraction``/``message`` while the worker runs and calls
    :meth:`cancel` to stop it: the progress callback then returns False, ``function`` raises
    ``texsynth.Cancelled`` and no result is kept.
    """

    def __init__(self, function, *args, predicted: float | None = None, **kwargs):
        self._call = (function, args, kwargs)
        self._cancel = threading.Event()
        self._thread = None
        self.fraction = 0.0
        self.message = "Starting"
        self.result = None
        self.error = None
        self.cancelled = False
        self.left = TimeLeft(predicted)

    def time_left(self, now: float | None = None) -> str:
        """The time still to go (", 3:00 left"), told as the command line's bar tells it
        (``texsynth.progress.TimeLeft.text``), or "" while there is nothing to go on."""
        told = self.left.text(self.fraction, now)
        return f", {told}" if told else ""

    def run(self) -> None:
        function, args, kwargs = self._call
        try:
            with serial_blas():  # every operator's work, the core's entries or not
                self.result = function(*args, progress=self._progress, **kwargs)
        except texsynth.Cancelled:
            self.cancelled = True
        except Exception as error:  # reported on the main thread, where bpy can be used
            self.error = error

    def start(self) -> None:
        self.left.restart()
        self._thread = threading.Thread(target=self.run, name="texsynth", daemon=True)
        self._thread.start()

    def cancel(self) -> None:
        self._cancel.set()

    @property
    def cancelling(self) -> bool:
        """Cancel was asked for (the worker may still be finishing its step)."""
        return self._cancel.is_set()

    @property
    def done(self) -> bool:
        return self._thread is not None and not self._thread.is_alive()

    def _progress(self, fraction: float, message: str) -> bool:
        self.fraction, self.message = fraction, message
        return not self._cancel.is_set()


class JobOperator:
    """Mixin for an operator (``class X(JobOperator, bpy.types.Operator)``) whose work is a
    :class:`Task`.

    The operator defines ``prepare(context) -> (job, plan)``, which checks everything and copies
    the pixels out of Blender (raising ``ValueError``), and ``make(result, plan) -> str``, which
    makes the new datablocks from the job's result and returns the message to report (raising
    ``ValueError`` or ``OSError``). :meth:`target` reads the operator's ``output``,
    ``output_dir`` and ``seed`` (added by ``properties.registry_settings``).
    """

    def execute(self, context):
        try:
            job, plan = self.prepare(context)
        except ValueError as error:
            return self._fail(error)
        job.run()
        return self._finish(job, plan)

    def invoke(self, context, event):
        if bpy.app.background:
            return self.execute(context)
        try:
            self._job, self._plan = self.prepare(context)
        except ValueError as error:
            return self._fail(error)
        self._job.start()
        wm = context.window_manager
        wm.progress_begin(0.0, 1.0)
        self._timer = wm.event_timer_add(POLL_SECONDS, window=context.window)
        wm.modal_handler_add(self)
        context.workspace.status_text_set("TexSynth: starting (Esc to cancel)")
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        job = self._job
        if event.type in {"ESC", "RIGHTMOUSE"} and event.value == "PRESS":
            job.cancel()  # the worker stops at its next progress report
            context.workspace.status_text_set("TexSynth: cancelling")
            return {"RUNNING_MODAL"}
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        if not job.done:
            context.window_manager.progress_update(job.fraction)
            context.workspace.status_text_set(
                "TexSynth: cancelling" if job.cancelling else
                f"TexSynth: {job.message} ({job.fraction:.0%}{job.time_left()}); Esc to cancel")
            return {"PASS_THROUGH"}
        self._end_ui(context)
        return self._finish(job, self._plan)

    def cancel(self, context):
        self._job.cancel()
        self._end_ui(context)

    def target(self, image_name: str, method_name: str) -> output.Target:
        """Where the result for ``image_name`` goes, from the operator's output settings."""
        return output.plan(self.output, self.output_dir, image_name, method_name, self.seed)

    def _end_ui(self, context):
        wm = context.window_manager
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        context.workspace.status_text_set(None)

    def _finish(self, job, plan):
        """Make the new datablocks from a finished job (main thread)."""
        if job.cancelled:
            self.report({"INFO"}, f"{self.bl_label}: cancelled, nothing was created")
            return {"CANCELLED"}
        if job.error is not None:
            return self._fail(job.error)
        try:
            message = self.make(job.result, plan)
        except (ValueError, OSError) as error:
            return self._fail(error)
        self.report({"INFO"}, message)
        return {"FINISHED"}

    def _fail(self, error):
        if not isinstance(error, (ValueError, OSError)):
            traceback.print_exception(error)
            error = f"{type(error).__name__}: {error}"
        self.report({"ERROR"}, str(error))
        return {"CANCELLED"}
