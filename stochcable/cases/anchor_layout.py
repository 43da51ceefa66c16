"""The layout the residual anchors of a load-case set work on: the diagram's columns
(the sea states of one heading and period, which differ by Hs) ordered by period per
heading, the corrections' ratios of the cases as one matrix, and the power law in Hs
of a column's ratios between the cases that computed them (:func:`correction_rows`;
the curves of a heading's columns from it in :mod:`stochcable.cases.anchor_transfer`).
Used by :mod:`stochcable.cases.residual_anchors`, whose notes say what is checked
where.
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from stochcable.cases.scatter import SeaState, tz_over_tp

__all__ = [
    "DAMAGE_TOLERANCE_FACTOR",
    "Column",
    "check_ratios",
    "column_keys",
    "correction_rows",
    "element_scale",
    "layout",
    "neighbours",
    "ratios",
]

#: The end damage rate's tolerance over σ's: damage ∝ σ^m with the S-N slope m ≈ 3
#: (a relative error δ on σ is ≈ 3δ on damage; the set's target 1e-2). [-]
DAMAGE_TOLERANCE_FACTOR = 3.0


@dataclass(frozen=True)
class Column:
    """The cases of one heading and period.

    Attributes
    ----------
    period : float
        Tp, or Tz (:func:`column_keys`). [s]
    hs : ndarray, shape (m,)
        Its distinct Hs, increasing. [m]
    members : tuple of tuple of int
        Per Hs, the cases with it.
    """

    period: float
    hs: np.ndarray
    members: tuple[tuple[int, ...], ...]

    @property
    def cases(self) -> list[int]:
        """Every case of the column."""
        return [i for m in self.members for i in m]

    def anchors(self, ok: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Its cases with computed residuals and a response (``ok``), one per Hs: their
        Hs [m] (increasing) and case indices."""
        hs, idx = [], []
        for h, m in zip(self.hs, self.members):
            good = [i for i in m if ok[i]]
            if good:
                hs.append(h)
                idx.append(good[0])
        return np.asarray(hs, dtype=float), np.asarray(idx, dtype=int)


def column_keys(states: tuple[SeaState, ...]) -> list[tuple[float, float]]:
    """Each state's column: its heading and its period — Tp, or Tz where the diagram
    has fewer distinct Tz than Tp (a diagram given in Tz with γ from Hs and Tp:
    DNV-RP-C205's γ, and so Tp, vary along a row of constant Tz). [deg, s]"""
    tp = [(s.heading, float(f"{s.tp:.9g}")) for s in states]
    tz = [(s.heading, float(f"{s.tp * tz_over_tp(s.gamma):.9g}")) for s in states]
    return tz if len(set(tz)) < len(set(tp)) else tp


def layout(states: tuple[SeaState, ...]) -> dict[float, list[Column]]:
    """Per heading [deg], its columns ordered by period."""
    members: dict[tuple[float, float], dict[float, list[int]]] = defaultdict(dict)
    for i, (s, c) in enumerate(zip(states, column_keys(states))):
        members[c].setdefault(s.hs, []).append(i)
    out: dict[float, list[Column]] = defaultdict(list)
    for (heading, period), by_hs in sorted(members.items()):
        u = sorted(by_hs)
        out[heading].append(Column(period, np.array(u), tuple(tuple(by_hs[h]) for h in u)))
    return dict(out)


def ratios(corrected: np.ndarray, linear: np.ndarray) -> np.ndarray:
    """corrected/linear, 1 where the linear value is 0 or not finite."""
    ok = np.isfinite(linear) & (linear != 0) & np.isfinite(corrected)
    return np.where(ok, corrected / np.where(ok, linear, 1.0), 1.0)


def check_ratios(
    stats: Mapping[str, Mapping[str, np.ndarray]],
    damage_ends: Mapping[str, np.ndarray],
    linear: Mapping[str, np.ndarray],
    along: tuple[Mapping[str, np.ndarray], Mapping[str, np.ndarray]] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """The corrections' ratios of every case as one matrix, and each ratio's tolerance
    in units of σ's.

    Parameters
    ----------
    stats, damage_ends, linear
        As in :func:`stochcable.cases.residual_anchors.interpolate_corrections`.
    along : (damage, linear_along), optional
        The along-line damage rates ``damage[line]`` (n, 2 + n_el) and the linear
        model's ``linear_along[line]`` (n, n_el): their ratios join, each element's
        tolerance the end damage's relative to the line's largest damage rate of the
        case (its ends' and elements'): :data:`DAMAGE_TOLERANCE_FACTOR` times the ratio
        of that largest to the element's.

    Returns
    -------
    R : ndarray, shape (n, q)
        Per end of every line σ, Tz and 3-h MPM over the linear ones, the end damage
        rate over the linear one, then the elements' damage ratios. [-]
    scale : ndarray, shape (n, q)
        Per case, 1, or :data:`DAMAGE_TOLERANCE_FACTOR` for the end damage rates, or
        the elements' (inf for an element without damage). [-]
    """
    cols, scale = [], []
    for name, lin in linear.items():
        for e, end in enumerate(("end_a", "end_b")):
            for col, q in ((1, 0), (2, 1), (3, 2)):
                cols.append(ratios(stats[name][end][:, col], lin[:, e, q]))
                scale.append(1.0)
            if name in damage_ends:
                cols.append(ratios(damage_ends[name][:, e], lin[:, e, 3]))
                scale.append(DAMAGE_TOLERANCE_FACTOR)
    n = next(iter(linear.values())).shape[0] if linear else 0
    scale = [np.full(n, x) for x in scale]
    if along is not None:
        damage, lin_along = along
        for name, lin in lin_along.items():
            r = ratios(damage[name][:, 2:], lin)
            cols.extend(r.T)
            scale.extend(element_scale(damage[name]).T)
    r_all = np.column_stack(cols) if cols else np.ones((n, 0))
    s_all = np.column_stack(scale) if scale else np.ones((n, 0))
    return r_all, s_all


def element_scale(damage: np.ndarray) -> np.ndarray:
    """The elements' damage tolerances in units of σ's (n, n_el): the end damage's
    (:data:`DAMAGE_TOLERANCE_FACTOR`) relative to the line's largest damage rate of
    each case, ``damage`` (n, 2 + n_el) its ends' and elements' (module notes of
    :mod:`stochcable.cases.residual_anchors`); inf where an element has none. [-]"""
    d = np.where(np.isfinite(damage), damage, 0.0)
    big = np.max(d, axis=1, keepdims=True) if d.size else np.zeros((d.shape[0], 1))
    el = d[:, 2:]
    ratio = np.divide(big, el, out=np.full_like(el, np.inf), where=el > 0)
    return DAMAGE_TOLERANCE_FACTOR * np.maximum(ratio, 1.0)


def correction_rows(
    hs: float, anchors: np.ndarray, r: np.ndarray, law: str = "power"
) -> np.ndarray:
    """The ratios (q,) at ``hs`` between the anchors' (``anchors`` sorted distinct Hs
    [m], their ratios ``r`` (m, q)); constant beyond the anchors (the law:
    :func:`stochcable.cases.residual_anchors.correction`). [-]"""
    h = np.asarray(anchors, dtype=float)
    r = np.asarray(r, dtype=float)
    if h.size == 1 or hs <= h[0]:
        return r[0].copy()
    if hs >= h[-1]:
        return r[-1].copy()
    k = int(np.searchsorted(h, hs, side="right")) - 1
    h0, h1, r0, r1 = h[k], h[k + 1], r[k], r[k + 1]
    out = r0 + (r1 - r0) * (hs * hs - h0 * h0) / (h1 * h1 - h0 * h0)
    if law == "power" and h0 > 0:
        x0, x1 = r0 - 1.0, r1 - 1.0
        same = x0 * x1 > 0
        if np.any(same):
            expo = math.log(hs / h0) / math.log(h1 / h0)
            q = np.where(same, x1 / np.where(same, x0, 1.0), 1.0)
            out = np.where(same, 1.0 + x0 * q**expo, out)
    return out


def neighbours(active: list[bool], j: int) -> tuple[int | None, int | None]:
    """The nearest active columns below and above column ``j``."""
    lo = next((k for k in range(j - 1, -1, -1) if active[k]), None)
    hi = next((k for k in range(j + 1, len(active)) if active[k]), None)
    return lo, hi
