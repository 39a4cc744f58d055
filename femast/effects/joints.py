"""Joint effects: clearance (backlash), friction hysteresis, ball-joint friction.

Hooks used (see the experiments' ``hooks``):

* mast-top -- ``joint_moment`` (the moments ``m`` (n, 3), N m, about the base axes that drive
  the elastic joints of the 3R model, seed 000 Eqs. 4-6) and ``joint_rotation`` (the joint
  rotations ``theta`` (n, 3), rad).  Only the two bending joints (columns 0 and 1) are affected:
  the torsion joint is rigid and invisible in top translations.
* latch-pull -- ``bead_position`` (bead position ``x`` (n,), m, seed 001 Eq. 15) and
  ``branch_force`` (the latching and unlatching branches ``[dT_in, dT_out]`` (n, 2), N, of
  seed 001 Eq. 14 at the bead positions).
* bay-torsion, tip-cycle (FE models) -- ``bay_parameters`` (the dict of inputs the FE bay or
  mast is built with: ``mu``, ``B``, ``pretension``, ...).
"""

from __future__ import annotations

import numpy as np

from .base import Effect, Implementation, register_effect
from .operators import iwan, jenkins, play
from .parameters import Parameter

FE = ("bay-torsion", "tip-cycle")


# ----------------------------------------------------------------------------- clearance
def _clearance_mast_top(theta, p, ctx):
    m = ctx["prep"]["m"][:, :2]
    ms = ctx["prep"]["m_smooth"][:2]
    theta = theta.copy()
    theta[:, :2] += p["c"] * np.tanh(m / ms)
    return theta


def _clearance_mast_top_smooth(theta, p, ctx):
    m = ctx["prep"]["m"][:, :2]
    theta = theta.copy()
    theta[:, :2] += p["c"] * np.tanh(m / p["m_c"])
    return theta


def _clearance_latch_pull(x, p, ctx):
    return x - p["c"] * np.tanh(ctx["prep"]["dT"] / 1.0)


def _clearance_latch_pull_smooth(x, p, ctx):
    return x - p["c"] * np.tanh(ctx["prep"]["dT"] / p["F_c"])


JOINT_CLEARANCE = register_effect(
    Effect(
        name="joint_clearance",
        title="joint clearance (backlash)",
        physics=(
            "A joint with a gap: as the load through it changes sign, the joint crosses its play of 2c before the "
            "elastic parts take up load again, so the displacement jumps by 2c at the load's zero crossing and is "
            "offset by +-c with the sign of the load (seed 000 Sec. IV-C suspects the clearance at the mast's beam "
            "assembly point).  Elastic (no hysteresis): the side of the gap follows the sign of the load, not the "
            "direction of loading."
        ),
        signature="a step in the displacement where the load changes sign; the error is largest near zero load",
        # forms: "sharp" (closing scale fixed at 1 % of the largest load: a nearly sharp gap) and "smooth"
        # (closing scale fitted: a contact that stiffens over a range of load, the sharp gap its limit)
        acts_where=("near-zero load",),
        seed="seed 000 Sec. IV-C",
        implementations={
            "mast-top": Implementation(
                hook="joint_rotation",
                order=30,
                parameters=(
                    Parameter(
                        "c", "rad", 1e-4, 0.0, 0.02, "half play of each bending joint", scale=1e-4, starts=(1e-5, 1e-3)
                    ),
                ),
                apply=_clearance_mast_top,
                form="sharp",
                doc="theta_k += c tanh(m_k / m_s), k = 1, 2 (bending joints); m_s = 1 % of the largest |m_k| in the "
                "data (a nearly sharp gap: the contact closes within 1 % of the load range).",
                forms={
                    "smooth": Implementation(
                        hook="joint_rotation",
                        order=30,
                        parameters=(
                            Parameter(
                                "c",
                                "rad",
                                1e-4,
                                0.0,
                                0.02,
                                "half play of each bending joint",
                                scale=1e-4,
                                starts=(1e-5, 1e-3, 3e-4),
                            ),
                            Parameter(
                                "m_c",
                                "N m",
                                5.0,
                                1e-3,
                                1e4,
                                "closing moment scale of the contact (the gap is closed to tanh(1) = 76 % at m_c)",
                                scale=5.0,
                                starts=(0.5, 30.0, 5.0),
                            ),
                        ),
                        apply=_clearance_mast_top_smooth,
                        doc="theta_k += c tanh(m_k / m_c), k = 1, 2: the contact closing the gap stiffens over a moment "
                        "range m_c (a contact stiffness of about c / m_c rad per N m); m_c -> 0 is the sharp gap, "
                        "m_c = 1 % of max |m_k| the default form.",
                    )
                },
            ),
            "latch-pull": Implementation(
                hook="bead_position",
                order=30,
                parameters=(
                    Parameter(
                        "c",
                        "m",
                        5e-5,
                        0.0,
                        2e-3,
                        "half play of the latch body on its mount",
                        scale=1e-4,
                        starts=(1e-5, 3e-4),
                    ),
                ),
                apply=_clearance_latch_pull,
                form="sharp",
                doc="x_bead = x - c tanh(dT / 1 N): the latch shifts by c towards the pulling cable (closing within "
                "about 1 N, the force noise of the seed's rig).",
                forms={
                    "smooth": Implementation(
                        hook="bead_position",
                        order=30,
                        parameters=(
                            Parameter(
                                "c",
                                "m",
                                5e-5,
                                0.0,
                                2e-3,
                                "half play of the latch body on its mount",
                                scale=1e-4,
                                starts=(1e-5, 3e-4),
                            ),
                            Parameter(
                                "F_c",
                                "N",
                                1.0,
                                1e-3,
                                200.0,
                                "force over which the mount's contact closes",
                                scale=1.0,
                                starts=(0.2, 10.0),
                            ),
                        ),
                        apply=_clearance_latch_pull_smooth,
                        doc="x_bead = x - c tanh(dT / F_c): a mount whose contact stiffens over F_c (F_c = 1 N: the "
                        "default form).",
                    )
                },
            ),
        },
    )
)


# ----------------------------------------------------------------------------- friction hysteresis
def _friction_mast_top(m, p, ctx):
    m = m.copy()
    m[:, :2] = play(m[:, :2], p["M_f"])
    return m


def _friction_mast_top_jenkins(m, p, ctx):
    m = m.copy()
    m[:, :2] = jenkins(m[:, :2], p["M_f"], p["alpha"])
    return m


def _friction_mast_top_iwan(m, p, ctx):
    m = m.copy()
    m[:, :2] = iwan(m[:, :2], p["M_f"], p["beta"], p["alpha"])
    return m


def _friction_latch_pull(D, p, ctx):
    D = D.copy()
    D[:, 0] -= p["F_f"]
    D[:, 1] += p["F_f"]
    return D


FRICTION_HYSTERESIS = register_effect(
    Effect(
        name="friction_hysteresis",
        title="friction hysteresis in a joint",
        physics=(
            "Coulomb friction in a joint: the joint slips only when the load exceeds the friction threshold in the "
            "direction of motion, so after every reversal it sticks until the load has changed by twice the "
            "friction (play operator).  The offset depends on the direction of loading, not on the sign of the "
            "load (seed 001 Sec. II.B.1, the ball joints' |M| <= mu B |F| with a constant normal force)."
        ),
        signature="the error changes sign with the direction of loading (loading and unloading offset in opposite "
        "directions) and the response sticks just after each reversal",
        acts_where=("loading", "unloading", "reversal"),
        seed="seed 001 Sec. II.B.1",
        implementations={
            "mast-top": Implementation(
                hook="joint_moment",
                order=40,
                parameters=(
                    Parameter(
                        "M_f",
                        "N m",
                        10.0,
                        0.0,
                        1e5,
                        "friction moment of each bending joint",
                        scale=10.0,
                        starts=(1.0, 100.0),
                    ),
                ),
                apply=_friction_mast_top,
                form="play",
                doc="m_k -> play(m_k; M_f), k = 1, 2: the elastic joint sees the moment less the friction, which "
                "holds until the moment has changed by 2 M_f after a reversal (the joint is rigid while it "
                "sticks).",
                forms={
                    "jenkins": Implementation(
                        hook="joint_moment",
                        order=40,
                        parameters=(
                            Parameter(
                                "M_f",
                                "N m",
                                10.0,
                                0.0,
                                1e5,
                                "slip moment of the Jenkins slider",
                                scale=10.0,
                                starts=(2.0, 50.0, 10.0),
                            ),
                            Parameter(
                                "alpha",
                                "-",
                                0.3,
                                0.0,
                                1.0,
                                "compliance of the stuck joint relative to the slipping one, k / (k + k_s)",
                                scale=0.3,
                                starts=(0.05, 0.6, 0.3),
                            ),
                        ),
                        apply=_friction_mast_top_jenkins,
                        doc="m_k -> alpha m_k + play((1 - alpha) m_k; M_f): the elastic joint k in parallel with a "
                        "Jenkins element (spring k_s = k (1 - alpha) / alpha in series with a slider of strength "
                        "M_f); stuck, the joint is k + k_s stiff, slipping k.  alpha = 0 is the play form.",
                    ),
                    "iwan": Implementation(
                        hook="joint_moment",
                        order=40,
                        parameters=(
                            Parameter(
                                "M_f",
                                "N m",
                                20.0,
                                0.0,
                                1e5,
                                "largest slip moment of the micro-slip elements",
                                scale=20.0,
                                starts=(4.0, 100.0, 20.0),
                            ),
                            Parameter(
                                "beta",
                                "-",
                                1.0,
                                0.05,
                                50.0,
                                "shape of the slip-strength distribution P(r <= s) = (s / M_f)^beta",
                                scale=1.0,
                                starts=(3.0, 0.5, 1.0),
                            ),
                            Parameter(
                                "alpha",
                                "-",
                                0.1,
                                0.0,
                                1.0,
                                "share of the load path that never slips",
                                scale=0.1,
                                starts=(0.0, 0.3, 0.1),
                            ),
                        ),
                        apply=_friction_mast_top_iwan,
                        doc="m_k -> alpha m_k + (1 - alpha) mean_j play(m_k; r_j): a series Iwan model of 24 "
                        "elasto-slip elements with slip strengths r_j = M_f q_j^(1/beta) (distributed micro-slip: "
                        "smooth Masing loops; beta -> inf, alpha = 0 is the play form).",
                    ),
                },
            ),
            "latch-pull": Implementation(
                hook="branch_force",
                order=40,
                parameters=(
                    Parameter(
                        "F_f",
                        "N",
                        1.0,
                        0.0,
                        200.0,
                        "friction force on the moving bead or cable",
                        scale=1.0,
                        starts=(0.2, 5.0),
                    ),
                ),
                apply=_friction_latch_pull,
                doc="dT_in -= F_f, dT_out += F_f: a constant friction opposing the motion of the bead, everywhere on "
                "the path (also out of roller contact).",
            ),
        },
    )
)


# ----------------------------------------------------------------------------- ball-joint friction
def _ball_joint_fe(bay, p, ctx):
    return {**bay, "mu": float(p["mu"])}


BALL_JOINT_FRICTION = register_effect(
    Effect(
        name="ball_joint_friction",
        title="ball-joint friction",
        physics=(
            "Coulomb friction in the longeron ball joints of an ADAM bay (seed 001 Sec. II.B.1): a moving joint "
            "transmitting a force F resists with a moment |M| = mu B |F| opposing the motion, a joint at rest holds "
            "|M| <= mu B |F| (mu = 0.5, B = 4 mm in the seed).  Unlike a constant friction it grows with the force "
            "through the joint, so the hysteresis widens with the cable pretension and the load."
        ),
        signature="hysteresis whose width grows with the load through the joints: the moment is offset against the "
        "direction of twisting all along the path (bay torsion), the tip keeps a residual displacement at "
        "zero load (mast)",
        acts_where=("reversal", "loading", "unloading", "near-zero load"),
        seed="seed 001 Sec. II.B.1",
        implementations={
            e: Implementation(
                hook="bay_parameters",
                order=40,
                parameters=(
                    Parameter(
                        "mu",
                        "-",
                        0.2,
                        0.0,
                        1.5,
                        "friction coefficient of the ball joints (B: option ball_B_m, 4 mm; only mu B counts)",
                        scale=0.1,
                    ),
                ),
                apply=_ball_joint_fe,
                doc="the FE ball joints (femast.elements.ball_joint) get the friction coefficient mu (the baseline has "
                "option ball_mu = 0); each joint holds |M| <= mu B |F| and slips against the motion beyond it.",
            )
            for e in FE
        },
    )
)
