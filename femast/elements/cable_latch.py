"""Cable over pulleys and a latch: the user element of Stohlman & Pellegrino, Section II.B.2 (Eqs. 2-5).

One element is one continuous cable divided into n straight sections by n+1
anchor nodes.  Each interior node is a frictionless pulley, except (optionally)
one, the *latch node*, where the cable passes through a roller latch that grips a
bead fixed on the cable (latch law: :mod:`femast.elements.latch_law`, Eqs. 6-14).  The element
solves its 2n equations (n tensions, n unstretched lengths) internally and returns
the nodal forces and the consistent tangent; see ``docs/cable_latch_element.md``.

Equations (SI: N, m)
--------------------
* Eqs. 2-3, per section: ``T_i = EA (L_i - L0_i) / L0_i`` if ``L_i > L0_i`` else 0,
  ``L_i = |x_{i+1} - x_i|``;
* Eq. 4: ``sum_i L0_i = L0``;
* frictionless pulleys: ``T_{i+1} = T_i``;
* Eq. 5 at the latch node j: ``T_{j+1} - T_j = dT(x)``, ``x = Lb - (L0_1 + ... + L0_j)``.

``Lb`` is the material coordinate of the bead (unstretched length from node 0 to
the bead).  ``x > 0`` means the bead is on the section-(j+1) side of the latch
(outside), ``x < 0`` on the section-j side, where the backstop is (at
``x = -x_backstop``).  So section j must be the cable that runs through the
backstop.  In the paper's two-section element, j = 1 (one-based), i.e. the latch
is local node 1 of nodes (0, 1, 2).

State per element (``n_state = n + 2``): ``[x_bead (m), status, L0_1 ... L0_n (m)]``,
status 0 stick, +1 slipping out, -1 slipping in, 2 held by the backstop.

Stick/slip is a return mapping from the *committed* bead position: if the trial
``T_{j+1} - T_j`` with the bead held at x_committed lies in the static-friction
band, the bead sticks; otherwise it slides to the first equilibrium in the
direction of the unbalanced force (or to the backstop).  The committed state is
never written.

Forces and tangent: with ``g_A``, ``g_B`` the gradients of the chord lengths of the
sections before/after the latch, ``f = T_A g_A + T_B g_B`` and
``K = sum_i T_i / L_i (I - e_i e_i^T) + [g_A g_B] M [g_A g_B]^T`` with
``M = d(T_A, T_B) / d(L_A, L_B)`` from implicit differentiation of the latch
equation (not symmetric while the bead slides).
"""

from __future__ import annotations

import numpy as np

from ..errors import ModelError
from ._cable_kernels import (
    BACKSTOP,
    ERR_BEAD_OFF_CABLE,
    ERR_NOT_FINITE,
    ERR_ZERO_LENGTH,
    SLIP_IN,
    SLIP_OUT,
    STICK,
    cable_latch_kernel,
)
from .base import ElementFamily, ElementResponse, IncrementContext, LazyOutput, chain_nodes
from .cable_latch_equations import cable_equations
from .latch_law import LatchParameters, _as_param_array, latch_zone, validate_latch_array

STATUS_NAMES = {STICK: "stick", SLIP_OUT: "slip out", SLIP_IN: "slip in", BACKSTOP: "backstop"}

__all__ = ["CableLatchFamily", "cable_equations", "STATUS_NAMES", "STICK", "SLIP_OUT", "SLIP_IN", "BACKSTOP"]


def _per_element(value, n_el, what, name):
    a = np.asarray(value, dtype=float)
    try:
        a = np.broadcast_to(a, (n_el,)).astype(float).copy()
    except ValueError:
        raise ModelError(
            f"{name}: {what} must be a scalar or one value per element ({n_el}), got shape {a.shape}"
        ) from None
    return a


def _hysteresis(hysteresis_force, hysteresis_length, latch, has, name):
    """(n_el, 2) [force (N, 0 without a latch), length (m)] of the latch hysteresis option, checked."""
    n_el = latch.shape[0]
    Fh = _per_element(hysteresis_force, n_el, "hysteresis_force (N)", name)
    ell = _per_element(hysteresis_length, n_el, "hysteresis_length (m)", name)
    bad = np.flatnonzero(~(np.isfinite(Fh) & (Fh >= 0.0)))
    if bad.size:
        raise ModelError(
            f"{name} element {bad[0]}: hysteresis_force = {Fh[bad[0]]!r} N must be finite and >= 0 "
            "(0 switches the latch hysteresis off)"
        )
    bad = np.flatnonzero(~(np.isfinite(ell) & (ell > 0.0)))
    if bad.size:
        raise ModelError(f"{name} element {bad[0]}: hysteresis_length = {ell[bad[0]]!r} m must be finite and > 0")
    xct = np.sqrt(np.clip((latch[:, 0] + latch[:, 5]) ** 2 - (latch[:, 4] + latch[:, 0]) ** 2, 0.0, None))
    bad = np.flatnonzero(has & (Fh > 0.0) & (latch[:, 1] >= xct))
    if bad.size:
        raise ModelError(
            f"{name} element {bad[0]}: the latch hysteresis option needs the backstop inside the "
            f"roller contact zone (x_backstop < x_contact = {xct[bad[0]]:.6g} m)"
        )
    return np.ascontiguousarray(np.column_stack([np.where(has, Fh, 0.0), ell]))


def _kinetic(mu_k, latch, has, name):
    """(n_el,) kinetic roller friction of the latches, checked 0 <= mu_k <= mu (the static ``latch`` mu);
    None: equal to the static one (the paper's one coefficient)."""
    n_el = latch.shape[0]
    if mu_k is None:
        return latch[:, 3].copy()
    mk = _per_element(mu_k, n_el, "mu_k", name)
    bad = np.flatnonzero(has & ~(np.isfinite(mk) & (mk >= 0.0) & (mk <= latch[:, 3])))
    if bad.size:
        el = bad[0]
        raise ModelError(
            f"{name} element {el}: kinetic latch friction mu_k = {float(mk[el])!r} must lie in [0, mu_s = "
            f"{float(latch[el, 3])!r}] (the latch's mu is the static coefficient: a bead starts at mu_s and slides at mu_k)"
        )
    return np.where(has, mk, latch[:, 3])


class CableLatchFamily(ElementFamily):
    """A batch of cable/pulley/latch elements (Stohlman & Pellegrino, Eqs. 2-5 and 14), all with n sections.

    Parameters
    ----------
    nodes : (n_el, n+1) int, node indices in cable order (anchor, pulleys/latch, anchor).
    EA : axial rigidity of the cable, N (scalar or per element).
    L0 : total unstretched length of the cable, m (Eq. 4).
    latch_node : local index j (1 <= j <= n-1) of the node carrying the latch, or None
        (every interior node is then a frictionless pulley and the element is a cable
        over pulleys).  Scalar or per element (0 = no latch).
    bead : material coordinate Lb of the bead, m (unstretched length from node 0), Eq. 5.
    latch : :class:`~femast.elements.latch_law.LatchParameters` (or (n_el, 6) array, SI); default the paper's fit.
    x0 : initial bead position, m (default ``-x_backstop``: latched, against the backstop).
    max_strain : largest cable strain accepted in a committed configuration; beyond it the
        total unstretched length is reported as too short (default 0.1).
    hysteresis_force, hysteresis_length : the *latch hysteresis* option (N, m; scalar or per
        element; default 0: off, the paper's law).  Near the latched state the static band
        widens to ``[dT_in - H, dT_out + H]`` and a sliding bead follows the widened branches,
        ``H = hysteresis_force * w(x)``, ``w = 1`` on the backstop fading to 0 at the roller axis
        over ``hysteresis_length`` (see :func:`femast.elements.latch_law.hysteresis_force`).
    mu_k : kinetic friction between rollers and bead (scalar or per element; default None: the
        latch's ``mu``, the paper's one coefficient).  With ``mu_k < mu`` the latch's ``mu`` is the
        static coefficient: a bead at rest starts to slide when the jump leaves the band of Eq. 14
        at ``mu``, slides on along Eq. 14 at ``mu_k``, and grips again when it stops or reverses.
    length_error : lack of fit per section, m, shape (n_el, n) or (n,) (default 0): the cable
        that runs in section i is ``length_error[:, i]`` longer than its nominal unstretched length
        (a lack of fit).  Their sum lengthens the cable (L0); those of the sections before the latch
        node move the bead along the cable (Lb).  A pretensioned cable over frictionless pulleys
        with a section too short by d then gains ``EA d / L0`` of tension (on rigid anchors).
    name : label used in messages and results.

    Thermal strain: ``length_factor`` (n_el,), set by the analysis from the temperatures of a
    step (:mod:`femast.model.thermal`, ``model.thermal_expansion(alpha, family=name)``), scales all
    unstretched lengths of an element, bead coordinate included: the kernels see
    ``L0 s`` and ``Lb s`` with ``s = 1 + alpha (T - T_init)``, so a free cable grows by
    ``alpha dT`` with no force.  (The strain is then measured on the heated length, ``T = EA (L -
    L0 s) / (L0 s)``, unlike the trusses' ``EA (l - L0 s) / L0``: the two differ by a factor
    ``s`` on EA, below 1e-3 for any real temperature change.)
    """

    active_dofs = (0, 1, 2)
    symmetric = False

    def __init__(
        self,
        nodes,
        EA,
        L0,
        *,
        latch_node=None,
        bead=None,
        latch=None,
        x0=None,
        max_strain: float = 0.1,
        hysteresis_force=0.0,
        hysteresis_length=3e-4,
        length_error=None,
        name: str = "cable_latch",
        mu_k=None,
    ):
        self.name = name
        self.nodes = chain_nodes(nodes, name)
        n_el, nn = self.nodes.shape
        self.n_sections = nn - 1
        self.n_state = self.n_sections + 2
        self.EA = _per_element(EA, n_el, "EA (N)", name)
        self.L0 = _per_element(L0, n_el, "L0 (m)", name)
        for what, arr, unit in (("EA", self.EA, "N"), ("L0", self.L0, "m")):
            bad = np.flatnonzero(~(np.isfinite(arr) & (arr > 0.0)))
            if bad.size:
                raise ModelError(f"{name} element {bad[0]}: {what} = {arr[bad[0]]!r} {unit} must be finite and > 0")
        if latch_node is None:
            latch_node = 0
        jl = np.broadcast_to(np.asarray(latch_node), (n_el,)).astype(np.int64).copy()
        bad = np.flatnonzero((jl != 0) & ((jl < 1) | (jl > self.n_sections - 1)))
        if bad.size:
            raise ModelError(
                f"{name} element {bad[0]}: latch_node = {jl[bad[0]]} must be an interior local node "
                f"1..{self.n_sections - 1} (0 or None for no latch)"
            )
        self.latch_node = jl
        self.latch = np.ascontiguousarray(np.broadcast_to(_as_param_array(latch), (n_el, 6)), dtype=float).copy()
        has = jl > 0
        for el in np.flatnonzero(has):
            validate_latch_array(self.latch[el], f"{name} element {el}")
        if bead is None:
            if np.any(has):
                raise ModelError(f"{name}: give bead= (material coordinate of the bead from node 0, m)")
            bead = 0.0
        self.bead = _per_element(bead, n_el, "bead (m)", name)
        bad = np.flatnonzero(has & ~((self.bead > 0.0) & (self.bead < self.L0)))
        if bad.size:
            el = bad[0]
            raise ModelError(
                f"{name} element {el}: bead Lb = {self.bead[el]!r} m must lie on the cable, 0 < Lb < L0 = {self.L0[el]!r} m"
            )
        if x0 is None:
            x0 = np.where(has, -self.latch[:, 1], 0.0)
        self.x0 = _per_element(x0, n_el, "x0 (m)", name)
        bad = np.flatnonzero(has & (self.x0 < -self.latch[:, 1] * (1.0 + 1e-12)))
        if bad.size:
            el = bad[0]
            raise ModelError(
                f"{name} element {el}: initial bead position x0 = {self.x0[el]!r} m is behind the backstop "
                f"(x >= -x_backstop = {-self.latch[el, 1]!r} m)"
            )
        s0 = self.bead - self.x0
        bad = np.flatnonzero(has & ~((s0 > 0.0) & (s0 < self.L0)))
        if bad.size:
            el = bad[0]
            raise ModelError(
                f"{name} element {el}: bead at x0 = {self.x0[el]!r} m puts {s0[el]!r} m of cable before the latch, "
                f"outside (0, L0 = {self.L0[el]!r}) m; check bead and x0"
            )
        if not max_strain > 0:
            raise ModelError(f"{name}: max_strain = {max_strain!r} must be > 0")
        self.max_strain = float(max_strain)
        self.hysteresis = _hysteresis(hysteresis_force, hysteresis_length, self.latch, has, name)
        self.mu_k = _kinetic(mu_k, self.latch, has, name)
        self.length_factor = np.ones(n_el)
        self.set_length_errors(np.zeros((n_el, self.n_sections)) if length_error is None else length_error)

    def set_length_errors(self, length_error) -> None:
        """Lack of fit per section, m ((n_el, n) or (n,); see the class docstring).  Replaces any
        given before; raises :class:`ModelError` naming the element whose cable it would make
        impossible (a non-positive length, or the bead off the cable)."""
        n_el, n = self.nodes.shape[0], self.n_sections
        try:
            dL = np.broadcast_to(np.asarray(length_error, dtype=float), (n_el, n)).copy()
        except (TypeError, ValueError):
            raise ModelError(
                f"{self.name}: length_error must be one value per section, shape ({n_el}, {n}) or "
                f"({n},), in m; got {np.shape(length_error)}"
            ) from None
        bad = np.argwhere(~np.isfinite(dL))
        if bad.size:
            el, i = bad[0]
            raise ModelError(
                f"{self.name} element {el}: length_error of section {i} = {float(dL[el, i])!r} m is not finite"
            )
        before = np.where(np.arange(n)[None, :] < self.latch_node[:, None], dL, 0.0).sum(axis=1)
        L0e = self.L0 + dL.sum(axis=1)
        Lbe = self.bead + before
        has = self.latch_node > 0
        bad = np.flatnonzero(~(L0e > 0.0) | (has & ~((Lbe - self.x0 > 0.0) & (Lbe - self.x0 < L0e))))
        if bad.size:
            el = bad[0]
            raise ModelError(
                f"{self.name} element {el}: length errors {dL[el].tolist()} m leave the cable "
                f"L0 = {L0e[el]:.6g} m with {Lbe[el] - self.x0[el]:.6g} m before the latch: not a cable "
                "(the errors must be small against the section lengths)"
            )
        self.length_error = dL
        self._misfit = (dL.sum(axis=1), before) if np.any(dL) else None

    def effective_lengths(self):
        """(L0, Lb) the kernels use, m: nominal + length errors, times the length factor."""
        L0, Lb = self.L0, self.bead
        misfit = getattr(self, "_misfit", None)
        if misfit is not None:
            L0, Lb = L0 + misfit[0], Lb + misfit[1]
        lf = getattr(self, "length_factor", None)
        if lf is not None and np.any(lf != 1.0):
            return L0 * lf, Lb * lf
        return L0, Lb

    # ------------------------------------------------------------------ construction helpers
    @classmethod
    def pretensioned(cls, nodes, X, EA, T0, *, latch_node=None, latch=None, x0=None, **kw):
        """Elements whose unstretched length gives tension T0 (N) in geometry X.

        X : (n_nodes, 3) nodal coordinates, m.  With a latch, the bead is placed at x0
        (default against the backstop) and both sides carry T0 (dT = 0 is inside the
        static band there).  Returns a :class:`CableLatchFamily`."""
        nodes = np.atleast_2d(np.asarray(nodes, dtype=np.int64))
        X = np.asarray(X, dtype=float)
        n_el, nn = nodes.shape
        Lsec = np.linalg.norm(np.diff(X[nodes], axis=1), axis=2)
        EA_ = np.broadcast_to(np.asarray(EA, float), (n_el,))
        T0_ = np.broadcast_to(np.asarray(T0, float), (n_el,))
        if np.any(T0_ < 0):
            raise ModelError("pretensioned: T0 must be >= 0 N (a cable cannot carry compression)")
        stretch = 1.0 + T0_ / EA_
        L0 = Lsec.sum(axis=1) / stretch
        if latch_node is None:
            return cls(nodes, EA, L0, latch=latch, **kw)
        jl = np.broadcast_to(np.asarray(latch_node), (n_el,)).astype(int)
        LA = np.array([Lsec[e, : jl[e]].sum() for e in range(n_el)])
        p = np.broadcast_to(_as_param_array(latch), (n_el, 6))
        x0_ = -p[:, 1] if x0 is None else np.broadcast_to(np.asarray(x0, float), (n_el,))
        bead = LA / stretch + x0_
        return cls(nodes, EA, L0, latch_node=latch_node, bead=bead, latch=latch, x0=x0_, **kw)

    # ------------------------------------------------------------------ contract
    def initial_state(self) -> np.ndarray:
        """[x0, status 0 (stick), L0_i] with L0 shared equally among the sections of each side
        of the latch (a placeholder: the first evaluation replaces it from the geometry)."""
        n = self.n_sections
        j = self.latch_node[:, None]
        L0, Lb = self.effective_lengths()
        s = np.where(self.latch_node > 0, Lb - self.x0, 0.0)[:, None]
        cols = np.arange(n)[None, :]
        with np.errstate(divide="ignore", invalid="ignore"):
            L0i = np.where(cols < j, s / j, (L0[:, None] - s) / (n - j))
        st = np.zeros((self.n_elements, self.n_state))
        st[:, 0] = self.x0
        st[:, 2:] = L0i
        return st

    def _check_configuration(self, X, L0=None, bead=None):
        """Raise ModelError if a (committed) configuration needs more than max_strain."""
        L0 = self.L0 if L0 is None else L0
        bead = self.bead if bead is None else bead
        Lsec = np.linalg.norm(np.diff(X, axis=1), axis=2)
        j = self.latch_node
        cols = np.arange(self.n_sections)[None, :]
        LA = np.where(cols < j[:, None], Lsec, 0.0).sum(axis=1)
        LB = Lsec.sum(axis=1) - LA
        # least strain over all bead positions the backstop allows (latch forces neglected)
        s_free = L0 * LA / (LA + LB)
        s = np.clip(np.minimum(s_free, bead + self.latch[:, 1]), 1e-12 * L0, (1 - 1e-12) * L0)
        with np.errstate(divide="ignore", invalid="ignore"):
            eps_latch = np.maximum(LA / s - 1.0, LB / (L0 - s) - 1.0)
        eps = np.where(j > 0, eps_latch, (LA + LB) / L0 - 1.0)
        bad = np.flatnonzero(~(eps <= self.max_strain))
        if bad.size:
            el = bad[0]
            raise ModelError(
                f"{self.name} element {el}: total unstretched length L0 = {L0[el]:.6g} m is too short for "
                f"any equilibrium within max_strain = {self.max_strain:g}: the anchors are "
                f"{LA[el] + LB[el]:.6g} m of cable apart and the cable would need a strain of {eps[el]:.3g}. "
                "Check the units of L0 and the node coordinates, or give the pretension instead "
                "(CableLatchFamily.pretensioned)."
            )

    def evaluate(self, x, R, state, ctx: IncrementContext | None = None) -> ElementResponse:
        """Forces, tangent and trial state of all elements (see module docstring).

        x : (n_nodes, 3) nodal positions, m.  R : ignored (no rotational DOFs).
        state : (n_el, n+2) committed state, not modified.
        ctx : the increment; ``ctx.x_committed`` (if given) is checked for an unstretched
            length too short for any equilibrium.
        Returns :class:`ElementResponse` with f (N), k (N/m), state, output and energy (J).
        """
        x = np.asarray(x, dtype=float)
        X = np.ascontiguousarray(x[self.nodes])
        # the committed configuration is that of the whole increment: check it once per increment, not
        # every iteration (10 % of a bay run).  The analysis passes the same x_committed array to every
        # iteration of an increment (kept referenced here, so it cannot be another array at the same
        # address); a new one is compared by value with what the last check read
        L0, Lb = self.effective_lengths()
        src = None if ctx is None else ctx.x_committed
        if src is None or src is not getattr(self, "_checked_src", None):
            Xc = X if src is None else np.asarray(src, float)[self.nodes]
            key = (Xc, L0, Lb, self.latch, self.latch_node, self.max_strain)
            last = getattr(self, "_checked", None)
            if last is None or not all(np.array_equal(a, b) for a, b in zip(last, key)):
                self._check_configuration(Xc, L0, Lb)
                self._checked = tuple(np.array(a, copy=True) for a in key)
            self._checked_src = src
        state = np.asarray(state, dtype=float)
        n_el, nn = self.nodes.shape
        n = self.n_sections
        f = np.empty((n_el, 6 * nn))
        k = np.empty((n_el, 6 * nn, 6 * nn))
        new = np.empty((n_el, self.n_state))
        T = np.zeros((n_el, n))
        dT = np.zeros(n_el)
        energy = np.zeros(n_el)
        err = np.zeros(n_el, dtype=np.int64)
        hy = getattr(self, "hysteresis", None)
        if hy is None:  # families pickled or built before the option existed
            hy = np.zeros((n_el, 2))
            hy[:, 1] = 1.0
        cable_latch_kernel(
            X,
            self.EA,
            L0,
            Lb,
            self.latch_node,
            self.latch,
            getattr(self, "mu_k", self.latch[:, 3]),  # (families pickled before the option: one coefficient)
            hy,
            np.ascontiguousarray(state),
            f,
            k,
            new,
            T,
            dT,
            energy,
            err,
        )
        bad = np.flatnonzero(err)
        if bad.size:
            el = bad[0]
            code = err[el]
            if code == ERR_ZERO_LENGTH:
                Ls = np.linalg.norm(np.diff(X[el], axis=0), axis=1)
                i = int(np.flatnonzero(Ls <= 0.0)[0])
                msg = (
                    f"section {i} between nodes {self.nodes[el, i]} and {self.nodes[el, i + 1]} has zero "
                    "length; anchors and pulleys must not coincide"
                )
            elif code == ERR_NOT_FINITE:
                msg = "nodal coordinates are not finite"
            elif code == ERR_BEAD_OFF_CABLE:
                msg = (
                    f"committed bead position x = {state[el, 0]!r} m puts the bead off the cable "
                    f"(Lb - x must lie in (0, L0 = {L0[el]!r}) m)"
                )
            else:  # pragma: no cover
                msg = f"kernel error {code}"
            raise ModelError(f"{self.name} element {el}: {msg}")
        return ElementResponse(
            f=f, k=k, state=new, output=LazyOutput(lambda: self._output(X, T, dT, new)), energy=energy
        )

    def _output(self, X, T, dT, new):
        """The output dict of :meth:`evaluate` (computed when first read)."""
        L0sec = new[:, 2:]
        Lsec = np.linalg.norm(np.diff(X, axis=1), axis=2)
        has = self.latch_node > 0
        zone = np.where(has, latch_zone(new[:, 0], self.latch), -1)
        return {
            "tension": T,
            "unstretched_length": L0sec.copy(),
            "strain": np.where(T > 0.0, Lsec / L0sec - 1.0, 0.0),
            "bead_position": np.where(has, new[:, 0], np.nan),
            "latch_status": new[:, 1].copy(),
            "latch_zone": zone,
            "latch_dT": dT,
        }


__all__ += ["LatchParameters"]
