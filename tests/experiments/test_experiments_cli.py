"""``femast compare`` / ``femast diagnose``: JSON reports, files, history, user scripts, parallel refits."""

import json
import os
import textwrap
from pathlib import Path

import numpy as np
import pytest
from spring_rig import spring_script

from femast.cli import main
from femast.effects import unregister_effect
from femast.experiments import diagnose, get_experiment, read_data, read_history, write_data
from femast.rigs.synthetic import mast_top_data, mast_top_path

ROOT = Path(__file__).resolve().parents[2]
MT_DATA = ROOT / "femast" / "examples" / "mast_top_example.csv"

USER_EXPERIMENT = spring_script("spring-test", "spring_slip")

USER_EFFECT = textwrap.dedent('''
    """A user effect for the built-in mast-top experiment: a linear thermal drift of the top."""
    from femast.effects import Effect, Implementation, register_effect
    from femast.experiments import Parameter

    def _drift(d, p, ctx):
        tau = ctx["prep"]["tau"]
        d = d.copy()
        d[:, 0] += p["vx"] * tau
        d[:, 1] += p["vy"] * tau
        return d

    register_effect(Effect(
        name="thermal_drift", title="thermal drift of the top", physics="the top drifts linearly in time.",
        implementations={"mast-top": Implementation(hook="top_displacement", apply=_drift, parameters=(
            Parameter("vx", "m", 0.0, -0.01, 0.01, "drift along x over the test", scale=1e-4),
            Parameter("vy", "m", 0.0, -0.01, 0.01, "drift along y over the test", scale=1e-4)))}),
        replace_existing=True)
''')


@pytest.fixture(scope="module")
def spring(tmp_path_factory):
    d = tmp_path_factory.mktemp("spring")
    script = d / "spring_test.py"
    script.write_text(USER_EXPERIMENT)
    t = np.linspace(0, 1, 300)
    F = 100 * np.sin(2 * np.pi * 3 * t) * (0.6 + 0.4 * t)
    u = F / 2e4 + 2e-4 * np.tanh(F / 1.0) + np.random.default_rng(0).normal(0, 2e-5, t.size)
    (d / "spring.csv").write_text("F_N,u_m\n" + "\n".join(f"{a:.6g},{b:.6g}" for a, b in zip(F, u)) + "\n")
    return script, d / "spring.csv"


def _run_json(capsys, argv):
    assert main(argv) == 0
    return json.loads(capsys.readouterr().out)


def test_compare_json_files_and_history_show_the_error_falling(tmp_path, capsys):
    out = tmp_path / "out"
    runs = [
        [],
        ["--fit"],
        ["--effects", "joint_clearance", "--fit"],
        ["--effects", "joint_clearance,friction_hysteresis", "--fit"],
    ]
    reports = [_run_json(capsys, ["compare", "mast-top", str(MT_DATA), "--out", str(out), "--json"] + r) for r in runs]
    r = reports[-1]
    for key in (
        "experiment",
        "data",
        "n_samples",
        "effects",
        "fit",
        "params",
        "error_unit",
        "rms",
        "noise_rms",
        "ratio",
        "channels",
        "segments_by_kind",
        "worst_segments",
        "version",
        "files",
    ):
        assert key in r
    assert r["experiment"] == "mast-top" and r["n_samples"] == 500 and r["error_unit"] == "m"
    assert set(r["channels"]) == {"dx_m", "dy_m", "dz_m"}
    assert r["params"]["joint_clearance.c"]["unit"] == "rad" and r["params"]["k_theta1"]["stderr"] > 0
    w = r["worst_segments"][0]
    assert {"kind", "start_row", "end_row", "first_line", "last_line", "rms", "ratio"} <= set(w)
    assert w["first_line"] == w["start_row"] + 5  # three comment lines and the header precede the rows
    rms = [x["rms"] for x in reports]
    assert rms[0] > rms[1] > rms[2] > rms[3]  # the error falls with each version
    assert r["ratio"] <= 1.2  # the last version is at the noise floor
    hist = read_history(out)
    assert [h["version"] for h in hist] == [1, 2, 3, 4]
    assert hist[3]["effects"] == ["joint_clearance", "friction_hysteresis"] and hist[1]["fit"] is True
    for f in ("compare.png", "compare.json", "history.png", "history.jsonl"):
        assert (out / f).stat().st_size > 0
    assert json.loads((out / "compare.json").read_text())["version"] == 4


def test_diagnose_json_schema(example_run):
    # `femast diagnose mast-top example --workers 1` (run once per session): its diagnose.json, the
    # report --json prints
    run = example_run("diagnose", "mast-top")
    r = run.report
    assert {"experiment", "n_samples", "noise_rms", "baseline", "ranking", "verdict"} <= set(r)
    assert {"rms", "params"} <= set(r["baseline"])
    for e in r["ranking"]:
        assert {"effect", "rms", "delta_bic", "params", "significant"} <= set(e)
        assert isinstance(e["significant"], bool)
        for p in e["params"].values():
            assert {"value", "stderr", "unit"} <= set(p)
    assert [e["delta_bic"] for e in r["ranking"]] == sorted(e["delta_bic"] for e in r["ranking"])
    assert set(r["verdict"]) >= {"missing_effect", "explained"}
    # the example hides two effects: the best single one does not explain it all, the pair does
    assert r["verdict"] == {
        **r["verdict"],
        "missing_effect": None,
        "explained": True,
        "kind": "missing_pair",
        "best_candidate": "joint_clearance",
    }
    assert sorted(r["verdict"]["missing_effects"]) == ["friction_hysteresis", "joint_clearance"]
    assert {"noise_model", "n_eff", "pairs", "form_check"} <= set(r)
    assert {"form", "forms", "ic_gain", "share_ok"} <= set(r["ranking"][0])
    assert (run.out / "diagnose.png").stat().st_size > 0 and r["files"]["json"] == str(run.out / "diagnose.json")
    # with joint_clearance in the model, friction_hysteresis is what is missing: the tutorial quotes that
    # diagnosis (docs/compare_and_diagnose.md, test_experiments_docs.py), not run a second time here


def test_text_output(tmp_path, capsys, example_run):
    assert (
        main(
            [
                "compare",
                "latch-pull",
                str(ROOT / "femast/examples/latch_pull_example.csv"),
                "--fit",
                "--out",
                str(tmp_path),
            ]
        )
        == 0
    )
    text = capsys.readouterr().out
    assert "overall RMS error" in text and "noise floor" in text and "worst segments:" in text
    assert "x_backstop =" in text and "file lines" in text
    # `femast diagnose latch-pull example --workers 1`, run once per session for the tests that read it
    text = example_run("diagnose", "latch-pull").stdout
    assert "verdict: missing effect: latch_hysteresis" in text and "reading of #1" in text


def test_parallel_refits_in_processes_match_serial():
    exp = get_experiment("mast-top")
    data = read_data(exp, MT_DATA)
    # three candidates (their forms: more refits than workers), no pairs or held-out stage: the refits alone
    refits = dict(candidates=["joint_clearance", "friction_hysteresis", "cable_hysteresis"], pairs=False, heldout=False)
    serial = diagnose(exp, data, workers=1, **refits)
    par = diagnose(exp, data, workers=2, **refits)
    assert par.executor == "2 local processes"
    assert {f.pid for f in par.fits.values()} - {os.getpid()}  # the refits ran in worker processes
    assert len(serial.ranking) == len(par.ranking) >= 3
    for a, b in zip(serial.ranking, par.ranking):
        assert a["effect"] == b["effect"]
        assert a["delta_bic"] == pytest.approx(b["delta_bic"], rel=1e-9, abs=1e-6)  # same deterministic fits


def test_user_experiment_and_effect_from_a_script(spring, tmp_path, capsys):
    script, csv = spring
    r = _run_json(capsys, ["diagnose", str(script), str(csv), "--out", str(tmp_path), "--json", "--workers", "2"])
    assert r["experiment"] == "spring-test"
    assert r["verdict"]["missing_effect"] == "spring_slip"
    s = r["ranking"][0]["params"]["s"]
    assert abs(s["value"] - 2e-4) < 4 * s["stderr"]  # within 4 standard errors of the hidden slip
    r = _run_json(
        capsys,
        ["compare", str(script), str(csv), "--effects", "spring_slip", "--fit", "--out", str(tmp_path), "--json"],
    )
    assert r["ratio"] <= 1.2


def test_user_effect_script_for_a_built_in_experiment(tmp_path, capsys, request):
    request.addfinalizer(lambda: unregister_effect("thermal_drift"))  # not a candidate of later mast-top diagnoses
    eff = tmp_path / "drift.py"
    eff.write_text(USER_EFFECT)
    data, _ = mast_top_data(path=mast_top_path(kind="ramps", seed=5), seed=5)
    tau = data.tau
    data.columns["dx_m"] = data["dx_m"] + 4e-4 * tau
    data.columns["dy_m"] = data["dy_m"] - 2e-4 * tau
    csv = write_data(tmp_path / "drifting.csv", data, get_experiment("mast-top"))
    base = _run_json(capsys, ["compare", "mast-top", str(csv), "--fit", "--json", "--out", str(tmp_path)])
    r = _run_json(
        capsys,
        [
            "compare",
            "mast-top",
            str(csv),
            "--fit",
            "--json",
            "--out",
            str(tmp_path),
            "--effects",
            f"{eff}:thermal_drift",
        ],
    )
    assert base["ratio"] > 2 and r["ratio"] <= 1.2
    assert r["params"]["thermal_drift.vx"]["value"] == pytest.approx(4e-4, rel=0.05)  # 0.4 mm drift, 0.05 mm noise
    r2 = _run_json(
        capsys, ["compare", "mast-top", str(csv), "--fit", "--json", "--out", str(tmp_path), "--effects", str(eff)]
    )  # every effect of the script
    assert r2["effects"] == ["thermal_drift"]


# slow: a user's script diagnosed on dask processes with the serial result is the default suite's
# test_diagnose_on_a_dask_cluster.py (a separate scheduler and worker, as users run it)
@pytest.mark.slow
def test_dask_local_cluster(spring):
    distributed = pytest.importorskip("distributed")
    script, csv = spring
    exp = get_experiment(str(script))
    data = read_data(exp, csv)
    serial = diagnose(exp, data, workers=1)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        d = diagnose(exp, data, scheduler=cluster.scheduler_address)
        # the workers are fresh processes: they re-loaded the user script to rebuild the experiment
        assert d.executor.startswith("dask.distributed at tcp://")
        assert {f.pid for f in d.fits.values()}.isdisjoint({os.getpid()})
    assert d.verdict["missing_effect"] == "spring_slip"
    assert d.ranking[0]["delta_bic"] == pytest.approx(serial.ranking[0]["delta_bic"], rel=1e-9)
