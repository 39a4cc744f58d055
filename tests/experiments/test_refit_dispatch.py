"""diagnose's refit executor (femast/experiments/refits.py): in the calling process unless workers
are asked for; then on femast.workers' pool (spawned processes, never more than asked), a helper
runs in the calling process meanwhile,
a worker that dies gives a failed refit while the others go on, and an FE experiment's workers
start with the diagnosis."""

from __future__ import annotations

import os
import threading
import time

from femast.experiments import get_experiment, refits
from femast.workers import worker_count


def _fake_task(payload):
    """Stands for a refit: sleeps, answers its process id; "die" kills its worker."""
    if payload["effects"] == ["die"]:
        os._exit(3)
    time.sleep(0.3)
    return os.getpid()


def _payloads(exp, names):
    return [{"source": exp.source, "options": exp.options, "scripts": [], "effects": [n]} for n in names]


def test_by_default_the_refits_run_in_this_process(monkeypatch):
    monkeypatch.setattr(refits, "_refit_task", _fake_task)
    exp = get_experiment("bay-torsion")
    assert refits.refit_pool(exp) is None
    pids, how = refits._dispatch(exp, None, _payloads(exp, "ab"), {}, {}, None, None, 1.0)
    assert how == "serial (in this process)" and set(pids) == {os.getpid()}


def test_expensive_refits_run_on_worker_processes_and_the_helper_runs_meanwhile(monkeypatch):
    monkeypatch.setattr(refits, "_refit_task", _fake_task)  # (submitted by reference: the workers import it)
    exp = get_experiment("bay-torsion")
    assert exp.fit_options.get("expensive")
    seen = []

    def helper():
        seen.append(threading.current_thread() is not threading.main_thread())

    pids, how = refits._dispatch(exp, None, _payloads(exp, "abcd"), {}, {}, "auto", None, 1.0, while_waiting=helper)
    n = worker_count(None, tasks=4)
    assert how == f"{n} local processes"
    assert os.getpid() not in pids and 1 <= len(set(pids)) <= n  # never more processes than CPUs
    assert seen == [True]  # the helper ran once, in a thread, and was joined


def test_an_explicit_worker_count_is_kept(monkeypatch):
    monkeypatch.setattr(refits, "_refit_task", _fake_task)
    exp = get_experiment("bay-torsion")
    pids, how = refits._dispatch(exp, None, _payloads(exp, "abcd"), {}, {}, 2, None, 1.0)
    assert how == "2 local processes" and len(set(pids)) <= 2 and os.getpid() not in pids


def test_a_worker_that_dies_gives_a_failed_refit_and_the_others_go_on(monkeypatch):
    monkeypatch.setattr(refits, "_refit_task", _fake_task)
    exp = get_experiment("bay-torsion")
    out, _ = refits._dispatch(exp, None, _payloads(exp, ["a", "die", "b"]), {}, {}, 2, None, 1.0)
    assert isinstance(out[0], int) and isinstance(out[2], int)
    assert out[1].failed and not out[1].success and "WorkerDied" in out[1].message
    assert out[1].effects == ("die",)


def test_the_workers_of_an_fe_experiment_start_with_the_diagnosis(monkeypatch):
    monkeypatch.setattr(refits, "_refit_task", _fake_task)
    bay, cheap = get_experiment("bay-torsion"), get_experiment("mast-top")
    assert refits.refit_pool(cheap, workers="auto") is None  # decided after the baseline fit, by its time
    assert refits.refit_pool(bay, workers=1) is None
    assert refits.refit_pool(bay, scheduler="tcp://127.0.0.1:1") is None
    with refits.refit_pool(bay, workers=2) as pool:
        assert pool.workers == 2
        pids, how = refits._dispatch(bay, None, _payloads(bay, "ab"), {}, {}, 2, None, 1.0, pool=pool)
        assert how == "2 local processes" and set(pids) <= set(pool.pids())  # the workers started early
        assert os.getpid() not in pids
    assert pool.pids() == []  # ended with the with block
