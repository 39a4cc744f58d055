"""Built-in experiment ``vibration``: measured natural frequencies against the prestressed modal
analysis (Stohlman & Pellegrino, Sec. IV).

Data format
-----------
=============  ====  ===========================================================================
column         unit  meaning
=============  ====  ===========================================================================
mode           -     which mode the row measures: 1 = the lowest of the model, 2 the next...
f_Hz           Hz    measured natural frequency (compared channel)
pretension_N   N     optional: the pretension setting of the row (e.g. read on the mock bay
                     side's inline sensors); rows without it share one tension
load_N         N     optional: static load on the drive node along the drive direction before
                     the modes are taken (a weight hung on the latch, a preload)
t_s            s     optional time
=============  ====  ===========================================================================

Rows with the same (pretension, load) share one static state and one modal analysis.

Baseline model
--------------
By default the mock bay side of Stohlman & Pellegrino, Fig. 11 (:func:`femast.adam.vibration.mock_bay_side`:
the cable/pulley/latch assembly of an ADAM bay side, four ends anchored, the unit's point mass,
the cables' lumped mass), brought to equilibrium under the row's load, then its modes
(:func:`femast.modal.modal_analysis`); mode 1 is the latch's out-of-plane mode of Sec. IV.
Option ``builder``: a user's model instead, a callable
``builder(tension_N, unit_mass_kg, load_N, options) -> (femast Model, drive node label)`` (or the
path of a script defining ``build`` with that signature); its steps are run and the modes of the
last state compared.

Parameters (which ones are fitted: option ``fit``)
---------------------------------------------------
* ``pretension`` (N): the average cable tension; with a ``pretension_N`` column the row's tension
  is ``pretension_N x pretension / nominal_pretension_N`` (a calibration factor of the settings);
* ``unit_mass`` (kg): the point mass at the drive node (the latch unit).

The out-of-plane mode alone depends on T / m only: ``fit="pretension"`` (default: the deployed
mast, mass known, option ``unit_mass_kg``) or ``fit="mass"`` (the paper's calibration: tensions
known from the settings, option ``pretension_N`` for rows without a setting); ``fit="both"``
needs data that separates them (modes whose stiffness is not the tension's).

Hooks (where effects act)
-------------------------
* ``tension`` -- value (n_states,) N, the tensions of the static states;
* ``unit_mass`` -- value kg, the unit's point mass;
* ``model`` -- value the femast Model of one state before it is solved (ctx ``drive``: the drive
  node label, ``direction``: the drive direction), for effects that add elements.

Effects (:mod:`femast.effects.vibration`): ``pretension_loss`` (T -> T + dT0), ``added_mass``
(m -> m + added), ``joint_stick`` (a spring k_stick at the drive node).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from femast.analysis import Analysis
from femast.effects import load_script
from femast.errors import ModelError
from femast.experiments.core import Column, Experiment, Measured, Parameter, prepared
from femast.modal import modal_analysis

FITS = {"pretension": ("pretension",), "mass": ("unit_mass",), "both": ("pretension", "unit_mass")}


def _param_table(options):
    return {
        "pretension": Parameter(
            "pretension",
            "N",
            float(options["nominal_pretension_N"]),
            5.0,
            1000.0,
            "average cable tension (with pretension_N: the tension at the nominal setting)",
            scale=100.0,
        ),
        "unit_mass": Parameter(
            "unit_mass",
            "kg",
            float(options["unit_mass_kg"]),
            1e-5,
            10.0,
            "point mass of the unit at the drive node",
            scale=0.02,
        ),
    }


def _prepare(data: Measured, options: dict) -> dict:
    mode = data["mode"]
    if np.any(mode < 1) or np.any(mode != np.round(mode)):
        bad = int(np.flatnonzero((mode < 1) | (mode != np.round(mode)))[0])
        raise ModelError(
            f"{data.path} line {data.lines[bad]}, column 'mode': mode = {float(mode[bad]):g}; modes are whole numbers "
            ">= 1 (1 = the lowest mode of the model)"
        )
    setting = data["pretension_N"] if "pretension_N" in data else np.full(data.n, np.nan)
    load = data["load_N"] if "load_N" in data else np.zeros(data.n)
    key = np.column_stack([np.nan_to_num(setting, nan=-1.0), load])
    states, inverse = np.unique(key, axis=0, return_inverse=True)
    return {
        "mode": mode.astype(int),
        "setting": setting,
        "state_of_row": inverse.ravel(),
        "state_setting": np.where(states[:, 0] < 0, np.nan, states[:, 0]),
        "state_load": states[:, 1],
    }


def _builder(options):
    b = options.get("builder")
    if b is None:
        return None
    if callable(b):
        return b
    mod = load_script(b)
    fn = getattr(mod, "build", None)
    if not callable(fn):
        raise ModelError(
            f"vibration builder script {b} defines no function build(tension_N, unit_mass_kg, load_N, options)"
        )
    return fn


def _state_model(T, m, load, options):
    """(Model, drive node, direction) of one static state."""
    build = _builder(options)
    if build is not None:
        model, drive = build(T, m, load, options)
        direction = np.asarray(options["drive_direction"], float)
    else:
        from femast.adam.vibration import mock_bay_side

        side = mock_bay_side(T, options.get("bay"), m, options.get("cable_mass_kg_per_m"))
        model, drive, direction = side.model, side.unit, side.normal
    if load:
        if not model.steps:
            model.step("preload")
        d = direction / np.linalg.norm(direction)
        model.steps[-1].load(drive, fx=load * d[0], fy=load * d[1], fz=load * d[2])
    return model, drive, direction


def state_frequencies(T, m, load, n_modes, options, effects=None, ctx=None) -> np.ndarray:
    """Frequencies (Hz) of the lowest ``n_modes`` modes of one state (tension T N, unit mass m kg,
    load N)."""
    model, drive, direction = _state_model(T, m, load, options)
    if effects:
        model = effects.apply("model", model, drive=drive, direction=direction, **(ctx or {}))
    if not model.steps:
        model.step("state")
    an = Analysis(model, None, progress=False, on_frame=lambda d: None)
    an.run()
    return modal_analysis(an, n_modes, label=f"T = {T:.4g} N, load {load:.4g} N").frequencies


def model(params: dict, data: Measured, effects, options: dict) -> dict:
    """Frequencies (Hz) of every row's mode at its state (see the module docstring)."""
    prep = prepared(data, _prepare, options)
    P = float(params.get("pretension", options["nominal_pretension_N"]))
    m = float(params.get("unit_mass", options["unit_mass_kg"]))
    nominal = float(options["nominal_pretension_N"])
    s = prep["state_setting"]
    T = np.where(np.isnan(s), P, s * P / nominal)
    ctx = dict(data=data, options=options, params=params, prep=prep)
    if effects:
        T = np.asarray(effects.apply("tension", T, **ctx), float)
        m = float(effects.apply("unit_mass", m, **ctx))
    n_modes = int(prep["mode"].max())
    f = np.empty(data.n)
    for k in range(len(T)):
        rows = prep["state_of_row"] == k
        fk = state_frequencies(float(T[k]), m, float(prep["state_load"][k]), n_modes, options, effects, ctx)
        f[rows] = fk[prep["mode"][rows] - 1]
    return {"f_Hz": f}


def load_measure(data: Measured, options: dict) -> np.ndarray:
    """The pretension setting (N) if given, else the static load (N), else the measured frequency."""
    for c in ("pretension_N", "load_N"):
        if c in data:
            return data[c]
    return data["f_Hz"]


def plot_measured(ax, data: Measured, predicted: dict, params: dict, options: dict) -> None:
    """Measured and model frequencies against the setting (or row), one colour per mode."""
    x = data["pretension_N"] if "pretension_N" in data else np.arange(data.n)
    for j in np.unique(data["mode"]).astype(int):
        r = data["mode"] == j
        ax.plot(x[r], data["f_Hz"][r], "o", ms=4, color=f"C{j - 1}", label=f"measured, mode {j}")
        ax.plot(x[r], predicted["f_Hz"][r], "-", lw=1.2, color=f"C{j - 1}", label=f"model, mode {j}")
    ax.set_xlabel("pretension setting (N)" if "pretension_N" in data else "row")
    ax.set_ylabel("f (Hz)")
    ax.set_title("natural frequencies")
    ax.legend(fontsize=7)


OPTIONS = {
    "fit": "pretension",
    "nominal_pretension_N": 170.0,
    "unit_mass_kg": None,
    "builder": None,
    "drive_direction": (0.0, 1.0, 0.0),
    "bay": None,
    "cable_mass_kg_per_m": None,
}


@dataclass(frozen=True)
class VibrationExperiment(Experiment):
    """The ``vibration`` experiment: its fitted parameters follow the option ``fit``."""

    def __post_init__(self):
        from femast.adam.mass import UNIT_MASS

        opts = dict(self.options)
        if opts.get("unit_mass_kg") is None:
            opts["unit_mass_kg"] = UNIT_MASS
        fit = opts.get("fit")
        if fit not in FITS:
            raise ModelError(f"experiment vibration: option fit = {fit!r}; use one of {', '.join(FITS)}")
        for name in ("nominal_pretension_N", "unit_mass_kg"):
            v = opts[name]
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise ModelError(f"experiment vibration: option {name} = {v!r} must be a number > 0 (SI)")
        table = _param_table(opts)
        object.__setattr__(self, "options", opts)
        object.__setattr__(self, "parameters", tuple(table[n] for n in FITS[fit]))
        super().__post_init__()


EXPERIMENT = VibrationExperiment(
    name="vibration",
    title="natural frequencies against the prestressed modal analysis (Stohlman & Pellegrino, Sec. IV)",
    columns=(
        Column("mode", "-", "mode number, 1 = lowest of the model"),
        Column("f_Hz", "Hz", "measured natural frequency"),
        Column("pretension_N", "N", "pretension setting of the row", required=False),
        Column("load_N", "N", "static load on the drive node along the drive direction", required=False),
    ),
    channels=("f_Hz",),
    parameters=(),
    model=model,
    options=dict(OPTIONS),
    hooks={
        "tension": "T (n_states,) N: tension of each static state",
        "unit_mass": "m kg: point mass of the unit at the drive node",
        "model": "the femast Model of a state before it is solved (ctx: drive, direction)",
    },
    doc=__doc__,
    prepare=_prepare,
    load_measure=load_measure,
    load_label="pretension setting (N)",
    plot_measured=plot_measured,
    error_unit="Hz",
    min_rows=2,
    fit_options={"diff_step": 1e-4, "xtol": 1e-8, "ftol": 1e-8, "gtol": 1e-8, "max_nfev_per_param": 30},
    source="vibration",
)
