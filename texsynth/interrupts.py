"""A Ctrl+C while the ``texsynth`` command starts ends as a later one does: one line, exit 130.

The command (``python -m texsynth``, or the installed ``texsynth``: ``texsynth_command``) spends
about a second importing numpy and scipy before :mod:`texsynth.cli` can catch anything. CPython
turns a SIGINT into a ``KeyboardInterrupt`` at the next bytecode, wherever that is, and there
three things can become of it: it propagates; numpy's own import code catches it and raises an
``ImportError`` that no longer names it (about 1 in 75 tries under load); or a library's
optional import takes it for a missing module and loading goes on (the run then finished and
wrote its output; threadpoolctl's walk over the loaded libraries, at the import of
``texsynth.blocks.parallel``, runs in a ctypes callback, which prints such an exception and
drops it). A handler that notes the signal and lets the imports finish (under a second) loses
nothing; :func:`while_starting` ends all three with the one line and ``os._exit(130)``
(not ``SystemExit``: a Ctrl+C that passed through an ``eval()`` of a string, namedtuple's in
scipy's imports, leaves CPython 3.11 marked to end by SIGINT whatever is raised after it: exit
-2 in about 1 of 20 tries under load). Only the command's start is watched: ``import texsynth``
in a script or in Blender raises ``KeyboardInterrupt`` as any import does, and a SIGINT ignored
(``nohup``, a shell's background job) stays ignored.
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading
from pathlib import Path

__all__ = ["while_starting", "starting_command", "MESSAGE"]

#: The one line a Ctrl+C during the start prints (the command's own, later, says the same).
MESSAGE = "texsynth: interrupted; nothing was written"


def starting_command() -> bool:
    """Whether this process is the ``texsynth`` command starting: ``python -m texsynth`` while
    Python imports the package (``sys.argv[0]`` is ``"-m"`` until ``__main__`` runs), or the
    installed entry point ``texsynth_command`` (imported by pip's script, or run as a file).

    Examples
    --------
    >>> starting_command()  # a doctest's process is not the command
    False
    """
    main = getattr(sys.modules.get("__main__"), "__file__", None) or ""
    return (sys.argv[:1] == ["-m"] or "texsynth_command" in sys.modules
            or Path(main).name == "texsynth_command.py")


def _watching() -> bool:
    """SIGINT is Python's default handler and can be replaced here (the main thread)."""
    return (threading.current_thread() is threading.main_thread()
            and signal.getsignal(signal.SIGINT) is signal.default_int_handler)


@contextlib.contextmanager
def while_starting(active: bool = True):
    """Run the ``with`` block's imports so that a Ctrl+C during them, however the libraries
    pass it on, prints :data:`MESSAGE` and ends the process with status 130; when ``active``
    is false, or SIGINT is not Python's default handler (ignored, or the caller's own), the
    block runs as it is.

    Examples
    --------
    >>> with while_starting(active=False):
    ...     import json
    >>> json.dumps([1])
    '[1]'
    """
    noted = []

    def note(signum, frame):  # no exception inside the imports: none to lose or to print
        noted.append(signum)

    watch = active and _watching()
    if watch:
        signal.signal(signal.SIGINT, note)
    try:
        yield
    except (KeyboardInterrupt, ImportError):
        if not (watch and noted):
            raise
        _interrupted()
    finally:
        if watch:
            signal.signal(signal.SIGINT, signal.default_int_handler)
    if noted:  # taken by a library's optional import for a missing module
        _interrupted()


def _interrupted():
    print(MESSAGE, file=sys.stderr, flush=True)
    os._exit(130)  # nothing is open to flush but stderr
