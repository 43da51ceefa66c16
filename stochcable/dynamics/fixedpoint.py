"""The drag linearization of one line: the σ of the relative velocities iterated to
a fixed point (seed 001 §5.3 steps 5–13), started from the fixed point on a frequency
subset (:func:`linearize`).

Coarse start
------------
On a grid of at least ``COARSE_MIN_FREQUENCIES`` points the drag fixed point is first
iterated on a frequency subset: every ``COARSE_STEP``-th frequency and the last, plus
the full-resolution neighbourhood (± ``COARSE_STEP`` points) of each channel's spectral
peak and of every natural frequency inside the grid whose half-power bandwidth (at the
starting drag) is narrower than two coarse spacings, so a narrow resonance between
coarse points is not missed.  The σ integrals on the subset use the *full grid's*
trapezoid rule applied to the local cubic (4-point Lagrange) interpolant of the
integrand S_i|H|² through the subset (:func:`interpolatory_weights`): on the DESIGN.md
chain the subset σ are within 1e-5 of the full-grid ones at the same drag, against
5e-4 for the trapezoid rule on the subset.  The coarse iteration stops at
``COARSE_TOLERANCE_RATIO`` times the tolerance; its fixed point is only the start of
the full-grid iteration, which runs (first step unmixed) until the usual test passes
on the full grid: the answer is the full-grid fixed point, and the record's iterations
and history count full-grid evaluations only (the coarse stage is
:attr:`~stochcable.dynamics.system.Linearization.coarse`).  The subset solves the same modal
equations per
frequency instead of by the Foss eigenproblem
(:func:`~stochcable.dynamics.solve.solve_free` with ``modal_direct``).  On the chain: 6
coarse evaluations on 51 frequencies and one full-grid evaluation (change 1.1e-5)
instead of 6 full-grid evaluations; end-tension σ equal to 1.5e-7.  Skipped for grids
below ``COARSE_MIN_FREQUENCIES``, subsets above ``COARSE_MAX_FRACTION`` of the grid
(many narrow resonances), ``max_iterations = 1`` and the vector form with a current
(its drag, not the frequencies, dominates).  A line that converges in two full-grid
steps anyway gains nothing and pays the coarse evaluations (the taut wire example:
≈ +3 ms).
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from stochcable.dynamics.blocks import (
    add_blocks,
    block_matvec,
    line_prep,
    trapezoid_weights,
)
from stochcable.dynamics.iteration import FixedPointResult, fixed_point
from stochcable.dynamics.line_loads import (
    LineInputs,
    drag_blocks,
    drag_inputs,
    line_inputs,
)
from stochcable.dynamics.loads import (
    Channel,
    element_mean_square,
)
from stochcable.dynamics.solve import (
    line_response,
    solve_free,
    total_displacement,
)
from stochcable.dynamics.system import (
    CoarseStage,
    Damping,
    Linearization,
    LineSystem,
    Progress,
    noop_progress,
)
from stochcable.dynamics.variance import (
    drag_coefficients,
    end_motion_projections,
    fluid_terms,
    rest_sigmas,
    sigmas_from_free,
    split_sigma,
)
from stochcable.errors import (
    ConvergenceError,
    InputError,
    PhysicsWarning,
    SolverError,
    warn,
)
from stochcable.results.documents import (
    LinearizationRecord,
)
from stochcable.scene.model import AnalysisSettings

# Mixing of the Anderson-accelerated steps of the drag fixed point (the plain steps use
# analysis.linearization.relaxation): undamped Anderson saves one iteration on the
# chain, the taut wire, the guy and a 3-D chain (docs/BENCHMARKS.md "Response analysis").
ANDERSON_MIXING = 1.0

#: Coarse start of the drag linearization (module docstring "Coarse start"): grids with
#: at least COARSE_MIN_FREQUENCIES points are first iterated on every COARSE_STEP-th
#: frequency (plus the neighbourhoods of spectral peaks and narrow resonances) to
#: COARSE_TOLERANCE_RATIO times the tolerance; a subset larger than
#: COARSE_MAX_FRACTION of the grid is not worth it (full grid only).
COARSE_STEP = 4
COARSE_MIN_FREQUENCIES = 80
COARSE_TOLERANCE_RATIO = 0.25
COARSE_MAX_FRACTION = 0.35


# ---------------------------------------------------------------------- coarse start


def relative_change(new: np.ndarray, x: np.ndarray) -> float:
    """max_i |new_i − x_i| / max(|new_i|, 1e-6·max|new|): the convergence measure of
    :func:`stochcable.dynamics.iteration.fixed_point`."""
    den = np.maximum(np.abs(new), 1e-6 * max(float(np.max(np.abs(new), initial=0.0)), 1e-300))
    return float(np.max(np.abs(new - x) / den, initial=0.0))


def interpolatory_weights(omega: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """Quadrature weights on the subset ``omega[idx]`` that stand for the full grid's
    trapezoid rule, (idx.size,). [rad/s]

    W = Pᵀq with q the trapezoid weights of ``omega`` and P (n_omega × n_sub) the local
    4-point Lagrange (cubic) interpolation from the subset (two nodes on each side,
    shifted inward at the ends; exact at the subset points): Σ_a W_a f(ω_a) =
    Σ_j q_j (Pf)(ω_j), the full-grid trapezoid sum of the interpolant of f.  f is
    reproduced wherever it is cubic over a stencil, so the error is O(H⁴) in the
    subset spacing H against O(H²) for the trapezoid rule on the subset (the
    (idx.size < 4) subsets use the highest order they allow)."""
    q = trapezoid_weights(omega)
    ws = omega[idx]
    n_sub = ws.size
    order = min(4, n_sub)
    pos = np.searchsorted(ws, omega)
    lo = np.clip(pos - order // 2, 0, n_sub - order)
    nodes = lo[:, None] + np.arange(order)  # (n_omega, order) stencil of each point
    x = ws[nodes]
    # Lagrange basis, vectorized over the frequencies and the stencil: the ratios
    # r_ab = (ω − x_b)/(x_a − x_b) (r_aa = 1), multiplied in the order b = 0, 1, …
    # (the same products as a loop over a and b)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = (omega[:, None, None] - x[:, None, :]) / (x[:, :, None] - x[:, None, :])
    idx_a = np.arange(order)
    r[:, idx_a, idx_a] = 1.0
    basis = r[:, :, 0].copy()
    for b in range(1, order):
        basis *= r[:, :, b]
    return np.bincount(nodes.ravel(), weights=(q[:, None] * basis).ravel(), minlength=n_sub)


def _coarse_subset(system: LineSystem, inp: LineInputs, damping: Damping) -> np.ndarray | None:
    """Indices of the coarse-start frequencies (module docstring "Coarse start"), or
    None when the grid is too small or the subset would not be much smaller.

    Every ``COARSE_STEP``-th frequency and the last, plus ± ``COARSE_STEP`` points at
    full resolution around the narrow features, those whose half-power band is
    narrower than two coarse spacings: a channel's spectral peak (the band where
    S_i >= S_i,max/2 around its maximum) and a natural frequency inside the grid
    (bandwidth 2ζ_jω_j = φ_jᵀCφ_j, mass-normalized φ_j, C the structural damping plus
    ``damping``, the starting drag).  Broad features are left to the cubic rule
    (:func:`interpolatory_weights`), which is most accurate on a uniform subset."""
    w = inp.omega
    n = w.size
    step = COARSE_STEP
    if n < COARSE_MIN_FREQUENCIES:
        return None
    keep = np.zeros(n, dtype=bool)
    keep[::step] = True
    keep[-1] = True
    coarse_spacing = step * np.gradient(w)
    centers = []
    spectra = inp.weights / np.maximum(trapezoid_weights(w), 1e-300)[:, None]
    for s_i in spectra.T:  # channels: is the half-power band of the peak narrow?
        k = int(np.argmax(s_i))
        if s_i[k] <= 0:
            continue
        low = s_i < 0.5 * s_i[k]
        lo = k - int(np.argmax(low[k::-1])) if np.any(low[: k + 1]) else 0
        hi = k + int(np.argmax(low[k:])) if np.any(low[k:]) else n - 1
        if w[hi] - w[lo] < 2.0 * coarse_spacing[k]:
            centers.append(np.array([k]))
    wn = np.asarray(system.modes.omega)
    inside = np.flatnonzero((wn > w[0]) & (wn < w[-1]))
    if inside.size:
        prep = line_prep(system)
        c = add_blocks(prep.S, drag_blocks(system, damping))
        phi = system.modes.shapes[system.model.free][:, inside]
        band = np.einsum("ij,ij->j", phi, prep.free_rows(block_matvec(c, prep.nodes(phi))))
        near = np.clip(np.searchsorted(w, wn[inside]), 1, n - 1)
        near -= (wn[inside] - w[near - 1]) < (w[near] - wn[inside])  # nearest point
        centers.append(near[band < 2.0 * coarse_spacing[near]])
    centers_ = np.concatenate(centers) if centers else np.zeros(0, dtype=int)
    if centers_.size:
        span = centers_[:, None] + np.arange(-step, step + 1)
        keep[np.clip(span, 0, n - 1).ravel()] = True
    idx = np.flatnonzero(keep)
    return idx if idx.size <= COARSE_MAX_FRACTION * n else None


def subset_inputs(
    system: LineSystem, channels: tuple[Channel, ...], inp: LineInputs, idx: np.ndarray
) -> LineInputs:
    """The inputs on the frequencies ``inp.omega[idx]``, weighted by
    :func:`interpolatory_weights` (the same layout as :func:`line_inputs`)."""
    comps = list(system.model.components)
    spectra = np.stack([c.spectrum for c in channels], axis=1)[idx]
    weights = interpolatory_weights(inp.omega, idx)[:, None] * spectra
    square = None
    for i, ch in enumerate(channels):
        if ch.element_velocity is None and ch.velocity is None:
            continue  # as line_inputs: the mean square goes with the element moments
        sq = element_mean_square(ch)[idx]
        sq = sq[:, :, np.array(comps)[:, None], comps]  # one gather of the d × d part
        sq = np.einsum("weij,w->eij", sq, weights[:, i])
        square = sq if square is None else square + sq

    def take(a: np.ndarray | None, axis: int) -> np.ndarray | None:
        return None if a is None else np.take(a, idx, axis=axis)

    sub = LineInputs(
        inp.omega[idx],
        take(inp.velocity, 2),
        take(inp.inertia_load, 2),
        take(inp.ub, 2),
        weights,
        take(inp.moments, 3),
        square,
    )
    # The drag-independent, per-frequency arrays the full grid has already computed
    # (:func:`base_motion`, :func:`drag_inputs`, :func:`end_motion_projections`, the projected
    # moments of
    # :func:`fluid_terms`) are the same numbers at the subset's frequencies: sliced,
    # not recomputed (0.3 ms of the chain's coarse start).
    n_w, n_ch = inp.weights.shape

    def take_view(a: np.ndarray | None) -> np.ndarray | None:
        """Slice the interleaved (n_w·n_ch·2) last axis of a real view."""
        if a is None:
            return None
        lead = a.shape[:-1]
        return np.ascontiguousarray(
            np.take(a.reshape(lead + (n_w, 2 * n_ch)), idx, axis=len(lead))
        ).reshape(lead + (-1,))

    for key, val in inp.cache.items():
        if key in ("foss", "direct"):
            u, f0, q = val
            sub.cache[key] = (take(u, 2), take(f0, 2), take(q, 2))
        elif key[0] == "drag_inputs":
            sub.cache[key] = (take(val[0], 3), take(val[1], 2))
        elif key[0] == "fluid_m":
            sub.cache[key] = take_view(val)
        elif key[0] == "qproj":
            q_p, wcol, y = val
            sub.cache[key] = (
                take_view(q_p),
                np.ascontiguousarray(wcol.reshape(n_w, n_ch)[idx]).ravel(),
                take(y, 2),
            )
    return sub


def _uniform_subset(n: int) -> np.ndarray:
    """Every ``COARSE_STEP``-th index of n and the last."""
    return np.unique(np.r_[np.arange(0, n, COARSE_STEP), n - 1])


def _coarse_start(
    system: LineSystem,
    channels: tuple[Channel, ...],
    inp: LineInputs,
    settings: AnalysisSettings,
    progress: Progress,
    timing: dict[str, float] | None,
) -> tuple[np.ndarray | None, CoarseStage | None]:
    """The start of the full-grid drag iteration: the fixed point on the coarse subset
    (module docstring "Coarse start"), iterated from the at-rest σ on the subset; or
    (None, None) when the grid is too small, the subset not much smaller, or the
    subset iteration breaks down (non-finite σ, a singular solve): the full-grid
    iteration then starts as without a coarse stage."""
    lin = settings.linearization
    method = lin.method
    n = inp.omega.size
    if n < COARSE_MIN_FREQUENCIES or lin.max_iterations == 1:
        return None, None  # too small, or a single response evaluation asked for
    if method == "vector" and (np.any(system.current_el) or np.any(system.current_node)):
        # the drag of the vector form with a current is a quadrature per element
        # (≈ 15 ms on the chain), not frequency work: a coarse grid saves nothing
        return None, None
    # the full grid's drag-independent arrays first (needed by its iteration anyway):
    # the subsets slice them (subset_inputs)
    end_motion_projections(system, inp, method)
    drag_inputs(system, line_prep(system), inp)
    fluid_terms(system, inp, method)
    # the at-rest start on the uniform part of the subset, whose drag decides which
    # resonances are narrow
    base = _uniform_subset(n)
    sub = subset_inputs(system, channels, inp, base)
    x_rest = rest_sigmas(system, sub, method)
    if not np.all(np.isfinite(x_rest)):
        return None, None
    first = drag_coefficients(system, x_rest, method)
    idx = _coarse_subset(system, inp, first)
    if idx is None:
        return None, None
    if idx.size != base.size:
        sub = subset_inputs(system, channels, inp, idx)
    fp = _coarse_fixed_point(system, sub, first, x_rest, lin, progress, timing)
    if fp is None:
        return None, None
    return fp.x, CoarseStage(int(idx.size), fp.iterations, fp.history, fp.converged)


def _coarse_fixed_point(
    system: LineSystem,
    sub: LineInputs,
    first: Damping,
    x_rest: np.ndarray,
    lin: Any,
    progress: Progress,
    timing: dict[str, float] | None,
) -> FixedPointResult | None:
    """The fixed point on the subset inputs ``sub`` from the at-rest σ ``x_rest`` (whose
    drag is ``first``) to ``COARSE_TOLERANCE_RATIO`` times the tolerance, unconverged
    allowed; None when it breaks down (non-finite σ, a singular subset solve)."""
    method = lin.method
    count = [0]

    def update(x: np.ndarray) -> np.ndarray:
        damping = first if x is x_rest else drag_coefficients(system, x, method)
        t0 = time.perf_counter()
        u_f, _ = solve_free(system, sub, damping, modal_direct=True)
        _add_time(timing, t0)
        new = sigmas_from_free(system, sub, u_f, method)
        count[0] += 1
        if progress is not noop_progress:  # (the change is for the callback only)
            progress(
                "linearization",
                {
                    "line": system.name,
                    "iteration": 0,
                    "coarse_iteration": count[0],
                    "change": relative_change(new, x),
                },
            )
        return new

    tol = COARSE_TOLERANCE_RATIO * lin.tolerance
    try:
        x0 = update(x_rest)  # unmixed first step, as on the full grid
        change0 = relative_change(x0, x_rest)
        if not np.all(np.isfinite(x0)):
            return None
        if change0 <= tol:
            return FixedPointResult(x0, 1, change0, True, (change0,))
        fp = fixed_point(
            update,
            x0,
            tol=tol,
            max_iterations=lin.max_iterations,
            relaxation=lin.relaxation,
            method="anderson" if lin.acceleration == "anderson" else "relaxed",
            mixing=ANDERSON_MIXING,
            allow_unconverged=True,
            name=f"coarse start of the drag linearization of line '{system.name}'",
        )
    except (ConvergenceError, SolverError, np.linalg.LinAlgError):
        return None  # non-finite σ or a singular subset solve
    return FixedPointResult(
        fp.x, fp.iterations + 1, fp.relative_change, fp.converged, (change0,) + fp.history
    )


def linearize(
    system: LineSystem,
    channels: tuple[Channel, ...],
    settings: AnalysisSettings,
    *,
    progress: Progress | None = None,
    timing: dict[str, float] | None = None,
    coarse: bool = True,
) -> Linearization:
    """Drag linearization of one line: iterate the σ of the relative velocities to a
    fixed point (seed 001 §5.3 steps 5–13).

    Parameters
    ----------
    system : LineSystem
    channels : tuple of Channel
        Inputs on the analysis grid.
    settings : AnalysisSettings
        ``linearization`` (method, tolerance, max_iterations, relaxation,
        acceleration, allow_unconverged).
    progress : callable, optional
        Called as ``progress("linearization", {"line", "iteration", "change"})``.
    timing : dict, optional
        Accumulates ``solve_s``.
    coarse : bool, optional
        Start from the fixed point on a frequency subset (module docstring "Coarse
        start"; grids of at least ``COARSE_MIN_FREQUENCIES`` points).  False iterates
        on the full grid from the at-rest start.  Both converge to the full-grid fixed
        point (the same convergence test on the full grid).

    Returns
    -------
    Linearization
        The drag of the last iteration, the record (full-grid evaluations) and the
        response computed with it (whose σ are the record's final σ: the outputs are
        exactly those of the recorded linear system); ``coarse`` the coarse stage.

    Raises
    ------
    ConvergenceError
        If the σ do not settle within ``max_iterations`` and ``allow_unconverged`` is
        false (the message names the line).
    InputError
        For the harmonic form with a current (not defined).

    Notes
    -----
    Start (step 5): the fluid velocity relative to the line at rest — or, for end
    motions, relative to the line following its ends quasi-statically, so an
    end-motion-only scene does not start undamped.  With ``coarse`` (and a large
    enough grid) the same iteration first runs on a frequency subset from there, and
    its fixed point becomes the start (module docstring "Coarse start").  The σ of the
    response to the start's drag (the first iteration) start the fixed-point
    iteration unmixed; then plain steps use ``relaxation`` and Anderson steps the
    mixing ``ANDERSON_MIXING`` (1).  Convergence: the relative change of every σ
    (:func:`stochcable.dynamics.iteration.fixed_point`) below the tolerance on the full
    grid; the record counts every full-grid response evaluation, the first included
    (the coarse ones are in :attr:`Linearization.coarse`).  The last evaluation's
    solve is reused for the outputs (no extra solve).
    """
    lin = settings.linearization
    method = lin.method
    progress = noop_progress if progress is None else progress
    if method == "harmonic" and (np.any(system.current_el) or np.any(system.current_node)):
        raise InputError(
            "analysis.linearization.method",
            "harmonic",
            "-",
            "the harmonic (regular-wave) form has no current term: use "
            "'seed' or 'vector' with a current",
        )
    inp = line_inputs(system, channels)
    step = _Step(system, inp, method, progress, timing)
    name = f"drag linearization of line '{system.name}'"
    # Step 5: the at-rest (quasi-static) σ are a guess, not an iterate: their response
    # starts the iteration unmixed (one iteration fewer than relaxing toward the guess
    # on the chain, taut wire and 3-D benchmarks; same fixed point).  The coarse stage
    # replaces the guess by the subset's fixed point (same first full-grid step).
    x_start, stage = (
        _coarse_start(system, channels, inp, settings, progress, timing) if coarse else (None, None)
    )
    if x_start is None:
        x_start = rest_sigmas(system, inp, method)
    fp = _full_grid_fixed_point(step, step(x_start), lin, name)
    if not fp.converged:
        warn(
            f"{name} did not converge: relative change {fp.relative_change:.3e} after "
            f"{fp.iterations} iterations (tolerance {lin.tolerance:.1e}); the result is "
            "flagged unconverged (increase analysis.linearization.max_iterations)",
            PhysicsWarning,
            stacklevel=2,
        )
    t0 = time.perf_counter()
    # transfer functions of the recorded drag: the last step solved with it
    u_f, c = step.solved
    resp = line_response(system, inp, step.damping, (total_displacement(system, inp, u_f), c))
    _add_time(timing, t0)
    record = linearization_record(system, step.sigma, step.damping, fp, lin.tolerance, method)
    return Linearization(damping=step.damping, record=record, response=resp, coarse=stage)


def _add_time(timing: dict[str, float] | None, t0: float) -> None:
    """Add the time since ``t0`` to ``timing["solve_s"]`` (when timing is kept)."""
    if timing is not None:
        timing["solve_s"] = timing.get("solve_s", 0.0) + time.perf_counter() - t0


class _Step:
    """One full-grid step of the drag fixed point, σ -> drag -> response -> new σ,
    keeping the last drag, σ and solve (the outputs reuse them: no extra solve)."""

    def __init__(
        self,
        system: LineSystem,
        inp: LineInputs,
        method: str,
        progress: Progress,
        timing: dict[str, float] | None,
    ) -> None:
        self.system, self.inp, self.method = system, inp, method
        self.progress, self.timing = progress, timing
        self.iterations = 0
        self.change = np.inf
        self.damping: Damping | None = None
        self.sigma: np.ndarray | None = None
        self.solved: tuple[np.ndarray, Any] | None = None

    def __call__(self, x: np.ndarray) -> np.ndarray:
        system = self.system
        damping = drag_coefficients(system, x, self.method)
        t0 = time.perf_counter()
        u_f, c = solve_free(system, self.inp, damping)  # outputs only at the end
        _add_time(self.timing, t0)
        new = sigmas_from_free(system, self.inp, u_f, self.method)
        self.iterations += 1
        self.change = relative_change(new, x)
        self.progress(
            "linearization",
            {"line": system.name, "iteration": self.iterations, "change": self.change},
        )
        self.damping, self.sigma, self.solved = damping, new, (u_f, c)
        return new


def _full_grid_fixed_point(step: _Step, x0: np.ndarray, lin: Any, name: str) -> FixedPointResult:
    """The fixed point from the first step's σ ``x0`` (its change in ``step.change``),
    the first step counted in the iterations and the history."""
    change0 = step.change
    hint = (
        "increase analysis.linearization.max_iterations, lower relaxation, or set "
        "allow_unconverged to get a flagged result"
    )
    if not np.all(np.isfinite(x0)):
        raise ConvergenceError(
            name, 1, float("nan"), lin.tolerance, hint="the first response gave non-finite σ"
        )
    if change0 <= lin.tolerance or lin.max_iterations == 1:
        fp = FixedPointResult(x0, 1, change0, change0 <= lin.tolerance, (change0,))
        if not fp.converged and not lin.allow_unconverged:
            raise ConvergenceError(name, 1, change0, lin.tolerance, hint=hint, partial=fp)
        return fp
    try:
        fp = fixed_point(
            step,
            x0,
            tol=lin.tolerance,
            max_iterations=lin.max_iterations - 1,
            relaxation=lin.relaxation,
            method="anderson" if lin.acceleration == "anderson" else "relaxed",
            mixing=ANDERSON_MIXING,
            allow_unconverged=lin.allow_unconverged,
            name=name,
        )
    except ConvergenceError as exc:
        partial = exc.partial
        if isinstance(partial, FixedPointResult):
            partial = FixedPointResult(
                partial.x,
                partial.iterations + 1,
                partial.relative_change,
                False,
                (change0,) + partial.history,
            )
        raise ConvergenceError(
            name, exc.iterations + 1, exc.residual, exc.tolerance, hint=hint, partial=partial
        ) from None
    return FixedPointResult(
        fp.x, fp.iterations + 1, fp.relative_change, fp.converged, (change0,) + fp.history
    )


def linearization_record(
    system: LineSystem, sigma: np.ndarray, damping: Damping, fp: Any, tolerance: float, method: str
) -> LinearizationRecord:
    """The record of a converged (or flagged) drag fixed point of one line: the
    iteration history of ``fp`` (a FixedPointResult), the final σ (the
    :func:`drag_coefficients` layout) split into normal and axial, and the linear
    drag (the vector form reports σ_n = |σ| and b_n = trace/2 of its 2×2 blocks)."""
    parts = split_sigma(system, sigma, method)
    if method == "vector":
        sig_n = np.sqrt(parts["normal"][0] ** 2 + parts["normal"][1] ** 2)
        b_n = 0.5 * np.trace(damping.b_normal, axis1=1, axis2=2)
    else:
        sig_n, b_n = parts["normal"][0], damping.b_normal
    return LinearizationRecord(
        method=method,
        converged=fp.converged,
        iterations=fp.iterations,
        relative_change=fp.relative_change,
        history=fp.history,
        tolerance=tolerance,
        sigma_normal=sig_n,
        sigma_axial=parts["axial"],
        b_normal=b_n,
        b_axial=damping.b_axial,
    )
