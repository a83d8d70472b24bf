"""python -m benchmarks [--quick] [--only NAME ...]: run the sections, write docs/BENCHMARKS.md."""

from __future__ import annotations

import argparse
import importlib
import os
import pkgutil
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import scipy

from .context import REPO, SHARED_TEXTURES, Context

DOCS = REPO / "docs"
REQUIREMENTS = Path(__file__).with_name("requirements.txt")


def install_peers() -> None:
    """The peers are the benchmark's own requirements: install them into this interpreter."""
    subprocess.run([sys.executable, "-m", "pip", "install", "-q", "-r", str(REQUIREMENTS)],
                   check=False)
    if not any((Path(p) / "gmic").exists() for p in os.environ.get("PATH", "").split(":")):
        apt = ["apt-get", "install", "-y", "-q", "--no-install-recommends", "gmic"]
        if subprocess.run(apt, check=False, capture_output=True).returncode:
            subprocess.run(["apt-get", "update", "-q"], check=False, capture_output=True)
            subprocess.run(apt, check=False, capture_output=True)


def machine() -> str:
    cpu = next((line.split(":", 1)[1].strip() for line in
                Path("/proc/cpuinfo").read_text().splitlines() if line.startswith("model name")),
               platform.processor() or "unknown CPU") if Path("/proc/cpuinfo").exists() else "?"
    ram = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2**30
    return f"{os.cpu_count()} cores, {cpu}, {ram:.0f} GiB RAM, {platform.platform()}"


def versions() -> str:
    found = [f"Python {platform.python_version()}", f"numpy {np.__version__}",
             f"scipy {scipy.__version__}"]
    for name in ("pyrtools", "resynthesizer"):
        try:
            from importlib.metadata import version
            found.append(f"{name} {version(name)}")
        except Exception:  # a missing peer is reported by its section
            pass
    gmic = subprocess.run(["dpkg-query", "-W", "-f", "${Version}", "gmic"], capture_output=True,
                          text=True, check=False)
    if gmic.returncode == 0:
        found.append(f"gmic {gmic.stdout}")
    return ", ".join(found)


def sections():
    from . import sections as package

    modules = [importlib.import_module(f"{package.__name__}.{m.name}")
               for m in pkgutil.iter_modules(package.__path__)]
    return sorted(modules, key=lambda m: m.ORDER)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true", help="a small subset, for development")
    parser.add_argument("--only", nargs="*", default=None, help="section module names to run")
    parser.add_argument("--no-install", action="store_true", help="do not pip/apt install peers")
    args = parser.parse_args()
    if not args.no_install:
        install_peers()
    ctx = Context(quick=args.quick, img_dir=DOCS / "img")
    source = (f"the {len(ctx.textures)} textures of ../shared/textures (MANIFEST.tsv)"
              if SHARED_TEXTURES.exists() else "the bundled sample only (../shared is absent)")
    parts = [
        "# Benchmarks",
        "",
        f"Written by `python -m benchmarks{' --quick' if args.quick else ''}` on "
        f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}. Do not edit by hand.",
        "",
        f"- Machine: {machine()}. Shared and noisy: read ratios between rows measured in this "
        "same run, not bare times.",
        f"- Versions: {versions()}.",
        f"- Inputs: {source}{'; quick mode: a subset' if args.quick else ''}.",
        "- Times are wall-clock medians (range in brackets) of repeated calls in this process; "
        "peak memory is tracemalloc's peak (numpy buffers included) over the call, and where "
        "said the growth of the process's resident high-water mark (which sees C code).",
        f"- Load average when the run started: {os.getloadavg()[0]:.1f} on {os.cpu_count()} "
        "cores.",
        "",
    ]
    out = DOCS / ("BENCHMARKS.md" if args.only is None else "BENCHMARKS.partial.md")
    run_start = time.perf_counter()
    for module in sections():
        if args.only is not None and module.__name__.rsplit(".", 1)[1] not in args.only:
            continue
        print(f"== {module.TITLE}", flush=True)
        start = time.perf_counter()
        body = module.run(ctx)
        parts += [f"## {module.TITLE}", "", body.strip(), "",
                  f"*Section time: {time.perf_counter() - start:.0f} s.*", ""]
        out.write_text("\n".join(parts + ["*(run in progress)*", ""]))  # kept if interrupted
    parts.append(f"*Whole run: {(time.perf_counter() - run_start) / 60:.1f} min.*")
    out.write_text("\n".join(parts) + "\n")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
