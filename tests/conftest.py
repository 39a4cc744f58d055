"""The test suite's environment: tests/ on sys.path (the shared helpers such as doc_examples import
from every test folder), figures drawn without a display, and the runs several tests read, made
once per session (``example_diagnosis``)."""

import os
import sys
from pathlib import Path

import pytest

os.environ.setdefault("MPLBACKEND", "Agg")
sys.path.insert(0, str(Path(__file__).resolve().parent))


@pytest.fixture(scope="session")
def example_diagnosis(tmp_path_factory):
    """``example_diagnosis(NAME)``: the diagnosis of experiment NAME's shipped example, run once per
    session (:func:`example_runs.diagnose_example`) for every test that reads it; read-only."""
    from example_runs import diagnose_example

    runs = {}

    def get(name):
        if name not in runs:
            runs[name] = diagnose_example(name, tmp_path_factory.mktemp(f"diagnose-{name}"))
        return runs[name]

    return get
