"""The installed ``texsynth`` command's entry point, outside the package on purpose.

Importing :mod:`texsynth` loads numpy and scipy for about a second; a Ctrl+C in that second
would end in Python's traceback. Here it ends as a Ctrl+C later does (:mod:`texsynth.cli`): one
line and exit status 130.
"""

import sys


def main() -> int:
    try:
        from texsynth.cli import main as run
    except KeyboardInterrupt:
        print("texsynth: interrupted; nothing was written", file=sys.stderr)
        return 130
    return run()


if __name__ == "__main__":
    sys.exit(main())
