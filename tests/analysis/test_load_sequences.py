"""Several steps (load, unload, reverse, repeat) under load, displacement and
arc-length control in one analysis, keeping path-dependent state across steps."""

import tempfile

import numpy as np
import pytest

import femast as fm
from femast.elements.ball_joint import add_ball_joints

MU, B, P, K_STICK = 0.5, 0.004, 1000.0, 2000.0
Y = MU * B * P  # slip moment of the joint, N m (Stohlman & Pellegrino, Sec. II.B.1)


def _joint_with_spring():
    """A friction ball joint (node a fixed, node b pressed by P) in parallel with a short beam
    that resists rz of b elastically (keeps the tangent regular while the joint slips)."""
    m = fm.Model("sequence")
    a, b, c = m.node(0, 0, 0), m.node(0, 0, 0), m.node(0, 1.0, 0)
    add_ball_joints(m, [(a, b)], MU, B, k_pen=1e8, k_stick=K_STICK)
    sec = fm.circular_solid(0.004, E=70e9)  # 4 EI / L = 3.5 N m/rad, soft against K_STICK
    m.beam(b, c, sec, up=(0, 0, 1))
    m.fix(a)
    m.fix(c)
    m.fix(b, "uy", "uz", "rx", "ry")
    return m, a, b, sec


def test_cycle_split_over_control_types_keeps_the_friction_state():
    m, a, b, sec = _joint_with_spring()
    k_beam = 4 * sec.E * sec.Iz / 1.0
    A = 0.02  # rad, 7 x the stick rotation Y / K_STICK
    m.step("press").load(b, fx=-P)
    s = m.step("twist up (displacement control)", initial_increment=0.05, control=fm.DisplacementControl(b, "rz", A))
    s.load(b, mz=1.0)  # reference moment pattern
    s = m.step(
        "twist down (arc length)",
        control=fm.ArcLength(initial_load_factor=0.05, max_load_factor=-10.0, monitor=(b, "rz", -A)),
    )
    s.load(b, mz=-1.0)
    s = m.step("twist up again (load control)", initial_increment=0.05)
    s.load(b, mz=0.0)  # remove the moment: spring + joint unload
    an = fm.Analysis(m, tempfile.mkdtemp(), progress=False)
    res = an.run()
    steps = np.array(res.steps)
    M = res.element_history("ball_joint", 1, "moment")[:, 2]
    limit = res.element_history("ball_joint", 1, "limit")  # mu B |F| with the joint's own force
    rz = res.node_history(b, "rz")
    D = res.element_history("ball_joint", 1, "dissipated")
    # end of the displacement-controlled step: slipping at +Y, applied moment = Y + k_beam A
    i1 = np.flatnonzero(steps == "twist up (displacement control)")[-1]
    assert rz[i1] == pytest.approx(A, rel=1e-9)  # controlled DOF on target
    assert M[i1] == pytest.approx(limit[i1], rel=1e-9)  # on the slip plateau, exactly
    assert limit[i1] == pytest.approx(Y, rel=1e-3)  # the beam's end shear changes F by ~1e-4 of P
    mz1 = res.node_history(b, "mz")[i1]
    # beam end moment 4EI/L A up to O(A^2) geometric terms at A = 0.02 rad
    assert mz1 == pytest.approx(M[i1] + k_beam * A, rel=1e-3)
    # end of the arc-length step: reversed to -A, slipping at -Y (state carried across steps)
    i2 = np.flatnonzero(steps == "twist down (arc length)")[-1]
    assert rz[i2] <= -A * (1 - 1e-9)
    assert M[i2] == pytest.approx(-limit[i2], rel=1e-9)
    # dissipated energy so far: first slip from Y/k to A, then from A - 2Y/k down to rz[i2]
    # (1e-3: F, hence Y, varies by ~1e-4 with the beam's end shear)
    D_expected = Y * (A - Y / K_STICK) + Y * ((A - 2 * Y / K_STICK) - rz[i2])
    assert D[i2] == pytest.approx(D_expected, rel=1e-3)
    # last step, load control to zero moment: the beam pulls back, the joint sticks then slips
    # forward; at equilibrium M_joint + beam end moment = 0, the latter 4EI/L rz up to O(rz^2)
    assert abs(M[-1] + k_beam * rz[-1]) < 1e-3 * abs(M[-1])
    assert abs(M[-1]) <= limit[-1] * (1 + 1e-9)  # inside the friction cone


def test_repeated_loads_converge_at_once():
    m, a, b, sec = _joint_with_spring()
    m.step("press").load(b, fx=-P)
    m.step("again").load(b, fx=-P)
    m.step("hold")
    an = fm.Analysis(m, tempfile.mkdtemp(), progress=False)
    res = an.run()
    assert [st["iterations"] for st in an.summary.steps[1:]] == [0, 0]  # nothing changed: no iteration
    assert res.steps == ["initial", "press", "again", "hold"]
