"""A load-case set's results as an xarray Dataset (NetCDF), a CSV summary and a JSON
document."""

from __future__ import annotations

import csv
import io
import math
from typing import Any

import numpy as np

from stochcable.cases.run import ENDS, CaseSetResult

__all__ = ["case_dataset", "case_summary_csv", "case_document"]

_STAT_NAMES = (
    ("tension_mean", "mean end tension", 0),
    ("tension_std", "standard deviation of the end tension", 1),
    ("tension_tz", "mean zero up-crossing period of the end tension", 2),
    ("tension_mpm_3h", "3-hour most probable maximum end tension", 3),
)


def _a(units: str, long_name: str) -> dict[str, str]:
    return {"units": units, "long_name": long_name}


def case_dataset(result: CaseSetResult, force_unit: str = "N"):
    """The set as an xarray Dataset.

    Dimensions ``case``, ``line``, ``end`` and, per line, ``element_<line>``;
    coordinates ``hs`` [m], ``tp`` [s], ``gamma``, ``heading`` [deg], ``probability``,
    ``status``; end statistics and damage rates per case, totals per line and end.
    Units and long names in the attributes.
    """
    import xarray as xr

    states = result.scatter.states
    coords: dict[str, Any] = {
        "case": np.arange(len(states)),
        "line": list(result.lines),
        "end": list(ENDS),
        "hs": ("case", [s.hs for s in states], _a("m", "significant wave height")),
        "tp": ("case", [s.tp for s in states], _a("s", "peak period")),
        "gamma": ("case", [s.gamma for s in states], _a("1", "JONSWAP γ")),
        "heading": ("case", [s.heading for s in states], _a("degree", "wave heading")),
        "probability": ("case", [s.probability for s in states], _a("1", "probability")),
        "status": ("case", [r.status for r in result.rows]),
        "reason": ("case", [r.reason for r in result.rows]),
    }
    data: dict[str, Any] = {}
    for name, long, j in _STAT_NAMES:
        arr = np.stack([[result.stats[ln][e][:, j] for e in ENDS] for ln in result.lines], axis=0)
        unit = "s" if name == "tension_tz" else force_unit
        data[name] = (("line", "end", "case"), arr, {"units": unit, "long_name": long})
    dr = np.stack([result.damage_rate_ends[ln].T for ln in result.lines])
    data["damage_rate"] = (("line", "end", "case"), dr, _a("s-1", "fatigue damage rate at the end"))
    annual = np.full((len(result.lines), 2), np.nan)
    life = np.full_like(annual, np.nan)
    level = np.full_like(annual, np.nan)
    for i, ln in enumerate(result.lines):
        t = result.totals[ln]
        for j, e in enumerate(ENDS):
            annual[i, j] = t.annual_damage.get(e, np.nan)
            life[i, j] = t.fatigue_life.get(e, np.nan)
            level[i, j] = t.return_level.get(e, np.nan)
    data["annual_damage"] = (
        ("line", "end"),
        annual,
        _a("year-1", "annual fatigue damage"),
    )
    data["fatigue_life"] = (
        ("line", "end"),
        life,
        _a("year", "fatigue life with the design fatigue factor"),
    )
    data["return_level"] = (
        ("line", "end"),
        level,
        _a(force_unit, f"{result.years:g}-year most probable maximum tension"),
    )
    for ln in result.lines:
        dim = f"element_{ln}"
        s = result.s_elements.get(ln, np.full(result.damage_rate_along[ln].shape[1], np.nan))
        coords[f"s_{ln}"] = (
            dim,
            s,
            {"units": "m", "long_name": f"arc length of the element midpoints of {ln}"},
        )
        data[f"damage_rate_along_{ln}"] = (
            ("case", dim),
            result.damage_rate_along[ln],
            {"units": "s-1", "long_name": f"fatigue damage rate along {ln}"},
        )
        along = result.totals[ln].annual_damage.get("along")
        if along is not None:
            data[f"annual_damage_along_{ln}"] = (
                (dim,),
                along,
                _a("year-1", f"annual damage along {ln}"),
            )
    attrs = {
        "title": "stochcable load-case set",
        "scatter_source": result.scatter.source,
        "spectrum_family": result.scatter.family,
        "return_period_years": result.years,
        "coverage_ok": result.coverage["ok"],
        "coverage_with_response": result.coverage["with_response"],
        "coverage_failed": result.coverage["failed"],
        "year_seconds": 365.25 * 86400.0,
        "Conventions": "CF-1.8",
    }
    return xr.Dataset(data, coords=coords, attrs=attrs)


def case_summary_csv(result: CaseSetResult) -> str:
    """One row per case: the sea state, its status, and per line and end the tension
    σ, 3-h MPM and damage rate."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    head = ["case", "hs", "tp", "gamma", "heading", "probability", "status", "reason"]
    for ln in result.lines:
        for e in ENDS:
            head += [f"{ln}.{e}.std", f"{ln}.{e}.mpm_3h", f"{ln}.{e}.damage_rate"]
    w.writerow(head)
    for i, (s, r) in enumerate(zip(result.scatter.states, result.rows)):
        row: list[Any] = [i, s.hs, s.tp, s.gamma, s.heading, s.probability, r.status, r.reason]
        for ln in result.lines:
            for j, e in enumerate(ENDS):
                st = result.stats[ln][e][i]
                row += [_num(st[1]), _num(st[3]), _num(result.damage_rate_ends[ln][i, j])]
        w.writerow(row)
    return buf.getvalue()


def _num(x: float) -> Any:
    return "" if not math.isfinite(float(x)) else repr(float(x))


def _json_num(x: Any) -> Any:
    x = float(x)
    return x if math.isfinite(x) else None


def case_document(result: CaseSetResult) -> dict[str, Any]:
    """JSON-ready document of the set: cases with their statistics, totals per line."""
    cases = []
    for i, (s, r) in enumerate(zip(result.scatter.states, result.rows)):
        lines = {}
        for ln in result.lines:
            lines[ln] = {
                e: {
                    "tension": {
                        k: _json_num(result.stats[ln][e][i, j])
                        for j, k in enumerate(("mean", "std", "tz", "mpm_3h"))
                    },
                    "damage_rate": _json_num(result.damage_rate_ends[ln][i, jj]),
                }
                for jj, e in enumerate(ENDS)
            }
        cases.append(
            {
                "hs": s.hs,
                "tp": s.tp,
                "gamma": s.gamma,
                "heading": s.heading,
                "probability": s.probability,
                "status": r.status,
                "reason": r.reason,
                "flags": list(r.flags),
                "warnings": list(r.warnings),
                "lines": lines,
            }
        )
    totals = {}
    for ln, t in result.totals.items():
        totals[ln] = {
            "annual_damage": {
                e: _json_num(t.annual_damage[e]) for e in t.annual_damage.keys() & ENDS
            },
            "fatigue_life_years": {
                e: _json_num(t.fatigue_life[e]) for e in t.fatigue_life.keys() & ENDS
            },
            "return_level": {e: _json_num(v) for e, v in t.return_level.items()},
            "governing_mpm_case": dict(t.governing_mpm_case),
            "governing_damage_case": dict(t.governing_damage_case),
        }
        if "along" in t.annual_damage:
            totals[ln]["annual_damage_along"] = [_json_num(x) for x in t.annual_damage["along"]]
    return {
        "scatter": {"source": result.scatter.source, "spectrum": result.scatter.family},
        "return_period_years": result.years,
        "coverage": dict(result.coverage),
        "cases": cases,
        "totals": totals,
    }
