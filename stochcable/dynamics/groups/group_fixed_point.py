"""The coupled drag linearization: one fixed point over every line and body of a
group (Tuah 1982, §5.3 steps 5–13, eq. 5.2.2).

The fixed-point variable is the concatenation of every attached line's σ vector
(:func:`stochcable.dynamics.linearization.variance.drag_coefficients` layout) and, per body with a
drag area, the σ of the relative velocity (fluid − body) at its drag point along x, y, z
(:func:`stochcable.dynamics.groups.group.linear_body_drag`: b = ρ·CdA·E|v|, Tuah (1982)
eq. 5.2.2 form with the current).  The iteration mirrors
:func:`stochcable.dynamics.groups.line_fixed_point.linearize`: the start is the fluid velocity
relative to lines and bodies at rest (lines following their moving unattached ends
quasi-statically), the first response starts the Anderson-accelerated iteration
unmixed.  The record is one for the whole group.  On fine grids the start is the
fixed point of a frequency subset, corrected by the full/coarse defect
(:mod:`stochcable.dynamics.groups.coarse`).

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass

import numpy as np

from stochcable.bodies.rigid import RigidBody
from stochcable.dynamics.groups.coarse import (
    COARSE_MIN_FREQUENCIES,
    COARSE_MIN_TOLERANCE,
    CoarseStart,
    coarse_group,
    coarse_subset,
    full_grid_arrays,
    uniform_subset,
)
from stochcable.dynamics.groups.fixed_point_state import (
    Evaluation,
    EvaluationCount,
    FixedPointRun,
)
from stochcable.dynamics.groups.freeline import FreeLine
from stochcable.dynamics.groups.group import GroupSystem, SigmaMap, body_sigma
from stochcable.dynamics.groups.inputs import BodyLoads, CoupledLine
from stochcable.dynamics.linearization.iteration import FixedPointResult
from stochcable.dynamics.linearization.variance import (
    linearization_record,
    quasi_static_motion,
    rest_sigmas,
    sigmas_from_nodes,
)
from stochcable.dynamics.loads.channels import Channel
from stochcable.dynamics.model.blocks import to_freq
from stochcable.dynamics.model.system import Linearization, Progress, Response, noop_progress
from stochcable.dynamics.solve.line_solve import end_tension_from_support
from stochcable.dynamics.solve.node_inputs import LineInputs
from stochcable.errors import ConvergenceError, InputError, PhysicsWarning, SolverError, warn
from stochcable.scene.model import AnalysisSettings, LinearizationSettings

__all__ = ["CoupledLinearization", "linearize_coupled", "warm_starts"]

#: The store of :func:`warm_starts` open in this context (None: every fixed point
#: starts at rest).
_WARM: ContextVar[dict[str, np.ndarray] | None] = ContextVar("warm_starts", default=None)
#: Converged σ a :func:`warm_starts` store keeps per group, and the weights of the
#: polynomial extrapolation of 1, 2 and 3 of them (newest first). [-]
_WARM_ORDER = 3
_EXTRAPOLATION = (np.array([1.0]), np.array([2.0, -1.0]), np.array([3.0, -3.0, 1.0]))

_HINT = (
    "increase analysis.linearization.max_iterations, lower relaxation, or set "
    "allow_unconverged to get a flagged result"
)


@dataclass(frozen=True, eq=False)
class CoupledLinearization:
    """Outcome of :func:`linearize_coupled`.

    Attributes
    ----------
    lines : dict of str to Linearization
        Per line: its drag, its record (the group's iteration history with the
        line's σ and B) and the coupled response (attached ends moving with the
        bodies) per physical channel.
    body_motion : dict of str to ndarray, complex, shape (n_omega, d, n_ch)
        Body response per unit input. [m/unit, rad/unit]
    body_sigma : dict of str to ndarray, shape (3,)
        σ of the relative velocity at the drag point along x, y, z. [m/s]
    body_drag : dict of str to ndarray, shape (3,)
        Linear drag coefficient per direction at the drag point. [N·s/m]
    converged, iterations, relative_change, history, tolerance
        The group's fixed-point record.
    """

    lines: dict[str, Linearization]
    body_motion: dict[str, np.ndarray]
    body_sigma: dict[str, np.ndarray]
    body_drag: dict[str, np.ndarray]
    converged: bool
    iterations: int
    relative_change: float
    history: tuple[float, ...]
    tolerance: float


@contextmanager
def warm_starts(store: dict[str, np.ndarray]) -> Iterator[dict[str, np.ndarray]]:
    """Warm starts of the drag fixed points solved inside the block: each group's
    iteration starts from the σ its last converged fixed points left in ``store``
    (keyed by the group's lines and bodies: extrapolated from the last three) instead
    of the rest start, and leaves its own there — sea states
    solved in order, each from its predecessors' answers
    (:func:`stochcable.cases.chunk.solve_chunk`).

    The fixed point found is the same within the linearization tolerance (the usual
    convergence test ends it; not to the bit: the iterates differ).  A warm start
    that does not converge is dropped for the rest start; a single evaluation
    (``max_iterations`` 1) always starts at rest.

    A warm start iterates on the full grid alone, with no coarse stage
    (:mod:`~stochcable.dynamics.groups.coarse`): the coarse fixed point is the coarse
    model's, a defect away from the full grid's, and from a start already near the
    answer its coarse evaluations and correction rounds cost more than the full-grid
    evaluations they save (the linear sets of docs/benchmarks/cases.md: −7 % a case
    on the chain example, −20 % on the taut wire and Tuah's leg); a start that is a
    case's own converged σ (:func:`stochcable.cases.chunk.solve_chunk` ``starts``)
    then costs one evaluation.

    Parameters
    ----------
    store : dict of str to ndarray
        The last converged σ vectors per group (newest first), filled and read
        here. [m/s]

    Yields
    ------
    dict
        ``store``.
    """
    token = _WARM.set(store)
    try:
        yield store
    finally:
        _WARM.reset(token)


def linearize_coupled(
    lines: Sequence[CoupledLine],
    bodies: Sequence[RigidBody],
    settings: AnalysisSettings,
    *,
    rho: float,
    loads: Mapping[str, BodyLoads] | None = None,
    channels: Sequence[Channel] | None = None,
    progress: Progress | None = None,
    timing: dict[str, float] | None = None,
    coarse: bool | None = None,
    inputs: Mapping[str, LineInputs] | None = None,
) -> CoupledLinearization:
    """Drag linearization and response of lines coupled through rigid bodies: the
    one drag fixed point of the engine (a single line is the group of one line and no
    bodies, :func:`stochcable.dynamics.groups.line_fixed_point.linearize`).

    Parameters
    ----------
    lines : sequence of CoupledLine
        The lines of the group (at least one; all with the same channels).
    bodies : sequence of RigidBody
        The free bodies of the group (static pose as ``position``).
    settings : AnalysisSettings
        ``linearization`` (method, tolerance, max_iterations, relaxation,
        acceleration, allow_unconverged).
    rho : float
        Water density for the body drag. [kg/m³]
    loads : mapping of body name to BodyLoads, optional
        Wave inputs of the bodies (default none).
    channels : sequence of Channel, optional
        The group's channels (names, spectra, grid); default those of the first
        line; required for bodies without lines (a body on springs).
    progress : callable, optional
        ``progress("linearization", {"group", "iteration", "change"})`` (and
        ``"line"`` for a line without bodies).
    timing : dict, optional
        Accumulates ``solve_s``. [s]
    coarse : bool, optional
        Start the full-grid iteration from the fixed point of a frequency subset and
        correct it by the full/coarse defect (:mod:`stochcable.dynamics.groups.coarse`);
        False iterates on the full grid only.  Default: when the tolerance is at
        least ``COARSE_MIN_TOLERANCE`` (1e-6), more than one evaluation is allowed
        and no line has the vector form with a current, under both solvers; skipped
        on grids below ``COARSE_MIN_FREQUENCIES``.
    inputs : mapping of str to LineInputs, optional
        The lines' inputs of their channels when already formed
        (:func:`~stochcable.dynamics.solve.line_loads.with_spectra`); default formed here.

    Returns
    -------
    CoupledLinearization

    Raises
    ------
    ConvergenceError
        When the σ do not settle (unless ``allow_unconverged``).
    SolverError
        A singular body impedance (undamped resonance).

    Notes
    -----
    Module docstrings: the substructured solve
    (:mod:`stochcable.dynamics.groups.group`), the fixed point (Tuah 1982, §5.3 steps
    5–13 over all lines and bodies).  Inside :func:`warm_starts` the iteration
    starts from the group's last converged σ.
    """
    lin = settings.linearization
    method = lin.method
    progress = noop_progress if progress is None else progress
    if channels is None:
        if not lines:
            raise InputError("channels", None, "-", "a group without lines needs its channels")
        channels = lines[0].channels
    if not lines and not bodies:
        raise InputError("lines", 0, "-", "a coupled group needs a line or a body")
    g = GroupSystem(lines, bodies, loads or {}, rho, channels, inp_phys=inputs)
    names = ", ".join(cl.name for cl in g.lines)
    gname = (
        f"drag linearization of line '{names}'"
        if len(g.lines) == 1 and not g.bodies
        else f"coupled drag linearization of lines {names} and bodies "
        f"{', '.join(b.name for b in g.bodies)}"
    )
    # coarse stage (stochcable.dynamics.groups.coarse): the fixed point of a frequency
    # subset supplies the start of the full-grid iteration; its history is kept
    if coarse is None:
        coarse = _coarse_pays(g, lin)
    run = FixedPointRun(method, rho, progress, names, lin, gname, timing)
    store = _WARM.get()
    warm = None if store is None or lin.max_iterations == 1 else _warm_start(store, gname)
    x_rest, fp = None, None
    if warm is not None and np.all(np.isfinite(warm)):
        # a warm start: the full grid alone (no coarse stage, see warm_starts)
        if len(g.lines) == 1 and not g.bodies:
            g.sizes = {g.lines[0].name: warm.size}  # (the σ layout: the line's alone)
            shape_ok = True
        else:  # (the σ layout, from the rest start)
            x_rest = _start(g, method, False)[0]
            shape_ok = warm.shape == x_rest.shape and x_rest.size > 0
        if shape_ok:
            try:  # a start that does not converge: the rest start, as without one
                fp, last = _iterate(g, warm, None, _CoarseGroupSlot(None), run, warm=True)
            except (ConvergenceError, SolverError):
                fp = None
    if fp is None or not fp.converged:
        x_rest, idx, gc = _start(g, method, coarse)
        # (the coarse group in a slot: released by _iterate when its stage is over)
        slot, gc = _CoarseGroupSlot(gc), None
        fp, last = _iterate(g, x_rest, idx, slot, run)
    if store is not None and fp.converged:  # the newest first
        hist = store.get(gname)
        keep = () if hist is None or hist.shape[1] != fp.x.size else tuple(hist)
        store[gname] = np.array((fp.x, *keep[: _WARM_ORDER - 1]))
    if not fp.converged:
        warn(
            f"{gname} did not converge: relative change {fp.relative_change:.3e} after "
            f"{fp.iterations} iterations (tolerance {lin.tolerance:.1e}); the result is "
            "flagged unconverged (increase analysis.linearization.max_iterations)",
            PhysicsWarning,
            stacklevel=2,
        )
    return _outcome(g, last, fp, lin.tolerance, method)


def _warm_start(store: dict[str, np.ndarray], gname: str) -> np.ndarray | None:
    """The warm start of group ``gname`` from ``store``: the polynomial extrapolation
    of its last (up to ``_WARM_ORDER``) converged σ, never negative (neighbouring sea
    states in order: on the chain example's diagram in runs of 8 cases, 4.9
    evaluations a case against 5.2 with 2, 5.8 with the last σ alone and 7.6 from
    rest). [m/s]"""
    hist = store.get(gname)
    if hist is None:
        return None
    coef = _EXTRAPOLATION[hist.shape[0] - 1]
    return np.maximum(coef @ hist, 0.0)


@dataclass(eq=False)
class _CoarseGroupSlot:
    """The coarse group built by the start (or None), handed to :func:`_iterate`,
    which takes it out: the caller keeps no reference to it, so its inputs are
    released once the coarse stage is over.  Not frozen: taking empties it."""

    group: GroupSystem | None

    def take(self) -> GroupSystem | None:
        group, self.group = self.group, None
        return group


def _iterate(
    g: GroupSystem,
    x_start: np.ndarray,
    idx: np.ndarray | None,
    slot: _CoarseGroupSlot,
    run: FixedPointRun,
    warm: bool = False,
) -> tuple[FixedPointResult, Evaluation]:
    """The fixed point from ``x_start`` (the coarse stage on ``idx`` first when not
    None, on the coarse group in ``slot`` when built: taken, so the coarse group's
    inputs are released once its stage is over) and its last evaluation.  ``warm``
    (a warm start, :func:`warm_starts`): the first evaluation opens the Anderson
    memory, so the next step is a secant step rather than a relaxed one."""
    gc = slot.take()
    count = EvaluationCount()
    stage = None
    if idx is not None:
        stage = CoarseStart(g, idx, run, count, group=gc)
        gc = None
        x_coarse = stage.start(x_start)
        if x_coarse is None:
            stage = None
        else:
            x_start = x_coarse
    update = SigmaMap(g, run.method, run.rho, count, run.progress, run.names, run.timing)
    stage_free = stage is None  # (x0 is then the map of x_start itself)
    x0 = update(x_start)
    change0 = count.change
    rounds = 0
    if stage is not None:
        x0, change0, rounds = stage.correct(update, x0, change0)
    coarse_hist = () if stage is None else stage.history
    stage = None  # (its coarse group and inputs released before the full-grid iteration)
    before = (x_start, x0) if warm and stage_free else None
    fp = _full_grid(update, x0, change0, rounds, len(coarse_hist), run, before)
    fp = FixedPointResult(
        fp.x,
        len(coarse_hist) + fp.iterations,
        fp.relative_change,
        fp.converged,
        coarse_hist + fp.history,
    )
    if update.last is None:  # (every evaluation keeps its outcome: not reached)
        raise RuntimeError(f"{run.gname}: no evaluation of the full grid")
    return fp, update.last


def _coarse_pays(g: GroupSystem, lin: LinearizationSettings) -> bool:
    """The default of the coarse start: tolerances of at least
    ``COARSE_MIN_TOLERANCE``, more than one evaluation allowed, and not the vector
    form with a current (its drag is a quadrature per element, ≈ 15 ms on the chain,
    not frequency work: a subset saves nothing)."""
    if lin.tolerance < COARSE_MIN_TOLERANCE or lin.max_iterations == 1:
        return False
    return not (
        lin.method == "vector"
        and any(np.any(cl.system.current_el) or np.any(cl.system.current_node) for cl in g.lines)
    )


def _start(
    g: GroupSystem, method: str, coarse: bool
) -> tuple[np.ndarray, np.ndarray | None, GroupSystem | None]:
    """The at-rest σ of the fixed point (:func:`_rest_start`), the coarse subset
    (:func:`~stochcable.dynamics.groups.coarse.coarse_subset`; None: no coarse stage)
    and the coarse group on it when already built.

    A group without bodies whose coarse stage may run takes its at-rest σ on the
    uniform subset (the coarse start only needs a start and the starting drag of the
    narrow-feature test): the coarse group of the uniform subset is built first and
    kept when the narrow features add no frequency; a group with bodies, on the full
    grid."""
    if coarse and not g.bodies and g.omega.size >= COARSE_MIN_FREQUENCIES:
        full_grid_arrays(g, method)
        base = uniform_subset(g.omega.size)
        gc = coarse_group(g, base)
        x_rest = _rest_start(gc, method)
        g.sizes = gc.sizes
        idx = coarse_subset(g, x_rest, method) if x_rest.size else None
        if idx is not None:
            gc.start_drag = g.start_drag
            return x_rest, idx, gc if np.array_equal(idx, base) else None
        return _rest_start(g, method), None, None
    x_rest = _rest_start(g, method)
    return x_rest, (coarse_subset(g, x_rest, method) if coarse and x_rest.size else None), None


def _rest_start(g: GroupSystem, method: str) -> np.ndarray:
    """σ of lines at rest (quasi-static on their moving ends) and bodies at rest;
    sets ``g.sizes``. [m/s]"""
    parts = [
        # a line alone: by the cached end-motion projections of its σ map (the same
        # numbers, :func:`~stochcable.dynamics.linearization.variance.rest_sigmas`)
        rest_sigmas(cl.system, g.inp_phys[cl.name], method)
        if not cl.attached()
        else sigmas_from_nodes(
            cl.system,
            g.inp_phys[cl.name],
            quasi_static_motion(cl.system, g.inp_phys[cl.name]),
            method,
        )
        for cl in g.lines
    ]
    g.sizes = {cl.name: p.size for cl, p in zip(g.lines, parts)}
    for b in g.drag:
        parts.append(body_sigma(g, b, None))
    return np.concatenate(parts) if parts else np.zeros(0)


def _full_grid(
    update: SigmaMap,
    x0: np.ndarray,
    change0: float,
    rounds: int,
    n_c: int,
    run: FixedPointRun,
    before: tuple[np.ndarray, np.ndarray] | None = None,
) -> FixedPointResult:
    """The full-grid iteration from the output ``x0`` (relative change ``change0``) of
    its first evaluation after ``rounds`` correction rounds and ``n_c`` coarse-stage
    entries: its record (first evaluation included, coarse stage not); ``before``, that
    first evaluation (input, ``x0``), opens the Anderson memory."""
    lin, gname = run.lin, run.gname
    if not np.all(np.isfinite(x0)):
        raise ConvergenceError(
            gname, n_c + 1, float("nan"), lin.tolerance, hint="the first response gave non-finite σ"
        )
    if change0 <= lin.tolerance or lin.max_iterations == 1 or x0.size == 0:
        fp = FixedPointResult(x0, 1, change0, change0 <= lin.tolerance or x0.size == 0, (change0,))
        if not fp.converged and not lin.allow_unconverged:
            raise ConvergenceError(gname, n_c + 1, change0, lin.tolerance, hint=_HINT, partial=fp)
        return fp
    try:
        fp = run.iterate(
            update,
            x0,
            tol=lin.tolerance,
            max_iterations=lin.max_iterations - 1 - rounds,
            allow_unconverged=lin.allow_unconverged,
            name=gname,
            before=before,
        )
    except ConvergenceError as exc:
        raise ConvergenceError(
            gname,
            n_c + exc.iterations + 1,
            exc.residual,
            exc.tolerance,
            hint=_HINT,
            partial=exc.partial,
        ) from None
    return FixedPointResult(
        fp.x, fp.iterations + 1, fp.relative_change, fp.converged, (change0,) + fp.history
    )


def _outcome(
    g: GroupSystem, last: Evaluation, fp: FixedPointResult, tolerance: float, method: str
) -> CoupledLinearization:
    """The record of the converged group from its last evaluation."""
    ls, bs = g.split(last.sigma)
    out = {}
    for cl in g.lines:
        system = cl.system
        damping = last.damping[cl.name]
        sol = last.sol[cl.name]
        nodes = None
        if isinstance(sol, FreeLine):  # read block by block, formed only if asked for
            nodes, disp, sc = sol.response()
        else:
            disp, sc = to_freq(sol[0]), sol[1]
        resp = Response(
            omega=g.omega,
            displacement=disp,
            nodes=nodes,
            support_force=sc,
            end_tension=end_tension_from_support(system, sc),
        )
        record = linearization_record(system, ls[cl.name], damping, fp, tolerance, method)
        out[cl.name] = Linearization(damping=damping, record=record, response=resp)
    xi = last.xi
    motion = {b.name: xi[:, g.off[b.name] : g.off[b.name] + b.n_dof, :].copy() for b in g.bodies}
    return CoupledLinearization(
        lines=out,
        body_motion=motion,
        body_sigma={b.name: bs[b.name].copy() for b in g.drag},
        body_drag={k: v.copy() for k, v in last.body_b.items()},
        converged=fp.converged,
        iterations=fp.iterations,
        relative_change=fp.relative_change,
        history=fp.history,
        tolerance=tolerance,
    )
