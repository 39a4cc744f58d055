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


_NUMBER = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?")


def _ulp(token: str) -> float:
    """One unit in the last printed digit of a number as quoted ("8.04317" -> 1e-5, "3.2e-07" -> 1e-8)."""
    mant, _, exp = token.lower().partition("e")
    decimals = len(mant.split(".")[1]) if "." in mant else 0
    return 10.0 ** (int(exp or 0) - decimals)


def _same_line(quoted: str, printed: str) -> bool:
    """``quoted`` equals ``printed`` up to its numbers, which may differ by 3 units in their last
    quoted digit: an FE fit quoted to 6 digits moves in the 6th with round-off in the solver's order
    of summation (session 3), while a wrong value differs by far more."""
    if _NUMBER.sub("#", quoted) != _NUMBER.sub("#", printed):
        return False
    q, p = _NUMBER.findall(quoted), _NUMBER.findall(printed)
    return len(q) == len(p) and all(abs(float(a) - float(b)) <= 3 * _ulp(a) for a, b in zip(q, p))


def _printed(line: str, out: str) -> bool:
    if line in out:
        return True
    core = line.strip()
    return any(core in o or _same_line(core, o.strip()) for o in out.splitlines())


def replay_transcript(block: str, folder, capsys, ignore=lambda line: False, what: str = "the page") -> int:
    """Run the commands of a quoted console transcript in ``folder`` (the current directory) --
    ``$ femast ...`` through femast.cli.main, ``$ head -N FILE`` -- and check that every other
    non-blank line (unless ``ignore(line)``) is in what the command before it printed, numbers to 3
    units in their last quoted digit (:func:`_same_line`).  A run time quoted after a command,
    ``(12.3 s)``, is not part of it.  Returns the number of lines checked."""
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
            assert _printed(line.rstrip(), out), f"{what} quotes a line the command does not print:\n{line}"
            checked += 1
    return checked
