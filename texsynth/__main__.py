"""``python -m texsynth``: the ``texsynth`` command (:mod:`texsynth.cli`) without installing it.

A Ctrl+C while Python loads the package and the command ends as a later one does
(:mod:`texsynth.cli`): one line and exit status 130 (:mod:`texsynth.interrupts`; the package's
own imports watch themselves in its ``__init__``, the command's are watched here).
"""

import sys

from . import interrupts

if __name__ == "__main__":
    with interrupts.while_starting():
        from .cli import main
    sys.exit(main())
