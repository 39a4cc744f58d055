"""Shape accuracy of ADAM masts under manufacturing and assembly scatter: the
model factory of the studies in ``benchmarks/shape_accuracy.py`` (``docs/shape_accuracy.md``).

A sample is a dict of per-element values (the fields of :class:`~femast.adam.scatter.MastScatter`);
:func:`sample_scatter` draws them from the stated scatter :data:`SCATTER` given uniform numbers in
[0, 1) per *group* of inputs (so that a study can vary one group at a time for group sensitivity
indices); :func:`tip_history` builds the mast with them, brings it to its pretensioned equilibrium
(the deployed state, Stohlman & Pellegrino, Sec. II.C) and applies the Table 1 load cycles (Sec. VII), and
returns the tip (control node) position and rotation after deployment and at each load level.

Units: SI inside (m, rad, N); the returned ``u_*`` in m and ``theta_*`` in rad (rotation vector
of the control node, global axes).
"""

from __future__ import annotations

import time

import numpy as np

from ..errors import ModelError
from .build import build_mast
from .parameters import BayParameters
from .scatter import MastScatter
from .steps import CONVERGENCE, TABLE1_F, TABLE1_M, add_initial_steps, add_table1_steps

#: The stated scatter: every value uniform in [nominal - half, nominal + half],
#: independent from element to element.  (group, MastScatter field, kind, half width, unit)
#: kind "rel": half width relative to the nominal value; "abs": absolute (lengths, m).
SCATTER = (
    ("joint friction", "mu", "rel", 0.20, "-"),  # ball-joint mu 0.5 +- 20 % (Stohlman & Pellegrino assume 0.5)
    ("latch", "latch_k", "rel", 0.20, "N/m"),  # roller stiffness 100 N/mm +- 20 %
    ("latch", "latch_mu", "rel", 0.20, "-"),  # roller friction 0.07 +- 20 %
    ("pretension", "pretension", "rel", 0.10, "N"),  # 170 N +- 10 % per bay side
    ("member lengths", "longeron_dL", "abs", 0.05e-3, "m"),
    ("member lengths", "batten_dL", "abs", 0.05e-3, "m"),
    ("member lengths", "arm_dL", "abs", 0.05e-3, "m"),
    ("member lengths", "cable_dL", "abs", 0.05e-3, "m"),
)
GROUPS = tuple(dict.fromkeys(g for g, *_ in SCATTER))
#: The bay of the study (docs/shape_accuracy.md): femast.adam's defaults, seated ball joints (the
#: physical default).  ``params=BayParameters(seat="tied")`` runs it on the paper's two-way tie.
STUDY_PARAMS = BayParameters()


def n_uniforms(n_bays: int) -> dict:
    """{group: number of uniform numbers a sample of that group needs} for a mast of n_bays."""
    out = dict.fromkeys(GROUPS, 0)
    for g, field, *_ in SCATTER:
        out[g] += int(np.prod(MastScatter.shape(field, n_bays)))
    return out


def sample_scatter(
    u: dict, n_bays: int, params: BayParameters | None = None, scale: float = 1.0, groups=GROUPS
) -> dict:
    """Per-element values of one sample from uniform numbers ``u`` ({group: array in [0, 1) of
    :func:`n_uniforms` length}).  Groups not in ``groups`` stay nominal.  ``scale`` multiplies every
    half width (1: the stated scatter).  Returns a dict for :class:`MastScatter`."""
    p = params or BayParameters()
    nominal = {"mu": p.mu, "latch_k": p.latch.k, "latch_mu": p.latch.mu, "pretension": p.pretension}
    need = n_uniforms(n_bays)
    used = dict.fromkeys(GROUPS, 0)
    out = {}
    for g, field, kind, half, _unit in SCATTER:
        if g not in groups:
            continue
        arr = np.asarray(u[g], dtype=float).ravel()
        if arr.size != need[g] or not np.all((arr >= 0) & (arr <= 1)):
            raise ModelError(
                f"sample_scatter: group {g!r} needs {need[g]} uniform numbers in [0, 1] for "
                f"{n_bays} bays, got {arr.size}"
            )
        shape = MastScatter.shape(field, n_bays)
        k = int(np.prod(shape))
        x = 2.0 * arr[used[g] : used[g] + k].reshape(shape) - 1.0  # in [-1, 1]
        used[g] += k
        out[field] = (nominal[field] * (1.0 + scale * half * x)) if kind == "rel" else scale * half * x
    return out


def stated_inputs(n_bays: int, params: BayParameters | None = None, scale: float = 1.0) -> list:
    """The stated scatter (:data:`SCATTER`) as absolute uniform bounds for a mast of n_bays:
    [(group, field, low, high, size, unit)], ``size`` the number of elements of the field."""
    p = params or BayParameters()
    nominal = {"mu": p.mu, "latch_k": p.latch.k, "latch_mu": p.latch.mu, "pretension": p.pretension}
    out = []
    for g, field, kind, half, unit in SCATTER:
        size = int(np.prod(MastScatter.shape(field, n_bays)))
        if kind == "rel":
            lo, hi = nominal[field] * (1 - scale * half), nominal[field] * (1 + scale * half)
        else:
            lo, hi = -scale * half, scale * half
        out.append((g, field, float(lo), float(hi), size, unit))
    return out


def as_scatter(values: dict, n_bays: int) -> dict:
    """Flat per-element arrays (a study sample: one array per MastScatter field, any layout of the
    right size) reshaped to the fields' shapes."""
    out = {}
    for field, v in values.items():
        shape = MastScatter.shape(field, n_bays) if field in MastScatter.__dataclass_fields__ else None
        a = np.asarray(v, dtype=float)
        out[field] = a.reshape(shape) if shape is not None and a.size == int(np.prod(shape)) else a
    return out


def mast_model(n_bays: int, cycles: int = 1, params: BayParameters | None = None, **values):
    """The mast with per-element ``values`` (MastScatter fields, flat or shaped arrays) and its load
    history (pretension step, ``cycles`` Table 1 cycles): a :class:`~femast.model.Model` with steps,
    for a study's model factory.  Returns (model, control node label)."""
    am = build_mast(n_bays, params or STUDY_PARAMS, scatter=as_scatter(values, n_bays))
    add_initial_steps(am)
    add_table1_steps(am, cycles=cycles)
    return am.model, am.control


def tip_history(
    n_bays: int,
    values: dict | None = None,
    cycles: int = 1,
    params: BayParameters | None = None,
    M: float = TABLE1_M,
    F: float = TABLE1_F,
    settle: bool = True,
    increments: int = 1,
) -> dict:
    """Build the mast with per-element ``values`` (None: nominal), deploy (pretension step) and apply
    ``cycles`` Table 1 cycles (M+F, 0, -M-F, 0; M in N m about z, F in N along x).

    settle : after the stabilised pretension step, a step ``equilibrium`` without stabilisation
        (``add_initial_steps(settle=True)``): the deployed state is then the equilibrium itself.
        Without it the viscous stabilisation of the pretension step (scaled on the stiff ball-joint
        penalties) holds the soft bending modes of a scattered mast back: a scattered 40-bay mast
        ends 1.4 mm short of its deployed lateral tip offset of 7.2 mm, and the load steps after it
        (no stabilisation) then carry that relaxation into the "load-cycle residual".
    increments : increments per Table 1 step (the friction return is first order in the increment:
        more increments, a closer path).

    Returns {"labels": step names, "u": (n_levels, 3) m, "theta": (n_levels, 3) rad, "iterations",
    "cutbacks", "cpu_s", "settle_force"}: ``settle_force`` is the largest viscous force (N) left at the
    end of the ``equilibrium`` step (NaN without ``settle``), the deployed state's distance from
    equilibrium (the convergence test's force tolerance is ~0.01 N); level 0 is the deployed state (end of ``equilibrium``, or of ``pretension``
    without ``settle``), then one level per load step, all relative to the initial (design)
    geometry: the control node's displacement and rotation vector at the end of each step."""
    t0 = time.process_time()
    am = build_mast(n_bays, params or STUDY_PARAMS, scatter=None if values is None else as_scatter(values, n_bays))
    add_initial_steps(am, settle=settle)
    add_table1_steps(am, cycles=cycles, M=M, F=F, increments=increments)
    row = am.model.index(am.control)
    last = {}

    def keep(fr):
        last[str(fr["step"])] = (fr["U"][row].copy(), fr["URA"][row].copy())

    from ..analysis import Analysis

    an = Analysis(am.model, None, progress=False, convergence=CONVERGENCE, on_frame=keep)
    an.run()
    labels = [s.name for s in am.model.steps][1 if settle else 0 :]
    missing = [s for s in labels if s not in last]
    if missing:  # pragma: no cover - the analysis raises before
        raise ModelError(f"tip_history: steps {missing} did not finish")
    return {
        "labels": labels,
        "u": np.array([last[s][0] for s in labels]),
        "theta": np.array([last[s][1] for s in labels]),
        "iterations": an.summary.iterations,
        "cutbacks": an.summary.cutbacks,
        "cpu_s": time.process_time() - t0,
        "settle_force": float(an.summary.steps[1]["stabilization_force"]) if settle else float("nan"),
    }


__all__ = [
    "SCATTER",
    "GROUPS",
    "n_uniforms",
    "sample_scatter",
    "stated_inputs",
    "as_scatter",
    "mast_model",
    "tip_history",
]
