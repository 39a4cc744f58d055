"""The command line as the docs write it: options anywhere among a command's arguments, VTK
output in one place (the results folder, as the API), "did you mean" for experiment and effect
names, and arguments given in the wrong order explained."""

from pathlib import Path

import pytest

import femast as fm
from femast.cli import main
from femast.post.vtk import export_vtk


def _two_steps(folder):
    m = fm.Model("lu")
    a, b = m.node(0, 0, 0), m.node(1, 0, 0)
    m.beam(a, b, fm.circular_tube(0.02, 0.016, E=70e9), n=4)
    m.fix(a)
    m.step("load", initial_increment=0.25).load(b, fz=-50.0)
    m.step("unload", initial_increment=0.5).load(b, fz=0.0)
    return fm.Analysis(m, folder, progress=False).run()


@pytest.mark.parametrize(
    "args",
    [
        ["R", "--frame", "last", "shape.png"],  # the getting-started page's line
        ["--frame", "last", "R", "shape.png"],
        ["R", "shape.png", "--frame", "last"],
        ["--scale", "1", "R", "--frame", "-1", "shape.png"],
    ],
)
def test_render_takes_its_options_anywhere(args, tmp_path, monkeypatch, capsys):
    pytest.importorskip("pyvista")
    res = _two_steps(tmp_path / "R")
    monkeypatch.chdir(tmp_path)
    assert main(["render", *args]) == 0
    out = capsys.readouterr().out
    assert (tmp_path / "shape.png").stat().st_size > 1000
    assert f"frame {len(res) - 1} of {len(res)}" in out  # 'last' and -1: the last frame


def test_vtk_goes_to_the_results_folder_from_the_cli_and_the_api(tmp_path, monkeypatch, capsys):
    res = _two_steps(tmp_path / "R")
    work = tmp_path / "elsewhere"
    work.mkdir()
    monkeypatch.chdir(work)
    assert main(["vtk", str(tmp_path / "R")]) == 0
    cli_files = sorted(p.name for p in (tmp_path / "R" / "vtk").iterdir())
    assert "series.pvd" in cli_files and len(cli_files) == len(res) + 1
    assert str(tmp_path / "R" / "vtk" / "series.pvd") in capsys.readouterr().out
    assert list(work.iterdir()) == []  # nothing in the working directory
    for p in (tmp_path / "R" / "vtk").iterdir():
        p.unlink()
    assert export_vtk(res) == tmp_path / "R" / "vtk" / "series.pvd"
    assert sorted(p.name for p in (tmp_path / "R" / "vtk").iterdir()) == cli_files
    # an explicit folder is the folder itself, for both
    assert main(["vtk", str(tmp_path / "R"), "--out", str(tmp_path / "mine")]) == 0
    assert export_vtk(res, tmp_path / "mine2").parent == tmp_path / "mine2"
    assert (tmp_path / "mine" / "series.pvd").is_file()


@pytest.mark.parametrize(
    "argv, hint",
    [
        (["compare", "mast-tpo", "example"], "did you mean 'mast-top'?"),
        (["diagnose", "bay-torsoin", "example"], "did you mean 'bay-torsion'?"),
        (["effects", "tip-cylce"], "did you mean 'tip-cycle'?"),
        (["compare", "mast-top", "example", "--effects", "joint_clearence"], "did you mean 'joint_clearance'?"),
    ],
)
def test_did_you_mean_for_experiments_and_effects(argv, hint, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("femast: error:") and hint in err and len(err.splitlines()) == 1


def test_swapped_experiment_and_data_are_explained(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["compare", "example", "mast-top"]) == 2
    err = capsys.readouterr().err
    assert "the experiment comes first" in err and "femast compare mast-top example" in err
    data = tmp_path / "rig.csv"
    data.write_text("fx_N,dx_m\n1,0\n")
    assert main(["diagnose", str(data), "bay-torsion"]) == 2
    assert f"femast diagnose bay-torsion {data}" in capsys.readouterr().err


def test_swapped_solve_arguments_are_explained(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    m = fm.Model("m")
    a, b = m.node(0, 0, 0), m.node(1, 0, 0)
    m.beam(a, b, fm.circular_tube(0.02, 0.016, E=70e9))
    m.fix(a)
    m.step("load").load(b, fz=-1.0)
    with pytest.raises(fm.ModelError, match=r"the model comes first, fm.solve\(model, 'results/x'\)"):
        fm.solve("results/x", m)
    with pytest.raises(fm.ModelError, match="needs a femast Model"):
        fm.Analysis(Path("results/x"))
    assert list(tmp_path.iterdir()) == []  # refused before any folder was made
