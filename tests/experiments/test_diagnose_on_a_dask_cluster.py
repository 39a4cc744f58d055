"""``femast diagnose ... --scheduler tcp://...`` against a real ``dask scheduler`` and ``dask worker``
started as separate processes (not an in-process client): the refits run on the worker, and the
verdict and the ranking are those of a serial run.  Two experiments: the built-in mast-top (finite
elements, the worker rebuilds the rig) and a user's experiment and effect from a script (the worker
loads the script)."""

import json
import subprocess
import sys
from pathlib import Path

import pytest
from dask_processes import dask_cluster
from spring_rig import spring_script

from femast.cli import main

pytest.importorskip("distributed")

ROOT = Path(__file__).resolve().parents[2]
MT_DATA = ROOT / "femast" / "examples" / "mast_top_example.csv"

SPRING = spring_script("spring-on-a-cluster", "mount_slip")


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    with dask_cluster(tmp_path_factory.mktemp("dask")) as address:
        yield address


@pytest.fixture
def spring_files(tmp_path, request):
    import numpy as np

    from femast.effects import unregister_effect

    script = tmp_path / "spring_on_a_cluster.py"
    script.write_text(SPRING)
    t = np.linspace(0, 1, 300)
    F = 100 * np.sin(2 * np.pi * 3 * t) * (0.6 + 0.4 * t)
    # the hidden slip as a smooth ramp of another form (a logistic, not a tanh): 0.2 mm either way
    u = F / 2e4 + 2e-4 * (2 / (1 + np.exp(-3 * F)) - 1) + np.random.default_rng(0).normal(0, 2e-5, t.size)
    csv = tmp_path / "spring.csv"
    csv.write_text("F_N,u_m\n" + "\n".join(f"{a:.6g},{b:.6g}" for a, b in zip(F, u)) + "\n")
    request.addfinalizer(lambda: unregister_effect("mount_slip"))
    return script, csv


def _cli_on_the_cluster(args, address, out):
    """The command as a user runs it (its own process); returns the parsed JSON report."""
    p = subprocess.run(
        [sys.executable, "-m", "femast.cli", "diagnose", *args, "--json", "--scheduler", address, "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert p.returncode == 0, p.stderr[-3000:]
    return json.loads(p.stdout)


def _serial(capsys, args, out):
    assert main(["diagnose", *args, "--json", "--workers", "1", "--out", str(out)]) == 0
    return json.loads(capsys.readouterr().out)


def _same_diagnosis(a, b):
    assert b["executor"] == "serial (in this process)"
    assert a["executor"].startswith("dask.distributed at tcp://127.0.0.1:")
    for key in ("kind", "missing_effect", "missing_effects", "best_candidate"):
        assert a["verdict"][key] == b["verdict"][key], key
    assert [r["effect"] for r in a["ranking"]] == [r["effect"] for r in b["ranking"]]
    for ra, rb in zip(a["ranking"], b["ranking"]):
        assert ra["delta_bic"] == pytest.approx(rb["delta_bic"], rel=1e-9, abs=1e-9), ra["effect"]


def test_diagnose_of_a_built_in_fe_experiment_on_a_separate_dask_scheduler_and_worker(cluster, tmp_path, capsys):
    # three of its candidates (every candidate costs the suite time; three make a ranking and a pair)
    args = ["mast-top", str(MT_DATA), "--candidates", "joint_clearance,friction_hysteresis,pretension_loss"]
    a = _cli_on_the_cluster(args, cluster, tmp_path / "dask")
    b = _serial(capsys, args, tmp_path / "serial")
    _same_diagnosis(a, b)
    # the example hides a joint clearance and friction hysteresis: the pair explains it
    assert set(a["verdict"]["missing_effects"]) == {"joint_clearance", "friction_hysteresis"}


def test_diagnose_of_a_user_script_on_a_separate_dask_scheduler_and_worker(cluster, spring_files, tmp_path, capsys):
    script, csv = spring_files
    args = [str(script), str(csv)]
    a = _cli_on_the_cluster(args, cluster, tmp_path / "dask")
    b = _serial(capsys, args, tmp_path / "serial")
    _same_diagnosis(a, b)
    assert a["verdict"]["missing_effect"] == "mount_slip"
