"""Joint effects: clearance (backlash), friction hysteresis, ball-joint friction.

Clearance and friction are mechanisms on the load through a connection and the displacement it
drives (:mod:`femast.effects.quantities`): they apply to every experiment that declares those
quantities, with a gap or a threshold per axis in their ``per_axis`` forms.

Rig-specific implementations, on the rigs' own hooks:

* latch-pull -- ``bead_position`` (bead position ``x`` (n,), m, Stohlman & Pellegrino Eq. 15) and
  ``branch_force`` (the latching and unlatching branches ``[dT_in, dT_out]`` (n, 2), N, of their
  Eq. 14 at the bead positions);
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
def _per_axis(p, name, axes):
    """(k,) values of a per-axis parameter ``name_<axis>`` (or the one ``name``), in axis order."""
    if name in p:
        return p[name]
    return np.array([p[f"{name}_{a}"] for a in axes])


def _clearance(u, p, ctx):
    L = ctx["load"]
    scale = np.maximum(0.01 * np.max(np.abs(L), axis=0), 1e-12)  # a nearly sharp gap: 1 % of the largest load
    return u + _per_axis(p, "c", ctx["quantities"]["displacement"].axes) * np.tanh(L / scale)


def _clearance_smooth(u, p, ctx):
    return u + p["c"] * np.tanh(ctx["load"] / p[f"{ctx['quantities']['load'].letter}_c"])


def _gap(D, per_axis=False, starts=None):
    names = [f"c_{a}" for a in D.axes] if per_axis else ["c"]
    where = "about " + ("its axis" if per_axis else "each axis") if D.axes else ""
    return tuple(
        Parameter(
            n,
            D.unit,
            D.scale / 10,
            0.0,
            20 * D.scale,
            f"half play of the connection{' ' + where if where else ''} ({D.doc or 'the displacement it drives'})",
            scale=D.scale / 10,
            starts=starts or (D.scale / 100, D.scale),
        )
        for n in names
    )


def _clearance_params(q):
    return _gap(q["displacement"])


def _clearance_smooth_params(q):
    D, L = q["displacement"], q["load"]
    return (
        *_gap(D, starts=(D.scale / 100, D.scale, 0.3 * D.scale)),
        Parameter(
            f"{L.letter}_c",
            L.unit,
            L.scale / 200,
            L.scale * 1e-6,
            10 * L.scale,
            f"load over which the contact closes the gap (closed to tanh(1) = 76 % at {L.letter}_c)",
            scale=L.scale / 200,
            starts=(L.scale / 2000, 3 * L.scale / 100, L.scale / 200),
        ),
    )


def _clearance_axes_params(q):
    return _gap(q["displacement"], per_axis=True)


def _clearance_latch_pull(x, p, ctx):
    return x - p["c"] * np.tanh(ctx["prep"]["dT"] / 1.0)


def _clearance_latch_pull_smooth(x, p, ctx):
    return x - p["c"] * np.tanh(ctx["prep"]["dT"] / p["F_c"])


JOINT_CLEARANCE = register_effect(
    Effect(
        name="joint_clearance",
        title="clearance (backlash) in a connection",
        physics=(
            "A connection with a gap: as the load through it changes sign, it crosses its play of 2c before the "
            "elastic parts take up load again, so the displacement jumps by 2c at the load's zero crossing and is "
            "offset by +-c with the sign of the load (the Rocaspect paper, Sec. IV-C, suspects the clearance at the "
            "mast's beam assembly point).  Elastic (no hysteresis): the side of the gap follows the sign of the "
            "load, not the direction of loading."
        ),
        signature="a step in the displacement where the load changes sign; the error is largest near zero load",
        acts_where=("near-zero load",),
        source="Rocaspect guyed mast, Sec. IV-C",
        mechanism=Implementation(
            hook="displacement",
            needs=("load",),
            order=30,
            parameters=_clearance_params,
            apply=_clearance,
            form="sharp",
            doc="u += c tanh(L / L_s) on every axis, L_s = 1 % of the largest |L| of the axis in the data (a nearly "
            "sharp gap: the contact closes within 1 % of the load range).",
            forms={
                "smooth": Implementation(
                    hook="displacement",
                    needs=("load",),
                    order=30,
                    parameters=_clearance_smooth_params,
                    apply=_clearance_smooth,
                    doc="u += c tanh(L / L_c): the contact closing the gap stiffens over a load range L_c (named M_c "
                    "on a moment, F_c on a force; a contact stiffness of about c / L_c); L_c -> 0 is the sharp gap.",
                ),
                "per_axis": Implementation(
                    hook="displacement",
                    needs=("load",),
                    order=30,
                    parameters=_clearance_axes_params,
                    apply=_clearance,
                    min_axes=2,
                    doc="u_k += c_k tanh(L_k / L_s,k): a gap of its own about each axis (c_x, c_y, ...: a joint "
                    "with play about one axis only, an overlap longer in one direction); equal gaps are the "
                    "default form.",
                ),
            },
        ),
        implementations={
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
                "about 1 N, the force noise of the paper's rig).",
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
def _friction(L, p, ctx):
    return play(L, _friction_threshold(p, ctx))


def _friction_threshold(p, ctx):
    q = ctx["quantities"]["load"]
    name = f"{q.letter}_f"
    return p[name] if name in p else _per_axis(p, name, q.axes)


def _friction_jenkins(L, p, ctx):
    return jenkins(L, _friction_threshold(p, ctx), p["alpha"])


def _friction_iwan(L, p, ctx):
    return iwan(L, _friction_threshold(p, ctx), p["beta"], p["alpha"])


def _threshold(L, per_axis=False, default=100, starts=(1000, 10)):
    """The slip threshold(s) ``M_f`` / ``F_f`` (``_<axis>`` per axis): default ``L.scale / default``,
    bounds [0, 100 L.scale], starts ``L.scale / s``."""
    base = f"{L.letter}_f"
    names = [f"{base}_{a}" for a in L.axes] if per_axis else [base]
    return tuple(
        Parameter(
            n,
            L.unit,
            L.scale / default,
            0.0,
            100 * L.scale,
            f"friction {'moment' if L.letter == 'M' else 'force'} of the connection"
            + (f" about {n.rsplit('_', 1)[1]}" if per_axis else (" about each axis" if L.axes else "")),
            scale=L.scale / default,
            starts=tuple(L.scale / s for s in starts),
        )
        for n in names
    )


def _friction_params(q):
    return _threshold(q["load"])


def _friction_axes_params(q):
    return _threshold(q["load"], per_axis=True)


def _friction_jenkins_params(q):
    return (
        *_threshold(q["load"], default=100, starts=(500, 20, 100)),
        Parameter(
            "alpha",
            "-",
            0.3,
            0.0,
            1.0,
            "compliance of the stuck connection relative to the slipping one, k / (k + k_s)",
            scale=0.3,
            starts=(0.05, 0.6, 0.3),
        ),
    )


def _friction_iwan_params(q):
    return (
        *_threshold(q["load"], default=50, starts=(250, 10, 50)),
        Parameter(
            "beta",
            "-",
            1.0,
            0.05,
            50.0,
            "shape of the slip-strength distribution P(r <= s) = (s / threshold)^beta",
            scale=1.0,
            starts=(3.0, 0.5, 1.0),
        ),
        Parameter(
            "alpha", "-", 0.1, 0.0, 1.0, "share of the load path that never slips", scale=0.1, starts=(0.0, 0.3, 0.1)
        ),
    )


def _friction_latch_pull(D, p, ctx):
    D = D.copy()
    D[:, 0] -= p["F_f"]
    D[:, 1] += p["F_f"]
    return D


FRICTION_HYSTERESIS = register_effect(
    Effect(
        name="friction_hysteresis",
        title="friction hysteresis in a connection",
        physics=(
            "Coulomb friction in a connection: it slips only when the load exceeds the friction threshold in the "
            "direction of motion, so after every reversal it sticks until the load has changed by twice the "
            "friction (play operator).  The offset depends on the direction of loading, not on the sign of the "
            "load (Stohlman & Pellegrino, Sec. II.B.1: the ball joints' |M| <= mu B |F| with a constant normal "
            "force)."
        ),
        signature="the error changes sign with the direction of loading (loading and unloading offset in opposite "
        "directions) and the response sticks just after each reversal",
        acts_where=("loading", "unloading", "reversal"),
        source="Stohlman & Pellegrino, Sec. II.B.1",
        mechanism=Implementation(
            hook="load",
            order=40,
            parameters=_friction_params,
            apply=_friction,
            form="play",
            doc="L -> play(L; M_f) on every axis (F_f on a force): the elastic part sees the load less the friction, "
            "which holds until the load has changed by 2 M_f after a reversal (the connection is rigid while it "
            "sticks).",
            forms={
                "jenkins": Implementation(
                    hook="load",
                    order=40,
                    parameters=_friction_jenkins_params,
                    apply=_friction_jenkins,
                    doc="L -> alpha L + play((1 - alpha) L; M_f): the elastic connection k in parallel with a Jenkins "
                    "element (spring k_s = k (1 - alpha) / alpha in series with a slider of strength M_f); stuck, "
                    "it is k + k_s stiff, slipping k.  alpha = 0 is the play form.",
                ),
                "iwan": Implementation(
                    hook="load",
                    order=40,
                    parameters=_friction_iwan_params,
                    apply=_friction_iwan,
                    doc="L -> alpha L + (1 - alpha) mean_j play(L; r_j): a series Iwan model of 24 elasto-slip "
                    "elements with slip strengths r_j = M_f q_j^(1/beta) (distributed micro-slip: smooth Masing "
                    "loops; beta -> inf, alpha = 0 is the play form).",
                ),
                "per_axis": Implementation(
                    hook="load",
                    order=40,
                    parameters=_friction_axes_params,
                    apply=_friction,
                    min_axes=2,
                    doc="L_k -> play(L_k; M_f,k): a friction threshold of its own about each axis (M_f_x, M_f_y, "
                    "...); equal thresholds are the play form.",
                ),
            },
        ),
        implementations={
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
            "Coulomb friction in the longeron ball joints of an ADAM bay (Stohlman & Pellegrino, Sec. II.B.1): a moving joint "
            "transmitting a force F resists with a moment |M| = mu B |F| opposing the motion, a joint at rest holds "
            "|M| <= mu B |F| (mu = 0.5, B = 4 mm in the paper).  Unlike a constant friction it grows with the force "
            "through the joint, so the hysteresis widens with the cable pretension and the load."
        ),
        signature="hysteresis whose width grows with the load through the joints: the moment is offset against the "
        "direction of twisting all along the path (bay torsion), the tip keeps a residual displacement at "
        "zero load (mast)",
        acts_where=("reversal", "loading", "unloading", "near-zero load"),
        source="Stohlman & Pellegrino, Sec. II.B.1",
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
