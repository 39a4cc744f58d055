"""Builders of ADAM-type bays and masts (Stohlman & Pellegrino, Secs. II and VII) for model scripts.

A mast of ``n_bays`` bays has ``n_bays + 1`` square batten frames (side ``b``) at heights
``0, l, 2 l, ...``.  Each frame has four rigid corner pieces; each bay has

* four longerons (corotational beams) from the bottom to the top corner pieces, joined to them by
  friction ball joints (Stohlman & Pellegrino, Sec. II.B.1: |M| <= mu B |F|) at the ball centres: seated by default
  (the ball sits in its socket, held there by the cables' preload: the seat carries compression and
  opens in tension; ``BayParameters.seat``), or tied (``seat="tied"``: the paper's two-way tie);
* on each of its four sides one cable/pulley/latch assembly (Stohlman & Pellegrino, Sec. II.B.2, Fig. 4): a unit at
  the centre of the side through which

  - one continuous cable runs from one bottom corner, through the latch, over the unit's pulley
    and back to the other bottom corner (the user element of Eqs. 2-5, latch between its two
    sections), and
  - two cables run from the unit to the two top corners (tension-only trusses);

  the four arms lie on the two diagonals of the side.  Twisting the top frame in the *folding
  sense* of the bay lengthens one diagonal and shortens the other: the arm of the latch cable on
  the lengthening diagonal (section 2) gains tension, the arm on the shortening one (section 1,
  the backstop side) loses it, and the bead is pulled out of the latch (dT = T2 - T1 > 0).  Once
  it is out, cable slides freely through the unit (to first order the two diagonals change length
  by equal and opposite amounts) and the side no longer resists the twist.  Twisting the other
  way pulls the bead against the backstop: the bay is stiff.

* Rigid corner pieces: the corner node (ball centre, where the ball joints and the cable anchors
  are) is the reference node of a rigid body that also carries the two batten ends, ``corner``
  from the ball centre along the frame edges.  The bottom frame is fixed; the top frame (corner
  pieces and battens) is one rigid body with the *control node* at its centre as reference
  (Stohlman & Pellegrino, Sec. II.C: "a control node ... rigidly connected to the four corners of the top batten frame").

Corners are numbered k = 0..3 counter-clockwise seen from +z, corner k at polar angle
45 + 90 k degrees (corner 0 at (+b/2, +b/2)); side k joins corners k and k+1 (side 0 is the
side y = +b/2, side 1 x = -b/2, side 2 y = -b/2, side 3 x = +b/2).  A bay with ``fold = +1`` folds
(stows) under a positive twist of its top frame about +z, one with ``fold = -1`` under a negative
twist (its cable assemblies are mirror images).  ``build_mast(..., alternate=True)`` alternates the
folding sense from bay to bay, as in the paper's mast (Sec. VIII).

All inputs are SI (m, N, Pa, rad).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..elements.ball_joint import add_ball_joints
from ..elements.cable_latch import CableLatchFamily
from ..errors import ModelError
from ..model import Model
from .joint_spring import JointSprings
from .parameters import BayParameters
from .scatter import MastScatter, latch_array

LATCH_FAMILY = "adam_latch"
ARM_FAMILY = "adam_arm"
JOINT_FAMILY = "adam_joint"
LONGERON_FAMILY = "adam_longeron"
BATTEN_FAMILY = "adam_batten"
SPRING_FAMILY = "adam_joint_spring"


@dataclass
class AdamModel:
    """What a builder returns: the :class:`~femast.model.Model` and where things are in it.

    model : the femast Model (add steps to it, then solve).
    params : the :class:`BayParameters` of every bay.
    n_bays : number of bays.  folds : (n_bays,) folding sense of each bay (+1 / -1).
    control : label of the control node (centre of the top frame, reference of its rigid body).
    corners : (n_bays + 1, 4) labels of the corner (ball centre) nodes, frame by frame.
    units : (n_bays, 4) labels of the pulley-and-latch unit nodes, bay by bay, side by side.
    latch_labels : (n_bays, 4) element labels in the latch-cable family ``latch_family``
        (results: ``res.element_history(latch_family, label, "bead_position")``).
    longerons : (n_bays, 4, 2) labels of the longeron end nodes (bottom, top).
    latch_family, arm_family, joint_family : family names.
    """

    model: Model
    params: BayParameters
    n_bays: int
    folds: np.ndarray
    control: int
    corners: np.ndarray
    units: np.ndarray
    latch_labels: np.ndarray
    longerons: np.ndarray
    latch_family: str = LATCH_FAMILY
    arm_family: str = ARM_FAMILY
    joint_family: str = JOINT_FAMILY
    base_nodes: list = field(default_factory=list)

    @property
    def height(self) -> float:
        """Deployed height of the mast, m."""
        return self.n_bays * self.params.l

    @property
    def latch(self) -> CableLatchFamily:
        """The latch-cable element family of the model (a CableDeviceFamily when the units have a bearing sheave)."""
        return next(f for f in self.model.families if f.name == self.latch_family)


def _sheave_latch_family(latch_nodes, LA, LB, stretch, sc, p: BayParameters):
    """The latch cables of a mast whose units' pulleys are bearing sheaves (``p.pulley``): one
    :class:`~femast.elements.cable_devices.CableDeviceFamily` of two-section cables over a
    :class:`~femast.elements.cable_devices.Latch` with that sheave, the same cables, pretensions,
    beads, latches and lack of fit as the paper's element (:class:`CableLatchFamily`)."""
    from ..elements.cable_devices import CableDeviceFamily, Latch

    lat = latch_array(sc, p)  # (n, 6): r, x_backstop, k, mu, h, R per latch
    values = {name: lat[:, i] for i, name in enumerate(("r", "x_backstop", "k", "mu", "h", "R"))}
    if p.latch_mu_k is not None:
        values["mu_k"] = np.minimum(p.latch_mu_k, lat[:, 3])
    latch = Latch(
        params=p.latch,
        x0=-p.latch.x_backstop,
        hysteresis_force=p.hysteresis_force,
        hysteresis_length=p.hysteresis_length,
        sheave=p.pulley,
    )
    return CableDeviceFamily(
        np.array(latch_nodes, dtype=np.int64),
        EA=p.cable_EA,
        L0=(LA + LB) / stretch,
        devices=[latch],
        s0=(LA / stretch)[:, None],
        device_values={0: values},
        length_error=sc["cable_dL"].reshape(-1, 2),
        name=LATCH_FAMILY,
    )


def corner_xy(b: float) -> np.ndarray:
    """(4, 2) plan positions of the corners of a frame of side b (m), counter-clockwise from (+b/2, +b/2)."""
    a = np.pi / 4 + np.arange(4) * np.pi / 2
    return (b / np.sqrt(2.0)) * np.column_stack([np.cos(a), np.sin(a)])


def _check_fold(fold, where):
    if fold not in (1, -1):
        raise ModelError(f"{where}: fold = {fold!r}; use +1 (folds under a positive twist about z) or -1")
    return int(fold)


def build_bay(
    params: BayParameters | None = None,
    fold: int = 1,
    name: str = "ADAM bay",
    cables: bool = True,
    scatter=None,
    **changes,
) -> AdamModel:
    """One ADAM bay (Stohlman & Pellegrino, Sec. II): bottom frame fixed, top frame rigid with the control node.

    params : :class:`BayParameters` (default: the documented choices); keyword ``changes``
        override single parameters, e.g. ``build_bay(b=0.3, cable_EA=5e4)``.
    fold : +1 (the bay folds under a positive twist about z) or -1.
    cables : False leaves out the cable/pulley/latch assemblies (frames, longerons and joints only:
        the deployment kinematics of Eq. 1).
    scatter : per-element values of the bay (:func:`build_mast`).
    Returns an :class:`AdamModel`; add steps to ``.model``."""
    return build_mast(1, params, fold=fold, alternate=False, name=name, cables=cables, scatter=scatter, **changes)


def build_mast(
    n_bays: int,
    params: BayParameters | None = None,
    fold: int = 1,
    alternate: bool = True,
    name: str | None = None,
    cables: bool = True,
    scatter=None,
    **changes,
) -> AdamModel:
    """A mast of ``n_bays`` identical ADAM bays (Stohlman & Pellegrino, Sec. VII: 40 bays, 6.84 m).

    params : :class:`BayParameters`; keyword ``changes`` override single parameters.
    fold : folding sense of the first (bottom) bay, +1 or -1.
    alternate : alternate the folding sense from bay to bay (Stohlman & Pellegrino, Sec. VIII: "the bays are
        arranged to fold in alternate directions").
    The base frame is fixed (all DOFs of its nodes); the top frame is a rigid body whose reference
    is the control node at its centre.  ``cables=False`` leaves out the cable assemblies.
    scatter : per-element values (:class:`~femast.adam.scatter.MastScatter` or a dict of its
        fields): friction per ball joint, latch k and mu per latch, pretension per bay side, length
        error per member.  Default: every bay exactly ``params``.
    Returns an :class:`AdamModel`."""
    try:
        n_ok = int(n_bays) == n_bays and int(n_bays) >= 1 and not isinstance(n_bays, bool)
    except (TypeError, ValueError):
        n_ok = False
    if not n_ok:
        raise ModelError(f"build_mast: n_bays = {n_bays!r} must be an integer >= 1")
    n_bays = int(n_bays)
    fold = _check_fold(fold, "build_mast")
    if params is None:
        params = BayParameters()
    if not isinstance(params, BayParameters):
        raise ModelError(f"build_mast: params must be a BayParameters, got {type(params).__name__}")
    if changes:
        unknown = sorted(set(changes) - set(BayParameters.__dataclass_fields__))
        if unknown:
            raise ModelError(f"build_mast: unknown bay parameter(s) {', '.join(unknown)}; see BayParameters")
        params = params.with_(**changes)
    p = params
    sc = MastScatter.from_dict({} if scatter is None else scatter).resolve(n_bays, p)
    folds = np.array([fold * ((-1) ** j if alternate else 1) for j in range(n_bays)], dtype=int)
    m = Model(name or f"ADAM mast, {n_bays} bays")
    xy = corner_xy(p.b)
    n_frames = n_bays + 1
    corners = np.zeros((n_frames, 4), dtype=np.int64)
    batten_ends = np.zeros((n_frames, 4, 2), dtype=np.int64)  # [k, 0]: towards corner k+1, [k, 1]: towards k-1
    for i in range(n_frames):
        z = i * p.l
        for k in range(4):
            corners[i, k] = m.node(xy[k, 0], xy[k, 1], z)
        for k in range(4):
            c = np.array([xy[k, 0], xy[k, 1], z])
            for s, other in ((0, (k + 1) % 4), (1, (k - 1) % 4)):
                d = np.array([xy[other, 0] - xy[k, 0], xy[other, 1] - xy[k, 1], 0.0])
                e = c + p.corner * d / np.linalg.norm(d) if p.corner > 0 else c
                batten_ends[i, k, s] = m.node(*e) if p.corner > 0 else corners[i, k]
    # battens: corner k (end towards k+1) to corner k+1 (end towards k)
    bsec, lsec = p.batten_section, p.longeron_section
    for i in range(n_frames):
        for k in range(4):
            m.beam(
                batten_ends[i, k, 0],
                batten_ends[i, (k + 1) % 4, 1],
                bsec,
                up=(0, 0, 1),
                n=p.n_batten,
                family=BATTEN_FAMILY,
                length_error_m=float(sc["batten_dL"][i, k]),
            )
    # longerons and their ball joints
    longerons = np.zeros((n_bays, 4, 2), dtype=np.int64)
    pairs = []
    for j in range(n_bays):
        for k in range(4):
            bot, top = corners[j, k], corners[j + 1, k]
            a = m.node(*m.xyz(bot))
            c = m.node(*m.xyz(top))
            radial = (xy[k, 0], xy[k, 1], 0.0)
            m.beam(
                a,
                c,
                lsec,
                up=radial,
                n=p.n_longeron,
                family=LONGERON_FAMILY,
                length_error_m=float(sc["longeron_dL"][j, k]),
            )
            longerons[j, k] = (a, c)
            pairs += [(a, bot), (c, top)]
    mu_s = sc["mu"].ravel()
    seat = (
        dict(seat="seated", clearance_radial=p.seat_clearance_radial, clearance_axial=p.seat_clearance_axial)
        if p.seat == "seated"
        else {}
    )
    add_ball_joints(
        m,
        pairs,
        mu_s=mu_s,
        mu_k=None if p.mu_k is None else mu_s * (p.mu_k / p.mu if p.mu > 0 else 0.0),
        B=p.B,
        penalty_factor=p.joint_penalty_factor,
        stick_factor=p.joint_stick_factor,
        name=JOINT_FAMILY,
        **seat,
    )
    if p.joint_spring > 0:
        m.add_family(JointSprings(pairs, p.joint_spring, name=SPRING_FAMILY))
    # cable/pulley/latch assemblies
    units = np.zeros((n_bays, 4 if cables else 0), dtype=np.int64)
    latch_nodes = []
    arm_labels = []
    stretch = 1.0 + sc["pretension"].ravel() / p.cable_EA
    LA_list, LB_list = [], []
    for j in range(n_bays if cables else 0):
        for k in range(4):
            k1 = (k + 1) % 4
            B0, B1 = corners[j, k], corners[j, k1]
            T0, T1 = corners[j + 1, k], corners[j + 1, k1]
            centre = 0.25 * (m.xyz(B0) + m.xyz(B1) + m.xyz(T0) + m.xyz(T1))
            u = m.node(*centre)
            units[j, k] = u
            if folds[j] > 0:
                # folding under +twist lengthens diagonal B0-T1: section 2 (to B0) is on it
                seq = (B1, u, B0)
                tops = (T0, T1)
            else:
                seq = (B0, u, B1)
                tops = (T1, T0)
            latch_nodes.append(seq)
            LA_list.append(np.linalg.norm(m.xyz(seq[1]) - m.xyz(seq[0])))
            LB_list.append(np.linalg.norm(m.xyz(seq[2]) - m.xyz(seq[1])))
            for a_, t in enumerate(tops):
                arm_labels.append(
                    m.truss(
                        u,
                        t,
                        EA=p.cable_EA,
                        pretension=float(sc["pretension"][j, k]),
                        tension_only=True,
                        family=ARM_FAMILY,
                        length_error_m=float(sc["arm_dL"][j, k, a_]),
                    )
                )
    LA, LB = np.array(LA_list), np.array(LB_list)
    x0 = -p.latch.x_backstop
    fam = (
        None
        if not cables
        else _sheave_latch_family(latch_nodes, LA, LB, stretch, sc, p)
        if p.pulley is not None
        else CableLatchFamily(
            np.array(latch_nodes, dtype=np.int64),
            EA=p.cable_EA,
            L0=(LA + LB) / stretch,
            latch_node=1,
            bead=LA / stretch + x0,
            latch=latch_array(sc, p),
            x0=x0,
            hysteresis_force=p.hysteresis_force,
            hysteresis_length=p.hysteresis_length,
            length_error=sc["cable_dL"].reshape(-1, 2),
            name=LATCH_FAMILY,
            mu_k=None if p.latch_mu_k is None else np.minimum(p.latch_mu_k, latch_array(sc, p)[:, 3]),
        )
    )
    if fam is not None:
        m.add_family(fam)
    latch_labels = np.arange(1, 4 * n_bays + 1).reshape(n_bays, 4) if cables else np.zeros((n_bays, 0), int)
    # boundary conditions and rigid bodies
    base = [int(c) for c in corners[0]] + [int(e) for e in np.unique(batten_ends[0])]
    for nd in sorted(set(base)):
        m.fix(nd)
    for i in range(1, n_bays):
        for k in range(4):
            if p.corner > 0:
                m.rigid_body(corners[i, k], batten_ends[i, k], name=f"corner {i}.{k}")
    top_z = n_bays * p.l
    control = m.node(0.0, 0.0, top_z)
    top_nodes = sorted(set(int(c) for c in corners[n_bays]) | set(int(e) for e in batten_ends[n_bays].ravel()))
    m.rigid_body(control, top_nodes, name="top frame")
    return AdamModel(
        model=m,
        params=p,
        n_bays=n_bays,
        folds=folds,
        control=control,
        corners=corners,
        units=units,
        latch_labels=latch_labels,
        longerons=longerons,
        base_nodes=sorted(set(base)),
    )
