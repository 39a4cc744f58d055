"""The element family of the friction ball joints: :class:`BallJointFamily` (parameters, checks,
the kernels' dispatch, the output).  The law, its equations and the helpers that add joints to a
model are in :mod:`femast.elements.ball_joint` (read that first).
"""

from __future__ import annotations

import numpy as np

from .._moved import renamed_attributes
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
from ._ball_seat_kernels import (
    I_RGAP,
    I_STATUS,
    I_TRUE_STATUS,
    N_OUT,
    N_STATE_SEATED,
    SEATED,
    seated_joint_family_kernel,
)
from .base import ElementFamily, ElementResponse, IncrementContext, LazyOutput

__all__ = ["BallJointFamily", "PENALTY_FACTOR", "STICK_FACTOR", "OPEN_FACTOR", "SEATS", "ADAM_MU", "ADAM_B"]

ADAM_MU = 0.5  # Stohlman & Pellegrino, Sec. II.B.1: static = kinetic friction coefficient
ADAM_B = 0.004  # Stohlman & Pellegrino, Sec. II.B.1: longeron ball end radius, m
#: The seats a joint can have (module docstring).
SEATS = ("tied", "seated")
# Default penalty k_pen = PENALTY_FACTOR * (largest EA/L of the members at the joint): the tie
# gap |F|/k_pen is 1e-4 of the stretch of the stiffest connected member under the same force.
PENALTY_FACTOR = 1e4
# Default stick stiffness k_stick = STICK_FACTOR * (largest 4EI/L or GJ/L of the beams at the
# joint): the elastic 'stick' rotation is 1e-3 of the end rotation of the stiffest connected beam.
STICK_FACTOR = 1e3
# Default stiffness of an open seat k_open = OPEN_FACTOR * (largest EA/L of the members at the
# joint): a regularisation that keeps a strut between two open seats from floating (a mechanism);
# the force it carries across a gap g is 1e-5 of what the member carries when stretched by g.
OPEN_FACTOR = 1e-5
# Default coincidence tolerance, as a fraction of the model's size.
TOL_FACTOR = 1e-6
# A clearance above this fraction of the joints' extent is a unit slip (mm given as m).
MAX_CLEARANCE_FRACTION = 0.05


_NO_PREV = {N_STATE: np.zeros((1, N_STATE)), N_STATE_SEATED: np.zeros((1, N_STATE_SEATED))}


def _per_joint(value, n, what, name):
    try:
        a = np.broadcast_to(np.asarray(value, dtype=float), (n,)).astype(float).copy()
    except (TypeError, ValueError):
        raise ModelError(
            f"ball joints '{name}': {what} must be a number or one number per joint ({n}), got {value!r}"
        ) from None
    return a


def friction_coefficients(mu, mu_s, mu_k, name):
    """(mu_s, mu_k) from the one-coefficient ``mu`` (static = kinetic, the paper's law) or the pair;
    mu_k defaults to mu_s."""
    if mu is not None and mu_s is not None:
        raise ModelError(
            f"ball joints '{name}': give mu (static = kinetic) or mu_s (and mu_k), not both (mu = {mu!r}, mu_s = {mu_s!r})"
        )
    mu_s = ADAM_MU if mu is None and mu_s is None else (mu if mu_s is None else mu_s)
    return mu_s, (mu_s if mu_k is None else mu_k)


class BallJointFamily(ElementFamily):
    """A batch of friction ball joints (Stohlman & Pellegrino, Sec. II.B.1), tied or seated.

    Parameters
    ----------
    nodes : (n_el, 2) node labels (a = longeron end (ball), b = corner (socket)) when added with
        :meth:`Model.add_family` (the analysis converts them to indices).
    k_pen : translational penalty stiffness of the tie / the seat, N/m (scalar or per joint).
    k_stick : rotational stick stiffness (regularised Coulomb), N m/rad.
    mu : friction coefficient (>= 0), static = kinetic (the paper's law), default 0.5.  Or give
    mu_s, mu_k : static and kinetic coefficients, mu_s >= mu_k >= 0 (mu_k defaults to mu_s).
    B : ball end radius, m (> 0), default 0.004 (ADAM).
    seat : ``"tied"`` (captive ball, the paper's joint) or ``"seated"`` (module docstring).
    axis : seated only: (n_el, 3) or (3,) seat axis, from the seat into the member (the direction
        in which the ball lifts off), in the initial configuration; normalised.
    clearance_radial : seated only: radial play of the ball in its socket, m (default 0).
    clearance_axial : seated only: axial play from the seat to a retainer, m; None (default): no
        retainer, the seat opens freely in tension.
    k_open : seated only: stiffness of an open seat (a regularisation), N/m; default
        ``OPEN_FACTOR / PENALTY_FACTOR * k_pen``.
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
        self,
        nodes,
        k_pen,
        k_stick,
        mu=None,
        B=ADAM_B,
        *,
        mu_s=None,
        mu_k=None,
        seat="tied",
        axis=None,
        clearance_radial=0.0,
        clearance_axial=None,
        k_open=None,
        X=None,
        tol=None,
        labels=None,
        name: str = "ball_joint",
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
        if seat not in SEATS:
            raise ModelError(f"ball joints '{name}': seat = {seat!r}; use one of {', '.join(map(repr, SEATS))}")
        self.seat = seat
        self.n_state = N_STATE_SEATED if seat == "seated" else N_STATE
        mu_s, mu_k = friction_coefficients(mu, mu_s, mu_k, name)
        self.k_pen = _per_joint(k_pen, n, "k_pen (N/m)", name)
        self.k_stick = _per_joint(k_stick, n, "k_stick (N m/rad)", name)
        self.mu_s = _per_joint(mu_s, n, "mu_s", name)
        self.mu_k = _per_joint(mu_k, n, "mu_k", name)
        self.B = _per_joint(B, n, "B (m)", name)
        for what, arr, ok, rule in (
            ("k_pen", self.k_pen, self.k_pen > 0, "must be finite and > 0 N/m"),
            ("k_stick", self.k_stick, self.k_stick > 0, "must be finite and > 0 N m/rad"),
            ("mu", self.mu_s, self.mu_s >= 0, "is a friction coefficient: it must be finite and >= 0"),
            ("mu_k", self.mu_k, self.mu_k >= 0, "is a friction coefficient: it must be finite and >= 0"),
            ("B", self.B, self.B > 0, "is the ball end radius: it must be finite and > 0 m (ADAM: 0.004)"),
        ):
            bad = np.flatnonzero(~(np.isfinite(arr) & ok))
            if bad.size:
                raise ModelError(f"{self._who(bad[0])}: {what} = {float(arr[bad[0]])!r} {rule}")
        bad = np.flatnonzero(self.mu_k > self.mu_s)
        if bad.size:
            el = bad[0]
            raise ModelError(
                f"{self._who(el)}: kinetic mu_k = {self.mu_k[el]:g} above static mu_s = {self.mu_s[el]:g}; "
                "a joint slips at mu_s and slides on at mu_k <= mu_s"
            )
        self.d0 = np.zeros((n, 3))
        self.tol = None
        if X is not None:
            self._check_coincident(X, tol)
        self._set_seat(axis, clearance_radial, clearance_axial, k_open, X)

    @property
    def mu(self):
        """The static coefficient (the paper's one coefficient when mu_s = mu_k)."""
        return self.mu_s

    def _check_coincident(self, X, tol):
        n, name = self.n_elements, self.name
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

    def _set_seat(self, axis, clearance_radial, clearance_axial, k_open, X):
        """The seat's axis, clearances and open stiffness (seated joints); checked, one per joint."""
        n, name = self.n_elements, self.name
        if self.seat == "tied":
            for what, v, default in (
                ("axis", axis, None),
                ("clearance_radial", clearance_radial, 0.0),
                ("clearance_axial", clearance_axial, None),
                ("k_open", k_open, None),
            ):
                if v is not default and not (default is not None and np.all(np.asarray(v) == default)):
                    raise ModelError(
                        f"ball joints '{name}': {what} is a parameter of seated joints; pass seat='seated'"
                    )
            return
        if axis is None:
            raise ModelError(
                f"ball joints '{name}': a seated joint needs its seat axis (axis=, from the seat into the member); "
                "add_ball_joints takes it from the member at the ball's node"
            )
        try:
            e = np.broadcast_to(np.asarray(axis, dtype=float), (n, 3)).copy()
        except (TypeError, ValueError):
            raise ModelError(f"ball joints '{name}': axis must be (3,) or ({n}, 3), got {np.shape(axis)}") from None
        ln = np.linalg.norm(e, axis=1)
        bad = np.flatnonzero(~(np.isfinite(ln) & (ln > 0)))
        if bad.size:
            raise ModelError(
                f"{self._who(bad[0])}: seat axis {tuple(e[bad[0]])} is not a direction (zero or not finite)"
            )
        self.axis = np.ascontiguousarray(e / ln[:, None])
        self.c_r = _per_joint(clearance_radial, n, "clearance_radial (m)", name)
        self.c_a = _per_joint(np.inf if clearance_axial is None else clearance_axial, n, "clearance_axial (m)", name)
        self.k_open = _per_joint(
            OPEN_FACTOR / PENALTY_FACTOR * self.k_pen if k_open is None else k_open, n, "k_open (N/m)", name
        )
        ext = float(np.ptp(np.asarray(X, dtype=float).reshape(-1, 3), axis=0).max()) if X is not None and n > 1 else 0.0
        for what, arr, ok, rule in (
            ("clearance_radial", self.c_r, np.isfinite(self.c_r) & (self.c_r >= 0), "must be finite and >= 0 m"),
            ("clearance_axial", self.c_a, self.c_a >= 0, "must be >= 0 m (None: no retainer)"),
            ("k_open", self.k_open, np.isfinite(self.k_open) & (self.k_open >= 0), "must be finite and >= 0 N/m"),
            (
                "k_open",
                self.k_open,
                self.k_open <= self.k_pen,
                "must not exceed k_pen (it is the open seat's stiffness)",
            ),
        ):
            bad = np.flatnonzero(~ok)
            if bad.size:
                raise ModelError(f"{self._who(bad[0])}: {what} = {float(arr[bad[0]])!r} {rule}")
        for what, arr in (("clearance_radial", self.c_r), ("clearance_axial", self.c_a)):
            big = np.flatnonzero(np.isfinite(arr) & (arr > MAX_CLEARANCE_FRACTION * ext) & (ext > 0))
            if big.size:
                raise ModelError(
                    f"{self._who(big[0])}: {what} = {arr[big[0]]:g} m is more than {MAX_CLEARANCE_FRACTION:g} of "
                    f"the joints' extent ({ext:g} m); clearances are in m (0.05 mm = 5e-5)"
                )

    def _who(self, el):
        return f"ball joint {self.labels[el]} (nodes {self.nodes[el, 0]}-{self.nodes[el, 1]}) of family '{self.name}'"

    # ------------------------------------------------------------------ contract
    def initial_state(self) -> np.ndarray:
        """Zero moment, sticking, no slip, no dissipation, Q = I (nodal rotations start at I);
        seated joints start seated, the ball centred in its socket."""
        st = np.zeros((self.n_elements, self.n_state))
        st[:, I_Q : I_Q + 9] = np.eye(3).ravel()
        if self.seat == "seated":
            st[:, I_STATUS] = st[:, I_TRUE_STATUS] = SEATED
            st[:, I_RGAP] = -self.c_r
        return st

    def evaluate(self, x, R, state, ctx: IncrementContext | None = None) -> ElementResponse:
        """Forces, tangent, trial state and output of all joints (see module docstring).

        x : (n_nodes, 3) positions, m.  R : (n_nodes, 3, 3) nodal rotations.
        state : (n_el, n_state) committed state (not modified).  ctx : its ``previous_state`` (the
        previous Newton iteration's trial states) is used to see slip reversals; the committed
        relative rotation is part of the state.
        """
        n = self.n_elements
        f = np.empty((n, 12))
        K = np.empty((n, 12, 12))
        new = np.empty((n, self.n_state))
        seated = self.seat == "seated"
        out = np.empty((n, N_OUT if seated else 11))
        energy = np.empty(n)
        err = np.zeros(n, dtype=np.int64)
        prev = ctx.previous_state(self) if hasattr(ctx, "previous_state") else None
        has_prev = prev is not None and prev.shape == (n, self.n_state)
        held = np.zeros(n, dtype=np.bool_)
        x = np.ascontiguousarray(x, dtype=float)
        R = np.ascontiguousarray(R, dtype=float)
        state = np.ascontiguousarray(state, dtype=float)
        prev = np.ascontiguousarray(prev, dtype=float) if has_prev else _NO_PREV[self.n_state]
        if seated:
            seated_joint_family_kernel(
                self.nodes, x, R, self.d0, self.axis, self.k_pen, self.k_open, self.c_r, self.c_a, self.k_stick,
                self.mu_s, self.mu_k, self.B, state, f, K, new, out, energy, err, held, prev, has_prev,
            )  # fmt: skip
        else:
            ball_joint_family_kernel(
                self.nodes, x, R, self.d0, self.k_pen, self.k_stick, self.mu_s, self.mu_k, self.B,
                state, f, K, new, out, energy, err, prev, has_prev,
            )  # fmt: skip
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
        return ElementResponse(
            f=f,
            k=K,
            state=new,
            output=LazyOutput(lambda: _outputs(out, seated)),
            energy=energy,
            provisional=bool((has_prev and np.any(new[:, I_SLIP] == REVERSED)) or held.any()),
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


def _outputs(out, seated):
    """The output dict of a family from its kernel's output rows (module docstring)."""
    d = {
        "moment": out[:, 0:3].copy(),
        "force": out[:, 3:6].copy(),
        "F": out[:, 6].copy(),
        "limit": out[:, 7].copy(),
        "slip": out[:, 8].copy(),
        "slip_angle": out[:, 9].copy(),
        "dissipated": out[:, 10].copy(),
        "moment_norm": np.linalg.norm(out[:, 0:3], axis=1),
    }
    if seated:
        d.update(
            normal_force=out[:, 11].copy(), gap=out[:, 12].copy(), contact=out[:, 13].copy(), wall=out[:, 14].copy()
        )
    return d


#: old names, kept for one release (they warn): femast 0.3 removes them
__getattr__ = renamed_attributes(__name__, {"SEED_MU": "ADAM_MU", "SEED_B": "ADAM_B"})
