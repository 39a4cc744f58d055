"""Ball joint with Coulomb friction: Stohlman & Pellegrino, Section II.B.1 (|M| <= mu B |F|).

A joint ties a longeron end node *a* to a coincident corner node *b*.  Translations are
tied by a stiff penalty; the relative rotation is resisted by a friction moment whose
magnitude cannot exceed ``mu B |F|``, with F the force the joint transmits, mu the
friction coefficient and B the radius of the longeron ball end (seed: mu = 0.5, B = 4 mm,
same static and kinetic coefficient).  The derivation is in ``docs/ball_joint.md``.

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
* Limit ``Y = mu B |F|``.  Stick if ``|m_tr| <= Y``: ``m = m_tr``.  Otherwise slip, radial
  return (backward Euler on the circle |m| = Y): ``m = Y n``, ``n = m_tr / |m_tr|``,
  slip increment ``dgamma = (|m_tr| - Y) / k_stick``, dissipation ``dD = Y dgamma``.
* Transmitted moment ``M = R_b m`` (global); internal moments ``-M`` on a, ``+M`` on b.

Consistent tangent (exact derivative, checked against finite differences by the tests),
with ``C = k_stick I`` (stick) or ``C = (Y k_stick / |m_tr|) (I - n n^T)`` (slip):

    dM = R_b C Ts^-T(theta) R_b^T (dw_b - dw_a) - [M]x dw_b
         + R_b n (mu B k_pen F^T / |F|) (dx_b - dx_a + [R_a d0]x dw_a)      (slip only)

The last term is how the limit changes with F; it makes the tangent non-symmetric while
the joint slips (``symmetric = False``).

State per element (15 values): committed moment m (3, body frame of b, N m), slip flag,
accumulated slip (rad), dissipated energy (J), committed relative rotation Q (9).  The
committed state is never modified: the trial state is returned and the analysis commits
it on convergence or drops it on a cutback.

Output per element: ``moment`` (3, global, N m, the moment on node b is -moment),
``force`` (3, global, N), ``F`` = |F| (N), ``limit`` = mu B |F| (N m), ``slip`` (1 slipping,
0 sticking), ``slip_angle`` (accumulated, rad), ``dissipated`` (J), ``moment_norm`` (N m).
"""

from __future__ import annotations

import numpy as np

from ..errors import ModelError
from ._ball_joint_kernels import (
    ERR_BIG_INCREMENT,
    ERR_NOT_FINITE,
    I_DISS,
    I_GAMMA,
    I_M,
    I_Q,
    I_SLIP,
    MAX_INCREMENT,
    N_STATE,
    REVERSED,
    ball_joint_family_kernel,
)
from .base import ElementFamily, ElementResponse, IncrementContext, LazyOutput

__all__ = [
    "BallJointFamily",
    "add_ball_joints",
    "default_stiffnesses",
    "friction_loop_energy",
    "PENALTY_FACTOR",
    "STICK_FACTOR",
    "SEED_MU",
    "SEED_B",
]

SEED_MU = 0.5  # Stohlman & Pellegrino, Sec. II.B.1: static = kinetic friction coefficient
SEED_B = 0.004  # Stohlman & Pellegrino, Sec. II.B.1: longeron ball end radius, m
# Default penalty k_pen = PENALTY_FACTOR * (largest EA/L of the members at the joint): the tie
# gap |F|/k_pen is 1e-4 of the stretch of the stiffest connected member under the same force.
PENALTY_FACTOR = 1e4
# Default stick stiffness k_stick = STICK_FACTOR * (largest 4EI/L or GJ/L of the beams at the
# joint): the elastic 'stick' rotation is 1e-3 of the end rotation of the stiffest connected beam.
STICK_FACTOR = 1e3
# Default coincidence tolerance, as a fraction of the model's size.
TOL_FACTOR = 1e-6


_NO_PREV = np.zeros((1, N_STATE))


def _per_joint(value, n, what, name):
    try:
        a = np.broadcast_to(np.asarray(value, dtype=float), (n,)).astype(float).copy()
    except (TypeError, ValueError):
        raise ModelError(
            f"ball joints '{name}': {what} must be a number or one number per joint ({n}), got {value!r}"
        ) from None
    return a


class BallJointFamily(ElementFamily):
    """A batch of friction ball joints (Stohlman & Pellegrino, Sec. II.B.1).

    Parameters
    ----------
    nodes : (n_el, 2) node labels (a = longeron end, b = corner) when added with
        :meth:`Model.add_family` (the analysis converts them to indices).
    k_pen : translational penalty stiffness of the tie, N/m (scalar or per joint).
    k_stick : rotational stick stiffness (regularised Coulomb), N m/rad.
    mu : friction coefficient (>= 0), default 0.5 (seed).
    B : ball end radius, m (> 0), default 0.004 (seed).
    X : optional (n_el, 2, 3) initial coordinates of nodes a and b; the joint checks that
        they coincide within ``tol`` and ties the small offset rigidly to node a.
    tol : coincidence tolerance, m (default 1e-6 of the joints' extent, at least 1e-9 m).
    labels : joint labels for results and messages (default 1..n).
    name : family name (results key, messages).
    """

    active_dofs = (0, 1, 2, 3, 4, 5)
    n_state = N_STATE
    symmetric = False

    def __init__(
        self, nodes, k_pen, k_stick, mu=SEED_MU, B=SEED_B, *, X=None, tol=None, labels=None, name: str = "ball_joint"
    ):
        self.name = name
        nodes = np.asarray(nodes)
        if nodes.ndim == 1 and nodes.size == 2:
            nodes = nodes[None, :]
        if nodes.ndim != 2 or nodes.shape[1] != 2 or not np.issubdtype(nodes.dtype, np.integer):
            raise ModelError(
                f"ball joints '{name}': nodes must be an (n, 2) array of integer node labels "
                f"(longeron end, corner), got shape {nodes.shape} of {nodes.dtype}"
            )
        self.nodes = np.ascontiguousarray(nodes, dtype=np.int64)
        n = self.nodes.shape[0]
        self.labels = np.arange(1, n + 1) if labels is None else np.asarray(labels).ravel()
        if self.labels.size != n:
            raise ModelError(f"ball joints '{name}': {self.labels.size} labels for {n} joints")
        same = np.flatnonzero(self.nodes[:, 0] == self.nodes[:, 1])
        if same.size:
            raise ModelError(
                f"{self._who(same[0])}: both ends are the same node; a ball joint connects a "
                "longeron end node to a different, coincident corner node"
            )
        self.k_pen = _per_joint(k_pen, n, "k_pen (N/m)", name)
        self.k_stick = _per_joint(k_stick, n, "k_stick (N m/rad)", name)
        self.mu = _per_joint(mu, n, "mu", name)
        self.B = _per_joint(B, n, "B (m)", name)
        for what, arr, ok, rule in (
            ("k_pen", self.k_pen, self.k_pen > 0, "must be finite and > 0 N/m"),
            ("k_stick", self.k_stick, self.k_stick > 0, "must be finite and > 0 N m/rad"),
            ("mu", self.mu, self.mu >= 0, "is a friction coefficient: it must be finite and >= 0"),
            ("B", self.B, self.B > 0, "is the ball end radius: it must be finite and > 0 m (seed: 0.004)"),
        ):
            bad = np.flatnonzero(~(np.isfinite(arr) & ok))
            if bad.size:
                raise ModelError(f"{self._who(bad[0])}: {what} = {float(arr[bad[0]])!r} {rule}")
        self.d0 = np.zeros((n, 3))
        self.tol = None
        if X is not None:
            X = np.asarray(X, dtype=float)
            if X.shape != (n, 2, 3):
                raise ModelError(f"ball joints '{name}': X must have shape ({n}, 2, 3), got {X.shape}")
            d0 = X[:, 1] - X[:, 0]
            if tol is None:
                ext = float(np.ptp(X.reshape(-1, 3), axis=0).max()) if n > 1 else 0.0
                tol = max(TOL_FACTOR * ext, 1e-9)
            tol = float(tol)
            if not (tol >= 0 and np.isfinite(tol)):
                raise ModelError(f"ball joints '{name}': tol = {tol!r} m must be finite and >= 0")
            gap = np.linalg.norm(d0, axis=1)
            bad = np.flatnonzero(~(gap <= tol))
            if bad.size:
                el = bad[0]
                raise ModelError(
                    f"{self._who(el)}: nodes {self.nodes[el, 0]} at {tuple(X[el, 0])} and "
                    f"{self.nodes[el, 1]} at {tuple(X[el, 1])} are {gap[el]:.3g} m apart, more than "
                    f"the tolerance {tol:.3g} m; a ball joint connects coincident nodes (check the "
                    "node labels, or pass a larger tol=)"
                )
            self.d0 = np.ascontiguousarray(d0)
            self.tol = tol

    def _who(self, el):
        return f"ball joint {self.labels[el]} (nodes {self.nodes[el, 0]}-{self.nodes[el, 1]}) of family '{self.name}'"

    # ------------------------------------------------------------------ contract
    def initial_state(self) -> np.ndarray:
        """Zero moment, sticking, no slip, no dissipation, Q = I (nodal rotations start at I)."""
        st = np.zeros((self.n_elements, N_STATE))
        st[:, I_Q : I_Q + 9] = np.eye(3).ravel()
        return st

    def evaluate(self, x, R, state, ctx: IncrementContext | None = None) -> ElementResponse:
        """Forces, tangent, trial state and output of all joints (see module docstring).

        x : (n_nodes, 3) positions, m.  R : (n_nodes, 3, 3) nodal rotations.
        state : (n_el, 15) committed state (not modified).  ctx : its ``previous_state`` (the
        previous Newton iteration's trial states) is used to see slip reversals; the committed
        relative rotation is part of the state.
        """
        n = self.n_elements
        f = np.empty((n, 12))
        K = np.empty((n, 12, 12))
        new = np.empty((n, N_STATE))
        out = np.empty((n, 11))
        energy = np.empty(n)
        err = np.zeros(n, dtype=np.int64)
        prev = ctx.previous_state(self) if hasattr(ctx, "previous_state") else None
        has_prev = prev is not None and prev.shape == (n, N_STATE)
        ball_joint_family_kernel(
            self.nodes,
            np.ascontiguousarray(x, dtype=float),
            np.ascontiguousarray(R, dtype=float),
            self.d0,
            self.k_pen,
            self.k_stick,
            self.mu,
            self.B,
            np.ascontiguousarray(state, dtype=float),
            f,
            K,
            new,
            out,
            energy,
            err,
            np.ascontiguousarray(prev, dtype=float) if has_prev else _NO_PREV,
            has_prev,
        )
        bad = np.flatnonzero(err)
        if bad.size:
            el = bad[0]
            if err[el] == ERR_NOT_FINITE:
                # the analysis cuts the increment back on FloatingPointError
                raise FloatingPointError(f"{self._who(el)}: nodal positions or rotations are not finite")
            if err[el] == ERR_BIG_INCREMENT:
                raise FloatingPointError(
                    f"{self._who(el)}: relative rotation increment above "
                    f"{MAX_INCREMENT} rad in one increment; use smaller increments"
                )
        output = LazyOutput(
            lambda: {
                "moment": out[:, 0:3].copy(),
                "force": out[:, 3:6].copy(),
                "F": out[:, 6].copy(),
                "limit": out[:, 7].copy(),
                "slip": out[:, 8].copy(),
                "slip_angle": out[:, 9].copy(),
                "dissipated": out[:, 10].copy(),
                "moment_norm": np.linalg.norm(out[:, 0:3], axis=1),
            }
        )
        return ElementResponse(
            f=f,
            k=K,
            state=new,
            output=output,
            energy=energy,
            provisional=bool(has_prev and np.any(new[:, I_SLIP] == REVERSED)),
        )

    # ------------------------------------------------------------------ helpers
    @staticmethod
    def state_moment(state):
        """Committed friction moments (n, 3) in the body frame of node b, N m."""
        return np.asarray(state)[:, I_M : I_M + 3]

    @staticmethod
    def state_dissipated(state):
        """Dissipated energy (n,) in the committed state, J."""
        return np.asarray(state)[:, I_DISS]

    @staticmethod
    def state_slip(state):
        """(slip flag, accumulated slip angle in rad) of the committed state."""
        st = np.asarray(state)
        return st[:, I_SLIP], st[:, I_GAMMA]


def friction_loop_energy(mu, B, F, amplitude, k_stick):
    """Energy (J) dissipated per cycle by a joint under a constant force F (N) and a relative
    rotation cycled between -amplitude and +amplitude (rad) about a fixed axis, after the
    first half cycle: ``4 Y (amplitude - Y / k_stick)`` with ``Y = mu B |F|`` (zero if the
    joint never slips, amplitude <= Y / k_stick)."""
    Y = mu * B * np.abs(F)
    return 4.0 * Y * np.maximum(amplitude - Y / k_stick, 0.0)


def _model_extent(model):
    X = model.coordinates
    return float(np.ptp(X, axis=0).max()) if len(X) > 1 else 0.0


def default_stiffnesses(model, pairs, penalty_factor=PENALTY_FACTOR, stick_factor=STICK_FACTOR):
    """Default ``(k_pen, k_stick)`` per joint from the members at its two nodes.

    k_pen = penalty_factor * max EA/L (beams and trusses at either node), N/m;
    k_stick = stick_factor * max(4 EIy/L, 4 EIz/L, GJ/L) (beams at either node), N m/rad.
    A joint with no such member at its nodes (e.g. a corner inside a rigid body) takes the
    largest value over the whole model.  Raises ModelError if the model has no beam (for
    k_stick) or no member at all (for k_pen): then give k_pen / k_stick explicitly."""
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


def add_ball_joints(
    model,
    pairs,
    mu=SEED_MU,
    B=SEED_B,
    *,
    k_pen=None,
    k_stick=None,
    penalty_factor=PENALTY_FACTOR,
    stick_factor=STICK_FACTOR,
    tol=None,
    labels=None,
    name="ball_joint",
) -> BallJointFamily:
    """Add friction ball joints (Stohlman & Pellegrino, Sec. II.B.1) between coincident node pairs.

    pairs : [(longeron_end, corner), ...] node labels.
    mu, B : friction coefficient and ball end radius, m (seed: 0.5, 0.004); scalars or per joint.
    k_pen, k_stick : penalty (N/m) and stick (N m/rad) stiffnesses; default from the members at
        each joint (:func:`default_stiffnesses`, factors ``penalty_factor`` = 1e4 and
        ``stick_factor`` = 1e3).
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
    if k_pen is None or k_stick is None:
        kp, ks = default_stiffnesses(model, pairs, penalty_factor, stick_factor)
        k_pen = kp if k_pen is None else k_pen
        k_stick = ks if k_stick is None else k_stick
    X = np.array([[model.xyz(a), model.xyz(b)] for a, b in pairs])
    if tol is None:
        tol = max(TOL_FACTOR * _model_extent(model), 1e-9)
    fam = BallJointFamily(pairs, k_pen, k_stick, mu, B, X=X, tol=tol, labels=labels, name=name)
    return model.add_family(fam)
