"""Shared by the documentation tests: run the ```python blocks of a docs page."""

import os
import re
import shlex
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


def replay_transcript(block: str, folder, capsys, ignore=lambda line: False, what: str = "the page") -> int:
    """Run the commands of a quoted console transcript in ``folder`` (the current directory) --
    ``$ femast ...`` through femast.cli.main, ``$ head -N FILE`` -- and check that every other
    non-blank line (unless ``ignore(line)``) is in what the command before it printed.  A run time
    quoted after a command, ``(12.3 s)``, is not part of it.  Returns the number of lines checked."""
    from femast.cli import main

    out, checked = "", 0
    for line in block.splitlines():
        if line.startswith("$ "):
            cmd = shlex.split(re.sub(r"\s+\(\d+(\.\d+)? s\)$", "", line[2:]))
            if cmd[0] == "femast":
                assert main(cmd[1:]) == 0, line
                out = capsys.readouterr().out
            elif cmd[0] == "head":
                out = "".join((Path(folder) / cmd[-1]).read_text().splitlines(True)[:int(cmd[1][1:])])
            continue
        if line.strip() and not ignore(line):
            assert line.rstrip() in out, f"{what} quotes a line the command does not print:\n{line}"
            checked += 1
    return checked
