"""Running a load-case set: one engine per scene, one solve per sea state, fatigue
damage and extremes per case, and the totals over the scatter diagram.

The sea-independent work — statics (with current), the finite-element models, modes,
factorizations and drag-independent arrays — is built once
(:func:`stochcable.cases.chunk.set_engine`, with the element check of
:mod:`stochcable.fidelity.mesh_engine`) and shared by every sea state; each
case is ``engine.solve(sea)``, which equals ``analyze`` of the scene with that sea.  A
case that fails or does not converge is a row with its status and reason, never a lost
set.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping
from concurrent.futures import as_completed
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from stochcable.cases.anchor_moments import damage_slopes
from stochcable.cases.anchor_passes import neighbour_starts, pass_chunks, split_last_pass
from stochcable.cases.chunk import ENDS, CaseRow, ChunkResult, set_engine, solve_chunk
from stochcable.cases.display import case_set_html, case_set_text
from stochcable.cases.fatigue_settings import LineFatigue
from stochcable.cases.plan import CasePlan, default_chunk_size, plan_cases
from stochcable.cases.residual_anchors import (
    RESIDUAL_TOLERANCE,
    first_anchors,
    interpolate_corrections,
    next_anchors,
)
from stochcable.cases.scatter import ScatterDiagram
from stochcable.design import SECONDS_PER_YEAR, return_level
from stochcable.dynamics.engine import Engine
from stochcable.errors import InputError, PhysicsWarning, warn
from stochcable.scene.model import Scene
from stochcable.scene.residual_kinds import asked_residuals

__all__ = ["CaseRow", "LineTotals", "CaseSetResult", "run_cases", "assemble_cases", "ENDS"]


Progress = Callable[[int, int], None]


@dataclass(frozen=True)
class LineTotals:
    """Totals of one line over the set, per end (``end_a``, ``end_b``) where keyed.

    Attributes
    ----------
    annual_damage : dict of float, and ``along`` ndarray (n_el,)
        Probability-weighted damage per year (365.25 days). [1/year]
    fatigue_life : dict of float, and ``along`` ndarray (n_el,)
        1/(DFF · annual damage). [years]
    return_level : dict of float
        The ``years``-year most probable maximum tension. [force unit]
    governing_mpm_case, governing_damage_case : dict of int
        Index of the case with the largest 3-h MPM, and with the largest contribution
        p·D to the damage.
    """

    annual_damage: dict[str, Any]
    fatigue_life: dict[str, Any]
    return_level: dict[str, float]
    governing_mpm_case: dict[str, int]
    governing_damage_case: dict[str, int]


@dataclass(frozen=True)
class CaseSetResult:
    """Results of a load-case set (:func:`run_cases`).

    Attributes
    ----------
    scatter : ScatterDiagram
    rows : tuple of CaseRow
    lines : tuple of str
        Line names, in scene order.
    s_elements : dict of ndarray
        Element midpoint arc length per line. [m]
    stats : dict of ndarray
        ``stats[line][end]`` shape (n_case, 4): mean, σ, Tz, 3-h MPM of the end tension
        (NaN for failed cases). [force unit, force unit, s, force unit]
    damage_rate_ends : dict of ndarray
        ``[line]`` shape (n_case, 2): damage rate at end_a, end_b (NaN: failed or no
        fatigue settings). [1/s]
    damage_rate_along : dict of ndarray
        ``[line]`` shape (n_case, n_el): damage rate of every element. [1/s]
    totals : dict of LineTotals
        Per line with fatigue settings (extremes for every line).
    coverage : dict of float
        Probability of the ``ok`` cases, of every case with a response, and of the
        failed cases. [-]
    years : float
        Return period of ``return_level``. [years]
    fatigue : dict of LineFatigue
        The settings used, per line.
    """

    scatter: ScatterDiagram
    rows: tuple[CaseRow, ...]
    lines: tuple[str, ...]
    s_elements: dict[str, np.ndarray]
    stats: dict[str, dict[str, np.ndarray]]
    damage_rate_ends: dict[str, np.ndarray]
    damage_rate_along: dict[str, np.ndarray]
    totals: dict[str, LineTotals]
    coverage: dict[str, float]
    years: float
    fatigue: dict[str, LineFatigue] = field(default_factory=dict)

    def __repr__(self) -> str:
        """A few lines: cases by status, per line end the governing MPM and damage."""
        return case_set_text(self)

    def _repr_html_(self) -> str:
        """The summary table a notebook shows (:mod:`stochcable.cases.display`)."""
        return case_set_html(self)

    @property
    def probabilities(self) -> np.ndarray:
        """Probability of every case. [-]"""
        return np.array([s.probability for s in self.scatter.states])


def run_cases(
    scene: Scene | Mapping[str, Any] | str,
    scatter: ScatterDiagram,
    *,
    fatigue: LineFatigue | Mapping[str, LineFatigue] | None = None,
    years: float = 100.0,
    progress: Progress | None = None,
    engine: Engine | None = None,
    executor: Any = None,
    chunk_size: int | None = None,
    client: Any = None,
    residual_span: int | None = None,
    residual_tolerance: float | None = RESIDUAL_TOLERANCE,
) -> CaseSetResult:
    """Solve every sea state of a scatter diagram on one scene.

    Parameters
    ----------
    scene : Scene, mapping, JSON string or path
        The scene template; its sea is replaced by each state's, its time-series
        settings are dropped (a set needs spectra, not records).
    scatter : ScatterDiagram
    fatigue : LineFatigue or mapping of line name to LineFatigue, optional
        Fatigue settings of every line (one for all) or per line; no damage without.
    years : float
        Return period of the long-term extremes. [years]
    progress : callable, optional
        ``progress(done, total)`` as cases finish (after every chunk); ``total`` the
        diagram's size (every case is solved once, the adaptive anchors' passes
        first).
    engine : Engine, optional
        A built engine of the same scene, used by the in-process executor
        (``stochcable.build_engine``'s carries the element check into every case).
    executor : concurrent.futures.Executor or dask.distributed.Client, optional
        Where the chunks run (None: in this process, one after the other).  With a
        Dask client the scene template is scattered to every worker once; a worker
        builds its engine once and keeps it for the next chunks.  Workers run
        ≈ 30 % faster with the process settings of the CLI and the service:
        ``client.run(stochcable.cases.chunk.prepare_worker)`` (not done here: the
        library changes no process by itself).
    chunk_size : int, optional
        Cases per chunk (default: all in one chunk in this process; with an executor,
        :func:`~stochcable.cases.plan.default_chunk_size` of its workers).
    client : dask.distributed.Client, optional
        The same as ``executor=client`` (give one of the two).
    residual_span : int or None
        With the residuals of the linear model asked for: most steps of a column's
        sorted Hs (one period and heading) between the first cases that compute them
        (None: the column's smallest and largest Hs); see ``residual_tolerance``.
    residual_tolerance : float or None
        With the residuals asked for, the adaptive anchors
        (:mod:`stochcable.cases.residual_anchors`): per heading the periods are
        bisected from the shortest, middle and longest, each computed period's Hs from
        its smallest, middle and largest, until the corrections interpolated at every
        checked middle (σ, Tz and 3-h MPM over the linear ones; the end damage rates',
        with 3 × the tolerance, and the elements' with 3 × the tolerance relative to
        the line's largest damage rate of the case) are within ``residual_tolerance``
        of the computed ones; the other cases get interpolated corrections, and a
        PhysicsWarning says how many cases computed them.  Default
        :data:`~stochcable.cases.residual_anchors.RESIDUAL_TOLERANCE` (2e-3; the
        measured error on the chain, the taut wire and Tuah's single leg is in
        docs/benchmarks/cases.md; never finer than the scene's
        ``analysis.linearization.tolerance``, to which the ratios are known).
        None: no check — with ``residual_span`` the fixed anchors of
        :func:`~stochcable.cases.residual_anchors.residual_anchors` (σ within 1.7e-3
        on the chain example, but 4.2 % and a factor 2.8 on end damage on the taut
        wire at Tp 10 s), without it every case computes them.

    Returns
    -------
    CaseSetResult
        The same numbers, bit for bit, whichever executor and chunking ran the set.
    """
    if client is not None:
        if executor is not None:
            raise InputError("client", client, "-", "give executor or client, not both")
        executor = client
    if chunk_size is None and executor is not None:
        chunk_size = default_chunk_size(len(scatter.states), _worker_count(executor))
    plan = plan_cases(
        scene, scatter, fatigue=fatigue, years=years, chunk_size=chunk_size,
        residual_span=residual_span, residual_tolerance=residual_tolerance,
    )  # fmt: skip
    if executor is None and engine is None:
        engine = set_engine(plan.template)
    if plan.adaptive:
        return assemble_cases(plan, _anchored(plan, engine, executor, chunk_size, progress))
    n, done = len(scatter.states), 0
    results: list[ChunkResult] = []
    for res in _run_chunks(plan, engine, executor):
        results.append(res)
        done += len(res.rows)
        if progress is not None:
            progress(done, n)
    return assemble_cases(plan, results)


def _anchored(
    plan: CasePlan,
    engine: Engine | None,
    executor: Any,
    chunk_size: int | None,
    progress: Progress | None = None,
) -> list[ChunkResult]:
    """The passes of the adaptive anchors (:mod:`stochcable.cases.anchor_passes`): the
    anchors' passes with the residuals, pass after pass until
    :func:`~stochcable.cases.residual_anchors.next_anchors` asks for no more, then
    every other case linear, each case once; ``progress(done, n)`` after each chunk."""
    states = plan.scatter.states
    n, done = len(states), 0
    # (the ratios are known to the fixed point's tolerance only: no finer checks)
    tol = max(float(plan.residual_tolerance or 0.0), plan.template.analysis.linearization.tolerance)
    exact = np.zeros(n, dtype=bool)
    known: dict[int, dict[str, np.ndarray]] = {}
    results: list[ChunkResult] = []
    todo = np.flatnonzero(first_anchors(states, plan.residual_span))
    starts = tuple({} for _ in todo)  # (the first pass: at rest)
    while True:
        if todo.size == 0 and exact.all():
            return results
        last = todo.size == 0
        if last:  # (the linear cases: those with a column start, then the others)
            ready = {i: x for i, x in known.items() if exact[i]}
            first, seeds, rest = split_last_pass(states, np.flatnonzero(~exact), ready)
            passes = [(first, seeds), (rest, None)]
        else:
            passes = [(todo.tolist(), starts)]
        for idx, begin in passes:
            if not idx:
                continue
            chunks, leads, seeds = pass_chunks(states, idx, not last, chunk_size, begin)
            sub = replace(plan, chunks=chunks, leads=leads, starts=seeds)
            for res in _run_chunks(sub, engine, executor):
                results.append(res)
                for j, i in enumerate(res.indices):
                    if j < len(res.starts):
                        known[int(i)] = res.starts[j]
                done += len(res.rows)
                if progress is not None:
                    progress(done, n)
        if last:
            return results
        idx = todo
        exact[idx] = True
        m = _merge(plan, results)
        todo = np.flatnonzero(next_anchors(
            states, plan.residual_span, tol, exact, m.rows, m.stats, m.d_ends, m.linear,
            (m.damage, m.linear_along), damage_slopes(plan.fatigue),
        ))  # fmt: skip
        starts = neighbour_starts(states, todo, {i: x for i, x in known.items() if exact[i]})


def _worker_count(executor: Any) -> int:
    info = getattr(executor, "scheduler_info", None)
    if callable(info):  # dask.distributed.Client
        return max(1, len(info().get("workers", {})))
    return max(1, int(getattr(executor, "_max_workers", 1) or 1))


def _run_chunks(plan: CasePlan, engine: Engine | None, executor: Any):
    """Yield the chunks' results as they finish."""
    family, settings = plan.scatter.family, plan.fatigue
    if executor is None:
        if engine is None:
            engine = set_engine(plan.template)
        for k in range(len(plan.chunks)):
            yield plan.solve(k, engine)
        return
    starts = plan.starts or tuple(() for _ in plan.chunks)
    if hasattr(executor, "scatter") and hasattr(executor, "gather"):  # dask client
        from distributed import as_completed as dask_completed

        shared = executor.scatter(plan.template, broadcast=True, hash=False)
        futures = [executor.submit(solve_chunk, shared, family, part, settings, None, lead,
                                   start, pure=False)
                   for part, lead, start in zip(plan.chunks, plan.leads, starts)]  # fmt: skip
        for fut in dask_completed(futures):
            yield fut.result()
        return
    futures = [
        executor.submit(solve_chunk, plan.template, family, part, settings, None, lead, start)
        for part, lead, start in zip(plan.chunks, plan.leads, starts)
    ]
    for fut in as_completed(futures):
        yield fut.result()


def assemble_cases(plan: CasePlan, results: Iterable[ChunkResult]) -> CaseSetResult:
    """The set's results from the results of its chunks (in any order).

    Parameters
    ----------
    plan : CasePlan
    results : iterable of ChunkResult
        Every chunk of ``plan`` once, or every case of the adaptive anchors' passes
        once (a case's later numbers replace its earlier ones).

    Returns
    -------
    CaseSetResult
    """
    scatter, settings, years = plan.scatter, plan.fatigue, plan.years
    m = _merge(plan, list(results))
    rows, stats, damage, names = m.rows, m.stats, m.damage, m.names
    d_ends = m.d_ends
    # the residuals' corrections of the cases that did not compute them
    law = "hs2" if plan.residual_tolerance is None else "power"
    along = (damage, m.linear_along)
    slopes = damage_slopes(settings)
    interpolate_corrections(
        scatter.states, m.exact, rows, stats, d_ends, m.linear, law, along, slopes
    )
    _warn_interpolated(plan, m.exact)
    s_el = m.s_el
    d_along = {ln: damage[ln][:, 2:] for ln in names}
    p = np.array([s.probability for s in scatter.states])
    has = np.array([r.has_numbers for r in rows])
    ok = np.array([r.status == "ok" for r in rows])
    coverage = {
        "ok": float(p[ok].sum()),
        "with_response": float(p[has].sum()),
        "failed": float(p[~has].sum()),
    }
    totals = {
        ln: _line_totals(p, has, stats[ln], d_ends[ln], d_along[ln], settings.get(ln), years)
        for ln in names
    }
    return CaseSetResult(
        scatter, tuple(rows), names, s_el, stats, d_ends, d_along, totals, coverage,
        years, settings,
    )  # fmt: skip


def _warn_interpolated(plan: CasePlan, exact: np.ndarray) -> None:
    """The set's PhysicsWarning when some cases' residuals were interpolated (none
    when every case computed them): how many computed them, and how."""
    asked = [k.name for k in asked_residuals(plan.template.analysis.linearization)]
    n, k = exact.size, int(np.sum(exact))
    if not asked or k == n:
        return
    how = (
        "the adaptive anchors' columns (period and heading) and Hs, checked to "
        f"{plan.residual_tolerance:g} (stochcable.cases.residual_anchors)"
        if plan.residual_tolerance is not None
        else f"per period and heading the smallest and largest Hs and at most "
        f"{plan.residual_span} Hs steps apart (stochcable.cases.residual_anchors)"
    )
    warn(
        "load-case set: "
        + ", ".join(f"analysis.linearization.{a}" for a in asked)
        + f" computed on {k} of the {n} cases ({how}); the other {n - k} cases' end "
        "statistics, end damage and along-line damage are their linear values times "
        "the computed cases' corrections interpolated in Hs along a period and linearly "
        "in the period between periods ("
        + (
            "the elements' damage checked relative to the line's largest; "
            if plan.residual_tolerance is not None
            else ""
        )
        + "residual_tolerance=None computes every case)",
        PhysicsWarning,
    )


@dataclass
class _Merged:
    """The chunks' numbers in the diagram's order (:func:`_merge`)."""

    names: tuple[str, ...]
    rows: list[Any]
    stats: dict[str, dict[str, np.ndarray]]
    damage: dict[str, np.ndarray]
    d_ends: dict[str, np.ndarray]
    linear: dict[str, np.ndarray]
    exact: np.ndarray
    s_el: dict[str, np.ndarray]
    linear_along: dict[str, np.ndarray]


def _merge(plan: CasePlan, results: list[ChunkResult]) -> _Merged:
    """The numbers of ``results`` by case (a later result of a case replaces an
    earlier one); ``d_ends`` views the end columns of ``damage``."""
    scene, n = plan.scene, len(plan.scatter.states)
    names = tuple(ln.name for ln in scene.lines)
    n_el = {ln.name: sum(seg.elements for seg in ln.segments) for ln in scene.lines}
    for res in results[:1]:  # the engine's counts (the element check may raise defaults)
        n_el = {ln: res.damage[ln].shape[1] - 2 for ln in names}
    stats = {ln: {e: np.full((n, 4), np.nan) for e in ENDS} for ln in names}
    damage = {ln: np.full((n, 2 + n_el[ln]), np.nan) for ln in names}
    rows: list[Any] = [None] * n
    s_el: dict[str, np.ndarray] = {}
    linear = {ln: np.full((n, 2, 4), np.nan) for ln in names}
    exact = np.ones(n, dtype=bool)
    along = {ln: np.full((n, n_el[ln]), np.nan) for ln in names}
    for res in results:
        for j, i in enumerate(res.indices):
            rows[i] = res.rows[j]
        for ln in names:
            for e in ENDS:
                stats[ln][e][res.indices] = res.stats[ln][e]
            damage[ln][res.indices] = res.damage[ln]
            if ln in res.linear:
                linear[ln][res.indices] = res.linear[ln]
            if ln in res.linear_along:
                along[ln][res.indices] = res.linear_along[ln]
        if res.exact is not None:
            exact[res.indices] = res.exact
        for ln, s in res.s_elements.items():
            s_el.setdefault(ln, s)
    for i in range(n):  # (a case not solved yet: the adaptive anchors' passes)
        rows[i] = rows[i] or CaseRow(i, "pending", "not solved yet")
    d_ends = {ln: damage[ln][:, :2] for ln in names}
    return _Merged(names, rows, stats, damage, d_ends, linear, exact, s_el, along)


def _line_totals(
    p: np.ndarray,
    has: np.ndarray,
    stats: dict[str, np.ndarray],
    d_ends: np.ndarray,
    d_along: np.ndarray,
    settings: LineFatigue | None,
    years: float,
) -> LineTotals:
    pw = np.where(has, p, 0.0)
    annual: dict[str, Any] = {}
    life: dict[str, Any] = {}
    gov_d: dict[str, int] = {}
    if settings is not None and has.any():
        dff = settings.design_factor
        for j, e in enumerate(ENDS):
            d = float(np.sum(pw[has] * d_ends[has, j])) * SECONDS_PER_YEAR
            annual[e], life[e] = d, (math.inf if d == 0 else 1.0 / (dff * d))
            gov_d[e] = int(np.argmax(np.where(has, p * np.nan_to_num(d_ends[:, j]), -1.0)))
        along = np.sum(pw[has, None] * d_along[has], axis=0) * SECONDS_PER_YEAR
        annual["along"] = along
        with np.errstate(divide="ignore"):
            life["along"] = np.where(along > 0, 1.0 / (dff * along), np.inf)
    levels: dict[str, float] = {}
    gov_m: dict[str, int] = {}
    for e in ENDS:
        st = stats[e]
        if has.any():
            levels[e] = float(return_level(years, p[has], st[has, 0], st[has, 1], st[has, 2]))
            gov_m[e] = int(np.argmax(np.where(has, st[:, 3], -np.inf)))
    return LineTotals(annual, life, levels, gov_m, gov_d)
