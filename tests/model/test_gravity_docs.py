"""The examples of docs/gravity.md run and print what the page quotes."""

import re

from doc_examples import printed_in, run_python_blocks


def test_gravity_page_examples(tmp_path, capsys):
    text = run_python_blocks("gravity.md", cwd=tmp_path)
    out = capsys.readouterr().out
    quoted = re.findall(r"prints `([^`]+)`", text) + re.findall(r"and\s+`(root reaction[^`]+)`", text)
    assert len(quoted) == 2
    for q in quoted:
        assert printed_in(q, out), q
