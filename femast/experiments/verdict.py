"""Scoring of model variants and the verdict of ``diagnose``.

Every fit of a diagnosis is scored with the same noise model (:mod:`femast.experiments.noise`):
``ratio`` is the robust RMS of the residuals whitened by the per-row noise
(:func:`~femast.experiments.residuals.robust_rms`: the 5 % largest left out, as the noise level is
a robust estimate too), ``ic`` the information
criterion with the effective sample sizes (:func:`~femast.experiments.noise.information_criterion`),
``delta_bic = ic - ic(baseline)`` and ``explained_fraction`` the share of the baseline's excess
error ``ratio0^2 - 1`` that the variant removes.

Significance
------------
A candidate is *significant* when both

* ``delta_bic < SIGNIFICANT_DBIC`` (-10: "very strong" evidence on the Kass-Raftery scale; for one
  parameter and 1500 residuals a chi-square drop of 17, p < 4e-5 under the null), and
* the same holds with the 2 % of rows (at least 3) that gain most left out (a mechanism acts on
  many rows; a gain from a handful of rows -- outliers, a model artefact at one spot of the path
  such as the break-out from the latch backstop -- is not evidence of it), and
* ``explained_fraction >= MIN_SHARE`` (10 %).  With hundreds of residuals a change of shape that
  removes 2 % of a large excess error passes any information criterion, yet it is not the missing
  mechanism: such gains come from a flexible effect bending into a structure it does not model
  ("beam flexibility" with no beam).  10 % of the excess is the smallest share whose
  removal is visible in the residual plot (the RMS of the excess falls by 5 %), and the
  smallest share a second mechanism of a pair contributes in the generalisation benchmark.

Conclusions (``verdict["kind"]``)
---------------------------------
* ``better_form`` -- the effects already in the model (``--effects``) are first refitted in their
  generalised forms; one that is significant and brings the model to the noise floor is a shape
  mismatch of the added effect, not a new mechanism;
* ``missing_effect`` -- the best significant candidate brings the model to the noise floor (and no
  pair does significantly better);
* ``missing_pair`` -- the best pair, fitted jointly, of the top four candidates with an
  information-criterion gain or of the best candidate with any other (forward selection: a
  second mechanism whose own gain the first one's larger error hides; not on the expensive FE
  experiments), brings the model
  to the noise floor and is significantly better than its best member alone (information
  criterion -10 and another 10 % of the excess), also when that member alone reaches the floor
  (a small second effect);
* ``form_imperfect`` -- the best pair passes the pair test and explains at least ``FORM_SHARE`` =
  60 % of the excess but leaves structure (``missing_effects`` names both: two mechanisms are
  there, their forms are not right); else the best candidate explains at least 60 % of the excess
  but leaves structure: the mechanism is there, its form is not right (the verdict names where the
  rest sits and what to try);
* ``nothing_missing`` -- no candidate is significant and the baseline is at the noise floor;
* ``not_explained`` -- otherwise ("none of the candidates explains this").
"""

from __future__ import annotations

import numpy as np

from .noise import information_criterion
from .residuals import robust_rms

SIGNIFICANT_DBIC = -10.0
MIN_SHARE = 0.10
FORM_SHARE = 0.60
PAIR_TOP = 4
FEW_ROWS = 0.02


def score(fit, models: dict, channels, n_rows: int) -> dict:
    """``{ratio, rss, ic, z}`` of a fit under the noise ``models`` ({channel: ChannelNoise})."""
    z = np.concatenate([fit.residuals[c] / models[c].sigma for c in channels])
    return {
        "ratio": robust_rms(z),
        "rss": float(z @ z),
        "ic": information_criterion(z, n_rows, {c: models[c] for c in channels}, int(fit.n_params)),
        "z": z,
    }


def robust_delta(z0, zc, n_rows: int, models: dict, p0: int, pc: int) -> float:
    """delta BIC of a variant (whitened residuals zc, pc parameters) against the baseline (z0, p0) with
    the ``FEW_ROWS`` share of rows (at least 3) that gain most left out of both: a mechanism acts on
    many rows, a gain that comes from a handful of them (a few outliers, a model artefact at one
    spot of the path) is not evidence of it."""
    nch = len(models)
    g = (np.asarray(z0).reshape(nch, n_rows) ** 2 - np.asarray(zc).reshape(nch, n_rows) ** 2).sum(axis=0)
    k = max(3, int(np.ceil(FEW_ROWS * n_rows)))
    if n_rows - k < 5:
        return -np.inf
    keep = np.ones(n_rows, bool)
    keep[np.argsort(-g)[:k]] = False
    sub = {c: m for c, m in models.items()}
    a = np.asarray(z0).reshape(nch, n_rows)[:, keep].ravel()
    b = np.asarray(zc).reshape(nch, n_rows)[:, keep].ravel()
    m = int(keep.sum())
    return information_criterion(b, m, sub, pc) - information_criterion(a, m, sub, p0)


def share(r0: float, r: float) -> float:
    """Share of the excess error ``r0^2 - 1`` removed by going from ratio r0 to r (0 if no excess)."""
    excess = r0**2 - 1.0
    return float(np.clip((r0**2 - r**2) / excess, 0.0, 1.0)) if excess > 0 else 0.0


def flags(delta_ic: float, frac: float, delta_robust: float = -np.inf) -> dict:
    """``ic_gain`` (delta_ic and the delta without the few rows that gain most both below -10),
    ``share_ok`` and ``significant`` (both) of a variant."""
    ic_gain = bool(delta_ic < SIGNIFICANT_DBIC and delta_robust < SIGNIFICANT_DBIC)
    share_ok = bool(frac >= MIN_SHARE)
    return {"ic_gain": ic_gain, "share_ok": share_ok, "significant": ic_gain and share_ok}


def pair_candidates(ranking: list, top: int = PAIR_TOP) -> list:
    """Effects worth pairing: the ``top`` best by delta_bic with an information-criterion gain."""
    ok = [e for e in ranking if not e.get("failed") and e["ic_gain"]]
    return [e["effect"] for e in ok[:top]]


def pair_beats_members(p: dict) -> bool:
    """True if the pair ``p`` passes the pair test: significant against the baseline, significantly
    better than its best member alone (information criterion and another ``MIN_SHARE`` of the
    excess) and, where it was checked, better held out than its best member."""
    return bool(
        p["significant"]
        and p["gain_over_best_single"] < SIGNIFICANT_DBIC
        and p["share_over_best_single"] >= MIN_SHARE
        and p.get("heldout_ok", True)
    )


def conclude(
    r0: float,
    thr: float,
    ranking: list,
    pairs: list,
    form_check: list,
    titles: dict,
    remaining_where=(),
    pair_where=(),
) -> dict:
    """The verdict (module docstring) from the scored ranking (best first), pairs and form check;
    ``remaining_where`` and ``pair_where`` name the segments where the error of the best candidate
    and of the best pair stays above the noise (worst first)."""
    best = next((e for e in ranking if e["significant"]), None)
    bp = min(pairs, key=lambda p: p["delta_bic"]) if pairs else None
    fc = min((f for f in form_check if f["significant"]), key=lambda f: f["delta_bic"], default=None)
    v = {
        "kind": None,
        "missing_effect": None,
        "missing_effects": [],
        "mechanism": None,
        "form": None,
        "explained": False,
        "best_candidate": best["effect"] if best else None,
        "alternatives": [],
        "best_pair": bp,
        "try_next": [],
        "remaining_where": list(remaining_where),
        "conclusion": "",
    }
    pair_ok = bp is not None and bp["ratio"] <= thr and best is not None and pair_beats_members(bp)
    if fc is not None and fc["ratio"] <= thr:
        v.update(kind="better_form", mechanism=fc["effect"], form=fc["form"], explained=True)
        v["conclusion"] = (
            f"the added effect {fc['effect']} has the wrong form: its form '{fc['form']}' brings the "
            f"error from {r0:.2f}x to {fc['ratio']:.2f}x the noise (no new mechanism is needed)"
        )
        return v
    if fc is not None:
        v["try_next"].append(f"{fc['effect']}/{fc['form']} (a better form of an added effect: {fc['ratio']:.2f}x)")
    if pair_ok:  # also when the best single one reaches the noise: the pair is significantly better
        v.update(kind="missing_pair", missing_effects=list(bp["effects"]), explained=True)
        v["conclusion"] = (
            f"missing effects: {' + '.join(bp['effects'])} (fitted together); the pair brings the "
            f"error from {r0:.2f}x to {bp['ratio']:.2f}x the noise, significantly below its best "
            "member alone"
        )
        return v
    if best is not None and best["ratio"] <= thr:
        alts = [
            e["effect"]
            for e in ranking
            if e is not best and e["significant"] and e["ratio"] <= thr and e["delta_bic"] - best["delta_bic"] < 10.0
        ]
        v.update(
            kind="missing_effect",
            missing_effect=best["effect"],
            missing_effects=[best["effect"]],
            mechanism=best["effect"],
            form=best.get("form") or None,
            explained=True,
            alternatives=alts,
        )
        v["conclusion"] = (
            f"missing effect: {best['effect']} ({titles.get(best['effect'], '')}"
            f"{', form ' + best['form'] if best.get('form') else ''}); with it the error falls from "
            f"{r0:.2f}x to {best['ratio']:.2f}x the noise"
        )
        if alts:
            v["conclusion"] += f"; also consistent with the data: {', '.join(alts)}"
        return v
    pair_found = bp is not None and best is not None and pair_beats_members(bp)
    if pair_found and bp["explained_fraction"] >= FORM_SHARE:
        where = ", ".join(pair_where[:3]) or "spread along the path"
        v.update(
            kind="form_imperfect",
            missing_effects=list(bp["effects"]),
            mechanism=" + ".join(bp["effects"]),
            remaining_where=list(pair_where),
        )
        v["try_next"].append("generalised forms of these effects (an own effect or form: docs/experiments.md)")
        v["conclusion"] = (
            f"mechanisms found, forms imperfect: {' + '.join(bp['effects'])} (fitted together) explain "
            f"{100 * bp['explained_fraction']:.0f} % of the excess error ({r0:.2f}x -> {bp['ratio']:.2f}x the "
            f"noise), significantly more than either alone, but structure remains, mostly in: {where}; try "
            f"{'; '.join(v['try_next'])}"
        )
        return v
    if bp is not None and bp["significant"] and bp["ratio"] < (best["ratio"] if best else r0):
        v["try_next"].append(f"the pair {' + '.join(bp['effects'])} ({bp['ratio']:.2f}x the noise)")
    if best is not None and best["explained_fraction"] >= FORM_SHARE:
        where = ", ".join(remaining_where[:3]) or "spread along the path"
        v.update(kind="form_imperfect", mechanism=best["effect"], form=best.get("form") or None)
        v["try_next"].append(f"a generalised form of {best['effect']} (an own effect or form: docs/experiments.md)")
        v["conclusion"] = (
            f"mechanism found, form imperfect: {best['effect']} ({titles.get(best['effect'], '')}) "
            f"explains {100 * best['explained_fraction']:.0f} % of the excess error ({r0:.2f}x -> "
            f"{best['ratio']:.2f}x the noise) but structure remains, mostly in: {where}; try "
            f"{'; '.join(v['try_next'])}"
        )
        return v
    if best is None and r0 <= thr:
        v.update(kind="nothing_missing", explained=True)
        v["conclusion"] = (
            f"nothing is missing: the model is at the noise floor ({r0:.2f}x noise) and no candidate is significant"
        )
        return v
    v["kind"] = "not_explained"
    if best is None:
        v["conclusion"] = (
            f"none of the candidates explains this: the model is {r0:.2f}x the noise and no candidate "
            "effect (or pair) "
            "explains a significant share of the excess error (an effect outside the library?)"
        )
    else:
        v["conclusion"] = (
            f"none of the candidates explains this: the best, {best['effect']}, brings the error from "
            f"{r0:.2f}x to "
            f"{best['ratio']:.2f}x the noise ({100 * best['explained_fraction']:.0f} % of the excess)"
            f"{'; try ' + '; '.join(v['try_next']) if v['try_next'] else ''} (an effect outside the "
            "library, or several at once)"
        )
    return v
