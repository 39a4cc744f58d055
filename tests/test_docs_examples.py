"""Every ```python block of the core docs pages runs (examples never rot), in a temporary folder."""

import re

import pytest
from doc_examples import run_python_blocks
PAGES = ["getting_started.md", "model.md", "solver.md", "results.md", "stabilize.md", "arc_length.md",
         "constraints.md"]


@pytest.mark.parametrize("page", PAGES)
def test_page_examples_run(page, tmp_path, capsys):
    text = run_python_blocks(page, cwd=tmp_path)
    out = capsys.readouterr().out
    # printed numbers quoted on the page must be what the example prints
    quoted = re.findall(r"prints `([^`]+)`", text)
    quoted += re.findall(r"^    (tip deflection[^\n]+)$", text, re.M)
    quoted += re.findall(r"^`(top lean[^`]+)`", text, re.M)
    for q in quoted:
        assert q in out, f"{page}: the page says it prints {q!r}"
