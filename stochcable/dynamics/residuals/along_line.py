"""The residuals of the linear model in the element tensions along the line: the
variance lines of every element's dynamic effective tension driven by the residual
loads whose end-tension lines :mod:`.drag_residual` and :mod:`.geometric_residual`
form, from the same load cross-spectra.

Each residual kind forms the cross-spectral lines G_cd(ω_j) of its loads (the drag
residual's panel forces, the geometric forces' element pairs) once and contracts them
with the end tensions per unit load, Var_j = Re Σ_cd conj(H_c) G_cd H_d
(:func:`~stochcable.dynamics.residuals.residual_lines.pair_outputs`).  The
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
of the drag residual's variance at the ends) is left out along the line.  A 3-D
line's drag residual (its vector form does not pass through the pair lines) is
contracted by :mod:`.along_line_3d`; a line on free bodies reaches its stations
through the coupled group (:mod:`.along_line_bodies`, ``influence_of``).  The node
motions' residuals: :mod:`.along_line_motion`.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from stochcable.dynamics.model.blocks import trapezoid_weights
from stochcable.dynamics.residuals.along_line_3d import (
    VectorTapMixin,
    vector_parts,
)
from stochcable.dynamics.residuals.corrected_spectrum import CorrectedSpectrum, corrected_spectrum
from stochcable.dynamics.residuals.drag_residual import CELL_BEND, bent_lines, cell_factor
from stochcable.dynamics.residuals.geometric_residual import LINE_STRIDE
from stochcable.dynamics.residuals.influence import (
    adjoint_rows,
    element_rows,
    geometric_feedthrough,
)
from stochcable.dynamics.residuals.residual_lines import (
    RESIDUAL_TAP,
    EndInfluence,
    along,
    dense_outputs,
    fill_lines,
    line_pair_outputs,
    line_stride,
    line_subset,
    load_transfer,
    shared_rows,
)

__all__ = [
    "AlongLineResidual",
    "ElementInfluence",
    "ResidualTap",
    "along_line_residual",
    "element_influence",
    "element_lines",
    "capture_outputs",
    "fill_lines",
    "line_stride",
    "line_subset",
    "element_rhs",
    "residual_tap",
    "station_weights",
    "end_station_influence",
    "stations",
    "top_line",
]

#: The bend threshold of the resonant cells of each covered kind (as the kind's own
#: :func:`~stochcable.dynamics.residuals.drag_residual.cell_factor` call). [-]
#: Elements the residuals are evaluated at (:func:`stations`; the others interpolated
#: linearly in arc length between them): its cost is one banded solve per line per
#: station (every element: chain +75 ms on a 26 ms linear analysis); 7 give every
#: element's σ within 0.13 % of all elements' on the chain, taut wire, deep wire,
#: two-segment line and inclined guy.  The node motions' stations (the same count:
#: along_line_motion.motion_stations) are coarser: every node's σ within 2.5 % (chain)
#: and 3.0 % (deep wire) of all nodes', the two-segment rope's x motion near the bed
#: 7.2 % of its largest σ (tests/dynamics/test_along_line_motion.py). [-]
MAX_STATIONS = 7
#: The element tensions' residual lines are formed up to the highest line where an end
#: tension's exceeds this fraction of its largest (:func:`top_line`): the superharmonic
#: tail above carries nothing at the ends (chain: lines 120 of 189, taut wire 55). [-]
LINE_FLOOR = 1e-8
#: The element tensions' and node motions' contraction of the kinds' dense pair lines
#: (:func:`capture_outputs`) in single precision: 8.0 -> 4.4 ms on the chain; their σ
#: within 2e-7 of double precision on the benchmark lines (a quadratic form of a
#: positive semi-definite cross-spectrum: no cancellation). [-]
ALONG_DTYPE = np.complex64
CELL_BENDS = {
    "drag_residual": CELL_BEND,
    "geometric_residual": CELL_BEND * LINE_STRIDE**2,
}


@dataclass
class Capture:
    """One contraction of a kind's load cross-spectra: the lines ``w`` [rad/s], every
    load of the kind's :func:`load_transfer` call ``unit`` (n_nodes, d, n_all), the
    loads ``kept`` (indices into it) and the blocks of pairs (g, e, f) of their
    cross-spectral lines ``g`` (n_pairs, n_o) between loads e and f (indices into
    ``kept``), as :func:`pair_outputs` takes them; ``g_all`` (n_o, n·n), where the kind
    gathered them into one dense matrix (:class:`~.residual_lines.PairLines`), G_ef in
    column e·n + f."""

    w: np.ndarray
    unit: np.ndarray
    kept: np.ndarray
    transfer: np.ndarray
    blocks: list[tuple[np.ndarray, np.ndarray, np.ndarray]]
    g_all: np.ndarray | None = None
    g_low: np.ndarray | None = None  # (``g_all`` in :data:`ALONG_DTYPE`, once asked)


class ResidualTap(VectorTapMixin):
    """Collects the loads and load cross-spectra of the residual kinds computed while
    it is active (:func:`residual_tap`; a 3-D line's drag residual:
    :class:`~stochcable.dynamics.residuals.along_line_3d.VectorTapMixin`)."""

    def __init__(self) -> None:
        self._loads: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
        self.captures: list[Capture] = []
        self.unmatched = 0
        self.misfits: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []

    def misfit(self, unit: np.ndarray, load: np.ndarray, w: np.ndarray) -> None:
        """The drag residual's linear misfit: its loads ``unit`` (n_nodes, d, n_load),
        their values per unit input ``load`` (n_ch, n_load, n_w) on the analysis grid
        ``w``."""
        self.misfits.append((unit, load, np.asarray(w, dtype=float)))

    def loads(self, unit: np.ndarray, w: np.ndarray, h: np.ndarray) -> None:
        """A :func:`load_transfer` call: its loads, frequencies and end transfer."""
        self._loads.append((unit, np.asarray(w, dtype=float), h))

    def dense(self, g_all: np.ndarray, transfer: np.ndarray) -> None:
        """A :class:`~.residual_lines.PairLines` contraction's dense lines (n_o, n·n),
        kept with the capture of its blocks (same ``transfer``)."""
        if self.captures and self.captures[-1].transfer is transfer:
            self.captures[-1].g_all = g_all

    def lines(
        self, g: np.ndarray, transfer: np.ndarray, e: np.ndarray, f: np.ndarray, keep: bool = True
    ) -> None:
        """A :func:`pair_outputs` call: a block of pairs' lines G and the loads' end
        transfer, matched column by column to the load transfer they were taken from
        (the blocks of one contraction share its transfer array).  ``keep`` False: the
        block is not kept (its lines come in the contraction's dense G, :meth:`dense`:
        the chain's drag blocks, 3.3 MB, were held twice)."""
        block = (g, np.asarray(e), np.asarray(f))
        if self.captures and self.captures[-1].transfer is transfer:
            if keep:
                self.captures[-1].blocks.append(block)
            return
        for unit, w, h in reversed(self._loads):
            kept = _columns_of(transfer, h)
            if kept is not None:  # (on the leading lines the contraction kept)
                w = w[: transfer.shape[2]]
                self.captures.append(Capture(w, unit, kept, transfer, [block] if keep else []))
                return
        self.unmatched += 1


def _columns_of(transfer: np.ndarray, h: np.ndarray) -> np.ndarray | None:
    """The columns of ``h`` (n_out, n_all, n_h) that ``transfer`` (n_out, n, n_o) holds
    on its leading n_o ≤ n_h lines (a contraction of the lines the outputs need:
    :mod:`.line_top`), in its order (indices), or None where it is not made of them:
    matched by their first line, then every column checked whole at once (column by
    column where the first lines repeat)."""
    if h.shape[0] != transfer.shape[0] or h.shape[2] < transfer.shape[2]:
        return None
    h = h[:, :, : transfer.shape[2]]
    # (the first lines' bytes: rows of contiguous (n_all, n_out) and (n, n_out) arrays)
    first = {r.tobytes(): j for j, r in enumerate(np.ascontiguousarray(h[:, :, 0].T))}
    keys = [r.tobytes() for r in np.ascontiguousarray(transfer[:, :, 0].T)]
    if len(first) == h.shape[1] and all(k in first for k in keys):
        kept = np.array([first[k] for k in keys], dtype=int)
        if np.array_equal(h[:, kept], transfer):
            return kept
    cols = [np.ascontiguousarray(transfer[:, c]).tobytes() for c in range(transfer.shape[1])]
    index = {np.ascontiguousarray(h[:, j]).tobytes(): j for j in range(h.shape[1])}
    if all(c in index for c in cols):
        return np.array([index[c] for c in cols], dtype=int)
    return None


@contextmanager
def residual_tap() -> Iterator[ResidualTap]:
    """A :class:`ResidualTap` active in the block (the kinds computed in it report to it)."""
    tap = ResidualTap()
    token = RESIDUAL_TAP.set(tap)
    try:
        yield tap
    finally:
        RESIDUAL_TAP.reset(token)


def element_rhs(model: Any, elements: np.ndarray | None = None) -> np.ndarray:
    """The adjoint right-hand sides of the tensions of ``elements`` (indices; default
    all): r_e on the free nodes 1 … n − 2, shape ((n_nodes − 2)·d, n_out) (the
    ``extra`` of :func:`~stochcable.dynamics.residuals.residual_lines.end_influence`).
    [N/m]"""
    d, n = model.dim, model.n_nodes
    rows = element_rows(model)
    idx = np.arange(rows.shape[0]) if elements is None else np.asarray(elements, dtype=int)
    rows = rows[idx]
    rhs = np.zeros(((n - 2) * d, idx.size), dtype=complex)
    for k in (0, 1):  # node e + k of element e, free nodes 1 … n − 2
        node = idx + k
        free = (node >= 1) & (node <= n - 2)
        for c in range(d):
            rhs[(node[free] - 1) * d + c, np.flatnonzero(free)] = rows[free, k, c]
    return rhs


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
    return adjoint_rows(system, damping, element_rhs(system.model, elements), w)


def end_station_influence(
    system: Any, damping: Any, max_stations: int = MAX_STATIONS, more: np.ndarray | None = None
) -> EndInfluence:
    """The line's end influence with its :func:`stations`' tension rows solved in the
    same factorization or modal sum (their :func:`element_rhs` first in its ``extra``,
    then ``more`` right-hand sides: the node motions' stations): the kinds' shared
    influence where the element tensions are formed too (:func:`along_line_residual`'s
    ``shared``; one solve per line for the 2 + 7 (+ more) rows, not one per set)."""
    rhs = element_rhs(system.model, stations(system.model, max_stations))
    if more is not None:
        rhs = np.hstack([rhs, more])
    return EndInfluence(system, damping, rhs)


class ElementInfluence:
    """:func:`element_influence` of one line and drag, kept for the frequencies asked
    (the geometric residual's lines are among the drag residual's): the ``influence``
    of :func:`~stochcable.dynamics.residuals.residual_lines.load_transfer`.  With
    ``shared`` (an :func:`end_station_influence` of the same elements) its rows are taken
    from it, solved with the end rows where it does not hold them."""

    def __init__(
        self,
        system: Any,
        damping: Any,
        elements: np.ndarray | None = None,
        shared: EndInfluence | None = None,
    ) -> None:
        self.system = system
        self.damping = damping
        self.elements = elements
        self.shared = shared
        self._kept: list[tuple[np.ndarray, np.ndarray]] = []

    def on(self, w: np.ndarray) -> np.ndarray:
        """The influence on ``w``, shape (n_out, n_nodes, d, n_w). [N/N]"""
        w = np.asarray(w, dtype=float)
        if self.shared is not None:
            return self.shared.extra_on(w)
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
    top_line: int | None = None,
    stride: int = 1,
    dtype: Any = complex,
) -> np.ndarray | None:
    """The variance lines (n_out, n_o) of the outputs of ``influence`` (n_out rows)
    driven by the loads of one kind's ``captures`` (module notes), on the captures'
    lines (the kinds form one each); None where there is none.  ``feedthrough``: the
    outputs are the element tensions, and the geometric forces' own second-order
    stretch enters each element's tension directly (:func:`geometric_feedthrough`).
    ``top_line``: the lines from it up are left out (zero; :func:`top_line`);
    ``stride``: formed on every stride-th line (:func:`line_stride`); ``dtype``: of
    the contraction (:func:`capture_outputs`)."""
    out = None
    for cap in captures:
        top = cap.w.size if top_line is None else min(top_line, cap.w.size)
        sel = line_subset(top, stride)
        w = cap.w[sel]
        full = load_transfer(system, damping, cap.unit, w, influence)  # (n_out, n_all, n_sel)
        if feedthrough and kind == "geometric_residual":
            own = geometric_feedthrough(system, cap.unit.shape[2])
            at = getattr(influence, "elements", None)
            full = full + own[slice(None) if at is None else at, :, None]
        part = capture_outputs(cap, full[:, cap.kept], sel, dtype)
        bend = CELL_BENDS[kind] * stride**2
        part *= cell_factor(
            system, damping, cap.unit, w, full, bend, influence=influence, power=load_power(full)
        )
        lines = np.zeros((full.shape[0], cap.w.size))
        lines[:, :top] = fill_lines(part, sel, top)
        out = lines if out is None else out + lines
    return out


def capture_outputs(
    cap: Capture, transfer: np.ndarray, sel: Any = None, dtype: Any = complex
) -> np.ndarray:
    """The variance lines (n_out, n_o) of outputs with transfer ``transfer`` (n_out,
    n_kept, n_o) per unit load of ``cap``'s kept loads on its first n_o lines, or on
    its lines ``sel`` (:func:`line_subset`): from the kind's dense pair lines where it
    kept them (``cap.g_all``; contracted in ``dtype``, :data:`ALONG_DTYPE` converted
    once per capture), else its blocks (:func:`~.residual_lines.dense_outputs`)."""
    sel = slice(0, transfer.shape[2]) if sel is None else sel
    if cap.g_all is None:
        return dense_outputs(cap.blocks, transfer, sel)
    g = cap.g_all
    if np.dtype(dtype) != g.dtype:
        if cap.g_low is None or cap.g_low.dtype != np.dtype(dtype):
            cap.g_low = g.astype(dtype)
        g = cap.g_low
    return line_pair_outputs(g, transfer, sel, dtype)


def top_line(record: Any, floor: float = LINE_FLOOR) -> int | None:
    """One past the highest of the uniform residual lines of ``record`` (its first
    part) where an end's variance line exceeds ``floor`` times the largest (None
    without lines)."""
    if not record.lines:
        return None
    _, part = record.lines[0]
    v = np.max(np.abs(np.stack([np.asarray(x, dtype=float) for x in part.values()])), axis=0)
    live = np.flatnonzero(v > floor * np.max(v, initial=0.0))
    return int(live[-1]) + 1 if live.size else 0


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


def misfit_lines(
    system: Any,
    damping: Any,
    misfit: tuple[np.ndarray, np.ndarray, np.ndarray],
    w_lines: np.ndarray,
    influence: Any,
    linear: np.ndarray,
    spectra: np.ndarray,
) -> np.ndarray:
    """The variance change (n_out, n_w) of the outputs of ``influence`` (their linear
    transfer ``linear`` (n_ch, n_out, n_w)) by the drag residual's linear ``misfit``
    (:meth:`ResidualTap.misfit`), Σ_c q·S_c(|H_L + H_c|² − |H_L|²) on the analysis grid
    (formed as Σ_c q·S_c Re((2H_L + H_c)·conj(H_c))),
    as :mod:`.drag_residual` forms the ends': the outputs per unit misfit load at the
    residual line ``w_lines`` nearest each frequency, solved at the frequency itself
    where the line's cell bends (:func:`bent_cells`). [N²]"""
    unit, load, w = misfit
    step = float(w_lines[0])
    at = np.clip(np.rint(w / step).astype(int) - 1, 0, w_lines.size - 1)
    # (the lines up to the band's top: among those the influence holds)
    on_lines = load_transfer(system, damping, unit, w_lines[: at.max() + 2], influence)
    h = on_lines.transpose(2, 0, 1)[at]  # (n_w, n_out, n_p): the product's layout
    exact = np.flatnonzero(bent_cells(on_lines)[at])
    if exact.size:
        h[exact] = load_transfer(system, damping, unit, w[exact], influence).transpose(2, 0, 1)
    h_c = (h @ load.transpose(2, 1, 0)).transpose(2, 1, 0)  # (n_ch, n_out, n_w)
    # |H_L + H_c|² − |H_L|² = Re((2H_L + H_c)·conj(H_c)): no difference of two squares
    x = (linear + linear + h_c) * h_c.conj()
    return np.einsum("cw,cow->ow", trapezoid_weights(w) * spectra, x.real)


def bent_cells(h: np.ndarray, bend: float = CELL_BEND, power: Any = None) -> np.ndarray:
    """The lines (n_o,) where the log power of ``h`` (n_out, n_p, n_o), summed over the
    loads, bends by more than ``bend`` between neighbours, and their neighbours (as
    :func:`~stochcable.dynamics.residuals.drag_residual.cell_factor`'s cells)."""
    return bent_lines(h, bend, load_power(h) if power is None else power)


def load_power(h: np.ndarray) -> np.ndarray:
    """Σ_p |h[o, p, j]|² of ``h`` (n_out, n_p, n_o), shape (n_out, n_o): a complex ``h``
    by one real contraction of its interleaved parts (the squares of a complex array's
    moduli by ``np.abs`` cost twice: its hypot). [unit²]"""
    if h.dtype.kind != "c" or not h.flags.c_contiguous:
        return np.sum(np.abs(h) ** 2, axis=1)
    x = h.view(h.real.dtype)  # (n_out, n_p, 2·n_o): Re, Im interleaved
    s = np.einsum("opj,opj->oj", x, x)
    return s[:, 0::2] + s[:, 1::2]


def station_transfer(system: Any, response: Any, at: np.ndarray) -> np.ndarray:
    """The linear tension transfer (n_ch, n_st, n_w) of the elements ``at`` from the
    line's ``response`` (as
    :func:`stochcable.dynamics.outputs.line_result.element_tension_transfer`). [N/unit]"""
    model = system.model
    n_w = np.asarray(response.omega).size
    u = np.asarray(response.displacement).reshape(n_w, model.n_nodes, model.dim, -1)
    rows = element_rows(model)[at]
    return along(u[:, at], rows[:, 0]) + along(u[:, at + 1], rows[:, 1])


@dataclass(frozen=True)
class _Lines:
    """The ``lines`` of one kind at one element, as a record's (for corrected_spectrum)."""

    lines: tuple


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
    lines : dict of str to tuple of (ndarray, ndarray)
        By kind, parts (as :class:`~stochcable.results.records.ResidualRecord`
        ``lines``): the frequencies [rad/s] (n,) and each element's variance at them
        (n_el, n) [N²] — the uniform residual lines, and the drag residual's linear
        misfit on the analysis grid (which may be negative) where there is one.
    variance : ndarray, shape (n_el,)
        The variance the residuals add to each element tension (their lines' sum). [N²]
    stations : ndarray of int
        The elements they were evaluated at (:func:`stations`); the others'
        interpolated linearly in arc length.
    """

    computed: bool
    reason: str = ""
    lines: dict[str, tuple[tuple[np.ndarray, np.ndarray], ...]] = field(default_factory=dict)
    variance: np.ndarray = field(default_factory=lambda: np.zeros(0))
    stations: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))

    def density(self, element: int, omega: np.ndarray, linear: np.ndarray) -> CorrectedSpectrum:
        """The spectral density of ``element``'s tension with the residuals, from its
        linear density ``linear`` on the analysis grid ``omega`` (as the ends',
        :func:`~stochcable.dynamics.residuals.corrected_spectrum.corrected_spectrum`:
        its area is the corrected σ²). [N²·s/rad]"""
        parts = [
            _Lines(tuple((om, {"element": v[element]}) for om, v in kind_parts))
            for kind_parts in self.lines.values()
        ]
        return corrected_spectrum(omega, linear, "element", parts if self.computed else [])

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
    response: Any,
    spectra: np.ndarray,
    max_stations: int = MAX_STATIONS,
    influence_of: Callable[[np.ndarray], Any] | None = None,
    shared: EndInfluence | None = None,
) -> AlongLineResidual:
    """The element tensions' residual variance lines of the ``applied`` records (by
    kind, computed and in range) from what their ``taps`` collected (module notes).

    ``response``, ``spectra`` (n_ch, n_w): the line's linear response and its inputs'
    spectra (the misfit's cross term).  ``max_stations``: :func:`stations`.  A kind
    without captures adds nothing where its record's lines are all zero (no drag, no
    order ≥ 2), and is not covered otherwise (the result not computed).
    ``influence_of``: the stations' influence (an ``on(w)`` object) from their indices
    (default :class:`ElementInfluence`, ends held; a line on free bodies:
    :mod:`.along_line_bodies`).  ``shared``: the kinds' :func:`end_station_influence`
    (the stations' rows taken from it, ends held), if any."""
    n_el = system.model.n_elements
    if not applied:
        return AlongLineResidual(False, "no residual applied")
    model = system.model
    at = stations(model, max_stations)
    weights = station_weights(0.5 * (model.mesh.s0[1:] + model.mesh.s0[:-1]), at)
    rows = None if shared is None else shared_rows(shared, element_rhs(model, at), 0)
    if rows is not None:
        rows.elements = at  # (the geometric feedthrough's rows: element_lines)
    influence = (
        (ElementInfluence(system, damping, at) if rows is None else rows)
        if influence_of is None
        else influence_of(at)
    )
    lines: dict[str, tuple[tuple[np.ndarray, np.ndarray], ...]] = {}
    total = np.zeros(n_el)
    linear = None
    for kind, rec in applied.items():
        tap = taps.get(kind)
        caps = [] if tap is None else tap.captures
        if kind not in CELL_BENDS or (tap is not None and tap.unmatched):
            caps = []
        if getattr(tap, "vectors", None) and not tap.unmatched:  # 3-D drag (.along_line_3d)
            lines[kind] = vector_parts(
                system,
                damping,
                tap,
                influence,
                weights,
                top_line(rec),
                spectra,
                lambda: station_transfer(system, response, at),
            )
            total += sum(v.sum(axis=1) for _, v in lines[kind])
            continue
        if not caps:
            if all(not np.any(np.asarray(v)) for _, part in rec.lines for v in part.values()):
                continue
            why = (
                "its loads were not matched to their load transfer (RESIDUAL_TAP)"
                if tap is not None and tap.unmatched
                else "its loads were not captured (no pair lines)"
            )
            return AlongLineResidual(
                False,
                f"the {kind.replace('_', ' ')} of this line is not covered along the line: "
                f"{why}; the element tensions are linear",
            )
        w_lines = np.asarray(caps[0].w, dtype=float)
        top = top_line(rec)
        stride = line_stride(rec, top)
        v = element_lines(system, damping, kind, caps, influence, True, top, stride, ALONG_DTYPE)
        parts = [(w_lines, weights @ v)]
        for mis in tap.misfits if tap is not None else ():
            if linear is None:
                linear = station_transfer(system, response, at)
            dv = misfit_lines(system, damping, mis, w_lines, influence, linear, spectra)
            parts.append((mis[2], weights @ dv))
        lines[kind] = tuple(parts)
        total += sum(v.sum(axis=1) for _, v in parts)
    return AlongLineResidual(True, "", lines, total, at)
