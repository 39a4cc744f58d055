"""What a run did (:class:`AnalysisSummary`)."""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass
class AnalysisSummary:
    """What a run did: counts, wall time and where it stopped."""

    completed: bool = False  # True only once every step has run (status "completed")
    status: str = "running"  # "running", then "completed", "failed" or "interrupted"
    increments: int = 0
    iterations: int = 0
    cutbacks: int = 0
    line_searches: int = 0
    wall_time: float = 0.0
    # wall time in the steps' increments (s): the run without its results-folder set-up, initial
    # frame, final drain of the writer and summary (per-run costs, not per-iteration ones)
    increment_time: float = 0.0
    assembly_time: float = 0.0
    solve_time: float = 0.0
    message: str = ""
    steps: list = field(default_factory=list)

    def __str__(self):
        state = {"completed": "completed", "interrupted": "INTERRUPTED"}.get(self.status, "FAILED")
        return (
            f"femast: analysis {state}: {_count(self.increments, 'increment')}, "
            f"{_count(self.iterations, 'Newton iteration')}, {_count(self.cutbacks, 'cutback')}, wall time {self.wall_time:.2f} s "
            f"(assembly {self.assembly_time:.2f} s, linear solve {self.solve_time:.2f} s)"
            + (f"\n  {self.message}" if self.message else "")
        )


def _count(n: int, noun: str) -> str:
    """``1 increment``, ``13 increments`` (as femast.text.count; the analysis imports no top-level helpers)."""
    return f"{n} {noun}{'' if n == 1 else 's'}"
