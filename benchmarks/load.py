"""A known load beside a measurement: ``with busy(n):`` runs ``n`` busy loops (one process each,
``nice -n 0``: as much priority as the work measured) and stops them, by their own ids, after.

The machine's own load comes on top; a section that measures under load reports
``os.getloadavg`` beside its figures and compares ratios taken in the same process.
"""

from __future__ import annotations

import contextlib
import subprocess
import sys
import time

LOOP = "while True: pass"


@contextlib.contextmanager
def busy(n: int, settle: float = 0.5):
    """``n`` busy-loop processes for the duration of the ``with`` block."""
    loops = [subprocess.Popen(["nice", "-n", "0", sys.executable, "-c", LOOP])
             for _ in range(n)]
    try:
        time.sleep(settle if n else 0.0)
        yield loops
    finally:
        for loop in loops:
            loop.kill()
        for loop in loops:
            loop.wait()
