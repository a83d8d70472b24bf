"""``python -m texsynth``: the ``texsynth`` command (:mod:`texsynth.cli`) without installing it."""

import sys

from .cli import main

if __name__ == "__main__":
    sys.exit(main())
