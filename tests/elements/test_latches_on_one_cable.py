"""Two and three latches sliding on one cable (CableDeviceFamily): every increment against the ADAM
latch law written out here (Stohlman & Pellegrino, Eq. 14) and exact conservation of the cable's
unstretched length, at load steps from 2.5 to 40 um, element by element and in a full Analysis."""

import math

import numpy as np
import pytest

import femast as fm
from femast.elements.base import IncrementContext
from femast.elements.cable_devices import CableDeviceFamily, Latch
from femast.elements.latch_law import LatchParameters

EA_CABLE = 2.0e4  # N
T0 = 5.0  # N


def params(k):
    return LatchParameters(r=1.1e-3, x_backstop=2.0e-3, k=k, mu=0.07, h=1.5e-3, R=2.4e-3)


def eq14(x, sigma, p):
    """Eq. 14 (Stohlman & Pellegrino): the jump T_out - T_in of a bead moving out (sigma = +1) or in
    (-1) at x, with y = h + delta + r = sqrt((r + R)^2 - x^2) while the rollers touch the bead."""
    rho = p.r + p.R
    y = math.sqrt(max(rho * rho - x * x, 0.0))
    delta = max(y - p.h - p.r, 0.0)
    return -2.0 * p.k * delta * (x - sigma * p.mu * y) / (y + sigma * p.mu * x)


def check_increment(res, fam, ps, tol_force):
    """Eq. 14 on every sliding latch, the static band on every gripping one, sum l0 = L0."""
    T = res.output["tension"][0]
    l0 = res.output["unstretched_length"][0]
    assert l0.sum() == pytest.approx(fam.L0[0], rel=1e-14, abs=0)  # Eq. 4: the cable's length is conserved
    modes = res.output["device_mode"][0]
    beads = res.output["bead_position"][0]
    for d, p in enumerate(ps):
        jump = T[d + 1] - T[d]
        x = beads[d]
        if T[d] == 0.0 and T[d + 1] == 0.0:
            continue  # both sides slack: nothing acts on the bead
        if modes[d] in (1, -1):
            assert jump == pytest.approx(eq14(x, modes[d], p), abs=tol_force), (d, modes[d], x)
        elif modes[d] == 0:
            lo, hi = sorted((eq14(x, -1, p), eq14(x, 1, p)))
            assert lo - tol_force <= jump <= hi + tol_force, (d, x, jump, lo, hi)
        else:  # on the backstop: holds any pull from the in side
            assert modes[d] == 2 and x == pytest.approx(-p.x_backstop, abs=1e-15)
            assert jump <= eq14(x, 1, p) + tol_force


def pull_element(ks, step, u_max, X, u_start=0.0):
    """Pull the last node along x from u_start to u_max (m) in steps ``step``; the first evaluation
    jumps from the initial state to u_start (every bead still on its backstop there)."""
    ps = [params(k) for k in ks]
    fam = CableDeviceFamily.pretensioned([list(range(len(X)))], X, EA_CABLE, T0, [Latch(p) for p in ps])
    st = fam.initial_state()
    out = []
    n = int(round((u_max - u_start) / step))
    for i in range(0 if u_start > 0 else 1, n + 1):
        Xp = X.copy()
        Xp[-1, 0] += u_start + i * step
        res = fam.evaluate(Xp, None, st, IncrementContext())
        check_increment(res, fam, ps, tol_force=1e-8)
        st = res.state
        out.append(res.output["bead_position"][0].copy())
    return np.array(out), res


X2 = np.array([[0.0, 0, 0], [0.5, 0, 0], [5.5, 0, 0], [6.0, 0, 0]])


XC = math.sqrt((2.4e-3 + 1.1e-3) ** 2 - (1.5e-3 + 1.1e-3) ** 2)  # end of the roller contact zone, m


@pytest.mark.parametrize("ks", [(30e3, 100e3), (10e3, 100e3), (100e3, 30e3)])
@pytest.mark.parametrize("step", [40e-6, 10e-6, 5e-6, 2.5e-6])
def test_two_latches_pulled_out(ks, step):
    """A weak latch far from the pulled end and a strong one near it (the case that failed between
    4.0 and 4.4 mm: the near bead snaps out and pulls the far one off its backstop in the same
    increment), and the other way round; from 0.3 mm (both beads still on their backstops) to 6 mm."""
    beads, res = pull_element(ks, step, 6e-3, X2, u_start=0.3e-3)
    np.testing.assert_allclose(beads[0], -2.0e-3, rtol=0, atol=1e-12)  # Lb - S: round-off of Lb
    assert beads[-1, 1] > XC  # the near one is out
    if ks[0] < ks[1]:
        assert beads[-1, 0] > -2.0e-3 + 1e-6  # a weaker far one has been pulled off its backstop
    assert np.all(np.diff(beads, axis=0) >= -1e-15)  # the beads only move out (the cable is pulled one way)


def test_path_does_not_depend_on_the_step():
    """40 and 2.5 um steps reach the same states at every common pull (the snaps land where the
    continuation of the device equations puts them, whatever the step)."""
    a, ra = pull_element((30e3, 100e3), 40e-6, 6.1e-3, X2, u_start=0.3e-3)
    b, rb = pull_element((30e3, 100e3), 2.5e-6, 6.1e-3, X2, u_start=0.3e-3)
    np.testing.assert_allclose(a, b[::16], rtol=0, atol=1e-12)
    np.testing.assert_allclose(ra.output["tension"], rb.output["tension"], rtol=1e-9)


def test_three_latches_on_one_cable():
    X3 = np.array([[0.0, 0, 0], [0.5, 0, 0], [2.5, 0, 0], [4.5, 0, 0], [5.0, 0, 0]])
    beads, _ = pull_element((10e3, 30e3, 100e3), 20e-6, 10e-3, X3, u_start=0.3e-3)
    assert beads[-1, 1] > XC and beads[-1, 2] > XC and beads[-1, 0] > -2.0e-3


def test_two_latches_in_an_analysis():
    """The same cable in a model: the pulled end is a node held by a stiff spring to a node moved by
    prescribed displacement in 5 um increments; every converged increment obeys Eq. 14 and Eq. 4."""
    ps = [params(30e3), params(100e3)]
    m = fm.Model("two latches")
    nodes = [m.node(*x) for x in X2]
    drive = m.node(6.1, 0.0, 0.0)
    fam = CableDeviceFamily.pretensioned([[m.index(n) for n in nodes]], X2, EA_CABLE, T0, [Latch(p) for p in ps])
    fam.nodes = np.array([nodes])  # model scripts give node labels
    fam.name = "latch cable"
    m.add_family(fam)
    m.truss(nodes[-1], drive, EA=1e7)
    for n in nodes[:-1]:
        m.fix(n)
    m.fix(nodes[-1], "uy", "uz")
    m.fix(drive, "uy", "uz")
    s = m.step("pull", initial_increment=5e-6 / 5e-3, max_increment=5e-6 / 5e-3)
    s.prescribe(drive, ux=5e-3)
    seen = []

    def record(fr):
        if fr["step"] != "pull":
            return
        T = fr["el/latch cable/tension"][0]
        l0 = fr["el/latch cable/unstretched_length"][0]
        modes = fr["el/latch cable/device_mode"][0]
        beads = fr["el/latch cable/bead_position"][0]
        seen.append((T.copy(), l0.sum(), modes.copy(), beads.copy()))

    fm.Analysis(m, None, progress=False, on_frame=record).run()
    assert len(seen) >= 1000
    for T, total, modes, beads in seen:
        assert total == pytest.approx(fam.L0[0], rel=1e-14, abs=0)
        for d, p in enumerate(ps):
            if modes[d] in (1, -1) and T[d] + T[d + 1] > 0:
                assert T[d + 1] - T[d] == pytest.approx(eq14(beads[d], modes[d], p), abs=1e-8)
    assert seen[-1][3][1] > XC and seen[-1][3][0] > -2.0e-3 + 1e-6


def test_unconverged_device_equations_cut_the_increment_back(monkeypatch):
    """A kernel that fails for increments above 0.2 mm (emulated): the analysis cuts back and goes on;
    called directly, the error names the devices, the beads and what to change."""
    import femast.elements.cable_devices as cd
    from femast.errors import ElementConvergenceError

    real = cd.device_kernel
    limit = 0.2e-3

    def flaky(X, radius, EA, L0, kinds, P, state, f, K, new, T, phi, energy, err, where):
        real(X, radius, EA, L0, kinds, P, state, f, K, new, T, phi, energy, err, where)
        if abs(X[0, -1, 0] - flaky.committed) > limit:
            err[0] = 10
        return None

    flaky.committed = X2[-1, 0]
    monkeypatch.setattr(cd, "device_kernel", flaky)
    fam = CableDeviceFamily.pretensioned([[0, 1, 2, 3]], X2, EA_CABLE, T0, [Latch(params(30e3)), Latch(params(1e5))])
    Xp = X2.copy()
    Xp[-1, 0] += 1e-3
    with pytest.raises(ElementConvergenceError, match=r"did not converge.*latch 0: bead at -2 mm.*max_increment"):
        fam.evaluate(Xp, None, fam.initial_state(), IncrementContext())

    m = fm.Model("flaky")
    nodes = [m.node(*x) for x in X2]
    fam2 = CableDeviceFamily.pretensioned([[0, 1, 2, 3]], X2, EA_CABLE, T0, [Latch(params(30e3)), Latch(params(1e5))])
    fam2.nodes = np.array([nodes])
    m.add_family(fam2)
    for n in nodes[:-1]:
        m.fix(n)
    m.fix(nodes[-1], "uy", "uz")
    m.step("pull", initial_increment=1.0).load(nodes[-1], fx=20.0)

    def track(fr):
        flaky.committed = X2[-1, 0] + fr["U"][3, 0]

    an = fm.Analysis(m, None, progress=False, on_frame=track)
    an.run()
    assert an.summary.cutbacks >= 1
    assert an.summary.increments >= 2
