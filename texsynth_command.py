"""The installed ``texsynth`` command's entry point, outside the package on purpose.

Importing :mod:`texsynth` loads numpy and scipy for about a second; a Ctrl+C in that second
would end in Python's traceback. Here it ends as a Ctrl+C later does (:mod:`texsynth.cli`): one
line and exit status 130 (:mod:`texsynth.interrupts`: the package watches its own imports when this
module is loaded, and this one the command's).
"""

import sys


def main() -> int:
    from texsynth import interrupts  # the package's imports watch themselves (starting_command)

    with interrupts.while_starting():
        from texsynth.cli import main as run
    return run()


if __name__ == "__main__":
    sys.exit(main())
