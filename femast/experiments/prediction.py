"""The prediction of a model variant along the measured path: the experiment's model with its
baseline parameters and the switched-on effects, group by group, with each group's offsets; the
residuals and the noise floor estimated from them.

:func:`predict` is what every fit (:mod:`~femast.experiments.fit_problem`,
:mod:`~femast.experiments.fitting`) evaluates; the parameter vector of a fit is laid out by
:func:`parameter_specs` and read back by :func:`split_parameters`.
"""

from __future__ import annotations

import numpy as np

from .. import progress
from ..effects.base import resolve
from ..errors import FemastError, ModelError
from .core import EffectStack, Experiment, Measured, effect_context
from .residuals import noise_floor

#: what a model may raise at a parameter set it cannot be evaluated at (an FE run that does not
#: converge, a singular matrix, a law outside its range): the set is skipped, the fit goes on
MODEL_FAILURES = (FemastError, ValueError, ArithmeticError, np.linalg.LinAlgError)


def parameter_specs(exp: Experiment, impls):
    """[(full name, Parameter, owner effect or None)] of the baseline and the effects."""
    specs = [(p.name, p, None) for p in exp.parameters]
    for name, impl in impls:
        specs += [(f"{name}.{p.name}", p, name) for p in impl.parameters]
    return specs


def split_parameters(specs, values):
    """``(baseline {name: value}, {effect: {name: value}})`` of the values of :func:`parameter_specs`."""
    base, eff = {}, {}
    for (_full, p, owner), v in zip(specs, values):
        if owner is None:
            base[p.name] = float(v)
        else:
            eff.setdefault(owner, {})[p.name] = float(v)
    return base, eff


def predict(exp: Experiment, data: Measured, params=None, effects=None) -> dict:
    """Predicted channels ``{channel: (n,) array}`` of a model variant.

    params : baseline parameters (defaults for those not given), SI.
    effects : ``{effect name: {param: value}}`` (missing effect parameters take their defaults)
        or a sequence of effect names (all defaults).
    """
    exp.require_model("the model")
    effects = effects or {}
    if not isinstance(effects, dict):
        effects = {name: {} for name in effects}
    impls = resolve(exp, list(effects))
    items = []
    for name, impl in impls:
        vals = {p.name: float(p.default) for p in impl.parameters}
        unknown = set(effects[name]) - set(vals)
        if unknown:
            raise ModelError(
                f"effect {name} on {exp.name} has no parameter(s) {', '.join(sorted(unknown))}; "
                f"its parameters: {', '.join(vals) or '(none)'}"
            )
        vals.update(effects[name])
        items.append((name, impl, vals))
    p = exp.defaults()
    unknown = set(params or {}) - set(p)
    if unknown:
        raise ModelError(f"{exp.name} has no parameter(s) {', '.join(sorted(unknown))}; its parameters: {', '.join(p)}")
    p.update(params or {})
    parts = data.group_subsets() or [(slice(None), data)]  # group by group: each starts from rest
    out = {c: np.empty(data.n) for c in exp.channels}
    for rows, part in parts:
        o = exp.model(p, part, EffectStack(items, effect_context(exp, part)), exp.options)
        missing = [c for c in exp.channels if c not in o]
        if missing:
            raise ModelError(f"the model of {exp.name} did not return channel(s) {', '.join(missing)}")
        for c in exp.channels:
            out[c][rows] = np.asarray(o[c], dtype=float).reshape(part.n)
    progress.tick()
    if data.offsets:
        out = with_offsets(exp, data, out)
    return out


def with_offsets(exp: Experiment, data: Measured, predicted: dict) -> dict:
    """``predicted`` plus a zero of its own for every group and channel (``data.offsets``): the mean
    of the channel's residual over the group -- each station re-zeroed, fitted in closed form."""
    out = {}
    groups = data.group_rows() or [("all", np.ones(data.n, bool))]
    for c in exp.channels:
        y = np.array(predicted[c], float)
        for _, rows in groups:
            y[rows] += np.mean(data[c][rows] - y[rows])
        out[c] = y
    return out


def n_offsets(exp: Experiment, data: Measured) -> int:
    """Parameters the offsets add (one per group and channel), counted in the information criterion."""
    return data.n_groups * len(exp.channels) if data.offsets else 0


def channel_residuals(exp: Experiment, data: Measured, predicted: dict) -> dict:
    """``{channel: measured - predicted}`` in the channel units."""
    return {c: data[c] - predicted[c] for c in exp.channels}


def estimate_noise(exp: Experiment, residuals: dict) -> dict:
    """Noise floor of every channel from its residual (:func:`~.residuals.noise_floor`), channel units.

    A channel whose estimate vanishes (noise-free data) gets 1e-9 of its residual scale (or 1e-12)
    so that whitening stays finite."""
    out = {}
    for c, r in residuals.items():
        s = noise_floor(r)
        floor = 1e-9 * max(float(np.max(np.abs(r))), 1e-3) if r.size else 1e-12
        out[c] = max(s, floor, 1e-300)
    return out
