"""Old path of :mod:`femast.rigs` (the built-in rigs, now a package above the experiments framework):
warns, gives ``femast.rigs``' names, and is removed in femast 0.3 (see femast/_moved.py).  Its modules
are old paths of their own, so that a rig module is loaded once, under its new name."""

from femast._moved import moved_package

__getattr__ = moved_package(__name__, "femast.rigs")
