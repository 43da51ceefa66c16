"""The residuals of the linear model in the node motions: the displacement variance the
residual loads add along the line, from the loads and load cross-spectra the kinds
form for the end tensions (as :mod:`.along_line` does for the element tensions).

A node's displacement component u_n,c = e_n,cᵀ u is another linear output of the
residual loads: with the ends held, u_f = A⁻¹F_f and u_n,c = (A⁻ᵀe_n,c)ᵀF_f (the
adjoint: one banded solve per frequency for the d components of every station node,
:func:`node_influence`).  The captured loads pass through these rows unchanged
(:func:`~stochcable.dynamics.residuals.along_line.element_lines` without the geometric
feedthrough — a stretch term of the tension, not a displacement;
:func:`~stochcable.dynamics.residuals.along_line_3d.vector_parts` for a 3-D line's
drag); a line on free bodies reaches its stations through the coupled group
(:class:`~stochcable.dynamics.residuals.along_line_bodies.NodeCoupledInfluence`: its
ends move with the bodies).  The residual variance adds to the linear variance per
node and component (uncorrelated with the linear response); the stations are up to
:data:`~stochcable.dynamics.residuals.along_line.MAX_STATIONS` nodes (both end nodes,
the segment junctions, evenly spaced ones), the other nodes' from the ratio of residual
to linear variance interpolated linearly in arc length (:func:`motion_weights`).  A
held end node moves with its prescribed motion only: no residual.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from stochcable.dynamics.loads.freqblocks import frequency_slices
from stochcable.dynamics.model.blocks import free_band, line_prep
from stochcable.dynamics.model.lift import lift_band, lift_pattern
from stochcable.dynamics.model.solvers import solve_band_stacked
from stochcable.dynamics.model.transport import gyro_band
from stochcable.dynamics.residuals.along_line import (
    CELL_BENDS,
    MAX_STATIONS,
    element_lines,
    misfit_lines,
    station_weights,
    top_line,
)
from stochcable.dynamics.residuals.along_line_3d import vector_parts
from stochcable.dynamics.solve.line_loads import drag_blocks

__all__ = [
    "MotionResidual",
    "NodeInfluence",
    "motion_residual",
    "motion_weights",
    "motion_stations",
    "node_influence",
]


def motion_stations(model: Any, max_stations: int = MAX_STATIONS) -> np.ndarray:
    """The nodes (indices, increasing) the motion residual is evaluated at: every node
    of a line of at most ``max_stations``, else both end nodes (at rest where held:
    no solve), every segment junction node and ``max_stations`` evenly spaced ones
    from the first inner node to the last (a held end lends no ratio to
    :func:`motion_weights`: the nodes next to it anchor the interpolation)."""
    n = model.n_nodes
    if n <= max_stations:
        return np.arange(n)
    seg = np.asarray(model.mesh.segment)
    junction = np.flatnonzero(np.diff(seg) != 0) + 1
    even = np.rint(np.linspace(1, n - 2, max_stations)).astype(int)
    return np.unique(np.concatenate([[0, n - 1], even, junction]))


def node_influence(system: Any, damping: Any, w: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    """The displacements of ``nodes`` (each of the model's d components, node-major:
    row k·d + c) per unit force on each node and component, ends held, the line's
    linear system with ``damping``: shape (n_nodes_out·d, n_nodes, d, n_w); zero rows
    for an end node. [m/N]

    By the adjoint (module notes), as
    :func:`~stochcable.dynamics.residuals.along_line.element_influence` (Aᵀ: a
    travelling line's C − G, a steady lift's C_Lᵀ)."""
    w = np.asarray(w, dtype=float)
    nodes = np.asarray(nodes, dtype=int)
    model = system.model
    prep = line_prep(system)
    d, n = model.dim, model.n_nodes
    cd = drag_blocks(system, damping)
    b_c = prep.bS + free_band(cd)
    if system.gyro is not None:
        b_c = b_c - gyro_band(system.gyro, d)
    if system.lift is not None:
        b_c = b_c + lift_band(np.transpose(system.lift, (0, 2, 1)), lift_pattern(model))
    n_out = nodes.size * d
    inner = np.flatnonzero((nodes >= 1) & (nodes <= n - 2))  # (an end node's rows: zero)
    cols = (inner[:, None] * d + np.arange(d)[None]).ravel()
    rhs = np.zeros(((n - 2) * d, cols.size), dtype=complex)
    rhs[((nodes[inner] - 1)[:, None] * d + np.arange(d)[None]).ravel(), np.arange(cols.size)] = 1.0
    out = np.zeros((n_out, n, d, w.size), dtype=complex)
    for sl in frequency_slices(w.size, 16 * n * d * max(cols.size, 1)):
        ws = w[sl]
        x = solve_band_stacked(
            prep.bK,
            prep.bM,
            b_c,
            np.broadcast_to(rhs, (ws.size,) + rhs.shape),
            ws,
            2 * d - 1,
            2 * d - 1,
            (model.K, model.M),
        )  # (n_w, (n − 2)·d, n_inner·d)
        out[cols, 1:-1, :, sl] = np.transpose(x.reshape(ws.size, n - 2, d, cols.size), (3, 1, 2, 0))
    return out


class NodeInfluence:
    """:func:`node_influence` of one line and drag at ``nodes``, kept for the
    frequencies asked (an ``influence`` of
    :func:`~stochcable.dynamics.residuals.residual_lines.load_transfer`)."""

    def __init__(self, system: Any, damping: Any, nodes: np.ndarray) -> None:
        self.system = system
        self.damping = damping
        self.nodes = np.asarray(nodes, dtype=int)
        self._kept: list[tuple[np.ndarray, np.ndarray]] = []

    def on(self, w: np.ndarray) -> np.ndarray:
        """The influence on ``w``, shape (n_nodes_out·d, n_nodes, d, n_w). [m/N]"""
        w = np.asarray(w, dtype=float)
        for om, g in self._kept if w.size else ():
            at = np.clip(np.searchsorted(om, w), 0, om.size - 1)
            near = np.where(np.abs(om[at - 1] - w) < np.abs(om[at] - w), at - 1, at)
            if np.allclose(om[near], w, rtol=1e-12, atol=0.0):
                return g[..., near]
        g = node_influence(self.system, self.damping, w, self.nodes)
        self._kept.append((w.copy(), g))
        return g


@dataclass(frozen=True)
class MotionResidual:
    """The residuals' variance of every node's displacement.

    Attributes
    ----------
    computed : bool
        False where a residual applied at the ends is not covered (``reason``): the
        motions are the linear model's.
    reason : str
        Why not computed ("" when computed).
    lines : dict of str to tuple of (ndarray, ndarray)
        By kind, parts: the frequencies [rad/s] (n,) and each node's variance at them
        along x, y, z (n_nodes, 3, n) [m²] (the drag residual's linear misfit on the
        analysis grid, which may be negative, a part of its own).
    variance : ndarray, shape (n_nodes, 3)
        The variance the residuals add to each node's displacement. [m²]
    stations : ndarray of int
        The nodes they were evaluated at (:func:`motion_stations`).
    """

    computed: bool
    reason: str = ""
    lines: dict[str, tuple[tuple[np.ndarray, np.ndarray], ...]] = field(default_factory=dict)
    variance: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    stations: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))

    def std(self, linear_std: np.ndarray) -> np.ndarray:
        """σ of the node displacements with the residuals from the linear σ (n_nodes,
        3) (a negative total clipped at 0). [m]"""
        lin = np.asarray(linear_std, dtype=float)
        if not self.computed:
            return lin
        return np.sqrt(np.maximum(lin**2 + self.variance, 0.0))


def motion_weights(s: np.ndarray, at: np.ndarray, linear_var: np.ndarray) -> np.ndarray:
    """The nodes' residual variance from the stations' (node-major rows and columns,
    shape (n·d, n_st·d)): each component's ratio of residual to linear variance
    interpolated linearly in the arc length ``s`` (n,) between the station nodes
    ``at`` (and held beyond the outermost), times the node's own linear variance
    ``linear_var`` (n, d) — the motion's shape along the line is the linear
    response's (a grounded or held node stays at rest, where the variance itself
    interpolated would move it).  Only the stations in motion lend their ratio (a
    linear σ at least 1 % of the line's largest: a held end, a grounded node or a
    component the line hardly moves in would lend the quotient of two small
    numbers). [-]"""
    n, d = linear_var.shape
    lv_st = linear_var[at]  # (n_st, d)
    live = lv_st > 1e-4 * np.max(linear_var, initial=0.0)
    out = np.zeros((n, d, at.size, d))
    for c in range(d):
        use = np.flatnonzero(live[:, c])
        if use.size:
            w = station_weights(s, at[use]) / lv_st[use, c][None]  # (n, n_use)
            out[:, c, use, c] = w * linear_var[:, c, None]
    return out.reshape(n * d, at.size * d)


def motion_residual(
    system: Any,
    damping: Any,
    applied: Mapping[str, Any],
    taps: Mapping[str, Any],
    motion: Callable[[], np.ndarray],
    spectra: np.ndarray,
    linear_std: np.ndarray,
    max_stations: int = MAX_STATIONS,
    influence_of: Callable[[np.ndarray], Any] | None = None,
) -> MotionResidual:
    """The node motions' residual variance of the ``applied`` records (by kind) from
    what their ``taps`` (:func:`~stochcable.dynamics.residuals.along_line.residual_tap`)
    collected (module notes).

    ``motion()``: the line's linear node motion transfer (n_ch, n_nodes, 3, n_w) on
    x, y, z (the misfit's cross term); ``spectra`` (n_ch, n_w) its inputs' spectra;
    ``linear_std`` (n_nodes, 3) its linear σ (:func:`motion_weights`).
    ``influence_of``: the stations' influence from their node indices (default
    :class:`NodeInfluence`, ends held; a line on free bodies:
    :func:`~stochcable.dynamics.residuals.along_line_bodies.node_station_influence`)."""
    model = system.model
    d, comps = model.dim, list(model.components)
    if not applied:
        return MotionResidual(False, "no residual applied")
    at = motion_stations(model, max_stations)
    weights = motion_weights(model.mesh.s0, at, np.asarray(linear_std)[:, comps] ** 2)
    influence = NodeInfluence(system, damping, at) if influence_of is None else influence_of(at)
    linear = None

    def station_motion() -> np.ndarray:
        u = motion()[:, at][:, :, comps]  # (n_ch, n_st, d, n_w)
        return u.reshape(u.shape[0], at.size * d, u.shape[3])

    lines: dict[str, tuple[tuple[np.ndarray, np.ndarray], ...]] = {}
    total = np.zeros((model.n_nodes, 3))
    for kind, rec in applied.items():
        tap = taps.get(kind)
        if getattr(tap, "vectors", None):  # a 3-D line's drag
            parts = vector_parts(
                system, damping, tap, influence, weights, top_line(rec), spectra, station_motion
            )
        else:
            caps = [] if tap is None or tap.unmatched or kind not in CELL_BENDS else tap.captures
            if not caps:
                if all(not np.any(np.asarray(v)) for _, part in rec.lines for v in part.values()):
                    continue
                return MotionResidual(
                    False,
                    f"the {kind.replace('_', ' ')} of this line is not covered in the node "
                    "motions: its loads were not captured; the motions are linear",
                )
            w_lines = np.asarray(caps[0].w, dtype=float)
            v = element_lines(system, damping, kind, caps, influence, False, top_line(rec))
            parts = ((w_lines, weights @ v),)
            for mis in tap.misfits:
                if linear is None:
                    linear = station_motion()
                dv = misfit_lines(system, damping, mis, w_lines, influence, linear, spectra)
                parts += ((mis[2], weights @ dv),)
        full = []
        for om, v in parts:  # (n·d, n) → (n_nodes, 3, n) on x, y, z
            out = np.zeros((model.n_nodes, 3, v.shape[1]))
            out[:, comps] = v.reshape(model.n_nodes, d, v.shape[1])
            full.append((om, out))
            total += out.sum(axis=2)
        lines[kind] = tuple(full)
    return MotionResidual(True, "", lines, total, at)
