"""Friction ball joint (Stohlman & Pellegrino, Sec. II.B.1): slip plateau at mu B |F|, dissipated energy per
cycle, no moment without force, consistent tangent (finite differences, stick and slip),
commit/rollback, a two-beam model solved with fm.solve, bad input."""

from __future__ import annotations

import numpy as np
import pytest
from doc_examples import printed_in, run_python_blocks

import femast as fm
from femast.elements.ball_joint import (
    PENALTY_FACTOR,
    STICK_FACTOR,
    BallJointFamily,
    add_ball_joints,
    default_stiffnesses,
    friction_loop_energy,
)
from femast.errors import ModelError
from femast.rotations import expm_so3
from femast.testing import fd_tangent

MU, B = 0.5, 0.004  # Stohlman & Pellegrino, Sec. II.B.1


# ----------------------------------------------------------------------------- helpers
def single_joint_model(P, A, k_stick=2000.0, max_increment=0.1, family=None, name="joint"):
    """Node a fixed; node b loaded by a constant axial force -P (x), its other translations and
    rx, ry held, rz cycled 0 -> +A -> -A -> +A (step 'cycle', step times 0, 1, 3, 5)."""
    m = fm.Model(name)
    a, b = m.node(0.0, 0.0, 0.0), m.node(0.0, 0.0, 0.0)
    if family is None:
        add_ball_joints(m, [(a, b)], MU, B, k_pen=1e8, k_stick=k_stick)
    else:
        m.add_family(family)
    m.fix(a)
    m.fix(b, "uy", "uz", "rx", "ry")
    s = m.step("press")
    s.load(b, fx=-P)
    s.prescribe(b, rz=0.0)
    amp = fm.Amplitude([0.0, 1.0, 3.0, 5.0], [0.0, 1.0, -1.0, 1.0])
    m.step("cycle", period=5.0, max_increment=max_increment).prescribe(b, amplitude=amp, rz=A)
    return m, a, b


def histories(res, b, fam="ball_joint"):
    return dict(
        t=res.time,
        rz=res.node_history(b, "rz"),
        M=res.element_history(fam, 1, "moment")[:, 2],
        F=res.element_history(fam, 1, "F"),
        limit=res.element_history(fam, 1, "limit"),
        slip=res.element_history(fam, 1, "slip"),
        D=res.element_history(fam, 1, "dissipated"),
        rmz=res.node_history(b, "rmz"),
    )


def at(h, total_time):
    i = int(np.argmin(np.abs(h["t"] - total_time)))
    assert abs(h["t"][i] - total_time) < 1e-9  # the amplitude's table times are hit exactly
    return i


# ----------------------------------------------------------------------- friction loop
@pytest.mark.parametrize("P, max_increment", [(1000.0, 0.1), (250.0, 0.1), (1000.0, 0.7)])
def test_loop_plateau_and_energy_per_cycle(tmp_path, P, max_increment):
    A, ks = 0.02, 2000.0
    m, a, b = single_joint_model(P, A, ks, max_increment)
    h = histories(fm.solve(m, tmp_path, progress=False), b)
    Y = MU * B * P
    # the tie carries the applied force (equilibrium of node b)
    assert np.allclose(h["F"][1:], P, rtol=1e-9)  # the tie is linear: Newton solves it to round-off
    # plateau exactly at mu B |F| and never above it
    assert np.max(np.abs(h["M"])) <= Y * (1 + 1e-12)  # return mapping lands on |m| = Y to round-off
    slip = h["slip"] > 0
    assert slip.sum() > 3
    assert np.allclose(np.abs(h["M"][slip]), Y, rtol=1e-12)  # radial return: |M| = Y exactly when slipping
    # reaction moment at the rotated node is the joint moment (no other element there)
    assert np.allclose(h["rmz"], h["M"], atol=1e-9 * Y)  # residual moments are 1e-6 relative or better
    # stick branches: slope k_stick from the turning points
    for t_turn, sign in ((2.0, -1.0), (4.0, 1.0)):
        i = at(h, t_turn)
        j = i + 1
        if not h["slip"][j]:
            # elastic predictor is exactly linear in the relative rotation: round-off only
            assert h["M"][j] - h["M"][i] == pytest.approx(ks * (h["rz"][j] - h["rz"][i]), rel=1e-9)
        assert h["M"][i] == pytest.approx(-sign * Y, rel=1e-12)  # at +A the joint slipped forwards
    # dissipated energy over the closed cycle +A -> -A -> +A (total times 2 -> 6)
    D = h["D"][at(h, 6.0)] - h["D"][at(h, 2.0)]
    exact = friction_loop_energy(MU, B, P, A, ks)
    assert exact == pytest.approx(4 * Y * (A - Y / ks), rel=1e-14)  # same formula, round-off
    # 1D radial return is exact for any increment size: only round-off differs
    assert D == pytest.approx(exact, rel=1e-9)
    # ... and is close to the area of the plotted loop: the trapezoid rule over increment ends
    # cuts the stick-slip corner that falls inside an increment (a triangle of at most
    # 2Y x one increment's rotation), a few % with 0.1 s increments, ~15% with 0.7 s
    i0, i1 = at(h, 2.0), at(h, 6.0)
    Mc, rc = h["M"][i0 : i1 + 1], h["rz"][i0 : i1 + 1]
    area = float(np.sum(0.5 * (Mc[1:] + Mc[:-1]) * np.diff(rc)))
    assert area == pytest.approx(exact, rel=0.2 if max_increment > 0.5 else 0.05)  # corner cut by coarse increments


def test_zero_force_carries_no_moment(tmp_path):
    m, a, b = single_joint_model(0.0, 0.02)
    h = histories(fm.solve(m, tmp_path, progress=False), b)
    assert np.all(h["M"] == 0.0)  # limit mu B |F| = 0: the return mapping gives exactly m = 0
    assert np.all(h["D"] == 0.0)  # no moment, no dissipation
    assert np.all(h["rmz"] == 0.0)  # nothing resists the prescribed rotation


def test_loop_energy_below_slip_threshold_is_zero():
    assert friction_loop_energy(MU, B, 1000.0, 1e-4, 1e4) == 0.0  # A < Y/k = 2e-4: the joint never slips


# ------------------------------------------------------------------- consistent tangent
def _random_case(rng, slip, offset):
    """A joint with arbitrary large nodal rotations, a committed moment, a tie force, and a
    trial relative rotation inside the stick or well inside the slip regime."""
    fam = BallJointFamily([[0, 1]], k_pen=1e4, k_stick=50.0, mu=MU, B=B)
    if offset:
        fam.d0 = np.array([[1e-4, -2e-4, 3e-4]])  # below a tolerance, tied rigidly to node a
    Ra, Rb = expm_so3(rng.normal(size=3)), expm_so3(rng.normal(size=3))
    x = np.array([[0.1, 0.2, 0.3], [0.1, 0.2, 0.3]])
    x[1] += Ra @ fam.d0[0] + rng.normal(size=3) * 2e-2  # tie force ~ 300 N, limit ~ 0.6 N m;
    # gap >> FD step, so the FD truncation error (h/|d|)^2 of d|F|/dx is ~1e-8
    st = fam.initial_state()
    st[0, 0:3] = [0.02, -0.01, 0.015]
    dtheta = rng.normal(size=3) * (0.05 if slip else 1e-3)
    st[0, 6:] = (Ra.T @ Rb @ expm_so3(-dtheta)).ravel()  # committed relative rotation
    return fam, x, np.stack([Ra, Rb]), st


@pytest.mark.parametrize("slip", [False, True], ids=["stick", "slip"])
@pytest.mark.parametrize("offset", [False, True], ids=["coincident", "offset"])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_tangent_matches_finite_differences(slip, offset, seed):
    rng = np.random.default_rng(seed)
    fam, x, R, st = _random_case(rng, slip, offset)
    r = fam.evaluate(x, R, st)
    Y, Mn = r.output["limit"][0], r.output["moment_norm"][0]
    assert r.output["slip"][0] == float(slip)
    if slip:
        # trial point well inside the slip regime: |m_tr| - Y >> the FD step's moment k_s h
        mtr = np.linalg.norm(st[0, :3] + fam.k_stick[0] * _rel_increment(R, st))
        assert mtr > 2 * Y  # |m_tr| - Y ~ Y >> k_stick h = 5e-5 N m: FD never crosses the surface
        assert Mn == pytest.approx(Y, rel=1e-12)  # radial return lands on the circle to round-off
        assert not np.allclose(r.k[0], r.k[0].T)  # non-symmetric while slipping (d|F| term)
    else:
        assert Mn < 0.5 * Y  # far from the switching surface: FD stays in stick
    Kn = fd_tangent(fam, x, R, st)[0]
    for rows in (np.r_[0:3, 6:9], np.r_[3:6, 9:12]):
        for cols in (np.r_[0:3, 6:9], np.r_[3:6, 9:12]):
            blk, ref = r.k[0][np.ix_(rows, cols)], Kn[np.ix_(rows, cols)]
            scale = max(np.abs(ref).max(), np.abs(r.k[0][np.ix_(rows, rows)]).max() * 1e-6, 1e-12)
            # central differences, h = 1e-6: truncation O(h^2) ~ 1e-12 relative, round-off
            # eps |f| / h ~ 1e-7 N against entries of order 1..1e6
            assert np.abs(blk - ref).max() <= 1e-6 * scale, (rows, cols)


def _rel_increment(R, st):
    from femast.rotations import logm_so3

    Qc = st[0, 6:].reshape(3, 3)
    return logm_so3(Qc.T @ R[0].T @ R[1])


def test_slip_tangent_includes_limit_derivative():
    """Dropping the d|F| term would leave the moment rows blind to the translations."""
    fam, x, R, st = _random_case(np.random.default_rng(5), slip=True, offset=False)
    k = fam.evaluate(x, R, st).k[0]
    assert np.abs(k[9:12, 6:9]).max() > 1e-3 * MU * B * 1e6  # dM/dx_b ~ mu B k_pen
    fam2, x2, R2, st2 = _random_case(np.random.default_rng(5), slip=False, offset=False)
    k2 = fam2.evaluate(x2, R2, st2).k[0]
    assert np.all(k2[9:12, 6:9] == 0.0)  # in stick the moment does not depend on F


def test_rigid_rotation_of_the_joint_rotates_forces():
    """Exact for large rotations: turning the whole joint (positions, rotations) by any G
    turns f by G and leaves the friction state (in the body frame of b) unchanged."""
    rng = np.random.default_rng(3)
    for slip in (False, True):
        fam, x, R, st = _random_case(rng, slip, offset=True)
        r0 = fam.evaluate(x, R, st)
        G = expm_so3(np.array([2.0, -1.0, 2.5]))  # |angle| > pi/2: a large rotation
        st_g = st.copy()  # Q = R_a^T R_b is invariant
        r1 = fam.evaluate(x @ G.T, np.einsum("ij,njk->nik", G, R), st_g)
        f0 = r0.f[0].reshape(4, 3)
        assert np.allclose(r1.f[0].reshape(4, 3), f0 @ G.T, rtol=1e-12, atol=1e-9 * np.abs(f0).max())  # round-off
        assert np.allclose(r1.state[:, :6], r0.state[:, :6], rtol=1e-12, atol=1e-15)  # round-off


# ------------------------------------------------------------- commit / rollback
def test_evaluate_is_a_pure_function_of_the_committed_state():
    fam, x, R, st = _random_case(np.random.default_rng(7), slip=True, offset=False)
    keep = st.copy()
    first = fam.evaluate(x, R, st)
    assert np.array_equal(st, keep)  # the committed state is never written
    # a second trial (e.g. after a cutback, from the same committed state) ignores the first
    fam.evaluate(x + 1e-5, R, st)
    again = fam.evaluate(x, R, st)
    for key in ("f", "k", "state"):
        assert np.array_equal(getattr(first, key), getattr(again, key))  # bitwise: no hidden memory
    assert again.state[0, 5] > st[0, 5]  # the trial state dissipated, the committed did not change
    assert np.array_equal(st, keep)


class _FailWhileSlipping(BallJointFamily):
    """Raises FloatingPointError (the analysis then cuts the increment back) after having
    evaluated a slipping trial state, on every 5th such call, at most 3 times."""

    log = {"calls": 0, "failed": 0}

    def evaluate(self, x, R, state, ctx=None):
        resp = super().evaluate(x, R, state, ctx)
        if resp.output["slip"].any() and ctx is not None and ctx.dtime > 0:
            self.log["calls"] += 1
            if self.log["calls"] % 5 == 0 and self.log["failed"] < 3:
                self.log["failed"] += 1
                raise FloatingPointError("injected failure after a slipping trial")
        return resp


def test_state_rolled_back_on_cutback(tmp_path):
    """Failed attempts (which evaluated slipping trial states) must leave no trace: the
    dissipated energy of the cycle still equals the closed form."""
    P, A, ks = 1000.0, 0.02, 2000.0
    fam = _FailWhileSlipping([[1, 2]], k_pen=1e8, k_stick=ks, mu=MU, B=B, name="ball_joint")
    _FailWhileSlipping.log.update(calls=0, failed=0)
    m, a, b = single_joint_model(P, A, ks, family=fam)
    res = fm.solve(m, tmp_path, progress=False)
    assert _FailWhileSlipping.log["failed"] == 3 and res.summary["cutbacks"] == 3
    h = histories(res, b)
    D = h["D"][at(h, 6.0)] - h["D"][at(h, 2.0)]
    assert D == pytest.approx(friction_loop_energy(MU, B, P, A, ks), rel=1e-9)  # as without cutbacks
    # the accumulated slip equals the slip the closed form predicts (per cycle 4 (A - Y/k))
    g = res.element_history("ball_joint", 1, "slip_angle")
    Y = MU * B * P
    assert g[at(h, 6.0)] - g[at(h, 2.0)] == pytest.approx(4 * (A - Y / ks), rel=1e-9)  # round-off


def test_big_relative_rotation_increment_asks_for_a_cutback():
    fam = BallJointFamily([[0, 1]], k_pen=1e6, k_stick=50.0)
    R = np.stack([np.eye(3), expm_so3(np.array([0.0, 0.0, 3.1]))])
    with pytest.raises(FloatingPointError, match="smaller increments"):
        fam.evaluate(np.zeros((2, 3)), R, fam.initial_state())


# ----------------------------------------------------------------- in a beam model
def two_beam_model(P=200.0, A=0.01, L=0.5):
    """Beam 1 clamped at node 1, ends at node 2; beam 2 from node 3 (coincident with 2) to
    node 4, which is held transversely, loaded by the axial compression P and rotated about z
    (0 -> +A -> -A -> +A).  A ball joint (default stiffnesses) joins 2 and 3."""
    sec = fm.circular_tube(0.02, 0.016, E=70e9)
    m = fm.Model("two_beams")
    n1, n2, n3, n4 = m.node(0, 0, 0), m.node(L, 0, 0), m.node(L, 0, 0), m.node(2 * L, 0, 0)
    m.beam(n1, n2, sec, up=(0, 1, 0), n=4)
    m.beam(n3, n4, sec, up=(0, 1, 0), n=4)
    fam = add_ball_joints(m, [(n2, n3)])
    m.fix(n1)
    m.fix(n4, "uy", "uz", "rx", "ry")
    m.step("press").load(n4, fx=-P).prescribe(n4, rz=0.0)
    amp = fm.Amplitude([0.0, 1.0, 3.0, 5.0], [0.0, 1.0, -1.0, 1.0])
    m.step("cycle", period=5.0, max_increment=0.1).prescribe(n4, amplitude=amp, rz=A)
    return m, fam, (n1, n2, n3, n4)


def test_two_beams_joint_transmits_mu_B_F(tmp_path):
    m, fam, (n1, n2, n3, n4) = two_beam_model()
    res = fm.solve(m, tmp_path, progress=False)
    M = res.element_history("ball_joint", 1, "moment")
    Fv = res.element_history("ball_joint", 1, "force")
    F = res.element_history("ball_joint", 1, "F")
    slip = res.element_history("ball_joint", 1, "slip") > 0
    Mn = np.linalg.norm(M, axis=1)
    assert np.allclose(F, np.linalg.norm(Fv, axis=1), rtol=1e-14)  # |F| output is the norm: round-off
    # at least the axial load (plus the shear of bending); 1e-6 = Newton's force tolerance
    assert F[1:].min() >= 200.0 * (1 - 1e-6)
    # slips both ways, and the slip plateau is mu B |F| with |F| the transmitted force
    assert (M[slip, 2] > 0).sum() > 3 and (M[slip, 2] < 0).sum() > 3
    assert np.allclose(Mn[slip], MU * B * F[slip], rtol=1e-12)  # return mapping, round-off
    assert np.all(Mn <= MU * B * F * (1 + 1e-12) + 1e-300)  # Coulomb: |M| <= mu B |F| always
    # independent check through beam 1: reactions at the clamp balance the joint's action on node 2,
    # (force F, moment M), so the transmitted moment follows from the reactions and the geometry
    RF = np.column_stack([res.node_history(n1, c) for c in ("rfx", "rfy", "rfz", "rmx", "rmy", "rmz")])
    arm = np.column_stack([res.node_history(n2, c) - res.node_history(n1, c) for c in ("ux", "uy", "uz")])
    arm += m.xyz(n2) - m.xyz(n1)
    for i in range(1, len(res)):
        assert np.allclose(RF[i, :3], -Fv[i], atol=1e-6 * 200.0)  # Newton force tolerance 1e-6 x load
        M_from_beam = -(RF[i, 3:] + np.cross(arm[i], Fv[i]))
        # Newton's moment tolerance: 1e-6 of the largest nodal moment (~ 3EI A / L ~ 20 N m)
        assert np.allclose(M_from_beam, M[i], atol=1e-4)


# ------------------------------------------------------------------------ bad input
def _model_with_pair(dx=0.0):
    m = fm.Model("bad")
    a, b = m.node(0, 0, 0), m.node(dx, 0, 0)
    c = m.node(1, 0, 0)
    m.beam(a, c, fm.circular_tube(0.02, 0.016, E=70e9))
    return m, a, b


def test_bad_input_is_named():
    m, a, b = _model_with_pair(1e-3)
    with pytest.raises(ModelError, match=rf"ball joint 1 \(nodes {a}-{b}\).*apart.*tolerance"):
        add_ball_joints(m, [(a, b)])
    m, a, b = _model_with_pair()
    with pytest.raises(ModelError, match=r"ball joint 1 .*mu = -0.1 .*>= 0"):
        add_ball_joints(m, [(a, b)], mu=-0.1)
    for bad_B in (0.0, -0.004, np.nan):
        with pytest.raises(ModelError, match=r"ball joint 1 .*B = .*> 0 m"):
            add_ball_joints(m, [(a, b)], B=bad_B)
    with pytest.raises(ModelError, match="same node"):
        add_ball_joints(m, [(a, a)])
    with pytest.raises(ModelError, match="k_pen"):
        add_ball_joints(m, [(a, b)], k_pen=-1.0)
    with pytest.raises(ModelError, match="unknown node 99"):
        add_ball_joints(m, [(a, 99)])
    with pytest.raises(ModelError, match=r"ball joint 7 "):
        add_ball_joints(m, [(a, b)], mu=[0.5], B=0.0, labels=[7])
    add_ball_joints(m, [(a, b)])
    with pytest.raises(ModelError, match="already has an element family named"):
        add_ball_joints(m, [(a, b)])
    m2 = fm.Model("no members")
    p, q = m2.node(0, 0, 0), m2.node(0, 0, 0)
    with pytest.raises(ModelError, match="give k_pen"):
        add_ball_joints(m2, [(p, q)])


def test_tiny_offset_within_tolerance_is_accepted_and_force_free():
    m, a, b = _model_with_pair(1e-8)  # 1e-8 m < default tolerance 1e-6 x 1 m
    fam = add_ball_joints(m, [(a, b)])
    assert fam.d0[0, 0] == 1e-8
    X = m.coordinates
    R = np.tile(np.eye(3), (len(X), 1, 1))
    fam_idx = BallJointFamily([[0, 1]], fam.k_pen, fam.k_stick, X=X[[0, 1]][None], tol=fam.tol)
    r = fam_idx.evaluate(X, R, fam_idx.initial_state())
    assert np.all(r.f == 0.0)  # the offset is subtracted: the joint starts force-free


def test_default_stiffnesses_follow_the_connected_members():
    m, fam, (n1, n2, n3, n4) = two_beam_model()
    sec = fm.circular_tube(0.02, 0.016, E=70e9)
    le = 0.5 / 4  # element length
    kp, ks = default_stiffnesses(m, [(n2, n3)])
    assert kp[0] == pytest.approx(PENALTY_FACTOR * sec.E * sec.A / le)  # same formula: round-off
    assert ks[0] == pytest.approx(STICK_FACTOR * 4 * sec.E * sec.Iz / le)  # same formula: round-off
    assert fam.k_pen[0] == kp[0] and fam.k_stick[0] == ks[0]


# ----------------------------------------------------------------------------- docs
def test_doc_examples_run(capsys):
    """The page's examples run and print what the page says they print (numbers as numbers)."""
    import re

    text = run_python_blocks("ball_joint.md")
    out = capsys.readouterr().out
    quoted = re.findall(r"prints `([^`]+)`", text) + re.findall(r"`(seated: [^`]+)`", text)
    assert len(quoted) >= 3
    for q in quoted:
        assert printed_in(q, out), f"ball_joint.md says it prints {q!r}"
