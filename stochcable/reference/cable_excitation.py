"""The excitation of the time-domain reference (:mod:`stochcable.reference.cable`): the
realization grid, the sea and end-motion coefficients on it (the realizations of the
frequency-domain analysis: same seeds, same channel order), and their time series on
the integration steps (wave kinematics and wave-inertia loads at the static positions,
ramped end motions)."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from stochcable import validation as _v
from stochcable.dynamics.loads.channels import element_wave_kinematics
from stochcable.dynamics.loads.sea_channels import spectrum_callable
from stochcable.errors import InputError
from stochcable.reference.cable_model import LineModel
from stochcable.scene.model import Environment, Line, Scene
from stochcable.sea import fft as _fft
from stochcable.sea import realization as _sea
from stochcable.sea.kinematics import wave_kinematics
from stochcable.sea.spreading import simulate_sea_directional

__all__ = [
    "ExcitationGrid",
    "realization_grid",
    "end_coefficients",
    "band_limited",
    "spectrum_density",
    "end_motion_generators",
    "upsample",
    "wave_series",
    "end_series",
    "half_cosine",
    "omega_quantile",
]


# ----------------------------------------------------------------- frequency domain


@dataclass(frozen=True, eq=False)
class ExcitationGrid:
    """The realization's frequency grid and length.

    Attributes
    ----------
    realization : SeaRealization or None
        The sea realization (None without a sea).
    length : float
        Period T_L of the realization. [s]
    dt : float
        Its time step. [s]
    n_samples : int
        Its samples per period. [-]
    omega : ndarray
        Its frequencies 2πm/T_L, m = 0 … n_samples/2. [rad/s]
    duration : float
        Simulated length (at most ``length``). [s]
    directions : tuple of (float, SeaRealization)
        The sea's directions [rad] and their realizations: one (the sea's heading, the
        realization) for a long-crested sea, one per direction of a short-crested one
        (:func:`stochcable.sea.spreading.simulate_sea_directional`, whose elevations add
        up to ``realization``'s); empty without a sea.
    """

    realization: Any
    length: float
    dt: float
    n_samples: int
    omega: np.ndarray
    duration: float
    directions: tuple = ()


def realization_grid(
    scene: Scene, realization: Any, duration: float | None, dt: float | None, seed: int, method: str
) -> ExcitationGrid:
    """The given realization's grid, or a new realization of the scene's sea on the grid
    of ``duration`` (default: the scene's time series, else 600 s) and the scene's
    time-series step (else ``dt``, else 0.25 s)."""
    env = scene.environment
    ts = scene.analysis.timeseries
    ds = None if scene.sea is None else scene.sea.direction_set()
    spread = ds is not None and ds.count > 1
    if spread and realization is not None:
        raise InputError(
            "realization",
            "a SeaRealization",
            "-",
            "is long-crested but the scene's sea is short-crested (sea.spreading): leave "
            "it out, the sea is then realized direction by direction",
        )
    directions: tuple = ()
    if realization is not None:
        if not isinstance(realization, _sea.SeaRealization):
            raise InputError(
                "realization", type(realization).__name__, "-", "must be a SeaRealization"
            )
        t_l, dt_sea, n_t = realization.duration, realization.dt, realization.n_samples
        omega = np.asarray(realization.omega)
    else:
        t_l = (
            _v.positive("duration", duration, "s")
            if duration is not None
            else (ts.duration if ts is not None else 600.0)
        )
        dt_sea = ts.dt if ts is not None else (dt if dt is not None else 0.25)
        dt_sea = _v.positive("dt", dt_sea, "s")
        n_t = 2 * max(1, int(math.ceil(t_l / dt_sea / 2.0 - 1e-9)))
        t_l = n_t * dt_sea
        omega = 2.0 * math.pi / t_l * np.arange(n_t // 2 + 1)
        if spread:  # the rule of the analysis' time series: a realization per direction
            reals = simulate_sea_directional(
                spectrum_density(scene.sea.spectrum, env.g), ds, t_l, dt_sea, method, int(seed)
            )
            directions = tuple((float(b), r) for b, r in zip(ds.heading, reals))
            realization = dataclasses.replace(
                reals[0],
                elevation=np.sum([r.elevation for r in reals], axis=0),
                coefficients=np.sum([r.coefficients for r in reals], axis=0),
            )
        elif scene.sea is not None:
            realization = _sea.simulate_sea(
                spectrum_density(scene.sea.spectrum, env.g), t_l, dt_sea, method, rng=int(seed)
            )
    sim_len = t_l if duration is None else _v.positive("duration", duration, "s")
    if sim_len > t_l * (1 + 1e-9):
        raise InputError(
            "duration", duration, "s", f"must be <= the realization's length {t_l:g} s"
        )
    if realization is not None and not directions:
        directions = ((scene.sea.heading_rad, realization),)
    return ExcitationGrid(realization, t_l, dt_sea, n_t, omega, sim_len, directions)


def end_coefficients(
    scene: Scene,
    line: Line,
    grid: ExcitationGrid,
    seed: int,
    method: str,
    end_realizations: dict | None,
) -> dict[str, np.ndarray]:
    """End-motion coefficients ``{"a"|"b": (3, N+1) complex}`` on the grid: the given
    ones, else the scene's end-motion spectra realized with the channel seeds of
    :func:`end_motion_generators`, or RAO × the sea's coefficients. [m]"""
    omega = grid.omega
    ends: dict[str, np.ndarray] = {}
    if end_realizations is not None:
        for k_, v_ in end_realizations.items():
            arr = np.asarray(v_, dtype=complex)
            if k_ not in ("a", "b") or arr.shape != (3, omega.size):
                raise InputError(
                    f"end_realizations[{k_!r}]",
                    f"shape {arr.shape}",
                    "m",
                    f"keys must be 'a' or 'b' and values of shape (3, "
                    f"{omega.size}) on the realization's grid",
                )
            ends[k_] = arr
        return ends
    env = scene.environment
    gens = end_motion_generators(scene, int(seed))
    for key, end in (("a", line.end_a), ("b", line.end_b)):
        m = end.motion
        c = np.zeros((3, omega.size), dtype=complex)
        for k_, dof in enumerate(("surge", "sway", "heave")):
            gen = gens.get((line.name, key, dof))
            if gen is None:
                continue
            r = _sea.simulate_sea(
                spectrum_density(getattr(m, dof), env.g), grid.length, grid.dt, method, rng=gen
            )
            c[k_] = r.coefficients
        if m is not None and m.rao is not None:
            if grid.realization is None:
                raise InputError(
                    f"{line.name}.{'end_' + key}.motion.rao",
                    "rao",
                    "-",
                    "needs a sea (the RAO multiplies the sea's amplitudes)",
                )
            c = sum(
                m.rao.transfer(omega, b) * np.asarray(r.coefficients)[None]
                for b, r in grid.directions
            )
        if np.any(c):
            ends[key] = c
    return ends


def band_limited(
    grid: ExcitationGrid, ends: dict[str, np.ndarray], band: tuple[float, float] | None
) -> tuple[dict[str, np.ndarray], tuple[tuple[float, np.ndarray], ...]]:
    """The end coefficients and the sea's per direction, ((heading [rad], coefficients),
    ...) (empty without a sea), with the components outside ``band`` = (low, high)
    zeroed (all kept when ``band`` is None)."""
    omega = grid.omega
    keep = np.ones(omega.size)
    if band is not None:
        lo = _v.nonnegative("band[0]", band[0], "rad/s")
        hi = _v.positive("band[1]", band[1], "rad/s")
        if hi <= lo:
            raise InputError("band", band, "rad/s", "must be (low, high) with high > low")
        keep = ((omega >= lo) & (omega <= hi)).astype(float)
        ends = {k_: c * keep for k_, c in ends.items()}
    seas = tuple((b, np.asarray(r.coefficients) * keep) for b, r in grid.directions)
    return ends, seas


def spectrum_density(spec: Any, g: float):
    """ω -> S(ω) with S(0) = 0, as :mod:`stochcable.dynamics` samples it
    (:func:`stochcable.dynamics.loads.sea_channels.spectrum_callable`)."""
    return spectrum_callable(spec, g)


def end_motion_generators(scene: Scene, seed: int) -> dict[tuple[str, str, str], Any]:
    """The generator of every end-motion spectrum channel, keyed (line, end, dof).

    The rule of :func:`stochcable.dynamics.timeseries.synthesis.simulate_timeseries`: channels in
    the order lines × (end_a, end_b) × (surge, sway, heave), channel k drawing from
    ``default_rng(SeedSequence(seed).spawn(n)[k])``.
    """
    keys = []
    for ln in scene.lines:
        for end in ("a", "b"):
            m = getattr(ln, "end_" + end).motion
            if m is None or m.rao is not None:
                continue
            keys += [
                (ln.name, end, dof)
                for dof in ("surge", "sway", "heave")
                if getattr(m, dof) is not None
            ]
    children = np.random.SeedSequence(int(seed)).spawn(len(keys)) if keys else []
    return {k: np.random.default_rng(c) for k, c in zip(keys, children)}


# ------------------------------------------------------------------- time series


def upsample(
    coeff: np.ndarray, n_t: int, k: int, dtype_factor: np.ndarray | None = None
) -> np.ndarray:
    """irfft of coefficients (..., N+1) on a grid k times finer: shape (..., k·n_t)."""
    n_fine = k * n_t
    shape = coeff.shape[:-1] + (n_fine // 2 + 1,)
    big = np.zeros(shape, dtype=complex)
    big[..., : coeff.shape[-1]] = coeff
    big[..., n_t // 2] = 0.0  # the coarse Nyquist term (zero by construction)
    return _fft.irfft(big * k, n_fine)


def wave_series(
    model: LineModel,
    x_static: np.ndarray,
    omega: np.ndarray,
    X: np.ndarray,
    heading: float,
    env: Environment,
    ax: np.ndarray,
    n_t: int,
    k_up: int,
    sl: np.ndarray,
    r: np.ndarray,
):
    """Wave excitation on the simulation steps, ramped by ``r``.

    Returns the fluid velocity at the nodes (n_steps+1, n, d) (attachment drag), at
    the drag quadrature points (n_steps+1, ne, ng, d), and the wave-inertia nodal load
    (n_steps+1, N): per element l0·ρ(πD²/4)(1 + Can)(I − e₀e₀ᵀ)·∫₀¹ N_i a dξ with the
    exact element moments of
    :func:`stochcable.dynamics.loads.element_kinematics.element_wave_kinematics`
    (the load of :func:`stochcable.dynamics.loads.channels.wave_loads`), plus the attachments'
    (buoyancy/g + added mass)·a_node.  All are linear transfer functions per unit wave
    amplitude at the static positions, synthesized with the realization's coefficients.
    """
    pts = np.array(x_static, dtype=float)
    pts[:, 2] = np.maximum(pts[:, 2], -env.depth)  # nodes pressed into the seabed
    gp = model.gauss_points(pts).reshape(-1, 3)
    kin = wave_kinematics(omega, np.vstack([pts, gp]), heading, env.depth, env.g)
    vel = np.einsum("pcw,cd->pdw", kin.velocity, ax)  # (n + ne·ng, d, n_w)
    acc_n = np.einsum("ncw,cd->ndw", kin.acceleration[: model.n], ax)
    el = element_wave_kinematics(omega, pts, heading, env.depth, env.g)
    mom = el.acceleration @ ax  # (n_w, ne, 2, d)
    f_el = np.einsum("eij,wesj->wesi", model.inertia_el, mom)  # (n_w, ne, 2, d)
    f_nodes = np.zeros((omega.size, model.n, model.dim), dtype=complex)
    f_nodes[:, :-1] += f_el[:, :, 0]
    f_nodes[:, 1:] += f_el[:, :, 1]
    f_nodes += model.node_mw[None, :, None] * np.moveaxis(acc_n, 2, 0)
    coeff = np.concatenate([vel, np.moveaxis(f_nodes, 0, 2)], axis=0) * X  # (p, d, n_w)
    series = upsample(coeff, n_t, k_up)[..., sl] * r  # (p, d, n_steps+1)
    series = np.moveaxis(series, 2, 0)  # (n_steps+1, p, d)
    n, ne = model.n, model.ne
    u_nodes = series[:, :n]
    u_gauss = series[:, n : n + gp.shape[0]].reshape(-1, ne, model.gauss_xi.size, model.dim)
    f_in = np.ascontiguousarray(series[:, n + gp.shape[0] :]).reshape(-1, model.N)
    return u_nodes, u_gauss, f_in


def end_series(
    ends: dict[str, np.ndarray],
    omega: np.ndarray,
    n_nodes: int,
    ax: np.ndarray,
    n_t: int,
    k_up: int,
    sl: np.ndarray,
    ramp: tuple[np.ndarray, ...],
) -> dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Prescribed end motion on the steps, per end node: the ramped displacement r·x,
    velocity and acceleration with the ramp's exact derivatives, each (n_steps+1, d)."""
    r, r1, r2 = ramp
    end_disp = {}
    for key, c in ends.items():
        node = 0 if key == "a" else n_nodes - 1
        xyz = upsample(np.stack([c, 1j * omega * c, -(omega**2) * c]), n_t, k_up)[..., sl]
        x_, v_, a_ = (np.einsum("ct,cd->td", xyz[j], ax) for j in range(3))
        # ramped motion r·x with its exact derivatives
        xr = r[:, None] * x_
        vr = r[:, None] * v_ + r1[:, None] * x_
        ar = r[:, None] * a_ + 2.0 * r1[:, None] * v_ + r2[:, None] * x_
        end_disp[node] = (xr, vr, ar)
    return end_disp


def half_cosine(t: np.ndarray, t_r: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The ramp r(t) = ½(1 − cos(πt/t_r)) up to t_r, then 1, with r' and r''."""
    if t_r <= 0.0:
        one = np.ones_like(t)
        return one, np.zeros_like(t), np.zeros_like(t)
    x = np.clip(t / t_r, 0.0, 1.0)
    inside = t < t_r
    r = np.where(inside, 0.5 * (1.0 - np.cos(math.pi * x)), 1.0)
    r1 = np.where(inside, 0.5 * math.pi / t_r * np.sin(math.pi * x), 0.0)
    r2 = np.where(inside, 0.5 * (math.pi / t_r) ** 2 * np.cos(math.pi * x), 0.0)
    return r, r1, r2


def omega_quantile(omega: np.ndarray, power: np.ndarray, q: float) -> float:
    """Lowest ω below which the fraction ``q`` of ``power`` lies (0 without power)."""
    tot = power.sum()
    if tot <= 0.0:
        return 0.0
    c = np.cumsum(power) / tot
    return float(omega[min(int(np.searchsorted(c, q)), omega.size - 1)])
