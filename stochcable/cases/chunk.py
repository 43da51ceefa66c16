"""One chunk of a load-case set: the cases that share one engine, solved where the
executor runs them (this process, a worker process, a Dask worker).

A chunk builds its scene's engine once — and a worker keeps the engine of the last
scenes it saw, so chunks of the same set on one worker reuse it — solves its sea states,
and turns the tension spectra into damage rates in one batched call per line.

The cases of a set form runs of ``WARM_RUN`` consecutive positions of the diagram
(0–15, 16–31, …): the first case of a run that a pass solves, and a case whose
heading differs from the case before it, starts its drag fixed point at rest, each
other from the converged σ of the pass's cases before it
(:func:`stochcable.dynamics.groups.group_fixed_point.warm_starts`;
neighbouring sea states of a diagram have neighbouring σ: ≈ 2.7 evaluations a
case, all on the full grid, instead of 7.6 from rest, most of them on a coarse
subset, on the chain example's 200 cases).  A chunk that starts inside a run
solves the pass's earlier cases of that run first (its ``lead``, discarded).  So each case's
numbers depend only on its run and the engine, and the engine is the same wherever it
is built (one BLAS thread per chunk): a set gives the same bits whichever executor ran
it and however it was chunked, and each case equals ``analyze()`` of its sea within
the linearization tolerance.  A chunk pays numba's import once for all its cases: its
banded solves take the compiled LU at any size (:func:`stochcable.compiled.kernels_paid`).
"""

from __future__ import annotations

import contextlib
import dataclasses
import hashlib
import math
import traceback
from collections import OrderedDict
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from threadpoolctl import threadpool_limits

from stochcable.cases.along_spectra import element_densities
from stochcable.cases.fatigue_settings import LineFatigue, curve_factor
from stochcable.cases.scatter import Family, SeaState
from stochcable.compiled import kernels_paid
from stochcable.design import damage_rate
from stochcable.dynamics.engine import Engine, build_engine
from stochcable.dynamics.groups.group_fixed_point import warm_starts
from stochcable.dynamics.groups.lineparts import SMALL_MODAL_DOFS
from stochcable.dynamics.outputs.line_result import MOTION_RESIDUALS
from stochcable.errors import StochcableError, collect_warnings
from stochcable.fidelity.mesh_engine import checked_engine
from stochcable.scene.model import Scene, Sea
from stochcable.scene.residual_kinds import asked_residuals

__all__ = [
    "CaseRow",
    "ChunkResult",
    "solve_chunk",
    "case_sea",
    "engine_template",
    "pilot_state",
    "prepare_worker",
    "set_engine",
    "ENDS",
    "WARM_RUN",
    "run_lead",
    "without_residuals",
]

ENDS = ("end_a", "end_b")
#: Cases of a warm-start run (module docstring): a chunk size that is a multiple of it
#: never solves a case twice. [-]
WARM_RUN = 16
#: Engines a worker keeps, most recent first (a set's scene, and the one before). [-]
_ENGINE_CACHE_SIZE = 2
_ENGINES: OrderedDict[str, Engine] = OrderedDict()


@dataclass(frozen=True)
class CaseRow:
    """One sea state of the set and its outcome.

    Attributes
    ----------
    index : int
        Position in the scatter diagram.
    status : {"ok", "flagged", "not_converged", "failed"}
        ``flagged``: an indicator of a line raised a flag (listed in ``flags``).
    reason : str
        Why the case is not ``ok`` ("" otherwise).
    flags : tuple of str
        ``"<line>:<flag>"`` of every raised indicator flag.
    warnings : tuple of str
        Messages of the warnings of this case's solve.
    """

    index: int
    status: str
    reason: str = ""
    flags: tuple[str, ...] = ()
    warnings: tuple[str, ...] = ()

    @property
    def has_numbers(self) -> bool:
        """Whether the case produced a response (every status but ``failed``)."""
        return self.status != "failed"


@dataclass(frozen=True)
class ChunkResult:
    """The numbers of the cases of one chunk (rows in the order of ``indices``).

    Attributes
    ----------
    indices : ndarray of int
        Positions of the cases in the scatter diagram.
    rows : tuple of CaseRow
    stats : dict
        ``stats[line][end]`` shape (k, 4): mean, σ, Tz, 3-h MPM of the end tension.
    damage : dict of ndarray
        ``[line]`` shape (k, 2 + n_el): damage rate at end_a, end_b and every element
        (NaN: failed case or no fatigue settings). [1/s]
    s_elements : dict of ndarray
        Element midpoint arc length per line. [m]
    linear : dict of ndarray
        ``[line]`` shape (k, 2, 4): per end the linear model's σ, Tz, 3-h MPM and
        damage rate (NaN: failed case, or no fatigue settings).
    exact : ndarray of bool or None
        Per case, whether its residuals were computed (else ``stats`` and ``damage``
        hold its linear values, until :func:`stochcable.cases.run.assemble_cases`
        interpolates the residuals' corrections); None: every case's.
    starts : tuple of dict or None
        Per case, the converged σ of its drag fixed points (per group, as
        :func:`~stochcable.dynamics.groups.group_fixed_point.warm_starts` keeps them;
        None: not kept): the start of the solves of the cases the adaptive anchors
        compute later near it (:func:`solve_chunk`'s ``starts``).  Not stored
        by :func:`stochcable.cases.plan.chunk_to_bytes`. [m/s]
    """

    indices: np.ndarray
    rows: tuple[CaseRow, ...]
    stats: dict[str, dict[str, np.ndarray]]
    damage: dict[str, np.ndarray]
    s_elements: dict[str, np.ndarray]
    linear: dict[str, np.ndarray] = dataclasses.field(default_factory=dict)
    exact: np.ndarray | None = None
    starts: tuple[dict[str, np.ndarray] | None, ...] = ()
    linear_along: dict[str, np.ndarray] = dataclasses.field(default_factory=dict)


def prepare_worker() -> None:
    """Settings of a process that runs chunks for the CLI or the service (a Dask
    worker: ``client.run(prepare_worker)``): :func:`stochcable.runtime.configure`,
    warnings not shown — every case's warnings are recorded in its row, and showing
    them costs ≈ 7 % of a chunk — and the compiled kernels the cases run loaded (numba
    and their cached machine code, ≈ 0.5 s once per process, before the first chunk
    instead of inside it)."""
    import warnings

    from stochcable import runtime
    from stochcable.dynamics.linearization.variance import element_variance_kernel

    runtime.configure()
    warnings.simplefilter("ignore")
    element_variance_kernel()
    with contextlib.suppress(ImportError):  # (no numba: the NumPy paths)
        import stochcable.dynamics.model.band_lu_kernels  # noqa: F401 (kernels_paid)
        import stochcable.line.strumming.kernels  # noqa: F401


def case_sea(scene: Scene, state: SeaState, family: Family) -> Sea:
    """The sea of one state of the set: its spectrum and heading, and the scene's
    directional spreading (if any) about that heading."""
    spreading = None if scene.sea is None else scene.sea.spreading
    return Sea(spectrum=state.spectrum(family), heading=state.heading, spreading=spreading)


def engine_template(scene: Scene, states: tuple[SeaState, ...], family: Family) -> Scene:
    """The scene a set's engine is built from: no time series, the scene's closed-form
    residuals as it asks for them (every kind of :mod:`stochcable.scene.residual_kinds`
    switched on: each case's end statistics and end damage are then those of
    the corrected spectrum, :meth:`stochcable.results.documents.LineResult.end_tension_density`),
    and the sea of its :func:`pilot_state` (an out-of-plane state when there is one:
    the models are then 3-D, and in-plane states are solved by them exactly as by 2-D
    models; the element check chooses the default element counts for it,
    :mod:`stochcable.fidelity.mesh_engine`)."""
    upd: dict[str, Any] = {"analysis": scene.analysis.model_copy(update={"timeseries": None})}
    if states:
        upd["sea"] = case_sea(scene, pilot_state(states), family)
    return scene.model_copy(update=upd)


def pilot_state(states: tuple[SeaState, ...]) -> SeaState:
    """The state a set's default element counts are chosen for: of the out-of-plane
    states if there are any (else of all), the shortest peak period (the highest
    response frequencies, which the element rules scale with), then the highest Hs,
    then the first.  The other states' estimates are checked case by case."""
    out = [s for s in states if abs(math.sin(math.radians(s.heading))) > 1e-9] or list(states)
    return min(out, key=lambda s: (s.tp, -s.hs))


def run_lead(
    states: tuple[SeaState, ...], first: int, members: Any = None
) -> tuple[tuple[int, SeaState], ...]:
    """The cases a chunk starting at position ``first`` solves before its own: the
    earlier cases of the warm-start run it starts in (none at a run's start); of
    ``members`` only (the positions a pass solves) where given."""
    run = range(first - first % WARM_RUN, first)
    keep = run if members is None else sorted(set(run) & {int(i) for i in members})
    return tuple((i, states[i]) for i in keep)


#: Fewest free DOFs of a line for a set to solve it directly when its Foss solve keeps
#: every mode (:func:`set_engine`); below it such a line alone solves its modal
#: equations per frequency in a chunk instead
#: (:data:`~stochcable.dynamics.groups.lineparts.SMALL_MODAL_DOFS`).  A linear set's
#: case by the direct solve over the Foss solve's (interleaved,
#: ``benchmarks/case_cost.py --solvers``): the taut wire (38 free DOFs, every mode kept)
#: 0.55 by the chunk's compiled banded LU; Tuah's single leg (4, every mode kept) 1.05
#: by LAPACK's gbsv (its jobs are under :data:`~stochcable.compiled.SET_KERNEL_MIN_ENTRIES`;
#: 0.95 by the compiled LU, not worth numba's import), 0.90 by its modal equations (one
#: batched 4 × 4 LU per evaluation, no eigenproblem); the chain and the two-segment
#: line (78; 20 and 17 modes kept, not the same equations) 1.1 and 1.2. [-]
DIRECT_MIN_DOFS = 20


def set_engine(template: Scene) -> Engine:
    """The engine of a set's :func:`engine_template`, with the element check
    (:func:`stochcable.fidelity.mesh_engine.checked_engine`: default counts chosen for
    the template's sea, a warning in the row of every case a count does not meet the
    element rules for); the same wherever it is built.

    Where the Foss solve of every line keeps every mode (no static correction: the
    same linear equations as the direct solve, to round-off: σ within 1e-11 on the
    taut wire) and a line has at least :data:`DIRECT_MIN_DOFS` free DOFs, its models
    are built again with ``analysis.solver = "direct"`` on the same statics, element
    counts and element check: its banded solve per frequency costs less than a Foss
    eigenproblem of all modes at every fixed-point evaluation
    (docs/benchmarks/cases.md)."""
    engine = checked_engine(template)
    systems = list(engine.systems.values())
    full = all(sys.solver == "foss" and sys.n_modes >= sys.model.free.size for sys in systems)
    if not (full and any(sys.model.free.size >= DIRECT_MIN_DOFS for sys in systems)):
        return engine
    # (the same statics, element counts and element check: only the solver changes)
    scene = engine.scene
    analysis = scene.analysis.model_copy(update={"solver": "direct"})
    direct = build_engine(scene.model_copy(update={"analysis": analysis}), statics=engine.statics)
    return dataclasses.replace(direct, check=engine.check)


def _engine(template: Scene) -> Engine:
    key = hashlib.sha256(template.model_dump_json().encode()).hexdigest()
    if key in _ENGINES:
        _ENGINES.move_to_end(key, last=False)
        return _ENGINES[key]
    engine = set_engine(template)
    _ENGINES[key] = engine
    _ENGINES.move_to_end(key, last=False)
    while len(_ENGINES) > _ENGINE_CACHE_SIZE:
        _ENGINES.popitem()
    return engine


def _solve_case(engine: Any, sea: Sea, index: int) -> tuple[CaseRow, Any]:
    with collect_warnings() as caught:
        try:
            res = engine.solve(sea)
        except StochcableError as exc:
            return CaseRow(index, "failed", f"{type(exc).__name__}: {exc}"), None
        except Exception as exc:  # a defect must cost its case only, with its trace
            tb = traceback.format_exception_only(type(exc), exc)[-1].strip()
            return CaseRow(index, "failed", f"internal error: {tb}"), None
    msgs = tuple(dict.fromkeys(str(w) for w in caught))
    flags = tuple(
        f"{name}:{f}"
        for name, lr in res.lines.items()
        if lr.indicators is not None
        for f in lr.indicators.flags
    )
    if not res.converged:
        lin = res.linearization
        reason = (
            f"drag linearization not converged after {lin['iterations']} iterations "
            f"(relative change {lin['relative_change']:.3g})"
        )
        return CaseRow(index, "not_converged", reason, flags, msgs), res
    if flags:
        return CaseRow(index, "flagged", "indicator flags: " + ", ".join(flags), flags, msgs), res
    return CaseRow(index, "ok", "", (), msgs), res


def _warm_store(
    store: dict[str, np.ndarray], prev: tuple[int, float] | None, i: int, state: SeaState
) -> dict[str, np.ndarray]:
    """The warm starts of case ``i`` (``state``) after the case ``prev`` (position,
    heading) solved before it: kept within a run and a heading (across the positions
    a pass leaves out), empty at a run's start or at a change of heading."""
    if prev is None or prev[1] != state.heading or prev[0] // WARM_RUN != i // WARM_RUN:
        return {}
    return store


def _strumming_damage(
    engine: Any, name: str, curve: Any, factor: float
) -> tuple[np.ndarray, str] | None:
    """The damage rate of line ``name``'s strumming mode at the two ends and every
    element (the end elements' ranges at the ends), and what the rows say of it; None
    when the line does not strum (docs/strumming.md).  The current is the scene's, the
    same in every sea state, so the same rate is added to every case's wave damage (the
    two summed, as DNV-RP-F204 sums wave and VIV fatigue damage)."""
    table = engine.strumming.get(name)
    if table is None or table.governing is None:
        return None
    mode = table.modes[table.governing]
    el = mode.damage_rate(curve, factor)
    rate = np.concatenate([el[[0, -1]], el])
    msg = (
        f"line {name!r}: strumming of mode {mode.index} ({mode.cycle_rate:.4g} Hz, "
        f"A/D {mode.amplitude_over_d:.3g}) adds a damage rate of {rate[1]:.3g}/s at end_b "
        f"and up to {el.max():.3g}/s along the line to every sea state's damage"
    )
    return rate, msg


def solve_chunk(
    template: Scene,
    family: Family,
    cases: tuple[tuple[int, SeaState], ...],
    fatigue: dict[str, LineFatigue],
    engine: Any = None,
    lead: tuple[tuple[int, SeaState], ...] = (),
    starts: tuple[dict[str, np.ndarray], ...] = (),
) -> ChunkResult:
    """Solve the cases of one chunk on the engine of ``template``.

    Parameters
    ----------
    template : Scene
        :func:`engine_template` of the set's scene (its engine is built once per
        worker and kept).
    family : {"pierson_moskowitz", "jonswap"}
    cases : tuple of (int, SeaState) or (int, SeaState, bool)
        The cases and their positions in the diagram, and whether a case computes the
        residuals of the linear model the scene asks for (default True; False: it is
        solved without them, its corrections interpolated by
        :func:`stochcable.cases.run.assemble_cases`).
    fatigue : dict of LineFatigue
        Settings per line with a fatigue check (validated).
    engine : Engine, optional
        Use this engine instead (the in-process executor's).
    lead : tuple of (int, SeaState), optional
        :func:`run_lead` of the chunk's first case: solved first and discarded (their
        σ start the chunk's first cases, as when the set runs in one chunk).
    starts : tuple of dict, optional
        Per case, the σ its drag fixed points start from (the converged σ of a case
        computed in an earlier pass, :attr:`ChunkResult.starts`; empty: at rest: the
        adaptive anchors' passes, :mod:`stochcable.cases.anchor_passes`), instead of
        the run's warm starts: each case then depends on its own start only.

    Returns
    -------
    ChunkResult
    """
    with threadpool_limits(limits=1), _set_solves(), kernels_paid():
        engine = _engine(template) if engine is None else engine
        linear_engine = None  # (the same engine without the residuals, when needed)
        # (the engine's counts: the element check may have raised the defaults)
        lines = {ln.name: sum(s.elements for s in ln.segments) for ln in engine.scene.lines}
        k = len(cases)
        stats = {ln: {e: np.full((k, 4), np.nan) for e in ENDS} for ln in lines}
        damage = {ln: np.full((k, 2 + n), np.nan) for ln, n in lines.items()}
        linear = {ln: np.full((k, 2, 4), np.nan) for ln in lines}
        exact = np.ones(k, dtype=bool)
        spectra: dict[str, list[np.ndarray]] = {ln: [] for ln in fatigue}
        have: dict[str, list[int]] = {ln: [] for ln in fatigue}
        corrected: dict[str, dict[int, list]] = {ln: {} for ln in fatigue}
        along: dict[str, dict[int, tuple]] = {ln: {} for ln in fatigue}
        linear_along = {ln: np.full((k, n), np.nan) for ln, n in lines.items() if ln in fatigue}
        s_el: dict[str, np.ndarray] = {}
        omega = None
        rows = []
        store: dict[str, np.ndarray] = {}
        prev: tuple[int, float] | None = None
        kept: list[dict[str, np.ndarray]] = []
        for i, state, *_ in lead:  # (discarded: the residuals are not needed)
            linear_engine = linear_engine or without_residuals(engine)
            store = _warm_store(store, prev, i, state)
            with warm_starts(store):
                _solve_case(linear_engine, case_sea(template, state, family), i)
            prev = (i, state.heading)
        for j, (i, state, *flag) in enumerate(cases):
            exact[j] = not flag or bool(flag[0])
            if not exact[j]:
                linear_engine = linear_engine or without_residuals(engine)
            if starts:  # (its own start: the newest of a warm-start history)
                store = {g: x[None] for g, x in starts[j].items()}
            else:
                store = _warm_store(store, prev, i, state)
            with warm_starts(store):
                row, res = _solve_case(
                    engine if exact[j] else linear_engine, case_sea(template, state, family), i
                )
            kept.append({g: x[0].copy() for g, x in store.items()})
            prev = (i, state.heading)
            rows.append(row)
            if res is None:
                continue
            for name, lr in res.lines.items():
                s_el.setdefault(name, lr.s_elements)
                omega = lr.omega
                for e, end in enumerate(ENDS):
                    st, lin = getattr(lr, end), lr.linear_end(end)
                    stats[name][end][j] = (st.mean, st.std, st.tz, st.mpm_3h)
                    linear[name][j, e, :3] = (lin.std, lin.tz, lin.mpm_3h)
                if name in fatigue:
                    ends = np.stack([lr.end_tension_spectrum(e) for e in ENDS])
                    el_spec = lr.tension_spectrum  # (formed at each read: once here)
                    if lr.corrected_spectra is not None:  # the ends' on their own grid
                        corrected[name][j] = [lr.end_tension_density(e) for e in ENDS]
                    if lr.along_line is not None and lr.along_line.computed:
                        along[name][j] = _along_densities(lr, el_spec)
                    spectra[name].append(np.concatenate([ends, el_spec]))
                    have[name].append(j)
        for name, settings in fatigue.items():
            if have[name]:
                curve, factor = curve_factor(settings, template.environment.g, name)
                dens = np.stack(spectra[name]) * factor**2
                damage[name][have[name]] = damage_rate(omega, dens, curve, settings.method)
                strum = _strumming_damage(engine, name, curve, factor)
                if strum is not None:
                    damage[name][have[name]] += strum[0]
                    for j in have[name]:
                        rows[j] = replace(rows[j], warnings=(*rows[j].warnings, strum[1]))
                linear[name][have[name], :, 3] = damage[name][have[name], :2]
                linear_along[name][have[name]] = damage[name][have[name], 2:]
                for j in sorted(corrected[name].keys() | along[name].keys()):
                    ends_c, el = corrected[name].get(j), along[name].get(j)
                    for at, om, dens in _corrected_rows(ends_c, el):
                        damage[name][j, at] = damage_rate(
                            om, dens * factor**2, curve, settings.method
                        )
                        if strum is not None:
                            damage[name][j, at] += strum[0][at]
    idx = np.array([c[0] for c in cases], dtype=int)
    return ChunkResult(
        idx, tuple(rows), stats, damage, s_el, linear, exact, tuple(kept), linear_along
    )


def _corrected_rows(
    ends: list[tuple[np.ndarray, np.ndarray]] | None,
    elements: tuple[np.ndarray, np.ndarray] | None,
) -> list[tuple[slice, np.ndarray, np.ndarray]]:
    """A computed case's corrected densities as damage-rate jobs (columns of its
    damage row, grid, densities (k, n)): the ends' (end_a, end_b: columns 0, 1) and
    the elements' (columns 2 …) in one job where they share a grid (the residual
    lines outside the analysis grid are the same for the ends and the elements: on the
    taut wire, Tuah's leg and the chain always), else one job each."""
    jobs: list[tuple[slice, np.ndarray, np.ndarray]] = []
    if ends is not None:
        jobs += [(slice(k, k + 1), om, d[None]) for k, (om, d) in enumerate(ends)]
    if elements is not None:
        jobs.append((slice(2, None), elements[0], elements[1]))
    if len(jobs) > 1 and all(np.array_equal(om, jobs[0][1]) for _, om, _ in jobs[1:]):
        cols = slice(jobs[0][0].start, jobs[-1][0].stop)  # (contiguous: 0, 1, 2 …)
        return [(cols, jobs[0][1], np.concatenate([d for _, _, d in jobs]))]
    return jobs


@contextlib.contextmanager
def _set_solves():
    """A set reports no node or body motions: their residuals are not computed (the
    end and element tensions the same; on the chain example ≈ 12 ms of a computed
    case's ≈ 53 ms of residuals, docs/benchmarks/cases.md); and a line alone below
    :data:`DIRECT_MIN_DOFS` free DOFs whose Foss solve keeps every mode solves its
    modal equations per frequency
    (:data:`~stochcable.dynamics.groups.lineparts.SMALL_MODAL_DOFS`: the same σ to
    round-off, no eigenproblem at each fixed-point evaluation)."""
    token = MOTION_RESIDUALS.set(False)
    small = SMALL_MODAL_DOFS.set(DIRECT_MIN_DOFS)
    try:
        yield
    finally:
        SMALL_MODAL_DOFS.reset(small)
        MOTION_RESIDUALS.reset(token)


def _along_densities(lr: Any, linear: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The element tensions' spectral densities with the residuals (their
    :class:`~stochcable.dynamics.residuals.along_line.AlongLineResidual` lines on the
    analysis grid extended as the ends', the same grid for every element), stacked
    (n_el, n), from their linear densities ``linear`` (n_el, n_w): the along-line
    damage of a case that computed them
    (:func:`~stochcable.cases.along_spectra.element_densities`)."""
    return element_densities(lr.along_line, lr.omega, linear)


def without_residuals(engine: Engine) -> Engine:
    """``engine`` solving without the residuals of the linear model (the same models
    and caches; its linear results are those of ``engine`` to the bit): for the cases
    whose residuals are interpolated (:mod:`stochcable.cases.residual_anchors`)."""
    analysis = engine.scene.analysis
    off = {kind.name: False for kind in asked_residuals(analysis.linearization)}
    lin = analysis.linearization.model_copy(update=off)
    scene = engine.scene.model_copy(
        update={"analysis": analysis.model_copy(update={"linearization": lin})}
    )
    return dataclasses.replace(engine, scene=scene)
