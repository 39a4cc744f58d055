"""Tension-only Dyneema shroud cable: two nodes, the tension-dependent rope law of the Rocaspect paper (Eq. 25).

One element is a straight rope between two end points.  Each end point may sit on a
*rigid offset* from its node (a lever rigidly attached to the node, as the paper's
shroud attachment points C_ir are rigidly attached to the mast top C_i3):

    p_a = x_a + R_a o_a                      (o_a: offset in the initial configuration, m)

with R_a the node's total rotation.  Without offsets the element is a plain cable with
translational DOFs only.

Axial law (the Rocaspect paper, Eqs. 25, 27, as corrected in :mod:`femast.elements.shroud_law`).  The strain is
measured from the unstretched length L0, ``eps = l / L0 - 1``, and the tension is the root of
``tau = g(tau) eps`` with ``g = k0 + k1 tau + k2 tau^2`` (k0 in N, k1 dimensionless, k2 in 1/N):

    tau(eps) = 2 k0 eps / ((1 - k1 eps) + sqrt((1 - k1 eps)^2 - 4 k0 k2 eps^2))   (eps >= 0)
    tau = 0                                                                       (eps < 0, slack)

and the material tangent ``d tau / d l = EA_t(tau) / L0`` with ``EA_t = g^2 / (k0 - k2 tau^2)``
(:func:`femast.elements.shroud_law.axial_rigidity_tangent`).  At exactly ``eps = 0`` the rope counts as
taut (tangent ``k0 / L0``, the one-sided derivative from the taut side): a shroud installed
exactly taut with zero pretension then has the paper's passive stiffness at tau = 0.

Forces and consistent tangent (q = [x_a, w_a, x_b, w_b], w spatial spins; e the unit vector from
p_a to p_b; r = R o the current arms; ``G = [I, -[r]x]`` maps a node increment to its end
point's increment; ``D = [-G_a, G_b]`` (3 x 12) maps q to ``d(p_b - p_a)``):

    f = tau D^T e                                   (f_a = -tau [e ; r_a x e], f_b = +tau [e ; r_b x e])
    K = (d tau / d l) D^T e e^T D                   material ("passive") part
      + tau / l D^T (I - e e^T) D                   geometric part of the rope turning
      + tau ([e]x [r_b]x on (w_b, w_b)  -  [e]x [r_a]x on (w_a, w_a))   arms turning with the nodes

The first term is the FE counterpart of the paper's passive stiffness K_p (Eq. 24), the last two
of the active stiffness K_a (Eq. 26): for a shroud from the mast top (node a, arm e_r) to a
ground anchor (node b, fixed) the (a, a) block of K is exactly ``K_p + K_a`` of
:mod:`femast.guyed.complete_mast`.  ``tangent_parts`` selects the parts assembled
("full", "material", "geometric" or "none"); anything but "full" is for decomposing the
tangent of a converged state, not for solving.  K is symmetric without offsets; with offsets
the arm term is not (``[e]x[r]x`` is symmetric only for r parallel to e).

Construction: :class:`ShroudCableFamily` takes the unstretched lengths; :func:`add_shrouds`
adds shrouds to a :class:`~femast.model.Model` given either the unstretched length or the
tension that each carries in the model's initial geometry.

Sources of error (as the cable families of :mod:`femast.model.thermal`): a *length error*
dL per rope (lack of fit, m; ``length_error=``, :meth:`ShroudCableFamily.set_length_errors`) makes it
stress free at ``L0 + dL``; a thermal strain scales that by the ``length_factor``
``s = 1 + alpha (T - T_init)`` the analysis writes from a step's temperatures
(``model.thermal_expansion(alpha, family=name)``, ``step.temperature(T, family=name)``).  The law
then sees the strain from the stress-free length ``L_f = (L0 + dL) s``: ``eps = l / L_f - 1``, the
strain of the tensile test (Eq. 27) on the rope as it is.  (Measured on L0 as the trusses do, the
strain would differ by a factor ~ s on EA, below 1e-3 for any real error or temperature change.)
"""

from __future__ import annotations

import numpy as np

from ..errors import ModelError
from ._shroud_kernels import _GW, _GX, ERR_BEYOND_LAW, ERR_ZERO_LENGTH, dyneema_tension, shroud_family_kernel  # noqa: F401
from .base import ElementFamily, ElementResponse
from .shroud_hysteresis import hysteresis_array
from .shroud_law import DyneemaLaw, strain_from_tension

PARTS = {"none": 0, "material": 1, "geometric": 2, "full": 3}


def _law_array(law, n_el, name):
    """(n_el, 3) array [k0, k1, k2] from a DyneemaLaw, a sequence of them, or an array."""

    if law is None:
        law = DyneemaLaw()
    if isinstance(law, DyneemaLaw):
        arr = np.array([[law.k0, law.k1, law.k2]])
    elif isinstance(law, (list, tuple)) and law and all(isinstance(v, DyneemaLaw) for v in law):
        arr = np.array([[v.k0, v.k1, v.k2] for v in law])
    else:
        arr = np.asarray(law, dtype=float)
        if arr.ndim == 1:
            arr = arr[None, :]
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise ModelError(
            f"{name}: the rope law must be a DyneemaLaw or [k0 (N), k1 (-), k2 (1/N)] per element; "
            f"got shape {arr.shape}"
        )
    try:
        arr = np.ascontiguousarray(np.broadcast_to(arr, (n_el, 3)), dtype=float).copy()
    except ValueError:
        raise ModelError(f"{name}: give one rope law or one per element ({n_el}); got {arr.shape[0]}") from None
    bad = np.flatnonzero(~np.all(np.isfinite(arr), axis=1) | ~(arr[:, 0] > 0.0))
    if bad.size:
        raise ModelError(
            f"{name} element {bad[0]}: rope law [k0, k1, k2] = {arr[bad[0]].tolist()} needs a finite, "
            "positive k0 (axial rigidity at zero tension, N) and finite k1 (-), k2 (1/N); "
            "give the physical stiffness (the paper's is k0 = 935353.664 N)"
        )
    return arr


def _per_element(value, n_el, name, what):
    try:
        return np.ascontiguousarray(np.broadcast_to(np.asarray(value, dtype=float), (n_el,)), dtype=float).copy()
    except (ValueError, TypeError):
        raise ModelError(f"{name}: {what} must be a scalar or one value per element ({n_el}); got {value!r}") from None


class ShroudCableFamily(ElementFamily):
    """A batch of tension-only Dyneema ropes (the Rocaspect paper, Eq. 25), optionally on rigid end offsets.

    Parameters
    ----------
    nodes : (n_el, 2) int, end nodes (labels when added with ``Model.add_family``).
    L0 : unstretched lengths, m (> 0), scalar or per element.
    law : :class:`~femast.elements.shroud_law.DyneemaLaw` (default: the paper's coefficients), a list of
        them, or an (n_el, 3) array ``[k0 (N), k1 (-), k2 (1/N)]``; k0 must be > 0.
    offsets : optional (n_el, 2, 3) rigid offsets of the end points from nodes a and b in the
        initial configuration, m (global axes).  With any nonzero offset the family also acts on
        the rotations of its nodes: every node of the family then needs rotational support
        (a beam, a fix) -- keep offset-free ropes on translational-only nodes in another family.
    length_error : lack of fit per rope, m (scalar or per element; default 0): the rope is stress free
        at ``L0 + length_error`` (negative: cut short, so it pulls harder).
    hysteresis : the loading/unloading option (Rocaspect paper Fig. 4a, :mod:`.shroud_hysteresis`):
        the half-width eta (-, 0 <= eta < 1, scalar or per rope) of the loop between the loading
        branch ``(1 + eta) tau(eps)`` and the unloading branch ``(1 - eta) tau(eps)`` about the law;
        0 (default): the paper's single curve.
    stick_rigidity : N, the friction element's stick rigidity k_s (default 10 k0 of each rope).
    name : label used in messages and results.

    Thermal strain: ``length_factor`` (n_el,), written by the analysis from the temperatures of a
    step (:mod:`femast.model.thermal`), scales the stress-free lengths (module docstring).

    Output per element: ``tension`` (N), ``strain`` (from the stress-free length ``(L0 + dL) s``),
    ``length`` (m, between the end points), ``slack`` (1.0 when the rope carries nothing).
    """

    def __init__(
        self,
        nodes,
        L0,
        law=None,
        offsets=None,
        labels=None,
        name: str = "shroud",
        length_error=None,
        hysteresis=0.0,
        stick_rigidity=None,
    ):
        self.name = name
        nodes = np.asarray(nodes)
        if nodes.ndim == 1:
            nodes = nodes[None, :]
        if nodes.ndim != 2 or nodes.shape[1] != 2 or not np.issubdtype(nodes.dtype, np.integer):
            raise ModelError(f"{name}: nodes must be an (n_el, 2) integer array; got shape {nodes.shape}")
        self.nodes = np.ascontiguousarray(nodes, dtype=np.int64)
        n_el = self.nodes.shape[0]
        self.L0 = _per_element(L0, n_el, name, "L0 (m)")
        bad = np.flatnonzero(~(np.isfinite(self.L0) & (self.L0 > 0.0)))
        if bad.size:
            raise ModelError(
                f"{name} element {bad[0]}: unstretched length L0 = {self.L0[bad[0]]!r} m must be finite and > 0"
            )
        self.law = _law_array(law, n_el, name)
        if offsets is None:
            off = np.zeros((n_el, 2, 3))
        else:
            try:
                off = np.broadcast_to(np.asarray(offsets, dtype=float), (n_el, 2, 3)).copy()
            except ValueError:
                raise ModelError(
                    f"{name}: offsets must have shape (n_el, 2, 3) in m; got {np.shape(offsets)}"
                ) from None
            if not np.all(np.isfinite(off)):
                raise ModelError(f"{name}: offsets must be finite, in m")
        self.offsets = np.ascontiguousarray(off)
        has_off = bool(np.any(off != 0.0))
        self.active_dofs = (0, 1, 2, 3, 4, 5) if has_off else (0, 1, 2)
        self.symmetric = not has_off
        self.labels = np.arange(1, n_el + 1) if labels is None else np.asarray(labels)
        self.tangent_parts = "full"
        self.length_factor = np.ones(n_el)
        self.set_length_errors(0.0 if length_error is None else length_error)
        self.hysteresis = hysteresis_array(hysteresis, stick_rigidity, self.law, n_el, name)
        # with the loading/unloading option the rope has a state [strain, friction tension (N)]
        self.n_state = 2 if np.any(self.hysteresis[:, 0] > 0.0) else 0
        self.path_independent = self.n_state == 0

    def set_length_errors(self, length_error) -> None:
        """Lack of fit per rope, m (scalar or one per element; replaces any given before): rope e is stress
        free at ``L0[e] + length_error[e]``.  Raises :class:`ModelError` naming the rope for a wrong shape,
        a non-finite value or a stress-free length that is not positive."""
        n_el = self.nodes.shape[0]
        try:
            dL = np.asarray(length_error, dtype=float)
        except (TypeError, ValueError):
            raise ModelError(
                f"{self.name}: length_error must be numbers in m (one or one per rope); got {length_error!r}"
            ) from None
        if dL.ndim > 1 or (dL.ndim == 1 and dL.size != n_el):
            raise ModelError(
                f"{self.name}: length_error must be a scalar or one value per rope, shape ({n_el},), "
                f"in m; got shape {dL.shape}"
            )
        dL = np.ascontiguousarray(np.broadcast_to(dL, (n_el,)), dtype=float).copy()
        for el in np.flatnonzero(~np.isfinite(dL) | ~(self.L0 + dL > 0.0)):
            label = self.labels[el]
            if not np.isfinite(dL[el]):
                raise ModelError(f"{self.name} element {label}: length_error = {float(dL[el])!r} m is not finite")
            raise ModelError(
                f"{self.name} element {label}: length_error = {float(dL[el])!r} m leaves the rope a stress-free "
                f"length {self.L0[el] + dL[el]:.6g} m (L0 = {self.L0[el]:.6g} m); it must stay > 0 "
                "(give the error in m)"
            )
        self.length_error = dL

    def stress_free_lengths(self) -> np.ndarray:
        """(n_el,) stress-free lengths the law sees, m: ``(L0 + length_error) * length_factor``."""
        L = self.L0 + self.length_error if np.any(self.length_error) else self.L0
        lf = self.length_factor
        return L * lf if np.any(lf != 1.0) else L

    def end_points(self, x, R) -> np.ndarray:
        """(n_el, 2, 3) current end points p = x + R o, m (x, R for all model nodes)."""
        x = np.asarray(x, dtype=float)
        R = np.asarray(R, dtype=float)
        return x[self.nodes] + np.einsum("enij,enj->eni", R[self.nodes], self.offsets)

    def evaluate(self, x, R, state, ctx=None) -> ElementResponse:
        if self.tangent_parts not in PARTS:
            raise ModelError(f"{self.name}: tangent_parts = {self.tangent_parts!r}; use one of {', '.join(PARTS)}")
        n = self.n_elements
        x = np.ascontiguousarray(x, dtype=float)
        R = np.ascontiguousarray(R, dtype=float) if R is not None else np.tile(np.eye(3), (x.shape[0], 1, 1))
        f = np.zeros((n, 12))
        K = np.zeros((n, 12, 12))
        tau = np.zeros(n)
        eps = np.zeros(n)
        length = np.zeros(n)
        energy = np.zeros(n)
        err = np.zeros(n, dtype=np.int64)
        L0 = np.ascontiguousarray(self.stress_free_lengths())
        # (with the loading/unloading option and no state given: a rope loaded from slack)
        st = np.ascontiguousarray(state, dtype=float) if self.n_state and state is not None else np.zeros((n, 2))
        new = st.copy()
        shroud_family_kernel(
            self.nodes,
            x,
            R,
            self.offsets,
            L0,
            self.law,
            self.hysteresis,
            st,
            PARTS[self.tangent_parts],
            _GX,
            _GW,
            f,
            K,
            new,
            tau,
            eps,
            length,
            energy,
            err,
        )
        bad = np.flatnonzero(err)
        if bad.size:
            el = int(bad[0])
            code = int(err[el])
            p = self.end_points(x, R)[el]
            if code == ERR_ZERO_LENGTH:
                msg = (
                    f"its two end points coincide at {np.round(p[0], 6).tolist()} m (nodes "
                    f"{self.nodes[el, 0]} and {self.nodes[el, 1]} plus offsets); a rope needs two distinct "
                    "attachment points"
                )
            elif code == ERR_BEYOND_LAW:
                l = float(np.linalg.norm(p[1] - p[0]))
                msg = (
                    f"strain {l / L0[el] - 1.0:.4g} is beyond the range of the rope law "
                    f"{self.law[el].tolist()} (no finite increasing tension there); check L0 = {self.L0[el]:.6g} m "
                    f"(stress free at {L0[el]:.6g} m with its length error and thermal strain) and the node "
                    "coordinates (units m)"
                )
            else:
                msg = "nodal coordinates are not finite"
            raise ModelError(f"{self.name} element {self.labels[el]}: {msg}")
        output = {"tension": tau, "strain": eps, "length": length, "slack": (eps < 0.0).astype(float)}
        if self.n_state:
            output["friction_tension"] = new[:, 1].copy()
        return ElementResponse(f=f, k=K, state=new if self.n_state else state, output=output, energy=energy)


def unstretched_length(law, tension, length):
    """Unstretched length L0 (m) at which a rope of the law carries ``tension`` (N) at ``length`` (m):
    ``L0 = length / (1 + eps(tension))`` with eps from :func:`femast.elements.shroud_law.strain_from_tension`."""

    return np.asarray(length, float) / (1.0 + strain_from_tension(law or DyneemaLaw(), tension))


def add_shrouds(
    model,
    pairs,
    law=None,
    tension=None,
    L0=None,
    offsets=None,
    name: str = "shroud",
    length_error=None,
    hysteresis=0.0,
    stick_rigidity=None,
) -> ShroudCableFamily:
    """Add Dyneema shrouds between node-label pairs ``pairs`` ((n, 2)) to ``model``; returns the family.

    Give either ``L0`` (unstretched lengths, m) or ``tension`` (N, >= 0: the tension each rope carries
    in the model's *initial* geometry, including the offsets); neither means taut at zero tension.
    ``offsets`` (n, 2, 3) as in :class:`ShroudCableFamily`.  ``length_error`` (m, scalar or per rope): lack
    of fit added to the unstretched lengths so found (a rope meant to carry ``tension`` but cut
    ``length_error`` too long).  ``hysteresis``, ``stick_rigidity``: the loading/unloading option of
    :class:`ShroudCableFamily` (``tension`` is then the tension of the law itself, the average
    curve: the rope starts with no friction tension).  Raises ModelError for coincident
    attachment points, non-positive lengths or stiffness, and tensions outside the law's range.
    """

    raw = np.atleast_2d(np.asarray(pairs, dtype=object))
    if raw.ndim != 2 or raw.shape[1] != 2:
        raise ModelError(f"{name}: pairs must be (n, 2) node labels; got shape {raw.shape}")
    for k, row in enumerate(raw.tolist()):  # whole labels of the model's nodes (2.7 is not node 2)
        for label in row:
            model._check_node(label, f"{name} {k + 1} (nodes {row[0]!r}-{row[1]!r})")
    pairs = raw.astype(np.int64)
    n = pairs.shape[0]
    laws = _law_array(law, n, name)
    off = np.zeros((n, 2, 3)) if offsets is None else np.broadcast_to(np.asarray(offsets, float), (n, 2, 3))
    p = np.array([[model.xyz(a), model.xyz(b)] for a, b in pairs]) + off
    length = np.linalg.norm(p[:, 1] - p[:, 0], axis=1)
    scale = max(1.0, float(np.abs(p).max()))
    for k in np.flatnonzero(length <= 1e-9 * scale):
        raise ModelError(
            f"{name} {k + 1} (nodes {pairs[k, 0]}-{pairs[k, 1]}): its attachment points coincide at "
            f"{np.round(p[k, 0], 6).tolist()} m; move one of them so the rope has a length"
        )
    if L0 is not None and tension is not None:
        raise ModelError(f"{name}: give the unstretched length L0 or the tension, not both")
    eta = hysteresis_array(hysteresis, stick_rigidity, laws, n, name)[:, 0]
    if tension is not None:
        tau = _per_element(tension, n, name, "tension (N)")
        L0v = np.empty(n)
        for k in range(n):
            lk = DyneemaLaw(*laws[k])
            if not (np.isfinite(tau[k]) and 0.0 <= tau[k] < lk.tau_max_valid):
                raise ModelError(
                    f"{name} {k + 1}: tension {float(tau[k])!r} N must be >= 0 and below "
                    f"{lk.tau_max_valid:.4g} N, where the rope law is increasing"
                )
            # with the loading/unloading option the rope, tensioned by loading, is on its loading branch
            # (1 + eta) tau_e: the law's tension there is tension / (1 + eta)
            L0v[k] = float(unstretched_length(lk, tau[k] / (1.0 + eta[k]), length[k]))
    elif L0 is not None:
        L0v = _per_element(L0, n, name, "L0 (m)")
    else:
        L0v = length.copy()
    fam = ShroudCableFamily(
        pairs,
        L0v,
        laws,
        offsets=None if offsets is None else off,
        name=name,
        length_error=length_error,
        hysteresis=hysteresis,
        stick_rigidity=stick_rigidity,
    )
    return model.add_family(fam)
