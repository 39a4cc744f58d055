"""The candidates stage of ``diagnose``: refit the model with each candidate effect, in each form.

1. the effects already in the model are refitted in their other forms (a shape mismatch: the form
   check), and every candidate in its default form, all from the baseline's fit; on an expensive
   (FE) model a candidate whose linearisation at the start of its refit shows that it cannot be
   significant stops there, screened out (:mod:`femast.experiments.screening`);
2. the generalised forms of the candidates whose default form gains in the information criterion
   (under the null nothing does, and a generalised form cannot gain where its default did not),
   from the default form's fit;
3. :func:`rank` scores every refit under the current noise model
   (:func:`~femast.experiments.verdict.score`): ``delta_bic``, the share of the excess error it
   explains, significance (:func:`~femast.experiments.verdict.flags`); each candidate keeps its best
   form; the candidates refitted in full come first, then those screened out (by the ``delta_bic``
   where their refits stopped), and a refit that failed is listed last, as failed.
"""

from __future__ import annotations

import numpy as np

from ..effects.base import forms_of, get_effect, resolve, split_form
from . import screening
from .fitting import params_table
from .verdict import MIN_SHARE, SIGNIFICANT_DBIC, flags, robust_delta, share


def fit_candidates(d, while_waiting=None) -> None:
    """Steps 1 and 2 of the module docstring: ``d.jobs`` and ``d.fits_list``."""
    start = d.start
    jobs = []
    for b in d.base_effects:
        name, form = split_form(b)
        for alt in forms_of(name, d.exp):
            if alt != b and alt != name + "/" + (form or ""):
                jobs.append(("form_check", name, alt, [alt if e == b else e for e in d.base_effects], start))
    for c in d.candidates:
        jobs.append(("candidate", c, c, d.base_effects + [c], start))
    scr = screening.spec(d) if d.screen and d.exp.fit_options.get("expensive") else None
    fits = d.refit(
        [
            {"effects": effs, "start": st, "screen": scr if stage == "candidate" else None}
            for stage, *_, effs, st in jobs
        ],
        while_waiting,
    )
    ic0 = d.score(d.baseline)["ic"]
    more = []
    for (stage, c, _spec, _, _), res in zip(jobs, fits):
        if (
            stage != "candidate"
            or getattr(res, "failed", False)
            or getattr(res, "screened", False)
            or d.score(res)["ic"] - ic0 >= SIGNIFICANT_DBIC
        ):
            continue
        fitted = {k.split(".", 1)[1]: v for k, v in zip(res.names, res.x) if k.startswith(c + ".")}
        base_fit = {k: v for k, v in zip(res.names, res.x) if "." not in k}
        for alt in forms_of(c, d.exp)[1:]:
            _, impl = resolve(d.exp, [alt])[0]
            st = {**base_fit, **{f"{alt}.{p.name}": fitted[p.name] for p in impl.parameters if p.name in fitted}}
            more.append(("candidate", c, alt, d.base_effects + [alt], st))
    if more:
        fits += d.refit([(effs, st) for *_, effs, st in more])
    d.jobs, d.fits_list = jobs + more, fits


def rank(d) -> None:
    """Step 3 of the module docstring: ``d.ranking`` (best first), ``d.fits`` (each candidate's best
    form), ``d.form_check``."""
    by_effect, d.form_check, d.fits = {}, [], {}
    for (stage, effect, spec, *_), res in zip(d.jobs, d.fits_list):
        e = entry(d, effect, spec, res)
        if stage == "form_check":
            keys = ("effect", "form", "ratio", "delta_bic", "explained_fraction", "significant", "params")
            d.form_check.append({k: e[k] for k in keys})
        else:
            by_effect.setdefault(effect, []).append((e, res))
    out = []
    for effect, items in by_effect.items():
        good = [it for it in items if not it[0].get("failed")]
        e, res = min(good, key=lambda it: it[0]["delta_bic"]) if good else items[0]
        e["forms"] = [
            {
                "form": x["form"],
                "ratio": x["ratio"],
                "delta_bic": x["delta_bic"],
                "n_params": x.get("n_params", 0),
                **({"failed": True} if x.get("failed") else {}),
            }
            for x, _ in items
        ]
        if not e.get("failed"):
            e["reading"] = reading(d, effect, e)
        d.fits[effect] = res
        out.append(e)
    out.sort(key=lambda e: (e.get("failed", False), e.get("screened", False), e["delta_bic"]))
    d.ranking = out


def entry(d, effect: str, spec: str, res) -> dict:
    """A refit scored against the baseline (the ranking's entry)."""
    r0, ic0 = d.s0["ratio"], d.s0["ic"]
    if getattr(res, "failed", False):
        return {
            "effect": effect,
            "form": form_of(spec, effect, d.exp),
            "rms": float(d.baseline.rms),
            "ratio": r0,
            "delta_bic": 0.0,
            "params": {},
            "significant": False,
            "ic_gain": False,
            "share_ok": False,
            "explained_fraction": 0.0,
            "baseline_params": {},
            "success": False,
            "at_bound": [],
            "failed": True,
            "spec": spec,
            "baseline_ratio": r0,
            "reading": f"The refit with {get_effect(effect).title} failed: {res.message}",
        }
    sc = d.score(res)
    delta, frac = sc["ic"] - ic0, share(r0, sc["ratio"])
    dr = robust_delta(d.s0["z"], sc["z"], d.data.n, d.models, int(d.baseline.n_params), int(res.n_params))
    table = params_table(res)
    return {
        "effect": effect,
        "form": form_of(spec, effect, d.exp),
        "spec": spec,
        "rms": float(res.rms),
        "ratio": sc["ratio"],
        "delta_bic": float(delta),
        "explained_fraction": frac,
        **flags(delta, frac, dr),
        "delta_bic_robust": float(dr),
        "params": {k.split(".", 1)[1]: v for k, v in table.items() if k.startswith(spec + ".")},
        "baseline_params": {k: v for k, v in table.items() if "." not in k},
        "baseline_ratio": r0,
        "success": bool(res.success),
        "at_bound": list(res.at_bound),
        "n_params": int(res.n_params),
        "skipped": int(getattr(res, "skipped", 0)),
        "_z": sc["z"],
        **({"screened": True, "significant": False, "ic_gain": False} if getattr(res, "screened", False) else {}),
    }


def form_of(spec: str, effect: str, exp) -> str:
    """Form name of an effect spec ("" for a one-form effect; the default form's name otherwise)."""
    f = split_form(spec)[1]
    if f:
        return f
    impl = get_effect(effect).implementation(exp)
    return impl.form if impl else ""


def kind_ratio(mask, z, nch) -> float:
    """RMS of the whitened residual z (channels stacked) over the rows of ``mask``."""
    z = np.asarray(z).reshape(nch, -1)[:, mask]
    return float(np.sqrt(np.mean(z**2))) if z.size else float("nan")


def reading(d, effect: str, e: dict) -> str:
    """The plain-language reading of a candidate's refit: its signature, the error before and after,
    where it gains, whether it is significant."""
    eff = get_effect(effect)
    nch, masks = len(d.channels), d.analysis["masks"]
    text = f"{eff.signature[0].upper()}{eff.signature[1:]}. " if eff.signature else ""
    form = f" (form {e['form']})" if e.get("form") else ""
    if e.get("screened"):
        return text + (
            f"Screened out: with {eff.title}{form} the error goes from {e['baseline_ratio']:.2f}x to "
            f"{e['ratio']:.2f}x the noise where its refit stopped (delta BIC {e['delta_bic']:+.1f}): from there "
            f"even {screening.SCREEN_MARGIN:g} times the gain its Gauss-Newton step predicts would not be "
            "significant, so it was not refitted to the end."
        )
    text += (
        f"Refitted with {eff.title}{form}, the error goes from {e['baseline_ratio']:.2f}x to "
        f"{e['ratio']:.2f}x the noise (explains {100 * e['explained_fraction']:.0f} % of the excess; "
        f"delta BIC {e['delta_bic']:+.1f})."
    )
    gains = [(kind_ratio(m, d.s0["z"], nch) - kind_ratio(m, e["_z"], nch), k) for k, m in masks.items() if m.sum() >= 3]
    if gains and e["significant"]:
        g, kind = max(gains)
        if g > 0:
            text += f" The largest gain is in the {kind} segments."
    worst = d.analysis["by_kind"][0]["kind"] if d.analysis["by_kind"] else None
    if worst and worst in eff.acts_where:
        text += f" The model fails most in the {worst} segments, where this effect acts."
    if not e["significant"]:
        text += (
            " Not significant: the data do not ask for it."
            if not e["ic_gain"]
            else f" Not significant: it explains less than {100 * MIN_SHARE:.0f} % of the excess error."
        )
    elif e["ratio"] > d.thr:
        text += " Structure remains after it."
    if e["skipped"]:
        text += f" ({e['skipped']} parameter sets skipped: the model failed there.)"
    return text


def remaining_where(d, z, min_rows: int = 3) -> list:
    """Kinds of segment where a fit's whitened residual is above the at-noise threshold, worst first."""
    nch = len(d.channels)
    out = [
        (r, k) for k, m in d.analysis["masks"].items() if m.sum() >= min_rows and (r := kind_ratio(m, z, nch)) > d.thr
    ]
    return [f"{k} ({r:.1f}x)" for r, k in sorted(out, reverse=True)]
