"""Reading a ``diagnose`` JSON report as a verdict, and the scoring rule of the benchmark.

The adapter reads the older report (``verdict.missing_effect`` / ``explained`` /
``best_candidate`` / ``conclusion``) and the newer fields: ``verdict.kind`` in
``nothing_missing``, ``missing_effect``, ``missing_pair``, ``form_imperfect``, ``better_form``,
``not_explained``; ``verdict.missing_effects`` ([X] or [X, Y]); ``verdict.mechanism`` (the X of
a form-imperfect verdict).  The structured fields are used when present, else the conclusion
text, whose first words are fixed ("missing effect:", "mechanism found, form imperfect", "not
explained" / "none of the candidates explains this", "nothing is missing").

Verdict kinds: ``missing`` (X brings the model to the noise), ``form_imperfect`` (X explains
most of the excess, structure remains), ``not_explained``, ``nothing``.

Scoring rule (also in the benchmark's docstring and the docs page)
------------------------------------------------------------------
* ``effect`` case with mechanism X: right iff the verdict is ``missing`` or ``form_imperfect``
  and names X alone (a pair verdict claims an effect that is not in the data: wrong);
* ``pair`` case {X, Y}: right iff the verdict (``missing`` or ``form_imperfect``) names exactly
  {X, Y};
* ``ool`` (out of library): right iff the verdict is ``not_explained`` or ``form_imperfect``
  (no claim that an effect of the library *is* the missing one, and no "nothing is missing");
* ``time`` (a time-dependent mechanism out of the library, creep): right iff the verdict is
  ``not_explained``, or names only effects that change with time (``TIME_EFFECTS``): reading
  creep as a form of friction is wrong;
* ``null`` redraw: right iff the verdict is ``nothing``; any other verdict is a false alarm.

Score = (number of right effect/pair/ool cases + sum over null cases of the fraction of its
redraws that are right) / (number of effect/pair/ool cases + number of null cases): every
null case weighs as much as one other case, its redraws share that weight.  False-alarm rate =
wrong null redraws / all null redraws.  Targets: score >= 0.95, false alarms <= 0.05.
"""

from __future__ import annotations

import re

KINDS = ("missing", "form_imperfect", "not_explained", "nothing")
TIME_EFFECTS = frozenset({"pretension_loss"})  # the library's effects that change with time

_KIND_WORDS = (  # (pattern in a kind field or in the conclusion, kind), first match wins
    (r"form.?imperfect|mechanism found", "form_imperfect"),
    (r"better.?form", "missing"),  # only after --effects: the generalised form of an added effect explains
    (r"nothing.?(is.?)?missing|^nothing", "nothing"),
    (r"not.?explained|none of the candidates", "not_explained"),
    (r"missing", "missing"),
)


def _kind_of(text: str):
    t = str(text).strip().lower()
    for pat, kind in _KIND_WORDS:
        if re.search(pat, t):
            return kind
    return None


def _names(value) -> list:
    """Effect names from a string ("X", "X+Y", "X + Y", "X, Y"), a list, or a dict with 'effect(s)'."""
    if value is None:
        return []
    if isinstance(value, dict):
        for key in ("effects", "pair", "effect", "name"):
            if key in value:
                return _names(value[key])
        return []
    if isinstance(value, (list, tuple)):
        out = []
        for v in value:
            out += _names(v)
        return out
    # "X/form" names a form of X: the mechanism is X
    return [s.strip().split("/")[0] for s in re.split(r"[+,&]| and ", str(value)) if s.strip()]


def read_verdict(report: dict) -> dict:
    """``{"kind", "effects", "conclusion"}`` from a diagnose JSON report (old or new fields)."""
    v = report.get("verdict", {}) or {}
    conclusion = str(v.get("conclusion", ""))
    kind = None
    for key in ("kind", "status", "verdict", "type"):
        if isinstance(v.get(key), str):
            kind = _kind_of(v[key])
            if kind:
                break
    if kind is None:
        kind = _kind_of(conclusion.split(":")[0]) or _kind_of(conclusion)
    if kind is None:  # old report with an unexpected conclusion: fall back on the flags
        kind = "missing" if v.get("missing_effect") else ("nothing" if v.get("explained") else "not_explained")
    effects = []
    if kind in ("missing", "form_imperfect"):
        for key in ("missing_effects", "missing_effect", "mechanism", "effects", "effect", "best_candidate"):
            if v.get(key):
                effects = _names(v[key])
                if effects:
                    break
    return {"kind": kind, "effects": sorted(set(effects)), "conclusion": conclusion}


def is_right(expect: str, expected_effects, verdict: dict) -> bool:
    """Whether ``verdict`` (from :func:`read_verdict`) is right for a case (module docstring)."""
    kind, named = verdict["kind"], set(verdict["effects"])
    if expect == "null":
        return kind == "nothing"
    if expect == "ool":
        return kind in ("not_explained", "form_imperfect")
    if expect == "time":
        return kind == "not_explained" or (
            kind in ("missing", "form_imperfect") and bool(named) and named <= TIME_EFFECTS
        )
    if kind not in ("missing", "form_imperfect"):
        return False
    return named == set(expected_effects)


def score(rows) -> dict:
    """Score and false-alarm rate of result rows (dicts with ``case``, ``expect``, ``right``)."""
    per_case = {}
    for r in rows:
        per_case.setdefault(r["case"], []).append(r)
    num = den = 0.0
    null_runs = null_wrong = 0
    other = other_right = 0
    for _case, rs in per_case.items():
        frac = sum(r["right"] for r in rs) / len(rs)
        num += frac
        den += 1
        if rs[0]["expect"] == "null":
            null_runs += len(rs)
            null_wrong += sum(not r["right"] for r in rs)
        else:
            other += 1
            other_right += frac
    return {
        "score": num / den if den else float("nan"),
        "cases": int(den),
        "non_null_cases": other,
        "non_null_right": other_right,
        "null_runs": null_runs,
        "false_alarms": null_wrong,
        "false_alarm_rate": null_wrong / null_runs if null_runs else float("nan"),
    }
