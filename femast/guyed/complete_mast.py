"""Complete mast model: beam plus three pretensioned shrouds in parallel (the Rocaspect paper, Eqs. 16-26).

The mast top C_i3 is a rigid body carrying the beam tip and the shrouds' upper
attachment points C_ir = C_i3 + e_r; each shroud runs to a fixed lower point D_r.
``d_r`` is the unit vector from C_ir to D_r (the direction in which the shroud pulls
the top) and ``l_r`` its length.  A top displacement ``dc = [dc_T ; dphi]`` (m; rad,
small rotation about C_i3) changes the shroud wrench ``W_s tau_s`` (Eq. 21, moments
about C_i3) and

    K_m = K_beam + K_a + K_p,      dc = K_m^+ dw                  (Eqs. 16-18, 22)

with the passive part ``K_p = W_s diag(k) W_s^T`` (Eq. 24, k from Eq. 25) and the
active part from the rotation of d_r and e_r at constant tension:

    K_a = sum_r tau_r / l_r [[ E_r,        -E_r [e_r]x                         ],
                             [ [e_r]x E_r, -[e_r]x E_r [e_r]x - l_r [d_r]x [e_r]x ]]

with ``E_r = I - d_r d_r^T``.

Correction to Eq. 26.  The printed lower-right block contains ``[l_r d_r]x``: times
``tau_r / l_r`` it has units of N, whereas a moment/rotation stiffness is in N m.
Deriving ``-d(W_s tau_s)/dc`` gives ``[l_r d_r]x [e_r]x`` instead (the moment arm e_r
rotating with the top): the paper's factor ``[e_r]x`` is missing.  The other blocks
of Eq. 26 agree with the derivation.  ``form="printed"`` in :func:`active_stiffness`
keeps the printed matrix for comparison.  K_a is not symmetric in general: with
spin increments of the top, the ``[d]x[e]x`` term (a force turning with its moment arm)
is only symmetric when the net shroud moment about C_i3 vanishes.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._moved import renamed
from ..elements.shroud_law import DyneemaLaw, shroud_stiffness
from ..errors import ModelError
from ._common import check_positive, check_vectors, skew, unit_vectors


@dataclass(frozen=True)
class ShroudSet:
    """The q shrouds of one mast.

    upper : (q, 3) upper attachment points C_ir in F_b, m (C_i3, the mast top, is one of them in the paper).
    lower : (q, 3) lower (ground) attachment points D_ir in F_b, m.
    tension : (q,) shroud tensions at the reference state, N (the paper measures them).
    law : Dyneema law of Eq. 25 (default: the paper's coefficients), or ``None`` when ``stiffness`` is given.
    stiffness : optional (q,) spring coefficients k_r, N/m, overriding the law.
    labels : shroud names for messages.
    """

    upper: np.ndarray
    lower: np.ndarray
    tension: np.ndarray
    law: DyneemaLaw | None = field(default_factory=DyneemaLaw)
    stiffness: np.ndarray | None = None
    labels: tuple = ()

    def __post_init__(self):
        up = check_vectors("shroud upper points C_ir", self.upper).reshape(-1, 3)
        lo = check_vectors("shroud lower points D_ir", self.lower).reshape(-1, 3)
        if up.shape != lo.shape:
            raise ModelError(f"shroud upper {up.shape} and lower {lo.shape} points must pair up, shape (q, 3), in m")
        try:
            tau = np.broadcast_to(np.asarray(self.tension, dtype=float), (up.shape[0],)).copy()
        except ValueError:
            raise ModelError(
                f"give one tension (N) per shroud ({up.shape[0]}) or a single value; got {self.tension!r}"
            ) from None
        if np.any(~np.isfinite(tau)) or np.any(tau < 0):
            raise ModelError(f"shroud tensions {tau} must be finite and >= 0 N (a shroud cannot push)")
        labels = tuple(self.labels) or tuple(f"{r + 1}" for r in range(up.shape[0]))
        unit_vectors("shroud", lo - up, labels=labels)  # coincident attachment points -> ModelError
        if self.stiffness is None and self.law is None:
            raise ModelError("give the shroud Dyneema law or explicit stiffness values (N/m)")
        if self.stiffness is not None:
            k = np.broadcast_to(np.asarray(self.stiffness, dtype=float), tau.shape).copy()
            check_positive("shroud stiffness", k, "N/m")
            object.__setattr__(self, "stiffness", k)
        object.__setattr__(self, "upper", up)
        object.__setattr__(self, "lower", lo)
        object.__setattr__(self, "tension", tau)
        object.__setattr__(self, "labels", labels)


def shroud_geometry(top, shrouds: ShroudSet):
    """Unit vectors d_r (q, 3) from C_ir to D_ir, lengths l_r (q,) in m and arms e_r = C_ir - C_i3 (q, 3) in m."""
    top = check_vectors("mast top C_i3", top).reshape(3)
    d, length = unit_vectors("shroud", shrouds.lower - shrouds.upper, labels=shrouds.labels)
    return d, length, shrouds.upper - top


def shroud_wrench_matrix(top, shrouds: ShroudSet) -> np.ndarray:
    """Shroud wrench matrix W_s (6, q) of Eq. 21: columns ``[d_r ; e_r x d_r]`` (per N; moments about C_i3)."""
    d, _, e = shroud_geometry(top, shrouds)
    return np.vstack([d.T, np.cross(e, d).T])


def shroud_coefficients(top, shrouds: ShroudSet, kind: str = "tangent") -> np.ndarray:
    """Spring coefficients k_r (q,) of Eq. 25 at the current tensions and lengths, N/m."""
    if shrouds.stiffness is not None:
        return shrouds.stiffness
    _, length, _ = shroud_geometry(top, shrouds)
    return shroud_stiffness(shrouds.law, shrouds.tension, length, kind=kind)


def passive_stiffness(top, shrouds: ShroudSet, kind: str = "tangent") -> np.ndarray:
    """Passive stiffness K_p = W_s diag(k) W_s^T (6, 6) of Eq. 24, in SI (N/m, N, N m/rad).

    ``kind`` selects the tangent (default) or the printed secant Eq. 25 coefficient (see :mod:`.shroud`).
    """
    W = shroud_wrench_matrix(top, shrouds)
    return (W * shroud_coefficients(top, shrouds, kind)) @ W.T


def passive_stiffness_blocks(top, shrouds: ShroudSet, kind: str = "tangent") -> np.ndarray:
    """Eq. 24's block form ``sum k_r [[D, D [e]x^T], [[e]x D, [e]x D [e]x^T]]`` (6, 6); equals :func:`passive_stiffness`."""
    d, _, e = shroud_geometry(top, shrouds)
    k = shroud_coefficients(top, shrouds, kind)
    D = d[:, :, None] * d[:, None, :]
    S = skew(e)
    St = np.swapaxes(S, 1, 2)
    blocks = np.block([[D, D @ St], [S @ D, S @ D @ St]])
    return np.einsum("r,rij->ij", k, blocks)


def active_stiffness(top, shrouds: ShroudSet, form: str = "corrected") -> np.ndarray:
    """Active stiffness K_a (6, 6) of Eq. 26 at the shroud tensions, in SI (N/m, N, N m/rad).

    ``form="corrected"`` (default) is ``-d(W_s tau)/dc`` at constant tension (module note);
    ``form="printed"`` is Eq. 26 as printed, kept only to show the difference (``"seed"``, its old
    name, warns and is removed in femast 0.3).
    """
    if form == "seed":
        renamed("active_stiffness(form='seed')", "active_stiffness(form='printed')")
        form = "printed"
    d, length, e = shroud_geometry(top, shrouds)
    tau = shrouds.tension
    E = np.eye(3) - d[:, :, None] * d[:, None, :]
    S = skew(e)
    if form == "corrected":
        br = -S @ E @ S - length[:, None, None] * skew(d) @ S
        blocks = np.block([[E, -E @ S], [S @ E, br]])
    elif form == "printed":
        br = skew(length[:, None] * d) + S @ E @ S
        blocks = -np.block([[-E, E @ S], [-S @ E, br]])
    else:
        raise ModelError(f"unknown active-stiffness form {form!r}; use 'corrected' or 'printed'")
    return np.einsum("r,rij->ij", tau / length, blocks)


@dataclass(frozen=True)
class MastStiffness:
    """Parts of the complete-mast stiffness at the mast top (all (6, 6), SI units; Eq. 17).

    K_beam : beam leg C_bi^-1 (Eq. 18).  K_a, K_p : active and passive shroud stiffness
    (Eqs. 26, 24).  K_m : their sum (Eqs. 17, 22).
    """

    K_beam: np.ndarray
    K_a: np.ndarray
    K_p: np.ndarray

    @property
    def K_m(self) -> np.ndarray:
        return self.K_beam + self.K_a + self.K_p

    @property
    def compliance(self) -> np.ndarray:
        """K_m^+ (Eq. 16), the pseudo-inverse used by the paper."""
        return np.linalg.pinv(self.K_m)


def mast_stiffness(
    K_beam, top, shrouds: ShroudSet | None, kind: str = "tangent", active_form: str = "corrected"
) -> MastStiffness:
    """Complete-mast stiffness (Eq. 17) from the beam stiffness K_beam (6, 6) and the shrouds.

    ``shrouds=None`` means no shrouds (detached): K_m = K_beam.
    """
    K_beam = np.asarray(K_beam, dtype=float)
    if K_beam.shape != (6, 6):
        raise ModelError(f"beam stiffness must be a (6, 6) matrix in SI units; got shape {K_beam.shape}")
    if shrouds is None:
        Z = np.zeros((6, 6))
        return MastStiffness(K_beam, Z, Z)
    return MastStiffness(K_beam, active_stiffness(top, shrouds, active_form), passive_stiffness(top, shrouds, kind))


def displacement_complete(stiffness: MastStiffness, dw) -> np.ndarray:
    """Top displacement ``dc = K_m^+ dw`` (Eq. 16) for wrenches dw (..., 6) in N, N m; returns m, rad."""
    return np.asarray(dw, dtype=float) @ stiffness.compliance.T
