"""The benchmark scripts, installed as ``femast.benchmarks``: ``python -m femast.benchmarks.NAME``
runs ``benchmarks/NAME.py`` from any folder (docs/performance.md)."""
