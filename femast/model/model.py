"""Model definition for scripts: nodes, elements, boundary conditions, loads, steps.

Example::

    import femast as fm
    m = fm.Model("cantilever")
    root, tip = m.node(0, 0, 0), m.node(1.0, 0, 0)
    m.beam(root, tip, fm.circular_tube(0.02, 0.016, E=70e9), up=(0, 0, 1), n=16)
    m.fix(root)
    step = m.step("bend")
    step.load(tip, mz=1.0)          # N m at the end of the step
    results = fm.solve(m, "results/cantilever")

All numbers are SI: coordinates and lengths in m, forces in N, moments in N m,
stiffnesses in N, N m^2, pressures in Pa, rotations in rad.
"""

from __future__ import annotations

import numpy as np

from ..elements.base import DOF_NAMES
from ..errors import ModelError
from . import validation
from .arrays import ElementList, add_beams, add_nodes, add_trusses
from .mass import point_mass_spec
from .sections import Section
from .specs import _DOF_INDEX, LOAD_NAMES, BeamSpec, TrussSpec, dof_index  # noqa: F401  (re-exported)
from .step import Condition, Step, _finite  # noqa: F401  (re-exported)


def _fixed_dofs(node, dofs) -> list[int]:
    """DOF indices of ``Model.fix(node, *dofs)``: none or "all" -> six, names, "translations", "rotations"."""
    if not dofs or dofs == ("all",):
        idx = range(6)
    else:
        idx = []
        for d in dofs:
            if d == "translations":
                idx += [0, 1, 2]
            elif d == "rotations":
                idx += [3, 4, 5]
            else:
                if str(d).lower() not in _DOF_INDEX:
                    raise ModelError(f"fix node {node}: unknown DOF '{d}'; use {', '.join(DOF_NAMES)}")
                idx.append(_DOF_INDEX[str(d).lower()])
    return list(idx)


class Model:
    """A structural model called ``name``: nodes (6 DOF each), element families, fixed DOFs and steps.

    ``model.beams`` and ``model.trusses`` are the lists of beam and truss element specs; called,
    they add many elements from arrays at once (``model.beams(pairs, section, up=...)``,
    ``model.trusses(pairs, EA)``; see :meth:`add_beams`, :meth:`add_trusses`)."""

    def __init__(self, name: str = "model"):
        self.name = name
        self._node_labels: list[int] = []
        self._node_xyz: list[tuple] = []
        self._node_index: dict[int, int] = {}
        self._max_label = 0  # largest node label so far (auto-numbering without a max() per node)
        self.beams: list[BeamSpec] = ElementList(self.add_beams)  # called: self.add_beams(...)
        self.trusses: list[TrussSpec] = ElementList(self.add_trusses)  # called: self.add_trusses(...)
        self.families: list = []  # user / custom ElementFamily objects (built with node labels)
        self.fixed: dict[int, set] = {}
        self.rigid_bodies: list = []
        self.ties: list = []
        self.steps: list[Step] = []
        self.point_masses: list = []  # femast.model.mass.PointMassSpec (modal analyses, gravity)
        self.length_errors: dict = {}  # element label -> m (lack of fit)
        self.expansion: dict = {}  # element label -> 1/K
        self.initial_temperatures: dict = {}  # element label -> K or degC
        self._next_element = 1

    # ---------------------------------------------------------------- nodes
    def node(self, x: float, y: float, z: float, label: int | None = None) -> int:
        """Add a node at (x, y, z) (m); returns its label (auto-numbered from 1 if not given)."""
        xyz = tuple(
            _finite(v, f"node {label if label is not None else len(self._node_labels) + 1} coordinate {c}", "m")
            for v, c in zip((x, y, z), "xyz")
        )
        if label is None:
            label = (self._max_label + 1) if self._node_labels else 1
        label = validation.whole(label, "node label")
        if label in self._node_index:
            raise ModelError(f"node {label} is defined twice; labels must be unique")
        self._max_label = label if not self._node_labels else max(self._max_label, label)
        self._node_index[label] = len(self._node_labels)
        self._node_labels.append(label)
        self._node_xyz.append(xyz)
        return label

    def nodes(self, coords) -> list[int]:
        """Add several nodes from ``coords``, an (n, 3) array of coordinates (m), labelled on from the largest
        label so far (as repeated :meth:`node` calls, checked at once); returns their labels."""
        return add_nodes(self, coords)

    @property
    def node_labels(self) -> np.ndarray:
        return np.array(self._node_labels, dtype=np.int64)

    @property
    def coordinates(self) -> np.ndarray:
        """(n_nodes, 3) initial coordinates, m, in the order of :attr:`node_labels`."""
        return np.array(self._node_xyz, dtype=float).reshape(-1, 3)

    def index(self, label) -> int:
        """Row of node ``label`` in the node table."""
        self._check_node(label, "lookup")
        return self._node_index[int(label)]

    def xyz(self, label) -> np.ndarray:
        """Initial coordinates (m) of node ``label``."""
        return np.array(self._node_xyz[self.index(label)])

    def _check_node(self, label, where):
        try:
            ok = (
                not isinstance(label, (str, bytes, bool, np.bool_))
                and float(label) == int(label)
                and int(label) in self._node_index
            )
        except (TypeError, ValueError, OverflowError):
            ok = False
        if not ok:
            validation.not_fractional(label, where)  # (2.7 is no label, and not node 2 either)
            known = self._node_labels
            hint = f"known labels {known[0]}..{known[-1]}" if known else "the model has no nodes yet"
            raise ModelError(f"{where}: unknown node {label!r} ({hint}); create it with model.node(x, y, z)")

    # ------------------------------------------------------------- elements
    def beam(
        self,
        n1,
        n2,
        section: Section,
        up=(0.0, 0.0, 1.0),
        n: int = 1,
        family: str = "beam",
        mass_per_length: float | None = None,
        length_error_m: float = 0.0,
        alpha_per_K: float = 0.0,
    ) -> list[int]:
        """Beam(s) from node ``n1`` to ``n2``, split into ``n`` equal elements (new nodes are
        created in between).  ``up`` (global vector) sets the local y axis: it is made
        orthogonal to the element; Iz resists bending in the plane of the axis and ``up``.
        ``mass_per_length`` (kg/m) overrides the section's ``rho * A`` for modal analyses.
        ``family`` names the element family (its output key in the results, ``el/<family>/...``).
        ``length_error_m`` (m): the member is stress free when that much longer than its nodes'
        distance (lack of fit, spread evenly over its ``n`` elements); ``alpha_per_K`` (1/K): its
        coefficient of thermal expansion (see :meth:`length_error`, :meth:`thermal_expansion`).
        Returns the element labels."""
        self._check_node(n1, "beam")
        self._check_node(n2, "beam")
        if not isinstance(section, Section):
            raise ModelError(f"beam {n1}-{n2}: section must be a femast Section (got {type(section).__name__})")
        n = validation.whole(n, f"beam {n1}-{n2}: number of elements n", minimum=1)
        a, b = self.xyz(n1), self.xyz(n2)
        L = float(np.linalg.norm(b - a))
        validation.element_length(L, float(max(np.abs(a).max(), np.abs(b).max())), f"beam {n1}-{n2}", "beam", n1, n2)
        up_arr = np.asarray(up, dtype=object)
        if up_arr.shape != (3,):
            raise ModelError(f"beam {n1}-{n2}: up-vector {up!r} must be 3 numbers (a global direction)")
        up = np.array([_finite(u, f"beam {n1}-{n2}: up-vector") for u in up_arr])
        e = (b - a) / L
        if np.linalg.norm(up - (up @ e) * e) < 1e-6 * max(np.linalg.norm(up), 1e-300):
            raise ModelError(
                f"beam {n1}-{n2}: up-vector {tuple(float(u) for u in up)} is parallel to the element axis "
                f"{tuple(float(v) for v in np.round(e, 6))}; choose an up-vector not along the beam"
            )
        if mass_per_length is not None:
            mass_per_length = _finite(mass_per_length, f"beam {n1}-{n2}: mass_per_length")
            if mass_per_length < 0:
                raise ModelError(f"beam {n1}-{n2}: mass_per_length = {mass_per_length} kg/m must be >= 0")
        chain = [n1] + [self.node(*(a + (b - a) * k / n)) for k in range(1, n)] + [n2]
        labels = []
        for p, q in zip(chain[:-1], chain[1:]):
            labels.append(self._next_element)
            self.beams.append(BeamSpec(self._next_element, (p, q), section, up, family, mass_per_length))
            self._next_element += 1
        self._error_sources(labels, length_error_m, alpha_per_K)
        return labels

    def add_beams(
        self,
        nodes,
        section: Section,
        up=(0.0, 0.0, 1.0),
        family="beam",
        mass_per_length=None,
        length_error_m=0.0,
        alpha_per_K=0.0,
    ) -> np.ndarray:
        """One beam per row of ``nodes`` ((n, 2) node labels), as :meth:`beam` with ``n=1`` for each
        row but checked at once (no Python call per element); also ``model.beams(...)``.
        ``section``, ``up`` (3,) or (n, 3), ``family``, ``mass_per_length`` (kg/m),
        ``length_error_m`` (m), ``alpha_per_K`` (1/K): shared or one per element.  Returns the
        element labels (see :mod:`femast.model.arrays`)."""
        return add_beams(self, nodes, section, up, family, mass_per_length, length_error_m, alpha_per_K)

    def add_trusses(
        self,
        nodes,
        EA,
        L0=None,
        pretension=None,
        tension_only=False,
        family=None,
        mass_per_length=0.0,
        length_error_m=0.0,
        alpha_per_K=0.0,
    ) -> np.ndarray:
        """One truss (cable with ``tension_only``) per row of ``nodes`` ((n, 2) node labels), as
        :meth:`truss` for each row but checked at once; also ``model.trusses(...)``.  ``EA`` (N),
        ``L0`` (m), ``pretension`` (N), ``family`` (name), ``mass_per_length`` (kg/m),
        ``length_error_m`` (m), ``alpha_per_K`` (1/K): shared or one per element.  Returns the labels."""
        return add_trusses(
            self, nodes, EA, L0, pretension, tension_only, family, mass_per_length, length_error_m, alpha_per_K
        )

    def _error_sources(self, labels, length_error_m, alpha_per_K):
        if length_error_m != 0.0:
            self.length_error(labels, _finite(length_error_m, f"element {labels[0]}: length_error_m (m)") / len(labels))
        if alpha_per_K != 0.0:
            self.thermal_expansion(alpha_per_K, elements=labels)

    def length_error(self, elements, dL_m):
        """Lack of fit: element(s) ``elements`` (labels of beams or trusses) are stress free at their
        reference length + ``dL_m`` (m; one value or one per element; a beam's reference is its
        nodes' distance, a truss's its unstretched length).  Acts from the first step."""
        from .thermal import set_length_errors

        return set_length_errors(self, elements, dL_m)

    def thermal_expansion(self, alpha_per_K, elements=None, family=None, where=None):
        """Coefficient of thermal expansion ``alpha_per_K`` (1/K; one value or one per element) of beam and truss
        elements picked by labels, family name or region (``where``: a function of the element
        midpoint, m); none: all.  Returns the labels."""
        from .thermal import set_expansion

        return set_expansion(self, alpha_per_K, elements, family, where)

    def initial_temperature(self, T, elements=None, family=None, where=None):
        """Initial temperature ``T`` (K or degC, default 0) of beam and truss elements (as Abaqus *INITIAL
        CONDITIONS, TYPE=TEMPERATURE): the elements are stress free at it.  Picked by ``elements``
        (labels), ``family`` (name) or ``where`` (a function of the element midpoint, m); none: all.
        Returns the labels."""
        from .thermal import set_initial_temperature

        return set_initial_temperature(self, T, elements, family, where)

    def truss(
        self,
        n1,
        n2,
        EA: float,
        L0: float | None = None,
        pretension: float | None = None,
        tension_only: bool = False,
        family: str | None = None,
        mass_per_length: float = 0.0,
        length_error_m: float = 0.0,
        alpha_per_K: float = 0.0,
    ) -> int:
        """Truss (or, with ``tension_only=True``, cable) from ``n1`` to ``n2``; EA in N.
        Give the unstretched length ``L0`` (m) or the ``pretension`` (N) it carries in the
        initial geometry; neither means stress-free.  ``mass_per_length`` (kg/m of the initial
        length; modal analyses): consistent mass for trusses, lumped at the ends for cables.
        ``length_error_m`` (m): stress free at the unstretched length + this (lack of fit);
        ``alpha_per_K`` (1/K): coefficient of thermal expansion.  ``family``: the element family's
        name (default "truss", or "cable" with ``tension_only``).  Returns the element label."""
        self._check_node(n1, "truss")
        self._check_node(n2, "truss")
        EA = _finite(EA, f"truss {n1}-{n2}: EA", "N")
        if EA <= 0:
            raise ModelError(f"truss {n1}-{n2}: EA = {EA} N must be positive")
        a, b = self.xyz(n1), self.xyz(n2)
        L = float(np.linalg.norm(b - a))
        validation.element_length(L, float(max(np.abs(a).max(), np.abs(b).max())), f"truss {n1}-{n2}", "truss", n1, n2)
        if L0 is not None and pretension is not None:
            raise ModelError(f"truss {n1}-{n2}: give L0 or pretension, not both")
        if L0 is not None:
            L0 = _finite(L0, f"truss {n1}-{n2}: L0", "m")
            if L0 <= 0:
                raise ModelError(f"truss {n1}-{n2}: unstretched length L0 = {L0} m must be positive")
        if pretension is not None:
            pretension = _finite(pretension, f"truss {n1}-{n2}: pretension", "N")
            if pretension <= -EA:
                raise ModelError(f"truss {n1}-{n2}: pretension {pretension} N <= -EA is impossible")
        mass_per_length = _finite(mass_per_length, f"truss {n1}-{n2}: mass_per_length")
        if mass_per_length < 0:
            raise ModelError(f"truss {n1}-{n2}: mass_per_length = {mass_per_length} kg/m must be >= 0")
        label = self._next_element
        self._next_element += 1
        fam = family or ("cable" if tension_only else "truss")
        self.trusses.append(TrussSpec(label, (n1, n2), EA, L0, pretension, bool(tension_only), fam, mass_per_length))
        self._error_sources([label], length_error_m, alpha_per_K)
        return label

    def add_family(self, family):
        """Add a user or built-in element family (see :mod:`femast.elements.base`) whose
        ``nodes`` array holds node *labels*; returns it."""
        for lab in np.unique(np.asarray(family.nodes)):
            self._check_node(int(lab), f"element family '{family.name}'")
        self.families.append(family)
        return family

    # ------------------------------------------------------- boundary conditions
    def fix(self, node, *dofs):
        """Fix ``dofs`` of ``node`` at zero for the whole analysis: ``fix(n)`` fixes all six,
        ``fix(n, "ux", "rz")`` some (names ux, uy, uz, rx, ry, rz; "translations", "rotations")."""
        self._check_node(node, "fix")
        self.fixed.setdefault(int(node), set()).update(_fixed_dofs(node, dofs))

    # ------------------------------------------------------------ constraints
    def point_mass(self, node, mass: float = 0.0, inertia=None, offset=None, name: str = ""):
        """A mass ``mass`` (kg) with rotary ``inertia`` (kg m^2 about its centre of mass: a scalar,
        3 principal values along the global axes or a 3x3 matrix, initial global axes) at
        ``node``, its centre of mass ``offset`` (m) from the node (modal analyses, gravity); ``name``
        labels it in messages.  Returns the :class:`femast.model.mass.PointMassSpec`."""
        self._check_node(node, "point mass")
        spec = point_mass_spec(node, mass, inertia, offset, name)
        self.point_masses.append(spec)
        return spec

    def rigid_body(self, reference, nodes, name: str | None = None, mass: float = 0.0, inertia=None, centre=None):
        """Tie ``nodes`` rigidly to the ``reference`` node (exact for large rotations, as Abaqus
        *RIGID BODY with a REF NODE).  Load, fix or drive the reference node; the tied nodes
        follow.  The reference node may be a node without elements (e.g. a control node).
        ``mass`` (kg) and ``inertia`` (kg m^2 about the centre of mass, see :meth:`point_mass`)
        of the body, its centre of mass at ``centre`` (m, global; default the reference node),
        are a point mass at the reference node.  ``name`` labels the body (default rigid-1...)."""
        from .constraints import rigid_body_spec

        name = name or f"rigid-{len(self.rigid_bodies) + 1}"
        spec = rigid_body_spec(self, reference, nodes, name)
        if mass or inertia is not None:
            off = None if centre is None else np.asarray(centre, float) - self.xyz(reference)
            self.point_mass(reference, mass, inertia, off, name=f"rigid body '{name}'")
        self.rigid_bodies.append(spec)
        return spec

    def tie(self, master, slave, *dofs):
        """Make ``dofs`` of node ``slave`` equal to those of ``master`` (default: the three
        translations, a pin between coincident nodes; "all" ties rotations too: exact for any
        rotation when all three rotations are tied)."""
        from .constraints import tie_spec

        spec = tie_spec(self, master, slave, dofs)
        self.ties.append(spec)
        return spec

    # ----------------------------------------------------------------- steps
    def step(self, name: str | None = None, **options) -> Step:
        """Append a static step called ``name`` (default Step-1, Step-2...); options are :class:`Step`
        fields: ``period`` (s), ``initial_increment``, ``max_increments``, ``control``... Returns it."""
        name = name or f"Step-{len(self.steps) + 1}"
        if any(s.name == name for s in self.steps):
            raise ModelError(f"step '{name}' is defined twice; step names must be unique")
        known = set(Step.__dataclass_fields__) - {"name", "loads", "prescribed", "_model"}
        for k in options:
            if k not in known:
                raise ModelError(f"step '{name}': unknown option '{k}'; step options are {', '.join(sorted(known))}")
        s = Step(name=name, **options)
        s._model = self
        validation.step_increments(s)
        if (
            isinstance(s.output_frequency, bool)
            or not isinstance(s.output_frequency, (int, np.integer))
            or s.output_frequency < 1
        ):
            raise ModelError(
                f"step '{name}': output_frequency = {s.output_frequency!r} must be a whole number "
                ">= 1 (a frame every that many increments)"
            )
        self.steps.append(s)
        return s

    def frequency_step(
        self, name: str | None = None, n_modes: int = 10, shift_hz: float | None = None, vtk: bool = False
    ):
        """Append a step called ``name`` that computes the lowest ``n_modes`` vibration modes of the
        state reached so far (prestress and loads included; see :mod:`femast.model.frequency`): the modes
        nearest ``shift_hz`` (Hz) when given, else the lowest; ``vtk=True`` also writes an animated
        VTK series per mode.  Returns it."""
        from .frequency import add_frequency_step

        return add_frequency_step(self, name, n_modes, shift_hz, vtk)

    def __repr__(self):
        return (
            f"Model({self.name!r}: {len(self._node_labels)} nodes, {len(self.beams)} beams, "
            f"{len(self.trusses)} trusses, {len(self.families)} other families, {len(self.steps)} steps)"
        )
