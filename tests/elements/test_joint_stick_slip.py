"""Static and kinetic friction of the ball joints: a joint starts to slip when its moment reaches
mu_s B |F|, slides on at mu_k B |F| (mu_k <= mu_s), and sticks again when the motion reverses or
stops; rate independent; mu_s = mu_k is the one-coefficient law of Stohlman & Pellegrino (Sec. II.B.1).

Closed forms written here: a joint under a constant force, turned through a cycle about a fixed
axis, follows the stick-slip automaton below at every increment (stick with slope k_stick, the
onset at Y_s, the kinetic plateau Y_k, stick again at each reversal until the moment reaches -Y_s);
its dissipation per cycle is (Y_s - Y_k)^2 / k_stick + 4 Y_k (A - Y_k / k_stick)."""

from __future__ import annotations

import numpy as np
import pytest

import femast as fm
from femast.elements.ball_joint import add_ball_joints, friction_loop_energy, stick_slip_loop_energy

MU_S, MU_K, B = 0.5, 0.3, 0.004
P, A, KS = 1000.0, 0.02, 2500.0  # N, rad, N m/rad: Y_s = 2 N m, Y_k = 1.2 N m


def joint_cycle(tmp_path, seat, mu_s=MU_S, mu_k=MU_K, period=5.0, max_increment=0.02, name="j"):
    """Socket fixed, ball pressed by P and turned about z: 0 -> +A -> -A -> +A (step 'cycle')."""
    m = fm.Model(name)
    b, a = m.node(0.0, 0.0, 0.0), m.node(0.0, 0.0, 0.0)
    seat_args = dict(seat="seated", axis=(1.0, 0.0, 0.0)) if seat == "seated" else {}
    add_ball_joints(m, [(a, b)], mu_s=mu_s, mu_k=mu_k, B=B, k_pen=1e8, k_stick=KS, **seat_args)
    m.fix(b)
    m.fix(a, "uy", "uz", "rx", "ry")
    m.step("press").load(a, fx=-P).prescribe(a, rz=0.0)
    s = period / 5.0
    amp = fm.Amplitude([0.0, 1.0 * s, 3.0 * s, 5.0 * s], [0.0, 1.0, -1.0, 1.0])
    m.step("cycle", period=period, max_increment=max_increment * s).prescribe(a, amplitude=amp, rz=A)
    res = fm.solve(m, tmp_path / name, progress=False)
    h = {k: res.element_history("ball_joint", 1, k) for k in ("moment", "slip", "dissipated", "limit", "F")}
    return res, res.node_history(a, "rz"), h


def automaton(theta, k, Ys, Yk):
    """The moment of a joint turned through the rotations ``theta`` (the relative rotation of the
    socket's node against the ball's: minus the ball's turn) from rest: elastic until |m| reaches
    Ys, then m = Yk sign (slip) while it keeps turning the same way; any reversal or stop sticks."""
    m, slipping, out = 0.0, False, [0.0]
    for d in np.diff(theta):
        trial = m + k * d
        limit = Yk if slipping and d * m > 0 else Ys
        if abs(trial) > limit:
            m, slipping = Yk * np.sign(trial), True
        else:
            m, slipping = trial, False
        out.append(m)
    return np.array(out)


@pytest.mark.parametrize("seat", ["tied", "seated"])
def test_stick_slip_cycle_against_the_automaton(tmp_path, seat):
    res, rz, h = joint_cycle(tmp_path, seat)
    Ys, Yk = MU_S * B * P, MU_K * B * P
    Mz = h["moment"][:, 2]
    t = res.time
    cyc = t >= 1.0 - 1e-12  # the cycle step (after 'press' at t = 1)
    ref = automaton(-rz[cyc], KS, Ys, Yk)  # the joint measures the socket against the ball: -rz
    assert np.allclose(Mz[cyc], ref, rtol=1e-9, atol=1e-9 * Ys)  # one-axis return mapping: round-off
    slip = h["slip"][cyc] > 0
    assert slip.sum() > 100 and (~slip).sum() >= 6  # stick: the start and three stretches after the turns
    assert np.allclose(np.abs(Mz[cyc][slip]), Yk, rtol=1e-12)  # the kinetic plateau
    assert np.all(np.abs(Mz) <= Ys * (1 + 1e-12))  # never above the static limit
    # the stuck moments between plateaus do exceed Yk: the static limit is what holds them
    assert np.abs(Mz[cyc][~slip]).max() > Yk * 1.3
    # the limit reported: mu_s B |F| while stuck, mu_k B |F| while slipping
    assert np.allclose(h["limit"][cyc][slip], Yk, rtol=1e-9) and np.allclose(h["limit"][cyc][~slip], Ys, rtol=1e-9)
    # dissipation over the closed cycle +A -> -A -> +A (total times 2 -> 6)
    i2, i6 = (int(np.argmin(np.abs(t - x))) for x in (2.0, 6.0))
    D = h["dissipated"][i6] - h["dissipated"][i2]
    exact = stick_slip_loop_energy(MU_S, MU_K, B, P, A, KS)
    assert exact == pytest.approx((Ys - Yk) ** 2 / KS + 4 * Yk * (A - Yk / KS), rel=1e-14)  # same formula
    assert D == pytest.approx(exact, rel=1e-9)  # round-off of the accumulated sums


def test_friction_is_rate_independent(tmp_path):
    """The same rotations over ten times the step time: the same moments and dissipation (the
    step times, and so the rotations, differ by round-off only)."""
    res1, rz1, h1 = joint_cycle(tmp_path, "tied", period=5.0, name="fast")
    res2, rz2, h2 = joint_cycle(tmp_path, "tied", period=50.0, name="slow")
    assert np.allclose(rz1, rz2, rtol=1e-12, atol=1e-14)  # (t / 10 x 10: round-off)
    assert np.allclose(h1["moment"], h2["moment"], rtol=1e-9, atol=KS * 1e-14)  # no time in the law: round-off
    assert np.allclose(h1["dissipated"], h2["dissipated"], rtol=1e-9, atol=1e-15)


def test_equal_coefficients_are_the_one_coefficient_law(tmp_path):
    """mu_s = mu_k = mu: the paper's law, whose loop dissipates 4 Y (A - Y / k_stick), and the
    same bits whether the coefficient is given as mu or as the pair."""
    res, rz, h = joint_cycle(tmp_path, "tied", mu_s=0.5, mu_k=0.5, name="pair")
    m = fm.Model("one")
    b, a = m.node(0.0, 0.0, 0.0), m.node(0.0, 0.0, 0.0)
    add_ball_joints(m, [(a, b)], 0.5, B, k_pen=1e8, k_stick=KS)
    m.fix(b)
    m.fix(a, "uy", "uz", "rx", "ry")
    m.step("press").load(a, fx=-P).prescribe(a, rz=0.0)
    amp = fm.Amplitude([0.0, 1.0, 3.0, 5.0], [0.0, 1.0, -1.0, 1.0])
    m.step("cycle", period=5.0, max_increment=0.02).prescribe(a, amplitude=amp, rz=A)
    res1 = fm.solve(m, tmp_path / "one", progress=False)
    assert np.array_equal(res1.element_history("ball_joint", 1, "moment"), h["moment"])
    t = res.time
    i2, i6 = (int(np.argmin(np.abs(t - x))) for x in (2.0, 6.0))
    D = h["dissipated"][i6] - h["dissipated"][i2]
    assert D == pytest.approx(friction_loop_energy(0.5, B, P, A, KS), rel=1e-9)  # round-off
