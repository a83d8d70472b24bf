"""python -m benchmarks [--quick] [--only NAME ...]: run the sections, write docs/BENCHMARKS.md.

``--quick`` writes build/benchmarks-quick/ instead, so it never replaces the committed figures.

``--only`` runs the named sections (module names) and keeps the others from the existing file.
``--pages`` runs nothing and rewrites the README's and the docs pages' blocks alone.

Then the figures of README.md and the docs/ pages are written from docs/BENCHMARKS.md: between
``<!-- benchmark:SECTION TABLE [COLUMN | COLUMN ...] [; COLUMN = VALUE] -->`` and
``<!-- /benchmark -->`` goes the TABLE-th table (from 1) of the section that the module
``benchmarks/sections/SECTION.py`` writes, with the named columns only (all when none are named),
the rows whose COLUMN reads VALUE only (all without it), and a line naming the section and when it
ran (links are to docs/BENCHMARKS.md from the page's folder). Nothing else in README.md and the
user's pages is a measured figure (tests/test_docs.py holds it).
"""

from __future__ import annotations

import argparse
import ast
import importlib
import os
import pkgutil
import platform
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import scipy

from .context import REPO, SHARED_TEXTURES, Context

DOCS = REPO / "docs"
README = REPO / "README.md"
QUICK_DOCS = REPO / "build" / "benchmarks-quick"
REQUIREMENTS = Path(__file__).with_name("requirements.txt")


#: Peers that are programs: (program on the PATH, Debian package).
PROGRAMS = (("gmic", "gmic"), ("gimp-console-2.10", "gimp"))


def install_peers() -> None:
    """The peers are the benchmark's own requirements: install them into this interpreter, and
    the programs (G'MIC, GIMP for its Make Seamless) with apt."""
    subprocess.run([sys.executable, "-m", "pip", "install", "-q", "-r", str(REQUIREMENTS)],
                   check=False)
    missing = [package for program, package in PROGRAMS if shutil.which(program) is None]
    if missing:
        apt = ["apt-get", "install", "-y", "-q", "--no-install-recommends", *missing]
        env = {**os.environ, "DEBIAN_FRONTEND": "noninteractive"}
        if subprocess.run(apt, check=False, capture_output=True, env=env).returncode:
            subprocess.run(["apt-get", "update", "-q"], check=False, capture_output=True)
            subprocess.run(apt, check=False, capture_output=True, env=env)


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
    for _, package in PROGRAMS:
        dpkg = subprocess.run(["dpkg-query", "-W", "-f", "${Version}", package],
                              capture_output=True, text=True, check=False)
        if dpkg.returncode == 0 and dpkg.stdout:
            found.append(f"{package} {dpkg.stdout}")
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
    parser.add_argument("--pages", action="store_true",
                        help="run nothing: rewrite the benchmark blocks of README.md and docs/")
    args = parser.parse_args()
    if args.pages:
        return write_pages(DOCS / "BENCHMARKS.md")
    if not args.no_install:
        install_peers()
    docs = QUICK_DOCS if args.quick else DOCS  # a quick run never replaces the committed figures
    ctx = Context(quick=args.quick, img_dir=docs / "img")
    source = (f"the {len(ctx.textures)} textures of ../shared/textures (MANIFEST.tsv)"
              if SHARED_TEXTURES.exists() else "the bundled sample only (../shared is absent)")
    parts = [
        "# Benchmarks",
        "",
        f"Written by `python -m benchmarks{' --quick' if args.quick else ''}`; each section "
        "says when it ran (`--only NAME ...` re-runs some sections and keeps the others). "
        "Do not edit by hand.",
        "",
        f"- Machine: {machine()}. Shared and noisy: read ratios between rows measured in this "
        "same run, not bare times.",
        f"- Versions: {versions()}.",
        f"- Inputs: {source}{'; quick mode: a subset' if args.quick else ''}.",
        "- Times are wall-clock medians (range in brackets) of repeated calls in this process; "
        "peak memory is tracemalloc's peak (numpy buffers included) over the call, and where "
        "said the growth of the process's resident high-water mark (which sees C code).",
        "",
    ]
    out = docs / "BENCHMARKS.md"
    run_start = time.perf_counter()
    done = {}
    for module in sections():
        if args.only is not None and module.__name__.rsplit(".", 1)[1] not in args.only:
            continue
        print(f"== {module.TITLE}", flush=True)
        start, load = time.perf_counter(), os.getloadavg()[0]
        body = module.run(ctx)
        done[module.TITLE] = "\n".join([
            f"## {module.TITLE}", "", body.strip(), "",
            f"*Section time: {time.perf_counter() - start:.0f} s; finished "
            f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, load average {load:.1f} at "
            "its start.*", ""])
        out.write_text(_document(parts, _kept(out, args.only), done)
                       + "*(run in progress)*\n")  # kept if interrupted
    minutes = (time.perf_counter() - run_start) / 60
    footer = f"*Whole run: {minutes:.1f} min.*" if args.only is None else ""
    out.write_text(_document(parts, _kept(out, args.only), done) + footer + "\n")
    print(f"wrote {out}")
    if not args.quick:
        write_pages(out)


def _kept(out: Path, only) -> dict[str, str]:
    """With ``--only``, the other sections as the file holds them now (read at every write, so
    that runs of different sections at the same time do not undo each other)."""
    return _sections_of(out.read_text()) if only is not None and out.exists() else {}


def _sections_of(text: str) -> dict[str, str]:
    """The ``## Title`` sections of an earlier BENCHMARKS.md, by title (for ``--only``)."""
    found = {}
    for chunk in text.split("\n## ")[1:]:
        title = chunk.split("\n", 1)[0].strip()
        body = chunk.split("\n*Whole run:")[0].split("\n*(run in progress)*")[0]
        found[title] = "## " + body.rstrip() + "\n"
    return found


def _document(header: list[str], kept: dict[str, str], done: dict[str, str]) -> str:
    """Header, then every section in ``ORDER``: this run's where it ran, else the earlier one."""
    titles = [m.TITLE for m in sections()]
    body = [done.get(t) or kept.get(t) for t in titles]
    return "\n".join(header) + "\n" + "\n".join(b for b in body if b) + "\n"


#: A README block: its opening marker (section module, table number, columns), body, closing marker.
BLOCK = re.compile(r"(<!-- benchmark:(\w+) (\d+)([^\n]*?) -->\n)(.*?)(<!-- /benchmark -->)",
                   re.S)


def write_pages(benchmarks: Path) -> None:
    """Rewrite the benchmark blocks of every page from ``benchmarks`` (docs/BENCHMARKS.md)."""
    for page in pages():
        text = page.read_text()
        filled = fill_blocks(text, benchmarks.read_text(), page.relative_to(REPO))
        if filled != text:
            page.write_text(filled)
            print(f"wrote the benchmark blocks of {page}")


def pages() -> list[Path]:
    """The pages that may hold benchmark blocks: README.md and docs/ but BENCHMARKS.md."""
    return [README, *sorted(p for p in DOCS.glob("*.md") if p.name != "BENCHMARKS.md")]


def fill_blocks(page: str, benchmarks: str, where: Path = Path("README.md")) -> str:
    """``page`` (at ``where`` in the repository) with every benchmark block rewritten from
    ``benchmarks``, the text of docs/BENCHMARKS.md."""
    titles = _titles()
    found = _sections_of(benchmarks)

    def block(match: re.Match) -> str:
        opening, name, number, columns, _, closing = match.groups()
        if name not in titles:
            raise SystemExit(f"{where}: no benchmark section module {name!r}")
        title = titles[name]
        text = found.get(title)
        if text is None:
            return f"{opening}*Not measured yet: `python -m benchmarks --only {name}`.*\n{closing}"
        tables = _tables(text)
        if not 1 <= int(number) <= len(tables):
            raise SystemExit(f"{where}: section {name!r} has {len(tables)} tables, "
                             f"not {number}")
        columns, _, row = columns.partition(";")
        table = _columns(tables[int(number) - 1], [c.strip() for c in columns.split("|")
                                                    if c.strip()], row, f"{where}: {name}")
        ran = re.search(r"finished (\d{4}-\d\d-\d\d)", text)
        link = "BENCHMARKS.md" if where.parts[:1] == ("docs",) else "docs/BENCHMARKS.md"
        source = (f"*Written by `python -m benchmarks` from [docs/BENCHMARKS.md]({link}), "
                  f"\"{title}\"{f', run {ran[1]}' if ran else ''}.*")
        return f"{opening}{table}\n\n{source}\n{closing}"

    return BLOCK.sub(block, page)


def _titles() -> dict[str, str]:
    """Each section module's ``TITLE``, by module name, read from its source (nothing of a
    section is imported: its peers need not be installed to write a page)."""
    titles = {}
    for path in sorted(Path(__file__).with_name("sections").glob("[!_]*.py")):
        for node in ast.parse(path.read_text()).body:
            if (isinstance(node, ast.Assign) and len(node.targets) == 1
                    and getattr(node.targets[0], "id", None) == "TITLE"):
                titles[path.stem] = ast.literal_eval(node.value)
    return titles


def _tables(section: str) -> list[list[list[str]]]:
    """The Markdown tables of a section, each a list of rows of cells (the rule row left out)."""
    tables, rows = [], []
    for line in section.splitlines() + [""]:
        if line.startswith("|"):
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if not all(set(c) <= set("-: ") for c in cells):
                rows.append(cells)
        elif rows:
            tables.append(rows)
            rows = []
    return tables


def _columns(rows: list[list[str]], names: list[str], row: str, section: str) -> str:
    """The table with the named columns only, in that order, and with ``row`` ("COLUMN =
    VALUE") the rows that read VALUE there only, as Markdown."""
    header = rows[0]
    column, _, value = (part.strip() for part in row.partition("="))
    missing = [n for n in [*names, *([column] if column else [])] if n not in header]
    if missing:
        raise SystemExit(f"{section}: the table has no column {missing}; "
                         f"it has {header}")
    keep = [header.index(n) for n in names] if names else range(len(header))
    rows = [rows[0], *(r for r in rows[1:] if not column or r[header.index(column)] == value)]
    picked = [[r[i] if i < len(r) else "" for i in keep] for r in rows]
    lines = ["| " + " | ".join(row) + " |" for row in picked]
    return "\n".join([lines[0], "|" + "---|" * len(keep), *lines[1:]])


if __name__ == "__main__":
    main()
