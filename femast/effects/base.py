"""The effect contract: named, documented physical mechanisms an experiment's model can switch on.

An :class:`Effect` has a name, its physics, the signature its absence leaves in the residual, and
the :class:`Implementation` s that say how it acts on a model.

Mechanisms on physical quantities
---------------------------------
An effect's ``mechanism`` acts on physical quantities, not on a rig: it names the quantity it
changes (its ``hook``: ``"load"`` or ``"displacement"``) and those it reads (``needs``: ``"load"``,
``"temperature"``; time is always there), and it applies to *every* experiment that declares
them in ``Experiment.quantities`` (:mod:`femast.effects.quantities`) -- a built-in rig or a user's
own, mixed freely with the user's own effects.  Its parameters may be a function of those
quantities, ``parameters(quantities) -> (Parameter, ...)``, so that they carry the experiment's
units and names and are sized by its scales (a clearance ``c`` in the displacement's unit, a
friction threshold ``M_f`` on a moment, ``F_f`` on a force; one per axis in a per-axis form).

A model calls ``value = effects.apply(hook, value, **ctx)`` at each hook; an implementation's
``apply(value, params, ctx)`` returns the changed value.  Besides the keyword arguments of the
call, ``ctx`` holds what the framework provides to every effect:

* ``load`` -- the load as it entered the ``"load"`` hook (before any effect), in the load's unit,
  ``(n,)`` or ``(n, k)``; ``load_eff`` -- the load after the effects on it;
* ``time`` -- ``(n,)`` normalised time in [0, 1] over the data (``t_s``, else the row index);
  ``t_s`` -- time in s (the row index where the data have none);
* ``temperature`` -- ``(n,)`` in the unit of the declared temperature quantity;
* ``quantities`` -- the experiment's ``{kind: Quantity}``; ``data``, ``options`` and ``params``
  (the baseline's) where the model passes them.

The model of a data set with several groups (stations, specimens, runs) is evaluated group by
group, so a path-dependent effect starts from its relaxed state in every group.

Rig-specific implementations
----------------------------
``implementations`` maps an experiment's name to an implementation on one of that experiment's own
hooks (``Experiment.hooks``: e.g. the inputs an FE bay is built with); it takes precedence over
the mechanism for that experiment.  An implementation with ``apply=None`` records that the effect
applies to an experiment but is not implemented yet.

Forms
-----
An implementation may carry generalised *forms* of its mechanism (``Implementation.forms``:
``{form name: Implementation}``), each a documented physical model of which the implementation's
own form (``Implementation.form``) is a special case, e.g. ``friction_hysteresis`` with its rigid
stick (``play``), a finite stick stiffness (``jenkins``), distributed micro-slip (``iwan``) and a
threshold per axis (``per_axis``, on quantities with two axes or more: ``min_axes``).  A form is
switched on as ``effect/form`` (``--effects friction_hysteresis/jenkins``); ``diagnose`` fits
every form of a candidate and keeps the one the information criterion prefers.

Users register their own effects from a script with :func:`register_effect` (or add an
implementation to an existing effect with :func:`add_implementation`); see docs/your_own_rig.md.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass, field, replace

from .._moved import renamed
from ..errors import ModelError, did_you_mean
from .parameters import Parameter  # noqa: F401  (re-exported: effects declare Parameters)
from .quantities import ALWAYS, HOOKS


@dataclass(frozen=True)
class Implementation:
    """How an effect acts on a model.

    hook : the quantity (``"load"``, ``"displacement"``) or the experiment's own hook it acts on.
    parameters : its fittable parameters (names unique within the effect), or for a mechanism a
        function ``parameters(quantities) -> (Parameter, ...)`` of the experiment's quantities.
    apply : ``apply(value, params, ctx) -> new value``; ``params`` is ``{name: value}`` (SI),
        ``ctx`` the keyword arguments of the hook call and the framework's (module docstring).
        None: applicable but not implemented yet.
    needs : the quantities it reads besides its hook (``("load",)``, ``("temperature",)``).
    order : effects on the same hook are applied in increasing ``order``.
    doc : how the effect enters the model (equation in words).
    form : name of this form of the mechanism (e.g. "play"); "" for an effect with one form.
    forms : ``{name: Implementation}`` of generalised forms (module docstring), selected as
        ``effect/name``; each has its own parameters and ``doc``.
    min_axes : fewest axes its quantities must have (2 for a per-axis form).
    from_baseline : for a generalised form that can gain where the default form does not (one-sided:
        the default, even in the sign of the load, averages a mechanism acting on one side away),
        ``diagnose`` fits it from the baseline beside the default form instead of only after the
        default has gained (:mod:`femast.experiments.candidates`).
    """

    hook: str
    parameters: tuple | Callable = ()
    apply: Callable | None = None
    order: int = 50
    doc: str = ""
    form: str = ""
    forms: dict = field(default_factory=dict)
    needs: tuple = ()
    min_axes: int = 1
    from_baseline: bool = False

    def variant(self, form: str | None) -> Implementation:
        """This implementation (``form`` None, "" or its own form name) or its generalised ``form``."""
        if not form or form == self.form:
            return self
        try:
            return self.forms[form]
        except KeyError:
            names = [self.form or "(default)", *self.forms]
            raise ModelError(f"unknown form '{form}'; accepted forms: {', '.join(names)}") from None

    @property
    def form_names(self) -> tuple:
        """Its own form then the generalised ones ("" for the default of a one-form effect)."""
        return (self.form, *self.forms)

    @property
    def implemented(self) -> bool:
        """False for an applicability recorded before the model exists."""
        return self.apply is not None

    def provided_by(self, quantities: dict) -> bool:
        """True if ``quantities`` (an experiment's) hold its hook and what it needs, with enough axes."""
        kinds = (self.hook, *self.needs)
        if not all(k in quantities or k in ALWAYS for k in kinds):
            return False
        return all(quantities[k].n_axes >= self.min_axes for k in kinds if k in HOOKS)

    def bind(self, quantities: dict) -> Implementation:
        """The implementation with its parameters for ``quantities`` and the forms they allow."""
        params = self.parameters(quantities) if callable(self.parameters) else tuple(self.parameters)
        forms = {n: f.bind(quantities) for n, f in self.forms.items() if f.provided_by(quantities)}
        return replace(self, parameters=tuple(params), forms=forms)


def _key_and_quantities(experiment):
    """(effect key, quantities) of an experiment, or of an experiment's name (no quantities)."""
    if isinstance(experiment, str):
        return experiment, {}
    return experiment.effect_key, dict(getattr(experiment, "quantities", None) or {})


@dataclass(frozen=True)
class Effect:
    """A physical effect (see the module docstring).

    name : identifier used on the command line (``--effects joint_clearance``).
    title : short human name.  physics : what happens, with the papers' equation references.
    signature : what its absence leaves in the residual, in plain words.
    acts_where : kinds of path segment where that residual is largest
        ("near-zero load", "reversal", "loading", "unloading", "peak", or an experiment's own).
    mechanism : the implementation on physical quantities (applies to every experiment that
        declares them), or None.
    implementations : ``{experiment name: Implementation}`` on experiments' own hooks.
    source : the paper and equation it comes from (``seed=``, its old name, warns and is removed in
        femast 0.3; ``effect.seed`` reads ``source`` with the same warning).
    """

    name: str
    title: str
    physics: str
    signature: str = ""
    acts_where: tuple = ()
    implementations: dict = field(default_factory=dict)
    source: str = ""
    mechanism: Implementation | None = None

    def implementation(self, experiment) -> Implementation | None:
        """The implementation for ``experiment`` (an Experiment, or a name: rig-specific ones only),
        its parameters bound to the experiment's quantities; None if the effect does not apply."""
        key, quantities = _key_and_quantities(experiment)
        impl = self.implementations.get(key)
        if impl is not None:
            return impl.bind(quantities) if callable(impl.parameters) else impl
        if self.mechanism is not None and self.mechanism.provided_by(quantities):
            return self.mechanism.bind(quantities)
        return None

    def applies_to(self, experiment) -> bool:
        """True if the effect is implemented for ``experiment`` (an Experiment or a name)."""
        impl = self.implementation(experiment)
        return impl is not None and impl.implemented

    def parameters(self, experiment) -> tuple:
        """Parameters of the effect in ``experiment``."""
        impl = self.implementation(experiment)
        return impl.parameters if impl else ()


def _with_old_seed_keyword(init):
    """``Effect(..., seed=...)``, the old name of ``source``, for one release (it warns)."""

    @functools.wraps(init)
    def __init__(self, *args, seed=None, **kwargs):
        if seed is not None:
            renamed("Effect(seed=...)", "Effect(source=...)")
            kwargs.setdefault("source", seed)
        init(self, *args, **kwargs)

    return __init__


def _old_seed(effect: Effect) -> str:
    renamed("Effect.seed", "Effect.source")
    return effect.source


Effect.__init__ = _with_old_seed_keyword(Effect.__init__)
Effect.seed = property(_old_seed, doc="Old name of :attr:`Effect.source`: warns, and is removed in femast 0.3.")

_REGISTRY: dict[str, Effect] = {}


def _check(effect: Effect) -> None:
    if "/" in effect.name or "." in effect.name:
        raise ModelError(f"effect name '{effect.name}': no '/' or '.' (they separate forms and parameters)")
    impls = list(effect.implementations.items())
    if effect.mechanism is not None:
        impls.append(("its mechanism", effect.mechanism))
    for exp, impl in impls:
        for label, im in [(impl.form or "default", impl), *impl.forms.items()]:
            if not callable(im.parameters):
                names = [p.name for p in im.parameters]
                if len(set(names)) != len(names):
                    raise ModelError(f"effect {effect.name} on {exp} (form {label}): duplicate parameter names {names}")
            if im.hook != impl.hook:
                raise ModelError(
                    f"effect {effect.name} on {exp}: form {label} acts on hook '{im.hook}', its "
                    f"default form on '{impl.hook}'; the forms of one effect share a hook"
                )
    m = effect.mechanism
    if m is not None and m.hook not in HOOKS:
        raise ModelError(
            f"effect {effect.name}: its mechanism acts on '{m.hook}', not a quantity ({', '.join(HOOKS)}); "
            "an experiment's own hook goes in implementations={experiment name: Implementation(...)}"
        )


def register_effect(effect: Effect, replace_existing: bool = False) -> Effect:
    """Add ``effect`` to the library; a name already taken raises unless ``replace_existing``."""
    if not isinstance(effect, Effect):
        raise ModelError(f"register_effect needs an Effect, got {type(effect).__name__}")
    if effect.name in _REGISTRY and not replace_existing and _REGISTRY[effect.name] is not effect:
        raise ModelError(
            f"an effect called '{effect.name}' is already registered; choose another name or pass replace_existing=True"
        )
    _check(effect)
    _REGISTRY[effect.name] = effect
    return effect


def unregister_effect(name: str) -> None:
    """Remove an effect from the library (e.g. a user effect after a study); unknown names are ignored."""
    _REGISTRY.pop(name, None)


def add_implementation(effect_name: str, experiment: str, implementation: Implementation) -> Effect:
    """Make a registered effect apply to another experiment, on that experiment's own hook."""
    eff = get_effect(effect_name)
    new = replace(eff, implementations={**eff.implementations, experiment: implementation})
    _check(new)
    _REGISTRY[effect_name] = new
    return new


def get_effect(name: str) -> Effect:
    """The registered effect ``name``; raises ModelError listing the accepted names."""
    try:
        return _REGISTRY[name]
    except KeyError:
        raise ModelError(
            f"unknown effect '{name}'{did_you_mean(name, _REGISTRY)}; accepted effects: {', '.join(sorted(_REGISTRY))}"
        ) from None


def list_effects() -> tuple:
    """All registered effects, in registration order."""
    return tuple(_REGISTRY.values())


def applicable_effects(experiment) -> tuple:
    """Effects implemented for ``experiment`` (an Experiment, or a name: rig-specific implementations
    only), in registration order."""
    return tuple(e for e in _REGISTRY.values() if e.applies_to(experiment))


def split_form(name: str) -> tuple:
    """``"effect/form"`` -> ``("effect", "form")``; ``"effect"`` -> ``("effect", "")``."""
    base, _, form = name.partition("/")
    return base.strip(), form.strip()


def resolve(experiment, names) -> list:
    """Check effect names for ``experiment`` and return ``[(name, Implementation)]``.

    A name may select a form of the effect (``effect/form``, see the module docstring); the
    implementation returned is then that form's, its parameters bound to the experiment's
    quantities.  Raises ModelError for an unknown name, an effect that does not apply to the
    experiment, or one registered for it but not implemented yet, listing the accepted names.
    """
    ok = [e.name for e in applicable_effects(experiment)]
    out, seen = [], set()
    for name in names:
        name = name.strip()
        if not name:
            continue
        full, (name, form) = name, split_form(name)
        if name in seen:
            raise ModelError(f"effect '{name}' given twice")
        seen.add(name)
        if name not in _REGISTRY:
            raise ModelError(
                f"unknown effect '{name}' for {experiment.name}{did_you_mean(name, ok or _REGISTRY)}; "
                f"accepted effects: {', '.join(ok) or '(none)'}"
            )
        eff = _REGISTRY[name]
        impl = eff.implementation(experiment)
        if impl is None:
            raise ModelError(
                f"effect '{name}' does not apply to {experiment.name} ({_needs(eff)}); accepted effects: {', '.join(ok)}"
            )
        if not impl.implemented:
            raise ModelError(
                f"effect '{name}' applies to {experiment.name} but is not implemented for it yet; "
                f"accepted effects: {', '.join(ok)}"
            )
        if experiment.hooks and impl.hook not in experiment.hooks:
            raise ModelError(
                f"effect '{name}' acts on hook '{impl.hook}', which {experiment.name} does not have; "
                f"its hooks: {', '.join(experiment.hooks)}"
            )
        try:
            impl = impl.variant(form)
        except ModelError as e:
            raise ModelError(f"effect '{full}' on {experiment.name}: {e}") from None
        out.append((full if form and form != impl_form(eff, experiment) else name, impl))
    return out


def _needs(effect: Effect) -> str:
    """What an effect needs, in words, for an error message."""
    parts = []
    m = effect.mechanism
    if m is not None:
        kinds = " and ".join(dict.fromkeys((m.hook, *m.needs)))
        parts.append(f"it needs an experiment declaring the quantities {kinds}")
    if effect.implementations:
        parts.append(f"it applies to {', '.join(effect.implementations)}")
    return "; ".join(parts) or "it applies to nothing yet"


def impl_form(effect: Effect, experiment) -> str:
    """Name of the default form of ``effect`` on an experiment ("" if it has one form)."""
    impl = effect.implementation(experiment)
    return impl.form if impl else ""


def forms_of(effect_name: str, experiment) -> tuple:
    """Names to switch on each form of an effect on an experiment: ``("effect", "effect/form", ...)``."""
    impl = get_effect(effect_name).implementation(experiment)
    if impl is None:
        return ()
    return (effect_name, *(f"{effect_name}/{f}" for f in impl.forms))
