"""The residuals of the linear model in a load-case set: computed on the *anchor* cases,
interpolated in Hs on the others.

The residuals (``analysis.linearization.drag_residual`` / ``geometric_residual``,
:mod:`stochcable.dynamics.residuals`) are evaluated on each case's own converged
response: their covariances and convolutions, the panels' Hermite coefficients and the
end tensions per unit load depend on the sea and on the linearized damping, which
differs in every case, so nothing of them is shared between cases, and they cost a
case several times its linear solve (docs/benchmarks/cases.md).  What they change is
smooth along a column of the diagram — the sea states of one period and heading, which
differ by Hs (and by the γ that DNV-RP-C205 derives from Hs and Tp): the corrections'
ratios — σ over the linear σ, Tz and 3-h MPM over the linear ones, end damage over the
linear damage — move little with Hs (the chain example's 10 × 20 diagram: σ ratio
1.04–1.08, end damage ratio 1.20–1.43).

So in each column the residuals are computed on the smallest and the largest Hs and
on Hs values at most :data:`RESIDUAL_SPAN` steps of the column's sorted Hs apart
(:func:`residual_anchors`), and every other case gets its linear values times the
ratios interpolated in Hs between the anchors (:func:`interpolate_corrections`:
linearly in Hs², :func:`correction`).
Measured on the chain example's 10 × 20 diagram against every case computed
(benchmarks/bench_cases.py, docs/benchmarks/cases.md): with a fixed γ (3.3), σ within
6e-5 (below the linearization tolerance), Tz 1.2e-4, end damage 2.7e-4; with DNV γ,
σ within 1.7e-3, Tz 5.4e-3 and end damage 9.3e-3 on the worst case.  The larger
figures are not the interpolation's: the computed ratios themselves step by 0.5 % of
σ where the drag residual's panels change (32 panels at γ ≤ 1.05, 27 from γ = 1.2, at
Hs 3 m and Tp 9.2 s; :mod:`stochcable.dynamics.residuals.drag_segments`) — a
discretization step of the residual, which the anchors straddle.  The taut wire,
whose correction grows with Hs (+0.03 … +2.6 % on σ over Hs 0.5 … 3.5 m): σ within
1.2e-3 at Tp 8 s (tests/cases/test_residual_anchors.py) — but at Tp 10 s, where its
correction at end_b reaches +49 % on σ and grows fast with Hs, the anchors at Hs 0.5,
2.0 and 3.5 m miss by up to 4.2 % on σ and a factor 2.8 on end damage.  So the anchors
are opt-in (``run_cases(..., residual_span=5)``); the default, ``residual_span=None``,
computes every case.

The anchors are fixed by the plan, from the diagram alone, so the numbers do not
depend on the executor or the chunking; the along-line damage is the linear model's
in both (the residuals act on the end tensions).
"""

from __future__ import annotations

import math
from collections import defaultdict
from dataclasses import replace
from typing import Any

import numpy as np

from stochcable.cases.scatter import SeaState, tz_over_tp

__all__ = ["RESIDUAL_SPAN", "correction", "residual_anchors", "interpolate_corrections"]

#: Most steps of a column's sorted Hs values between two anchors (module notes). [-]
RESIDUAL_SPAN = 5


def _columns(states: tuple[SeaState, ...]) -> list[tuple[float, float]]:
    """Each state's column: its heading and its period — Tp, or Tz where the diagram
    has fewer distinct Tz than Tp (a diagram given in Tz with γ from Hs and Tp:
    DNV-RP-C205's γ, and so Tp, vary along a row of constant Tz). [deg, s]"""
    tp = [(s.heading, float(f"{s.tp:.9g}")) for s in states]
    tz = [(s.heading, float(f"{s.tp * tz_over_tp(s.gamma):.9g}")) for s in states]
    return tz if len(set(tz)) < len(set(tp)) else tp


def residual_anchors(states: tuple[SeaState, ...], span: int | None = RESIDUAL_SPAN) -> np.ndarray:
    """Which cases compute the residuals (module notes).

    Parameters
    ----------
    states : tuple of SeaState
        The diagram's sea states.
    span : int or None
        Most steps of a column's sorted Hs values between anchors; None: every case.

    Returns
    -------
    ndarray of bool, shape (n_states,)
    """
    out = np.ones(len(states), dtype=bool)
    if span is None:
        return out
    key = _columns(states)
    columns: dict[tuple[float, float], set[float]] = defaultdict(set)
    for s, c in zip(states, key):
        columns[c].add(s.hs)
    keep: dict[tuple[float, float], set[float]] = {}
    for c, hs in columns.items():
        u = sorted(hs)
        m = math.ceil((len(u) - 1) / span) + 1 if len(u) > 2 else len(u)
        idx = np.unique(np.rint(np.linspace(0, len(u) - 1, m)).astype(int))
        keep[c] = {u[i] for i in idx}
    for i, (s, c) in enumerate(zip(states, key)):
        out[i] = s.hs in keep[c]
    return out


def interpolate_corrections(
    states: tuple[SeaState, ...],
    exact: np.ndarray,
    rows: list[Any],
    stats: dict[str, dict[str, np.ndarray]],
    damage_ends: dict[str, np.ndarray],
    linear: dict[str, np.ndarray],
) -> None:
    """Give the cases whose residuals were not computed the anchors' corrections, in
    place (module notes).

    Parameters
    ----------
    states : tuple of SeaState
    exact : ndarray of bool, shape (n,)
        Whether a case's residuals were computed.
    rows : list of CaseRow
        The cases' rows (a case whose column has no anchor with a response gets a
        warning in its row and keeps its linear values).
    stats : dict
        ``[line][end]`` shape (n, 4): mean, σ, Tz, 3-h MPM (corrected on the anchors,
        linear elsewhere): σ, Tz and MPM of the others are corrected.
    damage_ends : dict of ndarray
        ``[line]`` shape (n, 2): end damage rates, corrected likewise.
    linear : dict of ndarray
        ``[line]`` shape (n, 2, 4): per end the linear σ, Tz, MPM and damage rate.
    """
    todo = [i for i in range(len(states)) if not exact[i] and rows[i].has_numbers]
    if not todo:
        return
    key = _columns(states)
    columns: dict[tuple[float, float], list[int]] = defaultdict(list)
    for i in range(len(states)):
        if exact[i] and rows[i].has_numbers:
            columns[key[i]].append(i)
    hs = np.array([s.hs for s in states])
    for i in todo:
        anchors = columns.get(key[i], [])
        if not anchors:
            rows[i] = replace(
                rows[i],
                warnings=(
                    *rows[i].warnings,
                    "the residuals of the linear model are not applied to this case: no "
                    "case of its period and heading with computed residuals has a response",
                ),
            )
            continue
        _, first = np.unique(hs[anchors], return_index=True)
        a = np.asarray(anchors)[first]  # sorted by Hs, one per Hs value
        for name, lin in linear.items():
            for e, end in enumerate(("end_a", "end_b")):
                cur = stats[name][end]
                for col, q in ((1, 0), (2, 1), (3, 2)):  # σ, Tz, MPM
                    ratio = _ratios(cur[a, col], lin[a, e, q])
                    cur[i, col] = lin[i, e, q] * correction(hs[i], hs[a], ratio)
                if name in damage_ends and np.all(np.isfinite(lin[a, e, 3])):
                    ratio = _ratios(damage_ends[name][a, e], lin[a, e, 3])
                    damage_ends[name][i, e] = lin[i, e, 3] * correction(hs[i], hs[a], ratio)


def correction(hs: float, anchors: np.ndarray, ratios: np.ndarray) -> float:
    """The ratio at ``hs`` between the anchors' (``anchors`` sorted Hs [m], their
    ``ratios``): linear in Hs², the linear response's variance at a fixed spectral
    shape (the chain example's worst σ 5.9e-5 against 9.5e-5 linear in Hs; the taut
    wire's σ correction, growing +0.03 … +2.6 % over Hs 0.5 … 3.5 m, 1.2e-3 against
    2.4e-3); constant beyond the anchors. [-]"""
    return float(np.interp(hs * hs, anchors * anchors, ratios))


def _ratios(corrected: np.ndarray, linear: np.ndarray) -> np.ndarray:
    """corrected/linear, 1 where the linear value is 0 or not finite."""
    ok = np.isfinite(linear) & (linear != 0) & np.isfinite(corrected)
    return np.where(ok, corrected / np.where(ok, linear, 1.0), 1.0)
