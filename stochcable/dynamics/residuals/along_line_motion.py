"""The residuals of the linear model in the node motions: the displacement variance the
residual loads add along the line, from the loads and load cross-spectra the kinds
form for the end tensions (as :mod:`.along_line` does for the element tensions).

A node's displacement component u_n,c = e_n,cᵀ u is another linear output of the
residual loads: with the ends held, u_f = A⁻¹F_f and u_n,c = (A⁻ᵀe_n,c)ᵀF_f (the
adjoint: the d components of every station node, :func:`node_influence`; on a banded
line contracted with the loads as solved, :func:`node_transfer`). The captured loads
pass through these rows unchanged (:func:`~.along_line.element_lines` without the
geometric feedthrough — a stretch term of the tension, not a displacement;
:func:`~.along_line_3d.vector_parts` for a 3-D line's drag); a line on free bodies
reaches its stations through the coupled group
(:class:`~.along_line_bodies.NodeCoupledInfluence`: its ends move with the bodies). The
residual variance adds to the linear variance per node and component (uncorrelated with
the linear response); the stations are up to :data:`~.along_line.MAX_STATIONS` nodes
(both end nodes, the segment junctions, evenly spaced ones), the other nodes' from the
ratio of residual to linear variance interpolated linearly in arc length
(:func:`motion_weights`). A held end node moves with its prescribed motion only: no
residual. As at the ends (:data:`~.corrected.RESIDUAL_VARIANCE_LIMIT`), a node motion
whose residual variance is above twice its linear one stays linear, with a warning
naming the nodes (where one moves at least 1 % of the line's largest): node by node, the
others keep their residuals (the cable-laying line's out-of-plane motion, ×5.7 in σ by
the 3-D drag residual; the two-segment line's node 33 sits at 1.92×).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from stochcable.dynamics.residuals.along_line import (
    ALONG_DTYPE,
    CELL_BENDS,
    MAX_STATIONS,
    bent_cells,
    capture_outputs,
    fill_lines,
    line_subset,
    load_power,
    misfit_lines,
    station_weights,
    top_line,
)
from stochcable.dynamics.residuals.along_line_3d import sparse_transfer, vector_parts
from stochcable.dynamics.residuals.corrected import RESIDUAL_VARIANCE_LIMIT
from stochcable.dynamics.residuals.drag_residual import CELL_BEND, cell_factor
from stochcable.dynamics.residuals.influence import ModalRows, adjoint_rows
from stochcable.errors import PhysicsWarning, warn

__all__ = [
    "MotionResidual",
    "NodeInfluence",
    "motion_lines",
    "motions_in_range",
    "motion_residual",
    "motion_weights",
    "motion_stations",
    "solved_stations",
    "node_influence",
    "node_transfer",
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


def solved_stations(model: Any, max_stations: int = MAX_STATIONS) -> np.ndarray:
    """The :func:`motion_stations` whose rows are solved on a line with held ends: the
    inner ones (a held end node's residual is zero: the chain's 4 of 18 rows)."""
    at = motion_stations(model, max_stations)
    return at[(at > 0) & (at < model.n_nodes - 1)]


def node_rows(model: Any, nodes: np.ndarray) -> np.ndarray:
    """The right-hand sides ((n_nodes − 2)·d, n_nodes_out·d) of the displacements of
    ``nodes`` (node-major, each of the model's d components; zero for an end node)."""
    d, n = model.dim, model.n_nodes
    nodes = np.asarray(nodes, dtype=int)
    rhs = np.zeros(((n - 2) * d, nodes.size * d), dtype=complex)
    inner = np.flatnonzero((nodes >= 1) & (nodes <= n - 2))
    for c in range(d):
        rhs[(nodes[inner] - 1) * d + c, inner * d + c] = 1.0
    return rhs


def node_influence(system: Any, damping: Any, w: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    """The displacements of ``nodes`` (each of the model's d components, node-major:
    row k·d + c) per unit force on each node and component, ends held, the line's
    linear system with ``damping``: shape (n_nodes_out·d, n_nodes, d, n_w); zero rows
    for an end node. [m/N]

    By the adjoint (module notes): :func:`~.band_influence.adjoint_rows` of
    :func:`node_rows` (an end node's rows, zero, not solved)."""
    model = system.model
    rhs = node_rows(model, nodes)
    live = np.flatnonzero(np.any(rhs != 0, axis=0))
    out = np.zeros((rhs.shape[1], model.n_nodes, model.dim, np.size(w)), dtype=complex)
    out[live] = adjoint_rows(system, damping, rhs[:, live], w)
    return out


def _near(om: np.ndarray, w: np.ndarray) -> np.ndarray:
    """The index of each of ``w`` among the kept frequencies ``om`` (sorted; −1 where
    not kept)."""
    if om.size == 0:
        return np.full(w.size, -1)
    at = np.clip(np.searchsorted(om, w), 0, om.size - 1)
    lo = np.clip(at - 1, 0, om.size - 1)
    best = np.where(np.abs(om[lo] - w) < np.abs(om[at] - w), lo, at)
    return np.where(np.abs(om[best] - w) <= 1e-12 * np.abs(w), best, -1)


class NodeInfluence:
    """:func:`node_influence` of one line and drag at ``nodes``, kept for the frequencies
    asked (an ``influence`` of :func:`~.residual_lines.load_transfer`; a request all of
    whose frequencies one kept grid holds is taken from it)."""

    def __init__(self, system: Any, damping: Any, nodes: np.ndarray) -> None:
        self.system = system
        self.damping = damping
        self.nodes = np.asarray(nodes, dtype=int)
        self._kept: list[tuple[np.ndarray, np.ndarray]] = []

    def on(self, w: np.ndarray) -> np.ndarray:
        """The influence on ``w``, shape (n_nodes_out·d, n_nodes, d, n_w). [m/N]"""
        w = np.asarray(w, dtype=float)
        for om, g in self._kept:
            if om.size == w.size and np.allclose(om, w, rtol=1e-12, atol=0.0):
                return g
            near = _near(om, w)
            if w.size and np.all(near >= 0):
                return g[..., near]
        g = node_influence(self.system, self.damping, w, self.nodes)
        self._kept.append((w.copy(), g))
        return g


def node_transfer(influence: Any, w: np.ndarray, unit: np.ndarray) -> np.ndarray:
    """:func:`sparse_transfer` of ``influence.on(w)`` and the load cases ``unit``, or, where
    it reads a shared banded influence's ``rows`` (line_result's), their product as they
    are solved (:meth:`~.influence.EndInfluence.extra_transfer`). [m/unit]"""
    rows = getattr(influence, "rows", None)
    fused = getattr(getattr(rows, "shared", None), "extra_transfer", None)
    if (h := None if fused is None else fused(w, unit, rows.cols)) is not None:
        return h
    g = influence.on(w)  # (the modal rows: the loads projected on the modes)
    return g.transfer(unit) if isinstance(g, ModalRows) else sparse_transfer(g, unit)


@dataclass(frozen=True)
class MotionResidual:
    """The residuals' variance of every node's displacement.

    Attributes
    ----------
    computed : bool
        False where a residual applied at the ends is not covered (``reason``): the
        motions are the linear model's.
    reason : str
        Why not computed; computed, the warning naming the motions left linear
        (``beyond``; "" when none).
    lines : dict of str to tuple of (ndarray, ndarray)
        By kind, parts: the frequencies [rad/s] (n,) and each node's variance at them
        along x, y, z (n_nodes, 3, n) [m²] (the drag residual's linear misfit on the
        analysis grid, which may be negative, a part of its own).
    variance : ndarray, shape (n_nodes, 3)
        The variance the residuals add to each node's displacement. [m²]
    stations : ndarray of int
        The nodes they were evaluated at (:func:`motion_stations`).
    beyond : ndarray of bool, shape (n_nodes, 3)
        The node motion components left linear: their residual variance above
        :data:`~stochcable.dynamics.residuals.corrected.RESIDUAL_VARIANCE_LIMIT` times
        the linear one (``reason`` names them; zero ``variance`` and ``lines`` there).
    """

    computed: bool
    reason: str = ""
    lines: dict[str, tuple[tuple[np.ndarray, np.ndarray], ...]] = field(default_factory=dict)
    variance: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    stations: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    beyond: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), dtype=bool))

    def std(self, linear_std: np.ndarray) -> np.ndarray:
        """σ of the node displacements with the residuals from the linear σ (n_nodes,
        3) (a negative total clipped at 0). [m]"""
        lin = np.asarray(linear_std, dtype=float)
        if not self.computed:
            return lin
        return np.sqrt(np.maximum(lin**2 + self.variance, 0.0))


def motion_lines(
    system: Any,
    damping: Any,
    kind: str,
    captures: list[Any],
    influence: Any,
    top: int | None,
    stride: int = 1,
    dtype: Any = complex,
) -> np.ndarray:
    """The variance lines (n_out, n_o) of the outputs of ``influence`` driven by one
    kind's pair ``captures`` (as
    :func:`~stochcable.dynamics.residuals.along_line.element_lines` without the
    geometric feedthrough), the loads the kind kept only, contracted sparsely
    (:func:`sparse_transfer`); the lines from ``top`` up left out (zero), formed on
    every ``stride``-th (:func:`~stochcable.dynamics.residuals.along_line.line_stride`),
    contracted in ``dtype``. [m²]"""
    out = None
    for cap in captures:
        n_top = cap.w.size if top is None else min(top, cap.w.size)
        sel = line_subset(n_top, stride)
        w = cap.w[sel]
        unit = cap.unit[:, :, cap.kept]
        if n_top == 0:
            lines = np.zeros((influence.on(cap.w[:1]).shape[0], cap.w.size))
        else:
            full = node_transfer(influence, w, unit)  # (n_out, n_kept, n_sel)
            lines = np.zeros((full.shape[0], cap.w.size))
            part = capture_outputs(cap, full, sel, dtype) * motion_cells(
                system, damping, unit, w, full, CELL_BENDS[kind] * stride**2, influence
            )
            lines[:, :n_top] = fill_lines(part, sel, n_top)
        out = lines if out is None else out + lines
    return out


def motion_cells(
    system: Any,
    damping: Any,
    unit: np.ndarray,
    w: np.ndarray,
    h: np.ndarray,
    bend: float = CELL_BEND,
    influence: Any = None,
) -> np.ndarray:
    """:func:`~stochcable.dynamics.residuals.drag_residual.cell_factor` of the node
    motions ``h`` (n_out, n_load, n_o) per unit load on ``w``, its sub-samples solved
    for one station node only: near a lightly damped mode every output is the
    resonance times its shape (the factor's own premise), so in each component the
    node with the largest power in the bent cells gives every node's factor (at most
    d nodes' rows instead of every station's: the sub-samples' solves were most of
    the motions' cost on the 800-element chain).  A
    line on free bodies (an ``influence`` other than :class:`NodeInfluence`): every
    output's own factor. [-]"""
    if not isinstance(influence, NodeInfluence):
        return cell_factor(system, damping, unit, w, h, bend, influence=influence)
    power = load_power(h)  # (n_out, n_o)
    cells = np.flatnonzero(bent_cells(h, bend, power))
    out = np.ones_like(power)
    if cells.size == 0:
        return out
    d = system.model.dim
    # each component: the station node moving most in it (one solve for them all)
    top = np.argmax(power[:, cells].sum(axis=1).reshape(-1, d), axis=0)  # (d,)
    keep, slot = np.unique(top, return_inverse=True)
    node = NodeInfluence(system, damping, influence.nodes[keep])
    rows = (keep[:, None] * d + np.arange(d)[None]).ravel()
    sub = cell_factor(system, damping, unit, w, h[rows], bend, influence=node, power=power[rows])
    for c in range(d):
        out[c::d, cells] = sub[int(slot[c]) * d + c, cells]
    return out


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
    ends_held: bool = False,
) -> MotionResidual:
    """The node motions' residual variance of the ``applied`` records (by kind) from
    what their ``taps`` (:func:`~stochcable.dynamics.residuals.along_line.residual_tap`)
    collected (module notes).

    ``motion()``: the line's linear node motion transfer (n_ch, n_nodes, 3, n_w) on
    x, y, z (the misfit's cross term); ``spectra`` (n_ch, n_w) its inputs' spectra;
    ``linear_std`` (n_nodes, 3) its linear σ (:func:`motion_weights`).
    ``influence_of``: the stations' influence from their node indices (default
    :class:`NodeInfluence`, ends held; a line on free bodies:
    :func:`~stochcable.dynamics.residuals.along_line_bodies.node_station_influence`);
    ``ends_held``: the line's end nodes are held (a line alone) with an
    ``influence_of``: its rows are asked for the inner stations only
    (:func:`solved_stations`)."""
    model = system.model
    d, comps = model.dim, list(model.components)
    if not applied:
        return MotionResidual(False, "no residual applied")
    at = motion_stations(model, max_stations)
    weights = motion_weights(model.mesh.s0, at, np.asarray(linear_std)[:, comps] ** 2)
    # a held end node's residual is zero: its rows are not solved (its weights kept:
    # near a moving held end the ratio falls to its 0)
    solve = np.ones(at.size, dtype=bool)
    if influence_of is None or ends_held:
        solve = (at > 0) & (at < model.n_nodes - 1)
    weights = weights.reshape(-1, at.size, d)[:, solve].reshape(weights.shape[0], -1)
    at_s = at[solve]
    influence = NodeInfluence(system, damping, at_s) if influence_of is None else influence_of(at_s)
    linear = None

    def station_motion() -> np.ndarray:
        u = motion()[:, at_s][:, :, comps]  # (n_ch, n_solved, d, n_w)
        return u.reshape(u.shape[0], at_s.size * d, u.shape[3])

    lines: dict[str, tuple[tuple[np.ndarray, np.ndarray], ...]] = {}
    total = np.zeros((model.n_nodes, 3))
    for kind, rec in applied.items():
        tap = taps.get(kind)
        if getattr(tap, "vectors", None) and not tap.unmatched:  # a 3-D line's drag
            parts = vector_parts(
                system,
                damping,
                tap,
                influence,
                weights,
                top_line(rec),
                spectra,
                station_motion,
                motion_cells,
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
            # (every line: on the two-segment line's rope every second one moved the
            # node motions' residual by up to 7 % where the ends' moved 0.2 %)
            v = motion_lines(system, damping, kind, caps, influence, top_line(rec), 1, ALONG_DTYPE)
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
    beyond, reason = motions_in_range(system.name, lines, total, linear_std)
    return MotionResidual(True, reason, lines, total, at, beyond)


def motions_in_range(
    name: str,
    lines: dict[str, tuple],
    total: np.ndarray,
    linear_std: np.ndarray,
    known: np.ndarray | None = None,
) -> tuple[np.ndarray, str]:
    """The node motion components (n_nodes, 3) beyond the residuals' range (those of
    ``known`` too), their residual ``total`` and ``lines`` zeroed in place (the caller's
    own arrays), and the warning's text; warned only where a moving component is newly
    beyond (``known``: already said)."""
    beyond, reason = _beyond_range(name, total, linear_std, known)
    total[beyond] = 0.0
    for parts_k in lines.values():
        for _, v in parts_k:
            v[beyond] = 0.0
    return beyond, reason


def _node_list(nodes: np.ndarray) -> str:
    """Node indices as runs: "3, 7–9". [-]"""
    runs = np.split(nodes, np.flatnonzero(np.diff(nodes) != 1) + 1)
    return ", ".join(f"{r[0]}" if r.size == 1 else f"{r[0]}–{r[-1]}" for r in runs)


def _beyond_range(
    name: str, total: np.ndarray, linear_std: np.ndarray, known: np.ndarray | None = None
) -> tuple[np.ndarray, str]:
    """The node motion components (n_nodes, 3) whose residual variance ``total`` is
    above RESIDUAL_VARIANCE_LIMIT times the linear one, and the warning naming them,
    issued where one of them moves at least 1 % of the line's largest σ ("" when none:
    a component nearly at rest falls back silently, its ratio one of two small numbers).

    Node by node: the line's other motions keep their residuals (a whole line falling
    back for one node moved every node's σ by up to 41 % when that node's ratio
    crossed the limit)."""
    lin = np.asarray(linear_std, dtype=float) ** 2
    ratio = np.where(lin > 0.0, total / np.where(lin > 0.0, lin, 1.0), 0.0)
    beyond = ratio > RESIDUAL_VARIANCE_LIMIT
    if known is not None and known.shape != beyond.shape:
        known = None  # (a record without the mask: none known)
    if known is not None:
        beyond = beyond | known
    live = lin > 1e-4 * np.max(lin, initial=0.0)
    if not np.any(beyond & live):
        return beyond, ""
    k, c = np.unravel_index(int(np.argmax(np.where(live, ratio, 0.0))), ratio.shape)
    where = "; ".join(
        f"{'xyz'[j]} at node{'s' if np.count_nonzero(beyond[:, j]) > 1 else ''} "
        f"{_node_list(np.flatnonzero(beyond[:, j]))}"
        for j in range(3)
        if beyond[:, j].any()
    )
    reason = (
        f"line '{name}': the residuals' variance of the node motions is up to "
        f"{ratio[k, c]:.3g} × the linear variance (node {int(k)}'s {'xyz'[c]} motion), "
        f"above the residuals' range {RESIDUAL_VARIANCE_LIMIT:g} (RESIDUAL_VARIANCE_LIMIT) "
        f"({where}): the first-order closed forms are out of their depth there and those "
        "motions are the linear model's, the other nodes' keep the residuals; check with "
        "the nonlinear time-domain reference (stochcable.reference.cable), or make the "
        "line tauter (pretension) or its mesh finer"
    )
    if known is None or np.any(beyond & live & ~known):
        warn(reason, PhysicsWarning, stacklevel=5)
    return beyond, reason
