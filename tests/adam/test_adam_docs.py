"""The ```python examples of docs/adam_bay.md and docs/adam_mast.md run, and print what the pages
say they print (the quoted numbers are the benchmark's; the examples never rot)."""

import re

import pytest
from doc_examples import DOCS, printed_in, run_python_blocks


@pytest.mark.parametrize("page", ["adam_bay.md", "adam_mast.md"])
def test_adam_page_examples_run(page, tmp_path, capsys):
    text = run_python_blocks(page, cwd=tmp_path)
    out = capsys.readouterr().out
    quoted = re.findall(r"prints `([^`]+)`", text)
    block = re.search(r"\nprints\n\n((?:    [^\n]+\n)+)", text)
    if block:
        quoted += [ln[4:] for ln in block.group(1).splitlines()]
    assert quoted, f"{page} quotes no printed output"
    for q in quoted:
        assert printed_in(q, out), f"{page}: the page says it prints {q!r}"  # numbers as numbers
    for fig in re.findall(r"\]\((figures/[^)]+)\)", text):
        assert (DOCS / fig).exists(), f"{page}: missing figure {fig}"
