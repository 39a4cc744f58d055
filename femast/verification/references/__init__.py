"""Independent reference solutions for verifying the femast FE core.

Every function here is written from beam/truss theory, without any femast
element or solver code, so that the FE results can be checked against it.
Consistent units throughout: give E, G in force/length^2, lengths in length,
and forces come back in force (SI or the inch-pound units of the classic
benchmarks).  The docstring of each item names its literature source; where a
published number could not be confirmed it says so and gives a closed-form or
high-accuracy numerical reference instead.

One module per subject, every name re-exported here: :mod:`.cantilever` (elastica, pure bending,
linear compliance), :mod:`.bend45`, :mod:`.columns` (Euler columns, von Mises truss),
:mod:`.planar` (Lee's frame, Williams' toggle).

Contents (the verification cases of the FE core and its controls)
-----------------------------------------------------------------
* :func:`elastica_tip_load` -- cantilever under a transverse dead end load,
  exact elliptic-integral solution; :data:`MATTIASSON_1981` (published table).
* :func:`pure_bending_tip`, :func:`pure_bending_shape` -- cantilever under an end
  moment (circular arc, any moment, e.g. full circle or wound twice).
* :func:`bend45_tip_position`, :data:`BEND45_PUBLISHED` -- the 45-degree circular
  arc cantilever of Bathe and Bolourchi (1979): a converged Kirchhoff-rod
  shooting solution plus the published tip positions of several authors.
* :func:`euler_critical_load`, :func:`imperfect_column_deflection`,
  :func:`euler_column_postbuckling` -- Euler columns.
* :func:`von_mises_truss_load`, :func:`von_mises_truss_limit_points` -- the
  shallow two-bar truss, exact for axially elastic bars.
* :func:`lee_frame_path`, :func:`lee_frame_limit_load`, :data:`LEE_FRAME_PUBLISHED`
  -- Lee's frame; :func:`williams_toggle_path`, :func:`williams_toggle_limit_load`
  -- Williams' toggle.  Both from a high-accuracy planar elastica
  (shooting + pseudo-arclength continuation) of extensible Euler-Bernoulli bars.
* :func:`cantilever_compliance` -- 6x6 linear tip compliance of a cantilever.
"""

from .bend45 import BEND45, BEND45_COMMON_REFERENCE, BEND45_PUBLISHED, bend45_tip_position
from .cantilever import (
    MATTIASSON_1981,
    ElasticaTip,
    cantilever_compliance,
    elastica_tip_load,
    pure_bending_shape,
    pure_bending_tip,
)
from .columns import (
    EULER_SUPPORTS,
    euler_column_postbuckling,
    euler_critical_load,
    imperfect_column_deflection,
    von_mises_truss_limit_points,
    von_mises_truss_load,
)
from .planar import (
    LEE_FRAME,
    LEE_FRAME_PUBLISHED,
    WILLIAMS_TOGGLE,
    PlanarPath,
    lee_frame_limit_load,
    lee_frame_path,
    williams_toggle_limit_load,
    williams_toggle_path,
)

__all__ = [
    "ElasticaTip",
    "elastica_tip_load",
    "MATTIASSON_1981",
    "pure_bending_tip",
    "pure_bending_shape",
    "BEND45",
    "BEND45_PUBLISHED",
    "BEND45_COMMON_REFERENCE",
    "bend45_tip_position",
    "euler_critical_load",
    "EULER_SUPPORTS",
    "imperfect_column_deflection",
    "euler_column_postbuckling",
    "von_mises_truss_load",
    "von_mises_truss_limit_points",
    "PlanarPath",
    "lee_frame_path",
    "lee_frame_limit_load",
    "LEE_FRAME",
    "LEE_FRAME_PUBLISHED",
    "williams_toggle_path",
    "williams_toggle_limit_load",
    "WILLIAMS_TOGGLE",
    "cantilever_compliance",
]
