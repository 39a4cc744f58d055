"""The package list: femast, and the benchmark scripts of benchmarks/ installed as femast.benchmarks
(``python -m femast.benchmarks.adam_mast_table1`` from any folder).  Everything else is in
pyproject.toml."""

from setuptools import find_packages, setup

BENCHMARKS = ["femast.benchmarks"] + [f"femast.benchmarks.{p}" for p in find_packages("benchmarks")]

setup(
    packages=find_packages(include=["femast", "femast.*"]) + BENCHMARKS,
    package_dir={"femast.benchmarks": "benchmarks"},
)
