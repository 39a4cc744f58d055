"""The suite runs in random order (pytest-randomly) wherever it is installed as the README says, CI
included: a test that passes only after (or before) another fails somewhere instead of never."""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = (ROOT / "pyproject.toml").read_text()


def test_the_test_extra_brings_pytest_randomly():
    test_extra = re.search(r"^test = \[(.*?)\]", PYPROJECT, re.M | re.S).group(1)
    assert re.search(r"[\"']pytest-randomly\b", test_extra), test_extra


def test_nothing_switches_the_random_order_off():
    for where, text in (
        ("pyproject.toml", PYPROJECT),
        ("README.md", (ROOT / "README.md").read_text()),
        (".ci/run", (ROOT / ".ci" / "run").read_text()),
    ):
        assert "no:randomly" not in text and "randomly-dont-reorganize" not in text, where


def test_this_session_runs_in_random_order(request):
    assert request.config.pluginmanager.hasplugin("randomly")
