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


def _units(result: Any) -> Any:
    env = getattr(result.scene, "environment", None)
    return unit_labels(env.g if env is not None else 9.80665)


def _end_rows(result: Any) -> list[tuple[str, str, float, float, float, float]]:
    rows = []
    for name, line in result.lines.items():
        for end in ENDS:
            st = getattr(line, end, None)
            if st is not None:
                rows.append((name, end, st.mean, st.std, st.tz, st.mpm_3h))
    return rows


def result_text(result: Any) -> str:
    """A few lines on a :class:`~stochcable.results.documents.Result`: title, lines with
    their linearization, end-tension σ with units, the number of warnings."""
    units = _units(result)
    title = _short(getattr(result.scene, "title", "") or "(untitled scene)")
    lines = ", ".join(
        f"{name} ({'converged' if r.linearization.converged else 'NOT converged'}, "
        f"{r.linearization.iterations} it.)"
        for name, r in result.lines.items()
    )
    sigma = "; ".join(
        f"{name} {end} {format_value(std)}" for name, end, _, std, _, _ in _end_rows(result)
    )
    n = len(result.warnings)
    out = [
        f"<stochcable Result: {title}>",
        f"  lines: {lines}",
        f"  end tension σ [{units.force}]: {sigma}",
        f"  warnings: {n}" + (" (result.warnings)" if n else ""),
    ]
    if result.bodies:
        out.insert(2, f"  bodies: {', '.join(result.bodies)}")
    if result.fidelity is not None:
        out.append(f"  fidelity: target error {format_value(result.fidelity.target_error)}")
    return "\n".join(out)


def result_html(result: Any) -> str:
    """An HTML summary of a result: the end-tension statistics with units, the
    linearization per line and the warnings."""
    units = _units(result)
    f, t = units.force, units.time
    stats = html_table(
        ["line", "end", f"mean [{f}]", f"σ [{f}]", f"Tz [{t}]", f"MPM 3 h [{f}]"],
        _end_rows(result),
        caption="End-tension statistics",
    )
    lin = html_table(
        ["line", "linearization", "iterations", "relative change [-]"],
        [
            (
                name,
                "converged" if r.linearization.converged else "NOT converged",
                r.linearization.iterations,
                r.linearization.relative_change,
            )
            for name, r in result.lines.items()
        ],
    )
    warn = (
        f"<p>{len(result.warnings)} warning(s):</p>" + html_list(result.warnings)
        if result.warnings
        else "<p>No warnings.</p>"
    )
    title = getattr(result.scene, "title", "") or "(untitled scene)"
    return html_block(f"stochcable Result: {title}", [stats, lin, warn])


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
