"""Adaptive fidelity: model only what a scene needs.

:func:`choose_fidelity` picks the frequency grid, the elements per segment, the kept
modes and the linearization tolerance of a scene for a target relative error of the
response standard deviations, and records every choice with its reason and its error
estimate in a :class:`~stochcable.fidelity.plan.FidelityPlan`; :func:`apply_fidelity`
returns a new scene with the plan's settings (the input scene is never modified).

The steps: the static geometry of every segment (:mod:`stochcable.fidelity.meshing`),
the input band and a pilot analysis whose response spectra are bounded
(:mod:`stochcable.fidelity.pilot`; ``evaluate`` runs it), then the band, elements,
grid, modes and linearization tolerance by the rules and error budget of
:mod:`stochcable.fidelity.rules`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from pydantic import ValidationError

from stochcable import validation as _v
from stochcable.fidelity.limits import (
    check_plan_memory,
    elements_limit,
    omega_count_limit,
    planned_scene_error,
)
from stochcable.fidelity.meshing import (
    Segments,
    mesh_rules,
    segment_geometry,
    segments_scene,
    static_touchdowns,
)
from stochcable.fidelity.model_error import linearization_model_error
from stochcable.fidelity.pilot import (
    Evaluate,
    InputBand,
    Pilot,
    base_count,
    base_error,
    input_summary,
    modal_bandwidths,
    run_pilot,
)
from stochcable.fidelity.plan import Choice, FidelityPlan
from stochcable.fidelity.rules import (
    AUTO_FACTOR,
    BUDGET,
    DIRECT_MODES,
    MIN_TAIL_EXCESS,
    MODE_ERROR_CONSTANT,
    PEAK_RESOLVED,
    crossing_down,
    crossing_up,
    grid_points,
    points_per_bandwidth,
    tail_above,
    tail_below,
    tail_exponent,
    union_grid,
)
from stochcable.scene.model import OmegaGrid, Scene, load_scene
from stochcable.statics import solve_statics

__all__ = [
    "BUDGET",
    "Choice",
    "FidelityPlan",
    "choose_fidelity",
    "apply_fidelity",
    "grid_values_supported",
]


def choose_fidelity(
    scene: Scene | Any,
    target_error: float = 0.01,
    *,
    evaluate: Evaluate,
    exact_wave_integration: bool = False,
    allow_grid_values: bool | None = None,
) -> FidelityPlan:
    """Settings that meet a target error of the response σ at the least cost.

    Parameters
    ----------
    scene : Scene or document
        The scene; its own accuracy settings are ignored (except the solver's
        linearization method and structural damping).
    target_error : float, default 0.01
        Target relative error of the σ of end tensions and motions. [-]
    evaluate : callable, scene -> result
        The pilot analysis: the frequency-domain analysis of a scene, without a fidelity
        request (the orchestrator passes :func:`stochcable.analyze`; the scenes it is
        given have ``analysis.fidelity`` None when ``scene`` has).  Its result is read
        as described in :mod:`stochcable.fidelity.pilot`.
    exact_wave_integration : bool, default False
        Whether the engine integrates the wave loads exactly over each element (then the
        wave-load element rule is dropped).
    allow_grid_values : bool, optional
        Use a non-uniform grid (``analysis.omega.values``); default: when
        ``OmegaGrid`` has a ``values`` field.

    Returns
    -------
    FidelityPlan

    Notes
    -----
    See :mod:`stochcable.fidelity.rules` for the rules; the discretization's share of
    the target is what the linear model's own error
    (:mod:`stochcable.fidelity.model_error`) leaves of it.  Cost: one static solve and
    one pilot analysis (log grid of :data:`~stochcable.fidelity.pilot.PILOT_COUNT`
    points, kh = 1 at its top, doubled up to ``PILOT_EXTENSIONS`` times while the
    response tail is unbounded or the pilot's top is below 2·ω_max).
    """
    scene = load_scene(scene)
    eps = _v.in_range("target_error", target_error, "-", 0.0, 0.5, lo_open=True)
    grid_values = grid_values_supported() if allow_grid_values is None else allow_grid_values
    try:
        return _plan(scene, eps, evaluate, exact_wave_integration, bool(grid_values))
    except ValidationError as exc:  # a pilot or planned scene the model rejects
        raise planned_scene_error(exc, eps) from None


def _plan(
    scene: Scene,
    eps: float,
    evaluate: Evaluate,
    exact_wave_integration: bool,
    allow_grid_values: bool,
) -> FidelityPlan:
    """:func:`choose_fidelity` on a loaded scene and a checked target."""
    statics = solve_statics(scene, method="fe")
    geo = segment_geometry(scene, statics, tds := static_touchdowns(scene))
    inputs = input_summary(scene)
    pilot_args = (exact_wave_integration, evaluate)
    pilot = run_pilot(scene, geo, inputs, BUDGET["band"] * eps, *pilot_args)
    model, basis = linearization_model_error(pilot.result.lines, tds)
    disc = eps - model if model < eps else eps  # a smaller band share: a pilot further
    pilot = run_pilot(scene, geo, inputs, BUDGET["band"] * disc, *pilot_args, after=pilot)
    share = {k: v * disc for k, v in BUDGET.items()}
    band = _choose_band(pilot, inputs, share["band"])
    el_args = (band.omega2, band.omega_max, share["elements"], inputs.k_load)
    segs, el_choices, el_err = mesh_rules(scene, geo, *el_args, exact_wave_integration)
    segs, el_limit, el_factor = _clip_elements(segs)
    el_err *= el_factor  # the element error grows like h²
    solver, modes, mode_err, mode_choices = _choose_modes(
        pilot, segs, band.omega_max, share["modes"]
    )
    tol = share["linearization"]
    # what the other parts leave of the target (used only when the grid hits its limit)
    slack = sum(share.values()) - (band.error + el_err + mode_err + tol + share["grid"] / 2.0)
    grid = _choose_grid(scene, pilot, band, share["grid"], bool(allow_grid_values), slack)
    tol_choice = Choice(
        "analysis.linearization.tolerance",
        tol,
        "fraction of the target: the fixed point's remaining error ≈ "
        "the last relative change of the σ",
        tol,
    )
    parts = {
        "band": band.error,
        "grid": grid.error,
        "elements": el_err,
        "modes": mode_err,
        "linearization": tol,
    }
    if grid.unresolved or grid.base_clipped:
        parts["grid_unresolved"] = grid.unresolved_error
    parts["discretization"] = float(sum(parts.values()))
    parts["linearization_model"] = model
    parts["total"] = parts["discretization"] + model
    n_el = sum(sum(n for _, _, n in v) for v in segs.values())
    cost = {
        "elements": float(n_el),
        "frequencies": float(grid.n_freq),
        "elements_x_frequencies": float(n_el * grid.n_freq),
    }
    return FidelityPlan(
        target_error=eps,
        omega_min=float(band.omega_min),
        omega_max=float(band.omega_max),
        omega_count=grid.count_linear,
        omega_values=tuple(float(x) for x in grid.values),
        segments=segs,
        solver=solver,
        modes=modes,
        tolerance=float(tol),
        choices=(*band.choices, *el_choices, grid.choice, *mode_choices, tol_choice),
        error_estimate=parts,
        cost=cost,
        tail_bounded=bool(pilot.bounded),
        model_error_basis=basis,
        omega_response=float(band.omega2),
        pilot=pilot.info,
        grid_resolved=not (grid.unresolved or grid.base_clipped),
        limits=_limits_hit(grid, el_limit, band.omega_max),
    )


def _clip_elements(segs: Segments) -> tuple[Segments, str, float]:
    """The segments with every element count within the scene model's limit on
    ``lines[*].segments[*].elements``, a note when one was clipped, and the factor
    (n/limit)² of the element error estimate (it grows like h²; 1 when none was)."""
    limit = elements_limit()
    out: Segments = {}
    clipped, factor = [], 1.0
    for name, parts in segs.items():
        out[name] = tuple((i, L, min(n, limit)) for i, L, n in parts)
        clipped += [f"lines[{name}].segments[{i}]" for i, _, n in parts if n > limit]
        factor = max([factor] + [(n / limit) ** 2 for _, _, n in parts])
    if not clipped:
        return segs, "", 1.0
    return (
        out,
        f"{', '.join(clipped)}: the element rules ask for more than the scene model's "
        f"limit of {limit} elements per segment; clipped to it (element error estimate "
        f"× {factor:.3g})",
        factor,
    )


def _limits_hit(grid: _Grid, el_limit: str, omega_max: float) -> tuple[str, ...]:
    """One sentence per limit of the scene model the plan hit."""
    out = [el_limit] if el_limit else []
    if grid.base_clipped:
        out.append(
            "analysis.omega.count: the input spectra alone need a finer linear grid "
            f"on [ω_min, {omega_max:.3g}] rad/s than the scene model's limit of "
            f"{omega_count_limit()} frequencies; grid at the limit (estimated σ error "
            f"{grid.unresolved_error:.2g})"
        )
    if grid.unresolved:
        w_n, b_n = min(grid.unresolved, key=lambda p: p[1])
        out.append(
            f"analysis.omega.count: resolving every lightly damped mode in the band up "
            f"to {omega_max:.3g} rad/s needs more than the scene model's limit of "
            f"{omega_count_limit()} frequencies; {len(grid.unresolved)} mode(s) "
            f"(narrowest half-power bandwidth {b_n:.3g} rad/s at {w_n:.3g} rad/s) are "
            f"left unresolved (estimated σ error {grid.unresolved_error:.2g})"
        )
    return tuple(out)


# ------------------------------------------------------------------------- band


@dataclass(frozen=True)
class _Band:
    omega_min: float
    omega_max: float
    omega2: float  # ω₂ = √(m₂/m₀) of the response spectra (largest) [rad/s]
    error: float  # σ error the band leaves [-]
    choices: tuple[Choice, ...]


def _choose_band(pilot: Pilot, inputs: InputBand, band_share: float) -> _Band:
    """ω_max and ω_min from the pilot's response spectra (variance above ω_max ≤ 80 %,
    below ω_min ≤ 20 % of twice the band share), and the band error they leave."""
    w, spectra = pilot.omega, pilot.spectra
    lim_hi = 2.0 * band_share * 0.8  # variance fractions (σ error ≈ half)
    lim_lo = 2.0 * band_share * 0.2
    w_max, w_min, w2 = 0.0, math.inf, 0.0
    detail = []
    for name, s in spectra.items():
        if s.max() <= 0:
            continue
        p = tail_exponent(w, s)
        above = tail_above(w, s, p)
        below = tail_below(w, s)
        m0 = below[-1] + (above[-1] if np.isfinite(above[-1]) else 0.0)
        if m0 <= 0:
            continue
        fa = np.where(np.isfinite(above), above / m0, np.inf)
        hi = crossing_up(w, fa, lim_hi)
        lo = crossing_down(w, below / m0, lim_lo)
        w_max, w_min = max(w_max, hi), min(w_min, lo)
        m2 = np.trapezoid(w**2 * s, w)
        w2 = max(w2, math.sqrt(m2 / np.trapezoid(s, w)))
        detail.append(f"{name}: tail S ∝ ω^-{p:.2g} at the pilot top, ω_hi {hi:.3g}")
    if not detail:  # no response at all: keep the input band
        w_min, w_max, w2 = inputs.omega_lo, inputs.omega_hi, inputs.omega2
    w_max = min(max(w_max, 1.05 * w_min), float(w[-1]))
    band_err = _band_error(w, spectra, w_min, w_max)
    tail_note = (
        ""
        if pilot.bounded
        else "; a response tail is NOT bounded at the pilot top "
        f"{w[-1]:.3g} rad/s (decays slower than ω^-{1 + MIN_TAIL_EXCESS:g}, e.g. "
        "an ω⁻⁵ end-motion spectrum driving inertia loads): σ depends on the band "
        "and the band error is a lower bound"
    )
    choices = (
        Choice(
            "analysis.omega.max",
            w_max,
            f"response variance above ≤ {lim_hi:.2g} m0 (pilot to "
            f"{w[-1]:.3g} rad/s + power-law tail); " + "; ".join(detail) + tail_note,
            band_err,
        ),
        Choice(
            "analysis.omega.min",
            w_min,
            f"response variance below ≤ {lim_lo:.2g} m0 (pilot from {w[0]:.3g} rad/s)",
            0.0,
        ),
    )
    return _Band(w_min, w_max, w2, band_err, choices)


def _band_error(w: np.ndarray, spectra: dict[str, np.ndarray], w_min: float, w_max: float) -> float:
    """σ error left by the band: the largest variance fraction outside it, halved."""
    band_err = 0.0
    for s in spectra.values():
        if s.max() <= 0:
            continue
        p = tail_exponent(w, s)
        above = tail_above(w, s, p)
        below = tail_below(w, s)
        m0 = below[-1] + (above[-1] if np.isfinite(above[-1]) else 0.0)
        fa = np.interp(math.log(w_max), np.log(w), np.where(np.isfinite(above), above, np.nan)) / m0
        fb = np.interp(math.log(w_min), np.log(w), below) / m0
        band_err = max(band_err, 0.5 * ((fa if np.isfinite(fa) else 1.0) + fb))
    return band_err


# ------------------------------------------------------------------------- grid


@dataclass(frozen=True, eq=False)
class _Grid:
    count_linear: int  # points of the linear grid at the finest spacing
    values: np.ndarray  # the non-uniform union grid [rad/s]
    n_freq: int  # points of the grid applied
    error: float
    choice: Choice
    unresolved: tuple[tuple[float, float], ...] = ()  # (ω_j, b_j) beyond the count limit
    unresolved_error: float = 0.0  # estimated σ error they leave [-]
    base_clipped: bool = False  # the inputs' own spacing is finer than the limit allows


def _choose_grid(
    scene: Scene,
    pilot: Pilot,
    band: _Band,
    grid_share: float,
    allow_values: bool,
    slack: float = 0.0,
) -> _Grid:
    """The base linear spacing from the input spectra, refined around the pilot's
    lightly damped modes in the band (half of the grid share each), within the scene
    model's limit on ``analysis.omega.count`` (see :func:`_within_limit`)."""
    w_min, w_max = band.omega_min, band.omega_max
    limit = omega_count_limit()
    n_bw = points_per_bandwidth(grid_share / 2.0)
    base = base_count(scene, w_min, w_max, grid_share)
    # the inputs' own spacing beyond the limit: its error measured at the limit
    base_clip = base_error(scene, w_min, w_max, limit) if base > limit else 0.0
    base = min(base, limit)
    dw_base = (w_max - w_min) / (base - 1)
    peaks = _narrow_peaks(scene, pilot, w_min, w_max, dw_base)
    n_all = grid_points(w_max - w_min, min([dw_base] + [b / n_bw for _, b in peaks]))
    peaks, unresolved = _within_limit(pilot, peaks, w_min, w_max, base, n_bw, allow_values, slack)
    dw_fine = min([dw_base] + [b / n_bw for _, b in peaks])
    count_lin = min(grid_points(w_max - w_min, dw_fine), limit)
    values = union_grid(w_min, w_max, base, peaks, n_bw)
    grid_err = 2.0 * math.exp(-math.pi * n_bw) + grid_share / 2.0
    use_values = allow_values and len(values) < count_lin
    n_freq = len(values) if use_values else count_lin
    un_err = _unresolved_error(pilot, unresolved) + base_clip
    choice = Choice(
        "analysis.omega.count" if not use_values else "analysis.omega.values",
        n_freq,
        f"base linear spacing {dw_base:.3g} rad/s ({base} points: trapezoid of S, ω²S, "
        f"ω⁴S of the inputs within {grid_share / 2:.2g}); {len(peaks)} lightly damped "
        f"mode(s) in the band need {n_bw:.2g} points per half-power bandwidth "
        f"(2e^(-πN) ≤ {grid_share / 2:.2g})"
        + (
            f", narrowest {min(b for _, b in peaks):.3g} rad/s at "
            f"{min(peaks, key=lambda p: p[1])[0]:.3g} rad/s"
            if peaks
            else ""
        )
        + (
            "; non-uniform union grid"
            if use_values
            else f"; linear grid at the finest spacing {dw_fine:.3g} rad/s"
            + (f" (a non-uniform grid would need {len(values)})" if len(values) < count_lin else "")
        )
        + (_unresolved_note(unresolved, n_all, limit, un_err) if unresolved else "")
        + (
            f"; the inputs alone need {base_count(scene, w_min, w_max, grid_share)} "
            f"points, above the scene model's limit analysis.omega.count ≤ {limit}: "
            f"trapezoid error at the limit {base_clip:.2g}"
            if base_clip
            else ""
        ),
        grid_err + un_err,
    )
    return _Grid(
        count_lin, values, n_freq, grid_err, choice, tuple(unresolved), un_err, base_clip > 0
    )


def _within_limit(
    pilot: Pilot,
    peaks: list[tuple[float, float]],
    w_min: float,
    w_max: float,
    base: int,
    n_bw: float,
    allow_values: bool,
    slack: float,
) -> tuple[list[tuple[float, float]], list[tuple[float, float]]]:
    """The peaks to resolve and those left unresolved.  All are resolved when the grid
    that does fits the scene model's limit on ``analysis.omega.count`` (the plan is
    then the one of the rules alone).  Otherwise the modes whose spacing the limit
    cannot give are left unresolved, and, narrowest (costliest) first, more of them as
    long as the estimated σ error of all left (:func:`_unresolved_error`) stays within
    ``slack`` (what the other parts leave of the target): the best grid within the
    limit at the least cost."""
    limit = omega_count_limit()

    def count(pk: list[tuple[float, float]]) -> int:
        if allow_values:
            return min(len(union_grid(w_min, w_max, base, pk, n_bw)), _linear_count(pk))
        return _linear_count(pk)

    def _linear_count(pk: list[tuple[float, float]]) -> int:
        dw = min([(w_max - w_min) / (base - 1)] + [b / n_bw for _, b in pk])
        return grid_points(w_max - w_min, dw)

    if count(peaks) <= limit:
        return peaks, []
    order = sorted(peaks, key=lambda p: p[1])  # narrowest first
    k = next((i for i in range(len(order) + 1) if count(order[i:]) <= limit), len(order))
    while k < len(order) and _unresolved_error(pilot, order[: k + 1]) <= slack:
        k += 1
    return order[k:], order[:k]


def _unresolved_note(
    unresolved: list[tuple[float, float]], n_all: int, limit: int, err: float
) -> str:
    """The grid reason's part on the modes the count limit leaves unresolved."""
    w_n, b_n = min(unresolved, key=lambda p: p[1])
    return (
        f"; NOT resolved: resolving every mode needs {n_all} frequencies, above the "
        f"scene model's limit analysis.omega.count ≤ {limit}; {len(unresolved)} "
        f"lightly damped mode(s) (narrowest {b_n:.3g} rad/s at {w_n:.3g} rad/s) are left "
        "unresolved — those the limit cannot reach and, narrowest first, those whose "
        f"estimated σ error fits the target: ≈ {err:.2g} (half the variance fraction the "
        "pilot puts in their pilot bins: an estimate, not a bound)"
    )


def _unresolved_error(pilot: Pilot, unresolved: list[tuple[float, float]]) -> float:
    """Estimated σ error of modes the grid leaves unresolved: half the largest variance
    fraction (over the response spectra) the pilot puts in the pilot intervals that
    hold them (the pilot's log grid does not resolve them either: an estimate)."""
    if not unresolved:
        return 0.0
    w = pilot.omega
    idx = {int(np.clip(np.searchsorted(w, wj) - 1, 0, w.size - 2)) for wj, _ in unresolved}
    sel = np.array(sorted(idx))
    worst = 0.0
    for s in pilot.spectra.values():
        m0 = float(np.trapezoid(s, w))
        if m0 <= 0:
            continue
        part = 0.5 * (s[sel] + s[sel + 1]) * (w[sel + 1] - w[sel])
        worst = max(worst, float(np.sum(part)) / m0)
    return 0.5 * worst


def _narrow_peaks(
    scene: Scene, pilot: Pilot, w_min: float, w_max: float, dw_base: float
) -> list[tuple[float, float]]:
    """(ω_j, bandwidth) of the pilot's modes in the band narrower than
    :data:`~stochcable.fidelity.rules.PEAK_RESOLVED` base spacings (undamped: 1e-6·ω_j)."""
    peaks = []
    for lr in pilot.result.lines.values():
        wn, bw = modal_bandwidths(lr, scene)
        for wj, bj in zip(wn, bw):
            if w_min <= wj <= w_max and bj > 0 and bj < PEAK_RESOLVED * dw_base:
                peaks.append((float(wj), float(bj)))
            elif w_min <= wj <= w_max and bj <= 0:
                peaks.append((float(wj), 1e-6 * float(wj)))
    return peaks


# ------------------------------------------------------------------------ modes


def _choose_modes(
    pilot: Pilot, segs: Segments, w_max: float, mode_share: float
) -> tuple[str, Any, float, tuple[Choice, Choice]]:
    """Solver and kept modes: Foss "auto" when its factor suffices, else the pilot's
    modes up to F·ω_max, or the direct solve when they are many."""
    f_need = math.sqrt(MODE_ERROR_CONSTANT / mode_share)
    n_el_total = max(sum(n for _, _, n in v) for v in segs.values())
    if f_need <= AUTO_FACTOR:
        solver, modes = "foss", "auto"
        mode_err = MODE_ERROR_CONSTANT / AUTO_FACTOR**2
        why = (
            f"Foss 'auto' keeps the modes up to {AUTO_FACTOR:g}·ω_max ≥ F·ω_max, F = "
            f"√({MODE_ERROR_CONSTANT:g}/{mode_share:.2g}) = {f_need:.3g}"
        )
    else:
        wn_all = np.concatenate([np.asarray(lr.modes_omega) for lr in pilot.result.lines.values()])
        n_keep = int(np.count_nonzero(wn_all <= f_need * w_max))
        if n_keep > DIRECT_MODES or n_keep >= n_el_total:
            solver, modes, mode_err = "direct", "auto", 0.0
            why = (
                f"{n_keep} modes up to F·ω_max (F = {f_need:.3g}) > {DIRECT_MODES}: the "
                "direct solve is exact and cheaper"
            )
        else:
            solver, modes = "foss", max(1, n_keep)
            mode_err = MODE_ERROR_CONSTANT / f_need**2
            why = f"modes up to F·ω_max, F = √(C/ε_modes) = {f_need:.3g} (pilot modes)"
    return (
        solver,
        modes,
        mode_err,
        (
            Choice("analysis.solver", solver, why, 0.0),
            Choice("analysis.modes", modes, why, mode_err),
        ),
    )


# ------------------------------------------------------------------------ apply


def grid_values_supported() -> bool:
    """Whether ``OmegaGrid`` accepts ``values`` (a non-uniform grid)."""
    return "values" in getattr(OmegaGrid, "model_fields", {})


def apply_fidelity(scene: Scene | Any, plan: FidelityPlan) -> Scene:
    """A new scene with the plan's settings (the input is not modified).

    Parameters
    ----------
    scene : Scene or document
        The scene the plan was made for.
    plan : FidelityPlan

    Returns
    -------
    Scene
        Segments (possibly split, same properties) with the planned element counts, and
        ``analysis`` with the planned grid, solver, modes and tolerance; the
        non-uniform grid when ``OmegaGrid`` supports ``values`` and the plan chose it.
    """
    scene = load_scene(scene)
    if not isinstance(plan, FidelityPlan):
        raise _v.InputError("plan", type(plan).__name__, "-", "must be a FidelityPlan")
    use_values = (
        any(c.setting == "analysis.omega.values" for c in plan.choices) and grid_values_supported()
    )
    om: dict[str, Any] = {
        "min": plan.omega_min,
        "max": plan.omega_max,
        "count": plan.omega_count,
        "spacing": "linear",
    }
    if use_values:  # pragma: no cover - needs the proposed OmegaGrid.values
        om = {
            "min": plan.omega_min,
            "max": plan.omega_max,
            "count": len(plan.omega_values),
            "values": list(plan.omega_values),
        }
    update = {
        "omega": scene.analysis.omega.model_copy(update=om),
        "solver": plan.solver,
        "modes": plan.modes,
        "linearization": scene.analysis.linearization.model_copy(
            update={"tolerance": plan.tolerance}
        ),
    }
    try:
        planned = segments_scene(scene, plan.segments, update)
    except ValidationError as exc:  # never reaches a user as a pydantic error
        raise planned_scene_error(exc, plan.target_error) from None
    check_plan_memory(planned, plan.target_error)  # the budget of every analysis
    return planned
