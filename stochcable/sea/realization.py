"""Random sea realizations by the DSA and NSA methods (Tuah (1982), §5.1) and FFT synthesis.

A realization of length T_L = N_t Δt (N_t = 2N, even) lives on the grid
ω_m = mΔω, Δω = 2π/T_L, m = 0 … N (:func:`frequency_grid`).  Its rfft-domain
coefficients X_m = (N_t/2) a_m e^{−iθ_m} (X_0 = X_N = 0) give the elevation
η_n = Σ_{m=1}^{N−1} a_m cos(ω_m t_n − θ_m) = irfft(X, N_t) (Tuah (1982), eqs. 5.1.1, 5.1.4,
5.1.5), and any linear response with transfer function H (per unit amplitude,
Re{H e^{iωt}} convention) is irfft(H X, N_t) (:func:`synthesize`), so elevation,
kinematics, motions and tensions of one realization are mutually consistent.

Amplitudes (DESIGN.md; Tuah's (1982) eqs. 5.1.3a,b print the two-sided coefficient
magnitudes √(0.5 SΔω) and √(0.25 SΔω)(α²+β²)^½, half the cosine amplitude):

- DSA: a_m = √(2 S(ω_m) Δω); the variance of every realization is Σ S(ω_m)Δω.
- NSA: a_m = √(S(ω_m) Δω)·√(α_m² + β_m²), α, β ~ N(0, 1); E[a_m²/2] = S Δω.

Random numbers (reproducible on every machine with numpy's PCG64 Generator): first
u_m = ``rng.random()`` for m = 1 … N−1 in increasing m, θ_m = π − 2πu_m ∈ (−π, π];
then, for NSA only, α_1 … α_{N−1} = ``rng.standard_normal``, then β_1 … β_{N−1}.
DSA and NSA realizations with the same seed therefore share their phases.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import functools
import math
import os
import threading
from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike

from stochcable import validation as v
from stochcable.errors import InputError, ResolutionWarning, warn
from stochcable.sea import fft as _fft

# the coefficient kernel (white-box tests and benchmarks/bench_sea.py reach these here)
from stochcable.sea.coefficients import _CHUNK as _CHUNK
from stochcable.sea.coefficients import _TABLE as _TABLE
from stochcable.sea.coefficients import _give_back, _Synthesis, _work_arrays
from stochcable.sea.coefficients import _phasor_chunk as _phasor_chunk

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

_PARALLEL_MIN = 2**16
_SPECTRUM_PIECES = 8
_GRID_CACHE_SIZE = 4
_COMPILED_MIN = 2**16  # lines from which the numba kernel is used
_NUMBA_ENV = "STOCHCABLE_NUMBA"
_pool = None
_pool_lock = threading.Lock()
_compiled_state: list = []  # [kernel or None] once the import was tried
_compiled_lock = threading.Lock()


def _executor():
    """Module thread pool (os.cpu_count() workers) for the helpers of simulate_sea
    (the random draws, then chunks of the coefficient kernel; numpy releases the GIL
    inside its loops)."""
    global _pool
    with _pool_lock:
        if _pool is None:
            from concurrent.futures import ThreadPoolExecutor

            _pool = ThreadPoolExecutor(
                max_workers=os.cpu_count() or 1, thread_name_prefix="stochcable-sea"
            )
        return _pool


_cpus: list = [None, 1]  # [os.cpu_count as last called, its value]


def _cpu_count() -> int:
    """``os.cpu_count() or 1``, remembered (it reads /sys: 0.02–0.07 ms per call on
    the set-up path); asked again when ``os.cpu_count`` is replaced (tests patch it)."""
    fn = os.cpu_count
    if _cpus[0] is not fn:
        _cpus[1] = fn() or 1
        _cpus[0] = fn
    return _cpus[1]


def _compiled_kernel() -> Callable | None:
    """The numba coefficient kernel (:mod:`stochcable.sea.kernels`), or ``None``.

    ``None`` when numba is not installed, when ``STOCHCABLE_NUMBA=0``, or when numba
    fails to compile it (a UserWarning says so, once per process); callers then use the
    NumPy kernel :func:`_phasor_chunk`: the same bits where numpy's complex multiply
    uses fused multiply-adds (x86-64 with FMA3, as on the reference machine), else
    ≲ 1 ulp of |X| apart.  The first call of a process imports numba
    and loads (or compiles) the kernel, on the calling thread (0.5–1 s).
    """
    if os.environ.get(_NUMBA_ENV, "").strip() == "0":
        return None
    if _compiled_state:
        return _compiled_state[0]
    with _compiled_lock:
        if not _compiled_state:
            kernel = None
            try:
                from stochcable.sea import kernels as _kernels

                kernel = _kernels.phasor_chunk  # compiled (or loaded) at import
            except ImportError:  # numba not installed (or not for this numpy)
                kernel = None
            except Exception as exc:  # noqa: BLE001 - any numba/LLVM failure: fall back
                import warnings

                warnings.warn(
                    f"stochcable: the compiled sea kernel is unavailable ({exc!r}); "
                    f"using the NumPy kernel (same results, slower; set "
                    f"{_NUMBA_ENV}=0 to skip numba)",
                    UserWarning,
                    stacklevel=3,
                )
                kernel = None
            _compiled_state.append(kernel)
    return _compiled_state[0]


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
        ω_m = mΔω, m = 0 … N, N = N_t/2 (Tuah (1982), eq. 5.1.2b). [rad/s]
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
        raise InputError(
            "duration",
            duration,
            "s",
            f"duration/dt = {ratio:.10g} must be an even integer number of samples (dt = {dt:g} s)",
        )
    if n_t < 2 or n_t % 2:
        raise InputError(
            "duration",
            duration,
            "s",
            f"duration/dt = {n_t} samples must be an even integer >= 2 (dt = {dt:g} s)",
        )
    return int(n_t)


def _readonly(a: np.ndarray) -> np.ndarray:
    a.setflags(write=False)
    return a


@functools.lru_cache(maxsize=_GRID_CACHE_SIZE)
def _grid(n: int, d_omega: float) -> np.ndarray:
    """Read-only ω_m = mΔω, m = 0 … n, shared by the realizations on that grid.

    Cached (the last few (n, Δω)): building and first touching a 2^19-point grid costs
    0.2–0.5 ms per call; the array is read-only, so realizations may share it.
    """
    omega = np.arange(n + 1, dtype=np.float64)
    omega *= d_omega
    return _readonly(omega)


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
    m0 : float
        Target variance Σ_{m=1}^{N−1} S(ω_m)Δω of the simulated lines (NaN when not
        known, e.g. a realization built by hand). [m²]

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
    m0: float = math.nan

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


@functools.lru_cache(maxsize=_GRID_CACHE_SIZE)
def _tail_grid(omega_nyq: float) -> tuple[np.ndarray, np.ndarray]:
    """Read-only log grid ω_N·10^(2k/1200), k = 0 … 1200, and its steps of ln ω
    (cached per ω_N, like :func:`_grid`)."""
    w = omega_nyq * np.logspace(0.0, 2.0, 1201)
    return _readonly(w), _readonly(np.diff(np.log(w)))


def _nyquist_check(density: Callable, omega_nyq: float, d_omega: float, m0_grid: float) -> None:
    """Warn when more than NYQUIST_LOSS_TOLERANCE of m0 lies above π/Δt."""
    # Tail ∫_{ω_N}^{100 ω_N} S dω on a log grid (∫ S ω d ln ω), 1,201 points.
    w, dlw = _tail_grid(omega_nyq)
    s = np.asarray(density(w), dtype=float)
    if s.shape != w.shape or not np.isfinite(s).all():
        return
    if not (s > 0).any():
        return
    f = s * w
    seg = 0.5 * (f[1:] + f[:-1]) * dlw
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
        fix = (
            f"the spectrum still holds more than {NYQUIST_LOSS_TOLERANCE:.1%} of m0 above "
            f"{100 * omega_nyq:.4g} rad/s; use dt <= {math.pi / (100 * omega_nyq):.4g} s "
            "or a spectrum with a decaying tail"
        )
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
    """Simulate a random sea realization by DSA or NSA (Tuah (1982), §5.1).

    Parameters
    ----------
    density : callable
        One-sided spectrum ω → S(ω), a pointwise function vectorized over a 1-D
        (read-only) array, e.g. ``lambda w: spectrum_jonswap(w, 6.0, 10.0)``; for
        2^16 lines or more it is called on pieces of the grid from two threads, so it
        must be thread-safe (numpy functions are). [m²·s/rad]
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
    Tuah (1982), eqs. 5.1.1–5.1.5 with the amplitude constants of DESIGN.md (Tuah's eqs.
    5.1.3a,b are the two-sided magnitudes, half of a_m): DSA a_m = √(2SΔω),
    NSA a_m = √(SΔω)√(α²+β²); X_m = (N_t/2) a_m e^{−iθ_m}; η = irfft(X, N_t).
    The order of the random draws is given in the module docstring.  For 2^16 lines or
    more, a module pool thread makes the draws while the caller evaluates S on pieces
    of the grid, takes the remaining pieces, and shares the coefficient kernel; the
    result is the same bits whatever the split (and with one CPU, where S is one call
    on the whole grid).  A density that does not return one value per ω of a piece,
    or raises on one, is called again on the whole grid by the caller thread (its
    errors are reported from there).  The grid ω is cached per (N, Δω) and read-only:
    realizations on one grid share it.  ``SeaRealization.m0`` is the target
    Σ_{m=1}^{N−1} S(ω_m)Δω.  From 2^16 lines on, the coefficient kernel is the numba
    one of :mod:`stochcable.sea.kernels` when numba is installed (the first such call of
    a process imports numba: 0.5–1 s); ``STOCHCABLE_NUMBA=0`` selects the NumPy kernel
    (the same operations; the same bits on x86-64 with FMA3).
    """
    if not callable(density):
        raise InputError("density", density, "m²·s/rad", "must be a callable omega -> S(omega)")
    n_t = _sample_count(duration, dt)
    method_l = str(method).lower()
    if method_l not in ("dsa", "nsa"):
        raise InputError("method", method, "-", "must be 'dsa' or 'nsa'")
    if isinstance(rng, (int, np.integer)) and not isinstance(rng, bool) and rng >= 0:
        gen = seed = int(rng)  # default_rng(seed) is built by the draws
    else:
        gen, seed = _resolve_rng(rng)
    n = n_t // 2
    d_omega = 2.0 * math.pi / float(duration)
    dt_eff = float(duration) / n_t
    nsa = method_l == "nsa"
    coeff = np.empty(n + 1, dtype=np.complex128)
    work = _work_arrays(n_t)
    u, s_work, fft_in = work  # fft_in: the FFT's work array (destroyed by it)
    coeff[0] = coeff[n] = fft_in[0] = fft_in[n] = 0.0
    # X_m/N_t goes into the FFT input (exact for N_t = 2^k), so the FFT output is η
    omega = _grid(n, d_omega)
    parallel = n - 1 >= _PARALLEL_MIN and _cpu_count() >= 2
    kernel = _compiled_kernel() if n - 1 >= _COMPILED_MIN else None
    # a_m N_t/2 = √(c2 S_m), c2 = (2 or 1)·Δω·(N_t/2)², computed chunk by chunk in
    # the kernel (the callable's array is only read)
    c2 = (1.0 if nsa else 2.0) * d_omega * (0.5 * n_t) ** 2
    job = _Synthesis(
        gen,
        n - 1,
        nsa,
        coeff[1:n],
        fft_in[1:n],
        1.0 / n_t,
        density if parallel else None,
        omega,
        _SPECTRUM_PIECES,
        u,
        s_work,
        kernel,
        c2,
    )
    helper = None
    if parallel:
        # the draws meanwhile, then pieces of S, then kernel chunks
        helper = _executor().submit(job.work)
    try:
        s = None
        s_min = math.nan  # min of S from its pieces, if known
        if parallel:
            job.spectrum()
            job.s_ready.wait()
            if not job.piece_failed:
                s, s_min = job.s_grid, job.piece_min
            elif job.pipelined:
                # kernel pieces may have run on part of S: let the helper stop (or
                # drop it if still queued), then redo the whole kernel from the full
                # call's S (chunk scheme; this thread draws if nobody has)
                if not helper.cancel():
                    helper.result()
                job.pipelined = False
        if s is None:
            s = np.asarray(density(omega), dtype=float)
        if s.shape != omega.shape:
            raise InputError(
                "density",
                density,
                "m²·s/rad",
                f"must return an array of shape {omega.shape}, got {s.shape}",
            )
        # The helper may start on the kernel now (pipelined: it already has); this
        # thread validates S meanwhile and discards the work if S is invalid.
        job.start(s[1:n], c2)
        m0_grid = float(s[1:n].sum()) * d_omega
        if not (
            math.isfinite(m0_grid)
            and math.isfinite(s[0])
            and math.isfinite(s[n])
            and (s_min if s_min == s_min else s.min()) >= 0.0
        ):
            bad = np.flatnonzero(~(np.isfinite(s) & (s >= 0)))
            if bad.size:
                raise InputError(
                    "density",
                    density,
                    "m²·s/rad",
                    f"must return finite values >= 0 (S({omega[bad[0]]:.6g} rad/s) = {s[bad[0]]})",
                )
        if m0_grid <= 0.0:
            raise InputError(
                "density",
                density,
                "m²·s/rad",
                f"is zero at every grid frequency {d_omega:.4g} … {n * d_omega:.4g} rad/s",
            )
        _nyquist_check(density, n * d_omega, d_omega, m0_grid)
    except BaseException:
        job.cancel()
        if helper is not None and not helper.cancel():
            helper.result()
        raise
    job.work()
    # a helper still queued (pool busy with other calls) has nothing left to do
    if helper is not None and not helper.cancel():
        helper.result()
    elevation = _fft.irfft_overwrite(fft_in, n_t)
    _give_back(n_t, work)
    return SeaRealization(
        elevation=_readonly(elevation),
        omega=omega,
        coefficients=_readonly(coeff),
        d_omega=d_omega,
        dt=dt_eff,
        method=method_l,
        seed=seed,
        m0=m0_grid,
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
    Tuah (1982), eqs. 5.2.8–5.2.9: the response is Σ_m a_m Re{H(ω_m) e^{i(ω_m t − θ_m)}};
    with DSA its variance is Σ |H|² S Δω exactly.
    """
    if not isinstance(realization, SeaRealization):
        raise InputError("realization", type(realization).__name__, "-", "must be a SeaRealization")
    h = np.asarray(transfer)
    n1 = realization.coefficients.shape[0]
    if h.ndim == 0 or h.shape[-1] != n1:
        raise InputError(
            "transfer",
            h if h.size <= 6 else f"shape {h.shape}",
            "-",
            f"must have shape (..., {n1}) (one value per realization.omega)",
        )
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
