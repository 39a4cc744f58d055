"""Time dependence at constant load: creep told from friction by the holds of a test.

A rate-independent mechanism -- friction, a gap, a stiffening, pinching, damage -- moves the
displacement only when the load changes: while the load is held, the displacement holds too,
whatever the history before.  Creep (and relaxation, a slipping grip, a thermal drift) moves it on
at constant load, in the direction of the last load change, more slowly as the hold goes on.  Both
can leave a residual that follows the loops of a cyclic test, so the shape of the loops does not
tell them apart; the holds do.

:func:`holds` finds them: runs of at least ``MIN_HOLD_ROWS`` rows over which the load stays within
``HOLD_TOL`` noise of its first value. A hold must be a pause of the test: a load that stays flat
while the response moves on (by more than 3 noise) as fast as the ramp into it drove it (more than
``PAUSE_RATE`` = 0.5 of that rate) is a plateau -- a connection yielding under displacement
control -- and is not counted.
:func:`hold_drift` measures, in each hold, the change of a channel (measured, or the residual of
any rate-independent model: the same within a hold) from the hold's first third to its last third,
in units of its noise, signed by the direction of the load change that led into the hold (creep
goes on that way). Over ``H`` holds the mean of those signed changes divided by its standard error
across the holds is ``t``, Student-t with ``H - 1`` degrees of freedom when nothing moves at
constant load; it does not depend on the noise level or its correlation, which the scatter between
holds carries. ``t > CREEP_T`` (4: p < 0.002 one-sided for the fewest holds, ``MIN_HOLDS`` = 4)
says the displacement keeps moving at constant load.

In ``diagnose`` (:func:`creep_overrules`, on :func:`time_check` of the measured channels): where the
response keeps moving at constant load, a verdict that names only rate-independent effects is
wrong whatever their fit says -- a friction form can follow the loops of a creeping joint -- and
becomes "not explained" with the finding; an effect whose mechanism reads the time
(``pretension_loss``, a user's creep) may still be named.

Measured (``tests/experiments/test_time_dependence.py``; the generalisation benchmark's mast-top
rig with the load held at every peak and at zero, 16 holds of 15 rows, four noise draws each):
logarithmic creep of the joints (``phi = 0.08``, the displacement at the noise after a hold of
7.5 s) gives ``t`` = 6.8-8.6, elasto-slip friction and the plain joint -0.4 to 1.7, the plain joint
with AR(1) noise (``phi = 0.6``) -0.4 to 1.3.
"""

from __future__ import annotations

import numpy as np

from ..errors import ModelError

MIN_HOLD_ROWS = 6  # rows of a hold: its first and last thirds need two rows each
HOLD_TOL = 3.0  # a hold: the load within 3 noise of its first value
MIN_HOLDS = 4
CREEP_T = 4.0
PAUSE_RATE = 0.5  # a hold is a pause: the response moves at most half as fast as on the ramp into it


def holds(load, noise: float = 0.0, min_rows: int = MIN_HOLD_ROWS) -> list[tuple[int, int]]:
    """``[(first row, last row)]`` of the runs of ``load`` (n,) that stay within ``HOLD_TOL`` x
    ``noise`` (the load's unit) of their first value for at least ``min_rows`` rows."""
    s = np.asarray(load, dtype=float)
    tol = HOLD_TOL * max(float(noise), 0.0) + 1e-12 * (float(np.max(np.abs(s))) if s.size else 0.0)
    out, i, n = [], 0, s.size
    while i < n:
        j = i
        while j + 1 < n and abs(s[j + 1] - s[i]) <= tol:
            j += 1
        if j - i + 1 >= min_rows:
            out.append((i, j))
        i = j + 1
    return out


def hold_drift(load, measured: dict, sigma: dict, noise_load: float = 0.0) -> dict:
    """Does the response move while the load is held?  (module docstring)

    load : (n,) the signed load of the path.  measured : ``{channel: (n,)}`` the measured response
    (within a hold the residual of any rate-independent model is the measured value less a
    constant).  sigma : ``{channel: noise}`` (a level or (n,) per row).  noise_load : noise of ``load``.
    The channels are combined along the direction the load moves them (their least-squares slopes
    on the load, in noise units), and each hold's change is signed by the load change that led into
    it: creep carries the response on the way the load last moved it.  Returns ``{"holds": H, "t": t
    or None, "drift": mean signed change in noise units, "creep": bool, "per_hold": [...]}``; ``t`` is
    None with fewer than ``MIN_HOLDS`` holds (nothing to tell).
    """
    s = np.asarray(load, dtype=float)
    names = list(measured)
    V = np.column_stack([np.asarray(measured[c], dtype=float) for c in names])
    S = np.column_stack([np.broadcast_to(np.asarray(sigma[c], dtype=float), (s.size,)) for c in names])
    sc = s - s.mean()
    w = ((V - V.mean(axis=0)).T @ sc) / max(float(sc @ sc), 1e-300) / np.mean(S, axis=0)  # slope, noise units
    norm = float(np.linalg.norm(w))
    per = []
    if norm > 0:
        w = w / norm
        Z = V / S @ w  # the response along the load's direction, in noise units
        for a, b in holds(s, noise_load):
            if a < 1:
                continue  # no load change into a hold at the start of the test
            into = s[a] - s[max(a - 3, 0)]
            if into == 0:
                continue
            m = (b - a + 1) // 3
            change = Z[b - m + 1 : b + 1].mean() - Z[a : a + m].mean()
            z = change / np.sqrt(2.0 / m)
            L = min(b - a + 1, a)  # the ramp into the hold, as many rows as the hold
            ramp_rate = abs(Z[a : a + m].mean() - Z[a - L : a - L + m].mean()) / L
            if abs(z) > 3.0 and abs(change) / (b - a + 1 - m) > PAUSE_RATE * ramp_rate:
                continue  # the response moves on as fast as the ramp drove it: a plateau of the load, no pause
            per.append(float(np.sign(into) * z))
    out = {"holds": len(per), "t": None, "drift": None, "creep": False, "per_hold": per}
    if len(per) >= MIN_HOLDS:
        v = np.asarray(per)
        se = float(np.std(v, ddof=1)) / np.sqrt(v.size)
        t = float(np.mean(v)) / se if se > 0 else (np.inf if np.mean(v) > 0 else 0.0)
        out.update(t=t, drift=float(np.mean(v)), creep=bool(t > CREEP_T))
    return out


# ----------------------------------------------------------------------------- in diagnose's verdict
def time_check(load, measured: dict, sigma: dict) -> dict:
    """:func:`hold_drift` of the measured channels along the signed ``load`` of the path, its noise
    taken from the load itself (:func:`~femast.experiments.residuals.noise_floor`)."""
    from .residuals import noise_floor

    s = np.asarray(load, dtype=float)
    return hold_drift(s, measured, sigma, noise_load=noise_floor(s))


def reads_time(exp, name: str) -> bool:
    """True if the effect ``name`` (``effect`` or ``effect/form``) changes with time on ``exp``: its
    implementation there, or its mechanism on physical quantities, reads the time."""
    from ..effects.base import get_effect, split_form

    base, form = split_form(name)
    try:
        eff = get_effect(base)
    except ModelError:  # a name the registry no longer knows (a user script's effect): not claimed
        return False
    impls = [eff.implementation(exp), eff.mechanism]
    for impl in impls:
        if impl is None:
            continue
        try:
            impl = impl.variant(form)
        except ModelError:
            pass
        if "time" in impl.needs:
            return True
    return False


def creep_overrules(verdict: dict, check: dict, time_dependent) -> dict:
    """The verdict of ``diagnose`` once the holds have spoken (module docstring).

    verdict : :func:`~femast.experiments.verdict.conclude`'s.  check : :func:`time_check`'s.
    time_dependent : ``f(effect name) -> bool``, True for an effect that changes with time.
    Where the response keeps moving at constant load (``check["creep"]``), a verdict that names only
    rate-independent effects (friction, a gap, a stiffening: they cannot move anything while the
    load is held) becomes ``not_explained``, saying so; any other verdict gets the finding as
    ``time_dependence`` and, unless it names a time-dependent effect, a sentence in its conclusion.
    Returns a new dict (``verdict`` is not changed).
    """
    v = dict(verdict)
    v["time_dependence"] = {
        k: (None if isinstance(check.get(k), float) and not np.isfinite(check[k]) else check.get(k))
        for k in ("holds", "t", "drift", "creep")
    }
    if not check.get("creep"):
        return v
    named = list(v.get("missing_effects") or ([v["mechanism"]] if v.get("mechanism") else []))
    if named and any(time_dependent(e) for e in named):
        return v
    finding = (
        f"the response keeps moving while the load is held (t = {check['t']:.1f} over {check['holds']} holds: "
        "creep, relaxation or a slipping grip)"
    )
    if v.get("kind") in ("missing_effect", "missing_pair", "form_imperfect", "better_form") and named:
        v.update(
            kind="not_explained",
            missing_effect=None,
            missing_effects=[],
            mechanism=None,
            form=None,
            explained=False,
            rate_independent_best=named,
        )
        v["conclusion"] = (
            f"none of the candidates explains this: {finding}, which {' + '.join(named)} cannot do (it moves "
            "the response only when the load changes); a time-dependent mechanism is missing (an effect "
            "of your own on the time: docs/your_own_rig.md)"
        )
        v["try_next"] = ["an effect that moves the response at constant load (creep: docs/your_own_rig.md)"]
    elif v.get("kind") != "nothing_missing":
        v["conclusion"] = f"{v.get('conclusion', '')}; {finding}"
    return v
