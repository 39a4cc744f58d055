"""Verification of the modal analysis against closed forms, shared by the tests and
``benchmarks/verification.py``.  Each case returns :class:`~femast.verification.Check` rows
(relative frequency errors) and the numbers behind them for the plots.

* taut string (Rayleigh, Theory of Sound sec. 123): f_n = n / (2 L) sqrt(T / m');
* cantilever beam (Euler-Bernoulli): f_i = (beta_i L)^2 / (2 pi) sqrt(EI / (m L^4)),
  beta_i L = 1.87510, 4.69409, 7.85476 (roots of cos x cosh x = -1);
* pin-ended beam under axial force P (tension > 0; Timoshenko & Young, Vibration Problems in
  Engineering, sec. 5.13): f_1^2 = f_0^2 (1 + P / P_E), P_E = pi^2 EI / L^2, f_0 =
  (pi / (2 L^2)) sqrt(EI / m): f^2 linear in P, zero at the Euler load;
* rigid body on springs: a body (mass m, principal inertias J) whose reference node carries
  four arms of length a along +-x, +-y, each held by three springs k along x, y, z:
  omega^2 = 4 k / m (three translations), 2 k a^2 / J_x, 2 k a^2 / J_y, 4 k a^2 / J_z;
* pendulum: a point mass hanging on a string of length l under its weight: omega^2 = g / l
  (the whole restoring stiffness is the stress stiffness of the string's tension).
"""

from __future__ import annotations

import math

import numpy as np

from ..analysis import Analysis
from ..modal import modal_analysis
from ..model import Model
from ..model.sections import Section
from .cases import Check

BETA_L = (1.8751040687, 4.6940911330, 7.8547574382)  # roots of cos x cosh x + 1 = 0


def _analysis(model, run=True):
    a = Analysis(model, None, progress=False, on_frame=lambda d: None)
    if run:
        a.run()
    return a


def _rel(a, b):
    return abs(a - b) / abs(b)


def taut_string(n_elements=100, L=2.0, T=100.0, mass_per_length=0.01, cable=True, n_modes=3):
    """String of ``n_elements`` (cables: lumped mass; trusses: consistent), pretension T (N),
    fixed ends.  Each transverse mode appears twice (y and z); the pair's mean is compared.
    Discretisation error: lumped -(n pi h / L)^2 / 24, consistent +(...)^2 / 24 relative (h the
    element length): 3.7e-4 for mode 3 of 100 elements, within the 1e-3 asked."""
    m = Model("taut string")
    nodes = [m.node(L * k / n_elements, 0.0, 0.0) for k in range(n_elements + 1)]
    for p, q in zip(nodes[:-1], nodes[1:]):
        m.truss(p, q, EA=1e7, pretension=T, mass_per_length=mass_per_length, tension_only=cable)
    m.fix(nodes[0])
    m.fix(nodes[-1])
    m.step("hold")
    modes = modal_analysis(_analysis(m, run=False), 2 * n_modes)
    f = modes.frequencies.reshape(n_modes, 2).mean(axis=1)
    kind = "cable, lumped" if cable else "truss, consistent"
    rows = []
    for n in range(1, n_modes + 1):
        ref = n / (2 * L) * math.sqrt(T / mass_per_length)
        rows.append(
            Check(
                f"taut string ({n_elements} {kind})",
                f"f_{n} (Hz)",
                ref,
                float(f[n - 1]),
                _rel(f[n - 1], ref),
                "rel",
                1e-3,
                "f_n = n/(2L) sqrt(T/m')",
            )
        )
    return rows, modes


def cantilever(n_elements=20, L=1.0, EI=1.0, m=1.0, n_modes=3):
    """Cantilever (E-B beam, consistent mass), Iy = Iz so bending modes come in pairs.
    Tolerance 1e-4: the cubic element's error is O((beta h)^4), 3e-6 for mode 3 with 20 elements."""
    E = 1e4
    sec = Section(E=E, G=E / 2, A=1.0, Iy=EI / E, Iz=EI / E, J=2 * EI / E, rho=m, name="unit")
    mod = Model("cantilever")
    root, tip = mod.node(0.0, 0.0, 0.0), mod.node(L, 0.0, 0.0)
    mod.beam(root, tip, sec, up=(0, 1, 0), n=n_elements)
    mod.fix(root)
    mod.step("hold")
    modes = modal_analysis(_analysis(mod, run=False), 2 * n_modes)
    f = modes.frequencies.reshape(n_modes, 2).mean(axis=1)
    rows = []
    for i in range(n_modes):
        ref = BETA_L[i] ** 2 / (2 * math.pi) * math.sqrt(EI / (m * L**4))
        rows.append(
            Check(
                f"cantilever ({n_elements} beams)",
                f"f_{i + 1} (Hz)",
                ref,
                float(f[i]),
                _rel(f[i], ref),
                "rel",
                1e-4,
                "(beta L)^2/(2 pi) sqrt(EI/(m L^4))",
            )
        )
    return rows, modes


def pinned_beam_axial(load_ratios=(-1.2, -0.8, -0.4, 0.0, 0.4, 0.8), n_elements=48, L=1.0, EI=1.0, m=1.0, EA=1e6):
    """Pin-ended beam along x under an axial end force P = ratio x P_E (negative: compression),
    solved statically (the straight state), then its first bending mode.  Returns rows for
    f^2 (signed) at every load, the Euler load where the fitted line crosses zero, and
    (ratios, f^2 femast, f^2 exact).  Tolerance 1e-3 of f_0^2.  The corotational beam's stress
    stiffness is the chord rotation term N/l only (its local beam is linear), so its Euler load
    converges as O(h^2): P_E,h / P_E - 1 ~ (pi h / L)^2 / 12 = 3.6e-4 with 48 elements (3.2e-3
    with 16), against 1e-5 for the mass and bending parts and 1e-6 for the shortening P / EA."""
    E = 1e4
    sec = Section(E=E, G=E / 2, A=EA / E, Iy=EI / E, Iz=EI / E, J=2 * EI / E, rho=m * E / EA, name="unit")
    PE = math.pi**2 * EI / L**2
    f0sq = (math.pi / (2 * L**2)) ** 2 * EI / m
    f2 = []
    for r in load_ratios:
        mod = Model("pinned beam")
        a, b = mod.node(0.0, 0.0, 0.0), mod.node(L, 0.0, 0.0)
        mod.beam(a, b, sec, up=(0, 1, 0), n=n_elements)
        mod.fix(a, "ux", "uy", "uz", "rx")
        mod.fix(b, "uy", "uz")
        mod.step("axial").load(b, fx=r * PE)
        modes = modal_analysis(_analysis(mod), 2)
        f = float(modes.frequencies[:2].mean())
        f2.append(math.copysign(f * f, f))
    f2 = np.array(f2)
    ratios = np.asarray(load_ratios, float)
    exact = f0sq * (1 + ratios)
    rows = [
        Check(
            f"pin-ended beam ({n_elements} beams)",
            f"f^2 at P = {r:+.1f} P_E (Hz^2)",
            float(e),
            float(v),
            abs(v - e) / f0sq,
            "abs/f0^2",
            1e-3,
            "f^2 = f0^2 (1 + P/P_E)",
        )
        for r, v, e in zip(ratios, f2, exact)
    ]
    slope, icpt = np.polyfit(ratios, f2, 1)
    rows.append(
        Check(
            f"pin-ended beam ({n_elements} beams)",
            "P(f = 0) / P_E (fitted line)",
            -1.0,
            float(-icpt / slope),
            abs(-icpt / slope + 1.0),
            "abs",
            1e-3,
            "Euler load pi^2 EI/L^2",
        )
    )
    return rows, (ratios, f2, exact)


def rigid_body_springs(m=2.0, J=(0.3, 0.5, 0.8), a=0.4, k=5.0e3):
    """Rigid body (reference node with mass m kg and inertias J kg m^2; four arm nodes) on twelve
    springs; all six modes against the closed forms.  Tolerance 1e-8: the case is exact (no
    discretisation), the springs' axial strain under the vibration is linear."""
    mod = Model("rigid body on springs")
    ref = mod.node(0.0, 0.0, 0.0)
    arms = [mod.node(*p) for p in ((a, 0, 0), (-a, 0, 0), (0, a, 0), (0, -a, 0))]
    h = 0.5
    for nd in arms:
        p = mod.xyz(nd)
        for d in np.eye(3):
            g = mod.node(*(p + h * d))
            mod.truss(nd, g, EA=k * h)
            mod.fix(g)
    mod.rigid_body(ref, arms, name="body", mass=m, inertia=J)
    mod.step("hold")
    modes = modal_analysis(_analysis(mod, run=False), 6)
    om2 = {
        "translation (x3)": 4 * k / m,
        "rocking about x": 2 * k * a * a / J[0],
        "rocking about y": 2 * k * a * a / J[1],
        "rocking about z": 4 * k * a * a / J[2],
    }
    exact = np.sort(
        np.array(
            [om2["translation (x3)"]] * 3 + [om2["rocking about x"], om2["rocking about y"], om2["rocking about z"]]
        )
    )
    ref_f = np.sqrt(exact) / (2 * math.pi)
    rows = [
        Check(
            "rigid body on springs",
            f"f_{i + 1} (Hz)",
            float(r),
            float(f),
            _rel(f, r),
            "rel",
            1e-8,
            "omega^2 = 4k/m, 2ka^2/Jx, 2ka^2/Jy, 4ka^2/Jz",
        )
        for i, (r, f) in enumerate(zip(ref_f, modes.frequencies))
    ]
    return rows, modes


def pendulum(l=1.5, mass=3.0, g=9.81):
    """A point mass hanging on a string loaded by its weight (the string drawn at the length it
    has under the weight, ``pretension = m g``, so the initial state is only out of balance until
    the load step): the two swinging modes omega^2 = g / l.  Tolerance 1e-8: exact but for the
    Newton tolerance of the static state."""
    mod = Model("pendulum")
    top, bob = mod.node(0.0, 0.0, 0.0), mod.node(0.0, 0.0, -l)
    mod.truss(top, bob, EA=1e7, pretension=mass * g, tension_only=True)
    mod.fix(top)
    mod.point_mass(bob, mass)
    mod.step("weight").load(bob, fz=-mass * g)
    modes = modal_analysis(_analysis(mod), 2)
    ref = math.sqrt(g / l) / (2 * math.pi)
    return [
        Check(
            "pendulum (string + point mass)",
            f"f_{i + 1} (Hz)",
            ref,
            float(f),
            _rel(f, ref),
            "rel",
            1e-8,
            "omega^2 = g/l",
        )
        for i, f in enumerate(modes.frequencies)
    ], modes


def all_cases():
    rows = []
    for case in (
        taut_string,
        lambda: taut_string(cable=False),
        cantilever,
        pinned_beam_axial,
        rigid_body_springs,
        pendulum,
    ):
        rows += case()[0]
    return rows
