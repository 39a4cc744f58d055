"""A cable over an ordered list of devices: pulleys (frictionless), sheaves with bearing friction,
capstan drums, latches, clamps and user devices (Stohlman & Pellegrino, Sec. II.B.2, Eqs. 2-5).

Stohlman & Pellegrino write the cable element for a cable over any number of pulleys, latches or other
devices, each with its own law for the jump ``Delta T_i = T_{i+1} - T_i``.  One element here is
one cable of n sections between n + 1 nodes; ``devices[k]`` sits at interior node k + 1.  The
equations and the stick/slip return mapping are in :mod:`._device_kernels`, the laws (and the
contract a user law follows) in :mod:`._device_laws`, the geometry of sized pulleys in
:mod:`._cable_geometry`; see ``docs/cable_devices.md``.

State per element (``n_state = 2 (n - 1)``): the material coordinates S_k (m, unstretched
length from node 0) of the cable at each device, then each device's mode (0 stick, +1 sliding
with the out side pulling, -1 with the in side pulling, 2 at a stop, 3 frictionless).

:class:`femast.elements.cable_latch.CableLatchFamily` (frictionless point pulleys and one latch)
is unchanged; this family reproduces it (tests) and generalises it.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..errors import ElementConvergenceError, ModelError
from ._cable_geometry import (
    GEO_ADJACENT_PULLEYS,
    GEO_INSIDE_PULLEY,
    GEO_NOT_FINITE,
    GEO_OK,
    GEO_PLANE_UNDEFINED,
    GEO_ZERO_LENGTH,
    cable_geometry,
)
from ._device_kernels import ERR_ACTIVE_SET, ERR_SHORT, SLIDE_FREE, STOP, device_kernel
from ._device_laws import FREE, LATCH, LATCH_LB, N_PARAM, USER, builtin_law
from ._device_user_kernels import kernel_for_law
from .base import ElementFamily, ElementResponse, IncrementContext, LazyOutput, chain_nodes
from .cable_device_specs import (  # noqa: F401  (the devices are imported from here)
    Clamp,
    Drum,
    Latch,
    Pulley,
    Sheave,
    UserDevice,
    geometry_radius,
    kind_and_params,
    set_device_values,
)

MODE_NAMES = {0: "stick", 1: "slide (out side pulls)", -1: "slide (in side pulls)", 2: "at stop", 3: "frictionless"}

__all__ = [
    "Pulley",
    "Sheave",
    "Drum",
    "Latch",
    "Clamp",
    "UserDevice",
    "CableDeviceFamily",
    "MODE_NAMES",
    "wrap_geometry",
]


_COMBINED = {}


def _combined_law(user):
    """The built-in laws plus one user law, as one numba function (compiled on first use)."""
    if user not in _COMBINED:

        @njit
        def law(kind, sigma, T_in, T_out, s, phi, p, static):
            if kind == USER:
                r, a, b, c, d = user(sigma, T_in, T_out, s, phi, p)
                return float(r), float(a), float(b), float(c), float(d)
            return builtin_law(kind, sigma, T_in, T_out, s, phi, p, static)

        _COMBINED[user] = law
    return _COMBINED[user]


def _geometry(X, radius):
    """Section lengths (n,) and wrap angles (n-1,) of one cable, with the geometry error code."""
    nn = X.shape[0]
    n = nn - 1
    L = np.zeros(n)
    G = np.zeros((n, 3 * nn))
    H = np.zeros((1, 1, 1))
    phi = np.zeros(max(n - 1, 1))
    dphi = np.zeros((max(n - 1, 1), 3 * nn))
    code, where = cable_geometry(np.ascontiguousarray(X, dtype=float), radius, False, L, G, H, phi, dphi)
    return code, where, L, phi[: n - 1], G, dphi[: n - 1]


def wrap_geometry(X, radius):
    """Section lengths L (n,) in m, wrap angles phi (n-1,) in rad, and their gradients for one cable
    with nodes X (n+1, 3) in m and pulley radii ``radius`` (n+1,) in m (0 at point devices and the
    ends).  Raises :class:`ModelError` for an impossible geometry (a neighbour inside a pulley, ...)."""
    X = np.asarray(X, dtype=float)
    radius = np.ascontiguousarray(radius, dtype=float)
    code, where, L, phi, G, dphi = _geometry(X, radius)
    if code != GEO_OK:
        raise ModelError(_geometry_message(code, where, "cable", np.arange(X.shape[0]), radius, X))
    return L, phi, G, dphi


def _geometry_message(code, where, name, nodes, radius, X):
    if code == GEO_ZERO_LENGTH:
        return (
            f"{name}: section {where} between nodes {nodes[where]} and {nodes[where + 1]} has zero length; "
            "anchors and devices must not coincide"
        )
    if code == GEO_NOT_FINITE:
        return f"{name}: node {nodes[where]} has non-finite coordinates"
    if code == GEO_INSIDE_PULLEY:
        k = where
        pk = k + 1 if k + 1 < len(radius) and radius[k + 1] > 0 else k - 1
        d = float(np.linalg.norm(X[k] - X[pk]))
        return (
            f"{name}: node {nodes[k]} is {d:.6g} m from the centre of the pulley at node {nodes[pk]} of radius "
            f"{radius[pk]:.6g} m: no tangent exists (impossible wrap angle). Move the node out of the pulley "
            "or reduce the radius"
        )
    if code == GEO_PLANE_UNDEFINED:
        return (
            f"{name}: the pulley of radius {radius[where]:.6g} m at node {nodes[where]} lies on the straight line "
            f"through its neighbours {nodes[where - 1]} and {nodes[where + 1]}: the wrap plane is undefined. "
            "Offset the pulley from that line or make it a point pulley (radius 0)"
        )
    if code == GEO_ADJACENT_PULLEYS:
        return (
            f"{name}: sections {where} joins two pulleys of finite radius (nodes {nodes[where]} and "
            f"{nodes[where + 1]}); put a point device between them or give one of them radius 0"
        )
    return f"{name}: geometry error {code}"  # pragma: no cover


class CableDeviceFamily(ElementFamily):
    """A batch of cables, each over the same ordered list of devices (module note).

    Parameters
    ----------
    nodes : (n_el, n+1) int, node indices in cable order (anchor, devices, anchor).
    EA : axial rigidity, N (scalar or per element).
    L0 : total unstretched length, m (Eq. 4; scalar or per element).
    devices : list of n-1 devices (:class:`Pulley`, :class:`Latch`, :class:`Clamp`,
        :class:`UserDevice`), one per interior node, in cable order.
    s0 : (n_el, n-1) or (n-1,) initial material coordinates of the cable at the devices, m
        (needed where the cable is gripped: capstans, clamps, user devices; a latch's comes from
        its bead: s = Lb - x0).  Use :meth:`pretensioned` to get them from a geometry.
    device_values : per-element device parameters (scatter per latch or pulley), a dict
        ``{device index: {parameter: value or (n_el,) values}}``; parameters of a Latch: r,
        x_backstop, k, mu, h, R (SI, :class:`~femast.elements.latch_law.LatchParameters`), hysteresis_force,
        hysteresis_length, mu_s, mu_k; of a Drum (capstan Pulley) and of a Sheave with friction: mu,
        mu_s, mu_k (``mu`` sets both).  Each element's values are validated.
    length_error : lack of fit per section, m, (n_el, n) or (n,) (default 0): the cable in section
        i is that much longer than nominal.  The sum lengthens the cable (L0); the errors of the
        sections before a device move the cable's material coordinate there (s0, a bead).
    name : label used in messages and results.

    Thermal strain: ``length_factor`` (n_el,), set by the analysis (:mod:`femast.model.thermal`), scales
    every unstretched length of an element uniformly: the kernel sees ``L0 s``, beads at ``Lb s``
    and material coordinates ``S s`` (the state keeps them unscaled), so a free cable grows by
    ``alpha dT`` with no force; the strain is measured on the heated length (as
    :class:`~femast.elements.cable_latch.CableLatchFamily`).
    """

    active_dofs = (0, 1, 2)
    symmetric = False

    def __init__(
        self, nodes, EA, L0, devices, *, s0=None, device_values=None, length_error=None, name: str = "cable_devices"
    ):
        self.name = name
        self.nodes = chain_nodes(nodes, name)
        n_el, nn = self.nodes.shape
        n = nn - 1
        self.n_sections = n
        devices = list(devices)
        if len(devices) != n - 1:
            raise ModelError(
                f"{name}: {len(devices)} devices given for a cable of {n} sections ({nn} nodes per element); "
                f"give exactly one device per interior node ({n - 1}), in cable order"
            )
        self.devices = tuple(devices)
        self.n_state = 2 * (n - 1)
        self.EA = self._per_element(EA, "EA (N)")
        self.L0 = self._per_element(L0, "L0 (m)")
        for what, arr, unit in (("EA", self.EA, "N"), ("L0", self.L0, "m")):
            bad = np.flatnonzero(~(np.isfinite(arr) & (arr > 0.0)))
            if bad.size:
                raise ModelError(f"{name} element {bad[0]}: {what} = {arr[bad[0]]!r} {unit} must be finite and > 0")
        kinds, radius, P = [], np.zeros(nn), np.zeros((n_el, max(n - 1, 1), N_PARAM))
        users = set()
        for k, dev in enumerate(devices):
            kind, p, r = kind_and_params(dev, k, name)
            kinds.append(kind)
            radius[k + 1] = r
            P[:, k] = p
            if kind == USER:
                users.add(dev.law)
        if len(users) > 1:
            raise ModelError(
                f"{name}: the user devices use {len(users)} different law functions; one family takes "
                "one user law (dispatch on the parameters p inside it)"
            )
        self.kinds = np.array(kinds if kinds else [FREE], dtype=np.int64)[: max(n - 1, 0)]
        self.radius = radius
        self.P = P
        self._law = _combined_law(users.pop()) if users else None
        if device_values:
            set_device_values(self.P, self.kinds, devices, device_values, self.name)
        dL = np.zeros((n_el, n))
        if length_error is not None:
            try:
                dL[:] = np.broadcast_to(np.asarray(length_error, dtype=float), (n_el, n))
            except (TypeError, ValueError):
                raise ModelError(
                    f"{name}: length_error must be one value per section, shape ({n_el}, {n}) or ({n},), "
                    f"in m; got {np.shape(length_error)}"
                ) from None
            bad = np.argwhere(~np.isfinite(dL))
            if bad.size:
                raise ModelError(f"{name} element {bad[0][0]}: length_error of section {bad[0][1]} is not finite")
        self.length_error = dL
        self.L0 = self.L0 + dL.sum(axis=1)
        before = np.cumsum(dL, axis=1)[:, :-1]  # (n_el, n-1): errors before device k
        self.length_factor = np.ones(n_el)
        # initial material coordinates
        S0 = np.full((n_el, n - 1), np.nan)
        if s0 is not None:
            try:
                S0[:] = np.broadcast_to(np.asarray(s0, dtype=float), (n_el, n - 1))
            except ValueError:
                raise ModelError(
                    f"{name}: s0 must have shape (n_el, n-1) = ({n_el}, {n - 1}) or ({n - 1},), in m"
                ) from None
        for k, dev in enumerate(devices):
            if isinstance(dev, Latch):
                x0 = -self.P[:, k, 1] if dev.x0 is None else np.full(n_el, float(dev.x0))
                if dev.bead is None:
                    if s0 is None:
                        raise ModelError(
                            f"{name} device {k} (Latch): give bead= (material coordinate of the bead, m) "
                            "or build with CableDeviceFamily.pretensioned"
                        )
                    S0[:, k] += before[:, k]
                    self.P[:, k, 6] = S0[:, k] + x0
                else:
                    self.P[:, k, 6] = dev.bead + before[:, k]
                    S0[:, k] = self.P[:, k, 6] - x0
                behind = np.flatnonzero(x0 < -self.P[:, k, 1] * (1 + 1e-12))
                if behind.size:
                    el = behind[0]
                    raise ModelError(
                        f"{name} device {k} (Latch), element {el}: x0 = {x0[el]!r} m is behind the "
                        f"backstop (x0 >= -x_backstop = {-self.P[el, k, 1]!r} m)"
                    )
        need = [k for k, kd in enumerate(self.kinds) if kd != FREE]
        for k in need:
            if not isinstance(devices[k], Latch):
                S0[:, k] += before[:, k]
            if np.any(np.isnan(S0[:, k])):
                raise ModelError(
                    f"{name} device {k} ({type(devices[k]).__name__}) grips the cable: give s0 (the "
                    "material coordinate of the cable at the device, m) or build with "
                    "CableDeviceFamily.pretensioned(nodes, X, EA, T0, devices)"
                )
        # frictionless devices: a uniform share (a placeholder, the first evaluation replaces it)
        cols = np.arange(1, n)[None, :]
        S0 = np.where(np.isnan(S0), self.L0[:, None] * cols / n, S0)
        full = np.column_stack([np.zeros(n_el), S0, self.L0])
        bad = np.argwhere(~(np.diff(full, axis=1) > 0.0))
        if bad.size:
            el, i = bad[0]
            raise ModelError(
                f"{name} element {el}: the material coordinates s0 = {S0[el]} m must increase strictly "
                f"from 0 to L0 = {self.L0[el]:.6g} m along the cable (section {i} has none)"
            )
        self.S0 = S0

    def _per_element(self, value, what):
        a = np.asarray(value, dtype=float)
        try:
            return np.broadcast_to(a, (self.nodes.shape[0],)).astype(float).copy()
        except ValueError:
            raise ModelError(
                f"{self.name}: {what} must be a scalar or one value per element "
                f"({self.nodes.shape[0]}), got shape {a.shape}"
            ) from None

    # ------------------------------------------------------------------ construction helpers
    @classmethod
    def pretensioned(cls, nodes, X, EA, T0, devices, **kw):
        """Cables at uniform tension T0 (N) in the geometry X ((n_nodes, 3), m): L0 and the material
        coordinates at the devices follow from the (sized-pulley) section lengths."""
        nodes = np.atleast_2d(np.asarray(nodes, dtype=np.int64))
        X = np.asarray(X, dtype=float)
        n_el, nn = nodes.shape
        devices = list(devices)
        if len(devices) != nn - 2:
            raise ModelError(
                f"pretensioned: {len(devices)} devices for {nn - 1} sections; give one per interior node ({nn - 2})"
            )
        radius = np.zeros(nn)
        for k, d in enumerate(devices):
            radius[k + 1] = geometry_radius(d)
        EA_ = np.broadcast_to(np.asarray(EA, float), (n_el,))
        T0_ = np.broadcast_to(np.asarray(T0, float), (n_el,))
        if np.any(~(T0_ >= 0)):
            raise ModelError("pretensioned: T0 must be >= 0 N (a cable cannot carry compression)")
        Ls = []
        for e in range(n_el):
            code, where, L, _, _, _ = _geometry(X[nodes[e]], radius)
            if code != GEO_OK:
                raise ModelError(_geometry_message(code, where, "pretensioned", nodes[e], radius, X[nodes[e]]))
            Ls.append(L)
        Ls = np.array(Ls)
        stretch = 1.0 + T0_ / EA_
        L0 = Ls.sum(axis=1) / stretch
        s0 = np.cumsum(Ls, axis=1)[:, :-1] / stretch[:, None]
        return cls(nodes, EA, L0, devices, s0=s0, **kw)

    # ------------------------------------------------------------------ contract
    def initial_state(self) -> np.ndarray:
        n_el = self.n_elements
        m = self.n_sections - 1
        st = np.zeros((n_el, self.n_state))
        st[:, :m] = self.S0
        mode = np.where(self.kinds == FREE, SLIDE_FREE, 0)
        smax = np.where(self.kinds == LATCH, self.P[:, :m, 6] + self.P[:, :m, 1], np.inf)
        st[:, m:] = np.where(self.S0 >= smax - 1e-12 * self.L0[:, None], STOP, mode[None, :])
        return st

    def evaluate(self, x, R, state, ctx: IncrementContext | None = None) -> ElementResponse:
        """Forces f (N), tangent k (N/m), trial state, output and energy (J) of all elements.

        x : (n_nodes, 3) nodal positions, m.  R : ignored.  state : (n_el, n_state) committed."""
        X = np.ascontiguousarray(np.asarray(x, dtype=float)[self.nodes])
        state = np.ascontiguousarray(state, dtype=float)
        n_el, nn = self.nodes.shape
        m = self.n_sections - 1
        f = np.empty((n_el, 6 * nn))
        k = np.empty((n_el, 6 * nn, 6 * nn))
        new = np.empty_like(state)
        T = np.zeros((n_el, self.n_sections))
        phi = np.zeros((n_el, max(m, 1)))
        energy = np.zeros(n_el)
        err = np.zeros(n_el, dtype=np.int64)
        where = np.zeros(n_el, dtype=np.int64)
        P = np.ascontiguousarray(self.P)
        L0 = self.L0
        lf = getattr(self, "length_factor", None)
        scaled = lf is not None and bool(np.any(lf != 1.0))
        if scaled:  # thermal strain: every unstretched length and material coordinate times s
            L0 = L0 * lf
            P = P.copy()
            P[:, :, LATCH_LB] *= lf[:, None]
            state = state.copy()
            state[:, :m] *= lf[:, None]
        args = (X, self.radius, self.EA, L0, self.kinds, P, state, f, k, new, T, phi, energy, err, where)
        (device_kernel if self._law is None else kernel_for_law(self._law))(*args)
        if scaled:
            new[:, :m] /= lf[:, None]
        bad = np.flatnonzero(err)
        if bad.size:
            el = bad[0]
            self._raise(el, int(err[el]), int(where[el]), X[el], state)
        return ElementResponse(
            f=f,
            k=k,
            state=new,
            energy=energy,
            output=LazyOutput(lambda: self._output(T, new, phi[:, :m], lf if scaled else None)),
        )

    def _raise(self, el, code, where, X, state):
        name = f"{self.name} element {el}"
        if code < 10:
            raise ModelError(_geometry_message(code, where, name, self.nodes[el], self.radius, X))
        if code == ERR_SHORT:
            raise ModelError(
                f"{name}: the cable (L0 = {self.L0[el]:.6g} m) is far too short for the node positions: "
                "a section would need a non-positive unstretched length. Check the units of L0 and the "
                "coordinates, or build with CableDeviceFamily.pretensioned"
            )
        what = "cycled between stick and slip" if code == ERR_ACTIVE_SET else "did not converge"
        m = self.n_sections - 1
        where_latches = ""
        cells = []
        for k in np.flatnonzero(self.kinds == LATCH):
            p = self.P[el, k]
            xc = float(np.sqrt(max((p[0] + p[5]) ** 2 - (p[4] + p[0]) ** 2, 0.0)))
            cells.append(2.0 * xc / 256.0)
            where_latches += f"; latch {k}: bead at {1e3 * (p[LATCH_LB] - state[el, k]):.4g} mm"
        step = f" (less than {1e3 * min(cells):.3g} mm, one cell of the rollers' contact zone)" if cells else ""
        modes = ", ".join(MODE_NAMES.get(int(v), str(v)) for v in state[el, m:])
        raise ElementConvergenceError(
            f"{name}: the device equations {what} from the committed state (devices "
            f"{[type(d).__name__ for d in self.devices]}: {modes}{where_latches}). In an analysis the "
            "increment is cut back. If the step still gives up there: limit max_increment so that an "
            f"increment moves the cable through a latch by little{step}; check the device parameters (SI: "
            "k in N/m, radii in m) and that no sliding device has both of its sections slack"
        )

    def _output(self, T, new, phi, lf=None):
        m = self.n_sections - 1
        S = np.column_stack([np.zeros(len(T)), new[:, :m], self.L0])
        latch = self.kinds == LATCH
        bead = np.where(latch[None, :], self.P[:, :m, 6] - new[:, :m], np.nan)
        if lf is not None:  # physical (heated) lengths and bead positions
            S = S * lf[:, None]
            bead = bead * lf[:, None]
        return {
            "tension": T,
            "unstretched_length": np.diff(S, axis=1),
            "material_coordinate": new[:, :m].copy(),
            "device_mode": new[:, m:].copy(),
            "wrap_angle": phi.copy(),
            "bead_position": bead,
        }
