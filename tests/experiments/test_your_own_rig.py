"""docs/your_own_rig.md runs as a user would run it, from an empty folder: the rig script is saved
as the page says, the Python examples run in order, the command lines run, and what the page says
they print is what they print."""

import re
import shlex
import subprocess
import sys

from doc_examples import DOCS, check_output, printed_in, quoted_output

PAGE = DOCS / "your_own_rig.md"


def run_page(tmp_path, capsys):
    """Save the script blocks (first line ``# NAME.py``), run the others in order; returns the printed text.
    The effects the page registers (its ``load_creep``) are unregistered at the end: they must not
    become candidates of the diagnoses of tests that run later in the same process."""
    import os

    from femast.effects import list_effects, unregister_effect

    before = {e.name for e in list_effects()}
    text = PAGE.read_text()
    old = os.getcwd()
    os.chdir(tmp_path)
    printed = []
    try:
        for i, m in enumerate(re.finditer(r"```python\n(.*?)```", text, re.S)):
            block = m.group(1)
            name = re.match(r"# (\S+\.py)\b", block)
            if name:
                (tmp_path / name.group(1)).write_text(block)
                continue
            exec(compile(block, f"your_own_rig.md[{i}]", "exec"), {"__name__": "__doc_example__"})
            out = capsys.readouterr().out
            quoted = quoted_output(text[m.end() :])
            if quoted is not None:
                check_output(quoted, out, f"your_own_rig.md, example {i + 1}")
            printed.append(out)
    finally:
        os.chdir(old)
        for e in list_effects():
            if e.name not in before:
                unregister_effect(e.name)
    return text, "".join(printed)


def test_the_page_runs_from_an_empty_folder(tmp_path, capsys):
    text, out = run_page(tmp_path, capsys)
    for q in re.findall(r"prints `([^`]+)`", text):
        assert printed_in(q, out), f"the page says it prints {q!r}; it printed:\n{out}"
    assert "diagnose: joint_clearance, form per_axis" in out, out
    for cmd in re.findall(r"^    (femast [^\n]+)$", text, re.M):
        args = shlex.split(cmd)[1:]
        r = subprocess.run(
            [sys.executable, "-m", "femast.cli", *args], cwd=tmp_path, capture_output=True, text=True, timeout=600
        )
        assert r.returncode == 0, f"{cmd}:\n{r.stdout}\n{r.stderr}"
