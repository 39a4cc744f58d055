"""The four Rocaspect masts under each mast model, as :class:`~.platform_pose.MastSet`.

* ``"3R"``: Eqs. 4-6 (corrected J) with the Table III joint stiffnesses of the 50 kg tests at the
  shroud pretension (0 N: test "5 and 9", 400 N: "4", 800 N: "3", 1200 N: "1 and 8"; ``None``,
  detached shrouds: "7 and 10"); torsion joint rigid (unidentified in the paper).
* ``"beam"``: the cantilever of Eqs. 8-15 with the shrouds lumped into E, as the paper does: E =
  6.55e10 Pa without shrouds and 1.55e11 Pa at 1200 N (the paper); between them E is interpolated
  linearly in the pretension (an assumption: the paper identifies only these two).
* ``"beam+shroud"``: the complete model of Eqs. 16-26 (bare beam E = 6.55e10 Pa plus three
  shrouds at the pretension, tangent Dyneema stiffness, :func:`.rocaspect.rocaspect_shrouds`).
* ``"FE"``: :class:`~.fe_mast.MastFE` per mast, pretension equilibrated, condensed tangent as the
  linear part and the nonlinear FE run along the trajectory (:func:`.platform_pose.pose_trajectory`).
"""

from __future__ import annotations

import numpy as np

from ..errors import ModelError
from .cantilever import cantilever_compliance, cantilever_stiffness, mast_section
from .complete_mast import mast_stiffness
from .mast_3r import compliance_3r
from .platform_pose import MastSet
from .rocaspect import E_1200N, E_NO_SHROUD, L_BEAM, TABLE_III, mast_bases, mast_tops, rocaspect_shrouds

MODELS = ("3R", "beam", "beam+shroud", "FE")
_TEST_OF = {None: "7 and 10", 0.0: "5 and 9", 400.0: "4", 800.0: "3", 1200.0: "1 and 8"}


def _check(pretension):
    if pretension is not None and not (np.isfinite(pretension) and 0.0 <= pretension <= 1200.0):
        raise ModelError(
            f"shroud pretension {pretension!r} N: the Rocaspect masts are identified for 0 to 1200 N "
            "(None: shrouds detached)"
        )


def masts_3r(pretension) -> MastSet:
    """3R masts with the Table III stiffness of the test at ``pretension`` (N; 0, 400, 800, 1200 or None)."""
    _check(pretension)
    key = None if pretension is None else float(pretension)
    if key not in _TEST_OF:
        raise ModelError(
            f"Table III has 3R stiffnesses for pretensions {sorted(k for k in _TEST_OF if k is not None)} N "
            f"(or None, detached); got {pretension!r}"
        )
    k = (*TABLE_III[_TEST_OF[key]][2:], np.inf)
    C = np.array([compliance_3r(k, t - b) for t, b in zip(mast_tops(), mast_bases())])
    return MastSet(f"3R ({pretension} N)", C)


def beam_E(pretension) -> float:
    """Beam-model E (Pa) at the pretension (N): the paper's values at 0 (no shrouds) and 1200 N, linear between."""
    _check(pretension)
    p = 0.0 if pretension is None else float(pretension)
    return E_NO_SHROUD + (E_1200N - E_NO_SHROUD) * p / 1200.0


def masts_beam(pretension) -> MastSet:
    """Cantilever masts (Eqs. 8-15) with E from :func:`beam_E`."""
    C = cantilever_compliance(L_BEAM, mast_section(beam_E(pretension)))
    return MastSet(f"beam ({pretension} N)", np.repeat(C[None], 4, axis=0))


def masts_complete(pretension) -> MastSet:
    """Beam + shroud masts (Eqs. 16-26) at the pretension (N; None: detached = the bare beam)."""
    _check(pretension)
    K_beam = cantilever_stiffness(L_BEAM, mast_section(E_NO_SHROUD))
    C = []
    for i, top in enumerate(mast_tops()):
        sh = None if pretension is None else rocaspect_shrouds(i, pretension)
        C.append(mast_stiffness(K_beam, top, sh).compliance)
    return MastSet(f"beam+shroud ({pretension} N)", np.array(C))


def masts_fe(pretension, n_beam: int = 16) -> MastSet:
    """FE guyed masts (:class:`~.fe_mast.MastFE`, one per mast, pretension equilibrated)."""
    from .fe_mast import MastFE

    _check(pretension)
    fes, C = [], []
    for i in range(4):
        fe = MastFE(pretension, mast=i, E=E_NO_SHROUD, n_beam=n_beam)
        fe.equilibrate()
        C.append(np.linalg.inv(fe.top_stiffness("full")))
        fes.append(fe)
    return MastSet(f"FE ({pretension} N)", np.array(C), fe=fes)


def mast_set(model: str, pretension) -> MastSet:
    """One of :data:`MODELS` at the pretension (N)."""
    makers = {"3R": masts_3r, "beam": masts_beam, "beam+shroud": masts_complete, "FE": masts_fe}
    if model not in makers:
        raise ModelError(f"unknown mast model {model!r}; use one of {', '.join(MODELS)}")
    return makers[model](pretension)
