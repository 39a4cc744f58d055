"""Cable/pulley/latch element of Stohlman & Pellegrino, Eqs. 2-5 (femast.elements.cable_latch)."""

import numpy as np
import pytest

from femast.elements.base import IncrementContext
from femast.elements.cable_latch import (
    BACKSTOP,
    SLIP_IN,
    SLIP_OUT,
    STICK,
    CableLatchFamily,
    cable_equations,
)
from femast.elements.latch_law import LATCHING, UNLATCHING, LatchParameters, contact_half_width, latch_force
from femast.errors import ModelError
from femast.testing import fd_tangent as _fd

P = LatchParameters.adam_fit()
MM = 1e-3
# A bay-side cable: anchor, latch (node 1), anchor; section 0 runs through the backstop.
X3 = np.array([[-0.40, 0.0, 0.0], [0.0, 0.12, 0.02], [0.45, 0.01, 0.0]])
EA = 2.0e4  # N, a 1.5 mm steel-like cable scaled down so cable and latch stiffness compete


def evaluate(fam, X, state):
    return fam.evaluate(X, None, state, IncrementContext())


def fd_tangent(fam, X, state, h=1e-7):
    """Central differences of f w.r.t. nodal translations (state held fixed)."""
    return _fd(fam, X, None, state, h=h, dofs=range(3))[0]


def trans(K):
    idx = np.array([6 * a + c for a in range(K.shape[0] // 6) for c in range(3)])
    return K[np.ix_(idx, idx)]


def check_tangent(fam, X, state, expect_status):
    r = evaluate(fam, X, state)
    assert r.state[0, 1] == expect_status
    Kfd = fd_tangent(fam, X, state)
    # state must be in the same regime for all perturbations; FD error ~ h^2 f''' + eps f / h
    scale = np.abs(r.k).max()
    np.testing.assert_allclose(trans(r.k[0]), trans(Kfd), rtol=0, atol=2e-6 * scale)  # central FD, h = 1e-7 m
    return r


def family(x0, T0=50.0, X=X3, **kw):
    return CableLatchFamily.pretensioned([[0, 1, 2]], X, EA=EA, T0=T0, latch_node=1, x0=x0, latch=P, **kw)


# ---------------------------------------------------------------- closed forms


def test_pretension_and_stick_at_backstop():
    fam = family(None)
    st = fam.initial_state()
    r = evaluate(fam, X3, st)
    np.testing.assert_allclose(r.output["tension"], [[50.0, 50.0]], rtol=1e-12)  # closed form L0 = L/(1+T0/EA)
    assert r.state[0, 1] == BACKSTOP
    assert r.state[0, 0] == -P.x_backstop


def test_pulley_only_cable_closed_form():
    # 4 sections, 3 frictionless pulleys, no latch: T = EA (sum L / L0 - 1) (Eqs. 2-4 with T uniform).
    X = np.array([[0, 0, 0], [0.3, 0.1, 0], [0.5, 0.4, 0.2], [0.2, 0.6, 0.5], [0.0, 0.7, 0.1]], float)
    L = np.linalg.norm(np.diff(X, axis=0), axis=1).sum()
    fam = CableLatchFamily([[0, 1, 2, 3, 4]], EA=EA, L0=L / 1.004)
    r = evaluate(fam, X, fam.initial_state())
    np.testing.assert_allclose(r.output["tension"], EA * 0.004, rtol=1e-12)  # hand: EA * strain
    np.testing.assert_allclose(r.output["unstretched_length"].sum(), L / 1.004, rtol=1e-14)  # Eq. 4
    check_tangent(fam, X, fam.initial_state(), STICK)


def test_stick_at_backstop_closed_form():
    # Pull the outer anchor: the bead stays on the backstop while T_B - T_A <= dT_out(-x_bs) = 43.87 N.
    fam = family(None)
    st = fam.initial_state()
    X = X3.copy()
    X[2, 0] += 0.5 * MM
    r = evaluate(fam, X, st)
    s = fam.bead[0] + P.x_backstop
    L = np.linalg.norm(np.diff(X, axis=0), axis=1)
    TA = EA * (L[0] / s - 1)
    TB = EA * (L[1] / (fam.L0[0] - s) - 1)
    np.testing.assert_allclose(r.output["tension"][0], [TA, TB], rtol=1e-12)  # fixed s, Eqs. 2-3 by hand
    assert 0 < TB - TA < latch_force(-P.x_backstop, UNLATCHING, P)


def test_free_bead_acts_as_frictionless_pulley():
    # Bead outside the rollers (x = 5 mm): dT = 0, so T_A = T_B = EA (L / L0 - 1) after sliding.
    fam = family(5 * MM)
    X = X3.copy()
    X[2, 0] += 0.3 * MM
    r = evaluate(fam, X, fam.initial_state())
    L = np.linalg.norm(np.diff(X, axis=0), axis=1).sum()
    np.testing.assert_allclose(r.output["tension"][0], EA * (L / fam.L0[0] - 1), rtol=1e-11)  # closed form
    assert r.state[0, 1] in (SLIP_OUT, SLIP_IN)


def _slip_case(x0, pull_node, dx):
    fam = family(x0)
    st = fam.initial_state()
    X = X3.copy()
    X[pull_node, 0] += dx
    return fam, st, X


@pytest.mark.parametrize(
    "x0, node, dx, status",
    [
        (None, 2, 2.0 * MM, SLIP_OUT),  # pulled off the backstop, unlatching branch
        (1.8 * MM, 0, -1.5 * MM, SLIP_IN),  # pulled into the rollers, latching branch
        (0.1 * MM, 2, 0.05 * MM, STICK),  # static friction holds a small dT
    ],
)
def test_all_2n_equations_hold(x0, node, dx, status):
    fam, st, X = _slip_case(x0, node, dx)
    r = evaluate(fam, X, st)
    assert r.state[0, 1] == status
    res = cable_equations(
        X,
        r.output["tension"][0],
        r.state[0, 2:],
        EA,
        fam.L0[0],
        latch_node=1,
        bead=fam.bead[0],
        latch=P,
        status=status,
        x_committed=st[0, 0],
    )
    assert np.all(np.abs(res[:2]) < 1e-9)  # constitutive laws, N: solver tolerance ~1e-13 of EA
    assert abs(res[2]) < 1e-14  # Eq. 4, m: round-off on a 1 m cable
    assert abs(res[3]) < 1e-8  # latch jump (N, or m when sticking): solver tolerance


@pytest.mark.parametrize(
    "x0, node, dx, status",
    [
        (None, 2, 0.5 * MM, BACKSTOP),
        (None, 2, 2.0 * MM, SLIP_OUT),
        (1.8 * MM, 0, -1.5 * MM, SLIP_IN),
        (0.1 * MM, 2, 0.05 * MM, STICK),
        (5 * MM, 2, 0.3 * MM, SLIP_OUT),
    ],
)
def test_tangent_matches_central_differences(x0, node, dx, status):
    fam, st, X = _slip_case(x0, node, dx)
    check_tangent(fam, X, st, status)


def test_tangent_with_slack_side():
    # Section 0 slack (anchor moved towards the latch), bead pulled out by section 1.
    fam = family(None, T0=5.0)
    st = fam.initial_state()
    X = X3.copy()
    X[0, 0] += 5 * MM
    X[2, 0] += 3 * MM
    r = check_tangent(fam, X, st, SLIP_OUT)
    assert r.output["tension"][0, 0] == 0.0
    res = r.output["latch_dT"][0] - latch_force(r.state[0, 0], UNLATCHING, P)
    assert abs(res) < 1e-8  # slip equation with T_A = 0, solver tolerance


def test_tangent_multi_section_latch_in_the_middle():
    # 4 sections: pulley at node 1, latch at node 2, pulley at node 3 (general n).
    X = np.array([[0, 0, 0], [0.2, 0.05, 0], [0.35, 0.2, 0.05], [0.5, 0.1, 0.1], [0.7, 0.0, 0.0]], float)
    fam = CableLatchFamily.pretensioned([[0, 1, 2, 3, 4]], X, EA=EA, T0=40.0, latch_node=2, latch=P, x0=1.0 * MM)
    st = fam.initial_state()
    X2 = X.copy()
    X2[0, 0] -= 2.0 * MM  # T_A up by ~90 N: pulled in past dT_in(1 mm) = -57 N
    r = check_tangent(fam, X2, st, SLIP_IN)
    T = r.output["tension"][0]
    assert T[0] == pytest.approx(T[1], rel=1e-14) and T[2] == pytest.approx(T[3], rel=1e-14)  # pulleys
    assert T[2] - T[1] == pytest.approx(latch_force(r.state[0, 0], LATCHING, P), abs=1e-8)  # Eq. 5


# ---------------------------------------------------------------- invariants


def test_forces_are_self_equilibrated():
    fam, st, X = _slip_case(None, 2, 2.0 * MM)
    r = evaluate(fam, X, st)
    F = r.f[0].reshape(3, 6)[:, :3]
    np.testing.assert_allclose(F.sum(axis=0), 0.0, atol=1e-10)  # internal forces: no net force
    np.testing.assert_allclose(np.cross(X, F).sum(axis=0), 0.0, atol=1e-10)  # nor net moment


def test_committed_state_is_not_mutated():
    fam, st, X = _slip_case(None, 2, 2.0 * MM)
    before = st.copy()
    r = evaluate(fam, X, st)
    np.testing.assert_array_equal(st, before)
    assert r.state is not st and r.state[0, 0] != st[0, 0]


def test_both_sides_slack_bead_stays():
    # |x| < mu y: dT = 0 lies in the static band, so the bead stays where it is.
    fam = family(0.1 * MM, T0=0.0)
    st = fam.initial_state()
    X = X3.copy()
    X[0, 0] += 2 * MM
    X[2, 0] -= 2 * MM
    r = evaluate(fam, X, st)
    assert np.all(r.output["tension"] == 0.0) and np.all(r.f == 0.0) and np.all(r.k == 0.0)
    assert r.state[0, 0] == st[0, 0] and r.state[0, 1] == STICK


def test_batch_equals_single_elements():
    X = np.vstack([X3, X3 + [0, 0, 1.0]])
    nodes = [[0, 1, 2], [3, 4, 5]]
    fam = CableLatchFamily.pretensioned(nodes, X, EA=EA, T0=[50.0, 30.0], latch_node=1, latch=P, x0=1e-4)
    X2 = X.copy()
    X2[2, 0] += 2 * MM
    X2[5, 0] += 0.05 * MM
    r = evaluate(fam, X2, fam.initial_state())
    for e in range(2):
        single = CableLatchFamily(
            np.array([[0, 1, 2]]), EA=EA, L0=fam.L0[e], latch_node=1, bead=fam.bead[e], latch=P, x0=fam.x0[e]
        )
        rs = evaluate(single, X2[3 * e : 3 * e + 3], single.initial_state())
        np.testing.assert_allclose(r.f[e], rs.f[0], rtol=1e-14, atol=1e-12)  # same arithmetic
        np.testing.assert_allclose(r.k[e], rs.k[0], rtol=1e-14, atol=1e-9)  # same arithmetic


# ---------------------------------------------------------------- first equilibrium on a path


def _brute_force_first_root(fam, X, x_start, sigma, span):
    """Independent numpy reference: sample G on a 1e-8 m grid and take the first sign change."""
    L = np.linalg.norm(np.diff(X, axis=0), axis=1)
    LA, LB, L0, Lb = L[0], L[1], fam.L0[0], fam.bead[0]
    xs = x_start + sigma * np.arange(1, int(span / 1e-8) + 1) * 1e-8
    s = Lb - xs
    TA = np.where(LA > s, EA * (LA / s - 1), 0.0)
    TB = np.where(LB > L0 - s, EA * (LB / (L0 - s) - 1), 0.0)
    G = sigma * (TB - TA - latch_force(xs, sigma, P))
    if not np.any(G <= 0):
        return None, 0
    n_roots = np.count_nonzero(np.diff(np.sign(G)) != 0)
    return xs[np.argmax(G <= 0)], n_roots


@pytest.mark.parametrize("pull", [9e-3, 11e-3, 12e-3, 13e-3])
def test_first_equilibrium_matches_brute_force(pull):
    # Soft 3 m sections, bead outside, anchor 0 pulled: the cable line C(x) crosses the latching
    # branch several times; the bead must stop at the first crossing on its way in.
    Xl = np.array([[-3.0, 0, 0], [0, 0, 0], [3.0, 0, 0]])
    fam = CableLatchFamily.pretensioned([[0, 1, 2]], Xl, EA=EA, T0=30.0, latch_node=1, latch=P, x0=3 * MM)
    X = Xl.copy()
    X[0, 0] -= pull
    r = evaluate(fam, X, fam.initial_state())
    ref, n_roots = _brute_force_first_root(fam, X, 3 * MM, -1, span=3 * MM + P.x_backstop)
    if ref is None:  # no equilibrium before the backstop: the bead must end there
        assert r.state[0, 1] == BACKSTOP and r.state[0, 0] == -P.x_backstop
        return
    assert n_roots >= 2  # several equilibria on the path: the test means something
    assert r.state[0, 1] == SLIP_IN
    assert r.state[0, 0] == pytest.approx(ref, abs=1.1e-8)  # brute-force grid spacing 1e-8 m


def test_unlatching_snap_lands_at_contact_edge():
    # Section 0 slack, 0.8 m section 1 (25 N/mm) pulled past the 63.5 N peak: the cable softens
    # slower than the latch, the bead snaps out, section 1 goes slack before the rollers release
    # the bead, so it comes to rest exactly where contact ends, x = sqrt((r+R)^2 - (h+r)^2).
    Xl = np.array([[-0.4, 0, 0], [0, 0, 0], [0.8, 0, 0]])
    fam = CableLatchFamily.pretensioned([[0, 1, 2]], Xl, EA=EA, T0=0.0, latch_node=1, latch=P, x0=-1.5 * MM)
    X = Xl.copy()
    X[0, 0] += 10 * MM  # section 0 slack
    X[2, 0] += 2.88 * MM  # T_B = 72 N at the start: stays above dT_out all the way
    r = evaluate(fam, X, fam.initial_state())
    assert r.state[0, 1] == SLIP_OUT
    assert r.state[0, 0] == pytest.approx(contact_half_width(P), rel=1e-12)  # bisection to the contact edge
    np.testing.assert_array_equal(r.output["tension"], 0.0)


def test_slack_cable_rollers_push_bead_out():
    # Both sides slack, bead at 1 mm in front of the roller axis where dT_out < 0: static friction
    # cannot hold it, the rollers push it out to the edge of contact.
    fam = family(1.0 * MM, T0=0.0)
    X = X3.copy()
    X[0, 0] += 2 * MM
    X[2, 0] -= 2 * MM
    r = evaluate(fam, X, fam.initial_state())
    assert r.state[0, 0] == pytest.approx(contact_half_width(P), rel=1e-12)  # bisection to the contact edge


def test_latching_runs_into_backstop():
    Xl = np.array([[-0.4, 0, 0], [0, 0, 0], [0.4, 0, 0]])
    fam = CableLatchFamily.pretensioned([[0, 1, 2]], Xl, EA=EA, T0=0.0, latch_node=1, latch=P, x0=-0.5 * MM)
    X = Xl.copy()
    X[2, 0] -= 5 * MM  # section 1 slack
    X[0, 0] -= 2.0 * MM  # pull the bead in; rollers snap it onto the backstop
    r = evaluate(fam, X, fam.initial_state())
    assert r.state[0, 1] == BACKSTOP and r.state[0, 0] == -P.x_backstop


# ---------------------------------------------------------------- bad input


@pytest.mark.parametrize(
    "kw, words",
    [
        (dict(EA=0.0), "EA"),
        (dict(EA=-5.0), "EA"),
        (dict(L0=0.0), "L0"),
        (dict(L0=-1.0), "L0"),
        (dict(bead=2.0), "bead"),
        (dict(latch_node=2), "latch_node"),
        (dict(latch=LatchParameters(R=1.0e-3, h=1.5e-3)), "never touch"),
        (dict(x0=-3 * MM), "behind the backstop"),
    ],
)
def test_bad_input_raises_model_error(kw, words):
    args = dict(EA=EA, L0=0.85, latch_node=1, bead=0.4, latch=P)
    args.update(kw)
    with pytest.raises(ModelError, match=words) as e:
        CableLatchFamily([[0, 1, 2]], name="side_A", **args)
    assert "side_A" in str(e.value)


def test_unstretched_length_too_short():
    fam = CableLatchFamily([[0, 1, 2]], EA=EA, L0=0.5, latch_node=1, bead=0.2, latch=P, name="side_B")
    with pytest.raises(ModelError, match="side_B element 0.*too short"):
        evaluate(fam, X3, fam.initial_state())


def test_coincident_nodes():
    fam = family(None)
    X = X3.copy()
    X[1] = X[0]
    with pytest.raises(ModelError, match="zero length"):
        fam.evaluate(X, None, fam.initial_state(), IncrementContext(x_committed=X3))


def test_initial_state_layout():
    X = np.array([[0, 0, 0], [0.2, 0.05, 0], [0.35, 0.2, 0.05], [0.5, 0.1, 0.1], [0.7, 0.0, 0.0]], float)
    fam = CableLatchFamily(
        [[0, 1, 2, 3, 4], [0, 1, 2, 3, 4]], EA=EA, L0=0.9, latch_node=[2, 0], bead=0.45, latch=[P, P], x0=[1e-3, 0.0]
    )
    st = fam.initial_state()
    np.testing.assert_allclose(st[0], [1e-3, 0, 0.2245, 0.2245, 0.2255, 0.2255], rtol=1e-12)  # hand split
    np.testing.assert_allclose(st[1, 2:], 0.225, rtol=1e-12)  # no latch: L0 / n
    np.testing.assert_allclose(st[:, 2:].sum(axis=1), 0.9, rtol=1e-14)  # Eq. 4
    r = evaluate(fam, X, st)
    assert np.isnan(r.output["bead_position"][1]) and r.output["latch_zone"][1] == -1


def test_committed_configuration_is_checked_once_per_increment_but_for_every_new_one():
    fam = CableLatchFamily([[0, 1, 2]], EA=EA, L0=0.85, latch_node=1, bead=0.4, latch=P, name="side_C")
    st = fam.initial_state()
    Xc = X3.copy()
    fam.evaluate(X3, None, st, IncrementContext(x_committed=Xc))  # fine
    fam.L0 = np.array([0.5])  # now too short for the anchors (a user change between increments)
    # another iteration of the same increment (the same committed array): not checked again
    fam.evaluate(X3, None, st, IncrementContext(x_committed=Xc))
    # the next increment passes a new committed array with the same values: checked, and it fails
    with pytest.raises(ModelError, match="side_C element 0.*too short"):
        fam.evaluate(X3, None, st, IncrementContext(x_committed=Xc.copy()))
