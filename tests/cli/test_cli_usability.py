"""What a new user meets first: progress that never pollutes output, the compile notice,
a CLI that explains itself (lists from the registries), example data reachable from any folder,
``render`` choosing the frame of largest displacement."""

import argparse
import json
import sys
import types
from pathlib import Path

import pytest

import femast as fm
import femast.examples
from femast import jit, progress
from femast.cli import build_parser, main
from femast.effects import applicable_effects, list_effects
from femast.experiments import get_experiment, list_experiments

ROOT = Path(__file__).resolve().parents[2]


# ------------------------------------------------------------------ progress
def test_bars_are_off_when_stderr_is_not_a_terminal(capsys):
    assert not progress.enabled()  # pytest captures stderr: not a terminal
    with progress.task("fitting") as bar:
        progress.tick()
        progress.tick("FE runs")
    assert bar.disable
    assert capsys.readouterr().err == ""


def test_task_counts_ticks_and_names_the_work(monkeypatch, capsys):
    monkeypatch.setattr(progress, "enabled", lambda: True)
    with progress.task("fitting mast-top") as bar:
        for _ in range(3):
            progress.tick()
        progress.tick("FE runs")
        assert bar.n == 3
    err = capsys.readouterr().err
    assert "fitting mast-top" in err and "1 FE runs" in err
    progress.tick()  # outside a task: nothing to count, no error


def test_quiet_switches_bars_and_notices_off(monkeypatch):
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True, raising=False)
    try:
        progress.set_quiet(True)
        assert not progress.enabled() and progress.quiet()
    finally:
        progress.set_quiet(False)
    monkeypatch.setenv("FEMAST_QUIET", "1")
    assert progress.quiet()


def test_compare_fit_shows_a_bar_with_the_variant(monkeypatch, capsys, tmp_path):
    monkeypatch.setattr(progress, "enabled", lambda: True)
    monkeypatch.chdir(tmp_path)
    assert main(["compare", "mast-top", "example", "--fit"]) == 0
    cap = capsys.readouterr()
    assert "fitting mast-top" in cap.err and "evaluations" in cap.err
    assert "fitting" not in cap.out  # bars go to stderr only
    assert (tmp_path / "compare" / "mast-top_mast_top_example" / "compare.png").is_file()
    assert "compare/mast-top_mast_top_example/compare.png" in cap.out  # the output says where


def test_error_text_is_not_mixed_with_a_bar(monkeypatch, capsys, tmp_path):
    monkeypatch.setattr(progress, "enabled", lambda: True)
    bad = tmp_path / "bad.csv"
    bad.write_text("not,a,header\n1,2,3\n")
    assert main(["compare", "mast-top", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.strip().splitlines()[-1].startswith("femast: error:")


# ------------------------------------------------------------------ compile notice
def _fake_event(module):
    return types.SimpleNamespace(
        is_start=True,
        data={"dispatcher": types.SimpleNamespace(py_func=types.SimpleNamespace(__module__=module, __name__="kernel"))},
    )


def test_compile_notice_once_per_process_and_only_for_femast(monkeypatch, capsys):
    monkeypatch.setattr(jit, "_announced", False)
    monkeypatch.setattr(jit, "_delegate", None)
    monkeypatch.setattr(jit, "_depth", 0)
    monkeypatch.setattr(progress, "_QUIET", False)  # (whatever an earlier test left)
    monkeypatch.delenv("FEMAST_QUIET", raising=False)
    jit._on_start(_fake_event("numpy_user_module"))
    assert capsys.readouterr().err == ""
    jit._on_start(_fake_event("femast.rotations"))
    jit._on_start(_fake_event("femast.analysis.assembly"))
    err = capsys.readouterr().err
    assert err.count("compiling femast's numba kernels") == 1
    assert "femast warmup" in err and "min" in err  # what to do about it, and roughly how long


def test_compile_notice_respects_quiet(monkeypatch, capsys):
    monkeypatch.setattr(jit, "_announced", False)
    monkeypatch.setattr(jit, "_delegate", None)
    monkeypatch.setattr(jit, "_depth", 0)
    monkeypatch.setenv("FEMAST_QUIET", "1")
    jit._on_start(_fake_event("femast.rotations"))
    assert capsys.readouterr().err == ""


@pytest.mark.slow
def test_warmup_command(capsys):
    from femast.warmup import PARTS

    assert main(["warmup"]) == 0
    out = capsys.readouterr().out
    assert all(what in out for what, _ in PARTS)


# ------------------------------------------------------------------ the CLI explains itself
def _walk(parser):
    yield parser
    for a in parser._actions:
        if isinstance(a, argparse._SubParsersAction):
            for sp in a.choices.values():
                yield from _walk(sp)


def test_every_argument_has_help_and_its_default():
    for parser in _walk(build_parser()):
        for a in parser._actions:
            if isinstance(a, (argparse._HelpAction, argparse._SubParsersAction)):
                continue
            assert a.help, f"{parser.prog}: {a.dest} has no help"
            if a.option_strings and a.default not in (None, False, argparse.SUPPRESS):
                text = parser.format_help()
                assert f"default: {a.default}" in " ".join(text.split()), f"{parser.prog} {a.dest}: default not shown"
            if not a.option_strings and a.nargs == "?":
                assert "default" in a.help, f"{parser.prog}: optional {a.dest} does not say its default"


def test_help_lists_come_from_the_registries():
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    for cmd in ("compare", "diagnose"):
        text = "".join(sub.choices[cmd].format_help().split())  # help wraps lines at hyphens
        for e in list_experiments():
            assert e.name in text, f"{cmd} --help omits {e.name}"
    text = "".join(sub.choices["compare"].format_help().split())
    for e in list_effects():
        assert e.name in text


def test_experiments_and_effects_commands(capsys):
    assert main(["experiments", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert [r["name"] for r in rows] == [e.name for e in list_experiments()]
    assert all(r["title"] and r["physics"] for r in rows)
    exp = get_experiment("bay-torsion")
    assert main(["effects", "bay-torsion", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert [r["name"] for r in rows] == [e.name for e in applicable_effects(exp)]
    assert all(r["physics"].endswith(".") and "\n" not in r["physics"] for r in rows)
    assert main(["effects"]) == 0
    out = capsys.readouterr().out
    assert all(e.name in out for e in list_effects())


# ------------------------------------------------------------------ examples anywhere
def test_examples_are_package_data_reachable_by_name():
    p = femast.examples.path("mast_top_example.csv")
    assert p.is_file() and p.parent == Path(femast.examples.__file__).parent
    for exp, name in femast.examples.BY_EXPERIMENT.items():
        assert femast.examples.for_experiment(exp).name == name
    with pytest.raises(fm.DataFileError, match="shipped"):
        femast.examples.path("nope.csv")
    toml = (ROOT / "pyproject.toml").read_text()
    assert '"femast.examples" = ["*.csv", "*.txt"]' in toml  # the data and the licences of data made by others
    for name in femast.examples.names():
        assert all(c.is_file() for c in femast.examples.companions(name))


def test_examples_command_copies(tmp_path, capsys):
    assert main(["examples", "--copy", str(tmp_path / "ex")]) == 0
    names = femast.examples.names()
    expected = names + [c.name for n in names for c in femast.examples.companions(n)]
    assert sorted(p.name for p in (tmp_path / "ex").iterdir()) == sorted(expected)


def test_gitignore_covers_what_the_docs_commands_write():
    ignored = (ROOT / ".gitignore").read_text().split()
    for folder in ("results/", "compare/", "diagnose/", "render/", "vtk/", "tutorial/", "out/"):
        assert folder in ignored


# ------------------------------------------------------------------ render
def _load_unload(folder):
    m = fm.Model("lu")
    a, b = m.node(0, 0, 0), m.node(1, 0, 0)
    m.beam(a, b, fm.circular_tube(0.02, 0.016, E=70e9), n=4)
    m.fix(a)
    m.step("load", initial_increment=0.25).load(b, fz=-50.0)
    m.step("unload", initial_increment=0.5).load(b, fz=0.0)
    return fm.Analysis(m, folder, progress=False).run(), b


def test_render_defaults_to_the_largest_displacement(tmp_path, monkeypatch, capsys):
    pytest.importorskip("pyvista")
    from femast.post.render import largest_displacement_frame

    res, tip = _load_unload(tmp_path / "lu")
    k, umax = largest_displacement_frame(res)
    # the load is largest at the end of the load step (frames: 0, 4 load increments, 2 unload)
    assert res.frame(k)["step"] == "load" and k == res.steps.index("unload") - 1
    assert umax == pytest.approx(
        abs(res.node_history(tip, "uz")[k]), rel=1e-3
    )  # the tip moves most; |ux| ~ uz^2/L << |uz|
    monkeypatch.chdir(tmp_path)
    assert main(["render", str(tmp_path / "lu")]) == 0
    out = capsys.readouterr().out
    assert f"frame {k} of {len(res)}, the largest displacement" in out
    assert (tmp_path / "render" / f"lu_frame{k}.png").is_file()
    assert main(["render", str(tmp_path / "lu"), "--frame", "last"]) == 0
    assert f"frame {len(res) - 1} of {len(res)}" in capsys.readouterr().out


# ------------------------------------------------------------------ docs index
def test_index_has_the_task_entries_and_its_links_resolve():
    import re

    text = (ROOT / "docs" / "index.md").read_text()
    for task in (
        "Build your own mast",
        "Run a load cycle",
        "View in ParaView",
        "Compare your own data",
        "Add your own effect",
        "Run on a cluster",
    ):
        assert f"**{task}**" in text, task
    for page, anchor in re.findall(r"\]\(([\w.]+\.md)(?:#([\w-]+))?\)", text):
        doc = ROOT / "docs" / page
        assert doc.is_file(), page
        if anchor:  # GitHub's heading slug: lower case, punctuation dropped, spaces to '-'
            slugs = {
                re.sub(r"[^\w\- ]", "", h.strip().lower()).replace(" ", "-")
                for h in re.findall(r"^#+ (.*)$", doc.read_text(), re.M)
            }
            assert anchor in slugs, f"{page}#{anchor}"


def test_render_frame_out_of_range_is_a_femast_error(tmp_path, capsys):
    _load_unload(tmp_path / "lu")
    assert main(["render", str(tmp_path / "lu"), "--frame", "99", "--out", str(tmp_path / "pics")]) == 2
    err = capsys.readouterr().err
    assert "--frame 99" in err and "frames (0 to" in err and "Traceback" not in err
