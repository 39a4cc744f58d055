"""Creep told from friction by the holds of a test (femast.experiments.time_dependence).

Data with a hidden mechanism come from the independent generator of the generalisation benchmark
(benchmarks/generalisation: Boltzmann superposition of a logarithmic creep function, an elasto-slip
joint; numpy only).
"""

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))

from generalisation import connection as conn  # noqa: E402
from generalisation.cases import _m, generate, get_case  # noqa: E402

from femast.experiments.time_dependence import CREEP_T, creep_overrules, hold_drift, holds, reads_time  # noqa: E402

CH = ("dx_m", "dy_m", "dz_m")


def test_holds_are_the_runs_of_a_constant_load():
    s = np.r_[np.linspace(0, 1, 5), np.ones(8), np.linspace(1, -1, 5)[1:], -np.ones(4), np.zeros(7)]
    assert holds(s) == [(4, 12), (21, 27)]  # the four rows at -1 are too few
    assert holds(s + 1e-3 * np.sin(np.arange(s.size)), noise=1e-3) == [(4, 12), (21, 27)]


def test_a_steady_drift_at_constant_load_is_measured_in_noise_units():
    # ramps to +-1 and holds of 12 rows; the response moves on by r per row while held, towards the last load change
    n_h, m, r, sigma = 12, 4, 0.05, 0.1
    s, u = [0.0], [0.0]
    for k in range(10):
        target = 1.0 if k % 2 == 0 else -1.0
        s += list(np.linspace(s[-1], target, 6)[1:]) + [target] * n_h
        u += list(np.linspace(u[-1], target, 6)[1:]) + list(target + np.sign(target) * r * np.arange(n_h))
    s, u = np.array(s), np.array(u)
    rng = np.random.default_rng(0)
    out = hold_drift(s, {"u": u + sigma * rng.standard_normal(u.size)}, {"u": sigma})
    assert out["holds"] == 10
    # last third minus first third of a linear drift: r (n_h - m) rows, in units of sigma sqrt(2/m)
    expected = r * (n_h - m) / sigma / np.sqrt(2.0 / m)
    assert out["drift"] == pytest.approx(expected, rel=0.15)  # 10 holds: the mean carries 1/sqrt(10) of the noise
    assert out["creep"]


def test_rate_independent_data_do_not_creep_and_white_noise_rarely_says_so():
    rng = np.random.default_rng(1)
    s = np.repeat(np.tile([1.0, 0.0, -1.0, 0.0], 4), 12)
    t = [hold_drift(s, {"u": s + rng.standard_normal(s.size)}, {"u": 1.0})["t"] for _ in range(400)]
    # Student t with 14 degrees of freedom: P(t > 4) = 6.6e-4
    assert np.mean(np.array(t) > CREEP_T) <= 3 / 400


@pytest.mark.parametrize(
    "mechanism,creep",
    [
        (_m("creep", "log", phi=0.08, t0=1.0), True),
        (_m("friction", "jenkins", k_s=2.5e5, F_s=7.0), False),
        (None, False),
    ],
    ids=["log creep", "friction", "plain joint"],
)
def test_creep_is_told_from_friction_on_independent_data(mechanism, creep):
    case = replace(get_case("mt_creep_log"), mechanisms=(mechanism,) if mechanism else ())
    for seed in range(4):
        cols = generate(case, seed)
        load = np.hypot(cols["fx_N"], cols["fy_N"]) * np.sign(cols["fx_N"])
        out = hold_drift(load, {c: cols[c] for c in CH}, {c: 25e-6 for c in CH})
        assert out["holds"] == 16
        assert out["creep"] is creep, (seed, out["t"])


CREEP = {"holds": 16, "t": 7.4, "drift": 2.1, "creep": True}
STILL = {"holds": 16, "t": 0.6, "drift": 0.1, "creep": False}


def _verdict(kind, effects):
    return {
        "kind": kind,
        "missing_effect": effects[0] if len(effects) == 1 else None,
        "missing_effects": list(effects),
        "mechanism": effects[0] if kind == "form_imperfect" else None,
        "conclusion": f"{kind}: {' + '.join(effects)}",
        "try_next": [],
    }


@pytest.mark.parametrize("kind", ["missing_effect", "form_imperfect", "missing_pair"])
def test_creep_overrules_a_verdict_that_names_only_rate_independent_effects(kind):
    effects = ["friction_hysteresis", "joint_clearance"] if kind == "missing_pair" else ["friction_hysteresis"]
    v = creep_overrules(_verdict(kind, effects), CREEP, lambda name: name == "pretension_loss")
    assert v["kind"] == "not_explained" and v["missing_effects"] == [] and v["mechanism"] is None
    assert "keeps moving while the load is held" in v["conclusion"] and "t = 7.4 over 16 holds" in v["conclusion"]
    assert v["time_dependence"]["creep"] is True


def test_a_time_dependent_answer_or_still_holds_leave_the_verdict_alone():
    v0 = _verdict("missing_effect", ["pretension_loss"])
    assert creep_overrules(v0, CREEP, lambda name: name == "pretension_loss")["kind"] == "missing_effect"
    v1 = _verdict("missing_effect", ["friction_hysteresis"])
    v = creep_overrules(v1, STILL, lambda name: False)
    assert v["kind"] == "missing_effect" and v["conclusion"] == v1["conclusion"]
    assert v["time_dependence"] == STILL


def test_which_effects_read_the_time():
    from femast.experiments import get_experiment

    exp = get_experiment("mast-top")
    assert reads_time(exp, "pretension_loss")
    assert not reads_time(exp, "friction_hysteresis") and not reads_time(exp, "friction_hysteresis/iwan")
    assert not reads_time(exp, "no_such_effect")


def test_a_yield_plateau_under_displacement_control_is_no_hold():
    # a connection driven through displacement cycles: past yield its force stays nearly flat while
    # the displacement moves on at the drive's rate -- rate-independent, no creep
    u, _ = conn.cyclic_protocol((1e-3, 2e-3, 3e-3, 4e-3), step=0.04e-3)
    F = conn.bwbn_driven(u, conn.BWBN(), substeps=8)  # smooth Bouc-Wen: 5 % post-yield stiffness
    for seed in range(3):
        rng = np.random.default_rng(seed)
        Fm, um = F + rng.normal(0, 20.0, F.size), u + rng.normal(0, 20e-6, u.size)
        out = hold_drift(Fm, {"u_m": um}, {"u_m": 20e-6}, noise_load=20.0)
        assert not out["creep"], (seed, out)
