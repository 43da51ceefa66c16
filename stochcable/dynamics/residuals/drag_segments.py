"""Where the drag residual (:mod:`stochcable.dynamics.residuals.drag_residual`) is evaluated along
a line: elements split where the wave kinematics vary along them, grouped into panels.

The drag is a pointwise load, c|v(ξ)|v(ξ) along each element, while the linear model
takes one drag coefficient B per element (from the element mean of the pointwise
variance, Tuah 1982, eq. 5.2.2) and the residual a Hermite expansion of one velocity per
panel.  Where the kinematics decay or turn along an element (an element near the
surface: e^{kz} over its depth span, e^{−ikχ} over its horizontal span) both lump what
the time domain resolves: the panel mean velocity and a residual load split evenly
between the element's nodes miss that the load concentrates toward its upper node
(on the inclined guy the top element's load goes mostly into its fixed fairlead node,
and the first free node is what excites the line's lightly damped resonance), and a
constant B misplaces the linear drag load.  Such elements are split here into
sub-segments (:func:`segments`) evaluated one by one (never grouped into panels), each
loading its element's nodes with the shape functions at its midpoint; the variation of
the velocity variance along the element (its wet part's end values,
:attr:`stochcable.dynamics.element_kinematics.ElementKinematics.end_square`) sets how
many.  The fluid velocity of a sub-segment is integrated exactly over it
(:func:`~stochcable.dynamics.element_kinematics.element_wave_velocity` on the
subdivided static shape).  Whole elements are grouped into panels (the cost of the
residual grows with their square) in fixed tiles of the mesh, cut where the variance
is not nearly uniform over them (:func:`panel_groups`): on a fine mesh, groups of
elements near the surface would bring the even split back (the guy on 160 elements in
groups of three: +38 % again).  Neither steps with the sea: a load-case set interpolates
the residual (docs/benchmarks/cases.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from stochcable.dynamics.loads.element_kinematics import element_mean_velocity
from stochcable.dynamics.model.blocks import real_gemm, trapezoid_weights

__all__ = [
    "MAX_SUB",
    "SUB_RATIO",
    "WEIGHT_FLOOR",
    "Segments",
    "panel_groups",
    "panel_loads",
    "panel_mean",
    "panel_share",
    "segment_velocity",
    "segments",
]

#: Largest ratio of the velocity variance between the ends of a sub-segment: an element
#: whose end variances differ more is split into ⌈ln q / ln SUB_RATIO⌉ parts (the
#: inclined guy's corrected fairlead σ is within 0.2 % of that with 1.05, 186 panels;
#: 3 splits its top element alone and reads 3 % high). [-]
SUB_RATIO = 1.5
#: Most sub-segments of one element. [-]
MAX_SUB = 16
#: Elements whose drag scale c·l₀·σ² is below this fraction of the line's largest are
#: not split (their residual is negligible however it is distributed). [-]
WEIGHT_FLOOR = 1e-3


@dataclass(frozen=True, eq=False)
class Segments:
    """Consecutive pieces of a line's elements.

    Attributes
    ----------
    element : ndarray of int, shape (n_s,)
        The element each piece belongs to.
    lo, hi : ndarray, shape (n_s,)
        Its range of ξ = s/l on the element. [-]
    length : ndarray, shape (n_s,)
        Its unstretched length. [m]
    fine : ndarray of bool, shape (n_s,)
        Part of a split element (evaluated alone, never grouped into a panel).
    ends : ndarray, shape (n_s, 2), optional
        Wave-velocity variance at the ends of its element's wet part, where it matters
        for the grouping (drag scale above :data:`WEIGHT_FLOOR` of the line's largest;
        NaN elsewhere and without wave kinematics). [m²/s²]
    """

    element: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    length: np.ndarray
    fine: np.ndarray
    ends: np.ndarray | None = None

    @property
    def xi(self) -> np.ndarray:
        """Midpoint ξ of every piece. [-]"""
        return 0.5 * (self.lo + self.hi)

    @property
    def size(self) -> int:
        """Number of pieces."""
        return int(self.element.size)


def _kinematic_channels(channels: Any) -> list[Any]:
    """The sea channels that carry a heading and element kinematics."""
    return [
        ch
        for ch in channels
        if ch.kind == "sea"
        and ch.heading is not None
        and (ch.element_end_square is not None or ch.element_ends is not None)
    ]


def segments(system: Any, channels: Any, drag_scale: np.ndarray, max_panels: int) -> Segments:
    """Split the elements whose velocity variance varies along them (module notes).

    Parameters
    ----------
    system : LineSystem
        The line.
    channels : tuple of Channel
        Its inputs on the analysis grid.
    drag_scale : ndarray, shape (n_el,)
        c per unit length of each element (normal plus axial, ½ρC_dD). [N·s²/m³]
    max_panels : int
        The panel budget: split elements take at most half of it (:func:`_capped`).

    Returns
    -------
    Segments
    """
    mesh = system.model.mesh
    n_el = system.model.n_elements
    want = np.ones(n_el)
    kin = _kinematic_channels(channels)
    ends_el = np.full((n_el, 2), np.nan)
    high_first = np.ones(n_el, dtype=bool)
    if kin:
        ends = np.zeros((n_el, 2))
        for ch in kin:
            q = trapezoid_weights(np.asarray(ch.omega, dtype=float)) * ch.spectrum
            if ch.element_end_square is not None:
                ends += np.einsum("w,wea->ea", q, ch.element_end_square)
            else:  # (the sea's, formed block by block)
                ends += ch.element_ends.weighted(q)
        hi, lo = ends.max(axis=1), ends.min(axis=1)
        weight = drag_scale * mesh.l0 * hi
        live = (hi > 0) & (weight >= WEIGHT_FLOOR * weight.max(initial=0.0))
        with np.errstate(divide="ignore"):
            ratio = np.where(lo > 0, hi / np.where(lo > 0, lo, 1.0), np.inf)
        want = np.log(np.minimum(ratio, 1e300)) / math.log(SUB_RATIO)
        want = np.where(live, np.clip(want, 1.0, MAX_SUB), 1.0)
        ends_el[live] = ends[live]
        high_first = ends[:, 0] >= ends[:, 1]
        want = _capped(want, weight, max_panels // 2)
    return _pieces(mesh.l0, want, high_first, ends_el)


#: Pieces that move continuously with the sea (:func:`_pieces`); False: ⌈want⌉ equal
#: ones, as before (the chain's fairlead drag residual variance −3.6e-4). [-]
CONTINUOUS_PIECES = True
#: Shortest piece kept, as a fraction of its element (a shorter rest joins its neighbour). [-]
MIN_PIECE = 1e-6


def _capped(want: np.ndarray, weight: np.ndarray, budget: int) -> np.ndarray:
    """The wants capped at the largest whole number of pieces whose ⌈want⌉ fit in
    ``budget``; at most the ``budget // 2`` heaviest split.  (A real cap, Σ min(want,
    c) = budget, is continuous but passes the budget: the chain's panels 34 → 37.)"""
    split = want > 1.0
    if np.ceil(want[split]).sum() <= budget:
        return want
    if 2 * int(split.sum()) > budget:
        keep = np.flatnonzero(split)[np.argsort(-weight[split], kind="stable")[: budget // 2]]
        want = np.where(np.isin(np.arange(want.size), keep), want, 1.0)
        split = want > 1.0
    fits = [n for n in range(2, MAX_SUB + 1) if np.ceil(np.minimum(want[split], n)).sum() <= budget]
    return np.where(split, np.minimum(want, max(fits, default=2)), want)


def _pieces(l0: np.ndarray, want: np.ndarray, high_first: np.ndarray, ends_el: np.ndarray):
    """The pieces of every element: ⌈want⌉ of them, all but the last 1/want of the
    element long from its high-variance end, the last the rest (so that they move
    continuously with ``want``: a new piece appears at zero length)."""
    w = np.where(want > 1.0, want, 1.0)
    n = np.ceil(w).astype(int)
    step = w if CONTINUOUS_PIECES else n.astype(float)
    n = np.where(1.0 - (n - 1) / step < MIN_PIECE, n - 1, n)  # (too short a rest joins)
    element = np.repeat(np.arange(w.size), n)
    j = np.arange(element.size) - np.repeat(np.cumsum(n) - n, n)  # (along ξ)
    m, st, first = n[element], step[element], high_first[element]
    k = np.where(first, j, m - 1 - j)  # (from the high-variance end)
    a, b = k / st, np.where(k == m - 1, 1.0, (k + 1) / st)
    lo, hi = np.where(first, a, 1.0 - b), np.where(first, b, 1.0 - a)
    parts = np.bincount(element, minlength=l0.size)
    return Segments(
        element=element,
        lo=lo,
        hi=hi,
        length=l0[element] * (hi - lo),
        fine=parts[element] > 1,
        ends=ends_el[element],
    )


#: Largest ratio of the wave-velocity variance a tile of whole elements may span, as an
#: element (the guy on 160 elements: σ 1.024 × its 40 elements'; 1.043 at 2.25). [-]
GROUP_RATIO = SUB_RATIO


def panel_groups(seg: Segments, max_panels: int) -> list[np.ndarray]:
    """Pieces grouped into panels: every split element's pieces alone, the whole
    elements in fixed tiles of ⌈n_el / max_panels⌉ (the mesh's, not the sea's), cut
    where a split element interrupts one or its wave-velocity variance would span more
    than :data:`GROUP_RATIO`: ``max_panels`` tiles, the pieces (:func:`segments`)."""
    n_el = int(seg.element[-1]) + 1 if seg.size else 0
    size = max(1, math.ceil(n_el / max_panels))
    span = _spans(np.full((seg.size, 2), np.nan) if seg.ends is None else seg.ends)
    out: list[np.ndarray] = []
    cur: list[int] = []
    tile, lo, hi = 0, math.inf, 0.0
    for i in range(seg.size):
        t = ~i if seg.fine[i] else int(seg.element[i]) // size  # (a piece: a tile alone)
        v = span[i] if span[i] is not None else (lo, hi)
        lo_i, hi_i = min(lo, v[0]), max(hi, v[1])
        if cur and (t != tile or hi_i > max(GROUP_RATIO * lo_i, 0.0)):
            out.append(np.array(cur))
            cur = []
            lo_i, hi_i = span[i] if span[i] is not None else (math.inf, 0.0)
        cur.append(i)
        tile, lo, hi = t, lo_i, hi_i
    if cur:
        out.append(np.array(cur))
    return out


def _spans(ends: np.ndarray) -> list[tuple[float, float] | None]:
    """Each piece's (least, largest) finite end variance as floats (None: none finite)."""
    finite = np.isfinite(ends)
    lo = np.where(finite, ends, np.inf).min(axis=1)
    hi = np.where(finite, ends, -np.inf).max(axis=1)
    return [
        (float(a), float(b)) if any_ else None
        for a, b, any_ in zip(lo, hi, finite.any(axis=1), strict=True)
    ]


def segment_velocity(
    system: Any, channels: Any, resp: Any, seg: Segments, directions: dict[str, np.ndarray]
) -> dict[str, np.ndarray]:
    """Relative velocity (fluid − structure) of every piece along each of
    ``directions`` (name → (n_el, 3) unit vectors), per unit input of each channel on
    the analysis grid: name → (n_ch, n_s, n_w).  The structure's at the piece's
    midpoint (linear interpolation), the fluid's its mean over the piece (exact for the
    sea channels with element kinematics, else the element mean or the nodal
    interpolation); each projected on the directions as it is formed (no (n_w, n_s, 3,
    n_ch) array of the velocity vectors). [(m/s)/unit]"""
    model = system.model
    w = np.asarray(resp.omega, dtype=float)
    n_n, d = model.n_nodes, model.dim
    comps = list(model.components)
    e, xi = seg.element, seg.xi
    n_ch, n_s = len(channels), seg.size
    # the structure's displacement at the pieces' midpoints, (n_s, d, n_ch, n_w): the
    # shape functions as one real product on the interleaved complex values; along
    # each direction by real products on them (no complex einsum); each direction's
    # (n_ch, n_s, n_w) a view of its (n_s, n_ch, n_w) array (the layout panel_mean
    # reads)
    u = np.asarray(resp.displacement).reshape(w.size, n_n * d, n_ch)
    u = np.ascontiguousarray(np.transpose(u, (1, 2, 0)), dtype=complex).reshape(n_n, -1)
    interp = np.zeros((n_s, n_n))
    interp[np.arange(n_s), e] = 1.0 - xi
    interp[np.arange(n_s), e + 1] = xi
    u_s = (interp @ u.view(float)).reshape(n_s, d, n_ch, 2 * w.size)
    vecs = {name: np.asarray(vec, dtype=float)[e] for name, vec in directions.items()}
    out = {}
    for name, ve in vecs.items():
        ve_d = ve[:, comps, None, None]  # (n_s, d, 1, 1)
        s = ve_d[:, 0] * u_s[:, 0]
        for k in range(1, d):
            s += ve_d[:, k] * u_s[:, k]
        s = s.view(complex)
        s *= -1j * w  # (relative: fluid − structure, the structure's velocity −iω·u)
        out[name] = np.transpose(s, (1, 0, 2))
    fine = np.flatnonzero(seg.fine)
    run = slice(int(fine[0]), int(fine[-1]) + 1) if fine.size else slice(0, 0)
    sub = None
    for c, ch in enumerate(channels):
        moments = ch.element_velocity
        if moments is None and ch.element_velocity_parts is not None:  # (the sea's parts)
            moments = ch.element_velocity_parts
        if ch.kind == "sea" and ch.heading is not None and moments is not None:
            # the split elements' pieces (a run of them: from the first to the last)
            # integrated on the subdivided shape, the whole elements' from the channel
            if run.stop > run.start:
                if sub is None:
                    sub = _subdivided_points(system, seg)[run.start : run.stop + 1]
                env = system.environment
                # (the pieces' means: the moments' sum, horizontal and vertical parts)
                mean = element_mean_velocity(ch.omega, sub, ch.heading, env.depth, env.g)
                cb, sb = math.cos(ch.heading), math.sin(ch.heading)
                for name, ve in vecs.items():
                    v = ve[run]
                    along = mean[:, 0] * (cb * v[:, 0] + sb * v[:, 1])[:, None]
                    along += mean[:, 1] * v[:, 2][:, None]
                    out[name][c, run] += along
            rest = np.ones(n_s, dtype=bool)
            rest[run] = False
            if rest.any():
                for name, ve in vecs.items():
                    out[name][c, rest] += _element_mean_along(moments, e[rest], ve[rest])
        elif moments is not None:
            for name, ve in vecs.items():
                out[name][c] += _element_mean_along(moments, e, ve)
        elif ch.kind == "sea" and ch.velocity is not None:
            v_n = np.asarray(ch.velocity)  # (n_w, n_nodes, 3)
            v_s = (1.0 - xi)[None, :, None] * v_n[:, e] + xi[None, :, None] * v_n[:, e + 1]
            for name, ve in vecs.items():
                out[name][c] += np.einsum("wsd,sd->sw", v_s, ve)
    return out


def _element_mean_along(moments: Any, el: np.ndarray, vec: np.ndarray) -> np.ndarray:
    """The fluid velocity of the elements ``el`` (their mean: both shape functions'
    moments summed) along ``vec`` (n, 3), shape (n, n_w): from a channel's moments
    (an array (n_w, n_el, 2, 3), or parts with ``full()``); a sea's kept parts (the
    horizontal and vertical velocities, :class:`~stochcable.dynamics.loads.element_parts.
    MomentParts`) projected as they are (no (n_w, n_el, 2, 3) array). [(m/s)/unit]"""
    parts = getattr(moments, "parts", None)
    heading = getattr(moments, "heading", None)
    if parts is not None and heading is not None:  # (n_el, 2, 2, n_w): h and v parts
        cb, sb = math.cos(heading), math.sin(heading)
        h = parts[el, 0, 0] + parts[el, 1, 0]
        v = parts[el, 0, 1] + parts[el, 1, 1]
        return h * (cb * vec[:, 0] + sb * vec[:, 1])[:, None] + v * vec[:, 2][:, None]
    full = moments if isinstance(moments, np.ndarray) else moments.full()
    return np.einsum("wsd,sd->sw", full.sum(axis=2)[:, el], vec)


def _subdivided_points(system: Any, seg: Segments) -> np.ndarray:
    """The static shape with every piece's ends as nodes (piece j joins points j and
    j + 1), on the seabed where a node rests slightly below it (as the channels'). [m]"""
    x = np.asarray(system.positions, dtype=float)
    e = seg.element
    pts = np.empty((seg.size + 1, 3))
    pts[:-1] = x[e] + seg.lo[:, None] * (x[e + 1] - x[e])
    pts[-1] = x[-1]
    pts[:, 2] = np.maximum(pts[:, 2], -float(system.environment.depth))
    return pts


def panel_mean(
    values: np.ndarray, seg: Segments, groups: list[np.ndarray], share: Any = None
) -> np.ndarray:
    """Length-weighted mean of per-piece ``values`` (…, n_s, …) over each panel: the
    piece axis is axis 1 of a 3-D array or axis 0 of a 1-D one (one matrix product;
    ``share``: :func:`panel_share`, where the caller has it)."""
    if share is None:
        share = panel_share(seg, groups)
    if values.ndim == 3 and np.iscomplexobj(values):
        # the real shares times the complex values as one real product on their
        # interleaved view (a complex product upcasts the shares: 4× the work)
        n_a, n_s, n_w = values.shape
        flat = np.ascontiguousarray(np.moveaxis(values, 1, 0), dtype=complex).reshape(n_s, -1)
        out = real_gemm(np.ascontiguousarray(share.T), flat)  # (n_p, n_a·n_w)
        return np.moveaxis(out.reshape(-1, n_a, n_w), 0, 1)
    if values.ndim == 3:
        return np.moveaxis(np.moveaxis(values, 1, 2) @ share, 2, 1)
    return values @ share


def panel_share(seg: Segments, groups: list[np.ndarray]) -> np.ndarray:
    """Each piece's share of its panel's length, shape (n_s, n_panels) (:func:`panel_mean`)."""
    piece = np.concatenate(groups)
    panel = np.repeat(np.arange(len(groups)), [g.size for g in groups])
    share = np.zeros((seg.size, len(groups)))
    share[piece, panel] = seg.length[piece] / np.bincount(panel, weights=seg.length[piece])[panel]
    return share


def panel_loads(
    model: Any, seg: Segments, groups: list[np.ndarray], directions: list[np.ndarray]
) -> np.ndarray:
    """Unit forces spread uniformly over each panel along each of ``directions``
    (n_el, 3): every piece's share (its length over the panel's) on its element's two
    nodes with the shape functions at its midpoint (a whole element: half on each
    node, the consistent load of a uniform force); shape (n_nodes, d,
    n_directions · n_panels), direction-major."""
    comps = list(model.components)
    unit = np.zeros((model.n_nodes, model.dim, len(groups) * len(directions)))
    # every piece: its panel, its share of the panel's length, its element's two nodes
    piece = np.concatenate(groups)
    panel = np.repeat(np.arange(len(groups)), [g.size for g in groups])
    share = seg.length[piece] / np.bincount(panel, weights=seg.length[piece])[panel]
    e, xi = seg.element[piece], seg.xi[piece]
    for k, direction in enumerate(directions):
        col = k * len(groups) + panel
        vec = direction[e][:, comps] * share[:, None]  # (n_pieces, d)
        np.add.at(unit, (e, slice(None), col), (1.0 - xi)[:, None] * vec)
        np.add.at(unit, (e + 1, slice(None), col), xi[:, None] * vec)
    return unit
