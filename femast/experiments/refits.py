"""Refits of ``diagnose``: the candidate, form and pair fits run in this process, in local worker
processes or on a dask.distributed cluster (see :mod:`femast.experiments.diagnose`).

With the default number of workers a diagnosis whose refits are estimated to take under a second
in all runs in the calling process: starting worker processes would cost more than it saves (the FE
experiments are the ones that need the workers).
"""

from __future__ import annotations

import multiprocessing
import os
import threading
from concurrent.futures import ProcessPoolExecutor, as_completed
from contextlib import contextmanager

from scipy.optimize import OptimizeResult

from .. import progress
from ..effects.base import load_script
from ..errors import ModelError
from .core import Experiment
from .fitting import MODEL_FAILURES, fit

_START_METHOD = None  # multiprocessing start method of the local pool (None: the platform's default)
REFIT_NFEV = 25  # evaluations per parameter and start of a refit (a converging refit needs 5-20; a direction the
# data do not determine -- beam flexibility against the joint stiffness under top forces -- would use 100)
OVERSUBSCRIBE = 3  # default workers of the expensive (FE) experiments: up to this many processes per CPU
SERIAL_BELOW_S = 1.0  # default workers: refit in this process when the refits should take less than this (s)


# --------------------------------------------------------------------------- refit tasks
def _refit_task(payload: dict) -> OptimizeResult:
    """One refit (runs in a worker process or on a dask worker)."""
    from .registry import experiment_from_source

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
    )
    res.pid = os.getpid()
    return res


def _safe_fit(exp, data, effects, start, noise, sensitivity=None, rows=None) -> OptimizeResult:
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
            start_sensitivity=sensitivity if rows is None else None,
            rows=rows,
        )  # the baseline's derivatives seed the refit's
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


def _mp_context():
    """Start method of the local pool: ``_START_METHOD`` if set; else 'forkserver' once numba has
    started GNU OpenMP threads in this process (the FE experiments' ``kernel_threads`` does, and so
    would a parallel user kernel; forking after that aborts the child: "fork() called from a process
    already using GNU OpenMP"); else the platform's default (fork on Linux: the fastest start)."""
    if _START_METHOD:
        return multiprocessing.get_context(_START_METHOD)
    try:
        import numba

        layer = numba.threading_layer()  # ValueError while no parallel kernel has run
    except Exception:
        layer = None
    if layer == "omp" and "forkserver" in multiprocessing.get_all_start_methods():
        return multiprocessing.get_context("forkserver")
    return None


def _run_tasks(payloads, workers, scheduler, while_waiting=None):
    """Run the refits; returns (results, how) with ``how`` describing the executor used.
    while_waiting : a callable run in a thread of this process while local worker processes refit
    (started after they are forked, joined before the pool closes), e.g. an import the report needs."""
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
    n = (os.cpu_count() or 1) if workers is None else int(workers)
    if n < 1:
        raise ModelError(f"--workers must be >= 1, got {workers}")
    n = min(n, len(payloads))
    if n <= 1:
        return _serial_refits(payloads), "serial (1 process)"
    with frozen_heap(), ProcessPoolExecutor(max_workers=n, mp_context=_mp_context()) as pool:
        futures = [pool.submit(_refit_task, p) for p in payloads]
        helper = None
        if while_waiting is not None:
            helper = threading.Thread(target=_quietly, args=(while_waiting,), daemon=True)
            helper.start()
        with progress.counter(len(futures), f"diagnose: refits on {n} processes", unit="refits") as bar:
            for fut in as_completed(futures):
                bar.set_postfix_str(f"done: {_candidate(payloads[futures.index(fut)])}", refresh=False)
                bar.update(1)
        results = [fut.result() for fut in futures]
        if helper is not None:
            helper.join()  # (before any later fork: a thread holding the import lock must not be forked)
    return results, f"{n} local processes"


@contextmanager
def frozen_heap():
    """The garbage collector's view of this process's heap frozen while forked children run: a child's
    collections then skip the inherited objects instead of visiting them all, which copies every page
    they touch (copy-on-write) -- 8-17 % of the CPU of diagnose's refit processes on the bay.
    Objects made meanwhile are collected as usual; the frozen ones return to the collector after."""
    import gc

    gc.freeze()
    try:
        yield
    finally:
        gc.unfreeze()


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


def _dispatch(exp, data, payloads, start, sigma, workers, scheduler, t_base, while_waiting=None):
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
                )
                for p in payloads
            ],
            "serial (experiment defined in memory: worker processes cannot rebuild it)",
        )
    est = 6.0 * t_base * len(payloads)
    if workers is None and scheduler is None and not exp.fit_options.get("expensive") and est < SERIAL_BELOW_S:
        return _serial_refits(payloads), f"serial (refits estimated at {est:.2f} s: cheaper than starting processes)"
    if workers is None and scheduler is None and exp.fit_options.get("expensive"):
        # a process per refit (up to OVERSUBSCRIBE x the CPUs): the refits of the FE experiments take
        # 6-15 FE runs each, and a pool of one process per CPU ends with one CPU idle while the
        # longest refits finish; more processes than CPUs share them to the end
        workers = max(1, min(len(payloads), OVERSUBSCRIBE * (os.cpu_count() or 1)))
    return _run_tasks(payloads, workers, scheduler, while_waiting)
