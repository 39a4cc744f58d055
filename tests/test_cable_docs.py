"""The code examples of docs/cable_latch_element.md and docs/latch_identification.md run."""

import re
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parents[1] / "docs"


def blocks(name):
    text = (DOCS / name).read_text()
    return re.findall(r"```python\n(.*?)```", text, re.S)


@pytest.mark.parametrize("name", ["cable_latch_element.md", "latch_identification.md"])
def test_doc_examples_run(name):
    code = blocks(name)
    assert code, f"no python example in {name}"
    for i, src in enumerate(code):
        exec(compile(src, f"{name}[{i}]", "exec"), {"__name__": "__doc_example__"})
