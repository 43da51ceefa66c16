"""Short text and HTML summaries of results, for the terminal and for notebooks.

``repr(result)`` is a few lines (title, lines, end-tension σ with units, warnings) and
``result._repr_html_()`` a table that Jupyter renders, instead of the dataclass dump of
every array.  The helpers (:func:`format_value`, :func:`html_table`) are shared by the
summaries of load-case sets (:mod:`stochcable.cases.display`) and of the client's batch
jobs.  Every text put into HTML is escaped.
"""

from __future__ import annotations

import html
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

from stochcable.scene.units import unit_labels

__all__ = [
    "ENDS",
    "TITLE_CHARS",
    "format_value",
    "html_table",
    "html_list",
    "html_block",
    "result_text",
    "result_html",
    "document_text",
    "document_html",
    "batch_status_text",
    "batch_status_html",
]

ENDS = ("end_a", "end_b")
"""The two ends of a line, as the result documents name them."""

TITLE_CHARS = 100
"""Longest title a text summary shows (the rest elided with "…"). [characters]"""

_STYLE = "border-collapse:collapse;text-align:right"


def format_value(value: Any, digits: int = 4) -> str:
    """A number to ``digits`` significant digits, thousands separated (scientific notation
    outside 1e-3 … 1e7); "–" for None or a non-finite value."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        return "–"
    if not math.isfinite(x):
        return "–"
    if x == 0:
        return "0"
    if not 1e-3 <= abs(x) < 1e7:
        return f"{x:.{digits - 1}e}"
    rounded = float(f"{x:.{digits}g}")
    decimals = max(0, digits - 1 - math.floor(math.log10(abs(rounded))))
    return f"{rounded:,.{decimals}f}"


def _cell(value: Any) -> str:
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return f"<td>{format_value(value)}</td>"
    return f'<td style="text-align:left">{html.escape(str(value))}</td>'


def html_table(
    columns: Sequence[str], rows: Iterable[Sequence[Any]], caption: str | None = None
) -> str:
    """An HTML table: numbers formatted by :func:`format_value`, every text escaped."""
    head = "".join(f"<th>{html.escape(c)}</th>" for c in columns)
    body = "".join("<tr>" + "".join(_cell(v) for v in row) + "</tr>" for row in rows)
    cap = f"<caption>{html.escape(caption)}</caption>" if caption else ""
    head = f"<thead><tr>{head}</tr></thead>"
    return f'<table style="{_STYLE}">{cap}{head}<tbody>{body}</tbody></table>'


def html_list(items: Iterable[Any]) -> str:
    """An HTML bulleted list of the items' text, escaped."""
    return "<ul>" + "".join(f"<li>{html.escape(str(i))}</li>" for i in items) + "</ul>"


def html_block(title: str, parts: Iterable[str]) -> str:
    """The parts under a bold title, in one ``div``."""
    return f"<div><strong>{html.escape(title)}</strong>" + "".join(parts) + "</div>"


def _short(text: str) -> str:
    text = " ".join(str(text).split())
    return text if len(text) <= TITLE_CHARS else text[: TITLE_CHARS - 1] + "…"


@dataclass(frozen=True)
class _Summary:
    """What both summaries show, from a Result or from a result document."""

    kind: str
    title: str
    force: str
    time: str
    lines: list[tuple[str, bool, int, float]]  # name, converged, iterations, change
    ends: list[tuple[str, str, float, float, float, float]]  # line, end, mean, σ, Tz, MPM
    warnings: tuple[str, ...]
    bodies: tuple[str, ...] = ()
    target_error: float | None = None
    linear: tuple[float | None, ...] = ()  # the linear model's σ beside each end's
    residuals: tuple[str, ...] = ()  # the residual kinds the end statistics carry


def _ends(lines: Any) -> list[tuple[str, str, float, float, float, float]]:
    rows = []
    for name, line in lines.items():
        for end in ENDS:
            st = getattr(line, end, None)
            if st is not None:
                rows.append((name, end, st.mean, st.std, st.tz, st.mpm_3h))
    return rows


def _residuals(lines: Any) -> dict[str, Any]:
    """The linear σ beside every end (None where a line has no residual) and the
    residual kinds computed on some line (LineResult or the document's view)."""
    linear = [
        None if line.linear is None else line.linear[end].std
        for line in lines.values()
        for end in ENDS
        if getattr(line, end, None) is not None
    ]
    kinds = {k: None for line in lines.values() for k, r in line.residuals.items() if r.computed}
    return {"linear": tuple(linear), "residuals": tuple(kinds)}


def _of_result(result: Any) -> _Summary:
    env = getattr(result.scene, "environment", None)
    units = unit_labels(env.g if env is not None else 9.80665)
    lin = [
        (n, r.linearization.converged, r.linearization.iterations, r.linearization.relative_change)
        for n, r in result.lines.items()
    ]
    fid = result.fidelity
    return _Summary(
        "Result",
        getattr(result.scene, "title", "") or "(untitled scene)",
        units.force,
        units.time,
        lin,
        _ends(result.lines),
        tuple(result.warnings),
        tuple(result.bodies),
        None if fid is None else float(fid.target_error),
        **_residuals(result.lines),
    )


def _of_document(doc: Any) -> _Summary:
    units = doc.get("units") or {}
    lin = [
        (n, bool(r.linearization["converged"]), int(r.linearization["iterations"]),
         float(r.linearization["relative_change"]))
        for n, r in doc.lines.items()
    ]  # fmt: skip
    fid = doc.get("fidelity")
    return _Summary(
        "AnalysisDocument",
        "result of the service",
        units.get("force", "N"),
        units.get("time", "s"),
        lin,
        _ends(doc.lines),
        tuple(doc.warnings),
        tuple(doc.get("bodies") or ()),
        None if fid is None else float(fid["target_error"]),
        **_residuals(doc.lines),
    )


def _text(s: _Summary) -> str:
    lines = ", ".join(
        f"{name} ({'converged' if ok else 'NOT converged'}, {it} it.)"
        for name, ok, it, _ in s.lines
    )
    sigma = "; ".join(f"{name} {end} {format_value(std)}" for name, end, _, std, _, _ in s.ends)
    n = len(s.warnings)
    out = [f"<stochcable {s.kind}: {_short(s.title)}>", f"  lines: {lines}"]
    if s.bodies:
        out.append(f"  bodies: {', '.join(s.bodies)}")
    out.append(f"  end tension σ [{s.force}]: {sigma}")
    if s.residuals:
        lin = "; ".join(
            f"{e[0]} {e[1]} {format_value(v)}" for e, v in zip(s.ends, s.linear) if v is not None
        )
        out.append(f"  residuals included: {', '.join(s.residuals)} (linear σ: {lin})")
    out.append(f"  warnings: {n}" + (" (.warnings)" if n else ""))
    if s.target_error is not None:
        out.append(f"  fidelity: target error {format_value(s.target_error)}")
    return "\n".join(out)


def _html(s: _Summary) -> str:
    f, t = s.force, s.time
    cols = ["line", "end", f"mean [{f}]", f"σ [{f}]", f"Tz [{t}]", f"MPM 3 h [{f}]"]
    rows, caption = s.ends, "End-tension statistics"
    if s.residuals:  # the linear model's σ beside
        cols, rows = cols + [f"linear σ [{f}]"], [(*e, v) for e, v in zip(s.ends, s.linear)]
        caption += f" with the residuals ({', '.join(s.residuals)})"
    stats = html_table(cols, rows, caption=caption)
    lin = html_table(
        ["line", "linearization", "iterations", "relative change [-]"],
        [(n, "converged" if ok else "NOT converged", it, ch) for n, ok, it, ch in s.lines],
    )
    warn = (
        f"<p>{len(s.warnings)} warning(s):</p>" + html_list(s.warnings)
        if s.warnings
        else "<p>No warnings.</p>"
    )
    return html_block(f"stochcable {s.kind}: {s.title}", [stats, lin, warn])


def result_text(result: Any) -> str:
    """A few lines on a :class:`~stochcable.results.documents.Result`: title, lines with
    their linearization, bodies, end-tension σ with units, the number of warnings."""
    return _text(_of_result(result))


def result_html(result: Any) -> str:
    """An HTML summary of a result: the end-tension statistics with units, the
    linearization per line and the warnings."""
    return _html(_of_result(result))


def document_text(document: Any) -> str:
    """:func:`result_text` of a result document read back from the service
    (:class:`~stochcable.results.views.AnalysisDocument`)."""
    return _text(_of_document(document))


def document_html(document: Any) -> str:
    """:func:`result_html` of a result document read back from the service."""
    return _html(_of_document(document))


def _progress(status: Any) -> str:
    p = status.progress or {}
    text = f"{p.get('done', 0)}/{p.get('total', '?')} cases"
    if p.get("not_ok"):
        text += f", {p['not_ok']} not ok"
    if status.status in ("queued", "running") and p.get("eta_seconds") is not None:
        text += f", about {format_value(p['eta_seconds'], 2)} s left"
    return text


def batch_status_text(status: Any) -> str:
    """One line on a batch job of the service (the client's ``BatchJob``): id, status,
    progress, the number of warnings and the error of a failed batch."""
    text = f"<stochcable BatchJob {status.id}: {status.status}, {_progress(status)}"
    if status.warnings:
        text += f", {len(status.warnings)} warning(s)"
    if status.error:
        text += f"; error: {_short(status.error)}"
    return text + ">"


def batch_status_html(status: Any) -> str:
    """An HTML summary of a batch job: status, progress, dates, warnings, cases not ok."""
    doc = status.document or {}
    rows: list[tuple[str, Any]] = [
        ("status", status.status),
        ("progress", _progress(status)),
        ("submitted (UTC)", doc.get("created") or "–"),
        ("finished (UTC)", doc.get("finished") or "–"),
    ]
    if status.error:
        rows.append(("error", status.error))
    parts = [html_table(["", ""], rows)]
    if status.warnings:
        parts.append(f"<p>{len(status.warnings)} warning(s):</p>" + html_list(status.warnings))
    problems = [
        f"case {p.get('index')}: {p.get('status')} — {p.get('reason')}" for p in status.problems
    ]
    if problems:
        parts.append("<p>Cases not ok:</p>" + html_list(problems))
    return html_block(f"stochcable batch job {status.id}", parts)
