"""Nonlinear time-domain reference simulation of one line (Tuah (1982), §4.2, §3.1–3.2).

This is the yardstick of the frequency-domain method, not its main path: tests and
benchmarks run it with the *same* sea realization (the same FFT coefficients X_m of
:mod:`stochcable.sea.realization`) as the linear analysis and compare statistics and
time series, which measures the error of the statistical drag linearization and of
the small-motion assumption.

Modules: :mod:`~stochcable.reference.cable_model` (the nonlinear finite-element model:
elements, drag, seabed, static start), :mod:`~stochcable.reference.cable_excitation`
(realizations and their time series), :mod:`~stochcable.reference.cable_newmark` (the
integrator) and this one (:func:`simulate_line_timedomain` and its result).

Time stepping: Newmark average acceleration (β = 1/4, γ = 1/2; Tuah (1982), eqs.
4.2.7–4.2.11) with full Newton iterations per step on the residual R = M ü + F_int(x) −
F_ext(t, x, u̇) of the free DOFs, Jacobian 4/Δt² M + K_T + 2/Δt C_T (C_T the drag and
seabed velocity Jacobians; the drag's dependence on the tangent's rotation is left out
of the Jacobian — the S_ij of Tuah (1982), eq. 3.2.a.6, "negligible" — so Newton
converges linearly-fast rather than quadratically when the current is strong), with a
backtracking line search on the residual norm. Linear solves are banded LAPACK
(half-bandwidth 2·dim − 1). End tensions are the support reactions (the residual rows of
the prescribed end nodes), the quantity of the statics' ``tension_a``/``tension_b`` and
of the frequency-domain end tension. The excitation starts from the static equilibrium
of this same model and is ramped in by a half-cosine over ``ramp`` seconds; statistics
skip the ramp.

The integrator (:mod:`stochcable.reference.cable_newmark`) is written here rather than
taken from :mod:`stochcable.sea.timeseries` because the ends are *prescribed* and
time-dependent: the internal force of the elements next to the ends depends on t, which
the generic protocol's ``internal_force(u)`` cannot express without losing the
consistent tangent, and the banded Jacobian assembly is specific to the line topology.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from stochcable import validation as _v
from stochcable.errors import InputError, ResolutionWarning, warn
from stochcable.line.mesh import mesh_line
from stochcable.reference.cable_checks import check_seabed_contact
from stochcable.reference.cable_excitation import (
    ExcitationGrid,
    band_limited,
    end_coefficients,
    end_series,
    half_cosine,
    omega_quantile,
    realization_grid,
    wave_series,
)
from stochcable.reference.cable_model import (
    GAUSS_POINTS,
    SLACK_STIFFNESS_RATIO,
    LineModel,
    axes,
    static_equilibrium,
    statics_guess,
)
from stochcable.reference.cable_newmark import (
    integrate,
    newmark_period_error,
    newmark_step_for,
)
from stochcable.scene.model import Line, Scene, load_scene

__all__ = [
    "CableTimeHistory",
    "simulate_line_timedomain",
    "SLACK_STIFFNESS_RATIO",
    "PERIOD_ERROR_TOLERANCE",
    "newmark_period_error",
    "GAUSS_POINTS",
    "NONSTATIONARY_RATIO",
]

PERIOD_ERROR_TOLERANCE = 0.01
"""Largest accepted relative period elongation (ωΔt)²/12 of the average-acceleration
scheme at the highest excitation frequency before a ResolutionWarning. [-]"""

NONSTATIONARY_RATIO = 8.0
"""Largest accepted ratio of the largest to the smallest end-tension σ over windows of
the record after the ramp (:meth:`CableTimeHistory.stationarity_ratio`) before a
ResolutionWarning: the response to a stationary sea is stationary. [-]"""

_ENERGY_QUANTILE = 0.99  # fraction of excitation variance below the "highest" frequency


# --------------------------------------------------------------------------- result


@dataclass(frozen=True, eq=False)
class CableTimeHistory:
    """Nonlinear time-domain response of one line.

    Attributes
    ----------
    line : str
        Line name.
    t : ndarray, shape (n_t,)
        Time, t = 0 at the static start. [s]
    positions : ndarray, shape (n_t, n_nodes, 3)
        Node positions. [m]
    static_positions : ndarray, shape (n_nodes, 3)
        Static equilibrium of this model (the start). [m]
    tension_a, tension_b : ndarray, shape (n_t,)
        End tensions: magnitude of the force between the line and the support at end_a
        and end_b (the reaction rows of the equations of motion: element force plus the
        inertia, weight and hydrodynamic loads lumped on the end node), as the statics'
        ``tension_a``/``tension_b`` and the frequency-domain end tension. [N]
    element_tension : ndarray, shape (n_te, n_el)
        Effective tension of every element at ``element_time``. [N]
    element_time : ndarray, shape (n_te,)
        Times of ``element_tension`` (every ``element_every``-th step). [s]
    static_tension : ndarray, shape (n_el,)
        Element tension at the static start. [N]
    iterations : ndarray of int, shape (n_t,)
        Newton iterations per step (0 at t = 0). [-]
    max_residual : float
        Largest final residual norm (max abs) of all steps. [N]
    tolerance : float
        Newton residual tolerance. [N]
    dt : float
        Integration time step. [s]
    ramp : float
        Length of the half-cosine excitation ramp, excluded from statistics. [s]
    s0 : ndarray, shape (n_nodes,)
        Unstretched arc length of the nodes from end_a. [m]
    """

    line: str
    t: np.ndarray
    positions: np.ndarray
    static_positions: np.ndarray
    tension_a: np.ndarray
    tension_b: np.ndarray
    element_tension: np.ndarray
    element_time: np.ndarray
    static_tension: np.ndarray
    iterations: np.ndarray
    max_residual: float
    tolerance: float
    dt: float
    ramp: float
    s0: np.ndarray
    _meta: dict = field(default_factory=dict, repr=False)

    @property
    def displacements(self) -> np.ndarray:
        """Node displacements from the static position, shape (n_t, n_nodes, 3). [m]"""
        return self.positions - self.static_positions

    def steady(self, start: float | None = None) -> np.ndarray:
        """Boolean mask of the samples used for statistics (t >= start, default the ramp)."""
        t0 = self.ramp if start is None else float(start)
        return self.t >= t0 - 1e-9 * max(self.dt, 1.0)

    def tension_statistics(self, end: str = "b", start: float | None = None) -> dict[str, float]:
        """Mean, standard deviation, min and max of an end tension after the ramp.

        Parameters
        ----------
        end : {"a", "b"}
            Which end. [-]
        start : float, optional
            First time used (default: the ramp length). [s]

        Returns
        -------
        dict
            ``mean``, ``std``, ``min``, ``max``. [N]
        """
        if end not in ("a", "b"):
            raise InputError("end", end, "-", "must be 'a' or 'b'")
        x = (self.tension_a if end == "a" else self.tension_b)[self.steady(start)]
        return {
            "mean": float(x.mean()),
            "std": float(x.std()),
            "min": float(x.min()),
            "max": float(x.max()),
        }

    def stationarity_ratio(self, windows: int | None = None) -> tuple[float, float, float]:
        """Largest over smallest σ of the end tensions over windows after the ramp.

        Parameters
        ----------
        windows : int, optional
            Number of equal windows (default: one per 5 peak periods of the
            excitation, 4 to 16). [-]

        Returns
        -------
        (float, float, float)
            The ratio (the larger of the two ends) [-], the start time of the window of
            the largest σ [s] and the frequency of the largest spectral line of the end
            tension in that window [rad/s].

        Notes
        -----
        The response to a stationary excitation is stationary: window σ's of 5 peak
        periods scatter by a factor of about 2–3 even with slack–taut snaps (measured
        on tuah_1982_single_leg, 8 seeds).  A record that jumps to a persistent
        oscillation tens of times larger is a numerical artefact: the
        average-acceleration scheme conserves the energy of a *linear* system only;
        with the slack/taut switch of an element inside a step it can pump an
        under-resolved axial oscillation (ωΔt of order 2).
        """
        keep = self.steady()
        t = self.t[keep]
        if windows is None:
            w_peak = float(self._meta.get("omega_peak", 0.0)) or 1.0
            windows = int((t[-1] - t[0]) / (5.0 * 2.0 * math.pi / w_peak))
            windows = min(16, max(4, windows))
        n_w = _v.positive_int("windows", windows)
        size = t.size // n_w
        if size < 4:
            return 1.0, float(t[0]), 0.0
        worst = (1.0, float(t[0]), 0.0)
        for x in (self.tension_a[keep], self.tension_b[keep]):
            sig = np.array([x[j * size : (j + 1) * size].std() for j in range(n_w)])
            lo = float(sig.min())
            ratio = float(sig.max()) / lo if lo > 0 else (math.inf if sig.max() > 0 else 1.0)
            if ratio > worst[0]:
                j = int(np.argmax(sig))
                seg = x[j * size : (j + 1) * size]
                spec = np.abs(np.fft.rfft(seg - seg.mean())) ** 2
                w = 2.0 * math.pi * np.fft.rfftfreq(seg.size, self.dt)
                worst = (ratio, float(t[j * size]), float(w[int(np.argmax(spec))]))
        return worst

    def motion_std(self, start: float | None = None) -> np.ndarray:
        """Standard deviation of every node's x, y, z motion after the ramp. [m]"""
        return self.displacements[self.steady(start)].std(axis=0)

    def element_tension_std(self, start: float | None = None) -> np.ndarray:
        """Standard deviation of every element's tension after the ramp. [N]"""
        t0 = self.ramp if start is None else float(start)
        return self.element_tension[self.element_time >= t0 - 1e-9].std(axis=0)


# --------------------------------------------------------------------------- public


def simulate_line_timedomain(
    scene: Scene | dict[str, Any] | str | Path,
    line_name: str | None = None,
    *,
    realization: Any = None,
    duration: float | None = None,
    dt: float | None = None,
    seed: int | None = None,
    ramp: float | None = None,
    method: str | None = None,
    statics: Any = None,
    dim: int | None = None,
    tolerance: float = 1e-7,
    max_iterations: int = 30,
    element_every: int = 1,
    end_realizations: dict | None = None,
    band: tuple[float, float] | None = None,
    internal_damping: float = 0.0,
    mass_matrix: str = "consistent",
    drag: str = "quadratic",
    linear_drag: tuple[Any, Any] | None = None,
    seabed: str = "one_sided",
) -> CableTimeHistory:
    """Nonlinear time-domain response of one line to the scene's sea and end motions.

    Parameters
    ----------
    scene : Scene, mapping, JSON string or path
        The scene document (validated by :func:`stochcable.scene.model.load_scene`).
    line_name : str, optional
        Which line (default: the first). [-]
    realization : SeaRealization, optional
        The sea realization to use (the same one the frequency-domain analysis
        synthesizes from).  Default: ``simulate_sea`` of the scene's spectrum with
        ``duration``, the scene's time-series ``dt`` and ``seed``; a short-crested sea
        (``sea.spreading``) is realized direction by direction with the analysis'
        rule (:func:`stochcable.sea.spreading.simulate_sea_directional`) and each
        direction's waves load the line at its heading (a given realization is then
        refused). [-]
    duration : float, optional
        Simulated length, at most the realization's length (default: the
        realization's length, or the scene's time-series duration, else 600 s). [s]
    dt : float, optional
        Integration step; the realization's step is divided by the smallest integer k
        with Δt_sea/k <= dt (default: the largest step keeping the period error
        (ωΔt)²/12 at the highest excitation frequency below 0.5 %). [s]
    seed : int, optional
        Seed of the realization(s) (default: the scene's time-series seed, else 1). [-]
    ramp : float, optional
        Half-cosine ramp length of the excitation (default 3 peak periods). [s]
    method : {"dsa", "nsa"}, optional
        Spectral amplitude method of new realizations (default: the scene's, else DSA). [-]
    statics : StaticsResult or LineStatics, optional
        Static solution to start from (default: ``statics.solve_statics(scene)``). [-]
    dim : {2, 3}, optional
        Model dimension (default 2 when the scene is planar, else 3). [-]
    tolerance : float, default 1e-7
        Newton tolerance on max |residual| relative to the largest static tension. [-]
    max_iterations : int, default 30
        Newton iterations per step before a ConvergenceError. [-]
    element_every : int, default 1
        Store the element tensions every this many steps. [-]
    end_realizations : dict, optional
        Pre-computed end-motion coefficient arrays ``{"a"|"b": (3, N+1) complex}`` on
        the realization's grid (overrides the scene's end motions). [m]
    band : (float, float), optional
        Keep only the excitation components with band[0] <= ω <= band[1]; the
        frequency-domain analysis synthesizes its series on its ``omega`` range, so
        ``band=(omega.min, omega.max)`` reproduces its excitation exactly.  Default:
        every component of the realization. [rad/s]
    internal_damping : float, default 0
        Axial internal damping BA of every element: the axial force gains
        T_d = BA·(dl/dt)/l0, l0 the element's unstretched length (MoorDyn's line-type
        ``BA`` in N·s, :mod:`stochcable.reference.moordyn`); included in
        ``element_tension`` and the end tensions.  0 (the default): none. [N·s]
    mass_matrix : {"consistent", "lumped"}, default "consistent"
        Element mass and added mass: consistent (m l0 [[1/3, 1/6], [1/6, 1/3]], the
        frequency-domain model's) or lumped (half on each node, MoorDyn's). [-]
    drag : {"quadratic", "static_tangent", "linear"}, default "quadratic"
        Morison drag with the instantaneous element tangent (the default), with the
        static tangent (the frequency-domain model's normal/axial split), or linear
        with ``linear_drag`` (controlled experiments, docs/benchmarks/fd_budget.md). [-]
    linear_drag : (array_like, array_like), optional
        (B_n, B_t) per element for ``drag="linear"``, e.g. a frequency-domain
        analysis' converged ``linearization.b_normal`` and ``b_axial``; no current. [N·s/m²]
    seabed : {"one_sided", "linear"}, default "one_sided"
        The one-sided penalty bed, or its tangent at the static start (bilateral
        spring and dashpot, the frequency-domain model's kind of bed). [-]

    Returns
    -------
    CableTimeHistory
        Positions, tensions and Newton record.

    Raises
    ------
    InputError
        Unknown line, non-integer step ratio, duration beyond the realization.
    ConvergenceError
        Newton did not converge in a step (the message gives step, time, residual).

    Warns
    -----
    ResolutionWarning
        When (ωΔt)²/12 at the highest excitation frequency (99 % of the excitation
        variance below it) exceeds 1 %; when the record after the ramp is not
        stationary (:meth:`CableTimeHistory.stationarity_ratio` above
        :data:`NONSTATIONARY_RATIO`: a numerical blow-up, e.g. of a 3-element slack line
        at Δt = 0.125 s, seeds 3 and 6 of tuah_1982_single_leg).

    Notes
    -----
    Newmark average acceleration (Tuah (1982), eqs. 4.2.7a,b) with Newton iterations
    (eqs. 4.2.8–4.2.11, but with the full tangent re-formed at every iteration) on the
    element equations of seed §3.1 and the Morison loads of eqs. 3.2.a.2–3.2.a.5.  See
    the module docstring for the modelling choices.
    """
    scene = load_scene(scene)
    line = _select_line(scene, line_name)
    ts = scene.analysis.timeseries
    tolerance = _v.positive("tolerance", tolerance, "-")
    max_iterations = _v.positive_int("max_iterations", max_iterations)
    element_every = _v.positive_int("element_every", element_every)
    if dim is None:
        dim = 2 if scene.is_planar else 3
    if dim not in (2, 3):
        raise InputError("dim", dim, "-", "must be 2 or 3")
    if seed is None:
        seed = ts.seed if ts is not None else 1
    method = method or (ts.method if ts is not None else "dsa")

    # ---- the excitation in the frequency domain and the step
    grid = realization_grid(scene, realization, duration, dt, seed, method)
    ends = end_coefficients(scene, line, grid, seed, method, end_realizations)
    ends, seas = band_limited(grid, ends, band)
    if grid.realization is None and not ends:
        raise InputError(
            "scene",
            "no sea and no end motion",
            "-",
            "needs a sea or a prescribed end motion to excite the line",
        )
    wmax, w_peak, k_up, h = _time_step(grid, seas, ends, dt)
    n_steps = int(round(grid.duration / h))
    t = h * np.arange(n_steps + 1)
    if ramp is None:
        ramp = 3.0 * 2.0 * math.pi / w_peak if w_peak > 0 else 0.0
    ramp = _v.nonnegative("ramp", ramp, "s")
    if ramp >= grid.duration:
        raise InputError(
            "ramp", ramp, "s", f"must be shorter than the duration {grid.duration:g} s"
        )

    # ---- model, static start, excitation on the steps, integration
    mesh = mesh_line(line, scene.environment.rho, scene.environment.g)
    ax = axes(dim)
    x3 = statics_guess(scene, line, mesh, statics)
    internal_damping = _v.nonnegative("internal_damping", internal_damping, "N·s")
    if mass_matrix not in ("consistent", "lumped"):
        raise InputError("mass_matrix", mass_matrix, "-", "must be 'consistent' or 'lumped'")
    model, xs, u_cur, u_cur_g, tol_abs = _static_start(
        scene, mesh, x3, dim, tolerance, internal_damping, mass_matrix == "lumped"
    )
    model.set_variant(**_variant(scene, mesh, drag, linear_drag, seabed))
    check_seabed_contact(scene, mesh, model, xs, h, PERIOD_ERROR_TOLERANCE)
    r = half_cosine(t, ramp)
    sl = np.arange(n_steps + 1) % (k_up * grid.n_samples)  # periodic in T_L
    u_wave = u_wave_g = f_in = None
    for heading, x_sea in seas:  # the directions' excitations add
        part = wave_series(
            model, xs @ ax.T, grid.omega, x_sea, heading, scene.environment, ax,
            grid.n_samples, k_up, sl, r[0],
        )  # fmt: skip
        if u_wave is None:
            u_wave, u_wave_g, f_in = part
        else:
            u_wave, u_wave_g, f_in = (a + b for a, b in zip((u_wave, u_wave_g, f_in), part))
    end_disp = end_series(ends, grid.omega, mesh.n_nodes, ax, grid.n_samples, k_up, sl, r)
    pos, ten_el, iters, maxres = integrate(
        model,
        xs,
        u_cur,
        u_cur_g,
        u_wave,
        u_wave_g,
        f_in,
        end_disp,
        t,
        h,
        tol_abs,
        max_iterations,
        element_every,
    )

    # ---- the record, in 3-D coordinates
    y_off = 0.0 if dim == 3 else np.array([0.0, 1.0, 0.0]) * x3[0, 1]
    _, _, Ts, _ = model.elements(xs)
    out = CableTimeHistory(
        line=line.name,
        t=t,
        positions=pos @ ax.T + y_off,
        static_positions=xs @ ax.T + y_off,
        tension_a=ten_el[0],
        tension_b=ten_el[1],
        element_tension=ten_el[2],
        element_time=t[::element_every],
        static_tension=Ts,
        iterations=iters,
        max_residual=maxres,
        tolerance=tol_abs,
        dt=h,
        ramp=ramp,
        s0=mesh.s0,
        _meta={
            "omega_max": wmax,
            "omega_peak": w_peak,
            "upsample": k_up,
            "dim": dim,
            "realization": grid.realization,
            "ends": ends,
            "model": model,
        },
    )
    _check_stationary(out, h)
    return out


def _variant(scene: Scene, mesh: Any, drag: str, linear_drag: Any, seabed: str) -> dict[str, Any]:
    """The checked model variant of :func:`simulate_line_timedomain`."""
    if drag not in ("quadratic", "static_tangent", "linear"):
        raise InputError("drag", drag, "-", "must be 'quadratic', 'static_tangent' or 'linear'")
    if seabed not in ("one_sided", "linear"):
        raise InputError("seabed", seabed, "-", "must be 'one_sided' or 'linear'")
    pair = None
    if drag == "linear":
        if linear_drag is None or len(linear_drag) != 2:
            raise InputError(
                "linear_drag", linear_drag, "N·s/m²", "must be (B_n, B_t) with drag='linear'"
            )
        pair = tuple(np.broadcast_to(np.asarray(b, float), (mesh.n_elements,)) for b in linear_drag)
        if not all(np.all(np.isfinite(b)) and np.all(b >= 0) for b in pair):
            raise InputError("linear_drag", "negative or non-finite", "N·s/m²", "must be >= 0")
        if scene.environment.current:
            raise InputError(
                "linear_drag", "with a current", "N·s/m²", "is linear about zero mean flow"
            )
    return {"drag": drag, "linear_drag": pair, "seabed": seabed}


def _select_line(scene: Scene, line_name: str | None) -> Line:
    if line_name is None:
        return scene.lines[0]
    names = [ln.name for ln in scene.lines]
    if line_name not in names:
        raise InputError("line_name", line_name, "-", f"must be one of {names}")
    return scene.lines[names.index(line_name)]


def _time_step(
    grid: ExcitationGrid,
    seas: tuple[tuple[float, np.ndarray], ...],
    ends: dict[str, np.ndarray],
    dt: float | None,
) -> tuple[float, float, int, float]:
    """The highest excitation frequency (:data:`_ENERGY_QUANTILE` of every channel's
    variance below it), the peak frequency, the upsampling k of the realization's step
    and the step Δt_sea/k: ``dt`` or the largest with (ωΔt)²/12 <= 0.5 % (a
    ResolutionWarning above :data:`PERIOD_ERROR_TOLERANCE`)."""
    omega, dt_sea = grid.omega, grid.dt
    power = np.zeros(omega.size)
    wmax = 0.0
    chans = [x for _, x in seas]
    chans += [c for v_ in ends.values() for c in v_]
    for c in chans:
        p = np.abs(c) ** 2
        if p.sum() > 0:
            wmax = max(wmax, omega_quantile(omega, p, _ENERGY_QUANTILE))
            power = power + p / p.sum()
    w_peak = float(omega[int(np.argmax(power))]) if power.any() else 1.0
    if dt is None:
        # (ωΔt)²/12 <= 0.5 %  ->  ωΔt <= 0.245
        dt_target = 0.245 / wmax if wmax > 0 else dt_sea
    else:
        dt_target = _v.positive("dt", dt, "s")
    k_up = max(1, int(math.ceil(dt_sea / dt_target - 1e-9)))
    h = dt_sea / k_up
    err = newmark_period_error(wmax, h)
    if err > PERIOD_ERROR_TOLERANCE:
        dt_ok = newmark_step_for(wmax, PERIOD_ERROR_TOLERANCE)
        warn(
            f"time step {h:.4g} s gives a Newmark period error (omega dt)^2/12 = {err:.2%} "
            f"at the highest excitation frequency {wmax:.4g} rad/s (> "
            f"{PERIOD_ERROR_TOLERANCE:.0%}); use dt <= {dt_ok:.4g} s",
            ResolutionWarning,
            stacklevel=3,
        )
    return wmax, w_peak, k_up, h


def _static_start(
    scene: Scene,
    mesh: Any,
    x3: np.ndarray,
    dim: int,
    tolerance: float,
    ba: float = 0.0,
    lumped: bool = False,
) -> tuple[LineModel, np.ndarray, np.ndarray, np.ndarray, float]:
    """The model about its own static equilibrium (re-solved from the statics' shape
    ``x3``), the current at the nodes and the drag points, and the absolute Newton
    tolerance (``tolerance`` × the largest static force)."""
    env = scene.environment
    ax = axes(dim)
    model0 = LineModel(mesh, env, x3 @ ax, dim)
    u_cur = env.current_velocity(x3[:, 2]) @ ax  # (n, d)
    # current at the drag quadrature points (of the statics shape; the profile is
    # interpolated in z, the points move millimetres in the re-solve)
    u_cur_g = env.current_velocity(model0.gauss_points(x3)[..., 2]) @ ax  # (ne, ng, d)
    e0, _, T0, _ = model0.elements(x3 @ ax)
    f_ref = max(float(np.abs(T0).max()), float(np.abs(model0.f_gravity).max()), 1e-12)
    tol_abs = tolerance * f_ref
    xs, _ = static_equilibrium(
        model0, x3 @ ax, u_cur, u_cur_g, f_ref, max(1e-3 * tol_abs, 1e-11 * f_ref)
    )
    model = LineModel(mesh, env, xs, dim, ba, lumped)  # added mass about the re-solved tangents
    return model, xs, u_cur, u_cur_g, tol_abs


def _check_stationary(out: CableTimeHistory, h: float) -> None:
    """A ResolutionWarning when the record after the ramp is not stationary
    (:data:`NONSTATIONARY_RATIO`)."""
    ratio, t_jump, w_dom = out.stationarity_ratio()
    if ratio > NONSTATIONARY_RATIO:
        dt_ok = newmark_step_for(w_dom, PERIOD_ERROR_TOLERANCE)
        warn(
            f"the end tension is not stationary: its σ over windows after the ramp varies "
            f"by a factor {ratio:.3g} (threshold {NONSTATIONARY_RATIO:g}), largest in the "
            f"window from t = {t_jump:.4g} s, dominated by {w_dom:.4g} rad/s (omega dt = "
            f"{w_dom * h:.3g}, period error {newmark_period_error(w_dom, h):.0%}): an "
            "under-resolved oscillation pumped by the time stepping (typically at "
            f"slack–taut snaps), not the response; rerun with dt <= {dt_ok:.3g} s or at "
            "least a quarter of the present step",
            ResolutionWarning,
            stacklevel=3,
        )
