"""Refits of ``diagnose``: the candidate, form and pair fits run in this process, on worker
processes (:class:`femast.workers.Pool`: spawned, never more than the CPUs unless asked, ended with
the command however it ends) or on a dask.distributed cluster (see :mod:`femast.experiments.diagnose`).

``workers``: None (the default of the Python API) refits in the calling process, as femast
computes in the user's process unless asked otherwise; a number N refits on N worker processes;
``"auto"`` (the default of ``femast diagnose``) chooses: one worker per CPU, except for a diagnosis
whose refits are estimated to take under a second in all, which runs in the calling process
(starting worker processes would cost more than it saves; the FE experiments are the ones that
need the workers).  For those, :func:`refit_pool` starts the workers when the diagnosis starts,
so that they import femast and the rig while this process fits the baseline.  A refit whose worker dies or runs over its time-out comes back as a failed refit, named
in the report; the other refits go on.
"""

from __future__ import annotations

import os
import threading
from contextlib import nullcontext

from scipy.optimize import OptimizeResult

from .. import progress
from ..effects.scripts import load_script, loaded_scripts
from ..errors import ModelError, TaskTimeout, WorkerDied
from ..workers import Pool, worker_count
from .core import Experiment
from .fitting import fit
from .prediction import MODEL_FAILURES

REFIT_NFEV = 25  # evaluations per parameter and start of a refit (a converging refit needs 5-20; a direction the
# data do not determine -- beam flexibility against the joint stiffness under top forces -- would use 100)
SERIAL_BELOW_S = 1.0  # workers="auto": refit in this process when the refits should take less than this (s)
AUTO = "auto"  # workers: one per CPU unless the refits are quick (module docstring)


# --------------------------------------------------------------------------- refit tasks
def _refit_task(payload: dict) -> OptimizeResult:
    """One refit (runs in a worker process or on a dask worker)."""
    from .registry import experiment_from_source

    progress.relay_to(payload.get("progress_file"))  # the parent's bar moves with each model run of this refit
    try:
        for script in payload["scripts"]:
            load_script(script)
        exp = experiment_from_source(payload["source"], payload["options"])
        data = payload["data"]
        res = _safe_fit(
            exp,
            data,
            payload["effects"],
            start=payload["start"],
            noise=payload["noise"],
            sensitivity=payload.get("sensitivity"),
            rows=payload.get("rows"),
            screen=payload.get("screen"),
        )
    finally:
        progress.relay_to(None)
    res.pid = os.getpid()
    return res


def _safe_fit(exp, data, effects, start, noise, sensitivity=None, rows=None, screen=None) -> OptimizeResult:
    """:func:`fit`, or a result with ``failed = True`` and the error as ``message`` when the model
    cannot be evaluated even at the start of the refit (an FE run that does not converge with the
    effect's default parameters): one failed candidate must not end the whole diagnosis."""
    try:
        return fit(
            exp,
            data,
            effects,
            start=start,
            noise=noise,
            given_start_clip=True,
            nfev_per_param=REFIT_NFEV,
            start_sensitivity=sensitivity,
            rows=rows,
            screen=screen,  # a candidate screened by its linearisation (femast.experiments.screening)
        )  # derivatives known at (or near) the start seed the refit's: the baseline's for a candidate, a
        # model's own at its solution for a held-out fold
    except (*MODEL_FAILURES, ArithmeticError) as e:
        return OptimizeResult(failed=True, success=False, message=f"{type(e).__name__}: {e}", effects=tuple(effects))


def _rebuildable(exp: Experiment) -> bool:
    """True if a worker can rebuild ``exp`` from its source name/script and options."""
    if not exp.source:
        return False
    try:
        from .registry import experiment_from_source

        other = experiment_from_source(exp.source, exp.options)
    except Exception:
        return False
    return other.name == exp.name and other.model is exp.model


def _worker_setup(source: str, options: dict, scripts) -> None:
    """Runs in each refit worker as it starts: the user's effect scripts and the experiment's rig
    imported (and its model built) before the first refit arrives."""
    from .registry import experiment_from_source

    for script in scripts:
        load_script(script)
    experiment_from_source(source, options)


def refit_pool(exp: Experiment, workers=None, scheduler=None):
    """A :class:`~femast.workers.Pool` for the refits of ``exp``, started now, or None when they will
    not run on local workers known now: in this process (``workers`` None or 1), a cluster, an
    experiment the workers cannot rebuild, or ``"auto"`` for a cheap experiment (decided after the
    baseline fit, by its time).  Its workers import femast and the rig while the caller fits the baseline; the caller
    ends it (``with``)."""
    if workers is None or scheduler is not None or not _rebuildable(exp):
        return None
    if workers == AUTO and not exp.fit_options.get("expensive"):
        return None
    n = _worker_number(workers)
    if n <= 1:
        return None
    scripts = list(loaded_scripts())
    return Pool(n, initializer=_worker_setup, initargs=(exp.source, exp.options, scripts), name="diagnose refits")


def _worker_number(workers, tasks: int | None = None) -> int:
    """Worker processes for ``workers`` (None: 1, this process; "auto": the CPUs; N), at most ``tasks``."""
    if workers is None:
        return 1
    if workers == AUTO:
        return worker_count(None, tasks)
    if isinstance(workers, bool) or not isinstance(workers, (int, float)) or int(workers) != workers or workers < 1:
        raise ModelError(f"workers = {workers!r}: give a whole number >= 1, or 'auto'")
    return worker_count(int(workers), tasks)


def _run_tasks(payloads, workers, scheduler, while_waiting=None, pool=None):
    """Run the refits; returns (results, how) with ``how`` describing the executor used.
    while_waiting : a callable run in a thread of this process while local worker processes refit
    (joined before the pool closes), e.g. an import the report needs.  pool : workers already
    started (:func:`refit_pool`), which the caller ends; else a pool is started and ended here."""
    if scheduler is not None:
        try:
            from distributed import Client
        except ImportError:
            raise ModelError(
                "--scheduler needs dask.distributed: pip install 'dask[distributed]' (the femast extra 'dist')"
            ) from None
        own = not isinstance(scheduler, Client)
        client = Client(scheduler) if own else scheduler
        try:
            address = client.scheduler.address if client.scheduler is not None else str(scheduler)
            from distributed import as_completed as dask_completed

            futures = client.map(_refit_task, payloads, pure=False)
            names = {f.key: _candidate(p) for f, p in zip(futures, payloads)}
            with progress.counter(len(futures), "diagnose: refits on the cluster", unit="refits") as bar:
                for fut in dask_completed(futures):
                    bar.set_postfix_str(f"done: {names[fut.key]}", refresh=False)
                    bar.update(1)
            results = client.gather(futures)
        finally:
            if own:
                client.close()
        return list(results), f"dask.distributed at {address}"
    n = pool.workers if pool is not None else _worker_number(workers, len(payloads))
    if n <= 1:
        return _serial_refits(payloads), "serial (in this process)"
    own = pool is None
    if own:
        pool = Pool(n, initializer=_worker_setup, initargs=_setup_args(payloads[0]), name="diagnose refits")
    with pool if own else nullcontext(), progress.Relays() as relays:
        futures = [pool.submit(_refit_task, dict(p, progress_file=relays.path(i))) for i, p in enumerate(payloads)]
        helper = None
        if while_waiting is not None:
            helper = threading.Thread(target=_quietly, args=(while_waiting,), daemon=True)
            helper.start()
        for _ in progress.as_completed(
            futures, f"diagnose: refits on {n} processes", "refits", relays, lambda i: _candidate(payloads[i])
        ):
            pass  # the bar advances with every model run inside the refits (relayed by the workers)
        results = [_result(fut, p) for fut, p in zip(futures, payloads)]
        if helper is not None:
            helper.join()
    return results, f"{n} local processes"


def _result(fut, payload) -> OptimizeResult:
    """A refit's result; a worker that died or ran over its time-out gives a failed refit."""
    try:
        return fut.result()
    except (WorkerDied, TaskTimeout) as e:
        return OptimizeResult(
            failed=True, success=False, message=f"{type(e).__name__}: {e}", effects=tuple(payload["effects"])
        )


def _setup_args(payload) -> tuple:
    return payload["source"], payload["options"], payload["scripts"]


def _quietly(fn):
    try:
        fn()
    except Exception:  # a helper's failure shows later, where its work is needed
        pass


def _candidate(payload) -> str:
    return payload.get("label") or (payload["effects"] or ["the baseline"])[-1]


def _serial_refits(payloads):
    """The refits one after the other in this process, a progress bar per refit naming its candidate."""
    results = []
    for i, p in enumerate(payloads):
        with progress.task(f"diagnose: refit {i + 1}/{len(payloads)} with {_candidate(p)}"):
            results.append(_refit_task(p))
    return results


def _dispatch(exp, data, payloads, start, sigma, workers, scheduler, t_base, while_waiting=None, pool=None):
    """Run refit payloads: in this process when cheap or not rebuildable, else on the executor."""
    if not payloads:
        return [], "no candidates"
    if not _rebuildable(exp):
        return (
            [
                _safe_fit(
                    exp,
                    data,
                    p["effects"],
                    start=p["start"],
                    noise=p.get("noise", sigma),
                    sensitivity=p.get("sensitivity"),
                    rows=p.get("rows"),
                    screen=p.get("screen"),
                )
                for p in payloads
            ],
            "serial (experiment defined in memory: worker processes cannot rebuild it)",
        )
    est = 6.0 * t_base * len(payloads)
    if pool is None and workers == AUTO and scheduler is None and not exp.fit_options.get("expensive"):
        if est < SERIAL_BELOW_S:
            return _serial_refits(
                payloads
            ), f"serial (refits estimated at {est:.2f} s: cheaper than starting processes)"
    return _run_tasks(payloads, workers, scheduler, while_waiting, pool)
