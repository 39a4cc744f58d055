"""Running a study: in this process, in local worker processes, or on a dask.distributed cluster.

The runs are cut into chunks; each finished chunk is written to the study folder at once
(:mod:`femast.studies.store`), so a study that is interrupted (Ctrl-C, a killed job) resumes where
it stopped when run again with the same folder: the runs on disk are not run again, and the
points of the others do not depend on which were done (:mod:`femast.studies.sampling`).  At most
two chunks per worker are in flight, so memory does not grow with the number of samples.

Local workers are the processes of :class:`femast.workers.Pool` (they end with this process,
however it ends).  A study with a ``timeout_s`` runs its samples in worker processes even with
``workers=1``, one sample per task: a sample stuck where no signal reaches it (inside a compiled
loop) has its worker killed at ``timeout_s`` + :data:`KILL_GRACE_S` and is recorded as failed, and
the study goes on.  A worker that dies under a sample (out of memory, a crash in compiled code)
fails that sample the same way.

Worker warm-up: numba compiles femast's kernels once into its on-disk cache; a fresh process
still loads them on its first analysis.  Each local worker runs one nominal sample as it starts,
and dask workers run one each (``client.run``) before the study.  The warm-up samples are not
recorded.
"""

from __future__ import annotations

import hashlib
import math
import os
import socket
import time
from concurrent.futures import FIRST_COMPLETED, wait
from dataclasses import dataclass, field

import numpy as np

from .. import progress
from ..analysis.deadline import deadline
from ..errors import SampleTimeout, StudyError, TaskTimeout, WorkerDied
from ..workers import Pool
from .store import Store
from .study import Study

_STUDY = None  # the study of this worker process
KILL_GRACE_S = 2.0  # a sample's worker is killed this long (s) after timeout_s, if the sample has not stopped itself
START_S = 600.0  # with a timeout_s, a worker may take this long (s) more to start (import, load or compile kernels)
_DASK_STUDIES = {}  # payload hash -> study (dask workers)


@dataclass
class RunSummary:
    """What a call of :func:`run` did."""

    folder: str
    samples: int  # base samples of the study
    runs: int  # runs of the study (samples x (k + 2) with sensitivity)
    ran: int = 0  # runs made by this call
    ok: int = 0  # of them, successful
    failed: int = 0  # of them, failed (reasons in the store)
    resumed: int = 0  # runs already on disk when the call started
    wall_time: float = 0.0  # s
    cpu_time: float = 0.0  # s, this process and its local workers (not dask workers), warm-up included
    workers: int = 1
    engine: str = "serial"
    warmup_time: float = 0.0  # s, wall time of the warm-up (one nominal sample, not recorded)
    warmup_cpu: float = 0.0  # s, its CPU time in this process (serial, local)
    complete: bool = False
    failures: list = field(default_factory=list)  # (run, reason) of this call's failures (first 20)

    def __str__(self):
        state = (
            "complete"
            if self.complete
            else f"stopped with {self.runs - self.resumed - self.ran} runs to go "
            "(run again with the same folder to resume)"
        )
        fail = (
            f", {self.failed} FAILED (reasons: femast.studies.load('{self.folder}').failures())"
            if self.failed
            else ", 0 failed"
        )
        res = f" ({self.resumed} already on disk)" if self.resumed else ""
        return (
            f"study {state}: {self.samples} samples, {self.runs} runs{res}; this call ran {self.ran}: {self.ok} ok"
            f"{fail}; wall time {self.wall_time:.1f} s, CPU {self.cpu_time:.1f} s"
            f"{' (this process; not the dask workers)' if self.engine == 'dask' else ''}, {self.workers} "
            f"{self.engine} worker(s) (warm-up {self.warmup_time:.1f} s); results in {self.folder}"
        )


# ---------------------------------------------------------------- one chunk (any process)
def _over(seconds):
    return f"the sample ran over timeout_s = {seconds:g} s (wall clock); it is stopped"


def _limits(study):
    """The SIGALRM timer and the analyses' deadline of one sample."""
    t = study.timeout_s
    return _Timer(t), deadline(t, None if t is None else _over(t))


class _Timer:
    """A SIGALRM timer raising SampleTimeout after ``seconds`` (only in a main thread, Unix): it stops
    any code, the analysis' own deadline (femast/analysis/deadline.py, any thread: dask workers) only
    the analyses."""

    def __init__(self, seconds):
        import signal
        import threading

        self.seconds = seconds
        self.on = (
            seconds is not None
            and hasattr(signal, "setitimer")
            and threading.current_thread() is threading.main_thread()
        )

    def _alarm(self, signum, frame):
        raise SampleTimeout(_over(self.seconds))

    def __enter__(self):
        if self.on:
            import signal

            self.old = signal.signal(signal.SIGALRM, self._alarm)
            signal.setitimer(signal.ITIMER_REAL, self.seconds)

    def __exit__(self, *exc):
        if self.on:
            import signal

            signal.setitimer(signal.ITIMER_REAL, 0.0)
            signal.signal(signal.SIGALRM, self.old)


def _sample(study: Study, values: dict):
    t0 = time.perf_counter()
    try:
        timer, limit = _limits(study)
        with timer, limit:
            out = study.evaluate(values)
        for k, v in out.items():
            if not np.all(np.isfinite(v)):
                raise StudyError(f"output '{k}' is not finite ({v}); the sample is counted as failed")
        status, error = "ok", None
    except Exception as exc:  # recorded with its reason, never dropped
        msg = str(exc).strip().replace("\n", " ")
        status, error, out = "failed", f"{type(exc).__name__}: {msg}"[:1000], {}
    return status, error, out, time.perf_counter() - t0


def run_chunk(study: Study, runs, base, block, values) -> list:
    """Run the runs of one chunk; ``values`` is {input: (n,) or (n, size) array}.  Returns the rows."""
    names = study.design.block_names()
    worker = f"{socket.gethostname()}:{os.getpid()}"
    rows = []
    for i, r in enumerate(runs):
        v = {k: (float(a[i]) if a.ndim == 1 else a[i].copy()) for k, a in values.items()}
        status, error, out, sec = _sample(study, v)
        rows.append(
            {
                "run": int(r),
                "base": int(base[i]),
                "block": names[int(block[i])],
                "status": status,
                "error": error,
                "seconds": sec,
                "worker": worker,
                "inputs": v,
                "outputs": out,
            }
        )
    return rows


def _init_local(payload: bytes):
    global _STUDY
    import pickle

    _STUDY = pickle.loads(payload)
    warm(_STUDY)


def _local_chunk(runs, base, block, values):
    return run_chunk(_STUDY, runs, base, block, values)


def _dask_study(payload: bytes):
    key = hashlib.sha1(payload).hexdigest()
    if key not in _DASK_STUDIES:
        import cloudpickle

        _DASK_STUDIES[key] = cloudpickle.loads(payload)
    return _DASK_STUDIES[key]


def _dask_chunk(payload, runs, base, block, values):
    return run_chunk(_dask_study(payload), runs, base, block, values)


def _dask_warm(payload):
    return warm(_dask_study(payload))


def warm(study: Study) -> float:
    """Run one nominal sample (loads the kernels from numba's cache; not recorded); returns its
    wall time, s.  A :class:`StudyError` of the definition (a run function that does not return
    its outputs, a factory that returns no Model) is raised here, before any sample runs; any
    other failure of the nominal sample is left to the samples (which record it)."""
    t0 = time.perf_counter()
    try:
        timer, limit = _limits(study)
        with timer, limit:
            study.evaluate(study.nominal_values())
    except StudyError as exc:
        raise StudyError(f"the nominal sample (inputs at their medians): {exc}") from None
    except Exception:
        pass
    return time.perf_counter() - t0


# ---------------------------------------------------------------- the driver
def _connect(scheduler: str, timeout: float):
    try:
        from distributed import Client
    except ImportError:
        raise StudyError(
            "--scheduler needs dask.distributed: pip install 'dask[distributed]' (or femast[dist]); "
            "or drop --scheduler to use local processes"
        ) from None
    try:
        return Client(scheduler, timeout=f"{timeout}s", set_as_default=False)
    except (OSError, TimeoutError, ValueError) as exc:
        raise StudyError(
            f"cannot reach the dask scheduler at {scheduler!r} ({type(exc).__name__}: "
            f"{str(exc).splitlines()[0] if str(exc) else 'no answer'}); start one (`dask scheduler`, "
            "then `dask worker ADDRESS` on each machine) and give its address, or drop --scheduler to "
            "use local processes"
        ) from None


def run(
    study: Study,
    folder,
    samples: int,
    workers: int = 1,
    scheduler=None,
    chunk_size: int | None = None,
    limit: int | None = None,
    connect_timeout: float = 10.0,
) -> RunSummary:
    """Run ``samples`` base samples of ``study`` into ``folder`` (resuming what is there).

    workers : 1 runs in this process; n > 1 runs n local worker processes.
    scheduler : address of a dask.distributed scheduler (e.g. 'tcp://10.0.0.5:8786') or a
        ``distributed.Client``; then the cluster's workers run the samples.
    chunk_size : runs per chunk (a file of the store; default: about 20 chunks per worker, 1 to 256).
    limit : run at most this many runs now (the rest on a later call).
    Checks everything (inputs, outputs, scheduler) before any sample runs.
    """
    if not isinstance(study, Study):
        raise StudyError(f"{study!r} is not a femast.studies.Study")
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 1:
        raise StudyError(f"samples = {samples!r} must be a whole number >= 1")
    if isinstance(workers, bool) or not isinstance(workers, (int, np.integer)) or workers < 1:
        raise StudyError(f"workers = {workers!r} must be a whole number >= 1")
    samples = int(samples)
    study.check()
    store = Store(folder, study.spec(), samples)
    client = own = None
    if scheduler is not None:
        if isinstance(scheduler, str):
            client, own = _connect(scheduler, connect_timeout), True
        else:
            client, own = scheduler, False
    try:
        return _drive(study, store, samples, workers, client, chunk_size, limit)
    finally:
        if own:
            client.close()


def _drive(study, store, samples, workers, client, chunk_size, limit):
    t0 = time.perf_counter()
    c0 = _cpu()
    design = study.design
    total = samples * design.runs_per_sample
    done = store.done_runs()
    todo = np.setdiff1d(np.arange(total, dtype=np.int64), done)
    if limit is not None:
        todo = todo[: int(limit)]
    # a time-out needs samples in processes that can be killed (a stuck compiled loop ignores signals)
    engine = "dask" if client is not None else ("local" if workers > 1 or study.timeout_s is not None else "serial")
    if client is not None:
        workers = max(1, sum(client.nthreads().values()))
    s = RunSummary(
        folder=str(store.folder), samples=samples, runs=total, resumed=len(done), workers=workers, engine=engine
    )
    if chunk_size is None:
        chunk_size = int(min(256, max(1, math.ceil(len(todo) / (20 * workers)))))
    chunks = [todo[i : i + chunk_size] for i in range(0, len(todo), chunk_size)]
    sizes = {x.name: x.size for x in study.inputs}
    names = [x.name for x in study.inputs]

    def make(runs):
        base, block, u = design.points(runs, samples)
        return runs, base, block, design.values(u)

    def record(rows):
        ok, bad = store.write(rows, names, sizes)
        s.ran += len(rows)
        s.ok += ok
        s.failed += bad
        for r in rows:
            if r["status"] != "ok" and len(s.failures) < 20:
                s.failures.append((r["run"], r["error"]))
        bar.update(len(rows))
        if s.failed:
            bar.set_postfix_str(f"{s.failed} failed", refresh=False)

    with progress.counter(len(todo), desc=f"study {study.name}", unit="runs") as bar:
        try:
            if not chunks:
                pass
            elif engine == "serial":
                tw, cw = time.perf_counter(), _cpu()
                warm(study)
                s.warmup_time, s.warmup_cpu = time.perf_counter() - tw, _cpu() - cw
                for c in chunks:
                    record(run_chunk(study, *make(c)))
            elif engine == "local":
                _run_local(study, chunks, make, record, workers, s)
            else:
                _run_dask(study, chunks, make, record, client, s)
        finally:
            s.wall_time = time.perf_counter() - t0
            s.cpu_time = _cpu() - c0
    s.complete = len(store.done_runs()) >= total
    return s


def _cpu():
    import resource

    a, b = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return a.ru_utime + a.ru_stime + b.ru_utime + b.ru_stime


def _pipeline(chunks, make, record, submit, wait_one, in_flight):
    """Keep ``in_flight`` chunks submitted; record each as it finishes."""
    pending = set()
    it = iter(chunks)
    for c in it:
        pending.add(submit(*make(c)))
        if len(pending) >= in_flight:
            break
    while pending:
        finished, pending = wait_one(pending)
        for f in finished:
            record(f.result())
            c = next(it, None)
            if c is not None:
                pending.add(submit(*make(c)))


def _run_local(study, chunks, make, record, workers, s):
    """The chunks on a :class:`~femast.workers.Pool` of ``workers`` processes; with a ``timeout_s``,
    one sample per task (see the module docstring)."""
    try:
        import cloudpickle as cp  # (functions of a study script travel by value)
    except ImportError:  # pragma: no cover
        import pickle as cp

    tw = time.perf_counter()
    timeout = None if study.timeout_s is None else study.timeout_s + KILL_GRACE_S
    start = None if timeout is None else START_S + timeout  # (its warm-up sample too)
    with Pool(
        workers, _init_local, (cp.dumps(study),), timeout_s=timeout, name="study workers", start_timeout_s=start
    ) as pool:
        s.warmup_time = time.perf_counter() - tw
        if timeout is None:
            try:
                _pipeline(
                    chunks,
                    make,
                    record,
                    lambda *a: pool.submit(_local_chunk, *a),
                    lambda p: wait(p, return_when=FIRST_COMPLETED),
                    2 * workers,
                )
            except WorkerDied:
                raise StudyError(
                    f"a worker process died (killed, out of memory, or a crash in compiled code) after "
                    f"{s.ran} runs of this call; the finished runs are stored: run again to resume, "
                    "with --workers 1 to see which sample crashes"
                ) from None
        else:
            _pipeline(chunks, make, record, lambda *a: _ChunkOfSamples(pool, study, a), _wait_chunks, 2 * workers)


class _ChunkOfSamples:
    """A chunk submitted sample by sample (each its own task, killable at its time-out); done when
    every sample is; ``result()`` gives the chunk's rows, a killed or lost sample as a failed row."""

    def __init__(self, pool, study, chunk):
        self.chunk = chunk
        self.study = study
        runs, base, block, values = chunk
        self.futures = [
            pool.submit(
                _local_chunk,
                runs[i : i + 1],
                base[i : i + 1],
                block[i : i + 1],
                {k: a[i : i + 1] for k, a in values.items()},
            )
            for i in range(len(runs))
        ]

    def done(self):
        return all(f.done() for f in self.futures)

    def result(self):
        runs, base, block, values = self.chunk
        names = self.study.design.block_names()
        rows = []
        for i, f in enumerate(self.futures):
            try:
                rows.extend(f.result())
                continue
            except TaskTimeout:
                error = f"SampleTimeout: {_over(self.study.timeout_s)} (inside compiled code: its worker was killed)"
            except WorkerDied as exc:
                error = f"WorkerDied: {exc}"
            rows.append(
                {
                    "run": int(runs[i]),
                    "base": int(base[i]),
                    "block": names[int(block[i])],
                    "status": "failed",
                    "error": error,
                    "seconds": float(self.study.timeout_s or 0.0),
                    "worker": "",
                    "inputs": {k: (float(a[i]) if a.ndim == 1 else a[i].copy()) for k, a in values.items()},
                    "outputs": {},
                }
            )
        return rows


def _wait_chunks(pending):
    """(finished, still pending) chunks of samples, after at least one has finished."""
    while True:
        finished = {c for c in pending if c.done()}
        if finished:
            return finished, pending - finished
        wait([f for c in pending for f in c.futures if not f.done()], return_when=FIRST_COMPLETED)


def _run_dask(study, chunks, make, record, client, s):
    import cloudpickle
    from distributed import as_completed

    payload = cloudpickle.dumps(study)
    tw = time.perf_counter()
    client.run(_dask_warm, payload)
    s.warmup_time = time.perf_counter() - tw
    fut = client.scatter(payload, broadcast=True)
    finished = as_completed([], loop=client.loop)  # this client's (not a default client's: there may be none)

    def submit(*a):
        f = client.submit(_dask_chunk, fut, *a, pure=False)
        finished.add(f)
        return f

    def wait_one(pending):
        f = next(finished)
        return {f}, pending - {f}

    try:
        _pipeline(chunks, make, record, submit, wait_one, 2 * s.workers)
    except Exception as exc:
        if type(exc).__name__ != "KilledWorker":
            raise
        raise StudyError(
            f"dask workers died running a chunk ({exc}); the finished runs ({s.ran} of this call) are "
            "stored: run again to resume; check the workers' memory and logs"
        ) from None
