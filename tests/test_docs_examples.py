"""Every ```python block of the core docs pages runs (examples never rot), in a temporary folder."""

import os
import re
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parents[1] / "docs"
PAGES = ["getting_started.md", "model.md", "solver.md", "results.md", "stabilize.md", "arc_length.md",
         "constraints.md"]


@pytest.mark.parametrize("page", PAGES)
def test_page_examples_run(page, tmp_path, capsys):
    blocks = re.findall(r"```python\n(.*?)```", (DOCS / page).read_text(), re.S)
    assert blocks, f"{page} has no python example"
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        for i, src in enumerate(blocks):
            exec(compile(src, f"{page}[{i}]", "exec"), {"__name__": "__doc_example__"})
    finally:
        os.chdir(cwd)
    out = capsys.readouterr().out
    # printed numbers quoted on the page must be what the example prints
    text = (DOCS / page).read_text()
    quoted = re.findall(r"prints `([^`]+)`", text)
    quoted += re.findall(r"^    (tip deflection[^\n]+)$", text, re.M)
    quoted += re.findall(r"^`(top lean[^`]+)`", text, re.M)
    for q in quoted:
        assert q in out, f"{page}: the page says it prints {q!r}"
