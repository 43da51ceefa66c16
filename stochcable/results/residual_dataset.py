"""The residuals' part of the result Dataset (:mod:`stochcable.results.datasets`): the
end-tension spectral densities with the residuals of the linear model, the linear
model's end statistics beside the corrected ones, and each residual's variance.

The corrected densities (the document's ``lines.<line>.corrected_spectra``) live on
the analysis grid extended by the residual lines outside it
(:mod:`stochcable.dynamics.residuals.corrected_spectrum`), which is a line's own: the
Dataset puts them on their own frequency coordinate ``omega_corrected``, the union of
every line's grid, NaN where a line has no point.  A line's density over its finite
values integrates (trapezoid) to its ``end_tension_std`` squared.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from stochcable.scene.residual_kinds import RESIDUAL_KINDS

__all__ = ["ENDS", "residual_parts"]

ENDS = ("end_a", "end_b")
"""The two ends of a line, as the result documents name them."""


def _var(dims: tuple[str, ...], data: Any, units: str, long_name: str) -> tuple:
    """A Dataset variable with its CF ``units`` and ``long_name``."""
    return (dims, np.asarray(data), {"units": units, "long_name": long_name})


def _corrected(lines: Mapping[str, Any], u: Mapping[str, str]) -> tuple[dict, dict]:
    names = [n for n in lines if lines[n].get("corrected_spectra")]
    if not names:
        return {}, {}
    grid = np.unique(
        np.concatenate(
            [np.asarray(lines[n]["corrected_spectra"][e]["omega"]) for n in names for e in ENDS]
        )
    )
    data = np.full((len(lines), len(ENDS), grid.size), np.nan)
    for i, n in enumerate(lines):
        spectra = lines[n].get("corrected_spectra")
        for j, e in enumerate(ENDS):
            if spectra:
                at = np.searchsorted(grid, np.asarray(spectra[e]["omega"], dtype=float))
                data[i, j, at] = spectra[e]["tension"]
    coords = {
        "omega_corrected": _var(
            ("omega_corrected",),
            grid,
            "rad s-1",
            "angular frequency of the end-tension densities with the residuals (every "
            "line's analysis grid and residual lines outside it)",
        )
    }
    out = {
        "end_tension_corrected_spectrum": _var(
            ("line", "end", "omega_corrected"),
            data,
            u["force_spectrum"],
            "one-sided spectral density of the dynamic end tension with the residuals of "
            "the linear model (NaN off the line's own grid; over its finite values its "
            "area is end_tension_std squared)",
        )
    }
    return coords, out


def residual_parts(
    doc: Mapping[str, Any], u: Mapping[str, str], statistics: Mapping[str, str]
) -> tuple[dict, dict]:
    """The coordinates and variables of the residuals of a result document (empty when
    no line carries them).

    Parameters
    ----------
    doc : mapping
        A result document.
    u : mapping
        The unit labels of :mod:`stochcable.results.datasets` (``force``,
        ``force_spectrum``).
    statistics : mapping
        The end statistics to carry for the linear model, key to long name.

    Returns
    -------
    coords, variables : dict, dict
        ``omega_corrected`` and ``end_tension_corrected_spectrum`` (line, end,
        omega_corrected); ``linear_end_tension_<statistic>`` (line, end): the linear
        model's, NaN for a line without residuals (its ``end_tension_<statistic>``
        is the linear model's); ``tension_std_linear`` (line, element): the element
        tensions' linear σ where the residuals were computed along the line (NaN
        elsewhere); ``motion_std_linear`` (line, node, axis) likewise for the node
        motions; ``<kind>_variance`` (line, end) and
        ``<kind>_computed`` (line) of every residual kind present.
    """
    lines = doc["lines"]
    names = list(lines)
    coords, out = _corrected(lines, u)
    if any(lines[n].get("linear") for n in names):
        for key, long in statistics.items():
            data = [
                [lines[n]["linear"][e]["tension"][key] if lines[n].get("linear") else np.nan
                 for e in ENDS]
                for n in names
            ]  # fmt: skip
            unit = "s" if key == "tz" else u["force"]
            out[f"linear_end_tension_{key}"] = _var(
                ("line", "end"), data, unit, f"end tension of the linear model alone: {long}"
            )
    if any("std_linear" in lines[n]["tension"] for n in names):
        n_el = max(len(lines[n]["tension"]["s"]) for n in names)
        data = np.full((len(names), n_el), np.nan)
        for i, n in enumerate(names):
            lin = lines[n]["tension"].get("std_linear")
            if lin is not None:
                data[i, : len(lin)] = lin
        out["tension_std_linear"] = _var(
            ("line", "element"),
            data,
            u["force"],
            "standard deviation of the dynamic effective tension of the linear model alone "
            "(NaN for a line whose tension_std is the linear model's)",
        )
    if any("std_linear" in lines[n]["motion"] for n in names):
        n_nd = max(len(lines[n]["motion"]["s"]) for n in names)
        data = np.full((len(names), n_nd, 3), np.nan)
        for i, n in enumerate(names):
            lin = lines[n]["motion"].get("std_linear")
            if lin is not None:
                data[i, : len(lin)] = lin
        out["motion_std_linear"] = _var(
            ("line", "node", "axis"),
            data,
            u["length"],
            "standard deviation of the node displacement of the linear model alone, global "
            "axes (NaN for a line whose motion_std is the linear model's)",
        )
    for kind in RESIDUAL_KINDS:
        if not any(kind in lines[n] for n in names):
            continue
        recs = [lines[n].get(kind) for n in names]
        out[f"{kind}_variance"] = _var(
            ("line", "end"),
            [[np.nan if r is None else r[e]["variance"] for e in ENDS] for r in recs],
            f"{u['force']}2",
            f"end-tension variance the {kind.replace('_', ' ')} adds (0 where not computed)",
        )
        out[f"{kind}_computed"] = _var(
            ("line",),
            [bool(r is not None and r["computed"]) for r in recs],
            "1",
            f"{kind.replace('_', ' ')} computed for the line",
        )
    return coords, out
