"""One module per section of docs/BENCHMARKS.md: ``ORDER``, ``TITLE`` and ``run(ctx) -> str``."""
