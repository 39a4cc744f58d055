"""Progress of work done in worker processes: a worker's ticks reach its parent through a relay
file, so a bar over tasks that run elsewhere moves with every model run inside them."""

from femast import progress, workers


def test_ticks_of_a_worker_process_reach_the_parent():
    with progress.Relays() as relays, workers.Pool(1) as pool:
        assert pool.submit(progress.relay_to, relays.path("refit-0")).result() is None
        for kind in (None, None, None, "FE runs", "FE runs"):
            pool.submit(progress.tick, kind).result()
        assert relays.counts("refit-0") == (3, 2)  # 3 model evaluations, 2 FE runs, from another process
        assert relays.counts("refit-1") == (0, 0)  # a task that has not started reports nothing
        folder = relays.folder
        pool.submit(progress.relay_to, None).result()
        pool.submit(progress.tick).result()
        assert relays.counts("refit-0") == (3, 2)  # relay stopped
    import os

    assert not os.path.exists(folder)  # the relay files go with the Relays


def test_relay_in_this_process_and_fraction(tmp_path):
    path = tmp_path / "t.ticks"
    progress.relay_to(path)
    try:
        progress.tick()
        progress.tick("FE runs")
    finally:
        progress.relay_to(None)
    progress.tick()  # no relay, no task: nothing
    assert path.read_bytes() == b"ef"
    assert progress.task_fraction(0, 10) == 0.0
    assert progress.task_fraction(5, 10) == 0.5
    assert progress.task_fraction(50, 10) == 0.9  # a task is done only when it says so
    assert progress.task_fraction(3, 0) == 0.0


def test_plain_line_shows_tasks_partly_done():
    import io

    t = [0.0]
    out = io.StringIO()
    bar = progress.PlainProgress(desc="diagnose", total=4, unit=" refits", interval=1.0, file=out, clock=lambda: t[0])
    t[0] = 2.0
    bar.update(1.5)
    assert out.getvalue().splitlines() == ["diagnose: 1.5/4 refits [0:02 elapsed, ~0:03 left]"]  # 2 s * 2.5 / 1.5


def test_a_bar_over_tasks_moves_inside_running_tasks(monkeypatch):
    """Two tasks running elsewhere: before either finishes the bar stands between 0 and 1 step (each
    task's evaluations against twice the most any has done: 4/8 + 2/8); once one has finished after
    8 evaluations, the other counts 2/8 of a step beside it."""
    import concurrent.futures as cf
    import io
    import threading
    import time

    out = io.StringIO()
    monkeypatch.setattr(progress, "_bar", lambda **kw: progress.PlainProgress(interval=0.0, file=out, **kw))
    futures = [cf.Future(), cf.Future()]

    def until(text):
        t0 = time.monotonic()
        while text not in out.getvalue() and time.monotonic() - t0 < 60.0:
            time.sleep(0.01)

    with progress.Relays() as relays:

        def work():
            for i, n in ((0, 4), (1, 2)):
                with open(relays.path(i), "ab") as fh:
                    fh.write(b"e" * n)
            until("diagnose: 0.8/2 refits")  # 0.5 + 0.25 of a step
            with open(relays.path(0), "ab") as fh:
                fh.write(b"eeee" + b"ff")
            futures[0].set_result("a")
            until("diagnose: 1.2/2 refits")  # 1 + 2/8
            futures[1].set_result("b")

        t = threading.Thread(target=work, daemon=True)
        t.start()
        seen = [
            f.result() for f in progress.as_completed(futures, "diagnose", "refits", relays, "xy".__getitem__, 0.02)
        ]
        t.join()
    assert seen == ["a", "b"]
    lines = out.getvalue().splitlines()
    assert any(ln.startswith("diagnose: 0.8/2 refits, 0 of 2 finished, 6 model runs [") for ln in lines)
    assert any(
        ln.startswith("diagnose: 1.2/2 refits, 1 of 2 finished, 10 model runs, 2 FE runs, last: x [") for ln in lines
    )
    assert lines[-1].startswith("diagnose: 2/2 refits, 2 of 2 finished, 10 model runs, 2 FE runs, last: y [")
