"""The analysis state: everything a converged increment commits, in one object.

:class:`State` holds the nodal configuration (positions, rotation matrices, accumulated spins),
the committed state arrays of every element family, the applied loads and prescribed values, the
load factor, the step and total times, the energies and the memory the increment-size adaptation
carries from one increment to the next (increment size, easy-increment count, last increment for
extrapolation and the arc-length predictor, stabilisation damping).  The analysis owns one.

* :meth:`State.checkpoint` marks the start of an increment attempt (copies of the configuration);
  :meth:`State.rollback` returns to it after a failed attempt (a cutback);
  :meth:`State.commit` records a converged increment.  Each is one call.
* :meth:`State.save` writes the whole state to one ``.npz`` file and :meth:`State.load` reads it
  back bit for bit (floats as IEEE doubles, no text round trip): the basis of restarts.

Element families never touch it: they receive the configuration and their committed state array
and return a trial state (femast/elements/base.py); the commit copies the trial state in.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields

import numpy as np

from ..errors import FemastError

# scalar fields written by save(), in this order (all but the arrays and `families`)
_SCALARS = (
    "lam",
    "total_time",
    "step",
    "step_time",
    "increment",
    "size",
    "first_size",
    "easy",
    "strain_energy",
    "stabilization_energy",
    "stabilization_force",
    "stabilization_moment",
    "at_equilibrium",
    "version",
    "last_size",
    "last_dlam",
)
_ARRAYS = ("x", "R", "spin", "loads", "prescribed", "reactions", "last_increment", "damping", "damping0")
FORMAT = "femast-state-1"


@dataclass(eq=False)
class State:
    """What an increment commits (SI units; n nodes).

    x : (n, 3) nodal positions, m.  R : (n, 3, 3) nodal rotation matrices (from the initial triad).
    spin : (n, 3) accumulated rotation vectors, rad (beyond 2 pi for rotations about a fixed axis).
    families : per element family, its committed state array (n_el, n_state).
    loads : (n, 6) loads applied at the last converged increment, N and N m.
    prescribed : (n, 6) displacements (m) / rotations (rad) reached at the constrained DOFs.
    reactions : reactions on the constrained (fixed and prescribed) DOFs, in equation order, or None.
    lam : load factor.  total_time : analysis time, s.  step : index of the current step.
    step_time : time in the current step, s (arc length: the load factor).  increment : converged
    increments of the current step.
    size : size of the next increment (s of step time; arc length: the arc length, m).
    first_size : the step's first increment size.  easy : consecutive easy increments.
    strain_energy : J.  stabilization_energy : J dissipated by the viscous term in this step.
    stabilization_force, stabilization_moment : largest viscous force (N) / moment (N m) of the last
    increment.  at_equilibrium : False after a stabilised increment (viscous forces remain).
    version : configuration counter, bumped by every update of the configuration.
    last_increment, last_size, last_dlam : the last converged increment of the free DOFs, its size
    and load-factor change (linear extrapolation, arc-length predictor direction), or None.
    damping, damping0 : the stabilised step's viscous damping per free DOF (current, initial), or None.
    """

    x: np.ndarray
    R: np.ndarray
    spin: np.ndarray
    families: list
    loads: np.ndarray
    prescribed: np.ndarray
    reactions: np.ndarray | None = None
    lam: float = 0.0
    total_time: float = 0.0
    step: int = 0
    step_time: float = 0.0
    increment: int = 0
    size: float | None = None
    first_size: float | None = None
    easy: int = 0
    strain_energy: float = 0.0
    stabilization_energy: float = 0.0
    stabilization_force: float = 0.0
    stabilization_moment: float = 0.0
    at_equilibrium: bool = False
    version: int = 0
    last_increment: np.ndarray | None = None
    last_size: float | None = None
    last_dlam: float | None = None
    damping: np.ndarray | None = None
    damping0: np.ndarray | None = None
    _saved: tuple | None = field(default=None, repr=False)

    @classmethod
    def initial(cls, X0, families) -> State:
        """The undeformed, unloaded state of nodes at ``X0`` (n, 3) with element ``families``."""
        n = len(X0)
        return cls(
            x=X0.copy(),
            R=np.tile(np.eye(3), (n, 1, 1)),
            spin=np.zeros((n, 3)),
            families=[f.initial_state() for f in families],
            loads=np.zeros((n, 6)),
            prescribed=np.zeros((n, 6)),
        )

    # ------------------------------------------------------------ increments
    def checkpoint(self):
        """Start an increment attempt: keep copies of the configuration and load factor to roll
        back to.  Returns the copies (x, R) of the start of the increment (the committed ones)."""
        self._saved = (self.x.copy(), self.R.copy(), self.spin.copy(), self.lam, self.version)
        return self._saved[0], self._saved[1]

    def rollback(self):
        """Return to the last :meth:`checkpoint` (a failed attempt)."""
        self.x, self.R, self.spin, self.lam, self.version = self._saved

    def commit(self, family_states, loads, lam, reactions, strain_energy, equilibrium=True):
        """Record a converged increment: the families' trial states (None: the family's state is
        unchanged) become committed, with the loads, load factor, reactions and strain energy."""
        self.at_equilibrium = equilibrium
        self.families = [t.copy() if t is not None else s for t, s in zip(family_states, self.families)]
        self.loads = loads.copy()
        self.lam = lam
        self.strain_energy = strain_energy
        self.reactions = reactions

    # ------------------------------------------------------------ disk
    def save(self, path):
        """Write the state to ``path`` (an ``.npz`` file, or a binary file object), bit for bit (see :meth:`load`)."""
        data = {"format": np.array(FORMAT), "n_families": np.array(len(self.families))}
        for k, a in enumerate(self.families):
            data[f"family/{k}"] = np.asarray(a)
        for name in _ARRAYS:
            v = getattr(self, name)
            if v is not None:
                data[name] = np.asarray(v)
        for name in _SCALARS:
            v = getattr(self, name)
            if v is not None:
                data[name] = np.array(v)
        if hasattr(path, "write"):  # a file object (a restart point writes the bytes itself)
            np.savez(path, **data)
            return
        with open(path, "wb") as fh:
            np.savez(fh, **data)

    @classmethod
    def load(cls, path) -> State:
        """Read a state written by :meth:`save`; every array and number is the one saved, bit for bit."""
        with np.load(path, allow_pickle=False) as z:
            if "format" not in z.files or str(z["format"]) != FORMAT:
                raise FemastError(f"{path}: not a femast state file ({FORMAT}); write one with State.save")
            kw = {name: z[name] for name in _ARRAYS if name in z.files}
            kinds = {f.name: f.type for f in fields(cls)}
            for name in _SCALARS:
                if name in z.files:
                    v = z[name].item()
                    kw[name] = bool(v) if "bool" in str(kinds[name]) else v
            kw["families"] = [z[f"family/{k}"] for k in range(int(z["n_families"]))]
        return cls(**kw)

    def equal(self, other: State) -> bool:
        """True if every array and number of ``other`` is this one's, bit for bit."""
        if len(self.families) != len(other.families):
            return False
        same = all(
            np.array_equal(a, b) and a.dtype == b.dtype and a.shape == b.shape
            for a, b in zip(self.families, other.families)
        )
        for name in _ARRAYS:
            a, b = getattr(self, name), getattr(other, name)
            same &= (a is None and b is None) or (
                a is not None
                and b is not None
                and a.shape == b.shape
                and np.asarray(a).tobytes() == np.asarray(b).tobytes()
            )
        for name in _SCALARS:
            a, b = getattr(self, name), getattr(other, name)
            same &= (a is None and b is None) or (
                a is not None and b is not None and np.array(a).tobytes() == np.array(b).tobytes()
            )
        return bool(same)
