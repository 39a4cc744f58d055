"""The Experiment contract: columns, parameters, a model with hooks for effects, measured data.

An :class:`Experiment` pairs a measured data format (its :class:`Column` s) with a model
function and the model's fittable :class:`Parameter` s.  The model is called as::

    predicted = experiment.model(params, data, effects, options)

* ``params``  -- dict of baseline parameter values (SI units, names of ``experiment.parameters``);
* ``data``    -- the :class:`Measured` data (columns in the units of their names, e.g. ``x_mm``);
* ``effects`` -- an :class:`EffectStack`; the model passes its intermediate quantities through
  ``effects.apply(hook, value, **ctx)`` at the points named in ``experiment.hooks``, which is how
  a physical effect (``femast.effects``) changes the model without the model knowing it;
* ``options`` -- dict of geometry and other non-fitted settings (``experiment.options``).

It returns a dict ``{channel: (n,) array}`` with one predicted value per row for every name in
``experiment.channels``, in the units of the channel's column name.  Everything else (fits,
noise floor, segmentation, ranking of effects, figures, history) is generic.

The built-in experiments are rigs written against this contract, one module each in
:mod:`femast.rigs`; a user adds one from a Python script that defines a module-level
``experiment`` (see ``docs/experiments.md``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from .._moved import renamed
from ..effects.parameters import Parameter  # noqa: F401  (re-exported: experiments declare Parameters)
from ..effects.quantities import HOOKS, check_quantities
from ..errors import ModelError
from .measured import Measured


@dataclass(frozen=True)
class Column:
    """A column of a data file: ``name`` carries the unit as a suffix (``fx_N``, ``x_mm``).

    unit : the unit of the values in the file.  doc : what is measured, frame and sign.
    required : False for optional columns (missing means "not measured").
    codes : ``((text, value), ...)`` words a data file may write instead of the number (e.g. the
        loaded side of a latch pull test, ``("out", 1.0), ("in", -1.0)``); values are stored as floats.
    """

    name: str
    unit: str
    doc: str = ""
    required: bool = True
    codes: tuple = ()


#: Optional time column accepted by every experiment (s); without it time is the row index.
TIME_COLUMN = Column("t_s", "s", "time of the sample (optional; rows must be in time order)", required=False)
#: Optional group column accepted by every experiment: the station, specimen or run of each row (any label).
GROUP_COLUMN = Column(
    "group", "-", "group of the row: a station, specimen or test run (optional; any label)", required=False
)


@dataclass(frozen=True)
class Experiment:
    """A measured data format, a model and its parameters (see the module docstring).

    name : registry name (``mast-top``).  title : one line.  doc : data format and model.
    columns : every accepted column (required and optional; ``t_s`` is always accepted).
    channels : the columns the model predicts and that are compared (subset of ``columns``).
    parameters : fittable baseline parameters.
    model : ``model(params, data, effects, options) -> {channel: array}``; None while the
        experiment is *pending a model* (its data format is defined, compare/diagnose refuse it).
    options : non-fitted settings (geometry...) with their defaults; a user changes them with
        :func:`femast.experiments.get_experiment` ``(name, **options)``.
    hooks : ``{hook name: description}`` of the points where the model calls
        ``effects.apply``; an effect implementation names one of them.
    prepare : optional ``prepare(data, options) -> dict`` of per-data-set quantities, cached in
        ``data.cache`` (e.g. joint moments, directions of motion).
    initial_guess : optional ``initial_guess(data, options) -> {param: value}`` start of a fit.
    load_measure : optional ``load_measure(data, options) -> (n,) signed load`` (or (n, k) on several
        axes: taken along its principal direction) that drives the
        segmentation (loading, unloading, reversals, near-zero load, peaks); default: the first
        required non-channel column.
    load_label : name and unit of the load measure, for reports.
    extra_segments : optional ``extra_segments(data, params, options) -> [(kind, mask)]`` of
        experiment-specific path segments (e.g. the latch zones of Stohlman & Pellegrino, Fig. 6).
    plot_measured : optional ``plot_measured(ax, data, predicted, params, options)`` drawing the
        measured-against-model panel of the compare figure (default: channels against row).
    channel_weights : factors converting each channel to ``error_unit`` for the overall RMS
        (default 1: all channels already in ``error_unit``).
    error_unit : unit of the overall RMS error.
    min_rows : fewest data rows accepted.
    effects_from : name of the experiment whose effect implementations apply (default: own name;
        a variant of ``mast-top`` sets ``effects_from="mast-top"`` to inherit its effects).
    fit_options : settings of :func:`scipy.optimize.least_squares` for this model, overriding the
        defaults of :func:`~femast.experiments.fitting.fit` (``xtol = ftol = gtol = 1e-10``, 2-point
        differences with scipy's default step, ``max_nfev = 100 (p + 1)``).  An expensive model
        (the FE experiments: about a second per evaluation) sets looser tolerances, a forward
        difference step ``diff_step`` (``step x max(1, |u|)`` in the parameters scaled by their
        ``typical`` size, never smaller, so also at an effect's zero default) larger than the
        convergence noise of its solver, and a lower ``max_nfev_per_param`` (``max_nfev = that x
        (p + 1)``).  ``expensive: True`` makes ``diagnose`` refit in parallel by default even when
        the baseline fit was fast (its runs came from a cache); with ``diff_step`` it also makes the
        fit save runs (secant Jacobians, seeded refits, positive parameters spanning two decades in
        log scale: :func:`~femast.experiments.fitting.fit`).
    source : where it came from (a built-in name or a script path), set by the registry.
    noise_covariates : optional ``noise_covariates(data, params, options, fit) -> {channel: {name:
        (n,) array}}`` of quantities the noise level of a channel may grow with, because of how
        the data are measured (latch-pull: the slope of the law, Stohlman & Pellegrino, Eq. 15); the noise model
        of ``diagnose`` (:mod:`femast.experiments.noise`) tests them.
    path_coordinate : optional ``path_coordinate(data, options) -> (n,)`` the quantity the test
        drives along its passes (latch-pull: the bead position), whose repeated passes give the
        noise model a model-free level (:func:`~femast.experiments.noise.cycle_scatter`); default:
        the load measure.

    quantities : ``{kind: Quantity}`` the physical quantities the model shows to effects
        (:mod:`femast.effects.quantities`): ``"load"`` and ``"displacement"`` (the model passes them
        through ``effects.apply("load", ...)`` and ``effects.apply("displacement", ...)``),
        ``"temperature"`` (a data column).  Every effect whose mechanism acts on quantities the
        experiment declares applies to it, the library's and the user's alike.
    renamed_options : ``{old name: new name}`` of options renamed: :meth:`with_options` takes the old
        name for one release, with a DeprecationWarning naming the new one.

    Every channel ``c`` also accepts an optional column ``sigma_c`` (same unit) with the standard
    uncertainty of each row; ``diagnose`` then uses it as the noise of that channel.
    """

    name: str
    title: str
    columns: tuple
    channels: tuple
    parameters: tuple = ()
    model: Callable | None = None
    options: dict = field(default_factory=dict)
    hooks: dict = field(default_factory=dict)
    doc: str = ""
    prepare: Callable | None = None
    initial_guess: Callable | None = None
    load_measure: Callable | None = None
    load_label: str = "load"
    extra_segments: Callable | None = None
    plot_measured: Callable | None = None
    channel_weights: dict = field(default_factory=dict)
    error_unit: str = ""
    min_rows: int = 10
    effects_from: str | None = None
    fit_options: dict = field(default_factory=dict)
    source: str = ""
    noise_covariates: Callable | None = None
    path_coordinate: Callable | None = None
    quantities: dict = field(default_factory=dict)
    renamed_options: dict = field(default_factory=dict)

    def __post_init__(self):
        names = [c.name for c in self.columns]
        if len(set(names)) != len(names):
            raise ModelError(f"experiment {self.name}: duplicate column names in {names}")
        missing = [c for c in self.channels if c not in names]
        if missing:
            raise ModelError(f"experiment {self.name}: channels {missing} are not among its columns {names}")
        pn = [p.name for p in self.parameters]
        if len(set(pn)) != len(pn):
            raise ModelError(f"experiment {self.name}: duplicate parameter names in {pn}")
        quantities = check_quantities(f"experiment {self.name}", self.quantities)
        object.__setattr__(self, "quantities", quantities)
        hooks = dict(self.hooks)
        for kind in HOOKS:
            if kind in quantities and kind not in hooks:
                q = quantities[kind]
                shape = f"(n, {len(q.axes)}) about {', '.join(q.axes)}" if q.axes else "(n,)"
                hooks[kind] = f"{kind} {shape} {q.unit}{': ' + q.doc if q.doc else ''}"
        object.__setattr__(self, "hooks", hooks)

    # ------------------------------------------------------------------ helpers
    @property
    def pending(self) -> bool:
        """True while the experiment has a data format but no model yet."""
        return self.model is None

    @property
    def effect_key(self) -> str:
        """The experiment name under which effect implementations are looked up."""
        return self.effects_from or self.name

    def column(self, name: str) -> Column:
        """The :class:`Column` called ``name``."""
        for c in self.all_columns:
            if c.name == name:
                return c
        raise KeyError(name)

    @property
    def all_columns(self) -> tuple:
        """Declared columns, the optional time column ``t_s``, the optional ``group`` column and an
        optional ``sigma_<channel>`` (per-row standard uncertainty, the channel's unit) for every channel."""
        cols = tuple(self.columns)
        names = {c.name for c in cols}
        if TIME_COLUMN.name not in names:
            cols += (TIME_COLUMN,)
        if GROUP_COLUMN.name not in names:
            cols += (GROUP_COLUMN,)
        for ch in self.channels:
            if f"sigma_{ch}" not in names:
                unit = next((c.unit for c in self.columns if c.name == ch), "")
                cols += (
                    Column(
                        f"sigma_{ch}", unit, f"standard uncertainty of {ch} in each row (optional; > 0)", required=False
                    ),
                )
        return cols

    def unit_of(self, channel: str) -> str:
        """Unit of a channel (column)."""
        return self.column(channel).unit

    def weight(self, channel: str) -> float:
        """Factor converting ``channel`` to :attr:`error_unit` (1 by default)."""
        return float(self.channel_weights.get(channel, 1.0))

    @property
    def one_scale(self) -> bool:
        """True if every compared channel is in :attr:`error_unit`, unweighted: one RMS error and one
        noise floor in that unit then say what the ratio to the noise says (not so for metres and
        radians together, where each channel is read against its own noise)."""
        return all(self.unit_of(c) == self.error_unit and self.weight(c) == 1.0 for c in self.channels)

    def defaults(self) -> dict:
        """Default baseline parameters ``{name: value}``."""
        return {p.name: float(p.default) for p in self.parameters}

    def with_options(self, **options) -> Experiment:
        """A copy with some options changed; unknown option names raise ModelError."""
        for old in set(options) & set(self.renamed_options):
            new = self.renamed_options[old]
            renamed(f"option {old} of {self.name}", f"option {new}")
            options[new] = options.pop(old)
        unknown = sorted(set(options) - set(self.options))
        if unknown:
            raise ModelError(
                f"experiment {self.name}: unknown option(s) {', '.join(unknown)}; accepted: "
                f"{', '.join(sorted(self.options)) or '(none)'}"
            )
        return replace(self, options={**self.options, **options})

    def prepared(self, data: Measured) -> dict:
        """Per-data-set quantities from :attr:`prepare`, computed once and cached on ``data``."""
        return prepared(data, self.prepare, self.options) if self.prepare else {}

    def require_model(self, what: str = "this") -> None:
        """Raise ModelError if the experiment is pending a model."""
        if self.pending:
            raise ModelError(
                f"experiment '{self.name}' is registered with its data format but is pending a model, so "
                f"{what} cannot run yet. {self.doc.splitlines()[0] if self.doc else ''} "
                "A model can be plugged in from a script (docs/experiments.md, 'Adding an experiment'): "
                f"define `experiment = Experiment(name='{self.name}', ..., model=...)` and pass the script path "
                "instead of the name."
            )


def prepared(data: Measured, prepare: Callable, options: dict) -> dict:
    """``prepare(data, options)``, computed once per (function, options) and cached on ``data``.

    Models call it to get their per-data-set arrays (the options may differ between variants of
    one experiment, so they are part of the key)."""
    key = (
        "prepare",
        getattr(prepare, "__module__", ""),
        getattr(prepare, "__qualname__", repr(prepare)),
        repr(sorted(options.items(), key=lambda kv: kv[0])),
    )
    if key not in data.cache:
        data.cache[key] = prepare(data, options)
    return data.cache[key]


class EffectStack:
    """The effects switched on in one model run, each with its parameter values.

    ``items`` is a list of ``(effect_name, implementation, params)``; ``apply(hook, value, **ctx)``
    passes ``value`` through every implementation attached to ``hook``, in their ``order``.
    An implementation's function is called as ``fn(value, params, ctx)`` and returns the new value;
    ``ctx`` holds ``context`` (what the framework gives every effect: ``time``, ``t_s``,
    ``temperature``, ``quantities``; :func:`effect_context`), the load as it entered the ``"load"``
    hook (``load``) and after its effects (``load_eff``), and the keyword arguments of the hook call.
    """

    def __init__(self, items=(), context=None):
        self.items = sorted(list(items), key=lambda it: it[1].order)
        self.context = dict(context or {})

    def __bool__(self):
        return bool(self.items)

    @property
    def names(self) -> tuple:
        """Names of the active effects."""
        return tuple(name for name, _, _ in self.items)

    def apply(self, hook: str, value, **ctx):
        """Apply the active effects attached to ``hook`` to ``value`` (see the class docstring)."""
        if hook == "load" and self.items:
            self.context["load"] = value
        full = {**self.context, **ctx}
        for _, impl, params in self.items:
            if impl.hook == hook:
                value = impl.apply(value, params, full)
        if hook == "load" and self.items:
            self.context["load_eff"] = value
        return value

    def on(self, hook: str) -> bool:
        """True if an active effect is attached to ``hook``."""
        return any(impl.hook == hook for _, impl, _ in self.items)


def effect_context(exp: Experiment, data: Measured) -> dict:
    """What the framework gives every effect of a model run on ``data`` (:class:`EffectStack`)."""
    t = data.columns.get("t_s")
    ctx = {
        "time": data.tau,
        "t_s": np.asarray(t, float) if t is not None else np.arange(data.n, dtype=float),
        "quantities": exp.quantities,
    }
    temp = exp.quantities.get("temperature")
    if temp is not None and temp.column in data.columns:
        ctx["temperature"] = data[temp.column]
    return ctx


NO_EFFECTS = EffectStack()
