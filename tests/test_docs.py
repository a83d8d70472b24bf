"""No figure typed by hand in the README and the user's pages (issue 44): a measured number
(a time, a ratio, a share, a size in bytes, an angle) stands only between the benchmark markers
that ``python -m benchmarks`` fills from docs/BENCHMARKS.md, and what stands there is what it
writes.

Allowed outside the markers: numbers without a unit (version numbers, sizes such as 1024 and
``2048 x 2048``, counts), and anything in code (fenced blocks and inline spans: command lines,
examples). Units looked for: ``s ms min h x × % KiB MiB GiB KB MB GB deg ° days hours minutes
seconds``; ranges of decimals (``0.93-1.00``), which here are always measured; and a decimal
after a measure's name (``ratio 1.1``, ``confidence 0.29``, ``load 3.6``).
"""

import re
from pathlib import Path

import pytest

from benchmarks.__main__ import BLOCK, fill_blocks

REPO = Path(__file__).resolve().parent.parent
PAGES = ("README.md", "docs/METHODS.md", "docs/BLENDER.md", "docs/COMMAND_LINE.md", "docs/BATCH.md")

NUMBER = r"(?<![\w.])\d+(?:[.,]\d+)?"
FIGURE = re.compile(
    rf"{NUMBER}\s?(?:%|°|×|x(?!\s*\d)|(?:s|ms|min|h|KiB|MiB|GiB|KB|MB|GB|deg|degrees?|days?|"
    rf"hours?|minutes?|seconds?)(?![\w-]))"
    rf"|{NUMBER}\s?-\s?\d+\.\d+|\d+\.\d+\s?(?:-|to)\s?{NUMBER}"
    r"|\b(?:ratio|correlation|confidence|distance|W1|load)(?: of| at most| is| average)?"
    r" \d*\.\d+")


def figures(text: str) -> list[str]:
    """The typed figures of a Markdown page: outside benchmark blocks, code and comments."""
    text = BLOCK.sub("", text)
    text = re.sub(r"```.*?```", "", text, flags=re.S)
    text = re.sub(r"<!--.*?-->", "", text, flags=re.S)
    text = re.sub(r"``.*?``|`[^`\n]*`", "", text)
    return [m.group(0) for m in FIGURE.finditer(text)]


@pytest.mark.parametrize("page", PAGES)
def test_no_typed_figures(page):
    found = figures((REPO / page).read_text())
    assert not found, (f"{page} types measured figures by hand: {found}; put them in a "
                       "benchmark section's table and a <!-- benchmark:... --> block, or drop "
                       "them")


@pytest.mark.parametrize("page", PAGES)
def test_blocks_are_what_the_benchmark_command_writes(page):
    text = (REPO / page).read_text()
    written = fill_blocks(text, (REPO / "docs" / "BENCHMARKS.md").read_text(), Path(page))
    assert text == written, (f"{page}: a benchmark block differs from docs/BENCHMARKS.md; run "
                             "`python -m benchmarks --pages` to rewrite the blocks")


def test_the_rule_sees_typed_figures_and_lets_the_rest_pass():
    typed = ["1.6-2.5 s at 1024", "7.3 s at 2048", "renders 1.14-1.72x as long", "3.5-7x slower",
             "4-5 % of joints", "0.8 GiB", "slant 3° ± 14°", "a correlation of 0.93-1.00",
             "about 13 days", "2x the goal", "took 624s", "gradient ratio 1.1",
             "confidence 0.29", "at load 3.6", "W1 at most 0.027"]
    assert [t for t in typed if not figures(t)] == []
    allowed = ["Blender 4.2 or later", "Python 3.11", "a 2048 x 2048 texture tiled 2 x 2",
               "16 tiles", "`--size 2048 --in-size 1024`", "```\nblender -b 1.5x\n```",
               "12 MP photos", "seams in 8 sides", "version 0.1.0", "x86_64", "issue 44",
               "a confidence under one half",
               "<!-- benchmark:photos 1 -->\n| a | 20 s |\n<!-- /benchmark -->"]
    assert [a for a in allowed if figures(a)] == []
