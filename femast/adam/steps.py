"""Steps and load paths of the ADAM analyses (Stohlman & Pellegrino): the initial (pretension) step, the single-bay
torsion paths (Figs. 16-17) and the 40-bay load sequence (Table 1).

All angles in rad unless the name says ``_deg``; lengths in m, forces in N, moments in N m.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..analysis.control.stabilize import Stabilize
from ..analysis.convergence import Convergence
from ..errors import ModelError
from .build import AdamModel

#: Convergence test used for ADAM models.  The analysis' 'zero force' floor is 1e-6 x (largest
#: diagonal stiffness x model size); in these models the largest diagonal is the ball-joint
#: penalty, which puts the floor near 1e6 N for the 40-bay mast: with the default force_tol = 1e-6
#: a residual of ~1 N (and ~10 N m) would pass, against tip loads of 14 N and 6.8 N m.
#: force_tol = 1e-9 brings the tolerances to ~0.01 N and ~0.05 N m, still 30 x above the round-off
#: of the penalty forces (k_pen x 1 ulp of a coordinate, ~2e-4 N).
CONVERGENCE = Convergence(force_tol=1e-9, disp_tol=1e-6, max_iterations=25)

#: Table 1 of Stohlman & Pellegrino: tip torsion and shear of the pointing manoeuvre (Sec. VII).
TABLE1_M = 6.8  # N m about z
TABLE1_F = 14.0  # N along x
# Increments per Table 1 step by default: the friction return is first order in the increment (the
# joints' slip directions and normal forces change along a step); with 32 every Table 1 quantity of the
# 40-bay mast, one or three cycles, is within 1 % of its converged value (16: 1.3 % after two cycles;
# docs/adam_mast.md, benchmarks/friction_convergence.py).
TABLE1_INCREMENTS = 32
#: Damping of the ``equilibrium`` step of :func:`add_initial_steps` relative to the pretension step's: a
#: regularisation whose viscous force left at the end of the step is below 1e-4 N on 64 scattered 40-bay
#: masts (the convergence test's force tolerance is ~0.01 N), so the step ends in equilibrium; without it the Newton
#: iterates of some scattered masts cycle (a seat or a joint's stick/slip switching and back) and every
#: cutback repeats the same iterations, since nothing in the step depends on the increment.
SETTLE_DAMPING = 1e-3


def stabilize_for(am: AdamModel, fraction: float = 1e-4, dt0: float = 1.0) -> Stabilize:
    """Viscous stabilisation for the initial step of an ADAM model.

    femast's :class:`~femast.analysis.control.stabilize.Stabilize` scales the damping of each DOF by the
    diagonal of the tangent.  Here the largest diagonal terms are the ball-joint penalties
    (``joint_penalty_factor`` x EA/l of a longeron), 1e5-1e6 times the stiffness of the cable net
    that sets the prestressed shape; with the default energy fraction the step would end far from
    equilibrium (the damping holds the bay back) while the reported energy ratio stays small (the
    denominator is the prestress energy).  So the damping factor is set so that on the stiffest
    DOF the damping per increment is ``fraction`` x the stiffness of one cable arm:
    ``c = fraction dt0 k_arm / k_max`` (s), with k_arm = EA / (half diagonal)."""
    p = am.params
    k_arm = p.cable_EA / (0.5 * p.diagonal)
    fam = next(f for f in am.model.families if f.name == am.joint_family)
    k_max = float(np.max(fam.k_pen))
    return Stabilize(factor=fraction * dt0 * k_arm / k_max, warn_ratio=0.05, adaptive=False)


def add_initial_steps(
    am: AdamModel, stabilize: Stabilize | None = None, hold_control: tuple = (), settle: bool = False
):
    """The initial step of Stohlman & Pellegrino, Sec. II.C: the deployed, pretensioned structure comes to
    equilibrium with its cable pretensions under viscous stabilisation (step ``pretension``); the
    load steps added after it have no stabilisation (the paper: "no stabilization is used after the
    initial stable state is achieved"; ``settle`` below is an equilibrium step).  The members' length errors (a scattered mast's lack of fit,
    ``build_mast(scatter=...)``) grow over the same step with the step time
    (``step.ramp_length_errors()``): applied in full at its start, the misfit of some scattered
    masts pressed longerons into their seats by tens of micrometres against the penalty in the
    first increment, which no cutback could make smaller, and the step failed at time 0.

    hold_control : DOF names of the control node held at zero from the start (e.g. ``("ux", "uy",
    "rz")`` for the bay test, where the loading rig holds the top frame).
    settle : also add a step ``equilibrium`` without load change whose damping is
        :data:`SETTLE_DAMPING` of the pretension step's (its largest viscous force is in
        ``analysis.summary.steps[1]["stabilization_force"]``, N: below 1e-4 N on the scattered 40-bay
        masts, the step ends in equilibrium).  Off by default: femast's convergence test needs a displacement correction
        below 1e-15 (rad or 1e-15 x model size) in a step whose increment is zero, which round-off
        can miss when a soft mode (a longeron spin held by the joint springs) amplifies it.
    Returns the steps.  The stabilisation energy ratio is in ``analysis.summary.steps[0]``."""
    st = stabilize if stabilize is not None else stabilize_for(am)
    s1 = am.model.step("pretension", stabilize=st, initial_increment=1.0, max_increments=500).ramp_length_errors()
    if hold_control:
        s1.prescribe(am.control, **{d: 0.0 for d in hold_control})
    if not settle:
        return (s1,)
    weaker = (
        dict(factor=SETTLE_DAMPING * st.factor)
        if st.factor is not None
        else dict(energy_fraction=SETTLE_DAMPING * st.energy_fraction)
    )
    settle_damping = Stabilize(**weaker, warn_ratio=st.warn_ratio, adaptive=False)
    return s1, am.model.step("equilibrium", stabilize=settle_damping, initial_increment=1.0)


# ---------------------------------------------------------------------------- single-bay torsion
def add_idealised_torsion(
    am: AdamModel,
    theta_max: float = np.radians(3.5),
    name: str = "twist",
    max_increment: float = 0.01,
    unload: bool = True,
):
    """Stohlman & Pellegrino, Fig. 16, idealised path: the control node turns about z from 0 to ``theta_max`` (rad)
    in the bay's folding sense and back to 0, with x and y held (z and the tilts free).

    The twist is driven by displacement control of the control node's rz with a moment about z
    as the reference load (:class:`~femast.analysis.control.DisplacementControl`), so rz stays a
    free DOF and the moment is the load factor: step ``<name>-out`` (0 -> theta_max) and
    ``<name>-back`` (theta_max -> 0; its reference moment is a large fixed value, so that the
    pattern never vanishes whatever moment the bay holds at theta_max).  With ``unload`` a last,
    load-controlled step ``<name>-unload`` brings the moment to zero: the bay settles at its
    residual rotation at zero moment (Stohlman & Pellegrino, Sec. VIII).  ``max_increment``: fraction of each step.
    Returns the steps."""
    from ..analysis.control import DisplacementControl

    if not (0 < theta_max < am.params.stowed_angle):
        raise ModelError(
            f"add_idealised_torsion: theta_max = {theta_max!r} rad must lie in (0, "
            f"{am.params.stowed_angle:.4g}) (the stowed angle of Eq. 1)"
        )
    sense = int(am.folds[-1])
    opts = dict(initial_increment=max_increment, max_increment=max_increment, min_increment=1e-6, max_increments=20000)
    out = am.model.step(f"{name}-out", control=DisplacementControl(am.control, "rz", sense * theta_max), **opts)
    out.load(am.control, mz=sense * 1.0)
    out.prescribe(am.control, ux=0.0, uy=0.0)
    back = am.model.step(f"{name}-back", control=DisplacementControl(am.control, "rz", 0.0), **opts)
    back.load(am.control, mz=-sense * 1.0e3)
    steps = [out, back]
    if unload:
        steps.append(
            am.model.step(f"{name}-unload", initial_increment=0.25, max_increment=0.25, min_increment=1e-6).load(
                am.control, mz=0.0
            )
        )
    return steps


@dataclass
class MeasuredPath:
    """A measured-style path of the control node (Stohlman & Pellegrino, Sec. VI.B): step time ``t`` (s), twist
    ``theta`` (rad), translations ``x``, ``y`` (m).  ``synthetic`` says it was generated, not
    measured; ``note`` says how."""

    t: np.ndarray
    theta: np.ndarray
    x: np.ndarray
    y: np.ndarray
    synthetic: bool = True
    note: str = ""

    def to_csv(self, path) -> None:
        """Write ``theta_deg, ux_m, uy_m`` (the experiments' bay-torsion format) plus the step time."""
        head = "# measured-style path of the ADAM bay's control node (Stohlman & Pellegrino, Sec. VI.B). " + (
            "SYNTHETIC: " + self.note if self.synthetic else self.note
        )
        data = np.column_stack([self.t, np.degrees(self.theta), self.x, self.y])
        np.savetxt(path, data, delimiter=",", header=head + "\nt_s,theta_deg,ux_m,uy_m", comments="", fmt="%.9g")

    @classmethod
    def from_csv(cls, path) -> MeasuredPath:
        """Read a path written by :meth:`to_csv` (or any CSV with columns t_s, theta_deg, ux_m, uy_m)."""
        import csv

        with open(path) as fh:
            lines = [ln for ln in fh if not ln.startswith("#")]
        rows = list(csv.reader(lines))
        head = [h.strip() for h in rows[0]]
        try:
            cols = [head.index(c) for c in ("t_s", "theta_deg", "ux_m", "uy_m")]
        except ValueError:
            raise ModelError(f"{path}: need columns t_s, theta_deg, ux_m, uy_m; got {head}") from None
        a = np.array([[float(r[c]) for c in cols] for r in rows[1:] if r], dtype=float)
        return cls(a[:, 0], np.radians(a[:, 1]), a[:, 2], a[:, 3], synthetic=False, note=f"read from {path}")


def measured_style_path(
    b: float,
    theta_max: float = np.radians(3.2),
    hold_side: int = 0,
    n: int = 161,
    pivot: float = 1.0,
    drift=(0.0, -0.0005),
    theta_on: float = np.radians(0.4),
    theta_full: float = np.radians(1.6),
    noise: float = 0.0,
    rng_seed: int = 1,
    sense: int = 1,
) -> MeasuredPath:
    """A synthetic, measured-style path of the control node with off-axis drift (Stohlman & Pellegrino, Sec. VI.A-B:
    "displacements of up to 1 cm in the x and y directions were recorded").

    The paper's measured table is not available; this path has its character: the top frame turns
    from 0 to ``theta_max`` and back, and as the bay loosens the centre of rotation moves from the
    bay axis to the centre of side ``hold_side`` (the bay turns about the side that stays latched),
    plus a slow translation ``drift`` (m, at theta_max).  With ``pivot`` the fraction of the way the
    centre moves (ramped smoothly between twists ``theta_on`` and ``theta_full``), the control
    node's translation is ``(I - R(theta)) p + drift theta/theta_max`` with p the pivot's plan
    position.  ``noise`` (m) adds Gaussian measurement noise to x and y.  Step time runs 0..2."""
    if hold_side not in (0, 1, 2, 3):
        raise ModelError(f"measured_style_path: hold_side = {hold_side!r}; use a side 0..3")
    t = np.linspace(0.0, 2.0, n)
    frac = np.where(t <= 1.0, t, 2.0 - t)
    theta = sense * theta_max * frac
    ang = np.pi / 2 + hold_side * np.pi / 2  # side k faces the direction 90 + 90 k degrees
    c = 0.5 * b * np.array([np.cos(ang), np.sin(ang)])
    s = np.clip((np.abs(theta) - theta_on) / (theta_full - theta_on), 0.0, 1.0)
    alpha = pivot * s * s * (3 - 2 * s)
    cos, sin = np.cos(theta), np.sin(theta)
    px, py = alpha * c[0], alpha * c[1]
    x = px - (cos * px - sin * py) + drift[0] * frac
    y = py - (sin * px + cos * py) + drift[1] * frac
    if noise > 0:
        rng = np.random.default_rng(rng_seed)
        x = x + rng.normal(0.0, noise, n)
        y = y + rng.normal(0.0, noise, n)
    note = (
        f"generated by femast.adam.measured_style_path(b={b:g}, theta_max={np.degrees(theta_max):.3g} deg, "
        f"hold_side={hold_side}, pivot={pivot:g}, drift={tuple(drift)}, noise={noise:g})"
    )
    return MeasuredPath(t, theta, x, y, synthetic=True, note=note)


def add_measured_torsion(am: AdamModel, path: MeasuredPath, name: str = "twist", max_increment: float = 0.0125):
    """Stohlman & Pellegrino, Fig. 17: drive the control node along ``path`` (theta_z, x, y); z and tilts free."""
    period = float(path.t[-1])
    s = am.model.step(
        name,
        period=period,
        initial_increment=max_increment,
        max_increment=max_increment,
        min_increment=1e-6,
        max_increments=20000,
    )
    s.follow(am.control, path.t, rz=path.theta, ux=path.x, uy=path.y)
    return s


# ---------------------------------------------------------------------------- Table 1
TABLE1_SEQUENCE = ("M+F", "0", "-M-F", "0")


def add_table1_steps(
    am: AdamModel,
    cycles: int = 3,
    M: float = TABLE1_M,
    F: float = TABLE1_F,
    increments: int = TABLE1_INCREMENTS,
) -> list:
    """Stohlman & Pellegrino, Table 1 load sequence at the control node: M+F, 0, -M-F, 0, ``cycles`` times, with
    M (N m) about z and F (N) along x.  ``increments``: increments per step, of equal size (default
    :data:`TABLE1_INCREMENTS`, converged within 1 %; 1 is the paper's one increment per load step)."""
    steps = []
    for c in range(cycles):
        for k, lab in enumerate(TABLE1_SEQUENCE):
            sign = {"M+F": 1.0, "0": 0.0, "-M-F": -1.0}[lab]
            nm = f"{lab}#{c + 1}" if lab != "0" else f"0{'ab'[k // 2]}#{c + 1}"
            s = am.model.step(nm, initial_increment=1.0 / increments, max_increment=1.0 / increments)
            s.load(am.control, mz=sign * M, fx=sign * F)
            steps.append(s)
    return steps
