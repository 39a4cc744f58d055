"""The history of model versions (history.jsonl) read back and appended to safely: a line cut short
by an interrupted append is skipped with a warning, a damaged record is named, and compare runs
appending at the same moment get versions 1, 2, 3, ... (the history is locked while one appends)."""

import json
import multiprocessing as mp
import subprocess
import sys
import textwrap
import time

import pytest

import femast as fm
from femast.experiments.history import append_history, read_history


def _record(k=0):
    return {"experiment": "bay-torsion", "data": "d.csv", "effects": [], "fit": True, "rms": 1.0 + k, "noise_rms": 0.1}


def test_a_line_cut_short_by_an_interrupted_append_is_skipped_and_then_replaced(tmp_path):
    append_history(tmp_path, _record())
    with open(tmp_path / "history.jsonl", "a") as fh:
        fh.write('{"version": 2, "experiment": "bay-tor')  # a kill in the middle of an append
    with pytest.warns(UserWarning, match=r"ignoring line 2, cut short by an interrupted run"):
        recs = read_history(tmp_path)
    assert [r["version"] for r in recs] == [1]
    assert append_history(tmp_path, _record(1)) == 2  # the partial line is replaced, not glued to
    recs = read_history(tmp_path)
    assert [r["version"] for r in recs] == [1, 2] and recs[1]["rms"] == 2.0


@pytest.mark.parametrize(
    "line, named",
    [
        ('{"version": "two", "rms": 1, "noise_rms": 0, "experiment": "e", "data": "d"}', "'version' = 'two'"),
        ('{"version": 2, "rms": "abc", "noise_rms": 0, "experiment": "e", "data": "d"}', "'rms' = 'abc' is not"),
        ('{"version": 2, "rms": 1, "noise_rms": 0, "experiment": "e", "data": "d", "effects": "x"}', "'effects'"),
        ("[1, 2, 3]", "a list, not a history record"),
        ("[" * 50_000 + "]" * 50_000, "not valid JSON"),
    ],
    ids=["version", "rms", "effects", "list", "deep"],
)
def test_a_damaged_record_is_named(tmp_path, line, named):
    append_history(tmp_path, _record())
    with open(tmp_path / "history.jsonl", "a") as fh:
        fh.write(line + "\n")
    with pytest.raises(fm.FemastError, match="history.jsonl line 2") as err:
        read_history(tmp_path)
    assert named in str(err.value)


def _append_together(folder, barrier, rounds):
    for k in range(rounds):
        barrier.wait()
        append_history(folder, _record(k))


def test_concurrent_appends_get_distinct_versions(tmp_path):
    """Three compare runs appending at the same moments to a long history (reading it takes a while,
    so without a lock two of them would read the same length and write the same version)."""
    with open(tmp_path / "history.jsonl", "w") as fh:
        for k in range(3000):
            fh.write(json.dumps({"version": k + 1, **_record(k)}) + "\n")
    ctx = mp.get_context("spawn")
    barrier = ctx.Barrier(3)
    procs = [ctx.Process(target=_append_together, args=(str(tmp_path), barrier, 5)) for _ in range(3)]
    for p in procs:
        p.start()
    for p in procs:
        p.join(300)
    assert all(p.exitcode == 0 for p in procs)
    versions = [r["version"] for r in read_history(tmp_path)]
    assert versions == list(range(1, 3016)), sorted(v for v in set(versions) if versions.count(v) > 1)


def test_an_append_waits_for_the_one_in_progress(tmp_path):
    """Another compare holds the history (its append in progress): this one waits, then appends after it."""
    holder = textwrap.dedent(
        f"""
        import fcntl, time
        with open({str(tmp_path / "history.jsonl.lock")!r}, "w") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)  # the lock an append holds (docs/results.md)
            print("holding", flush=True)
            time.sleep(2.0)
            with open({str(tmp_path / "history.jsonl")!r}, "a") as fh:
                fh.write('{{"version": 1, "rms": 1.0, "noise_rms": 0.1, "experiment": "e", "data": "d"}}\\n')
        """
    )
    p = subprocess.Popen([sys.executable, "-c", holder], stdout=subprocess.PIPE, text=True)
    try:
        assert p.stdout.readline().strip() == "holding"
        t0 = time.monotonic()
        assert append_history(tmp_path, _record()) == 2  # after the holder's version 1, not a second 1
        assert time.monotonic() - t0 > 0.5  # (it did wait: the holder kept the lock ~2 s)
    finally:
        p.wait(60)
        p.stdout.close()
    assert [json.loads(x)["version"] for x in (tmp_path / "history.jsonl").read_text().splitlines()] == [1, 2]


def test_an_effect_name_that_looks_like_broken_maths_is_drawn_as_typed(tmp_path):
    from femast.experiments.history import plot_history

    rec = _record() | {"effects": ["$\\undefinedcmd{$"], "error_unit": "N m"}
    append_history(tmp_path, rec)
    append_history(tmp_path, _record(1) | {"error_unit": "N m"})
    png = plot_history(tmp_path)
    assert png.is_file() and png.stat().st_size > 1000


def test_compare_into_a_folder_with_a_damaged_history_says_so_in_one_line(tmp_path, capsys):
    from femast.cli import main

    (tmp_path / "history.jsonl").write_text(
        json.dumps({"version": 1, **_record()}) + "\n" + json.dumps({"version": "two", **_record(1)}) + "\n"
    )
    assert main(["compare", "latch-pull", "example", "--out", str(tmp_path)]) == 2
    said = capsys.readouterr().err
    err = [x for x in said.splitlines() if x.startswith("femast: error")]
    assert len(err) == 1 and "history.jsonl line 2: 'version' = 'two'" in err[0] and "fix or delete" in err[0], said
    assert "Traceback" not in said
