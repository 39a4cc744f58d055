"""Every command line the docs give works from a folder outside the repository: femast commands
parse (a synopsis line names only real commands and options), every benchmark the docs run is an
installed module (``python -m femast.benchmarks.NAME``), the getting-started commands run in an
empty folder, and (slow) every documented benchmark option is one its script accepts."""

import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest
from doc_examples import DOCS

from femast.cli import build_parser, main

_SHELLS = ("", "sh", "bash", "console", "shell")


def documented_commands():
    """(page, line number, command) of every command line in the docs' code blocks (indented or
    fenced), continuation lines joined, comments and a ``$ `` prompt removed."""
    found = []
    for page in sorted(DOCS.glob("*.md")):
        lines = page.read_text().splitlines()
        fence = None
        for i, line in enumerate(lines):
            if line.startswith("```"):
                fence = None if fence is not None else line[3:].strip()
                continue
            in_block = (fence is None and line.startswith("    ")) or fence in _SHELLS
            text = line.strip().removeprefix("$ ")
            if not in_block or not re.match(r"(femast|python) ", text):
                continue
            j = i
            while text.endswith("\\") and j + 1 < len(lines):
                j += 1
                text = text[:-1] + " " + lines[j].strip()
            text = re.split(r"\s+#", text)[0].strip()
            text = re.sub(r"\s+\(\d+(\.\d+)? s\)$", "", text)  # a run time quoted after a command
            if re.match(r"femast \w+:", text):  # a line of output ("femast compare: mast-top ...")
                continue
            found.append((page.name, i + 1, text))
    return found


COMMANDS = documented_commands()
_PLACEHOLDER = re.compile(r"\[|\.\.\.|\b(?:[A-Z][A-Z_]+|N|F|K)\b(?:\.csv)?")


def _is_synopsis(cmd: str) -> bool:
    """A synopsis (``femast compare EXPERIMENT DATA.csv [--fit]``) rather than a command to run."""
    return bool(_PLACEHOLDER.search(cmd.split(" ", 2)[-1] if cmd.startswith("python -m") else cmd))


def _options(cmd: str) -> list:
    return [w.split("=")[0] for w in re.findall(r"(?<![\w-])--?[a-zA-Z][\w-]*", cmd)]


def _ids(commands):
    return [f"{p}:{ln}" for p, ln, _ in commands]


def test_the_docs_have_command_lines():
    pages = {p for p, _, _ in COMMANDS}
    assert {"getting_started.md", "adam_mast.md", "performance.md", "studies.md"} <= pages
    assert len(COMMANDS) > 40


_FEMAST = [c for c in COMMANDS if c[2].startswith("femast ")]


@pytest.mark.parametrize("page, line, cmd", _FEMAST, ids=_ids(_FEMAST))
def test_femast_command_lines_parse(page, line, cmd):
    parser = build_parser()
    words = shlex.split(cmd)[1:]
    if _is_synopsis(cmd):  # the command exists and knows every option the synopsis names
        sub = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
        assert words[0] in sub.choices, f"{page} line {line}: no command {words[0]!r}"
        known = {o for a in sub.choices[words[0]]._actions for o in a.option_strings}
        missing = [o for o in _options(cmd) if o not in known]
        assert not missing, f"{page} line {line}: femast {words[0]} has no option {missing}"
        return
    try:
        args = parser.parse_args(words)
    except SystemExit:
        pytest.fail(f"{page} line {line}: `{cmd}` does not parse")
    script = getattr(args, "script", None)
    if script is not None and not script.endswith(".py"):  # a module name: installed
        from femast.studies.cli import script_path

        assert script_path(script).is_file()


def test_documented_scripts_are_installed_modules_or_files_the_page_makes():
    """No command names a path into the repository (``benchmarks/x.py``): from another folder it
    would not exist.  Scripts a page asks the reader to save (my_model.py) are the reader's."""
    for page, line, cmd in COMMANDS:
        for word in shlex.split(cmd):
            assert not re.match(r"(benchmarks|femast|tests)/", word), (
                f"{page} line {line}: `{cmd}` names {word}, a path inside the repository; "
                "use `python -m femast.benchmarks.NAME`"
            )


def test_documented_modules_resolve_from_an_empty_folder(tmp_path):
    modules = sorted({shlex.split(c)[2] for _, _, c in COMMANDS if c.startswith("python -m ")})
    assert "femast.benchmarks.adam_mast_table1" in modules
    code = (
        "import importlib.util, sys\n"
        "bad = [m for m in sys.argv[1:] if importlib.util.find_spec(m) is None]\n"
        "print(' '.join(bad))\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code, *modules], cwd=tmp_path, capture_output=True, text=True, check=True
    )
    assert out.stdout.split() == [], f"not importable from {tmp_path}: {out.stdout}"


def test_getting_started_commands_run_in_an_empty_folder(tmp_path, monkeypatch, capsys):
    """The page's script saved as my_model.py, then its command lines one by one."""
    pytest.importorskip("pyvista")
    text = (DOCS / "getting_started.md").read_text()
    script = re.search(r"```python\n(.*?)```", text, re.S).group(1)
    (tmp_path / "my_model.py").write_text(script)
    monkeypatch.chdir(tmp_path)
    cmds = [c for p, _, c in COMMANDS if p == "getting_started.md"]
    assert cmds[0] == "femast run my_model.py" and len(cmds) == 5
    for cmd in cmds:
        assert main(shlex.split(cmd)[1:]) == 0, cmd
    out = capsys.readouterr().out
    assert "tip deflection under load: -0.7496 m" in out
    assert (tmp_path / "results/getting_started/vtk/series.pvd").is_file()
    assert (tmp_path / "shape.png").stat().st_size > 1000
    assert sorted(p.name for p in tmp_path.iterdir()) == ["my_model.py", "render", "results", "shape.png"]


_BENCH = sorted({(p, ln, c) for p, ln, c in COMMANDS if c.startswith("python -m ")})


@pytest.mark.slow
@pytest.mark.parametrize("page, line, cmd", _BENCH, ids=_ids(_BENCH))
def test_documented_benchmark_options_exist(page, line, cmd, tmp_path):
    """Each documented benchmark line's options are ones its script's --help lists (run from an
    empty folder)."""
    module = shlex.split(cmd)[2]
    out = subprocess.run(
        [sys.executable, "-m", module, "--help"], cwd=tmp_path, capture_output=True, text=True, timeout=600
    )
    assert out.returncode == 0, f"{page} line {line}: {module} --help failed: {out.stderr[-500:]}"
    missing = [o for o in _options(cmd.split(module, 1)[1]) if o not in out.stdout]
    assert not missing, f"{page} line {line}: {module} does not accept {missing}"
    assert list(Path(tmp_path).iterdir()) == []  # --help writes nothing
