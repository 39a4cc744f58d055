"""ADAM-type deployable mast bays and masts (Stohlman & Pellegrino): builders, load paths, post-processing
and identification.  See ``docs/adam_bay.md`` and ``docs/adam_mast.md``.

    from femast.adam import BayParameters, build_bay, build_mast
"""

from .._moved import renamed_attributes
from .build import AdamModel, build_bay, build_mast, corner_xy
from .kinematics import eq1_height, eq1_twist
from .parameters import ADAM_BAY_HEIGHT, BayParameters

__all__ = [
    "AdamModel",
    "BayParameters",
    "ADAM_BAY_HEIGHT",
    "build_bay",
    "build_mast",
    "corner_xy",
    "eq1_height",
    "eq1_twist",
]

#: old names, kept for one release (they warn): femast 0.3 removes them
__getattr__ = renamed_attributes(__name__, {"SEED_BAY_HEIGHT": "ADAM_BAY_HEIGHT"})
