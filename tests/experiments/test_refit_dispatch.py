"""diagnose's refit executor (femast/experiments/refits.py): the FE experiments'
refits get a process each by default (more processes than CPUs share them to the end), and a
helper runs in the calling process while the workers refit."""

from __future__ import annotations

import os
import threading
import time

from femast.experiments import get_experiment, refits


def _fake_task(payload):
    time.sleep(0.3)
    return os.getpid()


def test_expensive_refits_get_a_process_each_and_the_helper_runs_meanwhile(monkeypatch):
    monkeypatch.setattr(refits, "_refit_task", _fake_task)  # forked workers see the patched module
    monkeypatch.setattr(refits, "_START_METHOD", "fork")
    exp = get_experiment("bay-torsion")
    assert exp.fit_options.get("expensive")
    payloads = [{"effects": [f"e{i}"]} for i in range(4)]
    seen = []

    def helper():
        seen.append(threading.current_thread() is not threading.main_thread())

    pids, how = refits._dispatch(exp, None, payloads, {}, {}, None, None, 1.0, while_waiting=helper)
    n = min(4, refits.OVERSUBSCRIBE * (os.cpu_count() or 1))
    assert how == f"{n} local processes"
    assert len(set(pids)) == n  # four 0.3 s tasks sleeping concurrently: each in its own process
    assert seen == [True]  # the helper ran once, in a thread, and was joined


def test_an_explicit_worker_count_is_kept(monkeypatch):
    monkeypatch.setattr(refits, "_refit_task", _fake_task)
    monkeypatch.setattr(refits, "_START_METHOD", "fork")
    exp = get_experiment("bay-torsion")
    pids, how = refits._dispatch(exp, None, [{"effects": [f"e{i}"]} for i in range(4)], {}, {}, 2, None, 1.0)
    assert how == "2 local processes" and len(set(pids)) <= 2
