"""The result document as an xarray Dataset (and NetCDF): the form spectra and
along-line results are handled in by MoorPy, wavespectra and capytaine users.

:func:`dataset_from_document` turns the JSON result document (``Result.to_document()``,
the CLI's and the service's answer, or one read back from a file) into an
:class:`xarray.Dataset`; :func:`dataset_from_result` adds what only the Python result
holds (the tension spectrum of every element and the motion spectrum of every node).

Dimensions: ``line``, ``end`` (end_a, end_b), ``omega`` (the analysis grid; and
``omega_corrected``, :mod:`stochcable.results.residual_dataset`, and
``omega_body_corrected`` for the bodies' densities with the residuals),
``element`` and ``node`` (index along each line; lines with fewer elements are padded
with NaN; the arc lengths are the coordinates ``element_arclength`` and
``node_arclength``), ``axis`` (x, y, z), ``mode``; with bodies ``body`` and ``dof``;
with a time series ``time``.  Every variable carries ``units`` (udunits symbols of
the scene's unit system, SI or ft/slug/lbf, as the document's ``units``) and
``long_name`` in its attributes, as the CF conventions ask.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from stochcable.results.residual_dataset import ENDS, _var, residual_parts

__all__ = [
    "dataset_from_document",
    "dataset_from_result",
    "write_netcdf",
    "netcdf_bytes",
]

AXES = ("x", "y", "z")
#: The statistics of a response the Dataset carries, with their long names.
STATISTICS = {
    "mean": "mean (static) value",
    "std": "standard deviation of the dynamic part",
    "tz": "mean zero-upcrossing period",
    "mpm_3h": "mean + Rayleigh most probable maximum over 3 hours",
    "significant": "significant value 2 sigma",
    "expected_max": "mean + expected maximum over analysis.duration",
}
_BODY_DOFS = ("surge", "sway", "heave", "roll", "pitch", "yaw")


def _xr():
    import xarray

    return xarray


def _pad(rows: Sequence[Sequence[Any]], width: int, tail: tuple[int, ...] = ()) -> np.ndarray:
    """Stack ragged rows into an array padded with NaN to ``width``."""
    out = np.full((len(rows), width, *tail), np.nan)
    for i, r in enumerate(rows):
        a = np.asarray(r, dtype=float).reshape((-1, *tail))
        out[i, : a.shape[0]] = a
    return out


def _units(doc: Mapping[str, Any]) -> dict[str, str]:
    u = doc.get("units") or {"length": "m", "force": "N", "mass": "kg"}
    length, force = u["length"], u["force"]
    return {
        "force": force,
        "length": length,
        "force_spectrum": f"{force}2 s rad-1",
        "length_spectrum": f"{length}2 s rad-1",
    }


def _omega(lines: Mapping[str, Any]) -> np.ndarray:
    grids = [np.asarray(v["spectra"]["omega"], dtype=float) for v in lines.values()]
    first = grids[0]
    for g in grids[1:]:
        if g.shape != first.shape or not np.array_equal(g, first):
            raise ValueError("the lines of a result document have different omega grids")
    return first


def _line_variables(doc: Mapping[str, Any], u: dict[str, str]) -> dict[str, tuple]:
    lines = doc["lines"]
    names = list(lines)
    f, ln = u["force"], u["length"]
    n_el = max(len(v["tension"]["s"]) for v in lines.values())
    n_nd = max(len(v["motion"]["s"]) for v in lines.values())
    n_md = max(len(v["modes"]["omega"]) for v in lines.values())
    out: dict[str, tuple] = {}
    for key, long in STATISTICS.items():
        data = [[lines[n][e]["tension"][key] for e in ENDS] for n in names]
        unit = "s" if key == "tz" else f
        out[f"end_tension_{key}"] = _var(("line", "end"), data, unit, f"end tension: {long}")
    out["end_tension_spectrum"] = _var(
        ("line", "end", "omega"),
        [[lines[n]["spectra"][e]["tension"] for e in ENDS] for n in names],
        u["force_spectrum"],
        "one-sided spectrum of the dynamic end tension",
    )
    out["end_force_std"] = _var(
        ("line", "end", "axis"),
        [[lines[n][e]["force_std"] for e in ENDS] for n in names],
        f,
        "standard deviation of the force on the support, global axes",
    )
    tension = [lines[n]["tension"] for n in names]
    out["tension_mean"] = _var(
        ("line", "element"), _pad([t["mean"] for t in tension], n_el), f, "static effective tension"
    )
    out["tension_std"] = _var(
        ("line", "element"),
        _pad([t["std"] for t in tension], n_el),
        f,
        "standard deviation of the dynamic effective tension",
    )
    out["motion_std"] = _var(
        ("line", "node", "axis"),
        _pad([lines[n]["motion"]["std"] for n in names], n_nd, (3,)),
        ln,
        "standard deviation of the node displacement, global axes",
    )
    out["natural_frequency"] = _var(
        ("line", "mode"),
        _pad([lines[n]["modes"]["omega"] for n in names], n_md),
        "rad s-1",
        "natural angular frequency of the line about its static shape",
    )
    lin = [lines[n]["linearization"] for n in names]
    out["linearization_converged"] = _var(
        ("line",), [bool(r["converged"]) for r in lin], "1", "drag linearization converged"
    )
    out["linearization_iterations"] = _var(
        ("line",), [int(r["iterations"]) for r in lin], "1", "drag linearization iterations"
    )
    out["linearization_relative_change"] = _var(
        ("line",),
        [float(r["relative_change"]) for r in lin],
        "1",
        "last relative change of the drag linearization",
    )
    statics = (doc.get("statics") or {}).get("lines") or {}
    if all(n in statics for n in names):
        out["static_position"] = _var(
            ("line", "node", "axis"),
            _pad([statics[n]["nodes"] for n in names], n_nd, (3,)),
            ln,
            "static node position",
        )
        out["touchdown"] = _var(
            ("line",),
            [
                np.nan if statics[n].get("touchdown") is None else statics[n]["touchdown"]
                for n in names
            ],
            ln,
            "unstretched arc length of the touchdown point from end_a",
        )
    return out


def _line_coords(doc: Mapping[str, Any], u: dict[str, str]) -> dict[str, Any]:
    lines = doc["lines"]
    names = list(lines)
    n_el = max(len(v["tension"]["s"]) for v in lines.values())
    n_nd = max(len(v["motion"]["s"]) for v in lines.values())
    return {
        "line": ("line", names),
        "end": ("end", list(ENDS)),
        "axis": ("axis", list(AXES)),
        "omega": _var(("omega",), _omega(lines), "rad s-1", "angular frequency"),
        "element_arclength": _var(
            ("line", "element"),
            _pad([lines[n]["tension"]["s"] for n in names], n_el),
            u["length"],
            "unstretched arc length of the element midpoint from end_a",
        ),
        "node_arclength": _var(
            ("line", "node"),
            _pad([lines[n]["motion"]["s"] for n in names], n_nd),
            u["length"],
            "unstretched arc length of the node from end_a",
        ),
    }


def _body_parts(doc: Mapping[str, Any], u: dict[str, str]) -> tuple[dict, dict]:
    bodies = doc.get("bodies") or {}
    if not bodies:
        return {}, {}
    names = list(bodies)
    dofs = list(_BODY_DOFS)
    rot = {"roll", "pitch", "yaw"}
    dof_units = [("rad" if d in rot else u["length"]) for d in dofs]
    coords = {
        "body": ("body", names),
        "dof": ("dof", dofs),
        "dof_units": (("dof",), dof_units, {"long_name": "units of each degree of freedom"}),
    }
    out: dict[str, tuple] = {}
    for key, long in STATISTICS.items():
        data = np.full((len(names), len(dofs)), np.nan)
        for i, n in enumerate(names):
            for j, d in enumerate(dofs):
                stats = bodies[n]["motion"].get(d)
                if stats is not None:
                    data[i, j] = stats[key]
        unit = "s" if key == "tz" else "see dof_units"
        out[f"body_motion_{key}"] = _var(("body", "dof"), data, unit, f"body motion: {long}")
    lin = [[bodies[n]["motion"].get(d, {}).get("std_linear", np.nan) for d in dofs] for n in names]
    if not np.all(np.isnan(lin)):  # a body whose motion carries its line's residuals
        out["body_motion_std_linear"] = _var(
            ("body", "dof"), np.array(lin, dtype=float), "see dof_units",
            "body motion: standard deviation of the linear model (NaN where the motion is "
            "the linear model's)",
        )  # fmt: skip
    spec = np.full((len(names), len(dofs), len(_doc_omega(doc))), np.nan)
    for i, n in enumerate(names):
        for j, d in enumerate(dofs):
            s = bodies[n]["spectra"].get(d)
            if s is not None:
                spec[i, j] = s
    out["body_motion_spectrum"] = _var(
        ("body", "dof", "omega"),
        spec,
        f"({u['length']}2 or rad2) s rad-1",
        "one-sided spectrum of the body motion (see dof_units)",
    )
    coords_c, out_c = _body_corrected(bodies, names, dofs, u)
    coords.update(coords_c)
    out.update(out_c)
    return coords, out


def _body_corrected(
    bodies: Mapping[str, Any], names: list[str], dofs: list[str], u: dict[str, str]
) -> tuple[dict, dict]:
    """``body_motion_corrected_spectrum`` (body, dof, omega_body_corrected): each DOF's
    density with the residuals (the document's ``corrected_spectra``) on the union of
    their grids, NaN off a DOF's own points (as the end tensions',
    :mod:`stochcable.results.residual_dataset`)."""
    have = [n for n in names if bodies[n].get("corrected_spectra")]
    if not have:
        return {}, {}
    grid = np.unique(
        np.concatenate(
            [np.asarray(s["omega"], dtype=float)
             for n in have for s in bodies[n]["corrected_spectra"].values()]
        )
    )  # fmt: skip
    data = np.full((len(names), len(dofs), grid.size), np.nan)
    for i, n in enumerate(names):
        for j, d in enumerate(dofs):
            s = (bodies[n].get("corrected_spectra") or {}).get(d)
            if s is not None:
                data[i, j, np.searchsorted(grid, np.asarray(s["omega"], dtype=float))] = s["motion"]
    coords = {
        "omega_body_corrected": _var(
            ("omega_body_corrected",), grid, "rad s-1",
            "angular frequency of the body-motion densities with the residuals (the "
            "analysis grid and the residual lines outside it)",
        )
    }  # fmt: skip
    out = {
        "body_motion_corrected_spectrum": _var(
            ("body", "dof", "omega_body_corrected"), data,
            f"({u['length']}2 or rad2) s rad-1",
            "one-sided spectral density of the body motion with the residuals of the "
            "linear model (see dof_units; NaN off the DOF's own grid and for a body "
            "without residuals; over its finite values its area is body_motion_std "
            "squared)",
        )
    }  # fmt: skip
    return coords, out


def _doc_omega(doc: Mapping[str, Any]) -> np.ndarray:
    """The analysis grid of a result document. [rad/s]"""
    return _omega(doc["lines"])


def _timeseries_parts(doc: Mapping[str, Any], u: dict[str, str]) -> tuple[dict, dict]:
    ts = doc.get("timeseries")
    if not ts:
        return {}, {}
    coords = {"time": _var(("time",), ts["time"], "s", "time")}
    out: dict[str, tuple] = {}
    if ts.get("elevation") is not None:
        out["elevation"] = _var(
            ("time",), ts["elevation"], u["length"], "wave elevation at the origin"
        )
    names = list(doc["lines"])
    tl = ts.get("lines") or {}
    if all(n in tl for n in names):
        out["end_tension_series"] = _var(
            ("line", "end", "time"),
            [[tl[n][e]["tension"] for e in ENDS] for n in names],
            u["force"],
            "end tension (mean + dynamic), one realization",
        )
        if any("tension_linear" in tl[n][e] for n in names for e in ENDS):
            # the linear model's beside it (asked for): where no residual component was
            # added, the tension itself
            out["end_tension_series_linear"] = _var(
                ("line", "end", "time"),
                [
                    [tl[n][e].get("tension_linear", tl[n][e]["tension"]) for e in ENDS]
                    for n in names
                ],
                u["force"],
                "end tension of the linear model (without the residuals' component), "
                "one realization",
            )
    return coords, out


def dataset_from_document(doc: Mapping[str, Any]):
    """The result document as an :class:`xarray.Dataset`.

    Parameters
    ----------
    doc : mapping
        A result document (``Result.to_document()``, the CLI's JSON or the service's
        answer to ``POST /v1/analyses``).

    Returns
    -------
    xarray.Dataset
        Dimensions ``line``, ``end``, ``omega``, ``element``, ``node``, ``axis``,
        ``mode`` (and ``body``, ``dof``, ``time`` when present); the values are the
        document's, in its unit system (``attrs["unit_system"]``).
    """
    xr = _xr()
    u = _units(doc)
    coords = _line_coords(doc, u)
    data = _line_variables(doc, u)
    parts = (_body_parts(doc, u), _timeseries_parts(doc, u), residual_parts(doc, u, STATISTICS))
    for part in parts:
        coords.update(part[0])
        data.update(part[1])
    units = doc.get("units") or {}
    attrs = {
        "title": "stochcable result",
        "Conventions": "CF-1.10",
        "source": "stochcable frequency-domain analysis",
        "unit_system": units.get("system", "SI"),
        "warnings": "\n".join(doc.get("warnings") or []),
        "linearization_converged": int(bool(doc.get("linearization", {}).get("converged", True))),
    }
    return xr.Dataset(data_vars=data, coords=coords, attrs=attrs)


def dataset_from_result(result: Any, timeseries_linear: bool = False):
    """:func:`dataset_from_document` of a result, with the spectra along the lines.

    Adds ``tension_spectrum`` (line, element, omega) and ``motion_spectrum`` (line,
    node, axis, omega), which the document leaves out for size.

    Parameters
    ----------
    result : Result
        A result of :func:`stochcable.analysis.analyze`.
    timeseries_linear : bool
        Add ``end_tension_series_linear``, the linear model's end-tension series,
        where the series carry the residuals' component.

    Returns
    -------
    xarray.Dataset
    """
    doc = result.to_document(timeseries="full", timeseries_linear=timeseries_linear)
    ds = dataset_from_document(doc)
    u = _units(doc)
    lines = list(result.lines.values())
    n_el, n_nd, n_w = ds.sizes["element"], ds.sizes["node"], ds.sizes["omega"]
    ts = np.full((len(lines), n_el, n_w), np.nan)
    ms = np.full((len(lines), n_nd, 3, n_w), np.nan)
    for i, lr in enumerate(lines):
        t = lr.tension_spectrum
        m = lr.motion_spectrum
        ts[i, : t.shape[0]] = t
        ms[i, : m.shape[0]] = m
    ds["tension_spectrum"] = (
        ("line", "element", "omega"),
        ts,
        {"units": u["force_spectrum"], "long_name": "one-sided spectrum of the element tension"},
    )
    ds["motion_spectrum"] = (
        ("line", "node", "axis", "omega"),
        ms,
        {"units": u["length_spectrum"], "long_name": "one-sided spectrum of the node displacement"},
    )
    return ds


def write_netcdf(dataset: Any, path: str | Path) -> Path:
    """Write a Dataset of this module as NetCDF-4 (netCDF4 engine); returns the path."""
    path = Path(path)
    dataset.to_netcdf(path, engine="netcdf4")
    return path


def netcdf_bytes(dataset: Any) -> bytes:
    """A Dataset as the bytes of a NetCDF-4 file (an HTTP answer's body).

    Parameters
    ----------
    dataset : xarray.Dataset
        For example :func:`dataset_from_document` of a result document.

    Returns
    -------
    bytes
        The file's content (HDF5-based NetCDF-4).
    """
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        path = write_netcdf(dataset, Path(tmp) / "result.nc")
        return path.read_bytes()
