"""Frames by step and histories over the frames: the part of :class:`~femast.post.results.Results`
that reads across frames (a node's displacement over the run, an element's section forces, the
last frame of a step).  Results gets them from :class:`Histories`; each needs only ``frame(i)``,
``len()``, the mesh's ``node_labels`` / ``labels/<family>`` and ``X``."""

from __future__ import annotations

import numpy as np

from ..errors import FemastError, did_you_mean

_COMPONENTS = {
    "ux": ("U", 0),
    "uy": ("U", 1),
    "uz": ("U", 2),
    "urx": ("URA", 0),
    "ury": ("URA", 1),
    "urz": ("URA", 2),
    "rx": ("URA", 0),
    "ry": ("URA", 1),
    "rz": ("URA", 2),
    "rfx": ("RF", 0),
    "rfy": ("RF", 1),
    "rfz": ("RF", 2),
    "rmx": ("RF", 3),
    "rmy": ("RF", 4),
    "rmz": ("RF", 5),
    "fx": ("P", 0),
    "fy": ("P", 1),
    "fz": ("P", 2),
    "mx": ("P", 3),
    "my": ("P", 4),
    "mz": ("P", 5),
}


class Histories:
    """Histories over the frames of a results folder (mixed into Results)."""

    def frame_number(self, step: str, index: int = -1) -> int:
        """The number of frame ``index`` of step ``step`` (-1: the step's last converged increment,
        0: its first; the initial state, frame 0, belongs to no step), for histories:
        ``res.node_history(tip, "uz")[res.frame_number("load")]``."""
        steps = self.steps
        mine = [k for k in range(1, len(steps)) if steps[k] == str(step)]
        if not mine:
            names = list(dict.fromkeys(steps[1:]))
            raise FemastError(
                f"{self.folder}: no frame of step '{step}'{did_you_mean(step, names)}; "
                f"its steps: {', '.join(names) or '(none: only the initial state)'}"
            )
        try:
            return mine[int(index)]
        except IndexError:
            raise FemastError(
                f"{self.folder}: step '{step}' has {len(mine)} frames; index {index} is out of range "
                f"(0..{len(mine) - 1}, or -1 for its last)"
            ) from None

    def _node_row(self, label):
        rows = np.flatnonzero(self.node_labels == int(label))
        if rows.size == 0:
            raise FemastError(
                f"node {label} is not in these results (labels {self.node_labels.min()}..{self.node_labels.max()})"
            )
        return int(rows[0])

    def scalar_history(self, name: str) -> np.ndarray:
        """History of a frame scalar: time, total_time, load_factor, increment, iterations."""
        return np.array([float(self.frame(i)[name]) for i in range(len(self))])

    @property
    def time(self):
        return self.scalar_history("total_time")

    @property
    def steps(self):
        return [str(self.frame(i)["step"]) for i in range(len(self))]

    def node_history(self, label, component: str) -> np.ndarray:
        """One nodal quantity of node ``label`` (the label ``Model.node`` returned) over all frames:
        an array of ``len(results)`` values, frame 0 (the initial state) first.

        component : ``ux``, ``uy``, ``uz`` displacement (m); ``rx``, ``ry``, ``rz`` (or ``urx``..)
            accumulated rotation about the global axes (rad, beyond 2 pi: the spins summed over the
            increments); ``rfx``, ``rfy``, ``rfz`` reaction force (N) and ``rmx``, ``rmy``, ``rmz``
            reaction moment (N m) at a supported or prescribed DOF (0 elsewhere); ``fx``, ``fy``, ``fz``
            applied force (N) and ``mx``, ``my``, ``mz`` applied moment (N m).  Case-insensitive.

        Frame ``k`` of step ``s`` is ``res.frame_number(s, k)``; the value at the end of step
        ``"load"``: ``res.node_history(tip, "uz")[res.frame_number("load")]``."""
        key = component.lower()
        if key not in _COMPONENTS:
            raise FemastError(f"unknown nodal component '{component}'; use one of {', '.join(_COMPONENTS)}")
        arr, col = _COMPONENTS[key]
        row = self._node_row(label)
        return np.array([self.frame(i)[arr][row, col] for i in range(len(self))])

    def element_history(self, family: str, label: int, name: str) -> np.ndarray:
        """Element output ``name`` of element ``label`` of ``family`` over all frames (first axis:
        frame).  Beams (``"beam"``): ``section_forces``, shape (frames, 2 ends, 6): N, Vy, Vz (N) and
        T, My, Mz (N m) in the element's local axes, end 1 then end 2; trusses and cables: ``N``
        (axial force, N).  The names a family writes are listed when one is missing."""
        if family not in self.families:
            raise FemastError(f"no element family '{family}' in these results; families: {', '.join(self.families)}")
        rows = np.flatnonzero(self.mesh[f"labels/{family}"] == int(label))
        if rows.size == 0:
            raise FemastError(f"element {label} is not in family '{family}'")
        key = f"el/{family}/{name}"
        if key not in self.frame(0):
            names = [k.split("/")[-1] for k in self.frame(0) if k.startswith(f"el/{family}/")]
            raise FemastError(f"family '{family}' has no output '{name}'; it has {', '.join(names)}")
        return np.array([self.frame(i)[key][rows[0]] for i in range(len(self))])

    def positions(self, i: int) -> np.ndarray:
        """Current nodal positions (m) at frame i."""
        return self.X + self.frame(i)["U"]
