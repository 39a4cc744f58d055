"""Per-joint, per-latch, per-side and per-member scatter of the ADAM mast builder."""

import numpy as np
import pytest

import femast as fm
from femast.adam import BayParameters, build_mast
from femast.adam.scatter import MastScatter
from femast.adam.steps import CONVERGENCE, add_initial_steps
from femast.elements.base import IncrementContext
from femast.errors import ModelError


def _family(am, name):
    return next(f for f in am.model.families if f.name == name)


def _deploy(am, frames=None):
    add_initial_steps(am)
    an = fm.Analysis(
        am.model,
        None,
        progress=False,
        convergence=CONVERGENCE,
        on_frame=(lambda fr: None) if frames is None else frames.append,
    )
    an.run()
    return an


def test_per_element_values_reach_the_right_elements():
    n = 2
    rng = np.random.default_rng(3)
    mu = rng.uniform(0.3, 0.7, (n, 4, 2))
    k = rng.uniform(80e3, 120e3, (n, 4))
    lmu = rng.uniform(0.05, 0.09, (n, 4))
    pre = rng.uniform(150.0, 190.0, (n, 4))
    am = build_mast(n, scatter=MastScatter(mu=mu, latch_k=k, latch_mu=lmu, pretension=pre))
    joints = _family(am, am.joint_family)
    for j in range(n):
        for c in range(4):
            for e in range(2):  # bottom joint ties the longeron's bottom end to corner (j, c)
                row = np.flatnonzero(
                    (joints.nodes[:, 0] == am.longerons[j, c, e]) & (joints.nodes[:, 1] == am.corners[j + e, c])
                )
                assert row.size == 1 and joints.mu[row[0]] == mu[j, c, e]
    latch = am.latch
    np.testing.assert_array_equal(latch.latch[:, 2], k.ravel())  # rows in latch_labels order
    np.testing.assert_array_equal(latch.latch[:, 3], lmu.ravel())
    # each side's latch cable carries its pretension in the built geometry (both sections)
    X = np.zeros((am.model.node_labels.max() + 1, 3))
    X[am.model.node_labels] = am.model.coordinates
    r = latch.evaluate(X, None, latch.initial_state(), IncrementContext())
    np.testing.assert_allclose(r.output["tension"], np.repeat(pre.reshape(-1, 1), 2, axis=1), rtol=1e-12)  # round-off
    arms = [t for t in am.model.trusses if t.family == am.arm_family]
    np.testing.assert_array_equal([t.pretension for t in arms], np.repeat(pre.ravel(), 2))


def test_uniform_scatter_is_bit_for_bit_the_scalar_parameter():
    """Per-element arrays holding one value give exactly the mast built from the scalar parameter."""
    p = BayParameters().with_(pretension=187.0, mu=0.45)
    a = _deploy(build_mast(2, p))
    b = _deploy(build_mast(2, scatter=MastScatter(pretension=np.full((2, 4), 187.0), mu=np.full((2, 4, 2), 0.45))))
    assert np.array_equal(a.x, b.x)


def test_uniform_longeron_length_error_lifts_the_tip_without_tilt_or_twist():
    """All longerons dL long: by the four-fold symmetry of each bay's geometry the tip rises, with no
    sideways motion and no tilt; the rise lies between 0 and n dL (the cables resist it) and doubles
    with dL (linear for dL << member length)."""
    n, dL = 2, 0.05e-3
    base = _deploy(build_mast(n, alternate=False))
    ctl = base.model.index(build_mast(n).control)
    rise = []
    for d in (dL, 2 * dL):
        an = _deploy(build_mast(n, alternate=False, scatter=MastScatter(longeron_dL=d)))
        u = an.x[ctl] - base.x[ctl]
        assert abs(u[0]) < 1e-3 * u[2] and abs(u[1]) < 1e-3 * u[2]  # the chiral cable net: a few 1e-4 of the rise
        rise.append(u[2])
    assert 0 < rise[0] < n * dL
    np.testing.assert_allclose(rise[1], 2 * rise[0], rtol=1e-3)  # second order in dL / l ~ 3e-4


def test_short_latch_cable_section_raises_its_tension_by_EA_d_over_2L():
    """Section 0 of one side's latch cable 0.05 mm short, bead on its backstop: that section and the
    arm on the same diagonal (equal length L_A, same EA) are two springs in series between the
    corners, so the unit node moves d/2 along the diagonal and the tension rises by EA d / (2 L_A)
    on rigid corners; the bay (longerons, frames) gives a little, so slightly less."""
    d = 0.05e-3
    cable = np.zeros((1, 4, 2))
    cable[0, 2, 0] = -d
    p = BayParameters()
    out = []
    for sc in (None, MastScatter(cable_dL=cable)):
        frames = []
        _deploy(build_mast(1, scatter=sc), frames)
        out.append(frames[-1]["el/adam_latch/tension"][2])
    dT = out[1][0] - out[0][0]
    LA = 0.5 * p.diagonal
    ref = p.cable_EA * d / (2 * LA)
    assert 0.95 * ref < dT <= ref * (1 + 1e-9)  # the bay's compliance takes ~1 % (measured 0.989 ref)


@pytest.mark.parametrize(
    "sc, words",
    [
        (
            dict(mu=np.r_[[0.5] * 7, -0.1].reshape(1, 4, 2)),
            r"MastScatter.mu\[0, 3, 1\] \(bay 0, corner 3, end 1\) = -0.1",
        ),
        (dict(latch_k=np.zeros((1, 4))), r"MastScatter.latch_k\[0, 0\] \(bay 0, side 0\) = 0.0 N/m must be > 0"),
        (
            dict(pretension=np.full((2, 4), 170.0)),
            r"MastScatter.pretension: give a number or an array of shape \(1, 4\)",
        ),
        (dict(longeron_dL=0.05), r"MastScatter.longeron_dL\[0, 0\] .* give it in m"),
        (dict(batten_dL=np.nan), r"MastScatter.batten_dL\[0, 0\] \(frame 0, side 0\) = nan"),
        (dict(friction=0.5), r"unknown item\(s\) 'friction'"),
    ],
)
def test_bad_scatter_names_the_item(sc, words):
    with pytest.raises(ModelError, match=words):
        build_mast(1, scatter=sc)


def test_stated_scatter_samples_lie_in_their_bounds_and_midpoints_are_nominal():
    from femast.adam.shape_study import GROUPS, n_uniforms, sample_scatter, stated_inputs

    n = 3
    p = BayParameters()
    need = n_uniforms(n)
    mid = sample_scatter({g: np.full(need[g], 0.5) for g in GROUPS}, n)
    sc = MastScatter(**mid).resolve(n, p)
    assert np.all(sc["mu"] == p.mu) and np.all(sc["pretension"] == p.pretension)
    assert not np.any(sc["longeron_dL"]) and not np.any(sc["cable_dL"])
    rng = np.random.default_rng(0)
    vals = sample_scatter({g: rng.random(need[g]) for g in GROUPS}, n)
    for _g, field, lo, hi, size, _unit in stated_inputs(n):
        a = np.asarray(vals[field])
        assert a.size == size and np.all((a >= lo) & (a <= hi)), field
    pre = [(lo, hi) for _, f, lo, hi, _, _ in stated_inputs(n) if f == "pretension"]
    np.testing.assert_allclose(pre, [(153.0, 187.0)], rtol=1e-15)  # 170 N +- 10 %, round-off of 170 x 1.1
    with pytest.raises(ModelError, match="group 'latch' needs 24 uniform numbers"):
        sample_scatter({g: rng.random(need[g] - (g == "latch")) for g in GROUPS}, n)


def test_tip_history_reports_every_load_level_and_the_nominal_mast_deploys_straight():
    from femast.adam.shape_study import tip_history

    h = tip_history(2, None, cycles=1)
    assert h["labels"] == ["equilibrium", "M+F#1", "0a#1", "-M-F#1", "0b#1"]
    # the nominal mast shortens under its pretension, with no sideways motion or rotation
    # (round-off and the 1e-9 force tolerance: far below 1 nm and 1e-8 rad)
    assert h["u"][0, 2] < 0 and np.abs(h["u"][0, :2]).max() < 1e-9 and np.abs(h["theta"][0]).max() < 1e-8
    assert h["theta"][1, 2] > 0 > h["theta"][3, 2]  # M twists the tip one way, -M the other


def test_tip_history_increments_change_only_the_friction_path():
    """Frictionless joints: the mast is elastic, its tip at every load level independent of the
    increments per step (to the Newton tolerance); with friction the return over an increment is
    first order, so the residual moves with the increments."""
    from femast.adam import BayParameters
    from femast.adam.shape_study import tip_history

    elastic = BayParameters(mu=0.0)
    a = tip_history(2, None, cycles=1, params=elastic, increments=1)
    b = tip_history(2, None, cycles=1, params=elastic, increments=3)
    np.testing.assert_allclose(b["u"], a["u"], rtol=0, atol=1e-6 * np.abs(a["u"]).max())
    np.testing.assert_allclose(b["theta"], a["theta"], rtol=0, atol=1e-6 * np.abs(a["theta"]).max())
    f1 = tip_history(2, None, cycles=1, increments=1)
    f3 = tip_history(2, None, cycles=1, increments=3)
    assert f3["iterations"] > f1["iterations"]
    assert not np.allclose(f3["theta"][-1], f1["theta"][-1], rtol=1e-6, atol=0)
