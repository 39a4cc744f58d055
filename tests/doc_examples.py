"""Shared by the documentation tests: run the ```python blocks of a docs page."""

import os
import re
from pathlib import Path

DOCS = Path(__file__).resolve().parents[1] / "docs"


def run_python_blocks(page: str, cwd=None) -> str:
    """Execute every ```python block of docs/``page`` in order, each in a fresh namespace, in folder
    ``cwd`` (default: the current one); returns the page's text.  Fails if the page has none."""
    text = (DOCS / page).read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert blocks, f"{page} has no python example"
    old = os.getcwd()
    if cwd is not None:
        os.chdir(cwd)
    try:
        for i, src in enumerate(blocks):
            exec(compile(src, f"{page}[{i}]", "exec"), {"__name__": "__doc_example__"})
    finally:
        os.chdir(old)
    return text
