"""Cable over an ordered list of devices (femast.elements.cable_devices; Stohlman & Pellegrino, Sec. II.B.2)."""

import math

import numpy as np
import pytest
from numba import njit
from scipy.optimize import brentq

from femast.elements.base import IncrementContext
from femast.elements.cable_devices import CableDeviceFamily, Clamp, Latch, Pulley, UserDevice, wrap_geometry
from femast.elements.cable_latch import CableLatchFamily
from femast.elements.latch_law import LatchParameters
from femast.errors import ModelError
from femast.testing import fd_tangent

EA = 1.0e5  # N
MU = 0.3


def ev(fam, X, state):
    return fam.evaluate(np.asarray(X, float), None, state, IncrementContext())


def trans(K):
    idx = np.array([6 * a + c for a in range(K.shape[0] // 6) for c in range(3)])
    return K[np.ix_(idx, idx)]


def check_tangent(fam, X, state, modes):
    """Analytic tangent = central differences of f (state held, modes unchanged by the perturbation)."""
    r = ev(fam, X, state)
    m = fam.n_sections - 1
    np.testing.assert_array_equal(r.state[0, m:], modes)
    Kfd = fd_tangent(fam, np.asarray(X, float), None, state, h=1e-7, dofs=range(3))[0]
    scale = np.abs(r.k).max()
    # central FD with h = 1e-7 m: truncation ~h^2 f''' and round-off ~1e-16 f / h, both < 1e-6 of max |K|
    np.testing.assert_allclose(trans(r.k[0]), trans(Kfd), rtol=0, atol=1e-6 * scale)
    return r


def rotation(seed):
    q = np.random.default_rng(seed).standard_normal(4)
    q /= np.linalg.norm(q)
    w, x, y, z = q
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


# a cable turning 90 deg over one pulley at node 1
X90 = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.2, 0.0]])


# ---------------------------------------------------------------- capstan: slip ratio and stick band
@pytest.mark.parametrize("pull_end, sigma", [(2, +1), (0, -1)])
def test_capstan_slip_ratio_is_exp_mu_phi(pull_end, sigma):
    fam = CableDeviceFamily.pretensioned([[0, 1, 2]], X90, EA, 100.0, [Pulley(mu=MU)])
    X = X90.copy()
    X[pull_end] += 0.01 * (X90[pull_end] - X90[1]) / np.linalg.norm(X90[pull_end] - X90[1])
    r = ev(fam, X, fam.initial_state())
    T = r.output["tension"][0]
    assert r.state[0, 1] == sigma
    # Euler-Eytelwein: the pulling side carries exp(mu phi) times the other, phi = pi/2 here
    assert r.output["wrap_angle"][0, 0] == pytest.approx(math.pi / 2, abs=1e-15)  # exact right angle
    assert T[1] / T[0] == pytest.approx(math.exp(sigma * MU * math.pi / 2), rel=1e-12)  # Newton to round-off
    # and Eq. 4: the unstretched lengths add up to L0
    assert r.output["unstretched_length"][0].sum() == pytest.approx(fam.L0[0], rel=1e-14)


def test_capstan_stick_band_closed_form():
    """Inside the band the pulley grips the cable: each section keeps its unstretched length."""
    T0 = 100.0
    fam = CableDeviceFamily.pretensioned([[0, 1, 2]], X90, EA, T0, [Pulley(mu=MU)])
    st = fam.initial_state()
    l0 = np.diff(np.r_[0.0, st[0, :1], fam.L0])
    ratio_max = math.exp(MU * math.pi / 2)
    # pull the out end by du: T_out = EA ((1.2 + du)/l0_out - 1) while T_out <= ratio_max T0
    du_limit = l0[1] * (1 + ratio_max * T0 / EA) - 1.2
    for du in (0.3 * du_limit, 0.99 * du_limit):
        X = X90.copy()
        X[2, 1] += du
        r = ev(fam, X, st)
        T = r.output["tension"][0]
        assert r.state[0, 1] == 0  # stick
        assert T[0] == pytest.approx(T0, rel=1e-11)  # round-off of L/l0 (1e-16) times EA/T = 1e3
        assert T[1] == pytest.approx(EA * ((1.2 + du) / l0[1] - 1.0), rel=1e-11)  # round-off of L/l0 times EA/T
    X = X90.copy()
    X[2, 1] += 1.01 * du_limit
    r = ev(fam, X, st)
    assert r.state[0, 1] == 1
    assert r.output["tension"][0, 1] / r.output["tension"][0, 0] == pytest.approx(ratio_max, rel=1e-12)


def belt_by_hand(L, l0_fixed, wraps, L0_free, sliding):
    """Tensions of a cable whose last sections slide over capstans, solved by hand: T_{k+1} = T_k e^(mu phi_k)
    on the sliding part, l0_i = L_i / (1 + T_i / EA), sum of the sliding part's l0 = L0_free (brentq on T)."""

    def lengths(t):
        Ts = t * np.exp(MU * np.concatenate([[0.0], np.cumsum(wraps)]))
        return Ts, L[sliding] / (1.0 + Ts / EA)

    t = brentq(lambda t: lengths(t)[1].sum() - L0_free, 1e-9, 1e6, xtol=1e-14, rtol=1e-15)
    return lengths(t)[0]


def test_belt_over_two_capstans_by_hand():
    """Anchor, capstan 1 (phi = pi/2), capstan 2 (phi = pi/2; a U-turn in all), pulled end.  A moderate pull slides the
    cable over pulley 2 only; a larger one over both."""
    X = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.5, 0.0]])
    T0 = 50.0
    fam = CableDeviceFamily.pretensioned([[0, 1, 2, 3]], X, EA, T0, [Pulley(mu=MU), Pulley(mu=MU)])
    st = fam.initial_state()
    s0 = st[0, :2]
    l0 = np.diff(np.r_[0.0, s0, fam.L0[0]])
    L = np.array([1.0, 1.0, 1.5])
    for du, slides in ((0.0008, [1, 2]), (0.03, [0, 1, 2])):
        Xp = X.copy()
        Xp[3, 1] += du
        r = ev(fam, Xp, st)
        T = r.output["tension"][0]
        Lp = L.copy()
        Lp[2] += du
        if slides == [1, 2]:
            np.testing.assert_array_equal(r.state[0, 2:], [0, 1])
            assert T[0] == pytest.approx(T0, rel=1e-11)  # gripped; round-off times EA/T
            ref = belt_by_hand(Lp, None, [math.pi / 2], l0[1] + l0[2], slice(1, 3))
            np.testing.assert_allclose(T[1:], ref, rtol=1e-11)  # two independent root finders, both to round-off
        else:
            np.testing.assert_array_equal(r.state[0, 2:], [1, 1])
            assert r.output["wrap_angle"][0] == pytest.approx([math.pi / 2, math.pi / 2], abs=1e-15)
            ref = belt_by_hand(Lp, None, [math.pi / 2, math.pi / 2], fam.L0[0], slice(0, 3))
            np.testing.assert_allclose(T, ref, rtol=1e-11)


# ---------------------------------------------------------------- latches
P1 = LatchParameters.adam_fit()
P2 = LatchParameters(r=1.1e-3, x_backstop=2.0e-3, k=30e3, mu=0.07, h=1.5e-3, R=2.4e-3)


def eq14_out(x, p):
    """Stohlman & Pellegrino, Eq. 14, unlatching branch, written out here (independent of femast.elements.latch_law)."""
    rho = p.r + p.R
    y = np.sqrt(np.clip(rho**2 - x**2, 0.0, None))
    delta = np.clip(y - p.h - p.r, 0.0, None)
    return -2.0 * p.k * delta * (x - p.mu * y) / (y + p.mu * x)


def test_two_latches_release_one_after_the_other():
    """Cable anchor - latch A - 5 m - latch B - pulled end.  B (the weaker, k = 30 N/mm) releases first when
    T_2 - T_1 reaches the peak of its Eq. 14 branch; A holds meanwhile (the long middle section keeps T_1
    below A's band) and releases later at the peak of its own branch."""
    X = np.array([[0.0, 0, 0], [0.5, 0, 0], [5.5, 0, 0], [6.0, 0, 0]])
    EAc = 2.0e4
    fam = CableDeviceFamily.pretensioned([[0, 1, 2, 3]], X, EAc, 5.0, [Latch(P1), Latch(P2)])
    st = fam.initial_state()
    np.testing.assert_array_equal(st[0, 2:], [2, 2])  # both beads on their backstops
    xs = np.linspace(-P1.x_backstop, 3e-3, 20001)
    peakA, peakB = eq14_out(xs, P1).max(), eq14_out(xs, P2).max()
    jumps, beads = [], []
    for du in np.linspace(0.0, 0.06, 2001)[1:]:
        Xp = X.copy()
        Xp[3, 0] += du
        r = ev(fam, Xp, st)
        st = r.state
        T = r.output["tension"][0]
        jumps.append([T[1] - T[0], T[2] - T[1]])
        beads.append(r.output["bead_position"][0])
        for d, p in enumerate((P1, P2)):
            if st[0, 2 + d] == 1:  # sliding out: the jump is on the unlatching branch (Eq. 14)
                assert T[d + 1] - T[d] == pytest.approx(eq14_out(beads[-1][d], p), rel=1e-9, abs=1e-9)
    jumps, beads = np.array(jumps), np.array(beads)
    xc = math.sqrt((P1.r + P1.R) ** 2 - (P1.h + P1.r) ** 2)
    out_B = np.flatnonzero(beads[:, 1] >= xc)[0]
    out_A = np.flatnonzero(beads[:, 0] >= xc)[0]
    assert out_B < out_A  # B first
    assert np.all(beads[: out_B + 1, 0] == beads[0, 0])  # A does not move before B is out
    # the largest jump each latch held is its branch peak (0.5 % = the load step near the peak)
    assert jumps[: out_B + 1, 1].max() == pytest.approx(peakB, rel=5e-3)
    assert jumps[: out_A + 1, 0].max() == pytest.approx(peakA, rel=5e-3)
    assert peakA > 3 * peakB  # distinct laws: the order is not an accident of geometry


def test_one_latch_reproduces_cable_latch_element():
    """A cable over a frictionless pulley and one latch: the old element (CableLatchFamily) and this
    one along a pull - release - relax - relatch path."""
    X = np.array([[-0.40, 0.0, 0.0], [0.0, 0.12, 0.02], [0.45, 0.01, 0.0], [0.9, 0.3, 0.0]])
    old = CableLatchFamily.pretensioned([[0, 1, 2, 3]], X, EA=2e4, T0=20.0, latch_node=2, latch=P1)
    new = CableDeviceFamily.pretensioned([[0, 1, 2, 3]], X, 2e4, 20.0, [Pulley(), Latch(P1)])
    so, sn = old.initial_state(), new.initial_state()
    path = np.r_[np.linspace(0, 0.004, 60), np.linspace(0.004, -0.004, 120)]
    for du in path:
        Xp = X.copy()
        Xp[3, 0] += du
        ro, rn = ev(old, Xp, so), ev(new, Xp, sn)
        so, sn = ro.state, rn.state
        # both solve Eq. 14 to round-off, but march their first-root grids differently: 1e-9 relative
        np.testing.assert_allclose(rn.output["tension"], ro.output["tension"], rtol=1e-9, atol=1e-9)
        assert rn.output["bead_position"][0, 1] == pytest.approx(ro.output["bead_position"][0], abs=1e-12)


def test_frictionless_pulleys_match_closed_form():
    X = np.array([[0.0, 0, 0], [1.0, 0.5, 0], [2.0, -0.3, 0.4], [2.5, 0, 1.0]])
    L = np.linalg.norm(np.diff(X, axis=0), axis=1).sum()
    fam = CableDeviceFamily([[0, 1, 2, 3]], EA, L / 1.001, [Pulley(), Pulley()])
    r = ev(fam, X, fam.initial_state())
    np.testing.assert_allclose(r.output["tension"][0], EA * 0.001, rtol=1e-12)  # T = EA (L/L0 - 1)


def test_clamp_fixes_the_cable():
    fam = CableDeviceFamily.pretensioned([[0, 1, 2]], X90, EA, 10.0, [Clamp()])
    X = X90.copy()
    X[2, 1] += 0.05
    r = ev(fam, X, fam.initial_state())
    T = r.output["tension"][0]
    assert T[0] == pytest.approx(10.0, rel=1e-11)  # round-off of L/l0 times EA/T
    l0 = fam.S0[0, 0]
    assert T[1] == pytest.approx(EA * (1.25 / (fam.L0[0] - l0) - 1), rel=1e-11)  # round-off of L/l0 times EA/T


# ---------------------------------------------------------------- tangents
XT = np.array([[0.0, 0.0, 0.0], [1.0, 0.2, 0.1], [1.3, 1.1, -0.2], [2.2, 1.4, 0.3]])


@pytest.mark.parametrize(
    "devices, pull, modes",
    [
        ([Pulley(mu=MU), Pulley()], 0.01, [1, 3]),
        ([Pulley(mu=MU), Pulley(mu=0.1)], 0.02, [1, 1]),
        ([Pulley(mu=MU, radius=0.1), Pulley()], 0.01, [1, 3]),
        ([Pulley(radius=0.15), Pulley(mu=0.2)], 0.0002, [3, 0]),
        ([Clamp(), Pulley(mu=0.2)], 0.03, [0, 1]),
    ],
)
def test_tangent_matches_finite_differences(devices, pull, modes):
    fam = CableDeviceFamily.pretensioned([[0, 1, 2, 3]], XT, EA, 80.0, devices)
    X = XT.copy()
    X[3] += pull * np.array([0.6, 0.8, 0.0])
    check_tangent(fam, X, fam.initial_state(), modes)


def test_tangent_sliding_latch():
    X = np.array([[0.0, 0, 0], [0.5, 0.05, 0], [1.0, 0, 0.02], [1.5, 0.1, 0]])
    fam = CableDeviceFamily.pretensioned([[0, 1, 2, 3]], X, 2e4, 5.0, [Pulley(mu=0.1), Latch(P1)])
    st = fam.initial_state()
    Xp = X.copy()
    Xp[3, 0] += 0.0014  # the bead slides on the rising part of the unlatching branch
    r = ev(fam, Xp, st)
    assert r.state[0, 3] == 1 and -P1.x_backstop < r.output["bead_position"][0, 1] < 0.0
    check_tangent(fam, Xp, st, r.state[0, 2:])


def test_forces_self_equilibrated_and_rigid_motion():
    fam = CableDeviceFamily.pretensioned([[0, 1, 2, 3]], XT, EA, 80.0, [Pulley(mu=MU, radius=0.1), Pulley()])
    X = XT.copy()
    X[3] += [0.01, 0.0, 0.0]
    r = ev(fam, X, fam.initial_state())
    f = r.f[0].reshape(4, 6)[:, :3]
    assert np.abs(f.sum(axis=0)).max() < 1e-10 * np.abs(f).max()  # round-off
    Q = rotation(3)
    r2 = ev(fam, X @ Q.T + [1.0, -2.0, 0.5], fam.initial_state())
    np.testing.assert_allclose(r2.output["tension"], r.output["tension"], rtol=1e-12)


# ---------------------------------------------------------------- pulley size (item 2)
@pytest.mark.parametrize("seed", [0, 1])
def test_sized_pulley_geometry_closed_forms(seed):
    """Two layouts with closed-form tangents, turned and moved in 3D: (a) vertical legs on both sides of a
    pulley of radius r (wrap pi, length 2H + pi r); (b) the cable arriving horizontally along y = -r and
    leaving vertically at x = r (wrap pi/2, lengths D + pi r/4 and H + pi r/4)."""
    Q = rotation(seed)
    t = np.array([0.3, -1.0, 2.0])
    r, H, D = 0.12, 1.7, 2.3
    Xa = np.array([[-r, H, 0.0], [0.0, 0.0, 0.0], [r, H, 0.0]]) @ Q.T + t
    L, phi, _, _ = wrap_geometry(Xa, [0, r, 0])
    assert phi[0] == pytest.approx(math.pi, abs=1e-14)
    np.testing.assert_allclose(L, H + math.pi * r / 2, rtol=1e-14)
    Xb = np.array([[-D, -r, 0.0], [0.0, 0.0, 0.0], [r, H, 0.0]]) @ Q.T + t
    L, phi, _, _ = wrap_geometry(Xb, [0, r, 0])
    assert phi[0] == pytest.approx(math.pi / 2, abs=1e-14)
    np.testing.assert_allclose(L, [D + math.pi * r / 4, H + math.pi * r / 4], rtol=1e-14)
    # the force on the pulley is the two leg tensions along the legs: -T (u_P + u_Q)
    T0 = 200.0
    fam = CableDeviceFamily.pretensioned([[0, 1, 2]], Xb, EA, T0, [Pulley(radius=r)])
    res = ev(fam, Xb, fam.initial_state())
    uP, uQ = Q @ [-1.0, 0, 0], Q @ [0, 1.0, 0]
    np.testing.assert_allclose(res.f[0, 6:9], -T0 * (uP + uQ), atol=1e-11 * T0)
    np.testing.assert_allclose(res.output["tension"][0], T0, rtol=1e-12)


def test_sized_pulley_tends_to_point_pulley():
    X = np.array([[0.0, 0, 0], [1.0, 0.2, 0.0], [1.5, 1.0, 0.3]])
    L0, phi0, _, _ = wrap_geometry(X, [0, 0, 0])
    L, phi, _, _ = wrap_geometry(X, [0, 1e-7, 0])
    np.testing.assert_allclose(phi, phi0, atol=1e-6)  # O(r / d) change
    np.testing.assert_allclose(L, L0, atol=1e-6)


def test_moving_sized_pulley_conserves_cable_length():
    """A frictionless pulley of radius 0.2 m moved along a path: sum l0 = L0 to round-off and
    T = EA (L_geom / L0 - 1) with the closed-form wrapped length."""
    r = 0.2
    X = np.array([[0.0, 2.0, 0.0], [1.0, 0.0, 0.0], [2.0, 2.0, 0.0]])
    fam = CableDeviceFamily.pretensioned([[0, 1, 2]], X, EA, 100.0, [Pulley(radius=r, mu=0.0)])
    st = fam.initial_state()
    for dx in np.linspace(0, 0.5, 6):
        Xp = X.copy()
        Xp[1] += [dx, -0.3 * dx, 0.1 * dx]
        res = ev(fam, Xp, st)
        st = res.state
        assert res.output["unstretched_length"][0].sum() == pytest.approx(fam.L0[0], rel=4e-16, abs=0)
        a, b = Xp[0] - Xp[1], Xp[2] - Xp[1]
        da, db = np.linalg.norm(a), np.linalg.norm(b)
        gam = math.acos(a @ b / (da * db))
        wrap = 2 * math.pi - gam - math.acos(r / da) - math.acos(r / db)
        Lg = math.sqrt(da**2 - r**2) + math.sqrt(db**2 - r**2) + r * wrap
        np.testing.assert_allclose(res.output["tension"][0], EA * (Lg / fam.L0[0] - 1), rtol=1e-11)


# ---------------------------------------------------------------- bad input (item 6)
def test_device_list_must_match_sections():
    with pytest.raises(ModelError, match="3 devices given for a cable of 2 sections"):
        CableDeviceFamily([[0, 1, 2]], EA, 2.0, [Pulley(), Pulley(), Pulley()])


def test_neighbour_inside_pulley_is_impossible_wrap():
    X = np.array([[0.0, 0, 0], [0.1, 0.0, 0.0], [2.0, 1.0, 0.0]])
    with pytest.raises(ModelError, match="no tangent exists"):
        CableDeviceFamily.pretensioned([[0, 1, 2]], X, EA, 10.0, [Pulley(radius=0.2)])
    fam = CableDeviceFamily.pretensioned([[0, 1, 2]], X90, EA, 10.0, [Pulley(radius=0.2)])
    with pytest.raises(ModelError, match="node 0 is 0.15 m from the centre of the pulley at node 1"):
        ev(fam, np.array([[0.85, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.2, 0.0]]), fam.initial_state())


def test_collinear_sized_pulley_and_adjacent_pulleys():
    X = np.array([[0.0, 0, 0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]])
    with pytest.raises(ModelError, match="wrap plane is undefined"):
        CableDeviceFamily.pretensioned([[0, 1, 2]], X, EA, 10.0, [Pulley(radius=0.1)])
    X = np.array([[0.0, 0, 0], [1.0, 1.0, 0.0], [2.0, 0.0, 0.0], [3, 1, 0]])
    with pytest.raises(ModelError, match="two pulleys of finite radius"):
        CableDeviceFamily.pretensioned([[0, 1, 2, 3]], X, EA, 10.0, [Pulley(radius=0.1), Pulley(radius=0.1)])


@pytest.mark.parametrize(
    "dev, words",
    [
        (Pulley(mu=-0.1), "mu = -0.1"),
        (Pulley(radius=float("nan")), "radius"),
        ("pulley", "is not a device"),
    ],
)
def test_bad_devices(dev, words):
    with pytest.raises(ModelError, match=words):
        CableDeviceFamily([[0, 1, 2]], EA, 2.0, [dev], s0=[1.0])


def test_gripping_device_needs_its_material_coordinate():
    with pytest.raises(ModelError, match="give s0"):
        CableDeviceFamily([[0, 1, 2]], EA, 2.0, [Pulley(mu=0.2)])
    with pytest.raises(ModelError, match="increase strictly"):
        CableDeviceFamily([[0, 1, 2]], EA, 2.0, [Clamp()], s0=[2.5])


# ---------------------------------------------------------------- a user device law
@njit
def brake_law(sigma, T_in, T_out, s, phi, p):
    """A brake holding a constant force p[0] (N) whatever the wrap: r = T_out - T_in - sigma F."""
    return T_out - T_in - sigma * p[0], -1.0, 1.0, 0.0, 0.0


@pytest.mark.slow  # compiles a copy of the device kernels for the user law: ~15 s CPU, ~60 s on the shared cores
def test_user_device_law():
    """A user law (the element contract of _device_laws) with a closed form: the brake slips when
    T_out - T_in = F; combined with a built-in capstan on the same cable."""
    F = 40.0
    X = np.array([[0.0, 0, 0], [1.0, 0, 0], [1.0, 1.0, 0], [2.0, 1.0, 0]])
    fam = CableDeviceFamily.pretensioned([[0, 1, 2, 3]], X, EA, 20.0, [UserDevice(brake_law, (F,)), Pulley(mu=0.2)])
    Xp = X.copy()
    Xp[3, 0] += 0.02
    r = ev(fam, Xp, fam.initial_state())
    T = r.output["tension"][0]
    np.testing.assert_array_equal(r.state[0, 2:], [1, 1])
    assert T[1] - T[0] == pytest.approx(F, rel=1e-12)  # brake law, Newton to round-off
    assert T[2] / T[1] == pytest.approx(math.exp(0.2 * math.pi / 2), rel=1e-12)  # capstan, phi = pi/2
    check_tangent(fam, Xp, fam.initial_state(), [1, 1])


def test_docs_page_examples_run(tmp_path):
    from doc_examples import run_python_blocks

    run_python_blocks("cable_devices.md", cwd=tmp_path)
