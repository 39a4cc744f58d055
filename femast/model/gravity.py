"""Gravity: the body forces of a uniform acceleration field on the model's mass.

``step.gravity(g=(0, 0, -9.81))`` applies, at the end of the step, the weight of everything that
has mass in the model (as Abaqus' ``*DLOAD, GRAV``): beams (``Section.rho`` or
``mass_per_length``), trusses and cables (``mass_per_length``), families with a
``mass_per_length`` or their own ``mass_matrices``, point masses and rigid bodies.  The nodal
loads are the mass matrix of the mass model (:mod:`femast.model.mass`) times the acceleration
``g`` on every translation:

    P = M a_g,   a_g = (g, 0, g, 0, ...)  (translations g, rotations 0)

which is the consistent load of the distributed weight: for a beam of mass per length m' and
length L along e, ``m' L g / 2`` at each end and the end moments ``+- m' L^2 / 12 (e x g)``
(exact nodal deflections of a cubic beam); for a truss or a cable ``m' L g / 2`` at each end;
for a point mass m with its centre of mass at offset c, the force ``m g`` and the moment
``m c x g``.

Gravity is a dead load: its direction is fixed and its nodal values are computed once, on the
initial geometry (the end moments of a beam keep the beam's initial orientation; they are a
self-equilibrated correction of O(L^2) that vanishes with mesh refinement).  It adds to the
step's concentrated loads, ramps from the gravity of the previous step to this step's over the
step (or follows an amplitude ``a(t)``: ``a(t) g``), and stays applied in later steps until a
step redefines it (``step.gravity(g=(0, 0, 0))`` removes it).  SI: g in m/s^2, loads in N and N m.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from .amplitudes import Amplitude

G_MAX = 1000.0
"""Largest plausible acceleration, m/s^2 (100 g; a larger one is taken for a unit mistake)."""


@dataclass(frozen=True)
class GravitySpec:
    """A step's gravity: acceleration ``g`` (3,) in m/s^2, global axes, and its amplitude."""

    g: np.ndarray
    amplitude: Amplitude | None = None


def _step_gravity(self, g=(0.0, 0.0, -9.81), amplitude: Amplitude | None = None):
    """Gravity at the end of the step: the acceleration ``g`` (m/s^2, global axes; default
    standard gravity along -z) on all the model's mass (see :mod:`femast.model.gravity`).  It
    ramps from the previous step's gravity over the step (or is ``amplitude(t) g``) and stays
    applied in later steps; ``g=(0, 0, 0)`` removes it.  Returns the step."""
    try:
        a = np.asarray(g, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise ModelError(f"step '{self.name}': gravity g = {g!r} must be a 3-vector in m/s^2") from None
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise ModelError(f"step '{self.name}': gravity g = {g!r} must be a finite 3-vector in m/s^2")
    if np.linalg.norm(a) > G_MAX:
        raise ModelError(
            f"step '{self.name}': gravity |g| = {np.linalg.norm(a):.6g} m/s^2 is implausible (over "
            f"{G_MAX:g} m/s^2); g is in m/s^2 (standard gravity: (0, 0, -9.81))"
        )
    if amplitude is not None and not isinstance(amplitude, Amplitude):
        raise ModelError(f"step '{self.name}': gravity amplitude must be an Amplitude, got {type(amplitude).__name__}")
    self.gravity_spec = GravitySpec(a, amplitude)
    return self


def unit_gravity_loads(model, families, X0, R0) -> np.ndarray:
    """(3, n_nodes, 6) nodal loads (N, N m) of a unit acceleration (1 m/s^2) along x, y and z on
    the mass model of ``model`` with its element ``families``, at the geometry (X0, R0)."""
    from .mass import family_mass_blocks

    n = X0.shape[0]
    out = np.zeros((3, n, 6))
    for block in family_mass_blocks(model, families, X0, R0, X0):
        n_el, nn = block.nodes.shape
        for axis in range(3):
            a = np.zeros(6 * nn)
            a[axis::6] = 1.0
            fe = (block.matrices @ a).reshape(n_el, nn, 6)
            np.add.at(out[axis], block.nodes, fe)
    return out


def step_gravity(model, step, unit) -> tuple[np.ndarray, np.ndarray, Amplitude | None] | None:
    """Gravity loads of ``step``: (G at the step's start, G at its end, amplitude), each (n, 6) in
    N and N m, from the ``unit`` loads of :func:`unit_gravity_loads` (a callable returning them,
    called only when some step up to this one has gravity); None without gravity."""
    specs = []
    for s in model.steps:
        specs.append(getattr(s, "gravity_spec", None))
        if s is step:
            break
    if not any(sp is not None for sp in specs):
        return None
    before = [sp for sp in specs[:-1] if sp is not None]
    g0 = before[-1].g if before else np.zeros(3)
    spec = specs[-1]
    U = unit()
    G0 = np.tensordot(g0, U, axes=1)
    if spec is None:
        return G0, G0, None
    G1 = np.tensordot(spec.g, U, axes=1)
    if np.any(spec.g != 0.0) and not np.any(G1 != 0.0):
        raise ModelError(
            f"step '{step.name}': gravity on a model without mass. Give beam sections a density "
            "(section.with_(rho=...), kg/m^3), trusses/cables a mass_per_length (kg/m), or add "
            "model.point_mass(node, mass=...)"
        )
    return G0, G1, spec.amplitude


__all__ = ["GravitySpec", "unit_gravity_loads", "step_gravity", "G_MAX"]
