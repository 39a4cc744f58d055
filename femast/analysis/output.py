"""Output as an observer: the results writer and the ``on_frame`` recorders.

The step loop (stepping.py) knows nothing of files.  It tells its observers what happened:

* ``started(analysis)``: before the first step (the initial state);
* ``cutback(analysis, step, increment, attempt, iterations, time, total_time, dtime, lam, note)``:
  an attempt failed and is retried smaller;
* ``converged(analysis, step, increment, attempt, iterations, time, dtime, last, responses, note)``:
  an increment converged and is committed (``last``: the step's last increment);
* ``stopped(analysis)``: the run gives up (after a :class:`~femast.errors.ConvergenceError`);
* ``finished(analysis)``: the run is over, however it ended (the summary is final).

An observer implements the methods it needs (:class:`Observer` has them all, doing nothing).
:class:`ResultsOutput` is the one every analysis has: it builds a frame (the arrays of a record
of ``frames/frames.npzs``, femast/post/results.py) at the step's output frequency and hands it to
the results writer and to every ``on_frame`` recorder.
"""

from __future__ import annotations

import sys
from collections.abc import Mapping

import numpy as np

from ..post import folder as folder_files  # noqa: F401 (the folder's file rules, for the restart observer)
from ..post.frame_coder import SCALARS, FrameCoder
from ..post.writer import NullWriter, ResultsWriter
from ..rotations import rotation_vectors


class Observer:
    """Does nothing on every event; subclass and override the events you need."""

    def started(self, analysis):
        pass

    def cutback(self, analysis, step, increment, attempt, iterations, time, total_time, dtime, lam, note):
        pass

    def converged(self, analysis, step, increment, attempt, iterations, time, dtime, last, responses, note):
        pass

    def stopped(self, analysis):
        pass

    def finished(self, analysis):
        pass


class ResultsOutput(Observer):
    """Frames and status lines of a run: to the results folder ``out`` (None: no folder) and to the
    ``recorders`` (callables taking a frame dict; do not modify its arrays: they are being written)."""

    def __init__(self, out, recorders=()):
        self.out = out
        self.recorders = [r for r in recorders if r is not None]
        self.writer = None
        self.pending = None  # a converged increment not written yet (Step.output_frequency)
        self.coder, self.coders_made = None, 0  # frames encoded from the state (frame_coder.py)

    @property
    def active(self) -> bool:
        """Whether frames go anywhere (a folder or a recorder)."""
        return self.out is not None or bool(self.recorders)

    def started(self, analysis):
        resume = getattr(analysis, "resume", None)  # a restarted run (restart.py): frames on disk kept
        self.writer = (
            NullWriter()
            if self.out is None
            else ResultsWriter(
                self.out,
                analysis.model,
                analysis.families,
                resume=None if resume is None else resume["frames"],
                lock=getattr(analysis, "folder_lock", None),
            )
        )
        self.pending = None
        if resume is None:
            self.frame(analysis, step_name="initial", inc=0, time=0.0, iterations=0, responses=None)

    @property
    def frames(self) -> int:
        """Frames written so far."""
        return self.writer.count if self.writer is not None else 0

    def flush(self):
        """Make every frame written so far durable (fsync of the frame log; a restart point names them)."""
        if self.writer is not None:
            self.writer.flush()

    def cutback(self, analysis, step, increment, attempt, iterations, time, total_time, dtime, lam, note):
        self.writer.status(step.name, increment, attempt, iterations, time, total_time, dtime, lam, f"cutback: {note}")

    def converged(self, analysis, step, increment, attempt, iterations, time, dtime, last, responses, note):
        """Write the frame of increment ``increment`` if the step's output frequency asks for it or
        it is the step's ``last``; else keep it pending.  Then the status line."""
        frame = (step.name, increment, time, iterations, responses)
        st = analysis.state
        line = (step.name, increment, attempt, iterations, time, st.total_time, dtime, st.lam, note)
        if last or increment % step.output_frequency == 0:
            self.frame(analysis, *frame)  # on the OS before the status line says it converged
            self.pending = None
        else:
            self.pending = frame
        self.writer.status(*line)

    def stopped(self, analysis):
        if self.pending is not None:  # the state is that of the last converged increment
            self.frame(analysis, *self.pending)
            self.pending = None

    def finished(self, analysis):
        if self.writer is not None:
            self.writer.close({**analysis.summary.__dict__, "strain_energy": analysis.state.strain_energy})

    def frame(self, analysis, step_name, inc, time, iterations, responses):
        """Build the frame of the current (converged) state and hand it to the writer and recorders."""
        if not self.active:
            return
        st, sys_ = analysis.state, analysis.system
        converged = responses is not None  # (the initial frame has no reactions)
        if responses is None:
            responses = sys_.evaluate(sys_.committed_context())
        outputs = {f.name: r.output for f, r in zip(analysis.families, responses)}
        scalars = (step_name, inc, time, st.total_time, st.lam, iterations, st.strain_energy, st.stabilization_energy)
        if self.coder is not None and not self.recorders:  # a folder only: the run's frames repeat one layout
            record = self.coder.record(
                scalars,
                st.x,
                sys_.X0,
                st.R,
                st.spin,
                st.loads,
                sys_.cons_node,
                sys_.cons_dof,
                st.reactions if converged else None,
                outputs,
            )
            if record is not None:
                self.writer.append(record)
                return
        n = len(sys_.X0)

        def reactions():
            RF = np.zeros((n, 6))
            if converged:
                RF[sys_.cons_node, sys_.cons_dof] = st.reactions
            return RF

        state = {
            "U": lambda: st.x - sys_.X0,
            "R": lambda: st.R.copy(),
            "UR": lambda: rotation_vectors(st.R),
            "URA": lambda: st.spin.copy(),
            "RF": reactions,
            "P": lambda: st.loads.copy(),
        }
        data = dict(zip(SCALARS, scalars))
        if isinstance(self.writer, NullWriter):
            # recorders only (out=None): a frame that computes what a recorder reads (an FE
            # experiment reads a few arrays of each increment); one kept by a recorder is completed
            frame = LazyFrame(data, state, outputs)
            self.writer.frame()
            for record in self.recorders:
                record(frame)
            if sys.getrefcount(frame) > 2:  # (this name and getrefcount's argument)
                frame.complete()
            return
        if self.recorders:  # a recorder may keep the arrays: the state's own are copied
            data.update({k: make() for k, make in state.items()})
        else:  # written at once (ResultsWriter.frame): the state's arrays as they are
            data.update(U=st.x - sys_.X0, R=st.R, UR=rotation_vectors(st.R), URA=st.spin, RF=reactions(), P=st.loads)
        for name, out in outputs.items():
            for key, val in out.items():
                data[f"el/{name}/{key}"] = val
        self.writer.frame(**data)
        if not self.recorders and self.coders_made < 8:  # (made again after a new step name; not forever)
            self.coders_made += 1
            self.coder = FrameCoder.make(data, n)
        for record in self.recorders:
            record(data)


class LazyFrame(Mapping):
    """The frame dict of a run without a results folder (only ``on_frame`` recorders), built on
    reading: the state arrays (U, R, UR, URA, RF, P) and each family's element outputs
    (``el/FAMILY/NAME``) are computed when first read; iterating it (``dict(frame)``,
    ``frame.items()``) computes everything.  A recorder that keeps the frame itself (not only arrays
    read from it) gets it completed before the analysis moves on (:meth:`complete`).  Keys, values
    and their order are those of the dict written to a results folder."""

    def __init__(self, data: dict, state: dict, outputs: dict):
        self._data, self._state, self._outputs = data, state, outputs
        self._done = False

    def __getitem__(self, key):
        d = self._data
        if key in d:
            return d[key]
        make = self._state.get(key)
        if make is not None:
            d[key] = v = make()
            return v
        if isinstance(key, str) and key.startswith("el/"):
            fam, _, name = key[3:].partition("/")
            out = self._outputs.get(fam)
            if out is not None and name in out:
                d[key] = v = out[name]
                return v
        raise KeyError(key)

    def complete(self) -> dict:
        """Compute every entry (in the order of a written frame); returns the plain dict."""
        if not self._done:
            d = self._data
            full = {k: d[k] for k in ("step", "increment", "time", "total_time", "load_factor", "iterations")}
            full.update({k: d[k] if k in d else make() for k, make in self._state.items()})
            full.update({k: d[k] for k in ("strain_energy", "stabilization_energy")})
            for fam, out in self._outputs.items():
                for name, val in out.items():
                    full[f"el/{fam}/{name}"] = val
            self._data, self._done = full, True
        return self._data

    def __iter__(self):
        return iter(self.complete())

    def __len__(self):
        return len(self.complete())

    def __contains__(self, key):
        try:
            self[key]
        except KeyError:
            return False
        return True
