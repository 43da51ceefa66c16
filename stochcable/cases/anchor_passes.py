"""The passes of a load-case set with adaptive residual anchors
(:mod:`stochcable.cases.residual_anchors`): which cases each pass solves, in which
chunks, and where their drag fixed points start.

Every case is solved once.  The anchor passes solve only the cases whose residuals
the checks ask for (the first anchors, then pass after pass those
:func:`~stochcable.cases.residual_anchors.next_anchors` asks for, with the residuals),
and a last pass every other case (linear, its corrections interpolated).  An anchor
of the first pass starts at rest; one of a later pass from the converged σ of the
cases computed before it (:func:`neighbour_starts`: where its column has two, their
σ interpolated in Hs, :func:`column_start`; else the nearest one's, of its heading,
the same Hs at the nearest period, else the nearest Hs).  The last pass solves
first the cases a column start serves well (:func:`split_last_pass`: between
computed Hs of a column whose σ follow the law, or that would start a warm-start run
at rest), each from its own start, then the others in the warm-start runs of
:mod:`stochcable.cases.chunk` over them.  So a case's start, and its numbers, depend
on the diagram and the computed numbers only, never on the executor or the chunking.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np

from stochcable.cases.chunk import WARM_RUN, run_lead
from stochcable.cases.scatter import SeaState

__all__ = ["column_start", "neighbour_starts", "pass_chunks", "split_last_pass"]

Chunk = tuple[tuple[int, SeaState, bool], ...]


def neighbour_starts(
    states: tuple[SeaState, ...], idx: Sequence[int], known: Mapping[int, dict[str, np.ndarray]]
) -> tuple[dict[str, np.ndarray], ...]:
    """Per case of ``idx``, the σ its drag fixed points start from (per fixed-point
    group, from the converged σ ``known[j]`` of the cases computed before it): where
    its column (heading and Tp) has two such cases, their σ interpolated in Hs
    (:func:`column_start`); else the σ of the case j of its heading nearest to it: the
    least |ln(Hs_i/Hs_j)|, then the least |Tp_i − Tp_j|, then the first; empty (at
    rest) where its heading has none."""
    out = []
    for i in idx:
        s = states[int(i)]
        best, key = None, (math.inf, math.inf, math.inf)
        for j, x in known.items():
            t = states[j]
            if t.heading != s.heading or not x or t.hs <= 0 or s.hs <= 0:
                continue
            k = (abs(math.log(s.hs / t.hs)), abs(s.tp - t.tp), j)
            if k < key:
                best, key = x, k
        column = _column(states, s, known)
        if len(column) >= 2:
            best = column_start(s.hs, column, known)
        out.append({} if best is None else best)
    return tuple(out)


def _column(
    states: tuple[SeaState, ...], s: SeaState, known: Mapping[int, dict[str, np.ndarray]]
) -> list[tuple[float, int]]:
    """The known cases of state ``s``'s column (its heading and Tp) at other Hs than
    its own, one per Hs, as (Hs, case) sorted by Hs."""
    out: dict[float, int] = {}
    for j, x in known.items():
        t = states[j]
        if x and t.heading == s.heading and t.tp == s.tp and t.hs != s.hs and t.hs > 0:
            out.setdefault(t.hs, j)
    return sorted(out.items())


#: Bounds of the local exponent of σ in Hs a column start extrapolates with
#: (:func:`column_start`): the relative velocities' σ grow with Hs, at most as Hs²
#: (drag damping makes them grow slower than Hs, a swell-like response faster). [-]
_EXPONENT_BOUNDS = (0.0, 2.0)
#: Largest relative miss of a column's σ law (:func:`split_last_pass`: each interior
#: computed case's σ against :func:`column_start` of its computed neighbours) for the
#: column's linear cases to start there: the taut wire's Tp 10–12 s columns miss by
#: 1e-5, its Tp 6–8 s and the chain example's by 7e-3 … 3e-1. [-]
START_TOLERANCE = 1e-3


def column_start(
    hs: float, column: list[tuple[float, int]], known: Mapping[int, dict[str, np.ndarray]]
) -> dict[str, np.ndarray]:
    """The start of a case at ``hs`` [m] from two converged cases of its column
    (``column``: (Hs, case) sorted by Hs, at least two): the nearest below and above it
    (else the two nearest on its side), their σ a power of Hs per component (log–log,
    the exponent within :data:`_EXPONENT_BOUNDS`; the nearer one's σ where a σ is not
    positive or a group's sizes differ).  The linear response grows with Hs and the
    drag damping with it, so the σ of a column move smoothly with Hs: the fixed point
    starts closer than from one neighbour's σ (on the taut wire 2.0 evaluations an
    anchor instead of 2.7, docs/benchmarks/cases.md), and converges to the same
    tolerance."""
    below = [c for c in column if c[0] < hs]
    above = [c for c in column if c[0] > hs]
    if below and above:
        (h0, j0), (h1, j1) = below[-1], above[0]
    else:
        (h0, j0), (h1, j1) = below[-2:] if below else above[:2]
    near = j0 if abs(math.log(hs / h0)) <= abs(math.log(hs / h1)) else j1
    out = {}
    for g, x0 in known[j0].items():
        x1 = known[j1].get(g)
        if x1 is None or x1.shape != x0.shape:
            out[g] = known[near][g]
            continue
        pos = (x0 > 0) & (x1 > 0)
        ratio = np.where(pos, x1, 1.0) / np.where(pos, x0, 1.0)
        p = np.clip(np.log(ratio) / math.log(h1 / h0), *_EXPONENT_BOUNDS)
        out[g] = np.where(pos, x0 * (hs / h0) ** p, known[near][g])
    return out


def _law_holds(column: list[tuple[float, int]], known: Mapping[int, dict[str, np.ndarray]]) -> bool:
    """Whether a column's σ follow :func:`column_start` within :data:`START_TOLERANCE`
    at each of its interior computed cases (from the computed ones beside it); False
    with fewer than three."""
    if len(column) < 3:
        return False
    for k in range(1, len(column) - 1):
        hs, j = column[k]
        got = column_start(hs, [column[k - 1], column[k + 1]], known)
        for g, x in known[j].items():
            if g not in got or got[g].shape != x.shape:
                return False
            live = x != 0
            if np.any(np.abs(got[g][live] / x[live] - 1.0) > START_TOLERANCE):
                return False
    return True


def split_last_pass(
    states: tuple[SeaState, ...], idx: Sequence[int], known: Mapping[int, dict[str, np.ndarray]]
) -> tuple[list[int], tuple[dict[str, np.ndarray], ...], list[int]]:
    """The last pass of the adaptive anchors (every case not computed, linear) in two:
    the cases between two computed Hs of a column (heading and Tp) whose σ follow
    :func:`column_start`'s law (:func:`_law_holds`, measured on the column's computed
    cases) or that would start its warm-start run at rest (no case of the run and
    heading before it left), each started from there (its fixed point on the full
    grid alone: on Tuah's single leg 3.8 evaluations instead of 8.3 from rest), and
    the others in the warm-start runs over them (on the chain example a column start
    between anchors several Hs apart takes 3.3 evaluations, a case of a warm-start run
    from its neighbours 2.7).  Returns the first cases, their starts, and the others."""
    first, starts, rest = [], [], []
    holds: dict[tuple[float, float], bool] = {}
    for i in sorted(int(i) for i in idx):
        s = states[i]
        column = _column(states, s, known)
        key = (s.heading, s.tp)
        if key not in holds:
            holds[key] = _law_holds(column, known)
        inside = bool(column) and column[0][0] < s.hs < column[-1][0]
        prev = rest[-1] if rest else None
        cold = prev is None or prev // WARM_RUN != i // WARM_RUN
        if inside and (holds[key] or cold or states[prev].heading != s.heading):
            first.append(i)
            starts.append(column_start(s.hs, column, known))
        else:
            rest.append(i)
    return first, tuple(starts), rest


def pass_chunks(
    states: tuple[SeaState, ...],
    idx: Sequence[int],
    exact: bool,
    chunk_size: int | None,
    starts: tuple[dict[str, np.ndarray], ...] | None = None,
) -> tuple[tuple[Chunk, ...], tuple, tuple]:
    """The chunks (of ``chunk_size`` cases; None: one) of a pass solving the cases
    ``idx`` (increasing positions), computing the residuals or not (``exact``); their
    leads (without ``starts``: the pass's earlier cases of a chunk's first warm-start
    run, :func:`~stochcable.cases.chunk.run_lead`) and per case the ``starts``
    (empty: the warm-start runs)."""
    idx = [int(i) for i in idx]
    size = max(1, len(idx) if chunk_size is None else chunk_size)
    cut = range(0, len(idx), size)
    chunks = tuple(tuple((i, states[i], exact) for i in idx[a : a + size]) for a in cut)
    if starts is not None:
        return chunks, tuple(() for _ in chunks), tuple(starts[a : a + size] for a in cut)
    leads = tuple(run_lead(states, part[0][0], idx) for part in chunks)
    return chunks, leads, tuple(() for _ in chunks)
