"""Prestressed modal analysis about a converged state of a static analysis.

At a converged state the small vibrations u(t) = phi sin(omega t) obey

    (K_T - omega^2 M) phi = 0

with K_T the analysis' own tangent at that state (elastic, geometric/stress stiffness of the
prestress, and the cable/latch and joint contributions at their committed state: a slipping
joint, a latched bead, a slack cable each give the tangent they give Newton) and M the mass
(:mod:`femast.modal.mass`), both on the free DOFs after the constraints (rigid bodies and ties:
T^T K T + G and T^T M T).  The lowest ``n`` pairs come from :mod:`.eigen`: with few massed DOFs
an exact condensation of the massless ones and a dense solution, else ARPACK's shift-invert
Lanczos with a basis no larger than the massed DOFs (DOFs without mass: modes at infinity).

The spin-variable tangent is symmetric at equilibrium for conservative loads; a follower-free
applied moment or a friction joint leaves a small unsymmetric part.  The symmetric part is used
and the relative size of the unsymmetric one is reported (``Modes.asymmetry``).

A state with eigenvalue omega^2 < 0 is statically unstable (past a buckling load): its
"frequency" is reported as -sqrt(|omega^2|) / (2 pi) (negative, Hz), so that f^2 sign(f) stays
linear in the load through the critical point.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..analysis.convergence import force_moment_abs_max
from ..elements.base import IncrementContext
from ..errors import ModelError, StateError
from .eigen import default_shift, solve_eigen
from .mass import assemble_mass

#: Largest residual / reference force ratio accepted as a converged state (100x Newton's default
#: force tolerance: a converged increment is well inside it, an unbalanced pretension is O(1)).
EQUILIBRIUM_TOL = 1e-4


@dataclass
class Modes:
    """Result of a modal analysis.

    eigenvalues : (n,) omega^2, (rad/s)^2, ascending.
    shapes : (n, n_nodes, 6) mode shapes, mass-normalised (phi^T M phi = 1 kg m^2 units: m/sqrt(kg)
        for translations, rad/sqrt(kg) for rotations), all nodes (dependent ones recovered), rows
        in the order of ``node_labels``.
    node_labels : (n_nodes,) labels.  x : (n_nodes, 3) node positions at the state, m.
    label : where the state comes from (e.g. "step 'pretension' increment 4").
    asymmetry : |K - K^T|_max / |K|_max of the tangent (its symmetric part was used).
    n_free : free DOFs of the problem; n_mass : free DOFs that carry mass.
    """

    eigenvalues: np.ndarray
    shapes: np.ndarray
    node_labels: np.ndarray
    x: np.ndarray
    label: str = ""
    asymmetry: float = 0.0
    n_free: int = 0
    n_mass: int = 0
    cells: dict = field(default_factory=dict)  # family name -> (n_el, nn) node rows, for VTK

    @property
    def frequencies(self) -> np.ndarray:
        """(n,) natural frequencies, Hz; negative for omega^2 < 0 (unstable state, see module)."""
        lam = self.eigenvalues
        return np.sign(lam) * np.sqrt(np.abs(lam)) / (2.0 * math.pi)

    def __len__(self):
        return len(self.eigenvalues)

    def shape(self, mode: int, label, dof) -> float:
        """Component ``dof`` (name or 0..5) of mode ``mode`` (0-based) at node ``label``."""
        from ..model import dof_index

        rows = np.flatnonzero(self.node_labels == int(label))
        if rows.size == 0:
            raise ModelError(f"Modes.shape: unknown node {label}")
        d = dof if isinstance(dof, (int, np.integer)) else dof_index(dof)
        return float(self.shapes[mode, rows[0], d])

    def table(self) -> str:
        """Plain-text table of the frequencies."""
        lines = [
            f"modes of {self.label or 'the state'} ({self.n_free} free DOFs, {self.n_mass} with mass)",
            f"{'mode':>5} {'f (Hz)':>14} {'omega^2 (rad/s)^2':>20}",
        ]
        for i, (f, lam) in enumerate(zip(self.frequencies, self.eigenvalues)):
            lines.append(f"{i + 1:>5} {f:>14.6g} {lam:>20.6g}")
        return "\n".join(lines)

    def write(self, folder, name: str = "modes") -> Path:
        """Write ``<folder>/<name>.npz`` (eigenvalues, frequencies_hz, shapes, node_labels, x,
        label) and ``<folder>/<name>.csv`` (mode, f_hz, omega2); returns the .npz path."""
        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        path = folder / f"{name}.npz"
        np.savez(
            path,
            eigenvalues=self.eigenvalues,
            frequencies_hz=self.frequencies,
            shapes=self.shapes,
            node_labels=self.node_labels,
            x=self.x,
            label=np.array(self.label),
            asymmetry=self.asymmetry,
            **{f"cells/{k}": v for k, v in self.cells.items()},
        )
        with open(folder / f"{name}.csv", "w") as fh:
            fh.write("mode,f_hz,omega2_rad2_per_s2\n")
            for i, (f, lam) in enumerate(zip(self.frequencies, self.eigenvalues)):
                fh.write(f"{i + 1},{f!r},{lam!r}\n")
        return path

    @classmethod
    def load(cls, path) -> Modes:
        """Read a file written by :meth:`write`."""
        d = np.load(path)
        cells = {k[len("cells/") :]: d[k] for k in d.files if k.startswith("cells/")}
        return cls(
            eigenvalues=d["eigenvalues"],
            shapes=d["shapes"],
            node_labels=d["node_labels"],
            x=d["x"],
            label=str(d["label"]),
            asymmetry=float(d["asymmetry"]),
            cells=cells,
        )


def _state(analysis):
    """(K_ff, residual on the free DOFs, reference force, reference moment) at the analysis'
    current configuration and committed state."""
    sys_ = getattr(analysis, "system", None)  # the analysis package: System holds the assembly
    if sys_ is not None:
        responses = sys_.evaluate(sys_.committed_context())
        res = sys_.residual(responses, analysis.loads)
        K, _ = sys_.tangent(responses, with_fc=False)
    else:
        responses = analysis._evaluate(IncrementContext(x_committed=analysis.x, R_committed=analysis.R))
        res = analysis._residual(responses, analysis.loads)
        K, _ = analysis._tangent(responses, with_fc=False)
    fmax, mmax = force_moment_abs_max(analysis.loads)
    for r in responses:
        ff, mm = force_moment_abs_max(r.f)
        fmax, mmax = max(fmax, ff), max(mmax, mm)
    return K.copy(), res[: analysis.dofmap.n_free], fmax, mmax


def check_equilibrium(analysis, r, fmax, mmax, tol=EQUILIBRIUM_TOL, where=""):
    """StateError if the free residual ``r`` is above ``tol`` of the reference force/moment."""
    L = analysis.length
    ref_f = max(fmax, 1e-2 * mmax / L, 1e-300)
    ref_m = max(mmax, 1e-2 * fmax * L, 1e-300)
    scale = np.where(analysis.is_rot, ref_m, ref_f)
    ratio = np.abs(r) / scale
    worst = int(np.argmax(ratio)) if ratio.size else 0
    if ratio.size and not ratio[worst] <= tol:
        raise StateError(
            f"modal analysis{where}: the state is not converged (not in equilibrium): residual "
            f"{r[worst]:.3g} {'N m' if analysis.is_rot[worst] else 'N'} at {analysis.dofmap.describe(worst)}, "
            f"{ratio[worst]:.2g} of the largest force (limit {tol:g}). Run the static analysis to a converged "
            "increment first (an initial pretension out of balance needs a step), or pass check=False."
        )


def _check_modes(n_modes, nf, n_mass, model_name):
    if isinstance(n_modes, bool) or not isinstance(n_modes, (int, np.integer)) or n_modes < 1:
        raise ModelError(f"modal analysis of '{model_name}': n_modes = {n_modes!r} must be a whole number >= 1")
    if n_modes > n_mass:
        raise ModelError(
            f"modal analysis of '{model_name}': n_modes = {n_modes} modes asked for, but the model has "
            f"only {n_mass} free DOFs that carry mass (of {nf} free DOFs); ask for at most {n_mass} "
            "modes, or add mass"
        )


def modal_analysis(
    analysis, n_modes: int = 10, shift_hz: float | None = None, check: bool = True, label: str = ""
) -> Modes:
    """The lowest ``n_modes`` vibration modes of ``analysis`` (a :class:`femast.Analysis`) about its
    current, converged state: before :meth:`~femast.Analysis.run` the initial state (if it is in
    equilibrium), after it the last converged increment, or inside ``on_frame`` any saved one.

    shift_hz : the modes nearest this frequency (Hz) are found (default: a shift just below the
        lowest mode of a stable state, see :func:`default_shift`).
    check : raise :class:`~femast.errors.StateError` if the state is not in equilibrium.
    Raises ModelError for a model without mass or more modes than free DOFs with mass."""
    model = analysis.model
    K, r, fmax, mmax = _state(analysis)
    if check:
        check_equilibrium(analysis, r, fmax, mmax, where=f" of '{model.name}'" + (f" ({label})" if label else ""))
    M, _ = assemble_mass(analysis)
    nf = K.shape[0]
    md = M.diagonal()
    if M.nnz == 0 or not np.any(md > 0):
        raise ModelError(
            f"modal analysis of '{model.name}': the model has no mass on its free DOFs. Give beam "
            "sections a density (section.with_(rho=...), kg/m^3), trusses/cables a mass_per_length "
            "(kg/m), a family a mass_per_length attribute, or add model.point_mass(node, mass=...)"
        )
    n_mass = int(np.count_nonzero(md > 0))
    _check_modes(n_modes, nf, n_mass, model.name)
    kmax = abs(K).max()
    asym = float(abs(K - K.T).max() / kmax) if kmax > 0 else 0.0
    Ks = ((K + K.T) * 0.5).tocsr()
    sigma = None if shift_hz is None else float(np.sign(shift_hz) * (2 * math.pi * shift_hz) ** 2)
    try:
        lam, V = solve_eigen(Ks, M, int(n_modes), sigma, describe=analysis.dofmap.describe)
    except ModelError as exc:
        raise type(exc)(f"modal analysis of '{model.name}': {exc}") from None
    shapes = expand_shapes(analysis, V)
    cells = {f.name: np.asarray(f.nodes) for f in analysis.families}
    return Modes(
        eigenvalues=lam,
        shapes=shapes,
        node_labels=np.asarray(model.node_labels),
        x=analysis.x.copy(),
        label=label,
        asymmetry=asym,
        n_free=nf,
        n_mass=n_mass,
        cells=cells,
    )


def expand_shapes(analysis, V) -> np.ndarray:
    """(n_modes, n_nodes, 6) nodal shapes from free-DOF vectors V (n_free, n_modes)."""
    dm = analysis.dofmap
    n_ind = dm.n_independent
    Vi = np.zeros((n_ind, V.shape[1]))
    Vi[: dm.n_free] = V
    Va = analysis.constraints.transformation(analysis.x) @ Vi if analysis.constraints.active else Vi
    node, dof = dm.slots(np.arange(dm.n_active))
    out = np.zeros((V.shape[1], len(analysis.X0), 6))
    out[:, node, dof] = Va[: dm.n_active].T
    return out


def frequencies_of(analysis, n_modes: int = 10, **kw) -> np.ndarray:
    """Just the frequencies (Hz) of :func:`modal_analysis`."""
    return modal_analysis(analysis, n_modes, **kw).frequencies


__all__ = ["Modes", "modal_analysis", "solve_eigen", "default_shift", "expand_shapes", "frequencies_of"]
