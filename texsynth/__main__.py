"""``python -m texsynth``: the ``texsynth`` command (:mod:`texsynth.cli`) without installing it.

A Ctrl+C while Python loads the package and the command ends as a later one does
(:mod:`texsynth.cli`): one line and exit status 130 (the package's own imports: its
``__init__``; the command's: here).
"""

import os
import sys

if __name__ == "__main__":
    try:
        from .cli import main
    except KeyboardInterrupt:
        print("texsynth: interrupted; nothing was written", file=sys.stderr, flush=True)
        os._exit(130)  # as the package's own imports end (texsynth/__init__.py says why)
    sys.exit(main())
