"""The element contract shared by built-in and user elements (the analogue of Abaqus UEL).

An *element family* is a batch of elements of one kind.  It holds, as arrays,

* ``nodes``: (n_el, n_nodes_per_el) int array of node *indices* (0-based rows of
  the model's node table; the Analysis converts user labels to indices);
* its parameters (any arrays it likes);
* ``n_state``: the number of state variables per element (0 if none).

and implements one method, :meth:`ElementFamily.evaluate`, which computes for all
its elements at once, from the current nodal configuration and the *committed*
state (the state at the start of the increment):

* ``f``: (n_el, 6 * n_nodes_per_el) internal force vectors, ordered per node as
  [fx, fy, fz, mx, my, mz] (N, N m), global axes;
* ``k``: (n_el, 6 * n_nodes_per_el, 6 * n_nodes_per_el) tangent stiffness, the
  derivative of ``f`` with respect to nodal translations (m) and nodal *spatial
  spin* increments (rad): a rotation increment dw updates a nodal rotation matrix
  as R <- expm(skew(dw)) R;
* ``state``: (n_el, n_state) trial state variables;
* ``output``: a dict of per-element output arrays (section forces, status, ...)
  with shape (n_el, ...), written to the results at converged increments.  Outputs that
  cost more than gathering them may be a :class:`LazyOutput`, computed only if read: most
  iterations' responses are never written.

The analysis owns commit and rollback: the trial state returned at the converged
iteration is copied into the committed state; on a cut-back it is simply
discarded.  An element must therefore never mutate its committed state.

Kernels that run per element per iteration are numba-compiled functions taking
plain arrays; ``evaluate`` only gathers arrays and calls them.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

# Node DOF layout used everywhere: 3 translations then 3 rotations.
DOF_NAMES = ("ux", "uy", "uz", "rx", "ry", "rz")
TRANSLATIONS = (0, 1, 2)
ROTATIONS = (3, 4, 5)


@dataclass
class IncrementContext:
    """What an element may need to know about the increment being solved.

    time : step time at the end of the increment, s (pseudo-time for static steps).
    dtime : increment of step time, s.
    total_time : analysis time at the end of the increment, s.
    x_committed : (n_nodes, 3) nodal positions at the start of the increment, m.
    R_committed : (n_nodes, 3, 3) nodal rotation matrices at the start of the increment.
    step_name : name of the current step.
    previous : the trial states of the previous Newton iteration of this attempt, one (n_el,
        n_state) array per family in the analysis' family order (None in the first iteration and
        outside Newton iterations); read with :meth:`previous_state`.  A family with a
        non-smooth law may use it to see that an element jumped from one branch of its law to
        the opposite one (see :attr:`ElementResponse.provisional`).
    """

    time: float = 0.0
    dtime: float = 0.0
    total_time: float = 0.0
    x_committed: np.ndarray | None = None
    R_committed: np.ndarray | None = None
    step_name: str = ""
    previous: dict | None = None

    def previous_state(self, family):
        """The previous iteration's trial state of ``family`` (None if there is none)."""
        return None if self.previous is None else self.previous.get(id(family))


class LazyOutput(Mapping):
    """A read-only output dict computed by ``make()`` on first access.

    Only the response of a converged iteration is written to the results; building the outputs
    at every iteration took 60 % of the ADAM bay's cable/latch family evaluation (51 -> 21 us)
    and 25 % of its ball joints' (24 -> 18 us).  ``make`` must only read arrays that
    nobody modifies afterwards (the family's own fresh arrays of this evaluation)."""

    __slots__ = ("_make", "_data")

    def __init__(self, make):
        self._make = make
        self._data = None

    def _get(self) -> dict:
        if self._data is None:
            self._data = self._make()
            self._make = None
        return self._data

    def __getitem__(self, key):
        return self._get()[key]

    def __iter__(self):
        return iter(self._get())

    def __len__(self):
        return len(self._get())


@dataclass
class ElementResponse:
    """What :meth:`ElementFamily.evaluate` returns (see module docstring)."""

    f: np.ndarray
    k: np.ndarray
    state: np.ndarray
    output: Mapping = field(default_factory=dict)
    # Strain energy per element, J (used for stabilisation energy ratios and reports).
    energy: np.ndarray | None = None
    # True when some element answered with a predictor of its law instead of the law itself (e.g.
    # a friction joint that reversed its slip direction between two iterations is taken as stuck
    # for one iteration): the forces are not the law's, so the analysis never accepts this
    # iteration as converged.
    provisional: bool = False


class ElementFamily:
    """Base class of element families.  Subclasses set ``name``, ``nodes``, ``n_state``,
    ``active_dofs`` and implement :meth:`evaluate`.

    ``active_dofs`` is a tuple of the node DOFs (0..5) the family gives stiffness to:
    (0, 1, 2) for trusses and cables, (0, ..., 5) for beams.  The analysis only numbers
    a node's rotational DOFs if some family activates them; entries of ``f``/``k`` on
    inactive DOFs are ignored.
    """

    name: str = "element"
    nodes: np.ndarray
    n_state: int = 0
    active_dofs: tuple = (0, 1, 2, 3, 4, 5)
    # True when ``k`` is always symmetric (lets the analysis use a symmetric solver).
    symmetric: bool = False
    # True when the nodal forces ``f`` of every element have zero resultant force and moment (no
    # element is tied to the ground): the analysis then checks that the reactions balance the loads
    self_equilibrated: bool = False
    # True when the response depends on the configuration (x, R) only: no state, no use of the
    # increment context.  The analysis then reuses the converged response of an increment as the
    # start of the next one instead of evaluating the same configuration again.  Leave False for
    # elements with history (friction, latches) or rate/time dependence.
    path_independent: bool = False

    @property
    def n_elements(self) -> int:
        return int(self.nodes.shape[0])

    def initial_state(self) -> np.ndarray:
        """Committed state before the first increment, (n_el, n_state)."""
        return np.zeros((self.n_elements, self.n_state))

    def evaluate(self, x, R, state, ctx: IncrementContext) -> ElementResponse:  # pragma: no cover
        """Internal forces, tangent and trial state for every element of the family.

        x : (n_nodes, 3) current nodal positions, m (all model nodes; gather with ``self.nodes``).
        R : (n_nodes, 3, 3) current nodal rotation matrices (total rotation from the initial triad).
        state : (n_el, n_state) committed state (do not modify).
        ctx : :class:`IncrementContext`.
        """
        raise NotImplementedError


def chain_nodes(nodes, name: str) -> np.ndarray:
    """Node labels of cable elements running through n+1 nodes, as an (n_el, n+1) int64 array.

    One row (a 1-D array) is one element.  Shared by the cable/latch and cable-device families.
    """
    from ..errors import ModelError

    nodes = np.asarray(nodes)
    if nodes.ndim == 1:
        nodes = nodes[None, :]
    if nodes.ndim != 2 or nodes.shape[1] < 2 or not np.issubdtype(nodes.dtype, np.integer):
        raise ModelError(f"{name}: nodes must be an (n_el, n+1) integer array with n+1 >= 2, got {nodes.shape}")
    return np.ascontiguousarray(nodes, dtype=np.int64)


def check_positive(name: str, value, unit: str, allow_inf: bool = False) -> np.ndarray:
    """Return ``value`` as a float array after checking every entry is finite and > 0.

    Raises :class:`~femast.errors.ModelError` naming ``name`` and the unit otherwise.
    """
    from ..errors import ModelError

    arr = np.asarray(value, dtype=float)
    bad = ~(arr > 0.0) | (np.isinf(arr) if not allow_inf else np.isnan(arr))
    if np.any(bad):
        where = "" if arr.ndim == 0 else f" (entry {int(np.flatnonzero(bad.ravel())[0])})"
        what = "a positive number" + (" or inf (rigid)" if allow_inf else "")
        raise ModelError(f"{name}={value!r}{where} must be {what} in {unit}; give a physical value")
    return arr
