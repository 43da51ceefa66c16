"""The residuals of the linear model in the element tensions along the line: the
variance lines of every element's dynamic effective tension driven by the residual
loads whose end-tension lines :mod:`.drag_residual` and :mod:`.geometric_residual`
form, from the same load cross-spectra.

Each residual kind forms the cross-spectral lines G_cd(ω_j) of its loads (the drag
residual's panel forces, the geometric forces' element pairs) once and contracts them
with the end tensions per unit load, Var_j = Re Σ_cd conj(H_c) G_cd H_d
(:func:`~stochcable.dynamics.residuals.residual_lines.pair_output_lines`).  The
element tension δT_e = r_e·u
(:func:`stochcable.dynamics.outputs.line_result.element_tension_transfer`) is another
linear output of the same loads: with the ends held, u_f = A⁻¹F_f and
δT_e = (A⁻ᵀr_e)ᵀF_f (the adjoint, as the end influence: one banded solve per
frequency for all elements, whatever the number of loads; a load on an end node goes
to the support and leaves the line's tensions unchanged).  The loads and G are read
as the kinds form them (:data:`~stochcable.dynamics.residuals.residual_lines.RESIDUAL_TAP`,
:func:`residual_tap`): no second pass of the convolutions.  The resonant cells are
integrated as the kinds' (:func:`~stochcable.dynamics.residuals.drag_residual.cell_factor`,
their bend thresholds) with the element tensions' own transfer functions.

The element tensions' residual variance adds to their linear variance as the end
tensions' does (:mod:`.corrected`; uncorrelated with the linear response).  With the
two end rows in place of the elements the same steps give the kinds' end lines to
round-off (tests/dynamics/test_along_line.py).

Scope: the kinds' uniform lines; the drag residual's linear misfit of split elements
(:mod:`.drag_segments`, a variance change on the analysis grid: on the chain 0.04 %
of the drag residual's variance at the ends) is left out along the line; lines on
free bodies (coupled influence) and 3-D lines' drag residual (its vector form does not
pass through the pair lines) are not covered: their element tensions stay linear and
the record says why.  The node motions stay linear (their residual is not formed).
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from stochcable.dynamics.loads.freqblocks import frequency_slices
from stochcable.dynamics.model.blocks import free_band, line_prep
from stochcable.dynamics.model.lift import lift_band, lift_pattern
from stochcable.dynamics.model.solvers import solve_band_stacked
from stochcable.dynamics.model.transport import gyro_band
from stochcable.dynamics.residuals.drag_residual import CELL_BEND, cell_factor
from stochcable.dynamics.residuals.geometric_residual import LINE_STRIDE
from stochcable.dynamics.residuals.residual_lines import (
    RESIDUAL_TAP,
    load_transfer,
    pair_output_lines,
)
from stochcable.dynamics.solve.line_loads import drag_blocks
from stochcable.line.fem import SLACK_EA_RATIO

__all__ = [
    "AlongLineResidual",
    "ElementInfluence",
    "ResidualTap",
    "along_line_residual",
    "element_influence",
    "element_lines",
    "residual_tap",
    "station_weights",
    "stations",
]

#: The bend threshold of the resonant cells of each covered kind (as the kind's own
#: :func:`~stochcable.dynamics.residuals.drag_residual.cell_factor` call). [-]
#: Elements the residuals are evaluated at (:func:`stations`; the others interpolated
#: linearly in arc length between them): its cost is one banded solve per line per
#: station (every element: chain +75 ms on a 26 ms linear analysis). [-]
MAX_STATIONS = 9
CELL_BENDS = {
    "drag_residual": CELL_BEND,
    "geometric_residual": CELL_BEND * LINE_STRIDE**2,
}


@dataclass
class Capture:
    """One contraction of a kind's load cross-spectra: the lines ``w`` [rad/s], every
    load of the kind's :func:`load_transfer` call ``unit`` (n_nodes, d, n_all), the
    loads ``kept`` (indices into it) whose cross-spectral lines ``g`` (n, n, n_o) are."""

    w: np.ndarray
    unit: np.ndarray
    kept: np.ndarray
    g: np.ndarray


class ResidualTap:
    """Collects the loads and load cross-spectra of the residual kinds computed while
    it is active (:func:`residual_tap`)."""

    def __init__(self) -> None:
        self._loads: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
        self.captures: list[Capture] = []
        self.unmatched = 0

    def loads(self, unit: np.ndarray, w: np.ndarray, h: np.ndarray) -> None:
        """A :func:`load_transfer` call: its loads, frequencies and end transfer."""
        self._loads.append((unit, np.asarray(w, dtype=float), h))

    def lines(self, g: np.ndarray, transfer: np.ndarray) -> None:
        """A :func:`pair_output_lines` call: G and the loads' end transfer, matched
        column by column to the load transfer they were taken from."""
        n_o = transfer.shape[2]
        cols = [np.ascontiguousarray(transfer[:, c]).tobytes() for c in range(transfer.shape[1])]
        for unit, w, h in reversed(self._loads):
            if h.shape[2] != n_o or h.shape[0] != transfer.shape[0]:
                continue
            index = {np.ascontiguousarray(h[:, j]).tobytes(): j for j in range(h.shape[1])}
            if all(c in index for c in cols):
                kept = np.array([index[c] for c in cols], dtype=int)
                self.captures.append(Capture(w, unit, kept, g))
                return
        self.unmatched += 1


@contextmanager
def residual_tap() -> Iterator[ResidualTap]:
    """A :class:`ResidualTap` active in the block (the kinds computed in it report to it)."""
    tap = ResidualTap()
    token = RESIDUAL_TAP.set(tap)
    try:
        yield tap
    finally:
        RESIDUAL_TAP.reset(token)


def element_rows(model: Any) -> np.ndarray:
    """The element tension rows (n_el, 2, d): δT_e = rows[e, 0]·u_e + rows[e, 1]·u_{e+1}
    (as :func:`stochcable.dynamics.outputs.line_result.element_tension_transfer`). [N/m]"""
    rows = model.tension_rows
    if rows is None:
        ea = np.where(model.slack, SLACK_EA_RATIO * model.mesh.ea, model.mesh.ea)
        t = model.tangents * (ea / model.l0)[:, None]
        rows = np.stack([-t, t], axis=1)
    return np.asarray(rows, dtype=float)


def element_influence(
    system: Any, damping: Any, w: np.ndarray, elements: np.ndarray | None = None
) -> np.ndarray:
    """The tensions of ``elements`` (indices; default all) per unit force on each node
    and component, ends prescribed, the line's linear system with ``damping``: shape
    (n_out, n_nodes, d, n_w). [N/N]

    By the adjoint (module notes): x_e = A⁻ᵀ r_e on the free nodes, one banded solve
    per frequency with the n_el right-hand sides; zero on the end nodes.  A travelling
    line's Aᵀ has C − G, a line with a steady lift C_Lᵀ (as
    :func:`~stochcable.dynamics.residuals.residual_lines.end_influence`)."""
    w = np.asarray(w, dtype=float)
    model = system.model
    prep = line_prep(system)
    d, n = model.dim, model.n_nodes
    cd = drag_blocks(system, damping)
    b_c = prep.bS + free_band(cd)
    if system.gyro is not None:
        b_c = b_c - gyro_band(system.gyro, d)
    if system.lift is not None:
        b_c = b_c + lift_band(np.transpose(system.lift, (0, 2, 1)), lift_pattern(model))
    rows = element_rows(model)
    idx = np.arange(rows.shape[0]) if elements is None else np.asarray(elements, dtype=int)
    rows = rows[idx]
    n_el = idx.size
    rhs = np.zeros(((n - 2) * d, n_el), dtype=complex)
    for k in (0, 1):  # node e + k of element e, free nodes 1 … n − 2
        node = idx + k
        free = (node >= 1) & (node <= n - 2)
        for c in range(d):
            rhs[(node[free] - 1) * d + c, np.flatnonzero(free)] = rows[free, k, c]
    out = np.zeros((n_el, n, d, w.size), dtype=complex)
    for sl in frequency_slices(w.size, 16 * n * d * max(n_el, 1)):
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
        )  # (n_w, (n − 2)·d, n_el)
        out[:, 1:-1, :, sl] = np.transpose(x.reshape(ws.size, n - 2, d, n_el), (3, 1, 2, 0))
    return out


class ElementInfluence:
    """:func:`element_influence` of one line and drag, kept for the frequencies asked
    (the geometric residual's lines are among the drag residual's): the ``influence``
    of :func:`~stochcable.dynamics.residuals.residual_lines.load_transfer`."""

    def __init__(self, system: Any, damping: Any, elements: np.ndarray | None = None) -> None:
        self.system = system
        self.damping = damping
        self.elements = elements
        self._kept: list[tuple[np.ndarray, np.ndarray]] = []

    def on(self, w: np.ndarray) -> np.ndarray:
        """The influence on ``w``, shape (n_out, n_nodes, d, n_w). [N/N]"""
        w = np.asarray(w, dtype=float)
        for om, g in self._kept if w.size else ():
            at = np.clip(np.searchsorted(om, w), 0, om.size - 1)
            near = np.where(np.abs(om[at - 1] - w) < np.abs(om[at] - w), at - 1, at)
            if np.allclose(om[near], w, rtol=1e-12, atol=0.0):
                return g[..., near]
        g = element_influence(self.system, self.damping, w, self.elements)
        self._kept.append((w.copy(), g))
        return g


def element_lines(
    system: Any,
    damping: Any,
    kind: str,
    captures: list[Capture],
    influence: Any,
    feedthrough: bool = True,
) -> np.ndarray | None:
    """The variance lines (n_out, n_o) of the outputs of ``influence`` (n_out rows)
    driven by the loads of one kind's ``captures`` (module notes), on the captures'
    lines (the kinds form one each); None where there is none.  ``feedthrough``: the
    outputs are the element tensions, and the geometric forces' own second-order
    stretch enters each element's tension directly (:func:`geometric_feedthrough`)."""
    out = None
    for cap in captures:
        full = load_transfer(system, damping, cap.unit, cap.w, influence)  # (n_out, n_all, n_o)
        if feedthrough and kind == "geometric_residual":
            own = geometric_feedthrough(system, cap.unit.shape[2])
            sel = getattr(influence, "elements", None)
            full = full + own[slice(None) if sel is None else sel, :, None]
        lines = pair_output_lines(cap.g, full[:, cap.kept])
        lines = lines * cell_factor(
            system, damping, cap.unit, cap.w, full, CELL_BENDS[kind], influence=influence
        )
        out = lines if out is None else out + lines
    return out


def geometric_feedthrough(system: Any, n_all: int) -> np.ndarray:
    """Each element tension per unit of the geometric residual's components (its
    :func:`load_transfer` columns, component-major: ½|b_e|² first), shape (n_el, n_all).
    [N/m]

    To second order the stretch of element e is a + |b|²/(2l) (|ℓ| = |l·t + Δu|, Δu =
    a·t + b): the linear model's tension (EA/L₀)·a (the rows of
    :func:`element_rows`) misses (EA/L₀)·½|b|²/l, the element's own share of the
    quadratic force κ·½|b|² it applies as a node pair (the pair's response through
    the line, r_e·A⁻¹F, is the rest).  The products a·b_k do not stretch it."""
    rows = element_rows(system.model)
    n_el = rows.shape[0]
    length = np.linalg.norm(np.diff(np.asarray(system.positions, dtype=float), axis=0), axis=1)
    out = np.zeros((n_el, n_all))
    el = np.arange(n_el)
    out[el, el] = -np.linalg.norm(rows[:, 1], axis=1) / length
    return out


def stations(model: Any, max_stations: int = MAX_STATIONS) -> np.ndarray:
    """The elements (indices, increasing) the residuals are evaluated at: every
    element of a line of at most ``max_stations``, else both end elements, both
    elements of every segment junction and ``max_stations`` evenly spaced ones."""
    n_el = model.n_elements
    if n_el <= max_stations:
        return np.arange(n_el)
    seg = np.asarray(model.mesh.segment)
    junction = np.flatnonzero(np.diff(seg) != 0)
    even = np.rint(np.linspace(0, n_el - 1, max_stations)).astype(int)
    return np.unique(np.concatenate([even, junction, junction + 1]))


def station_weights(s: np.ndarray, at: np.ndarray) -> np.ndarray:
    """Linear interpolation in the arc length ``s`` (n_el,) of the elements from the
    station elements ``at`` (increasing, both end elements among them): shape (n_el,
    n_st), rows summing to 1."""
    s = np.asarray(s, dtype=float)
    xs = s[at]
    k = np.clip(np.searchsorted(xs, s, side="right") - 1, 0, max(at.size - 2, 0))
    out = np.zeros((s.size, at.size))
    if at.size == 1:
        out[:, 0] = 1.0
        return out
    t = np.clip((s - xs[k]) / (xs[k + 1] - xs[k]), 0.0, 1.0)
    rows = np.arange(s.size)
    out[rows, k] = 1.0 - t
    out[rows, k + 1] = t
    return out


@dataclass(frozen=True)
class AlongLineResidual:
    """The residuals' variance of every element's dynamic effective tension.

    Attributes
    ----------
    computed : bool
        False where a residual applied at the ends is not covered along the line
        (``reason`` says why): the element tensions are the linear model's.
    reason : str
        Why not computed ("" when computed).
    lines : dict of str to (ndarray, ndarray)
        By kind: the lines ω_j [rad/s] (n_o,) and each element's variance at them
        (n_el, n_o) [N²].
    variance : ndarray, shape (n_el,)
        The variance the residuals add to each element tension (their lines' sum). [N²]
    stations : ndarray of int
        The elements they were evaluated at (:func:`stations`); the others'
        interpolated linearly in arc length.
    """

    computed: bool
    reason: str = ""
    lines: dict[str, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)
    variance: np.ndarray = field(default_factory=lambda: np.zeros(0))
    stations: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))

    def std(self, linear_std: np.ndarray) -> np.ndarray:
        """σ of the element tensions with the residuals, from the linear σ (n_el,)
        (a negative total clipped at 0, as the ends'). [N]"""
        lin = np.asarray(linear_std, dtype=float)
        if not self.computed:
            return lin
        return np.sqrt(np.maximum(lin**2 + self.variance, 0.0))


def along_line_residual(
    system: Any,
    damping: Any,
    applied: Mapping[str, Any],
    taps: Mapping[str, ResidualTap],
    max_stations: int = MAX_STATIONS,
) -> AlongLineResidual:
    """The element tensions' residual variance lines of the ``applied`` records (by
    kind, computed and in range) from what their ``taps`` collected (module notes).

    ``max_stations``: :func:`stations`.  A kind without captures adds nothing where its
    record's lines are all zero (no drag, no order ≥ 2), and is not covered otherwise
    (the result not computed)."""
    n_el = system.model.n_elements
    if not applied:
        return AlongLineResidual(False, "no residual applied")
    model = system.model
    at = stations(model, max_stations)
    weights = station_weights(0.5 * (model.mesh.s0[1:] + model.mesh.s0[:-1]), at)
    influence = ElementInfluence(system, damping, at)
    lines: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    total = np.zeros(n_el)
    for kind, rec in applied.items():
        tap = taps.get(kind)
        caps = [] if tap is None else tap.captures
        if kind not in CELL_BENDS or (tap is not None and tap.unmatched):
            caps = []
        if not caps:
            if all(not np.any(np.asarray(v)) for _, part in rec.lines for v in part.values()):
                continue
            return AlongLineResidual(
                False,
                f"the {kind.replace('_', ' ')} of this line is not covered along the line "
                "(3-D drag, or a line on free bodies): the element tensions are linear",
            )
        v = weights @ element_lines(system, damping, kind, caps, influence)
        lines[kind] = (np.asarray(caps[0].w, dtype=float), v)
        total += v.sum(axis=1)
    return AlongLineResidual(True, "", lines, total, at)
