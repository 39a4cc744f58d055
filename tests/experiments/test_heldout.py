"""Validation in the loop: fit on one part of the data, score another -- a fit on chosen rows, the
folds (groups, else blocks of cycles), diagnose keeping a mechanism only where it lowers the held-out
error, and compare with the parameters of an earlier run (Python and --params-from)."""

import json

import numpy as np
import pytest
import two_axis_rig as rig

from femast.cli import main
from femast.experiments import compare, diagnose, fit, write_data
from femast.experiments.heldout import folds

START = {"k_x": 2e6, "k_y": 3e6}


def test_a_fit_on_some_rows_ignores_the_others_and_predicts_them():
    data = rig.data(gap_x=0.0, n=300, seed=21)
    bad = np.zeros(data.n, bool)
    bad[100:150] = True
    data.columns["ux_mm"] = np.where(bad, data["ux_mm"] + 0.5, data["ux_mm"])  # a block the fit must not see
    sigma = {"ux_mm": np.full(data.n, 5e-3), "uy_mm": np.full(data.n, 5e-3)}
    f = fit(data=data, exp=rig.RIG, start=START, noise=sigma, rows=~bad)
    assert abs(f.x[0] - rig.K[0]) < 4 * f.stderr[0] < 0.005 * rig.K[0]  # as if the block were not there
    all_rows = fit(data=data, exp=rig.RIG, start=START, noise=sigma)
    assert abs(all_rows.x[0] - rig.K[0]) > 20 * f.stderr[0]  # seen, it pulls the stiffness off
    assert np.abs(f.residuals["ux_mm"][bad] - 0.5).max() < 0.03  # predicted there: the offset is the error


def test_folds_are_the_groups_else_blocks_of_whole_cycles():
    data = rig.data(gap_x=0.0, n=400)
    fl = folds(rig.RIG, data)
    assert len(fl) == 4 and all(m.sum() >= 50 for _, m in fl)
    assert np.array_equal(np.sum([m for _, m in fl], axis=0), np.ones(data.n))  # every row left out once
    assert all(name.startswith("cycles") for name, _ in fl)
    g = np.repeat(["A", "B", "C"], [100, 150, 150])
    grouped = rig.data(gap_x=0.0, n=400, groups=g)
    fg = folds(rig.RIG, grouped)
    assert [name for name, _ in fg] == ["group A", "group B", "group C"]
    assert [int(m.sum()) for _, m in fg] == [100, 150, 150]


def test_diagnose_keeps_the_mechanism_that_lowers_the_held_out_error_and_refuses_an_absent_second_one():
    data = rig.data(gap_x=2e-4, n=400, seed=3)  # a gap along x only, no other mechanism
    d = diagnose(rig.RIG, data, ["joint_clearance", "friction_hysteresis", "pretension_loss"], workers=1)
    best = d.ranking[0]
    assert best["effect"] == "joint_clearance" and best["form"] == "per_axis" and best["heldout_ok"]
    assert best["heldout_ratio"] < 1.2 < d.report["baseline"]["heldout_ratio"]
    assert d.verdict["kind"] == "missing_effect"
    # pairs that add friction or a stiffness loss fit as well (a spare parameter at zero) but are no
    # better than the clearance alone on data they have not seen: refused
    for p in d.pairs:
        if "heldout_ratio" in p:
            assert not p["heldout_ok"], p
    assert "held out" in d.report["ranking"][0] or "heldout_ratio" in d.report["ranking"][0]


def test_fit_on_one_file_score_another(tmp_path, capsys):
    a, b = rig.data(gap_x=2e-4, n=300, seed=31), rig.data(gap_x=2e-4, n=300, seed=32)
    c1 = compare(rig.RIG, a, ["joint_clearance/per_axis"], fit=True)
    c2 = compare(rig.RIG, b, params=c1.params)  # the effects of "effect.param" names are switched on
    assert c2.effects == ("joint_clearance/per_axis",) and not c2.fitted
    assert c2.ratio < 1.3  # the fit of file a predicts file b to its noise
    assert set(c1.params) == set(c1.params_table) and isinstance(c1.params["k_x"], float)
    # the same from the command line: the RUN is the first compare's folder
    script = tmp_path / "rig.py"
    script.write_text("from two_axis_rig import RIG as experiment\n")
    for name, d in (("a.csv", a), ("b.csv", b)):
        write_data(tmp_path / name, d, rig.RIG)
    args = [str(script), str(tmp_path / "a.csv"), "--effects", "joint_clearance/per_axis", "--fit"]
    assert main(["compare", *args, "--out", str(tmp_path / "fit_a")]) == 0
    out_b = tmp_path / "score_b"
    assert (
        main(
            [
                "compare",
                str(script),
                str(tmp_path / "b.csv"),
                "--params-from",
                str(tmp_path / "fit_a"),
                "--out",
                str(out_b),
            ]
        )
        == 0
    )
    capsys.readouterr()
    rep = json.loads((out_b / "compare.json").read_text())
    assert rep["effects"] == ["joint_clearance/per_axis"] and not rep["fit"]
    assert rep["params"]["joint_clearance/per_axis.c_x"]["value"] == pytest.approx(
        c1.params["joint_clearance/per_axis.c_x"], rel=1e-6
    )
    assert rep["ratio"] < 1.3
    assert main(["compare", str(script), str(tmp_path / "b.csv"), "--params-from", str(tmp_path / "nothing")]) == 2
    assert "no compare.json there" in capsys.readouterr().err


def test_nothing_significant_nothing_held_out(monkeypatch):
    """The held-out check can only refuse a candidate or a pair: without a significant one it refits
    nothing (the verdict cannot depend on it), and the report has no held-out ratio of the baseline."""
    from femast.experiments import heldout

    calls = []
    monkeypatch.setattr(heldout, "folds", lambda *a, **k: calls.append(a) or [])
    data = rig.data(gap_x=0.0, n=300, seed=4)  # springs only: nothing is missing
    d = diagnose(rig.RIG, data, ["joint_clearance", "friction_hysteresis"], workers=1)
    assert d.verdict["kind"] == "nothing_missing"
    assert not any(e["significant"] for e in d.ranking)
    assert calls == [] and d.report["baseline"]["heldout_ratio"] is None
