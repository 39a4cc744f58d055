"""Restart (Abaqus *RESTART): save the analysis state at converged increments, continue a killed
or stopped run from the last one saved.

``Analysis(model, out, restart_every=n)`` saves, every n-th converged increment and at the last
increment of every step, everything the run needs to go on into ``<out>/restart/``:

* ``state-<k>.npz``: the :class:`~femast.analysis.state.State` (configuration, element states,
  loads, prescribed values, load factor, times, increment sizes, damping...), bit for bit;
* ``extra-<k>.npz``: the loads and prescribed values at the start of the step in progress (the
  step's loads ramp from them), and the configuration at which the factorisation that the next
  increment's first iteration reuses was formed (newton.py, ``tangent="auto"``), if any;
* ``restart.json``: which step and increment, how many frames are on disk, the run's counts so far,
  the convergence floor of the run (its first tangent's), and the names of the two files.  It is
  written last (atomically), so a run killed while saving keeps the previous restart point.

Before saving, the results writer is drained, so every frame up to the restart point is on disk.

``Analysis(model, out, restart=folder)`` (or ``femast run SCRIPT --restart FOLDER``, which sets the
environment variable ``FEMAST_RESTART`` for the analyses of the script whose ``out`` is FOLDER)
loads the restart point of ``folder``, keeps the frames written up to it (later ones, and partial
files, are removed), and continues: the frames it writes are the uninterrupted run's, bit for bit
(tested with kill -9 at random moments).  Conditions: the same model and analysis options, the
default full Newton tangent (a "modified" or "initial" tangent would be formed at another state),
and, for stabilised steps, a restart point after them or in the first one (the linear solver's
ordering may otherwise be analysed from another pattern and move the results at round-off).
"""

from __future__ import annotations

import io
import json
import os
import re
import stat
from dataclasses import fields
from pathlib import Path

import numpy as np

from ..errors import FemastError
from .output import Observer, folder_files
from .restart_check import FORMAT, check_arrays, check_point
from .state import State

RESTART_DIR = "restart"
ENV = "FEMAST_RESTART"
_OWN = re.compile(r"^(?:(?:state|extra)-[1-9]\d{0,17}\.npz|restart\.json)(?:\.tmp)?$")  # the files it writes


def restart_folder(out, restart):
    """The folder to restart from: ``restart`` if given, else ``$FEMAST_RESTART`` when it names the
    results folder ``out`` (``femast run SCRIPT --restart FOLDER``), else None."""
    if restart is not None:
        return Path(restart)
    env = os.environ.get(ENV)
    if env and out is not None and Path(env).resolve() == Path(out).resolve():
        return Path(env)
    return None


class RestartOutput(Observer):
    """Saves the restart point every ``every`` converged increments and at each step's end."""

    def __init__(self, every: int | None):
        self.every = every  # None: the restarted run's (1 for a fresh run)
        self.saves = 0
        self.folder = None
        self.step_start = None

    def started(self, analysis):
        if analysis.out is None:
            raise FemastError("restart_every needs a results folder (out=None writes nothing to restart from)")
        self.writer = analysis.output.writer  # every file of the results folder goes through it
        self.folder = folder_files.own_dir(analysis.out, RESTART_DIR)  # (a link there is refused)
        resume = analysis.resume
        if resume is None:  # a fresh run: an earlier run's restart point is stale (only its files go)
            for f in sorted(self.folder.iterdir()):
                if _OWN.match(f.name):
                    folder_files.remove_own(f)
            st = analysis.state
            self.step_start = (st.loads.copy(), st.prescribed.copy())
            # the start is a restart point too: a run killed before its first save starts over
            self._write_json({"format": FORMAT, "initial": True, **_model_id(analysis)})
        else:
            self.saves = resume["saves"]
            self.step_start = resume["step_start"]
            if self.every is None:
                self.every = resume["every"]
        if self.every is None:
            self.every = 1

    def converged(self, analysis, step, increment, attempt, iterations, time, dtime, last, responses, note):
        if last or increment % self.every == 0:
            self.save(analysis, step_done=last)
        if last:  # the next step starts from this state
            st = analysis.state
            self.step_start = (st.loads.copy(), st.prescribed.copy())

    def _write_json(self, info: dict):
        self.writer.write_file(self.folder / "restart.json", json.dumps(info, indent=1).encode(), sync=True)

    def save(self, analysis, step_done: bool):
        an, st, summary = analysis, analysis.state, analysis.summary
        an.output.flush()  # every frame up to here on disk (fsync'd) before the restart point names them
        self.saves += 1
        k = self.saves
        state_file, extra_file = f"state-{k}.npz", f"extra-{k}.npz"
        buf = io.BytesIO()
        st.save(buf)
        self.writer.write_file(self.folder / state_file, buf.getvalue(), sync=True)
        reuse = an.algorithm.reuse_configuration()  # the factorisation the next increment reuses
        extra = {} if reuse is None else {"reuse_x": reuse[0], "reuse_R": reuse[1]}
        buf = io.BytesIO()
        np.savez(buf, load_start=self.step_start[0], pres_start=self.step_start[1], **extra)
        self.writer.write_file(self.folder / extra_file, buf.getvalue(), sync=True)
        done_iters = sum(s["iterations"] for s in summary.steps)
        zf = an.system.zero_force
        info = {
            "format": FORMAT,
            "step": int(st.step),
            "step_name": an.model.steps[st.step].name,
            "step_done": bool(step_done),
            "increment": int(st.increment),
            "frames": an.output.frames,
            "saves": k,
            "every": self.every,
            "state_file": state_file,
            "extra_file": extra_file,
            "zero_force": None if zf is None else float(zf).hex(),
            **_model_id(an),
            "summary": {
                "increments": summary.increments,
                "iterations": summary.iterations,
                "cutbacks": summary.cutbacks,
                "line_searches": summary.line_searches,
                "steps": summary.steps,
                "step_iterations": summary.iterations - done_iters,
            },
        }
        self._write_json(info)
        for f in sorted(self.folder.iterdir()):  # the previous restart point's files
            if _OWN.match(f.name) and f.name.endswith(".npz") and f.name not in (state_file, extra_file):
                folder_files.remove_own(f)


def _model_id(analysis) -> dict:
    return {"n_nodes": int(len(analysis.system.X0)), "steps": [s.name for s in analysis.model.steps]}


def require_point(folder) -> Path:
    """The restart.json of results folder ``folder``, or a FemastError saying there is none."""
    jfile = Path(folder) / RESTART_DIR / "restart.json"
    st = folder_files.lstat_or_none(jfile)
    if st is not None and not stat.S_ISREG(st.st_mode):  # a link, FIFO, folder...: named, never followed
        raise FemastError(f"{folder}: the restart point is refused: {folder_files.refusal(jfile, st.st_mode, 'reads')}")
    if st is None:
        raise FemastError(
            f"{folder}: no restart point ({jfile} is missing); run the analysis with "
            "restart_every=n (a restart point every n increments) to be able to restart it"
        )
    return jfile


def load_restart(folder, analysis) -> dict | None:
    """Read the restart point of results folder ``folder`` for ``analysis`` (same model): a dict
    with the State and what the run needs to go on, or None when the point is the run's start (the
    run starts over); a FemastError naming the folder otherwise.  Every value is checked
    (restart_check.py): a restart point edited by hand or damaged is refused, never half-used."""
    folder = Path(folder)
    rdir = folder / RESTART_DIR
    jfile = require_point(folder)
    try:
        folder_files.own_dir(folder, RESTART_DIR)  # (a link is refused)
        info = check_point(folder_files.read_json(jfile, "restart point"), jfile, analysis)
        if info.get("initial"):
            state = None
        else:
            with folder_files.open_regular(rdir / info["state_file"]) as fh:
                state = State.load(io.BytesIO(fh.read()))
            with folder_files.open_regular(rdir / info["extra_file"]) as fh:
                z = np.load(io.BytesIO(fh.read()), allow_pickle=False)
                step_start = (z["load_start"], z["pres_start"])
                reuse = (z["reuse_x"], z["reuse_R"]) if "reuse_x" in z.files else None
            check_arrays(state, step_start, reuse, analysis, rdir)
            if (state.step, state.increment) != (info["step"], info["increment"]):
                raise FemastError(
                    f"{rdir / info['state_file']}: the state is at step {state.step} increment {state.increment}, "
                    f"restart.json says step {info['step']} increment {info['increment']}"
                )
    except FemastError as exc:
        raise FemastError(
            f"{folder}: the restart point is refused: {exc}; run the analysis again from the start"
        ) from None
    except Exception as exc:
        raise FemastError(
            f"{folder}: the restart point is unreadable ({type(exc).__name__}: {exc}); "
            "run the analysis again from the start"
        ) from None
    if state is None:
        return None
    info.update(state=state, step_start=step_start, folder=folder, reuse=reuse)
    return info


def restore(analysis, info) -> None:
    """Put the restart point ``info`` into ``analysis``: the state (in place: the analysis' parts
    hold the State object), the convergence floor and the run's counts."""
    st = analysis.state
    saved = info["state"]
    for f in fields(State):
        if f.name != "_saved":
            setattr(st, f.name, getattr(saved, f.name))
    if info["zero_force"] is not None:
        analysis.system.zero_force = float.fromhex(info["zero_force"])
    if info.get("reuse") is not None:  # the factorisation the next increment reuses: formed again there
        analysis.algorithm.resume_reuse(st.version, *info["reuse"])
    s = info["summary"]
    summ = analysis.summary
    summ.increments, summ.iterations = s["increments"], s["iterations"]
    summ.cutbacks, summ.line_searches = s["cutbacks"], s["line_searches"]
    summ.steps = list(s["steps"])
