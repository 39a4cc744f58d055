"""Exceptions raised by femast.

Every error names the offending item (node label, element, DOF, file line...)
and says what to do about it.  Catch :class:`FemastError` to catch them all.
"""


class FemastError(Exception):
    """Base class of every error femast raises on purpose."""


class ModelError(FemastError, ValueError):
    """The model definition is invalid (unknown node, zero-length element, ...)."""


class SingularModelError(FemastError):
    """The tangent stiffness is singular: the model has a mechanism or rigid-body mode."""


class ElementConvergenceError(FemastError, FloatingPointError):
    """An element's own equations (a cable's device equations) did not converge at a trial
    configuration.  The analysis treats it as a failed attempt and cuts the increment back (it is a
    FloatingPointError for the Newton loop); called directly, it says what to change."""


class ConvergenceError(FemastError):
    """The solver gave up on a step after cutting the increment back to its minimum."""


class DataFileError(FemastError, ValueError):
    """A measured-data file is malformed."""


class NonFiniteError(FemastError, FloatingPointError):
    """An element family returned NaN or infinite internal forces.  Inside an increment it is a failed
    attempt (a cutback: a too-large increment can drive a law out of its range); anywhere else (the
    initial state, the end of a run) it stops the run, naming the family and the element."""


class EquilibriumError(FemastError):
    """A converged increment whose reactions do not balance the applied loads (a lost load)."""


class StateError(FemastError, ValueError):
    """An analysis state cannot be used as asked (e.g. a modal analysis of a state that is not in
    equilibrium)."""


class StudyError(FemastError, ValueError):
    """A study (femast.studies) is set up wrongly: an impossible distribution, an input or output
    that matches nothing, a scheduler that cannot be reached.  Raised before any sample runs."""


class ResultsWriteError(FemastError, OSError):
    """A results folder could not be written (a full disk, a folder that became read-only): the
    run stops at the frame that could not be written and its summary says "failed"."""


class FolderInUseError(FemastError):
    """A results (or history) folder is being written by another femast run: two writers would mix
    their frames, so the second is refused; the message names the folder and the other process."""


class SampleTimeout(FemastError):
    """A sample of a study ran longer than the study's ``timeout_s`` (it is recorded as failed)."""


class WorkerDied(FemastError):
    """A worker process of a :class:`femast.workers.Pool` died running a task (killed, out of
    memory, a crash in compiled code), or the pool was stopped before the task ran."""


class TaskTimeout(FemastError, TimeoutError):
    """A task of a :class:`femast.workers.Pool` ran over its time-out; its worker was killed."""


def did_you_mean(name, choices) -> str:
    """`` (did you mean 'x'?)`` for the choice closest to a mistyped ``name`` (difflib's ratio of at
    least 0.6), or ``""`` when none is close: the tail of an "unknown ..." message."""
    import difflib

    close = difflib.get_close_matches(str(name), [str(c) for c in choices], n=1, cutoff=0.6)
    return f" (did you mean '{close[0]}'?)" if close else ""
