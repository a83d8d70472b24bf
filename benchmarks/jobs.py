"""Runs in their own subprocess, kept on disk (the production and photos sections).

A run is ``python -m <module> RUN <args...> <out.npy>``: the child does the work, saves its
output with :func:`report` and prints one JSON line: its wall time, its own peak resident memory
(``VmHWM``, which sees numpy, FFTs and C code alike; not the parent's ``ru_maxrss`` of the child,
which starts from the parent's size at the fork) and whatever else it measured. :func:`run` keeps
that record beside the output in a cache folder (:func:`cache`), so an interrupted section picks
up where it stopped when re-run on the same library code.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from .context import REPO

_STATUS = Path("/proc/self/status")


def cache(kind: str) -> Path:
    """``build/<kind>/<tree>/``, ``<tree>`` the git hash of the committed ``texsynth/`` folder,
    where runs of this library code are kept (a fresh temporary folder when ``texsynth/`` has
    uncommitted changes)."""
    head = subprocess.run(["git", "rev-parse", "--short", "HEAD:texsynth"], capture_output=True,
                          text=True, cwd=REPO, check=False).stdout.strip()
    dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no", "texsynth"],
                           capture_output=True, text=True, cwd=REPO, check=False).stdout.strip()
    if not head or dirty:
        return Path(tempfile.mkdtemp(prefix=f"{kind}-"))
    path = REPO / "build" / kind / head
    path.mkdir(parents=True, exist_ok=True)
    return path


def status_mib(field: str) -> float:
    """A memory figure of this process from ``/proc/self/status`` (``VmHWM``, ``VmRSS``), MiB."""
    return int(re.search(rf"{field}:\s+(\d+)", _STATUS.read_text()).group(1)) / 1024


def reset_peak() -> float:
    """In the child, before the work: reset the peak resident memory to the present size (what
    was freed before, such as a large photo a crop was cut from, no longer counts); return that
    size, MiB."""
    Path("/proc/self/clear_refs").write_text("5")
    return status_mib("VmRSS")


def report(out: str, image: np.ndarray | None, **figures) -> None:
    """In the child: save ``image`` (as float32 RGB) to ``out`` and print ``figures`` and this
    process's peak resident memory (``rss``, MiB) as the run's JSON line."""
    if image is not None:
        np.save(out, np.asarray(image, np.float32)[:, :, :3])
    print(json.dumps({**figures, "rss": status_mib("VmHWM")}), flush=True)


def run(module: str, args: list[str], stem: Path, timeout: float | None = None,
        env: dict | None = None) -> dict:
    """The record of run ``stem``: the child's figures, its output as ``image`` when it saved
    one, or ``error`` (the last line of its stderr, or the time limit it hit); from the cache, or
    by running ``python -m module RUN *args stem.npy`` (stopped after ``timeout`` seconds;
    ``env`` entries added to its environment)."""
    out, record = stem.with_suffix(".npy"), stem.with_suffix(".json")
    if not record.exists():
        proc = subprocess.Popen([sys.executable, "-m", module, "RUN", *args, str(out)],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, cwd=REPO,
                                env={**os.environ, **(env or {})})
        try:
            stdout, stderr = proc.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.communicate()
            result = {"error": f"stopped at the time limit of {timeout:.0f} s", "limit": timeout}
        else:
            if proc.returncode:
                tail = stderr.decode(errors="replace").strip().splitlines()[-1:] or ["?"]
                result = {"error": tail[0]}
            else:
                result = json.loads(stdout.decode().strip().splitlines()[-1])
        record.write_text(json.dumps(result))
    result = json.loads(record.read_text())
    return {**result, "image": np.load(out)} if out.exists() else result
