"""The passes of a load-case set with adaptive residual anchors
(:mod:`stochcable.cases.residual_anchors`): which cases each pass solves, in which
chunks, and where their drag fixed points start.

Every case is solved once.  The anchor passes solve only the cases whose residuals
the checks ask for (the first anchors, then pass after pass those
:func:`~stochcable.cases.residual_anchors.next_anchors` asks for, with the residuals),
and a last pass every other case (linear, its corrections interpolated).  An anchor
of the first pass starts at rest; one of a later pass from the converged σ of the
nearest case computed before it (:func:`neighbour_starts`: of its heading, the same
Hs at the nearest period, else the nearest Hs), and the last pass in the warm-start
runs of :mod:`stochcable.cases.chunk` over the cases it solves.  So a case's start,
and its numbers, depend on the diagram and the computed numbers only, never on the
executor or the chunking.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np

from stochcable.cases.chunk import run_lead
from stochcable.cases.scatter import SeaState

__all__ = ["neighbour_starts", "pass_chunks"]

Chunk = tuple[tuple[int, SeaState, bool], ...]


def neighbour_starts(
    states: tuple[SeaState, ...], idx: Sequence[int], known: Mapping[int, dict[str, np.ndarray]]
) -> tuple[dict[str, np.ndarray], ...]:
    """Per case of ``idx``, the converged σ (``known[j]``, per fixed-point group) of
    the case j of its heading nearest to it: the least |ln(Hs_i/Hs_j)|, then the least
    |Tp_i − Tp_j|, then the first; empty (at rest) where its heading has none."""
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
        out.append({} if best is None else best)
    return tuple(out)


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
