"""Old path of :mod:`femast.rigs.synthetic`: warns, and is removed in femast 0.3 (see femast/_moved.py)."""

from femast._moved import moved

moved(__name__, "femast.rigs.synthetic")
