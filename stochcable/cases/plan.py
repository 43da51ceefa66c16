"""Planning a load-case set: the validated inputs, the scene its engine is built from and
the chunks of cases, fixed before any work so that a set can be run, stored chunk by
chunk and resumed (the service's batch jobs) with the same numbers as in one go.

A chunk's result travels as bytes (:func:`chunk_to_bytes`): NumPy arrays in an ``.npz``
archive (no pickles) and the case rows as JSON inside it.
"""

from __future__ import annotations

import io
import json
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from stochcable.cases.chunk import (
    WARM_RUN,
    CaseRow,
    ChunkResult,
    engine_template,
    run_lead,
    solve_chunk,
)
from stochcable.cases.fatigue_settings import LineFatigue, curve_factor
from stochcable.cases.residual_anchors import first_anchors, residual_anchors
from stochcable.cases.scatter import ScatterDiagram, SeaState
from stochcable.errors import InputError
from stochcable.scene.model import Scene, load_scene
from stochcable.scene.residual_kinds import asked_residuals

__all__ = [
    "CasePlan",
    "plan_cases",
    "default_chunk_size",
    "chunk_to_bytes",
    "chunk_from_bytes",
    "MAX_CHUNK_CASES",
]

#: Largest default chunk: small enough that progress is seen and a lost worker costs
#: little, large enough that a chunk's overhead (a task, a database row) is amortized. [-]
MAX_CHUNK_CASES = 64


@dataclass(frozen=True)
class CasePlan:
    """A load-case set ready to run.

    Attributes
    ----------
    scene : Scene
        The scene template.
    scatter : ScatterDiagram
    template : Scene
        The scene every chunk's engine is built from (:func:`engine_template`).
    fatigue : dict of LineFatigue
        Validated settings per line with a fatigue check.
    years : float
        Return period of the long-term extremes. [years]
    chunks : tuple of tuple of (int, SeaState, bool)
        The cases of every chunk with their positions in the diagram, and whether the
        case computes the residuals (:mod:`stochcable.cases.residual_anchors`).
    leads : tuple of tuple of (int, SeaState)
        Per chunk, the cases solved before its own and discarded
        (:func:`~stochcable.cases.chunk.run_lead`: the earlier cases of the warm-start
        run its first case is in); executors pass ``leads[k]`` with ``chunks[k]``.
    residual_span : int or None
    residual_tolerance : float or None
        The adaptive anchors' settings (:func:`plan_cases`); ``chunks`` hold every
        case with their first anchors flagged, :func:`stochcable.cases.run.run_cases`
        runs the anchors' passes instead (:mod:`stochcable.cases.anchor_passes`).
    starts : tuple of tuple of dict
        Per chunk, per case, the σ its drag fixed points start from (a pass of the
        adaptive anchors; empty: the warm-start runs); executors pass
        ``starts[k]`` with ``chunks[k]`` when not empty.
    """

    scene: Scene
    scatter: ScatterDiagram
    template: Scene
    fatigue: dict[str, LineFatigue]
    years: float
    chunks: tuple[tuple[tuple[int, SeaState], ...], ...]
    leads: tuple[tuple[tuple[int, SeaState], ...], ...] = ()
    residual_span: int | None = None
    residual_tolerance: float | None = None
    starts: tuple[tuple[dict[str, np.ndarray], ...], ...] = ()

    @property
    def adaptive(self) -> bool:
        """Whether the set's residuals take the adaptive anchors' later passes."""
        return self.residual_tolerance is not None and not all(
            c[2] for chunk in self.chunks for c in chunk
        )

    def solve(self, k: int, engine: Any = None) -> ChunkResult:
        """Solve chunk ``k`` (here; executors call :func:`solve_chunk` with the same
        arguments)."""
        lead = self.leads[k] if self.leads else ()
        start = self.starts[k] if self.starts else ()
        return solve_chunk(
            self.template, self.scatter.family, self.chunks[k], self.fatigue, engine, lead, start
        )


def _fatigue_settings(
    scene: Scene, fatigue: LineFatigue | Mapping[str, LineFatigue] | None
) -> dict[str, LineFatigue]:
    names = [ln.name for ln in scene.lines]
    if fatigue is None:
        return {}
    if isinstance(fatigue, LineFatigue):
        return dict.fromkeys(names, fatigue)
    unknown = sorted(set(fatigue) - set(names))
    if unknown:
        raise InputError("fatigue", unknown[0], "-", f"names no line of the scene ({names})")
    return dict(fatigue)


def default_chunk_size(n_cases: int, workers: int) -> int:
    """Cases per chunk: about four chunks per worker, at most :data:`MAX_CHUNK_CASES`,
    a multiple of ``WARM_RUN`` (the whole set when smaller): every chunk then starts
    at a warm-start run's start and solves no case twice
    (:mod:`stochcable.cases.chunk`; a chunk inside a run first solves the run's earlier
    cases). [-]"""
    size = max(1, min(MAX_CHUNK_CASES, math.ceil(n_cases / (4 * max(workers, 1)))))
    return max(1, min(n_cases, WARM_RUN * max(1, round(size / WARM_RUN))))


def plan_cases(
    scene: Scene | Mapping[str, Any] | str,
    scatter: ScatterDiagram,
    *,
    fatigue: LineFatigue | Mapping[str, LineFatigue] | None = None,
    years: float = 100.0,
    chunk_size: int | None = None,
    residual_span: int | None = None,
    residual_tolerance: float | None = None,
) -> CasePlan:
    """Validate a load-case set and split it into chunks.

    Parameters
    ----------
    scene : Scene, mapping or path
        The scene template (its sea is replaced by each state's, its time-series
        settings dropped).
    scatter : ScatterDiagram
    fatigue : LineFatigue or mapping of line name to LineFatigue, optional
        Settings of every line (one for all) or per line; no damage without.
    years : float
        Return period of the long-term extremes. [years]
    chunk_size : int, optional
        Cases per chunk; default all cases in one chunk.
    residual_span : int or None
        With residuals asked for: most steps of a column's sorted Hs between the cases
        that compute them, the others interpolated
        (:mod:`stochcable.cases.residual_anchors`; opt-in, its measured error in the
        module notes); None (default): every case computes them, unless
        ``residual_tolerance`` is given.
    residual_tolerance : float or None
        The adaptive anchors' tolerance (:func:`stochcable.cases.run.run_cases`):
        ``chunks`` then hold their first pass
        (:func:`~stochcable.cases.residual_anchors.first_anchors`), and the set needs
        the later passes :func:`~stochcable.cases.run.run_cases` runs
        (:attr:`CasePlan.adaptive`).  None (default): no checks.

    Returns
    -------
    CasePlan
    """
    scene = load_scene(scene)
    if residual_span is not None and (
        not isinstance(residual_span, int) or isinstance(residual_span, bool) or residual_span < 1
    ):
        raise InputError("residual_span", residual_span, "-", "must be an integer >= 1 or None")
    if residual_tolerance is not None and not (
        isinstance(residual_tolerance, (int, float))
        and not isinstance(residual_tolerance, bool)
        and 0 < residual_tolerance < 1
    ):
        raise InputError("residual_tolerance", residual_tolerance, "-", "must be in (0, 1) or None")
    if not (
        isinstance(years, (int, float))
        and not isinstance(years, bool)
        and math.isfinite(years)
        and years > 0
    ):
        raise InputError("years", years, "years", "must be finite and > 0")
    settings = _fatigue_settings(scene, fatigue)
    for name, s in settings.items():
        s.check(f"fatigue[{name}]")
        curve_factor(s, scene.environment.g, f"fatigue[{name}]")  # refused before work
    n = len(scatter.states)
    if chunk_size is None:
        chunk_size = max(n, 1)
    if not isinstance(chunk_size, int) or isinstance(chunk_size, bool) or chunk_size < 1:
        raise InputError("chunk_size", chunk_size, "-", "must be an integer >= 1")
    template = engine_template(scene, scatter.states, scatter.family)
    asked = [k.name for k in asked_residuals(scene.analysis.linearization)]
    adaptive = bool(asked) and residual_tolerance is not None
    if adaptive:
        exact = first_anchors(scatter.states, residual_span)
    else:
        exact = residual_anchors(scatter.states, residual_span if asked else None)
    chunks = tuple(
        tuple((i, scatter.states[i], bool(exact[i])) for i in range(a, min(a + chunk_size, n)))
        for a in range(0, n, chunk_size)
    )
    leads = tuple(run_lead(scatter.states, part[0][0]) for part in chunks)
    return CasePlan(
        scene, scatter, template, settings, float(years), chunks, leads,
        residual_span, residual_tolerance if adaptive else None,
    )  # fmt: skip


def chunk_to_bytes(result: ChunkResult) -> bytes:
    """A chunk's result as bytes (an ``.npz`` archive without pickles)."""
    lines = sorted(result.stats)
    header = {
        "lines": lines,
        "ends": sorted(next(iter(result.stats.values()), {})),
        "s_elements": sorted(result.s_elements),
        "rows": [
            [r.index, r.status, r.reason, list(r.flags), list(r.warnings)] for r in result.rows
        ],
    }
    arrays: dict[str, np.ndarray] = {
        "header": np.frombuffer(json.dumps(header).encode(), dtype=np.uint8),
        "indices": np.asarray(result.indices, dtype=np.int64),
    }
    for k, ln in enumerate(lines):
        for e in header["ends"]:
            arrays[f"stats_{k}_{e}"] = result.stats[ln][e]
        arrays[f"damage_{k}"] = result.damage[ln]
        if ln in result.linear:
            arrays[f"linear_{k}"] = result.linear[ln]
    if result.exact is not None:
        arrays["exact"] = np.asarray(result.exact, dtype=bool)
    for k, ln in enumerate(header["s_elements"]):
        arrays[f"s_{k}"] = result.s_elements[ln]
    buf = io.BytesIO()
    np.savez_compressed(buf, **arrays)
    return buf.getvalue()


def chunk_from_bytes(data: bytes) -> ChunkResult:
    """The chunk result :func:`chunk_to_bytes` wrote."""
    with np.load(io.BytesIO(data), allow_pickle=False) as z:
        header = json.loads(z["header"].tobytes().decode())
        stats = {
            ln: {e: z[f"stats_{k}_{e}"] for e in header["ends"]}
            for k, ln in enumerate(header["lines"])
        }
        damage = {ln: z[f"damage_{k}"] for k, ln in enumerate(header["lines"])}
        s_el = {ln: z[f"s_{k}"] for k, ln in enumerate(header["s_elements"])}
        linear = {
            ln: z[f"linear_{k}"] for k, ln in enumerate(header["lines"]) if f"linear_{k}" in z
        }
        exact = z["exact"] if "exact" in z else None
        indices = z["indices"]
    rows = tuple(
        CaseRow(int(i), st, reason, tuple(flags), tuple(warns))
        for i, st, reason, flags, warns in header["rows"]
    )
    return ChunkResult(indices, rows, stats, damage, s_el, linear, exact)
