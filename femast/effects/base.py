"""Effects: named, documented physical mechanisms an experiment's model can switch on.

An :class:`Effect` has a name, its physics, the signature its absence leaves in the
residual, and one :class:`Implementation` per experiment it applies to.  An implementation
names a *hook* of that experiment's model (``Experiment.hooks``), its own fittable
:class:`~femast.experiments.core.Parameter` s, and a function
``apply(value, params, ctx) -> value`` that changes the quantity passing through the hook.
An implementation with ``apply=None`` records that the effect applies to the experiment but
is not implemented yet (e.g. for experiments pending an FE model).

Users register their own effects from a script with :func:`register_effect` (or add an
implementation to an existing effect with :func:`add_implementation`).

Forms
-----
An implementation may carry generalised *forms* of its mechanism (``Implementation.forms``:
``{form name: Implementation}``), each a documented physical model of which the implementation's
own form (``Implementation.form``) is a special case, e.g. ``friction_hysteresis`` with its rigid
stick (``play``), a finite stick stiffness (``jenkins``) and distributed micro-slip (``iwan``).  A
form is switched on as ``effect/form`` (``--effects friction_hysteresis/jenkins``); ``diagnose``
fits every form of a candidate and keeps the one the information criterion prefers.
"""

from __future__ import annotations

import hashlib
import importlib.util
import sys
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path

from ..errors import ModelError, did_you_mean
from ..experiments.core import Parameter  # noqa: F401  (re-exported: effects declare Parameters)


@dataclass(frozen=True)
class Implementation:
    """How an effect acts on one experiment's model.

    hook : name of the model hook it acts on (a key of ``Experiment.hooks``).
    parameters : its fittable parameters (names unique within the effect).
    apply : ``apply(value, params, ctx) -> new value``; ``params`` is ``{name: value}`` (SI),
        ``ctx`` the keyword arguments of the hook call.  None: applicable but not implemented yet.
    order : effects on the same hook are applied in increasing ``order``.
    doc : how the effect enters this experiment (equation in words).
    form : name of this form of the mechanism (e.g. "play"); "" for an effect with one form.
    forms : ``{name: Implementation}`` of generalised forms (see the module docstring), selected as
        ``effect/name``; each has its own parameters and ``doc``.
    """

    hook: str
    parameters: tuple = ()
    apply: Callable | None = None
    order: int = 50
    doc: str = ""
    form: str = ""
    forms: dict = field(default_factory=dict)

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


@dataclass(frozen=True)
class Effect:
    """A physical effect (see the module docstring).

    name : identifier used on the command line (``--effects joint_clearance``).
    title : short human name.  physics : what happens, with seed equation references.
    signature : what its absence leaves in the residual, in plain words.
    acts_where : kinds of path segment where that residual is largest
        ("near-zero load", "reversal", "loading", "unloading", "peak", or an experiment's own).
    implementations : ``{experiment name: Implementation}``.
    seed : the seed reference it comes from.
    """

    name: str
    title: str
    physics: str
    signature: str = ""
    acts_where: tuple = ()
    implementations: dict = field(default_factory=dict)
    seed: str = ""

    def implementation(self, experiment: str) -> Implementation | None:
        """The implementation for ``experiment`` (None if the effect does not apply to it)."""
        return self.implementations.get(experiment)

    def applies_to(self, experiment: str) -> bool:
        """True if the effect is implemented for ``experiment``."""
        impl = self.implementations.get(experiment)
        return impl is not None and impl.implemented

    def parameters(self, experiment: str) -> tuple:
        """Parameters of the effect in ``experiment``."""
        impl = self.implementations.get(experiment)
        return impl.parameters if impl else ()


_REGISTRY: dict[str, Effect] = {}
_SCRIPTS: list[str] = []  # scripts loaded in this process (re-loaded by worker processes)
_SCRIPT_EFFECTS: dict[str, list] = {}  # script path -> names of the effects it registered


def register_effect(effect: Effect, replace_existing: bool = False) -> Effect:
    """Add ``effect`` to the library; a name already taken raises unless ``replace_existing``."""
    if not isinstance(effect, Effect):
        raise ModelError(f"register_effect needs an Effect, got {type(effect).__name__}")
    if effect.name in _REGISTRY and not replace_existing and _REGISTRY[effect.name] is not effect:
        raise ModelError(
            f"an effect called '{effect.name}' is already registered; choose another name or pass replace_existing=True"
        )
    if "/" in effect.name or "." in effect.name:
        raise ModelError(f"effect name '{effect.name}': no '/' or '.' (they separate forms and parameters)")
    for exp, impl in effect.implementations.items():
        for label, im in [(impl.form or "default", impl), *impl.forms.items()]:
            names = [p.name for p in im.parameters]
            if len(set(names)) != len(names):
                raise ModelError(f"effect {effect.name} on {exp} (form {label}): duplicate parameter names {names}")
            if im.hook != impl.hook:
                raise ModelError(
                    f"effect {effect.name} on {exp}: form {label} acts on hook '{im.hook}', its "
                    f"default form on '{impl.hook}'; the forms of one effect share a hook"
                )
    _REGISTRY[effect.name] = effect
    return effect


def unregister_effect(name: str) -> None:
    """Remove an effect from the library (e.g. a user effect after a study); unknown names are ignored."""
    _REGISTRY.pop(name, None)


def add_implementation(effect_name: str, experiment: str, implementation: Implementation) -> Effect:
    """Make a registered effect apply to another experiment (e.g. a user's)."""
    eff = get_effect(effect_name)
    new = replace(eff, implementations={**eff.implementations, experiment: implementation})
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
    """Effects implemented for ``experiment`` (an Experiment or its effect key), registration order."""
    key = experiment if isinstance(experiment, str) else experiment.effect_key
    return tuple(e for e in _REGISTRY.values() if e.applies_to(key))


def split_form(name: str) -> tuple:
    """``"effect/form"`` -> ``("effect", "form")``; ``"effect"`` -> ``("effect", "")``."""
    base, _, form = name.partition("/")
    return base.strip(), form.strip()


def resolve(experiment, names) -> list:
    """Check effect names for ``experiment`` and return ``[(name, Implementation)]``.

    A name may select a form of the effect (``effect/form``, see the module docstring); the
    implementation returned is then that form's.  Raises ModelError for an unknown name, an effect that does not apply to the experiment, or
    one registered for it but not implemented yet, listing the accepted names each time.
    """
    key = experiment.effect_key
    ok = [e.name for e in applicable_effects(key)]
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
        impl = eff.implementation(key)
        if impl is None:
            raise ModelError(
                f"effect '{name}' does not apply to {experiment.name} (it applies to "
                f"{', '.join(eff.implementations) or 'nothing yet'}); accepted effects: {', '.join(ok)}"
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
        out.append((full if form and form != impl_form(eff, key) else name, impl))
    return out


def impl_form(effect: Effect, experiment_key: str) -> str:
    """Name of the default form of ``effect`` on an experiment ("" if it has one form)."""
    impl = effect.implementations.get(experiment_key)
    return impl.form if impl else ""


def forms_of(effect_name: str, experiment_key: str) -> tuple:
    """Names to switch on each form of an effect on an experiment: ``("effect", "effect/form", ...)``."""
    impl = get_effect(effect_name).implementations.get(experiment_key)
    if impl is None:
        return ()
    return (effect_name, *(f"{effect_name}/{f}" for f in impl.forms))


def load_script(path) -> object:
    """Import a user script (experiment and/or effects) once per process and return the module.

    The script registers effects with :func:`register_effect` and may define ``experiment``.
    Its resolved path is remembered so that worker processes of ``diagnose`` load it too.
    """
    p = Path(path).resolve()
    if not p.is_file():
        raise ModelError(f"no such script: {path}")
    modname = "femast_user_" + hashlib.sha1(str(p).encode()).hexdigest()[:12]
    if modname in sys.modules:
        return sys.modules[modname]
    spec = importlib.util.spec_from_file_location(modname, p)
    module = importlib.util.module_from_spec(spec)
    sys.modules[modname] = module
    before = set(_REGISTRY)
    try:
        spec.loader.exec_module(module)
    except Exception:
        del sys.modules[modname]
        raise
    _SCRIPT_EFFECTS[str(p)] = [n for n in _REGISTRY if n not in before]
    if str(p) not in _SCRIPTS:
        _SCRIPTS.append(str(p))
    return module


def effects_of_script(path) -> list:
    """Names of the effects a script registered when it was loaded (loads it if needed)."""
    load_script(path)
    return list(_SCRIPT_EFFECTS.get(str(Path(path).resolve()), []))


def loaded_scripts() -> tuple:
    """Resolved paths of the user scripts loaded in this process."""
    return tuple(_SCRIPTS)
