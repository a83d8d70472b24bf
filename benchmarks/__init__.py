"""Speed, memory and quality of every registered method beside the peers, in one run.

    python -m benchmarks [--quick] [--only NAME ...]

writes docs/BENCHMARKS.md and docs/img/. See benchmarks/context.py for what a section gets.
"""
