"""The test suite's environment: tests/ on sys.path (the shared helpers such as doc_examples import
from every test folder), figures drawn without a display, and the runs several tests read, made
once per session (``example_run``)."""

import os
import sys
from pathlib import Path

import pytest

os.environ.setdefault("MPLBACKEND", "Agg")
sys.path.insert(0, str(Path(__file__).resolve().parent))


@pytest.fixture(scope="session")
def example_run(tmp_path_factory):
    """``example_run(COMMAND, NAME)``: ``femast compare NAME example`` or ``femast diagnose NAME example
    --workers 1`` of experiment NAME's shipped example, run once per session
    (:func:`example_runs.run_example`) for every test that reads it; read-only."""
    from example_runs import run_example

    runs = {}

    def get(command, name):
        if (command, name) not in runs:
            runs[command, name] = run_example(command, name, tmp_path_factory.mktemp(f"{command}-{name}"))
        return runs[command, name]

    return get
