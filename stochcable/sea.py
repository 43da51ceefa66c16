"""Random sea realizations by the DSA and NSA methods (seed 001 §5.1) and FFT synthesis.

A realization of length T_L = N_t Δt (N_t = 2N, even) lives on the grid
ω_m = mΔω, Δω = 2π/T_L, m = 0 … N (:func:`frequency_grid`).  Its rfft-domain
coefficients X_m = (N_t/2) a_m e^{−iθ_m} (X_0 = X_N = 0) give the elevation
η_n = Σ_{m=1}^{N−1} a_m cos(ω_m t_n − θ_m) = irfft(X, N_t) (seed eqs. 5.1.1, 5.1.4,
5.1.5), and any linear response with transfer function H (per unit amplitude,
Re{H e^{iωt}} convention) is irfft(H X, N_t) (:func:`synthesize`), so elevation,
kinematics, motions and tensions of one realization are mutually consistent.

Amplitudes (DESIGN.md; the seed's eqs. 5.1.3a,b print the two-sided coefficient
magnitudes √(0.5 SΔω) and √(0.25 SΔω)(α²+β²)^½, half the cosine amplitude):

- DSA: a_m = √(2 S(ω_m) Δω); the variance of every realization is Σ S(ω_m)Δω.
- NSA: a_m = √(S(ω_m) Δω)·√(α_m² + β_m²), α, β ~ N(0, 1); E[a_m²/2] = S Δω.

Random numbers (reproducible on every machine with numpy's PCG64 Generator): first
u_m = ``rng.random()`` for m = 1 … N−1 in increasing m, θ_m = π − 2πu_m ∈ (−π, π];
then, for NSA only, α_1 … α_{N−1} = ``rng.standard_normal``, then β_1 … β_{N−1}.
DSA and NSA realizations with the same seed therefore share their phases.
"""

from __future__ import annotations

import math
import os
import threading
from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike

from . import _fft
from . import _validate as v
from .errors import InputError, ResolutionWarning, warn

__all__ = [
    "frequency_grid",
    "SeaRealization",
    "simulate_sea",
    "synthesize",
    "welch_spectrum",
    "NYQUIST_LOSS_TOLERANCE",
]

NYQUIST_LOSS_TOLERANCE = 1e-3
"""Fraction of m0 above the Nyquist frequency π/Δt that triggers a ResolutionWarning. [-]"""

_TABLE_BITS = 11
_TABLE_SIZE = 1 << _TABLE_BITS
_TABLE = np.exp(2j * np.pi * np.arange(_TABLE_SIZE) / _TABLE_SIZE)
_TAB_C = np.ascontiguousarray(_TABLE.real)
_TAB_S = np.ascontiguousarray(_TABLE.imag)
_CHUNK = 32768
_PARALLEL_MIN = 2**16
_pool = None
_pool_lock = threading.Lock()


def _executor():
    """Module thread pool (os.cpu_count() workers) for the phasor kernel; numpy
    releases the GIL inside ufunc loops, so the chunks run in parallel."""
    global _pool
    with _pool_lock:
        if _pool is None:
            from concurrent.futures import ThreadPoolExecutor

            _pool = ThreadPoolExecutor(max_workers=os.cpu_count() or 1,
                                       thread_name_prefix="stochcable-sea")
        return _pool


def frequency_grid(duration: float, dt: float) -> tuple[np.ndarray, float]:
    """FFT frequency grid of a record of length ``duration`` sampled every ``dt``.

    Parameters
    ----------
    duration : float
        Record length T_L. [s]
    dt : float
        Time step Δt; T_L/Δt = N_t must be an even integer. [s]

    Returns
    -------
    omega : numpy.ndarray
        ω_m = mΔω, m = 0 … N, N = N_t/2 (seed eq. 5.1.2b). [rad/s]
    d_omega : float
        Δω = 2π/T_L. [rad/s]
    """
    n_t = _sample_count(duration, dt)
    d_omega = 2.0 * math.pi / float(duration)
    return d_omega * np.arange(n_t // 2 + 1), d_omega


def _sample_count(duration: float, dt: float) -> int:
    duration = v.positive("duration", duration, "s")
    dt = v.positive("dt", dt, "s")
    ratio = duration / dt
    n_t = round(ratio)
    if abs(ratio - n_t) > 1e-9 * max(ratio, 1.0):
        raise InputError("duration", duration, "s",
                         f"duration/dt = {ratio:.10g} must be an even integer number of samples (dt = {dt:g} s)")
    if n_t < 2 or n_t % 2:
        raise InputError("duration", duration, "s",
                         f"duration/dt = {n_t} samples must be an even integer >= 2 (dt = {dt:g} s)")
    return int(n_t)


def _readonly(a: np.ndarray) -> np.ndarray:
    a.setflags(write=False)
    return a


@dataclass(frozen=True, eq=False)
class SeaRealization:
    """One random-sea realization and its FFT coefficients.

    Attributes
    ----------
    elevation : numpy.ndarray
        Surface elevation η(t_n), shape (N_t,). [m]
    omega : numpy.ndarray
        Frequencies ω_m = mΔω, m = 0 … N, shape (N+1,). [rad/s]
    coefficients : numpy.ndarray
        Complex rfft coefficients X_m = (N_t/2) a_m e^{−iθ_m}, X_0 = X_N = 0, so that
        ``elevation = irfft(coefficients, N_t)``; shape (N+1,). [m]
    d_omega : float
        Frequency step 2π/T_L. [rad/s]
    dt : float
        Time step. [s]
    method : str
        ``"dsa"`` or ``"nsa"``. [-]
    seed : int or None
        The integer seed if one was given (``None`` for a Generator or fresh entropy). [-]

    Notes
    -----
    ``time`` (t_n = nΔt, shape (N_t,)) is computed on first access.  Arrays are read-only.
    """

    elevation: np.ndarray
    omega: np.ndarray
    coefficients: np.ndarray
    d_omega: float
    dt: float
    method: str
    seed: int | None = None

    @property
    def n_samples(self) -> int:
        """Number of time samples N_t. [-]"""
        return self.elevation.shape[-1]

    @property
    def duration(self) -> float:
        """Record length T_L = N_t Δt. [s]"""
        return 2.0 * math.pi / self.d_omega

    @cached_property
    def time(self) -> np.ndarray:
        """Sample times t_n = nΔt, n = 0 … N_t−1. [s]"""
        return _readonly(self.dt * np.arange(self.n_samples))

    @property
    def amplitudes(self) -> np.ndarray:
        """Cosine amplitudes a_m = 2|X_m|/N_t, shape (N+1,). [m]"""
        return np.abs(self.coefficients) * (2.0 / self.n_samples)

    @property
    def phases(self) -> np.ndarray:
        """Phases θ_m = −arg X_m (0 where a_m = 0), shape (N+1,). [rad]"""
        return -np.angle(self.coefficients)

    @property
    def variance_grid(self) -> float:
        """Σ a_m²/2, the variance of the realization's elevation. [m²]"""
        a = self.amplitudes
        return float(0.5 * np.dot(a, a))


def _resolve_rng(rng) -> tuple[np.random.Generator, int | None]:  # noqa: ANN001
    if isinstance(rng, np.random.Generator):
        return rng, None
    if rng is None:
        return np.random.default_rng(), None
    if isinstance(rng, (int, np.integer)) and not isinstance(rng, bool) and rng >= 0:
        return np.random.default_rng(int(rng)), int(rng)
    raise InputError("rng", rng, "-", "must be a numpy Generator, a non-negative int seed or None")


def _unit_phasors_into(u: np.ndarray, amp: np.ndarray, out: np.ndarray) -> None:
    """out = amp · e^{−iθ}, θ = π − 2πu, i.e. −amp · e^{2πiu}, without calling cos/sin.

    e^{2πiu} = T[j] · e^{iδ}, j = ⌊2048u⌋, δ = 2π(2048u − j)/2048 ∈ [0, 3.07e-3): a
    2048-entry table times Taylor series of cos δ, sin δ to δ⁶, δ⁷ (truncation
    < 2e-22); |error| < 2e-16 per entry.  Processed in cache-sized chunks.
    """
    n = u.shape[0]
    B = min(_CHUNK, n)
    s = np.empty(B)
    j = np.empty(B, dtype=np.intp)
    d2 = np.empty(B)
    c = np.empty(B)
    sn = np.empty(B)
    ta = np.empty(B)
    tb = np.empty(B)
    w = np.empty(B)
    k = 2.0 * math.pi / _TABLE_SIZE
    ov = out.view(np.float64)
    for a in range(0, n, B):
        b = min(a + B, n)
        m = b - a
        s_, j_, d2_, c_, sn_, ta_, tb_, w_ = (x[:m] for x in (s, j, d2, c, sn, ta, tb, w))
        np.multiply(u[a:b], float(_TABLE_SIZE), out=s_)
        np.floor(s_, out=w_)
        np.copyto(j_, w_, casting="unsafe")
        np.subtract(s_, w_, out=s_)
        s_ *= k                               # δ
        np.multiply(s_, s_, out=d2_)          # δ²
        # cos δ = 1 − δ²/2 + δ⁴/24 − δ⁶/720
        np.multiply(d2_, -1.0 / 720.0, out=c_)
        c_ += 1.0 / 24.0
        c_ *= d2_
        c_ -= 0.5
        c_ *= d2_
        c_ += 1.0
        # sin δ = δ(1 − δ²/6 + δ⁴/120 − δ⁶/5040)
        np.multiply(d2_, -1.0 / 5040.0, out=sn_)
        sn_ += 1.0 / 120.0
        sn_ *= d2_
        sn_ -= 1.0 / 6.0
        sn_ *= d2_
        sn_ += 1.0
        sn_ *= s_
        np.take(_TAB_C, j_, out=ta_)
        np.take(_TAB_S, j_, out=tb_)
        am = amp[a:b]
        # −amp (ta + i tb)(c + i sn): real = amp (tb sn − ta c), imag = −amp (ta sn + tb c)
        np.multiply(tb_, sn_, out=w_)
        np.multiply(ta_, c_, out=s_)
        w_ -= s_
        np.multiply(w_, am, out=ov[2 * a:2 * b:2])
        np.multiply(ta_, sn_, out=w_)
        np.multiply(tb_, c_, out=s_)
        w_ += s_
        w_ *= am
        np.negative(w_, out=ov[2 * a + 1:2 * b:2])


def _phasors(u: np.ndarray, amp: np.ndarray, out: np.ndarray) -> None:
    """_unit_phasors_into split over the CPU cores for long records (same result)."""
    n = u.shape[0]
    workers = os.cpu_count() or 1
    if n < _PARALLEL_MIN or workers < 2:
        _unit_phasors_into(u, amp, out)
        return
    edges = [n * i // workers for i in range(workers + 1)]
    futs = [_executor().submit(_unit_phasors_into, u[a:b], amp[a:b], out[a:b])
            for a, b in zip(edges[:-1], edges[1:])]
    for f in futs:
        f.result()


def _nyquist_check(density: Callable, omega_nyq: float, d_omega: float, m0_grid: float) -> None:
    """Warn when more than NYQUIST_LOSS_TOLERANCE of m0 lies above π/Δt."""
    # Tail ∫_{ω_N}^{100 ω_N} S dω on a log grid (∫ S ω d ln ω), 1,201 points.
    w = omega_nyq * np.logspace(0.0, 2.0, 1201)
    s = np.asarray(density(w), dtype=float)
    if s.shape != w.shape or not np.isfinite(s).all():
        return
    if not (s > 0).any():
        return
    f = s * w
    lw = np.log(w)
    seg = 0.5 * (f[1:] + f[:-1]) * np.diff(lw)
    tail_from = np.concatenate([np.cumsum(seg[::-1])[::-1], [0.0]])  # ∫_{w_i}^{100 ω_N}
    tail = float(tail_from[0])
    total = m0_grid + tail
    if total <= 0.0:
        return
    frac = tail / total
    if frac <= NYQUIST_LOSS_TOLERANCE:
        return
    ok = np.flatnonzero(tail_from <= NYQUIST_LOSS_TOLERANCE * total)
    if ok.size and ok[0] < w.size - 1:
        dt_ok = math.pi / w[ok[0]]
        fix = f"use dt <= {dt_ok:.4g} s to keep the loss below {NYQUIST_LOSS_TOLERANCE:.1%}"
    else:
        fix = (f"the spectrum still holds more than {NYQUIST_LOSS_TOLERANCE:.1%} of m0 above "
               f"{100 * omega_nyq:.4g} rad/s; use dt <= {math.pi / (100 * omega_nyq):.4g} s "
               "or a spectrum with a decaying tail")
    warn(
        f"{frac:.2%} of the spectrum's m0 lies above the Nyquist frequency "
        f"pi/dt = {omega_nyq:.4g} rad/s and is not simulated; {fix}",
        ResolutionWarning,
        stacklevel=3,
    )


def simulate_sea(
    density: Callable[[np.ndarray], np.ndarray],
    duration: float,
    dt: float,
    method: str = "dsa",
    rng: np.random.Generator | int | None = None,
) -> SeaRealization:
    """Simulate a random sea realization by DSA or NSA (seed 001 §5.1).

    Parameters
    ----------
    density : callable
        One-sided spectrum ω → S(ω), vectorized over a 1-D array, e.g.
        ``lambda w: spectrum_jonswap(w, 6.0, 10.0)``. [m²·s/rad]
    duration : float
        Record length T_L (= the period of the realization). [s]
    dt : float
        Time step; ``duration/dt`` must be an even integer N_t. [s]
    method : {"dsa", "nsa"}, default "dsa"
        Deterministic or nondeterministic spectral amplitudes. [-]
    rng : numpy.random.Generator or int, optional
        Random generator or integer seed (PCG64); ``None`` uses fresh entropy. [-]

    Returns
    -------
    SeaRealization
        Elevation, coefficients and grid.

    Warns
    -----
    ResolutionWarning
        When more than 0.1 % of m0 lies above the Nyquist frequency π/Δt (the
        message gives the fraction and a Δt that keeps the loss below 0.1 %).

    Notes
    -----
    Seed eqs. 5.1.1–5.1.5 with the amplitude constants of DESIGN.md (the seed's
    5.1.3a,b are the two-sided magnitudes, half of a_m): DSA a_m = √(2SΔω),
    NSA a_m = √(SΔω)√(α²+β²); X_m = (N_t/2) a_m e^{−iθ_m}; η = irfft(X, N_t).
    The order of the random draws is given in the module docstring.
    """
    if not callable(density):
        raise InputError("density", density, "m²·s/rad", "must be a callable omega -> S(omega)")
    n_t = _sample_count(duration, dt)
    method_l = str(method).lower()
    if method_l not in ("dsa", "nsa"):
        raise InputError("method", method, "-", "must be 'dsa' or 'nsa'")
    gen, seed = _resolve_rng(rng)
    n = n_t // 2
    d_omega = 2.0 * math.pi / float(duration)
    dt_eff = float(duration) / n_t
    omega = d_omega * np.arange(n + 1)
    s = np.asarray(density(omega), dtype=float)
    if s.shape != omega.shape:
        raise InputError("density", density, "m²·s/rad",
                         f"must return an array of shape {omega.shape}, got {s.shape}")
    if not np.isfinite(s).all() or (s < 0).any():
        bad = np.flatnonzero(~(np.isfinite(s) & (s >= 0)))[0]
        raise InputError("density", density, "m²·s/rad",
                         f"must return finite values >= 0 (S({omega[bad]:.6g} rad/s) = {s[bad]})")
    m0_grid = float(s[1:n].sum()) * d_omega
    if m0_grid <= 0.0:
        raise InputError("density", density, "m²·s/rad",
                         f"is zero at every grid frequency {d_omega:.4g} … {n * d_omega:.4g} rad/s")
    _nyquist_check(density, n * d_omega, d_omega, m0_grid)

    # amplitude × N_t/2 in a new array: the callable's array is never written to
    amp = s[1:n] * ((2.0 if method_l == "dsa" else 1.0) * d_omega)
    np.sqrt(amp, out=amp)
    amp *= 0.5 * n_t
    u = gen.random(n - 1)
    if method_l == "nsa":
        alpha = gen.standard_normal(n - 1)
        beta = gen.standard_normal(n - 1)
        np.hypot(alpha, beta, out=alpha)
        amp *= alpha
    coeff = np.empty(n + 1, dtype=np.complex128)
    coeff[0] = 0.0
    coeff[n] = 0.0
    _phasors(u, amp, coeff[1:n])
    elevation = _fft.irfft(coeff, n_t)
    return SeaRealization(
        elevation=_readonly(elevation),
        omega=_readonly(omega),
        coefficients=_readonly(coeff),
        d_omega=d_omega,
        dt=dt_eff,
        method=method_l,
        seed=seed,
    )


def synthesize(realization: SeaRealization, transfer: ArrayLike) -> np.ndarray:
    """Time series of a linear response driven by ``realization``.

    Parameters
    ----------
    realization : SeaRealization
        The sea realization (its coefficients X_m).
    transfer : array_like
        Complex transfer function per unit wave amplitude (Re{H e^{iωt}} convention)
        sampled at ``realization.omega``; shape (..., N+1). [unit/m]

    Returns
    -------
    numpy.ndarray
        irfft(H X, N_t) along the last axis, shape (..., N_t). [unit]

    Notes
    -----
    Seed eqs. 5.2.8–5.2.9: the response is Σ_m a_m Re{H(ω_m) e^{i(ω_m t − θ_m)}};
    with DSA its variance is Σ |H|² S Δω exactly.
    """
    if not isinstance(realization, SeaRealization):
        raise InputError("realization", type(realization).__name__, "-", "must be a SeaRealization")
    h = np.asarray(transfer)
    n1 = realization.coefficients.shape[0]
    if h.ndim == 0 or h.shape[-1] != n1:
        raise InputError("transfer", h if h.size <= 6 else f"shape {h.shape}", "-",
                         f"must have shape (..., {n1}) (one value per realization.omega)")
    if not np.isfinite(h).all():
        raise InputError("transfer", f"shape {h.shape}", "-", "must be finite (not NaN or inf)")
    return _fft.irfft(h * realization.coefficients, realization.n_samples)


def welch_spectrum(
    x: ArrayLike, dt: float, nperseg: int | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """One-sided spectral density estimate of a time series in rad/s (Welch).

    Parameters
    ----------
    x : array_like
        Time series, 1-D. [unit]
    dt : float
        Sampling interval. [s]
    nperseg : int, optional
        Segment length (default: scipy's, 256 or len(x)). [-]

    Returns
    -------
    omega : numpy.ndarray
        Frequencies 2πf. [rad/s]
    density : numpy.ndarray
        S(ω) = S_f/(2π), integrating to the variance over ω. [unit²·s/rad]
    """
    from scipy.signal import welch

    x = v.float_array("x", x, "unit", min_size=2)
    dt = v.positive("dt", dt, "s")
    if nperseg is not None:
        nperseg = v.positive_int("nperseg", nperseg, minimum=2)
        if nperseg > x.size:
            raise InputError("nperseg", nperseg, "-", f"must be <= len(x) = {x.size}")
    f, sf = welch(x, fs=1.0 / dt, nperseg=nperseg)
    return 2.0 * math.pi * f, sf / (2.0 * math.pi)
