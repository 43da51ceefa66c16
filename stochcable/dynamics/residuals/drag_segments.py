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
(:func:`~stochcable.dynamics.element_kinematics.element_wave_kinematics` on the
subdivided static shape).  Whole elements are grouped into panels (the cost of the
residual grows with their square) only where the variance is nearly uniform over the
group (:func:`panel_groups`): on a fine mesh, groups of elements near the surface would
bring the even split back (the guy on 160 elements in groups of three: +38 % again).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from stochcable.dynamics.loads.element_kinematics import element_wave_kinematics
from stochcable.dynamics.model.blocks import trapezoid_weights

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
        The panel budget: split elements take at most half of it (the largest
        splits are reduced first).

    Returns
    -------
    Segments
    """
    mesh = system.model.mesh
    n_el = system.model.n_elements
    parts = np.ones(n_el, dtype=int)
    kin = _kinematic_channels(channels)
    ends_el = np.full((n_el, 2), np.nan)
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
        want = np.ceil(np.log(np.minimum(ratio, 1e300)) / math.log(SUB_RATIO))
        parts = np.where(live, np.clip(want, 1, MAX_SUB), 1).astype(int)
        ends_el[live] = ends[live]
        budget = max_panels // 2
        while parts[parts > 1].sum() > budget:
            parts[int(np.argmax(parts))] -= 1
    element = np.repeat(np.arange(n_el), parts)
    k = np.concatenate([np.arange(p) for p in parts])
    m = parts[element].astype(float)
    return Segments(
        element=element,
        lo=k / m,
        hi=(k + 1) / m,
        length=mesh.l0[element] / m,
        fine=parts[element] > 1,
        ends=ends_el[element],
    )


#: Variance ratios a group of whole elements may span, tried in turn (the finest whose
#: panels fit in the budget wins): the reason to split an element holds for a group. [-]
GROUP_RATIOS = (1.05, 1.1, 1.25, 1.5, 2.0, 4.0, 16.0, math.inf)


def panel_groups(seg: Segments, max_panels: int) -> list[np.ndarray]:
    """Pieces grouped into panels: every split element's pieces alone; the runs of
    whole elements between them in consecutive groups, closed where the group's
    wave-velocity variance would vary by more than a ratio of :data:`GROUP_RATIOS` (the
    finest that fits in ``max_panels``) or where it reaches a length (the least that
    fits; ⌈n/max_panels⌉ for a line without wave kinematics, as equal groups)."""
    runs: list[np.ndarray] = []
    start = None
    for i in range(seg.size + 1):
        coarse = i < seg.size and not seg.fine[i]
        if coarse and start is None:
            start = i
        elif not coarse and start is not None:
            runs.append(np.arange(start, i))
            start = None
    n_fine = int(seg.fine.sum())
    n_coarse = seg.size - n_fine
    room = max(1, max_panels - n_fine - (len(runs) - 1 if runs else 0))
    ends = np.full((seg.size, 2), np.nan) if seg.ends is None else seg.ends
    fine = [np.array([i]) for i in np.flatnonzero(seg.fine)]
    budget = max_panels - n_fine
    size = max(1, math.ceil(n_coarse / room))
    for ratio in GROUP_RATIOS:
        if ratio < math.inf and len(_grouped_all(runs, max(n_coarse, 1), ends, ratio)) > budget:
            continue  # the ratio alone needs more panels than there are
        lo, hi = size, max(size, n_coarse)  # the count falls as the length grows: bisect
        while lo < hi:
            mid = (lo + hi) // 2
            if len(_grouped_all(runs, mid, ends, ratio)) <= budget:
                hi = mid
            else:
                lo = mid + 1
        return sorted(fine + _grouped_all(runs, lo, ends, ratio), key=lambda g: int(g[0]))
    raise AssertionError("unreachable: GROUP_RATIOS ends with inf")


def _grouped_all(runs: list[np.ndarray], size: int, ends: np.ndarray, ratio: float) -> list:
    """The groups of every run (:func:`_grouped`)."""
    span = _spans(ends)
    return [g for run in runs for g in _grouped(run, size, span, ratio)]


def _spans(ends: np.ndarray) -> list[tuple[float, float] | None]:
    """Each piece's (least, largest) finite end variance, None where none is finite
    (plain floats: :func:`_grouped` walks them one by one)."""
    finite = np.isfinite(ends)
    lo = np.where(finite, ends, np.inf).min(axis=1)
    hi = np.where(finite, ends, -np.inf).max(axis=1)
    return [
        (float(a), float(b)) if any_ else None
        for a, b, any_ in zip(lo, hi, finite.any(axis=1), strict=True)
    ]


def _grouped(
    run: np.ndarray, size: int, span: list[tuple[float, float] | None], ratio: float
) -> list[np.ndarray]:
    """Consecutive groups of ``run`` of at most ``size``, closed where the variance
    ``span`` of the pieces (:func:`_spans`; None: no matter) would span more than
    ``ratio``."""
    out, cur, lo, hi = [], [], math.inf, 0.0
    for i in run.tolist():
        v = span[i]
        lo_i, hi_i = (min(lo, v[0]), max(hi, v[1])) if v is not None else (lo, hi)
        if cur and (len(cur) == size or (hi_i > 0 and hi_i > ratio * lo_i)):
            out.append(np.array(cur))
            cur, lo, hi = [], math.inf, 0.0
            lo_i, hi_i = v if v is not None else (lo, hi)
        cur.append(i)
        lo, hi = lo_i, hi_i
    if cur:
        out.append(np.array(cur))
    return out


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
    # the structure's displacement at the pieces' midpoints, (n_s, d, n_w, n_ch): the
    # shape functions as one real product on the interleaved complex values
    u = np.transpose(resp.displacement.reshape(w.size, n_n, d, n_ch), (1, 2, 0, 3))
    u = np.ascontiguousarray(u, dtype=complex).reshape(n_n, -1)
    interp = np.zeros((n_s, n_n))
    interp[np.arange(n_s), e] = 1.0 - xi
    interp[np.arange(n_s), e + 1] = xi
    u_s = (interp @ u.view(float)).view(complex).reshape(n_s, d, w.size, n_ch)
    vecs = {name: np.asarray(vec, dtype=float)[e] for name, vec in directions.items()}
    out = {}
    for name, ve in vecs.items():
        s = np.einsum("sdwc,sd->csw", u_s, ve[:, comps])
        s *= -1j * w  # (relative: fluid − structure, the structure's velocity −iω·u)
        out[name] = s
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
                kin = element_wave_kinematics(
                    np.asarray(ch.omega), sub, ch.heading, env.depth, env.g
                )
                v_run = kin.velocity.sum(axis=2)  # (n_w, n_run, 3)
                for name, ve in vecs.items():
                    out[name][c, run] += np.einsum("wsd,sd->sw", v_run, ve[run])
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
