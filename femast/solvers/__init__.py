"""Old path of :mod:`femast.analysis.solvers` (itself an old path: its modules warn and name their
new places); removed in femast 0.3 (see femast/_moved.py)."""

from femast._moved import moved

moved(__name__, "femast.analysis.solvers", warn=False)
