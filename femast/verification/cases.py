"""The verification cases of the FE core, as functions shared by the tests and the
``benchmarks/verification.py`` script.

Each case builds a model, solves it and returns a list of :class:`Check` rows
(quantity, reference, femast value, error) against the independent references in
:mod:`femast.verification.references`.  Units: the classic cases are dimensionless or in the units
of their source (Bathe-Bolourchi in consistent inch-pound units).
"""

from __future__ import annotations

import math
import tempfile
from dataclasses import dataclass

import numpy as np

from ..analysis import Analysis
from ..analysis.control import DisplacementControl
from ..model import Model
from ..model.sections import Section, square_tube
from . import references as ref


@dataclass
class Check:
    case: str
    quantity: str
    reference: float
    femast: float
    error: float  # as defined by ``measure``
    measure: str  # 'abs/L', 'rel', ...
    tolerance: float
    source: str

    @property
    def passed(self) -> bool:
        return self.error <= self.tolerance


def _out(name, out_dir):
    return f"{out_dir}/{name}" if out_dir else tempfile.mkdtemp(prefix=f"femast_{name}_")


def _unit_beam(EI=1.0, EA=1e4, GJ=1.0):
    """A section with given rigidities (E = 1e4 scaling keeps the numbers readable)."""
    E = 1.0e4
    return Section(E=E, G=E / 2.0, A=EA / E, Iy=EI / E, Iz=EI / E, J=2.0 * GJ / E, name="unit")


def _cantilever(n, L=1.0, section=None, up=(0.0, 1.0, 0.0)):
    m = Model("cantilever")
    root, tip = m.node(0.0, 0.0, 0.0), m.node(L, 0.0, 0.0)
    m.beam(root, tip, section or _unit_beam(), up=up, n=n)
    m.fix(root)
    return m, root, tip


def roll_up(n_elements=16, turns=1, out_dir=None, progress=False):
    """Cantilever (L = 1, EI = 1) under end moment M = 2 pi turns EI / L: a full circle
    (turns = 1) or wound twice (turns = 2); the tip returns to the root."""
    m, root, tip = _cantilever(n_elements)
    M = 2.0 * math.pi * turns
    m.step("roll", initial_increment=0.05 / turns, max_increment=0.1 / turns).load(tip, mz=M)
    res = Analysis(m, _out(f"rollup{turns}", out_dir), progress=progress).run()
    U = res.frame(-1)["U"]
    X = m.coordinates
    tip_pos = X[m.index(tip)] + U[m.index(tip)]
    rz = res.node_history(tip, "rz")[-1]
    case = f"roll-up {turns}x2pi, {n_elements} el."
    src = "closed form: circle of radius EI/M"
    return [
        Check(
            case,
            "distance tip-root / L",
            0.0,
            float(np.linalg.norm(tip_pos)),
            float(np.linalg.norm(tip_pos)),
            "abs/L",
            1e-3,
            src,
        ),
        Check(
            case,
            "tip rotation / (2 pi)",
            float(turns),
            rz / (2 * math.pi),
            abs(rz / (2 * math.pi) - turns),
            "abs",
            1e-9,
            src,
        ),
    ], res


def elastica(n_elements=20, loads=(1, 2, 3, 4, 5, 6, 7, 8, 9, 10), out_dir=None, progress=False):
    """Cantilever (L = 1, EI = 1, EA = 1e7: inextensible) under a dead transverse end load
    P = k EI / L^2, k = 1..10; tip displacements against the elliptic-integral elastica."""
    m, root, tip = _cantilever(n_elements, section=_unit_beam(EA=1e7))
    kmax = max(loads)
    step = m.step("load", initial_increment=0.05, max_increment=0.1, hit_times=[k / kmax for k in loads])
    step.load(tip, fy=-kmax)
    res = Analysis(m, _out("elastica", out_dir), progress=progress).run()
    lam = res.scalar_history("time")
    uy = -res.node_history(tip, "uy")
    ux = -res.node_history(tip, "ux")
    rows = []
    for k in loads:
        i = int(np.argmin(np.abs(lam * kmax - k)))
        exact = ref.elastica_tip_load(float(k))
        case = f"elastica PL^2/EI={k:g}, {n_elements} el."
        for name, fe, rv in (("v/L", uy[i], exact.v_over_L), ("u/L", ux[i], exact.u_over_L)):
            rows.append(
                Check(
                    case,
                    name,
                    rv,
                    float(fe),
                    abs(fe - rv) / abs(rv),
                    "rel",
                    5e-3,
                    "elliptic integrals (Mattiasson 1981)",
                )
            )
    return rows, res


def bend45(n_elements=16, out_dir=None, progress=False):
    """Bathe-Bolourchi 45-degree bend: R = 100, unit square section, E = 1e7, G = E/2, tip load
    along +Z up to 600; tip positions at 300, 450, 600 against a converged rod solution."""
    R, E = 100.0, 1.0e7
    sec = Section(E=E, G=E / 2.0, A=1.0, Iy=1.0 / 12, Iz=1.0 / 12, J=0.140577, name="unit square")
    m = Model("bend45")
    angles = np.linspace(0.0, math.pi / 4, n_elements + 1)
    labels = m.nodes(np.column_stack([R * (1 - np.cos(angles)), R * np.sin(angles), np.zeros_like(angles)]))
    for a, c in zip(labels[:-1], labels[1:]):
        m.beam(a, c, sec, up=(0.0, 0.0, 1.0))
    m.fix(labels[0])
    step = m.step("load", initial_increment=0.05, max_increment=0.1, hit_times=[0.5, 0.75])
    step.load(labels[-1], fz=600.0)
    res = Analysis(m, _out("bend45", out_dir), progress=progress).run()
    t = res.scalar_history("time")
    X = m.coordinates[-1]
    loads = (300.0, 450.0, 600.0)
    exact = ref.bend45_tip_position(loads)
    rows = []
    for j, P in enumerate(loads):
        i = int(np.argmin(np.abs(t * 600 - P)))
        pos = X + res.frame(i)["U"][m.index(labels[-1])]
        e = np.asarray(exact[j] if not isinstance(exact, dict) else exact[P])
        for c, name in enumerate("xyz"):
            rows.append(
                Check(
                    f"45-degree bend P={P:g}, {n_elements} el.",
                    f"tip {name}",
                    float(e[c]),
                    float(pos[c]),
                    abs(pos[c] - e[c]) / float(np.linalg.norm(e)),
                    "rel to |tip|",
                    1e-2,
                    "Kirchhoff rod shooting; Bathe-Bolourchi 1979",
                )
            )
    return rows, res


def linear_compliance(n_elements=4, L=3.651, out_dir=None):
    """Tip compliance of the Rocaspect paper's square-tube cantilever from the FE tangent at the
    undeformed state against the beam-theory compliance (the Rocaspect paper, Eq. 8, correct J)."""
    sec = square_tube(0.1, 0.094, E=2.1e11, nu=0.3)
    m, root, tip = _cantilever(n_elements, L=L, section=sec, up=(0.0, 1.0, 0.0))
    m.step("none")
    an = Analysis(m, _out("compliance", out_dir), progress=False)
    C_fe = np.linalg.inv(an.condensed_stiffness(tip))
    C = ref.cantilever_compliance(L, sec.E, sec.G, sec.A, sec.Iy, sec.Iz, sec.J)
    err = float(np.abs(C_fe - C).max() / np.abs(C).max())
    diag_err = float(np.max(np.abs(np.diag(C_fe) - np.diag(C)) / np.diag(C)))
    return [
        Check(
            f"square-tube cantilever compliance, {n_elements} el.",
            "max abs(C_fe - C) / max abs(C)",
            0.0,
            err,
            err,
            "rel",
            1e-8,
            "Rocaspect paper, Eq. 8 / beam theory",
        ),
        Check(
            f"square-tube cantilever compliance, {n_elements} el.",
            "diagonal terms",
            0.0,
            diag_err,
            diag_err,
            "rel",
            1e-8,
            "Rocaspect paper, Eq. 8 / beam theory",
        ),
    ], C_fe


def euler_column(n_elements=16, imperfection=1e-3, out_dir=None, progress=False):
    """Pinned-pinned column (L = 1, EI = 1) with a sinusoidal imperfection e0 = L/1000, driven
    by midspan deflection (displacement control) past the bifurcation.  P_cr from the
    Southwell plot of the pre-buckling points; the post-buckling load against the elastica."""
    L, EI = 1.0, 1.0
    m = Model("column")
    xs = np.linspace(0.0, L, n_elements + 1)
    labels = m.nodes(np.column_stack([xs, imperfection * L * np.sin(np.pi * xs / L), np.zeros_like(xs)]))
    sec = _unit_beam(EI=EI, EA=1e7)
    for a, c in zip(labels[:-1], labels[1:]):
        m.beam(a, c, sec, up=(0.0, 1.0, 0.0))
    m.fix(labels[0], "ux", "uy", "uz", "rx", "ry")
    m.fix(labels[-1], "uy", "uz", "rx", "ry")
    mid = labels[n_elements // 2]
    Pcr = ref.euler_critical_load(EI, L, "pinned-pinned")
    step = m.step("buckle", initial_increment=0.01, max_increment=0.02, control=DisplacementControl(mid, "uy", 0.3 * L))
    step.load(labels[-1], fx=-Pcr)
    res = Analysis(m, _out("column", out_dir), progress=progress).run()
    lam = res.scalar_history("load_factor")
    w = res.node_history(mid, "uy") + imperfection * L  # total deflection from the chord
    d = w - imperfection * L
    # Southwell: d / P = d / Pcr + e0 / Pcr  -> slope 1/Pcr (pre-buckling points, P < 0.9 Pcr)
    sel = (lam > 0.3) & (lam < 0.9)
    slope = np.polyfit(d[sel], d[sel] / (lam[sel] * Pcr), 1)[0]
    pcr_fe = 1.0 / slope
    rows = [
        Check(
            f"Euler column, e0=L/1000, {n_elements} el.",
            "P_cr (Southwell)",
            Pcr,
            pcr_fe,
            abs(pcr_fe - Pcr) / Pcr,
            "rel",
            1e-2,
            "pi^2 EI / L^2",
        )
    ]
    # post-buckling: at w_mid/L = 0.3 the elastica gives P/Pcr
    from scipy.optimize import brentq

    alpha = brentq(
        lambda a: ref.euler_column_postbuckling(a)[1] - w[-1] / L, 1e-3, 2.0
    )  # w(alpha) rises up to alpha ~ 2.3
    p_el = ref.euler_column_postbuckling(alpha)[0]
    rows.append(
        Check(
            f"Euler column, e0=L/1000, {n_elements} el.",
            "P/Pcr at w/L=0.3 (post-buckling)",
            p_el,
            float(lam[-1]),
            abs(lam[-1] - p_el) / p_el,
            "rel",
            1e-2,
            "elastica (Timoshenko & Gere)",
        )
    )
    return rows, res


def all_cases(out_dir=None, progress=False):
    rows = []
    for fn in (roll_up, elastica, bend45, linear_compliance, euler_column):
        rows += fn(out_dir=out_dir)[0] if fn is not roll_up else fn(out_dir=out_dir, progress=progress)[0]
    rows += roll_up(turns=2, out_dir=out_dir, progress=progress)[0]
    return rows


def format_table(rows) -> str:
    head = f"{'case':44} {'quantity':34} {'reference':>12} {'femast':>12} {'error':>10} {'tol':>8}  ok"
    lines = [head, "-" * len(head)]
    for r in rows:
        lines.append(
            f"{r.case:44.44} {r.quantity:34.34} {r.reference:12.6g} {r.femast:12.6g} {r.error:10.2e} "
            f"{r.tolerance:8.0e}  {'yes' if r.passed else 'NO'}"
        )
    return "\n".join(lines)
