"""The experiments docs run: python examples execute, and the tutorial's commands print what the page quotes."""

import re
from pathlib import Path

import pytest
from doc_examples import printed_in, replay_transcript, run_python_blocks

from femast.effects import list_effects, unregister_effect

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"


@pytest.mark.parametrize("page", ["experiments.md", "compare_and_diagnose.md"])
def test_python_examples_run(page, capsys, tmp_path):
    before = {e.name for e in list_effects()}
    try:  # from a folder outside the repository: the examples find the shipped data
        text = run_python_blocks(page, cwd=tmp_path)
    finally:  # an example's user effect must not become a candidate of later diagnoses
        for e in list_effects():
            if e.name not in before:
                unregister_effect(e.name)
    out = capsys.readouterr().out
    for q in re.findall(r"prints `([^`]+)`", text):
        assert printed_in(q, out), f"{page}: the page says it prints {q!r}"  # numbers as numbers


#: the tutorial's diagnoses of the shipped examples as a test session runs them once, with --workers 1
#: (the refits' results do not depend on where they run: test_experiments_cli, parallel refits)
SHARED = {
    "femast diagnose mast-top example --out tutorial/mast": "mast-top",
    "femast diagnose latch-pull example --out tutorial/latch": "latch-pull",
    "femast diagnose vibration example --out tutorial/vib --workers 1": "vibration",
}


def test_tutorial_commands_print_what_the_page_quotes(tmp_path, capsys, monkeypatch, example_run):
    text = (DOCS / "compare_and_diagnose.md").read_text()
    blocks = re.findall(r"```console\n(.*?)```", text, re.S)
    assert len(blocks) >= 5
    assert all(f"$ {cmd}\n" in text for cmd in SHARED), "a shared diagnosis is no longer on the page"
    printed = {cmd: example_run("diagnose", name).stdout for cmd, name in SHARED.items()}
    capsys.readouterr()
    monkeypatch.chdir(tmp_path)  # outputs (tutorial/...) go to a temporary folder; the data are femast's examples
    checked = sum(
        replay_transcript(
            block, tmp_path, capsys, ignore=lambda line: line.strip() == "...", what="the tutorial", printed=printed
        )
        for block in blocks
    )
    assert checked > 40
