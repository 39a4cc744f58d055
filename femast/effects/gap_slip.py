"""Slip through a gap with friction: the pinching of a dowel-type connection, driven by its load.

The physics (a nail, screw or dowel through a plate into timber, or a bolt in a hole):

* **Embedment.**  Pushed against the material beside it, the connector crushes it once the load
  exceeds the embedment strength ``R(e) = F_y + k_e e`` of the crushed depth ``e`` (linear
  hardening; ``F_y`` the onset, ``k_e`` the bearing stiffness of the crushed zone).  Crushing on the
  positive side leaves a hole edge at ``+e_p``, on the negative side at ``-e_n``; both only grow.
* **The gap.**  Between the edges the connector bears on nothing: it is held by friction ``F_f``
  (the plate on the timber, the shank in the hole) and by the bending of its own shank,
  ``k_g s`` towards its original position ``s = 0`` (the part of the connector deep in the
  uncrushed material does not move).  It rests at ``s`` wherever ``|F - k_g s| <= F_f``, and
  slides when the load leaves that band.
* **Pinching.**  After an excursion to one side, a reversed load first unloads the connector
  elastically (the baseline's stiffness), then slides it across the gap at a load of about
  ``F_f`` (the stiffness ``k_g``), and only where it meets the other edge does the joint stiffen
  again: the loop narrows (pinches) near zero load, by more the larger the past excursions.

Driven by the load ``F`` (force control: the row order is the path), the slip ``s`` follows

    e_p <- max(e_p, (F - F_y) / k_e),   e_n <- max(e_n, (-F - F_y) / k_e)
    s   <- clip(s, clip((F - F_f) / k_g, -e_n, e_p), clip((F + F_f) / k_g, -e_n, e_p))

(``k_g = 0``: ``s`` jumps to ``+e_p`` when ``F > F_f`` and to ``-e_n`` when ``F < -F_f``, a sharp
slip).  The connection's displacement is the elastic part (``F / k``, the baseline) plus ``s``.
Consistency needs ``F_f <= F_y`` (the connector slides before it crushes) and ``k_g <= k_e``
(it reaches an edge before that edge yields): larger values are used as ``F_y`` and ``k_e``.

Closed forms (``tests/effects/test_gap_slip.py``): under a monotonic load ``s = <F - F_y> / k_e``;
on symmetric load cycles ``+-F_m`` after the first (``e_p = e_n = e = (F_m - F_y) / k_e``), the
loop of ``F`` against ``s`` dissipates ``4 F_f e`` per cycle, for any ``k_g`` with ``k_g e >= F_f``
(two parallel branches ``F = k_g s +- F_f`` across the gap ``2 e``).

Units: ``F``, ``F_y``, ``F_f`` in the load's unit (N, or N m for a moment), ``k_e``, ``k_g`` in the
load's unit per displacement unit (N/m, N m/rad); ``s``, ``e`` in the displacement's unit.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def _gap_slip(F, F_y, k_e, F_f, k_g, s_out, e_out):
    """Columns of ``F`` (n, m) independent; per-column parameters (m,); writes s (n, m) and the edges
    ``e_out`` (n, m, 2) = (e_p, e_n) after each row."""
    n, m = F.shape
    for j in range(m):
        fy = F_y[j]
        ke = k_e[j]
        ff = min(F_f[j], fy)
        kg = min(k_g[j], ke)
        e_p = 0.0
        e_n = 0.0
        s = 0.0
        for i in range(n):
            f = F[i, j]
            if f > fy + ke * e_p:
                e_p = (f - fy) / ke
            elif -f > fy + ke * e_n:
                e_n = (-f - fy) / ke
            if kg > 0.0:
                lo = (f - ff) / kg
                hi = (f + ff) / kg
            else:
                lo = np.inf if f > ff else -np.inf
                hi = -np.inf if f < -ff else np.inf
            lo = min(max(lo, -e_n), e_p)
            hi = min(max(hi, -e_n), e_p)
            if s < lo:
                s = lo
            elif s > hi:
                s = hi
            s_out[i, j] = s
            e_out[i, j, 0] = e_p
            e_out[i, j, 1] = e_n


def _column_values(value, m: int, name: str) -> np.ndarray:
    v = np.asarray(value, dtype=float).ravel()
    if v.size == 1:
        v = np.full(m, v[0])
    if v.size != m:
        raise ValueError(f"gap_slip: {name} has {v.size} values for {m} load columns; give one or one per column")
    return v


def gap_slip(F, F_y, k_e, F_f, k_g=0.0, edges: bool = False):
    """Slip ``s`` of a connector through its embedment gap, driven by the load ``F`` (n,) or (n, m).

    F_y : embedment onset (load unit, > 0).  k_e : bearing stiffness of the crushed zone (load unit
    per displacement unit, > 0).  F_f : friction in the gap (load unit, >= 0; at most F_y).  k_g :
    bending stiffness of the connector across the gap (>= 0; at most k_e; 0: a sharp slip).  Each may
    be one value or one per column of ``F`` (a connection loaded about several axes).  Returns ``s``
    in the shape of ``F``; with ``edges=True`` also the hole edges ``(e_p, e_n)`` after each row,
    shape ``F.shape + (2,)`` (both >= 0: the edges are at ``+e_p`` and ``-e_n``).
    """
    F = np.asarray(F, dtype=float)
    F2 = np.ascontiguousarray(F.reshape(F.shape[0], -1))
    m = F2.shape[1]
    F_y, k_e, F_f, k_g = (_column_values(v, m, n) for v, n in ((F_y, "F_y"), (k_e, "k_e"), (F_f, "F_f"), (k_g, "k_g")))
    if np.any(F_y <= 0) or np.any(k_e <= 0) or np.any(F_f < 0) or np.any(k_g < 0):
        raise ValueError("gap_slip: F_y and k_e must be > 0, F_f and k_g >= 0")
    s = np.empty_like(F2)
    e = np.empty(F2.shape + (2,))
    _gap_slip(F2, F_y, k_e, F_f, k_g, s, e)
    s = s.reshape(F.shape)
    return (s, e.reshape(F.shape + (2,))) if edges else s
