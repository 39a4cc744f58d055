"""Ball joint with Coulomb friction: Stohlman & Pellegrino, Sec. II.B.1 (|M| <= mu B |F|).

A joint connects a longeron end node *a* (the ball) to a coincident corner node *b* (the
socket).  The relative rotation is resisted by a friction moment whose magnitude cannot exceed
``mu B |F|``, with F the force pressing the ball into its socket, mu the friction coefficient and
B the radius of the longeron ball end (ADAM: mu = 0.5, B = 4 mm, the same static and kinetic
coefficient; here ``mu_s`` >= ``mu_k`` may differ).  Two seats (``seat=``):

* ``"tied"``: the paper's joint, a captive ball (a rod end, a retained socket): translations tied
  by a stiff penalty in every direction, tension as well as compression; F is the tie force.
* ``"seated"``: a ball held in its seat by preload.  The seat carries compression along the seat
  axis and opens in tension (optionally a retainer catches the ball after an axial clearance
  ``clearance_axial``); radially the ball is held by the socket wall, with an optional play
  ``clearance_radial``.  Friction acts on the seat's normal force N only: ``|M| <= mu B N``, zero
  once the seat opens.  Penalty contact (the same k_pen as the tie; the kernels are in
  :mod:`femast.elements._ball_seat_kernels`): see ``docs/ball_joint.md`` for why.

The derivation is in ``docs/ball_joint.md``.  Below, the tied joint.

Equations (SI: N, m, rad)
-------------------------
* Tie: ``F = k_pen d``, ``d = x_b - x_a - R_a d0`` (d0 the initial offset, zero for
  coincident nodes, below ``tol`` otherwise).  Internal forces ``f_a = -F``, ``f_b = F``
  (plus the moment ``F x R_a d0`` on node a when d0 != 0, which makes the pair moment-free).
* Relative rotation ``Q = R_a^T R_b``; its finite increment over the increment,
  ``theta = log(Q_c^T Q)`` (right / body-b form, exact for any rotation of the joint as a
  whole and any relative rotation below pi per increment); Q_c is the committed Q, held
  in the state.
* Elastic predictor (regularised stick): ``m_tr = m_c + k_stick theta`` (m in the body
  frame of node b, so a stuck moment turns with the joint).
* Limits ``Y_s = mu_s B |F|`` (to start slipping) and ``Y_k = mu_k B |F|`` (to keep slipping:
  the joint slipped in the last increment and turns on the same way).  Stick if ``|m_tr| <= Y``:
  ``m = m_tr``.  Otherwise slip, radial return (backward Euler on the circle |m| = Y_k):
  ``m = Y_k n``, ``n = m_tr / |m_tr|``, slip increment ``dgamma = (|m_tr| - Y_k) / k_stick``,
  dissipation ``dD = Y_k dgamma`` (+ ``(Y_s - Y_k)^2 / (2 k_stick)`` at an onset).
* Transmitted moment ``M = R_b m`` (global); internal moments ``-M`` on a, ``+M`` on b.

Consistent tangent (exact derivative, checked against finite differences by the tests),
with ``C = k_stick I`` (stick) or ``C = (Y k_stick / |m_tr|) (I - n n^T)`` (slip):

    dM = R_b C Ts^-T(theta) R_b^T (dw_b - dw_a) - [M]x dw_b
         + R_b n (mu_k B k_pen F^T / |F|) (dx_b - dx_a + [R_a d0]x dw_a)    (slip only)

The last term is how the limit changes with F; it makes the tangent non-symmetric while
the joint slips (``symmetric = False``).

State per element (15 values): committed moment m (3, body frame of b, N m), slip flag,
accumulated slip (rad), dissipated energy (J), committed relative rotation Q (9).  The
committed state is never modified: the trial state is returned and the analysis commits
it on convergence or drops it on a cutback.

Output per element: ``moment`` (3, global, N m, the moment on node b is -moment),
``force`` (3, global, N), ``F`` = |F| (N), ``limit`` (N m: mu_s B |F| stuck, mu_k B |F| slipping),
``slip`` (1 slipping, 0 sticking), ``slip_angle`` (accumulated, rad), ``dissipated`` (J),
``moment_norm`` (N m); seated joints also ``normal_force`` (N, the seat's or retainer's), ``gap``
(axial opening, m, > 0 lifted off) and ``contact`` (1 seated, 0 open, 2 on the retainer).
"""

from __future__ import annotations

import numpy as np

from .._moved import renamed_attributes
from ..errors import ModelError
from .ball_joint_family import (
    ADAM_B,
    ADAM_MU,
    MAX_CLEARANCE_FRACTION,
    OPEN_FACTOR,
    PENALTY_FACTOR,
    SEATS,
    STICK_FACTOR,
    TOL_FACTOR,
    BallJointFamily,
)

__all__ = [
    "BallJointFamily",
    "add_ball_joints",
    "default_stiffnesses",
    "seat_axes",
    "friction_loop_energy",
    "stick_slip_loop_energy",
    "PENALTY_FACTOR",
    "STICK_FACTOR",
    "OPEN_FACTOR",
    "SEATS",
    "ADAM_MU",
    "ADAM_B",
]


def friction_loop_energy(mu, B, F, amplitude, k_stick):
    """Energy (J) dissipated per cycle by a joint under a constant force F (N) and a relative
    rotation cycled between -amplitude and +amplitude (rad) about a fixed axis, after the
    first half cycle: ``4 Y (amplitude - Y / k_stick)`` with ``Y = mu B |F|`` (zero if the
    joint never slips, amplitude <= Y / k_stick)."""
    Y = mu * B * np.abs(F)
    return 4.0 * Y * np.maximum(amplitude - Y / k_stick, 0.0)


def stick_slip_loop_energy(mu_s, mu_k, B, F, amplitude, k_stick):
    """As :func:`friction_loop_energy` with a static coefficient mu_s above the kinetic mu_k: each
    half cycle sticks from -Y_k to +Y_s, drops to Y_k (releasing (Y_s - Y_k)^2 / (2 k_stick)) and
    slides at Y_k, so ``(Y_s - Y_k)^2 / k_stick + 4 Y_k (amplitude - Y_k / k_stick)`` per cycle
    (J), valid when each half cycle reaches the onset, 2 amplitude >= (Y_s + Y_k) / k_stick."""
    Ys, Yk = mu_s * B * np.abs(F), mu_k * B * np.abs(F)
    return (Ys - Yk) ** 2 / k_stick + 4.0 * Yk * (amplitude - Yk / k_stick)


def _model_extent(model):
    X = model.coordinates
    return float(np.ptp(X, axis=0).max()) if len(X) > 1 else 0.0


def _member_lengths(model):
    """{node: (largest EA/L, largest 4EI/L or GJ/L)} of the beams and trusses at each node."""
    X = {lab: model.xyz(lab) for lab in model.node_labels}
    kt, kr = {}, {}
    for b in model.beams:
        L = float(np.linalg.norm(X[b.nodes[1]] - X[b.nodes[0]]))
        s = b.section
        t = s.E * s.A / L
        r = max(4 * s.E * s.Iy / L, 4 * s.E * s.Iz / L, s.G * s.J / L)
        for nd in b.nodes:
            kt[nd] = max(kt.get(nd, 0.0), t)
            kr[nd] = max(kr.get(nd, 0.0), r)
    for tr in model.trusses:
        L = tr.L0 or float(np.linalg.norm(X[tr.nodes[1]] - X[tr.nodes[0]]))
        for nd in tr.nodes:
            kt[nd] = max(kt.get(nd, 0.0), tr.EA / L)
    return kt, kr


def default_stiffnesses(model, pairs, penalty_factor=PENALTY_FACTOR, stick_factor=STICK_FACTOR):
    """Default ``(k_pen, k_stick)`` per joint from the members at its two nodes.

    k_pen = penalty_factor * max EA/L (beams and trusses at either node), N/m;
    k_stick = stick_factor * max(4 EIy/L, 4 EIz/L, GJ/L) (beams at either node), N m/rad.
    A joint with no such member at its nodes (e.g. a corner inside a rigid body) takes the
    largest value over the whole model.  Raises ModelError if the model has no beam (for
    k_stick) or no member at all (for k_pen): then give k_pen / k_stick explicitly."""
    kt, kr = _member_lengths(model)
    kt_all = max(kt.values(), default=0.0)
    kr_all = max(kr.values(), default=0.0)
    k_pen, k_stick = [], []
    for a, b in pairs:
        t = max(kt.get(int(a), 0.0), kt.get(int(b), 0.0)) or kt_all
        r = max(kr.get(int(a), 0.0), kr.get(int(b), 0.0)) or kr_all
        if t <= 0:
            raise ModelError(
                f"ball joint {a}-{b}: no beam or truss in the model to set the default penalty "
                "stiffness from; give k_pen (N/m) explicitly"
            )
        if r <= 0:
            raise ModelError(
                f"ball joint {a}-{b}: no beam in the model to set the default stick stiffness "
                "from; give k_stick (N m/rad) explicitly"
            )
        k_pen.append(penalty_factor * t)
        k_stick.append(stick_factor * r)
    return np.array(k_pen), np.array(k_stick)


def seat_axes(model, pairs):
    """(n, 3) default seat axes: from each joint's ball node *a* along the member that ends there
    (beam or truss) towards that member's other node.  Raises ModelError naming the joint when its
    ball node has no member or several in different directions: then give ``axis=``."""
    X = {lab: model.xyz(lab) for lab in model.node_labels}
    ends = {}
    for el in list(model.beams) + list(model.trusses):
        a, b = el.nodes[0], el.nodes[-1]
        ends.setdefault(a, []).append(X[b] - X[a])
        ends.setdefault(b, []).append(X[a] - X[b])
    out = np.zeros((len(pairs), 3))
    for i, (a, b) in enumerate(pairs):
        dirs = [d / np.linalg.norm(d) for d in ends.get(int(a), []) if np.linalg.norm(d) > 0]
        if not dirs or any(float(d @ dirs[0]) < 1 - 1e-9 for d in dirs[1:]):
            what = "no beam or truss" if not dirs else "members in different directions"
            raise ModelError(
                f"ball joint {a}-{b}: its ball node {a} has {what}, so the seat axis is not known; "
                "give axis= (from the seat into the member, per joint)"
            )
        out[i] = dirs[0]
    return out


def add_ball_joints(
    model,
    pairs,
    mu=None,
    B=ADAM_B,
    *,
    mu_s=None,
    mu_k=None,
    seat="tied",
    axis=None,
    clearance_radial=0.0,
    clearance_axial=None,
    k_pen=None,
    k_stick=None,
    k_open=None,
    penalty_factor=PENALTY_FACTOR,
    stick_factor=STICK_FACTOR,
    open_factor=OPEN_FACTOR,
    tol=None,
    labels=None,
    name="ball_joint",
) -> BallJointFamily:
    """Add friction ball joints (Stohlman & Pellegrino, Sec. II.B.1) between coincident node pairs.

    pairs : [(longeron_end, corner), ...] node labels (the ball, the socket).
    mu : friction coefficient, static = kinetic (ADAM: 0.5); or ``mu_s`` and ``mu_k`` (static,
        kinetic, mu_s >= mu_k).  B : ball end radius, m (ADAM: 0.004).  Scalars or per joint.
    seat : ``"tied"`` (captive ball, the paper's two-way tie) or ``"seated"`` (carries compression,
        opens in tension; see the module docstring).
    axis : seated: seat axes (3,) or (n, 3); default along the member at each ball node, pointing
        into it (:func:`seat_axes`).
    clearance_radial, clearance_axial : seated: radial play (m, default 0) and axial play up to a
        retainer (m; default None: no retainer).
    k_pen, k_stick, k_open : penalty (N/m), stick (N m/rad) and open-seat (N/m) stiffnesses; default
        from the members at each joint (:func:`default_stiffnesses`; factors ``penalty_factor`` = 1e4,
        ``stick_factor`` = 1e3 and ``open_factor`` = 1e-5 of the largest EA/L; k_open is
        ``open_factor / penalty_factor`` of k_pen when k_pen is given).
    tol : coincidence tolerance, m (default 1e-6 of the model's size, at least 1e-9 m).
    Returns the :class:`BallJointFamily` (already added to ``model``)."""
    pairs = np.asarray(pairs)
    if pairs.ndim == 1 and pairs.size == 2:
        pairs = pairs[None, :]
    if pairs.ndim != 2 or pairs.shape[1] != 2 or pairs.shape[0] == 0:
        raise ModelError(
            f"ball joints '{name}': pairs must be a list of (longeron end, corner) node labels, got shape {pairs.shape}"
        )
    for a, b in pairs.tolist():
        model._check_node(a, f"ball joint {a}-{b}")
        model._check_node(b, f"ball joint {a}-{b}")
    pairs = pairs.astype(np.int64)
    if any(getattr(f, "name", None) == name for f in model.families):
        raise ModelError(f"the model already has an element family named '{name}'; pass another name=")
    if seat not in SEATS:
        raise ModelError(f"ball joints '{name}': seat = {seat!r}; use one of {', '.join(map(repr, SEATS))}")
    seated = seat == "seated"
    if k_pen is None or k_stick is None:
        kp, ks = default_stiffnesses(model, pairs, penalty_factor, stick_factor)
        k_pen = kp if k_pen is None else k_pen
        k_stick = ks if k_stick is None else k_stick
    if seated and k_open is None:  # open_factor x EA/L = open_factor / penalty_factor x the default k_pen
        k_open = open_factor / penalty_factor * np.asarray(k_pen, dtype=float)
    if seated and axis is None:
        axis = seat_axes(model, pairs)
    ext = _model_extent(model)
    for what, v in (("clearance_radial", clearance_radial), ("clearance_axial", clearance_axial)):
        big = np.asarray(v if v is not None else 0.0, dtype=float)
        if seated and ext > 0 and np.any(big > MAX_CLEARANCE_FRACTION * ext):
            raise ModelError(
                f"ball joints '{name}': {what} = {float(big.max()):g} m is more than {MAX_CLEARANCE_FRACTION:g} of "
                f"the model's size ({ext:g} m); clearances are in m (0.05 mm = 5e-5)"
            )
    X = np.array([[model.xyz(a), model.xyz(b)] for a, b in pairs])
    if tol is None:
        tol = max(TOL_FACTOR * ext, 1e-9)
    extra = dict(axis=axis, clearance_radial=clearance_radial, clearance_axial=clearance_axial, k_open=k_open)
    fam = BallJointFamily(
        pairs, k_pen, k_stick, mu, B, mu_s=mu_s, mu_k=mu_k, seat=seat, X=X, tol=tol, labels=labels, name=name, **extra
    )
    return model.add_family(fam)


#: old names, kept for one release (they warn): femast 0.3 removes them
__getattr__ = renamed_attributes(__name__, {"SEED_MU": "ADAM_MU", "SEED_B": "ADAM_B"})
