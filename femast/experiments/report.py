"""Self-contained HTML reports of ``compare`` and ``diagnose``: one file a team can
share and open offline -- the verdict, the tables, the figures inlined as base64 PNG, and the
history of the model versions.  No script, no external link, no web font.
"""

from __future__ import annotations

import base64
import html
import time
from pathlib import Path

from ..post.plotstyle import display_scale, num

_CSS = """
body { font-family: -apple-system, "Segoe UI", Helvetica, Arial, sans-serif; margin: 2em auto; max-width: 70em;
       color: #222; line-height: 1.4; padding: 0 1em; }
h1 { font-size: 1.5em; margin-bottom: 0.2em; } h2 { font-size: 1.2em; margin-top: 1.6em; border-bottom: 1px solid #ddd; }
.meta { color: #666; font-size: 0.9em; }
.verdict { font-size: 1.1em; padding: 0.8em 1em; border-radius: 6px; margin: 1em 0; }
.good { background: #e7f5e9; border: 1px solid #7bc47f; } .bad { background: #fdecea; border: 1px solid #e57373; }
.neutral { background: #eef3fb; border: 1px solid #90a4c8; }
table { border-collapse: collapse; margin: 0.5em 0; font-size: 0.92em; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: left; } td.n { text-align: right; }
th { background: #f3f3f3; } img { max-width: 100%; border: 1px solid #eee; margin: 0.5em 0; }
figure { margin: 1em 0; } figcaption { color: #555; font-size: 0.9em; }
"""


def esc(x) -> str:
    return html.escape(str(x))


def png_tag(png, caption: str = "") -> str:
    """An ``<img>`` with the PNG inlined as a base64 data URI (and a caption)."""
    data = base64.b64encode(Path(png).read_bytes()).decode("ascii")
    alt = esc(caption or Path(png).name)
    cap = f"<figcaption>{esc(caption)}</figcaption>" if caption else ""
    return f'<figure><img alt="{alt}" src="data:image/png;base64,{data}">{cap}</figure>'


def table(header, rows, numeric=()) -> str:
    """An HTML table; columns whose index is in ``numeric`` are right-aligned."""
    head = "".join(f"<th>{esc(h)}</th>" for h in header)
    body = "".join(
        "<tr>" + "".join(f"<td{' class=n' if i in numeric else ''}>{esc(c)}</td>" for i, c in enumerate(r)) + "</tr>"
        for r in rows
    )
    return f"<table><tr>{head}</tr>{body}</table>"


def page(title: str, meta: str, verdict: str, tone: str, sections) -> str:
    """The whole document: ``sections`` is a list of (heading, html)."""
    parts = [
        f"<!DOCTYPE html><html lang=en><head><meta charset=utf-8><title>{esc(title)}</title>",
        f"<style>{_CSS}</style></head><body>",
        f"<h1>{esc(title)}</h1>",
        f"<p class=meta>{esc(meta)}</p>",
        f'<div class="verdict {tone}" id=verdict><b>Verdict:</b> {esc(verdict)}</div>',
    ]
    for heading, body in sections:
        parts.append(f"<h2>{esc(heading)}</h2>{body}")
    parts.append("</body></html>")
    return "\n".join(parts)


def _params_rows(params: dict):
    rows = []
    for name, p in params.items():
        se = p.get("stderr")
        rows.append([name, num(p["value"], 5), "" if se is None else num(se, 2), p.get("unit", "")])
    return rows


def _sources(noise: dict, unit: str) -> str:
    """The source of a channel's noise level, and the others' levels where they disagree."""
    text = noise["source"]
    if noise.get("disagree"):
        f, ul = display_scale(unit)
        text += " (" + ", ".join(f"{k} {num(f * v, 3)} {ul}" for k, v in noise["levels"].items()) + ")"
    return text


def _history_section(folder: Path, exp) -> str:
    from .history import read_history

    recs = read_history(folder)
    if not recs:
        return "<p>No history yet.</p>"
    f, ul = display_scale(recs[-1].get("error_unit", ""))
    rows = [
        [
            r["version"],
            "+".join(r.get("effects") or []) or "baseline",
            "yes" if r.get("fit") else "no",
            num(f * r["rms"], 4),
            num(r["ratio"], 3) if r.get("ratio") is not None else "",
        ]
        for r in recs
    ]
    body = table(["version", "effects", "fitted", f"RMS error ({ul})", "x noise"], rows, numeric=(0, 3, 4))
    png = folder / "history.png"
    if png.is_file():
        body += png_tag(png, "RMS error against the model version (history.png)")
    return body


def _meta(exp, data, n) -> str:
    return (
        f"experiment {exp.name} ({exp.title}); data {data.path} ({n} samples); written "
        f"{time.strftime('%Y-%m-%d %H:%M')} by femast"
    )


def compare_report(exp, data, result, folder) -> Path:
    """Write ``compare_report.html`` of a ``compare`` run into ``folder`` (beside compare.png and .json)."""
    folder = Path(folder)
    f, ul = display_scale(exp.error_unit)
    ratio = result.ratio
    at = result.report.get("at_noise", 1.2)
    verdict = (
        f"the model is at the noise floor ({num(ratio)}x noise)"
        if ratio <= at
        else f"the model is {num(ratio)}x the noise: it misses something (femast diagnose says what)"
    )
    eff = "+".join(result.effects) or "baseline"
    sections = [
        (
            "Model",
            f"<p>{esc(eff)}, {'parameters fitted' if result.fitted else 'given parameters'}</p>"
            + table(["parameter", "value", "std. error", "unit"], _params_rows(result.params_table), numeric=(1, 2)),
        ),
        (
            "Error",
            table(
                ["channel", "RMS", "noise", "noise from", "x noise", "unit"],
                [
                    [
                        c,
                        num(display_scale(v["unit"])[0] * v["rms"], 4),
                        num(display_scale(v["unit"])[0] * v["noise"], 4),
                        _sources(result.report["noise_model"][c], v["unit"]),
                        num(v.get("ratio", v["rms"] / v["noise"] if v["noise"] else float("nan")), 3),
                        display_scale(v["unit"])[1],
                    ]
                    for c, v in result.report["channels"].items()
                ],
                numeric=(1, 2, 4),
            )
            + (
                f"<p>overall RMS error {num(f * result.rms, 4)} {esc(ul)}; noise floor "
                f"{num(f * result.noise_rms, 4)} {esc(ul)}.</p>"
                if exp.one_scale
                else f"<p>overall: {num(result.ratio, 3)}x the noise (each channel's error over its own noise).</p>"
            ),
        ),
        (
            "Where it fails",
            table(
                ["kind of segment", "x noise", "samples"],
                [[k["kind"], num(k["ratio"], 3), k.get("n", "")] for k in result.by_kind],
                numeric=(1, 2),
            )
            + table(
                ["#", "kind", "rows", "file lines", "x noise"],
                [
                    [
                        i + 1,
                        w["kind"],
                        f"{w['start_row']}-{w['end_row']}",
                        f"{w.get('first_line', '')}-{w.get('last_line', '')}",
                        num(w["ratio"], 3),
                    ]
                    for i, w in enumerate(result.worst[:5])
                ],
                numeric=(0, 4),
            ),
        ),
        (
            "Figure",
            png_tag(result.files["png"], "measured against model; residual along the path (compare.png)")
            if result.files.get("png")
            else "<p>(no figure)</p>",
        ),
        ("History", _history_section(folder, exp)),
    ]
    doc = page(
        f"femast compare: {exp.name}",
        _meta(exp, data, result.n_samples),
        verdict,
        "good" if ratio <= at else "bad",
        sections,
    )
    out = folder / "compare_report.html"
    out.write_text(doc, encoding="utf-8")
    return out


def diagnose_report(exp, data, result, folder) -> Path:
    """Write ``diagnose_report.html`` of a ``diagnose`` run into ``folder``."""
    folder = Path(folder)
    f, ul = display_scale(exp.error_unit)
    v = result.verdict
    tone = "good" if v.get("explained") else ("neutral" if v.get("best_candidate") else "bad")
    b = result.baseline
    rows = []
    for i, e in enumerate(result.ranking):
        ps = ", ".join(
            f"{k} = {num(p['value'], 4)}"
            + (f" +- {num(p['stderr'], 2)}" if p.get("stderr") is not None else "")
            + f" {p.get('unit', '')}"
            for k, p in e.get("params", {}).items()
        )
        rows.append(
            [
                i + 1,
                e["effect"],
                *(["failed" if e.get("failed") else num(f * e["rms"], 4)] if exp.one_scale else []),
                num(e["ratio"], 3),
                f"{e['delta_bic']:+.1f}",
                "yes" if e["significant"] else "no",
                ps,
            ]
        )
    sections = [
        (
            "Baseline",
            f"<p>baseline{' + ' + ' + '.join(b['effects']) if b['effects'] else ''}: "
            + (
                f"RMS {num(f * b['rms'], 4)} {esc(ul)} ({num(b['ratio'], 3)}x noise; noise floor "
                f"{num(f * result.noise_rms, 4)} {esc(ul)})</p>"
                if exp.one_scale
                else f"{num(b['ratio'], 3)}x the noise (each channel's error over its own noise)</p>"
            )
            + table(["parameter", "value", "std. error", "unit"], _params_rows(b["params"]), numeric=(1, 2)),
        ),
        (
            "Candidates, best first",
            table(
                # channels of different units (m and rad): no pooled RMS, each channel over its own noise
                ["rank", "effect", *([f"RMS ({ul})"] if exp.one_scale else []), "x noise", "delta BIC", "significant"]
                + ["parameters"],
                rows,
                numeric=(0, 2, 3, 4) if exp.one_scale else (0, 2, 3),
            )
            + "".join(f"<p><b>{esc(e['effect'])}</b>: {esc(e['reading'])}</p>" for e in result.ranking[:3]),
        ),
        (
            "Figure",
            png_tag(result.files["png"], "error after each refit; residual along the path (diagnose.png)")
            if result.files.get("png")
            else "<p>(no figure)</p>",
        ),
        ("History", _history_section(folder, exp)),
    ]
    doc = page(
        f"femast diagnose: {exp.name}",
        _meta(exp, data, result.n_samples) + f"; refits: {result.executor}",
        v["conclusion"],
        tone,
        sections,
    )
    out = folder / "diagnose_report.html"
    out.write_text(doc, encoding="utf-8")
    return out
