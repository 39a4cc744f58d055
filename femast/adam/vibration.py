"""Stohlman & Pellegrino's pretension-by-vibration method (Sec. IV, Eq. 16) reproduced with the modal analysis.

The mock bay side (Stohlman & Pellegrino, Fig. 11) holds one cable/pulley/latch assembly in the geometry of a bay
side: the latch cable from one bottom corner through the unit (pulley and latch) to the other,
and the two arms from the unit to the top corners, all four anchored.  A shaker drives the unit
out of the plane of the side; the resonance gives the average cable tension through Eq. 16.

**Eq. 16 as printed is inconsistent.**  ``T = 0.012 w^2 - 0.58 w + 17`` with w in Hz gives
30-47 "N" over the 65-80 Hz of Fig. 14, whose axis spans 130-210 N; with w in rad/s it gives
1.8-2.7 kN.  Read with w in Hz and T in **pound-force** (the mock bay's inline sensors are
+-250 lbf units) it gives 133-211 N over 65-80 Hz, Fig. 14's data, and places the peaks of Fig.
13 (125-188 N) at 63-76 Hz, inside its 55-85 Hz axis.  femast therefore uses

    T [N] = 4.44822 (0.012 f^2 - 0.58 f + 17),   f in Hz,

and reads the fit's "standard deviation of 2 N" as 2 lbf = 8.9 N (deviations are reported
against both).  :func:`eq16_printed` keeps the formula as printed.

The physics: the unit (effective mass m) on four taut sections of lengths L_i and tensions T_i
has the out-of-plane stiffness sum T_i / L_i (the stress stiffness; the cables' bending is
nil), so f^2 = sum(T_i / L_i) / (4 pi^2 m): T = c f^2 for the average tension.  Eq. 16 is a
quadratic with a linear term; over 120-200 N the best c f^2 differs from it by at most 3.9 N
(RMS 2.0 N), inside its 8.9 N scatter.  The effective mass is therefore identified from the
Eq. 16 curve (:func:`identify_unit_mass`) with the FE model of the side: the cables' own mass
(lumped at the section ends) is in the model, the unit's point mass is what is fitted.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar

from ..analysis import Analysis
from ..elements.cable_latch import CableLatchFamily
from ..errors import ModelError
from ..modal import modal_analysis
from ..model import Model
from .build import corner_xy
from .mass import UNIT_MASS, cable_mass_per_length
from .parameters import BayParameters

LBF = 4.4482216152605  # N per pound-force
EQ16 = (0.012, -0.58, 17.0)  # coefficients as printed (f in Hz; the result in lbf, see module)
EQ16_SD_N = 2.0 * LBF  # the fit's standard deviation, 2 (lbf), in N
EQ16_RANGE_N = (120.0, 200.0)  # average tensions of the comparison (Stohlman & Pellegrino, Figs. 13-14: 125-210 N)
ARM_FAMILY = "mock_arm"
LATCH_FAMILY = "mock_latch"


def eq16_printed(f_hz):
    """Stohlman & Pellegrino, Eq. 16 exactly as printed: 0.012 f^2 - 0.58 f + 17 (f in Hz; see module)."""
    f = np.asarray(f_hz, dtype=float)
    a, b, c = EQ16
    return a * f * f + b * f + c


def eq16_tension(f_hz):
    """Average cable tension (N) from the resonant frequency (Hz): Eq. 16 read in lbf (module)."""
    return LBF * eq16_printed(f_hz)


def eq16_frequency(tension_n):
    """Inverse of :func:`eq16_tension` on its rising branch (f > 24 Hz): frequency in Hz."""
    a, b, c = EQ16
    t = np.asarray(tension_n, dtype=float) / LBF
    disc = b * b - 4 * a * (c - t)
    if np.any(disc < 0):
        raise ModelError(
            f"eq16_frequency: tension {tension_n!r} N is below Eq. 16's minimum ({LBF * (c - b * b / (4 * a)):.1f} N)"
        )
    return (-b + np.sqrt(disc)) / (2 * a)


@dataclass
class MockSide:
    """The mock bay side model and where things are in it."""

    model: Model
    unit: int
    corners: tuple
    lengths: np.ndarray  # (4,) initial section lengths, m (latch cable 2, arms 2)
    normal: np.ndarray  # unit normal of the side (out-of-plane direction)


def mock_bay_side(
    tension: float = 170.0,
    params: BayParameters | None = None,
    unit_mass: float = UNIT_MASS,
    cable_mass: float | None = None,
) -> MockSide:
    """Stohlman & Pellegrino, Fig. 11: side 0 of an ADAM bay (``params``: b, l, cable EA, latch) with the latch cable
    and both arms pretensioned to ``tension`` (N), the four ends anchored, a point mass
    ``unit_mass`` (kg) at the unit and the cables' mass ``cable_mass`` (kg/m; default steel,
    :func:`femast.adam.mass.cable_mass_per_length`) lumped at the section ends."""
    p = params or BayParameters()
    if not (math.isfinite(tension) and tension > 0):
        raise ModelError(f"mock_bay_side: tension = {tension!r} N must be > 0")
    cm = cable_mass_per_length(p.cable_EA) if cable_mass is None else float(cable_mass)
    xy = corner_xy(p.b)
    m = Model("mock bay side")
    B0, B1 = m.node(xy[0, 0], xy[0, 1], 0.0), m.node(xy[1, 0], xy[1, 1], 0.0)
    T0, T1 = m.node(xy[0, 0], xy[0, 1], p.l), m.node(xy[1, 0], xy[1, 1], p.l)
    centre = 0.25 * (m.xyz(B0) + m.xyz(B1) + m.xyz(T0) + m.xyz(T1))
    u = m.node(*centre)
    stretch = 1.0 + tension / p.cable_EA
    seq = (B1, u, B0)  # as build_mast for fold = +1 (section 2 on the lengthening diagonal)
    LA = float(np.linalg.norm(m.xyz(u) - m.xyz(B1)))
    LB = float(np.linalg.norm(m.xyz(B0) - m.xyz(u)))
    x0 = -p.latch.x_backstop
    fam = CableLatchFamily(
        np.array([seq], dtype=np.int64),
        EA=p.cable_EA,
        L0=(LA + LB) / stretch,
        latch_node=1,
        bead=LA / stretch + x0,
        latch=p.latch,
        x0=x0,
        name=LATCH_FAMILY,
    )
    fam.mass_per_length = cm
    m.add_family(fam)
    arms = [float(np.linalg.norm(m.xyz(t) - m.xyz(u))) for t in (T0, T1)]
    for t in (T0, T1):
        m.truss(u, t, EA=p.cable_EA, pretension=tension, tension_only=True, family=ARM_FAMILY, mass_per_length=cm)
    for c in (B0, B1, T0, T1):
        m.fix(c)
    if unit_mass > 0:
        m.point_mass(u, unit_mass, name="latch unit")
    m.step("settle")
    return MockSide(m, u, (B0, B1, T0, T1), np.array([LA, LB] + arms), np.array([0.0, 1.0, 0.0]))


def latch_resonance(side: MockSide):
    """(out-of-plane frequency of the unit, Hz; average tension of the four sections, N; Modes)
    of a mock side, after its static equilibrium step."""
    last = {}
    an = Analysis(side.model, None, progress=False, on_frame=last.update)
    an.run()
    tensions = np.concatenate(
        [np.asarray(last[f"el/{LATCH_FAMILY}/tension"]).ravel(), np.asarray(last[f"el/{ARM_FAMILY}/N"]).ravel()]
    )
    modes = modal_analysis(an, 3, label="mock bay side")
    row = int(np.flatnonzero(modes.node_labels == side.unit)[0])
    oop = np.abs(modes.shapes[:, row, :3] @ side.normal)
    k = int(np.argmax(oop))
    return float(modes.frequencies[k]), float(tensions.mean()), modes


@dataclass
class UnitMassFit:
    """Result of :func:`identify_unit_mass` (SI)."""

    unit_mass: float  # kg, the unit's point mass (the cables' mass is in the model)
    effective_mass: float  # kg, unit + cable mass seen at the unit: sum(T_i/L_i) / (2 pi f)^2
    tension: np.ndarray  # model average tensions, N
    frequency: np.ndarray  # model frequencies, Hz
    eq16: np.ndarray  # Eq. 16 (lbf reading) at the model frequencies, N
    max_dev: float  # N
    rms_dev: float  # N
    sigma_unit_mass: float  # kg, from the Eq. 16 scatter (EQ16_SD_N over n_points)
    n_points: int = 9

    @property
    def deviation(self) -> np.ndarray:
        """Model tension - Eq. 16 tension at the same frequency, N."""
        return self.tension - self.eq16


def identify_unit_mass(
    params: BayParameters | None = None,
    tensions=None,
    cable_mass: float | None = None,
    n_points: int = 9,
    reference_mass: float = UNIT_MASS,
) -> UnitMassFit:
    """Fit the unit's mass so that the FE mock side's (tension, frequency) curve matches Eq. 16
    (lbf reading) in the least-squares sense over ``tensions`` (N; default 9 settings across
    120-200 N, like the paper's 9 points).  The FE model is solved once per tension with
    ``reference_mass``; the fit scales its frequencies (at fixed tension f^2 M_total is fixed; the
    cable share of M_total is found from two masses)."""
    T_set = np.linspace(*EQ16_RANGE_N, n_points) if tensions is None else np.asarray(tensions, float)
    f_ref, T_avg = [], []
    for T in T_set:
        f, Ta, _ = latch_resonance(mock_bay_side(T, params, reference_mass, cable_mass))
        f_ref.append(f)
        T_avg.append(Ta)
    f_ref, T_avg = np.array(f_ref), np.array(T_avg)
    # the cables' mass seen by the mode: from a second unit mass at the middle tension
    j = len(T_set) // 2
    f2, _, _ = latch_resonance(mock_bay_side(T_set[j], params, 2 * reference_mass, cable_mass))
    # f^2 (m_u + m_c) = const:  f1^2 (m + mc) = f2^2 (2 m + mc)
    r = (f_ref[j] / f2) ** 2
    m_c = reference_mass * (2 - r) / (r - 1)

    def freq(mu):
        return f_ref * np.sqrt((reference_mass + m_c) / (mu + m_c))

    def cost(mu):
        return float(np.sum((T_avg - eq16_tension(freq(mu))) ** 2))

    # Eq. 16 falls again below 24 Hz: a coarse grid picks the basin on its rising branch first
    grid = np.geomspace(1e-4, 0.5, 400)
    i = int(np.argmin([cost(g) for g in grid]))
    res = minimize_scalar(
        cost, bounds=(grid[max(i - 1, 0)], grid[min(i + 1, grid.size - 1)]), method="bounded", options={"xatol": 1e-10}
    )
    mu = float(res.x)
    f = freq(mu)
    dev = T_avg - eq16_tension(f)
    # sensitivity of the tension to the mass at a fixed frequency: dT/dm = T/(m + m_c)
    m_eff = mu + m_c
    sigma = m_eff * EQ16_SD_N / float(np.mean(T_avg)) / math.sqrt(len(T_set))
    return UnitMassFit(
        unit_mass=mu,
        effective_mass=m_eff,
        tension=T_avg,
        frequency=f,
        eq16=eq16_tension(f),
        max_dev=float(np.abs(dev).max()),
        rms_dev=float(np.sqrt(np.mean(dev**2))),
        sigma_unit_mass=sigma,
        n_points=len(T_set),
    )


def tension_from_frequency(f_hz, fit: UnitMassFit, sigma_f_hz: float = 0.0):
    """Average cable tension (N) and its standard uncertainty (N) from a measured resonance
    ``f_hz`` (Hz, +- ``sigma_f_hz``) with the identified model: T = c f^2 through the fit's
    points (c from the model curve), uncertainty from the frequency (2 T sigma_f / f), the
    identified mass (T sigma_m / m_eff) and the calibration scatter (EQ16_SD_N)."""
    f = np.asarray(f_hz, dtype=float)
    if np.any(~np.isfinite(f)) or np.any(f <= 0):
        raise ModelError(f"tension_from_frequency: frequency {f_hz!r} Hz must be finite and > 0")
    c = float(np.sum(fit.tension * fit.frequency**2) / np.sum(fit.frequency**4))
    T = c * f * f
    sigma = np.sqrt((2 * T * sigma_f_hz / f) ** 2 + (T * fit.sigma_unit_mass / fit.effective_mass) ** 2 + EQ16_SD_N**2)
    return T, sigma
