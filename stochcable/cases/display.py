"""Short text and HTML summaries of a load-case set (:class:`~stochcable.cases.run.CaseSetResult`)
for the terminal and notebooks: cases and their status, the coverage, and per line and end
the governing 3-hour MPM, the annual damage, the fatigue life and the return level."""

from __future__ import annotations

import html
import math
from typing import Any

from stochcable.results.display import ENDS, format_value, html_block, html_list, html_table

__all__ = ["case_set_text", "case_set_html"]


def _counts(result: Any) -> dict[str, int]:
    out: dict[str, int] = {}
    for r in result.rows:
        out[r.status] = out.get(r.status, 0) + 1
    return out


def _nanmax(values: Any) -> float:
    finite = [float(v) for v in values if math.isfinite(float(v))]
    return max(finite) if finite else math.nan


def _end_rows(result: Any) -> list[tuple[Any, ...]]:
    rows = []
    for name in result.lines:
        totals = result.totals.get(name)
        for end in ENDS:
            mpm = _nanmax(result.stats[name][end][:, 3])
            annual = life = level = math.nan
            if totals is not None:
                annual = totals.annual_damage.get(end, math.nan)
                life = totals.fatigue_life.get(end, math.nan)
                level = totals.return_level.get(end, math.nan)
            rows.append((name, end, mpm, annual, life, level))
    return rows


def _status_line(result: Any) -> str:
    counts = ", ".join(f"{n} {s}" for s, n in sorted(_counts(result).items()))
    ok = format_value(result.coverage["ok"])
    return f"{len(result.rows)} cases ({counts}); probability ok {ok}"


def case_set_text(result: Any, force_unit: str = "N") -> str:
    """A few lines on a load-case set: the diagram, the cases by status, and per line
    end the governing 3-hour MPM and the annual damage."""
    source = result.scatter.source or "scatter diagram"
    out = [f"<stochcable CaseSetResult: {source[:80]}>", f"  {_status_line(result)}"]
    for name, end, mpm, annual, life, _ in _end_rows(result):
        out.append(
            f"  {name} {end}: max MPM 3 h {format_value(mpm)} [{force_unit}], "
            f"annual damage {format_value(annual)} [1/year], life {format_value(life)} [years]"
        )
    return "\n".join(out)


def case_set_html(result: Any, force_unit: str = "N") -> str:
    """An HTML summary of a load-case set: per line and end the largest 3-hour MPM of the
    cases, the annual damage, the fatigue life and the return level, and the cases that
    are not ok (the tensions in ``force_unit``, as :func:`~stochcable.cases.case_dataset`)."""
    table = html_table(
        [
            "line",
            "end",
            f"max MPM 3 h [{force_unit}]",
            "annual damage [1/year]",
            "fatigue life [years]",
            f"{result.years:g}-year return level [{force_unit}]",
        ],
        _end_rows(result),
    )
    problems = [
        f"case {i}: {r.status} — {r.reason}" for i, r in enumerate(result.rows) if r.status != "ok"
    ]
    parts = [f"<p>{html.escape(_status_line(result))}</p>", table]
    if problems:
        parts.append(f"<p>{len(problems)} case(s) not ok:</p>" + html_list(problems[:20]))
    source = result.scatter.source or "scatter diagram"
    return html_block(f"stochcable load-case set: {source}", parts)
