"""Reference runs of the FE experiments: the converged path of one run predicts the next.

A fit runs the FE model along the same measured path many times with parameters close to each
other.  The experiment option ``fe_reference`` names the baseline parameters of a *reference
run* (the model without effects at those parameters, along the unmodified path); every other run
of the fit then starts each increment from the reference run's converged increment
(:mod:`femast.analysis.reference`) instead of the tangent predictor of the new load or prescribed
motion: about half the Newton iterations (bay-torsion: 2 per increment instead of 4).

:func:`~femast.experiments.fitting.fit` of an expensive experiment sets ``fe_reference`` to the
baseline parameters of its start when it is None (the default): the baseline fit of ``diagnose``
refers to the start values, every refit to the baseline's solution (its start).

The converged solution of a run depends on the path Newton takes to it only within what the
convergence tolerances leave open, plus, in the ADAM models, the order in which the prescribed
rotation and the free tilts of the control node are composed (prescribed rotations are
accumulated spins): 6e-5 N m in the bay-torsion example, 3e-4 of its noise
(docs/performance.md).  To keep every run a function of its inputs alone, the reference is part
of a run's cache key: the same inputs with another reference are another entry.

This module keeps the paths of the last :data:`PATH_ENTRIES` reference runs of the process in
memory (their run outputs go to :mod:`femast.experiments.fe_cache` as usual).
"""

from __future__ import annotations

from collections import OrderedDict

from .fe_cache import cached, run_key

PATH_ENTRIES = 32  # (a bay path is 25 kB; a fit with another drive path -- off_axis_motion -- records each of its runs)
_PATHS: OrderedDict = OrderedDict()


def reference_path(kind: str, key_parts, run, options: dict | None = None):
    """The :class:`~femast.analysis.reference.ReferencePath` of the run ``key_parts`` of ``kind``.

    run : ``run(recorder) -> output dict`` computes the run (without a reference) recording its
        path with ``recorder``; called when the path of that run is not in memory (the output is
        then also stored in the run cache, where the same run without a reference is looked up).
    Returns None if the reference run fails (the caller then runs without a reference)."""
    from ..analysis.reference import ReferencePath

    key = run_key(kind, key_parts)
    path = _PATHS.get(key)
    if path is not None:
        _PATHS.move_to_end(key)
        return path
    rec = ReferencePath()
    out = cached(kind, key_parts, lambda: run(rec), options, refresh=True)
    if "error" in out or not len(rec):
        return None
    remember(key, rec)
    return rec


def cached_run(kind: str, key_parts, ref_parts, run, options: dict | None = None) -> dict:
    """A run of ``kind``, cached (:func:`~femast.experiments.fe_cache.cached`), started from the
    reference run ``ref_parts`` (None: no reference; the run itself: none either).

    run : ``run(parts, reference=None, record=None) -> output dict`` computes the run described by
        the key parts ``parts`` (catching its own failures as ``{"error": ...}``), starting from the
        ReferencePath ``reference`` and recording its own path with ``record`` when given.
    A run without a reference keeps its path (it may become a reference); a run with one is cached
    under its key and the reference's."""
    from ..analysis.reference import ReferencePath

    key = run_key(kind, key_parts)
    if ref_parts is not None and run_key(kind, ref_parts) == key:
        ref_parts = None

    def compute():
        if ref_parts is None:
            rec = ReferencePath()
            out = run(key_parts, record=rec)
            if "error" not in out and len(rec):
                remember(key, rec)
            return out
        path = reference_path(kind, ref_parts, lambda rec: run(ref_parts, record=rec), options)
        return run(key_parts, reference=path)

    return cached(kind, key_parts if ref_parts is None else (*key_parts, "reference", ref_parts), compute, options)


def remember(key: str, path) -> None:
    """Keep ``path`` as the reference path of run ``key`` (the last PATH_ENTRIES of them)."""
    _PATHS[key] = path
    _PATHS.move_to_end(key)
    while len(_PATHS) > PATH_ENTRIES:
        _PATHS.popitem(last=False)


def clear() -> None:
    """Forget the reference paths kept in memory."""
    _PATHS.clear()
