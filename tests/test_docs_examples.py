"""Every ```python block of the core docs pages runs (examples never rot), in a temporary folder."""

import re

import pytest
from doc_examples import printed_in, run_python_blocks

PAGES = [
    "getting_started.md",
    "model.md",
    "solver.md",
    "results.md",
    "stabilize.md",
    "arc_length.md",
    "constraints.md",
    "robustness.md",
    "restart.md",
    "misfit_and_thermal.md",
    "studies.md",
    "shape_accuracy.md",
]


@pytest.mark.parametrize("page", PAGES)
def test_page_examples_run(page, tmp_path, capsys):
    text = run_python_blocks(page, cwd=tmp_path)
    out = capsys.readouterr().out
    # printed numbers quoted on the page must be what the example prints
    quoted = re.findall(r"prints `([^`]+)`", text)
    quoted += re.findall(r"^    (tip deflection[^\n]+)$", text, re.M)
    quoted += re.findall(r"^`(top lean[^`]+)`", text, re.M)
    for q in quoted:
        assert printed_in(q, out), f"{page}: the page says it prints {q!r}"  # numbers as numbers


def test_quoted_transcript_numbers_match_to_three_units_of_their_last_digit():
    # the tolerance of doc_examples.replay_transcript: round-off moves a 6-digit fit in its last digit
    from doc_examples import _same_line

    assert _same_line("F_h = 8.04317 N (stderr 0.21)", "F_h = 8.04319 N (stderr 0.21)")
    assert not _same_line("F_h = 8.04317 N (stderr 0.21)", "F_h = 8.04321 N (stderr 0.21)")  # 4 units off
    assert _same_line("p = 3.2e-07", "p = 3.4e-07") and not _same_line("p = 3.2e-07", "p = 3.6e-07")
    assert not _same_line("F_h = 8.04317 N", "F_h = 8.04317 kN")  # the words count


def test_quoted_phrases_and_fitted_values_match_as_numbers():
    from doc_examples import _same_line, quoted_in

    assert quoted_in("x = 1740 um", "pre x = 1741 um, post")  # inside a line, 1 unit off
    assert not quoted_in("x = 1740 um", "x = 1750 um")  # 10 units off
    assert not quoted_in("x = 1740 um", "x = 1740 mm")
    # a value quoted with its standard error may move by a tenth of it (the fits' stopping rule)
    assert _same_line("mu = 0.04745 +- 0.02 -", "mu = 0.04759 +- 0.02 -")
    assert not _same_line("mu = 0.04745 +- 0.02 -", "mu = 0.0520 +- 0.02 -")


def test_quoted_fragments_and_lines_are_compared_as_numbers():
    import pytest as _pt
    from doc_examples import assert_same_numbers, printed_in

    out = "run 3: tip deflection 12.345 mm, residual 2.1e-13 N\nother 1.0"
    assert printed_in("tip deflection 12.346 mm", out)  # one unit of the last digit
    assert not printed_in("tip deflection 12.35 mm", "tip deflection 12.31 mm")  # 4 units off
    assert not printed_in("tip deflection 12.345 m,", out)  # the words count
    assert_same_numbers("residual 1.4e-13 N", "residual 2.1e-13 N", roundoff=1e-9)  # round-off: a bound
    with _pt.raises(AssertionError):
        assert_same_numbers("residual 1.4e-13 N", "residual 2.1e-3 N", roundoff=1e-9)
    with _pt.raises(AssertionError):
        assert_same_numbers("k = 143.872", "k = 143.874")
