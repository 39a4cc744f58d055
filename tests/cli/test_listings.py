"""Listings in the user's words: whole first sentences, lines wrapped to the terminal's width
(never cut), counts with the right noun."""

import pytest

from femast.analysis.summary import AnalysisSummary
from femast.cli import main
from femast.text import count, first_sentence, hanging


@pytest.mark.parametrize(
    "text, first",
    [
        ("Refits the latch (Figs. 10-11). Then more.", "Refits the latch (Figs. 10-11)."),
        ("See Eqs. 6-14 of the paper. Then more.", "See Eqs. 6-14 of the paper."),
        ("A law (as in Fig. 5a. and below) holds; the rest.", "A law (as in Fig. 5a. and below) holds."),
        ("the loads 0, M+F, 0, ... with M = 6 N m. Then.", "the loads 0, M+F, 0, ... with M = 6 N m."),
        ("no full stop at all", "no full stop at all"),
        ("e.g. this. That.", "e.g. this."),
    ],
)
def test_first_sentence(text, first):
    assert first_sentence(text) == first


def test_hanging_wraps_instead_of_cutting():
    body = "word " * 40
    out = hanging("  name", body.strip(), 10, columns=50)
    lines = out.splitlines()
    assert len(lines) > 3 and all(len(ln) <= 50 for ln in lines)
    assert lines[0].startswith("  name    word") and all(ln.startswith(" " * 10 + "word") for ln in lines[1:])
    assert " ".join(out.split()[1:]) == body.strip()  # every word kept


@pytest.mark.parametrize("command", [["effects"], ["examples"], ["experiments"]])
def test_listings_fit_the_terminal_and_end_their_sentences(command, monkeypatch, capsys):
    monkeypatch.setenv("COLUMNS", "72")
    assert main(command) == 0
    out = capsys.readouterr().out
    lines = out.splitlines()
    assert all(len(ln) <= 72 for ln in lines[1:]), [ln for ln in lines if len(ln) > 72]
    if command == ["effects"]:  # each effect: its name and title, then its physics, a whole sentence
        starts = [i for i, ln in enumerate(lines) if ln.startswith("  ") and not ln.startswith("   ")]
        for a, b in zip(starts, starts[1:] + [len(lines)]):
            entry = " ".join(" ".join(lines[a:b]).split())
            assert entry.endswith(".") and entry.count("(") == entry.count(")"), entry


def test_counts_take_the_right_noun():
    assert count(1, "increment") == "1 increment" and count(0, "cutback") == "0 cutbacks"
    s = AnalysisSummary(increments=1, iterations=1, cutbacks=0)
    assert "1 increment, 1 Newton iteration, 0 cutbacks" in str(s)
