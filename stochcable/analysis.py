"""The analysis pipeline (Tuah 1982, ch. 5): scene -> statics -> FE model ->
excitation -> drag linearization -> solve -> results.

:func:`analyze` runs the whole pipeline through the engine seam
(:mod:`stochcable.dynamics.engine`): build the sea-independent model once, then solve
it for the scene's sea state.  Each stage is a public function that an engineer can
inspect or replace::

    statics = solve_statics(scene, method="fe")           # stochcable.line.statics
    system  = build_line_system(scene, line, statics.lines[line.name])  # dynamics.model.system
    chans   = line_channels(scene, line, system.positions, omega)   # dynamics.loads.channels
    lin     = linearize(system, chans, scene.analysis)    # dynamics.groups.line_fixed_point
    resp    = solve(system, chans, lin.damping)           # dynamics.solve.line_solve
    out     = line_result(system, chans, lin, scene.analysis)       # dynamics.outputs.line_result

One engine solves every scene (:mod:`stochcable.dynamics.groups`): free bodies with
the lines attached to them form coupled groups, and a line attached to no free body
is the degenerate group of one line and no bodies; every group goes through the same
drag fixed point, the same substructured solve and the same time-series transfer.
The sea channel of all lines shares one realization in the time series
(:mod:`stochcable.dynamics.timeseries.synthesis`).

Choices (see the functions for details)
---------------------------------------
- Model: 2-D (x–z) when ``scene.is_planar``, else 3-D; both ends prescribed.
- Drag damping and added mass distributed like the model mass (consistent by default),
  element direction constant per element (:mod:`stochcable.dynamics.loads.channels`).
- Wave loads (Morison inertia and linearized drag) integrated exactly along each
  element's wet part (:func:`stochcable.dynamics.loads.element_kinematics.element_wave_kinematics`),
  B
  constant per element.
- The σ of the relative velocity of an element is its element mean square
  (:func:`stochcable.dynamics.linearization.variance.relative_velocity_sigmas`).
- ``modes="auto"`` (Foss): all modes up to ``AUTO_ALL_MODES`` free DOFs, else those up
  to ``AUTO_MODE_FACTOR``·ω_max (:mod:`stochcable.dynamics.model.system`); moving ends use
  the quasi-static split (:func:`stochcable.dynamics.solve.line_solve.solve`).
- Drag linearization: a coarse start on a frequency subset with a defect
  correction, then the full grid (:mod:`stochcable.dynamics.groups.coarse`,
  :mod:`stochcable.dynamics.groups.group_fixed_point`).
- Time series: the first 2048 samples go in the document (``to_document(timeseries=
  "full")`` for all); the full series are on
  :class:`~stochcable.results.documents.TimeSeries`.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Mapping
from typing import Any

from stochcable.dynamics.engine import Engine
from stochcable.dynamics.engine import build_engine as _build_unchecked
from stochcable.dynamics.model.system import Progress, noop_progress
from stochcable.errors import PhysicsWarning, warn
from stochcable.fidelity.mesh_engine import checked_build
from stochcable.fidelity.mesh_engine import checked_engine as build_engine
from stochcable.results.documents import Result
from stochcable.scene.model import Scene, load_scene
from stochcable.statics import StaticsResult

__all__ = ["Engine", "analyze", "build_engine"]


def analyze(
    scene: Scene | Mapping[str, Any] | str,
    *,
    statics: StaticsResult | None = None,
    progress: Progress | None = None,
) -> Result:
    """Stochastic response of every line of a scene (Tuah 1982, ch. 5).

    Parameters
    ----------
    scene : Scene, mapping, JSON string or path
        The scene document (validated by :func:`stochcable.scene.model.load_scene`).
    statics : StaticsResult, optional
        A precomputed static equilibrium (default: the FE equilibrium of
        :func:`stochcable.statics.solve_statics`; ignored under adaptive
        fidelity, which changes the mesh).
    progress : callable, optional
        ``progress(stage, info)`` (see :data:`stochcable.dynamics.model.system.Progress`).

    Returns
    -------
    Result
        Statics, modes, linearization record, transfer functions, spectra,
        statistics, time series, timing and warnings.

    Raises
    ------
    InputError
        Invalid scene.
    ConvergenceError
        Statics or drag linearization did not converge (unless
        ``analysis.linearization.allow_unconverged``, which returns a flagged result).
    SolverError
        An undamped resonance on the frequency grid.

    Notes
    -----
    Pipeline: adaptive fidelity (when ``analysis.fidelity`` is set: the mesh, grid,
    modes and tolerance the target error needs) -> :func:`build_engine` (statics, FE
    model about the static shape, modes) -> :meth:`Engine.solve` for the scene's sea
    (input channels, drag linearization, direct or Foss response, spectra
    S_x = Σ_i |H_{x,i}|² S_i and statistics, time series).
    """
    t_start = time.perf_counter()
    scene = load_scene(scene)
    progress = noop_progress if progress is None else progress
    plan = None
    if scene.analysis.fidelity is not None:
        scene, plan = _plan_fidelity(scene, progress)
        statics = None  # the mesh changed
    if plan is not None:  # (the planned counts: no element check)
        result = _build_unchecked(scene, progress=progress).solve(progress=progress)
        return _with_plan(result, plan, time.perf_counter() - t_start)
    # the element check (stochcable.fidelity.mesh_engine): default counts that meet
    # the element rules, a warning on the counts that do not
    engine, result = checked_build(scene, statics=statics, progress=progress)
    if result is None:
        result = engine.solve(progress=progress)
    if engine.scene is scene:
        return result
    timing = dict(result.timing)  # (with the pilot on the default mesh)
    timing["total_s"] = time.perf_counter() - t_start
    return dataclasses.replace(result, timing=timing)


def _plan_fidelity(scene: Scene, progress: Progress) -> tuple[Scene, Any]:
    """The scene with the settings adaptive fidelity chose, and the plan."""
    from stochcable.fidelity import apply_fidelity, choose_fidelity  # (only when asked)

    progress("fidelity", {})
    target = scene.analysis.fidelity.target_error
    # the planner runs pilot analyses of the scene: without the request itself
    base = scene.model_copy(
        update={"analysis": scene.analysis.model_copy(update={"fidelity": None})}
    )
    # exact_wave_integration stays False: its element rule alone can leave a short
    # line with a single element (no free node); the surface rule is conservative
    # with the exact element integration of the wave loads
    plan = choose_fidelity(base, target, evaluate=analyze)
    return apply_fidelity(base, plan), plan


def _with_plan(result: Result, plan: Any, total_s: float) -> Result:
    """The result with its fidelity plan, the planning time in ``total_s``, and the
    warnings of what the plan could not bound first."""
    messages = list(result.warnings)
    for text in reversed(fidelity_warnings(plan)):
        warn(text, PhysicsWarning)
        messages.insert(0, text)
    timing = dict(result.timing)
    timing["total_s"] = total_s
    return dataclasses.replace(result, warnings=tuple(messages), fidelity=plan, timing=timing)


def fidelity_warnings(plan: Any) -> list[str]:
    """The warnings of a fidelity plan that does not meet its target: an unbounded
    response tail (what is unbounded and the fix), a linear model whose own error
    exceeds the target, and every limit of the scene model the plan hit (what it leaves
    unresolved), each with the plan's error estimate."""
    out = []
    est = plan.error_estimate
    if not plan.tail_bounded:
        out.append(
            "adaptive fidelity could not bound the response tail: the response "
            f"variance above the pilot's top {plan.pilot.get('omega_max', plan.omega_max):.3g}"
            f" rad/s is not bounded within the target error {plan.target_error:g} "
            f"(band ω_max {plan.omega_max:.3g} rad/s, band error ≥ {est['band']:.2g}, a "
            "lower bound).  Typical cause: an end-motion spectrum with an ω⁻⁵ tail "
            "drives inertia loads whose tension spectrum decays like ω⁻¹, so the "
            "tension σ grows like log ω_max; band-limit the motion spectrum or give the "
            "end motion as a vessel RAO"
        )
    model = est.get("linearization_model", 0.0)
    if model > plan.target_error:
        out.append(
            f"adaptive fidelity cannot meet the target error {plan.target_error:g}: the "
            f"linear model's own σ error against the nonlinear time domain is estimated "
            f"at {model:.2g} ({plan.model_error_basis}); the plan resolves the "
            f"discretization to {est.get('discretization', est['total']):.2g}, the "
            f"answer carries both (total {est['total']:.2g}).  Check a design value "
            "against a nonlinear time-domain analysis (stochcable.reference) or use a "
            "target_error of at least the model error"
        )
    if plan.limits:
        met = est.get("discretization", est["total"]) <= plan.target_error
        out.append(
            "adaptive fidelity reached the scene model's limits for the target error "
            f"{plan.target_error:g}: best plan within them, estimated discretization "
            f"error {est.get('discretization', est['total']):.2g} ("
            + (
                "within the target, but part of it is an estimate, not a bound"
                if met
                else "the target is NOT met"
            )
            + "): "
            + "; ".join(plan.limits)
            + ".  Use a larger "
            "analysis.fidelity.target_error, or add damping to the lightly damped modes"
        )
    return out
