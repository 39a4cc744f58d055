"""Seated ball joints (``seat="seated"``): a ball held in its socket by preload carries compression,
opens in tension (optionally caught by a retainer after an axial clearance, and with radial play),
and its friction moment mu B N acts on the seat's normal force N only.

Checks against closed forms written here: a strut between two seats (the seat opens at exactly zero
axial force; the compression stiffness is the series of seat, member and seat); an ADAM bay with a
warp length error (the forces are bounded by what the cable pretension can hold, derived by hand
in the test's docstring); every contact and friction state (seated, open, on the retainer, on the
socket wall; stick and slip) against finite-difference tangents; rigid-body invariance; a path
through open, closed, stick and slip; bad input named."""

from __future__ import annotations

import numpy as np
import pytest

import femast as fm
from femast.elements._ball_seat_kernels import I_STATUS, I_TRUE_STATUS, seat_hold_gap, seat_status
from femast.elements.ball_joint import OPEN_FACTOR, PENALTY_FACTOR, BallJointFamily, add_ball_joints
from femast.elements.base import IncrementContext
from femast.errors import ModelError
from femast.rotations import expm_so3
from femast.testing import fd_tangent

MU, B = 0.5, 0.004  # Stohlman & Pellegrino, Sec. II.B.1
SEC = fm.circular_tube(0.02, 0.016, E=70e9)


# ------------------------------------------------------------------ a strut between two seats
def strut_model(L=0.5, u0=2e-5):
    """Corner b1 fixed; a strut (4 beams) from ball a1 (at b1) to ball a2 (at corner b2, x = L); a1's
    rotations held (the strut cannot spin or swing); corner b2 moved along x: -u0 (push), then +u0
    (pull), in 20 increments."""
    m = fm.Model("strut between two seats")
    b1, a1 = m.node(0, 0, 0), m.node(0, 0, 0)
    a2, b2 = m.node(L, 0, 0), m.node(L, 0, 0)
    m.beam(a1, a2, SEC, up=(0, 1, 0), n=4)
    fam = add_ball_joints(m, [(a1, b1), (a2, b2)], MU, B, seat="seated")
    m.fix(b1)
    m.fix(a1, "rx", "ry", "rz")
    m.fix(b2, "uy", "uz", "rx", "ry", "rz")
    m.step("push", max_increment=0.1).prescribe(b2, ux=-u0)
    m.step("pull", max_increment=0.05).prescribe(b2, ux=u0)
    return m, fam, (a1, b1, a2, b2)


def test_strut_between_two_seats_opens_at_zero_axial_force(tmp_path):
    """Closed form: with u the corner's displacement, the strut force is k_c u for u <= 0 with
    1/k_c = 1/k_pen + L/EA + 1/k_pen (two seats and the member in series), and for u > 0 only the
    open seats' regularisation carries it: 1/k_t = 2/k_open + L/EA.  The seat opens at u = 0, where
    the force is zero."""
    L = 0.5
    m, fam, (a1, b1, a2, b2) = strut_model(L)
    res = fm.solve(m, tmp_path, progress=False)
    u = res.node_history(b2, "ux")
    rf = res.node_history(b2, "rfx")  # force the corner needs: + pulls the strut
    N = res.element_history("ball_joint", 2, "normal_force")
    contact = res.element_history("ball_joint", 2, "contact")
    gap1, gap2 = (res.element_history("ball_joint", j, "gap") for j in (1, 2))
    kp, ko = fam.k_pen[0], fam.k_open[0]
    assert ko == pytest.approx(OPEN_FACTOR / PENALTY_FACTOR * kp, rel=1e-14)  # the documented default
    k_c = 1.0 / (2.0 / kp + L / (SEC.E * SEC.A))
    k_t = 1.0 / (2.0 / ko + L / (SEC.E * SEC.A))
    push, pull = u < -1e-12, u > 1e-12
    assert push.sum() >= 5 and pull.sum() >= 5
    # compression: the series stiffness (penalty and beam are linear: round-off and Newton's 1e-6)
    assert np.allclose(rf[push], k_c * u[push], rtol=1e-6)
    assert np.allclose(N[push], -k_c * u[push], rtol=1e-6)
    assert np.all(contact[push] == 1)
    # tension: both seats open, no normal force, only the regularisation's k_t u: k_open is 1e-5 of
    # the EA/l of a quarter strut, so k_t ~ k_open / 2 = 2e-5 EA/L ~ 2e-5 k_c
    assert np.all(contact[pull] == 0) and np.all(N[pull] == 0.0)
    assert np.allclose(rf[pull], k_t * u[pull], rtol=1e-6)
    assert np.all(np.abs(rf[pull]) <= 2.1e-5 * k_c * np.abs(u[pull]))
    # the two seats share the opening equally (same k_open), and the gaps add up to the pull
    # less the member's stretch under k_t u
    stretch = k_t * u[pull] * L / (SEC.E * SEC.A)
    assert np.allclose(gap1[pull], gap2[pull], rtol=1e-6)
    assert np.allclose(gap1[pull] + gap2[pull], u[pull] - stretch, rtol=1e-6)
    # at u = 0 (the end of the push's return, start of the pull) the force is zero: the seat opens there
    i0 = np.flatnonzero(np.abs(u) < 1e-15)
    assert i0.size >= 1 and np.all(np.abs(rf[i0]) < 1e-6 * k_c * 2e-5)


# ------------------------------------------------------------- ADAM bay with a warp error
def _bay(seat, delta):
    from femast.adam import build_bay
    from femast.adam.scatter import MastScatter
    from femast.adam.steps import CONVERGENCE, add_initial_steps

    am = build_bay(seat=seat, scatter=MastScatter(longeron_dL=np.array([[delta, -delta, delta, -delta]])))
    add_initial_steps(am, settle=True)
    frames = []
    fm.Analysis(am.model, None, progress=False, convergence=CONVERGENCE, on_frame=frames.append).run()
    return am, frames[-1]


def test_warped_bay_forces_are_bounded_by_the_pretension():
    """One ADAM bay, bottom frame fixed, top frame rigid; longerons 0 and 2 (diagonally opposite)
    too long by delta = 25 um, longerons 1 and 3 too short by delta (a warp).

    By hand: the cables pull the top frame down with Sigma = sum of their arms' vertical components,
    about 8 T l / d (8 arms of tension T = 170 N, each at l/d to the horizontal: side diagonal
    d = sqrt(b^2 + l^2)) = 768 N.  The frame rests on the longerons like a table on four legs.  Seats
    cannot pull, so the frame sits on the two long legs: by the bay's symmetry under a half turn
    about z (it maps corner k to k + 2), N_0 = N_2 = Sigma / 2 and N_1 = N_3 = 0.  The short legs'
    seats stay open by 2 delta less the shortening of the long legs (member l/EA and two seats'
    penetration 2/k_pen), split equally between their two ends (same k_open): each end opens by
    (2 delta - N_0 (l/EA + 2/k_pen)) / 2.  The tied joints of the paper, instead, force the
    frames to warp and carry kilonewtons (6.4-6.8 kN here)."""
    delta = 25e-6
    am, fr = _bay("seated", delta)
    p = am.params
    N = fr["el/adam_joint/normal_force"].reshape(4, 2)  # (corner, bottom/top end)
    gap = fr["el/adam_joint/gap"].reshape(4, 2)
    contact = fr["el/adam_joint/contact"].reshape(4, 2)
    arm = fr["el/adam_arm/N"]  # tensions of the 8 arm cables, N
    d = np.hypot(p.b, p.l)
    Sigma = float(np.sum(arm)) * (p.l / d)  # arms run from mid-side (height l/2) to the top corners
    assert Sigma == pytest.approx(8 * p.pretension * p.l / d, rel=0.02)  # hand estimate: T nearly kept
    assert np.all(contact[[0, 2]] == 1) and np.all(contact[[1, 3]] == 0)
    assert np.all(N[[1, 3]] == 0.0)  # open seats carry no normal force
    assert np.allclose(N[[0, 2]], Sigma / 2, rtol=2e-3)  # (arm geometry: the arms are not exactly at l/d)
    EA = p.longeron_section.E * p.longeron_section.A
    kp = 1.0 / (am.model.families[[f.name for f in am.model.families].index("adam_joint")].k_pen[0])
    each = (2 * delta - N[0, 0] * (p.l / EA + 2 * kp)) / 2
    assert np.allclose(gap[[1, 3]], each, rtol=1e-3)
    assert N.max() <= Sigma  # bounded by what the pretension can hold
    # the same bay with the paper's tied joints: the lack of fit is forced in, kilonewtons
    _, fr_tied = _bay("tied", delta)
    assert fr_tied["el/adam_joint/F"].max() > 5 * Sigma


# ---------------------------------------------------------------- tangents in every state
def _case(rng, where, slip, offset):
    """One seated joint with large random nodal rotations, the ball placed ``where`` (seated, open,
    retainer, wall) well away from any switching surface, a committed moment, and a trial rotation
    inside stick or well inside slip (limits: mu_s B N, mu_k B N with mu_s > mu_k)."""
    e = rng.normal(size=3)
    fam = BallJointFamily(
        [[0, 1]],
        k_pen=1e4,
        k_stick=50.0,
        mu_s=0.5,
        mu_k=0.3,
        seat="seated",
        axis=e,
        clearance_radial=2e-3 if where == "wall" else 0.0,
        clearance_axial=1e-3 if where == "retainer" else None,
        k_open=300.0,
    )
    if offset:
        fam.d0 = np.array([[1e-4, -2e-4, 3e-4]])
    Ra, Rb = expm_so3(rng.normal(size=3)), expm_so3(rng.normal(size=3))
    en = Rb @ fam.axis[0]
    t = np.cross(en, rng.normal(size=3))
    t /= np.linalg.norm(t)
    gn = {"seated": -2e-2, "open": 2e-2, "retainer": 3e-2, "wall": -2e-2}[where]
    p = gn * en + (5e-3 if where == "wall" else 1e-2) * t  # N ~ 200 N: limits ~0.4 N m
    x = np.array([[0.0, 0.0, 0.0], [0.1, 0.2, 0.3]])
    x[0] = x[1] + p - Ra @ fam.d0[0]
    st = fam.initial_state()
    st[0, 0:3] = [0.02, -0.01, 0.015]
    st[0, 3] = 1.0  # slipped in the committed increment
    dtheta = rng.normal(size=3) * (0.05 if slip else 1e-3)
    st[0, 6:15] = (Ra.T @ Rb @ expm_so3(-dtheta)).ravel()
    st[0, I_STATUS] = st[0, I_TRUE_STATUS] = seat_status(
        Rb.T @ p, fam.axis[0], fam.c_r[0], fam.c_a[0]
    )  # committed in this status: the law answers
    return fam, x, np.stack([Ra, Rb]), st


@pytest.mark.parametrize("where", ["seated", "open", "retainer", "wall"])
@pytest.mark.parametrize("slip", [False, True], ids=["stick", "slip"])
@pytest.mark.parametrize("offset", [False, True], ids=["coincident", "offset"])
def test_seated_tangent_matches_finite_differences(where, slip, offset):
    rng = np.random.default_rng(["seated", "open", "retainer", "wall"].index(where) + 10 * slip + 100 * offset)
    fam, x, R, st = _case(rng, where, slip, offset)
    r = fam.evaluate(x, R, st)
    o = r.output
    assert not r.provisional
    assert o["contact"][0] == {"seated": 1, "open": 0, "retainer": 2, "wall": 1}[where]
    assert o["wall"][0] == (where == "wall")
    N = o["normal_force"][0]
    if where == "open":
        assert N == 0.0 and o["moment_norm"][0] == 0.0  # no seat force, no friction: the moment is released
    else:
        assert N > 100.0
        assert o["slip"][0] == float(slip)
        if slip:
            assert o["moment_norm"][0] == pytest.approx(0.3 * B * N, rel=1e-12)  # kinetic plateau: round-off
        else:
            assert o["moment_norm"][0] < 0.5 * 0.3 * B * N  # far inside the stick circle
    # the contact force acts through the ball centre: the pair is moment-free about any point
    f = r.f[0]
    total = np.cross(x[0], f[0:3]) + f[3:6] + np.cross(x[1], f[6:9]) + f[9:12]
    assert np.allclose(f[0:3] + f[6:9], 0.0, atol=1e-12 * np.abs(f).max())  # round-off
    assert np.abs(total).max() <= 1e-12 * np.abs(f).max()  # round-off
    Kn = fd_tangent(fam, x, R, st)[0]
    # central differences, h = 1e-6 m / rad: truncation (h / gap)^2 ~ 1e-8 on the wall (curved),
    # round-off eps |f| / h ~ 1e-8 against entries up to 1e4
    assert np.abs(r.k[0] - Kn).max() <= 1e-6 * np.abs(Kn).max()


def test_rigid_rotation_of_a_seated_joint_rotates_its_forces():
    """Turning the whole joint (positions and nodal rotations) by any G turns the forces by G and
    leaves the contact (gap, N, status) and the friction state unchanged: the seat frame is the
    socket's body frame."""
    rng = np.random.default_rng(3)
    for where in ("seated", "open", "retainer", "wall"):
        for slip in (False, True):
            fam, x, R, st = _case(rng, where, slip, offset=True)
            r0 = fam.evaluate(x, R, st)
            G = expm_so3(np.array([2.0, -1.0, 2.5]))  # |angle| > pi/2: a large rotation
            r1 = fam.evaluate(x @ G.T, np.einsum("ij,njk->nik", G, R), st)
            f0 = r0.f[0].reshape(4, 3)
            assert np.allclose(r1.f[0].reshape(4, 3), f0 @ G.T, rtol=1e-12, atol=1e-9 * np.abs(f0).max())  # round-off
            assert np.allclose(r1.state[:, :6], r0.state[:, :6], rtol=1e-12, atol=1e-15)
            for key in ("gap", "normal_force", "contact", "wall", "limit"):
                assert r1.output[key][0] == pytest.approx(r0.output[key][0], rel=1e-9, abs=1e-15)  # round-off


def test_a_status_change_is_taken_when_two_iterates_agree():
    """A seat closed in the committed state whose first iterate opens it is answered closed
    (provisionally); the next iterate takes 'open' only if it is open again."""
    rng = np.random.default_rng(4)
    fam, x, R, st = _case(rng, "open", False, offset=False)
    st[0, I_STATUS] = st[0, I_TRUE_STATUS] = 1  # committed seated
    first = fam.evaluate(x, R, st)
    assert first.provisional and first.output["contact"][0] == 0  # the law says open ...
    assert first.output["normal_force"][0] > 100.0  # ... but it was answered on the seated branch
    ctx = IncrementContext(previous={id(fam): first.state})
    second = fam.evaluate(x, R, st, ctx)
    assert not second.provisional and second.output["normal_force"][0] == 0.0  # open, as the law says


def _lifted(gap_ulps, committed):
    """One seated joint, ball node a above socket node b = (0, 0, 1) m along the seat axis z by
    ``gap_ulps`` units of round-off of 1 m (2.2e-16 m), its seat ``committed`` seated (1) or open (0)."""
    fam = BallJointFamily([[0, 1]], k_pen=2.66e11, k_stick=50.0, mu_s=0.5, mu_k=0.5, seat="seated", axis=(0, 0, 1))
    x = np.array([[0.0, 0.0, 1.0 + gap_ulps * np.finfo(float).eps], [0.0, 0.0, 1.0]])
    st = fam.initial_state()
    st[0, I_STATUS] = st[0, I_TRUE_STATUS] = committed
    return fam, x, np.stack([np.eye(3), np.eye(3)]), st


@pytest.mark.parametrize("gap_ulps", [1.0, 2.0, 8.0])
def test_a_seat_lifted_by_round_off_stays_seated(gap_ulps):
    """A gap of a few units of round-off says nothing about the side the ball is on: a seated ball
    stays seated up to seat_hold_gap = 8 ulps of its position (1.8e-15 m at 1 m) and carries the
    tension k_pen g of that gap, and its seat keeps the penalty stiffness; an open seat at the same
    gap stays open (hysteresis, no chattering between the branches)."""
    fam, x, R, st = _lifted(gap_ulps, committed=1)
    g = gap_ulps * np.finfo(float).eps
    assert seat_hold_gap(x[0], x[1]) == pytest.approx(8 * np.finfo(float).eps, rel=1e-15)
    r = fam.evaluate(x, R, st)
    assert not r.provisional and r.output["contact"][0] == 1 and r.output["gap"][0] == g  # exact: 1 + k eps
    assert r.output["normal_force"][0] == pytest.approx(2.66e11 * g, rel=1e-12)  # k_pen g, <= 4.7e-4 N
    assert r.k[0][8, 8] == pytest.approx(2.66e11, rel=1e-12)  # the seat's axial stiffness, node b's uz
    fam, x, R, st = _lifted(gap_ulps, committed=0)
    r = fam.evaluate(x, R, st)
    assert r.output["contact"][0] == 0 and r.output["normal_force"][0] == 0.0
    assert r.k[0][8, 8] == pytest.approx(fam.k_open[0], rel=1e-12)


def test_a_seat_lifted_beyond_round_off_opens():
    """Past seat_hold_gap (16 ulps here) a seated ball opens its seat as before (its gap moved by less
    than the contact search's floor since the committed state, so at once): no normal force, k_open."""
    fam, x, R, st = _lifted(16.0, committed=1)
    r = fam.evaluate(x, R, st)
    assert not r.provisional and r.output["contact"][0] == 0 and r.output["normal_force"][0] == 0.0
    assert r.k[0][8, 8] == pytest.approx(fam.k_open[0], rel=1e-12)


# ------------------------------------------------------------- a path through every state
def test_path_through_open_closed_stick_and_slip(tmp_path):
    """One joint: corner fixed; ball pressed by P along the seat axis, turned (stick, then slip at
    mu B P), pulled off the seat (open: no moment, no force), pressed again (seated, the moment
    starts from zero and sticks), then pulled past a retainer at c_a (its pull k_pen (g - c_a) +
    k_open c_a carries the load)."""
    P, ks, kp, ko, ca = 1000.0, 2000.0, 1e8, 1e3, 1e-4
    m = fm.Model("seat path")
    b, a = m.node(0, 0, 0), m.node(0, 0, 0)
    add_ball_joints(
        m, [(a, b)], MU, B, seat="seated", axis=(1, 0, 0), clearance_axial=ca, k_pen=kp, k_stick=ks, k_open=ko
    )
    m.fix(b)
    m.fix(a, "uy", "uz", "rx", "ry")
    m.step("press").load(a, fx=-P).prescribe(a, rz=0.0)
    m.step("turn", max_increment=0.1).prescribe(a, rz=0.01)  # Y/ks = 1e-3 rad: sticks, then slips
    m.step("lift", max_increment=0.25).load(a, fx=0.5 * ko * ca)  # pulled: opens, stays inside c_a
    m.step("press again", max_increment=0.25).load(a, fx=-P).prescribe(a, rz=0.0105)
    m.step("pull", max_increment=0.25).load(a, fx=P).prescribe(a, rz=0.0105)
    res = fm.solve(m, tmp_path, progress=False)
    h = {k: res.element_history("ball_joint", 1, k) for k in ("moment", "normal_force", "gap", "contact", "slip")}
    ux = res.node_history(a, "ux")
    Mz = h["moment"][:, 2]
    t = res.time
    turn = (t > 1) & (t <= 2 + 1e-12)
    # turn: stick with slope ks until mu B P, then the plateau
    Y = MU * B * P
    assert np.all(h["contact"][turn] == 1) and np.allclose(h["normal_force"][turn], P, rtol=1e-9)
    assert np.all(np.abs(Mz[turn]) <= Y * (1 + 1e-12))
    assert h["slip"][turn].sum() >= 5 and abs(Mz[turn][-1]) == pytest.approx(Y, rel=1e-12)  # radial return
    # lift: open, force 0.5 ko ca on the regularisation, gap 0.5 ca, no moment
    lift = (t > 2 + 1e-12) & (t <= 3 + 1e-12)
    end_lift = np.flatnonzero(lift)[-1]
    assert h["contact"][end_lift] == 0 and h["normal_force"][end_lift] == 0.0 and Mz[end_lift] == 0.0
    assert ux[end_lift] == pytest.approx(0.5 * ca, rel=1e-9)
    # pressed again with a small extra turn: seated, the moment restarts from zero and sticks
    again = np.flatnonzero((t > 3 + 1e-12) & (t <= 4 + 1e-12))[-1]
    assert h["contact"][again] == 1 and h["slip"][again] == 0
    assert abs(Mz[again]) < Y  # (a turn of 5e-4 rad from the open state, k_s x 5e-4 = 1 N m < Y = 2 N m)
    # pulled past the retainer: k_open ca + k_pen (g - ca) = P
    end = -1
    assert h["contact"][end] == 2
    assert ux[end] == pytest.approx(ca + (P - ko * ca) / kp, rel=1e-9)
    assert h["normal_force"][end] == pytest.approx(P - ko * ca, rel=1e-9)


# ------------------------------------------------------------------------ bad input
def test_seated_bad_input_is_named():
    m = fm.Model("bad")
    a, b, c = m.node(0, 0, 0), m.node(0, 0, 0), m.node(1, 0, 0)
    m.beam(a, c, SEC)
    with pytest.raises(ModelError, match="seat = 'glued'"):
        add_ball_joints(m, [(a, b)], seat="glued")
    with pytest.raises(ModelError, match=r"clearance_radial = -1e-05 .*>= 0"):
        add_ball_joints(m, [(a, b)], seat="seated", clearance_radial=-1e-5)
    with pytest.raises(ModelError, match=r"clearance_axial = 0.5 m is more than"):
        add_ball_joints(m, [(a, b)], seat="seated", clearance_axial=0.5)  # 0.5 m on a 1 m model: a unit slip
    with pytest.raises(ModelError, match="not a direction"):
        add_ball_joints(m, [(a, b)], seat="seated", axis=(0, 0, 0))
    with pytest.raises(ModelError, match="parameter of seated joints"):
        add_ball_joints(m, [(a, b)], clearance_radial=1e-5)
    with pytest.raises(ModelError, match=r"kinetic mu_k = 0.6 above static mu_s = 0.5"):
        add_ball_joints(m, [(a, b)], mu_s=0.5, mu_k=0.6)
    with pytest.raises(ModelError, match="not both"):
        add_ball_joints(m, [(a, b)], mu=0.5, mu_s=0.5)
    d = m.node(0, 1, 0)
    m.beam(a, d, SEC)  # two members at the ball node in different directions: the axis is unknown
    with pytest.raises(ModelError, match=r"members in different directions.*give axis="):
        add_ball_joints(m, [(a, b)], seat="seated")
