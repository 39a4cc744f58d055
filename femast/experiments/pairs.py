"""The pairs stage of ``diagnose``: two effects at once, fitted jointly.

Real rigs often miss two mechanisms at once (a clearance and a friction).  The top candidates with an
information-criterion gain (``PAIR_TOP`` = 4) are paired among themselves, and -- except on the
expensive (FE) experiments, where a pair costs a minute of FE runs -- the best one with every other
candidate: a second mechanism whose own gain the first one's larger error hides (forward
selection).  Each pair starts from its members' fits.  :func:`score_pairs` scores them against the
baseline and against their best member alone (``gain_over_best_single``,
``share_over_best_single``): the verdict's test of a pair (:mod:`femast.experiments.verdict`).
"""

from __future__ import annotations

from ..effects.base import split_form
from .candidates import form_of
from .verdict import flags, pair_candidates, robust_delta, share


def fit_pairs(d) -> None:
    """The pairs' fits: ``d.pair_fits`` ``[(x, y, fit)]`` (none when the baseline is at the noise)."""
    d.pair_fits = []
    top = pair_candidates(d.ranking)
    if not top or d.s0["ratio"] <= d.thr:
        return
    by = {e["effect"]: e for e in d.ranking}
    combos = [(x, y) for i, x in enumerate(top) for y in top[i + 1 :]]
    if not d.exp.fit_options.get("expensive"):
        combos += [(top[0], e["effect"]) for e in d.ranking if not e.get("failed") and e["effect"] not in top]
    specs = []
    for x, y in combos:
        st = dict(d.start)
        for z in (x, y):
            st.update({f"{by[z]['spec']}.{k}": v["value"] for k, v in by[z]["params"].items()})
        specs.append((d.base_effects + [by[x]["spec"], by[y]["spec"]], st))
    fits = d.refit(specs)
    d.pair_fits = [(x, y, res) for (x, y), res in zip(combos, fits) if not getattr(res, "failed", False)]


def score_pairs(d) -> None:
    """``d.pairs``: each pair scored (module docstring), best ``delta_bic`` first."""
    by = {e["effect"]: e for e in d.ranking}
    order = list(by)
    r0, ic0 = d.s0["ratio"], d.s0["ic"]
    out = []
    for x, y, res in d.pair_fits:
        sc = d.score(res)
        delta, frac = sc["ic"] - ic0, share(r0, sc["ratio"])
        dr = robust_delta(d.s0["z"], sc["z"], d.data.n, d.models, int(d.baseline.n_params), int(res.n_params))
        x, y = sorted((x, y), key=order.index)  # the better-ranked member first
        spec = {split_form(s)[0]: s for s in res.effects}  # the forms fitted (the ranking may since differ)
        out.append(
            {
                "effects": [x, y],
                "forms": [form_of(spec[x], x, d.exp), form_of(spec[y], y, d.exp)],
                "ratio": sc["ratio"],
                "rms": float(res.rms),
                "delta_bic": float(delta),
                "explained_fraction": frac,
                **flags(delta, frac, dr),
                "gain_over_best_single": float(delta - min(by[x]["delta_bic"], by[y]["delta_bic"])),
                "share_over_best_single": float(frac - max(by[x]["explained_fraction"], by[y]["explained_fraction"])),
                "_fit": res,
            }
        )
    d.pairs = sorted(out, key=lambda p: p["delta_bic"])
