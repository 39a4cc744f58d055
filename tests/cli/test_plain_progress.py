"""Progress where a bar cannot show: a terminal of 0 columns or FEMAST_PROGRESS=plain gets a plain
line every few seconds, with the count, the elapsed time and the time left."""

import io

from femast import progress


class Clock:
    def __init__(self):
        self.t = 100.0

    def __call__(self):
        return self.t


def test_a_line_every_interval_with_an_eta():
    clock, out = Clock(), io.StringIO()
    bar = progress.PlainProgress(desc="diagnose", total=10, unit=" FE runs", interval=5.0, file=out, clock=clock)
    bar.update(1)  # 0 s: nothing yet (a short wait prints nothing)
    clock.t += 2.0
    bar.update(1)
    assert out.getvalue() == ""
    clock.t += 3.0  # 5 s, 2 of 10 done at the first line... now 3
    bar.update(1)
    lines = out.getvalue().splitlines()
    assert lines == ["diagnose: 3/10 FE runs [0:05 elapsed, ~0:12 left]"]  # 5 s * 7 / 3 = 11.7 s
    clock.t += 1.0
    bar.set_postfix_str("refit 2/4 with joint_clearance")
    assert len(out.getvalue().splitlines()) == 1  # within the interval: no line
    clock.t += 4.0
    bar.update(2)
    assert out.getvalue().splitlines()[-1] == (
        "diagnose: 5/10 FE runs, refit 2/4 with joint_clearance [0:10 elapsed, ~0:10 left]"
    )


def test_plain_mode_is_chosen_by_the_environment(monkeypatch, capsys):
    monkeypatch.setenv("FEMAST_PROGRESS", "plain")
    monkeypatch.setattr(progress, "PLAIN_INTERVAL_S", 0.0)
    assert progress.plain()
    with progress.task("fitting mast-top") as bar:
        progress.tick()
        progress.tick("FE runs")
    assert isinstance(bar, progress.PlainProgress)
    err = capsys.readouterr().err.splitlines()
    assert err[0].startswith("fitting mast-top: 1 evaluations") and "1 FE runs" in err[-1]
    monkeypatch.setenv("FEMAST_QUIET", "1")  # quiet wins
    assert not progress.plain()


def test_a_terminal_without_width_gets_plain_lines(monkeypatch):
    import os

    monkeypatch.delenv("FEMAST_PROGRESS", raising=False)
    monkeypatch.setattr(progress, "enabled", lambda: True)
    monkeypatch.setattr(os, "get_terminal_size", lambda fd=None: os.terminal_size((0, 0)))
    assert progress.plain()
    monkeypatch.setattr(os, "get_terminal_size", lambda fd=None: os.terminal_size((80, 24)))
    assert not progress.plain()


def test_short_tasks_one_after_the_other_still_print_a_line_every_interval(monkeypatch):
    """Six refits of 2 s each: one stream of lines (at 5 s and 10 s), not six silent bars; after an
    idle gap a new short task prints nothing again."""
    clock = Clock()
    monkeypatch.setattr(progress, "_plain_clock", clock)
    monkeypatch.setattr(progress, "_PLAIN", {"last": None, "open": 0, "closed_at": None})
    out = io.StringIO()
    for i in range(6):
        with progress.PlainProgress(desc=f"refit {i + 1}/6", unit=" evaluations", interval=5.0, file=out) as bar:
            for _ in range(2):
                clock.t += 1.0
                bar.update(1)
    assert out.getvalue().splitlines() == [
        "refit 3/6: 1 evaluations [0:01 elapsed]",  # 5 s after the first task started
        "refit 5/6: 2 evaluations [0:02 elapsed]",  # 10 s
    ]
    clock.t += 60.0  # idle: a new stretch of work
    with progress.PlainProgress(desc="compare", unit=" evaluations", interval=5.0, file=out) as bar:
        clock.t += 4.0
        bar.update(1)
    assert len(out.getvalue().splitlines()) == 2
