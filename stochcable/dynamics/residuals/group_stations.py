"""The group's and the bodies' parts of a line's stations: the element tensions and node
motions at the stations of a line on free bodies take what its own along-line records
do not (:mod:`.along_line`, :mod:`.along_line_motion`): the group's part of the joint
sums over every line's loads (:mod:`.group_motion`), and the residual of the bodies'
own drag (:mod:`.body_drag_residual`), each one more part of the kind's lines, carried
to every element and node as the line's own parts (the stations' weights).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from typing import Any

import numpy as np

from stochcable.dynamics.residuals.along_line import station_weights
from stochcable.dynamics.residuals.along_line_motion import motion_weights, motions_in_range
from stochcable.dynamics.residuals.group_motion import BodyRows, station_misfit

__all__ = ["group_station_parts", "with_group_stations", "with_station_parts"]

#: The along-line record's kind of each joint sum (its key's first item).
_KINDS = {"drag": "drag_residual", "drag_3d": "drag_residual", "geometric": "geometric_residual"}


def group_station_parts(rows: BodyRows, name: str) -> dict[str, dict[str, tuple]]:
    """The group's parts of line ``name``'s stations by set ("elements", "nodes") and
    kind: (frequencies [rad/s] (n_o,), variance lines (n_rows, n_o)), one joint key
    per kind."""
    out: dict[str, dict[str, tuple]] = {"elements": {}, "nodes": {}}
    for key, sets in rows.stations.items():
        kind = _KINDS.get(key[0])
        for st in ("elements", "nodes"):
            if kind is not None and (st, name) in sets and kind not in out[st]:
                out[st][kind] = sets[st, name]
    return out


def _with_misfit(
    parts: Mapping[str, tuple], misfit: np.ndarray | None, omega: np.ndarray
) -> dict[str, list[tuple[np.ndarray, np.ndarray]]]:
    """The kinds' group parts as lists, the drag residual's with its misfit part."""
    out = {kind: [part] for kind, part in parts.items()}
    if misfit is not None and "drag_residual" in out:
        out["drag_residual"].append((omega, misfit))
    return out


def with_group_stations(result: Any, rows: BodyRows) -> Any:
    """``result`` (a line's LineResult) with the group's parts of its stations added to
    its element tensions' and node motions' residual records (:func:`with_station_parts`,
    the other lines' drag misfit loads with them)."""

    def misfit(kind: str, linear: np.ndarray, spectra: np.ndarray, w: np.ndarray) -> Any:
        return station_misfit(rows, result.name, kind, linear, spectra, w)

    return with_station_parts(result, group_station_parts(rows, result.name), misfit)


def with_station_parts(
    result: Any, parts: Mapping[str, Mapping[str, tuple]], misfit: Any = None
) -> Any:
    """``result`` (a line's LineResult) with ``parts`` of its stations by set
    ("elements", "nodes") and kind, (frequencies [rad/s] (n_o,), variance lines
    (n_rows, n_o)), added to its element tensions' and node motions' residual records
    (each a part of the kind's lines, carried to every element and node as the line's
    own parts: the stations' weights), and their σ; ``misfit(set, linear transfer,
    spectra, ω)`` the drag residual's misfit part of a set's stations (None: none);
    unchanged where a record is not computed or lacks the kind; a node motion whose
    total would leave the closed forms' range is the linear model's, node by node
    (:func:`~.along_line_motion.motions_in_range`)."""
    model = result.model
    omega = np.asarray(result.omega, dtype=float)
    spectra = np.asarray(result.input_spectra, dtype=float)
    s0 = np.asarray(model.mesh.s0, dtype=float)
    changes: dict[str, Any] = {}
    along = result.along_line
    if along is not None and along.computed and parts.get("elements"):
        weights = station_weights(0.5 * (s0[1:] + s0[:-1]), along.stations)
        lines, var = dict(along.lines), along.variance.copy()
        lin = np.asarray(result.tension_transfer)[:, along.stations]
        mis = None if misfit is None else misfit("elements", lin, spectra, omega)
        for kind, v in _with_misfit(parts["elements"], mis, omega).items():
            if kind in lines:
                lines[kind] = lines[kind] + tuple((om, weights @ x) for om, x in v)
                var = var + sum((weights @ x).sum(axis=1) for _, x in v)
        new = dataclasses.replace(along, lines=lines, variance=var)
        changes.update(along_line=new, tension_std=new.std(result.tension_std_linear))
    moves = result.motion_residual
    if moves is not None and moves.computed and parts.get("nodes"):
        comps, d = list(model.components), model.dim
        lin = np.asarray(result.motion_std_linear, dtype=float)
        weights = motion_weights(s0, moves.stations, lin[:, comps] ** 2)
        lines = {k: tuple((om, v.copy()) for om, v in p) for k, p in moves.lines.items()}
        total = moves.variance.copy()
        u = np.asarray(result.motion_transfer)[:, moves.stations][:, :, comps]
        u = u.reshape(u.shape[0], -1, u.shape[3])
        mis = None if misfit is None else misfit("nodes", u, spectra, omega)
        for kind, v in _with_misfit(parts["nodes"], mis, omega).items():
            if kind in lines:
                for om, x in v:
                    full = np.zeros((model.n_nodes, 3, om.size))
                    full[:, comps] = (weights @ x).reshape(model.n_nodes, d, om.size)
                    lines[kind] = lines[kind] + ((om, full),)
                    total = total + full.sum(axis=2)
        beyond, reason = motions_in_range(result.name, lines, total, lin, moves.beyond)
        new = dataclasses.replace(
            moves, lines=lines, variance=total, beyond=beyond, reason=reason or moves.reason
        )
        changes.update(motion_residual=new, motion_std=new.std(lin))
    return dataclasses.replace(result, **changes) if changes else result
