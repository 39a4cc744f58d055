"""Every ```python block of the core docs pages runs (examples never rot), in a temporary folder."""

import re

import pytest
from doc_examples import run_python_blocks
PAGES = ["getting_started.md", "model.md", "solver.md", "results.md", "stabilize.md", "arc_length.md",
         "constraints.md", "misfit_and_thermal.md"]


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


def test_quoted_transcript_numbers_match_to_three_units_of_their_last_digit():
    # the tolerance of doc_examples.replay_transcript: round-off moves a 6-digit fit in its last digit
    from doc_examples import _same_line

    assert _same_line("F_h = 8.04317 N (stderr 0.21)", "F_h = 8.04319 N (stderr 0.21)")
    assert not _same_line("F_h = 8.04317 N (stderr 0.21)", "F_h = 8.04321 N (stderr 0.21)")   # 4 units off
    assert _same_line("p = 3.2e-07", "p = 3.4e-07") and not _same_line("p = 3.2e-07", "p = 3.6e-07")
    assert not _same_line("F_h = 8.04317 N", "F_h = 8.04317 kN")                             # the words count
