"""Linear (Airy) wave kinematics: dispersion and transfer functions (Tuah (1982), §5.2).

Conventions (DESIGN.md "Linear wave kinematics"): z up, z = 0 still water level,
seabed z = −h; heading β from +x toward +y; a harmonic quantity is Re{X e^{iωt}}; transfer
functions are per unit wave amplitude, with the elevation phase P = e^{−ik(x cos β + y sin β)}.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from stochcable import validation as v
from stochcable.errors import ConvergenceError, InputError
from stochcable.sea.realization import SeaRealization, synthesize

__all__ = [
    "wavenumber",
    "WaveKinematics",
    "wave_kinematics",
    "wave_kinematics_unchecked",
    "kinematics_timeseries",
]

G_STANDARD = 9.80665

_NEWTON_TOL = 1e-15
_NEWTON_MAX = 8


def _depth(depth: float) -> float:
    if depth is None:
        raise InputError("depth", depth, "m", "must be > 0 or inf")
    try:
        d = float(depth)
    except (TypeError, ValueError):
        raise InputError("depth", depth, "m", "must be > 0 or inf") from None
    if math.isnan(d) or d <= 0.0 or d == -math.inf:
        raise InputError("depth", depth, "m", "must be > 0 or inf")
    return d


def _solve_kh(x: np.ndarray) -> np.ndarray:
    """Solve y tanh y = x for y > 0 (x > 0), to machine precision.

    Start: Fenton & McKee (1990), y0 = x coth(x^(3/4))^(2/3) (< 1.5 % error), then
    vectorized Newton on f(y) = y tanh y − x with f' = tanh y + y (1 − tanh² y)
    until the largest relative correction is below 1e-15 (2–4 iterations).
    """
    if x.size == 0:
        return x.copy()
    t = np.tanh(x**0.75)
    y = x / t ** (2.0 / 3.0)
    for _ in range(_NEWTON_MAX):
        t = np.tanh(y)
        f = y * t
        f -= x
        fp = t * t
        np.subtract(1.0, fp, out=fp)
        fp *= y
        fp += t
        np.divide(f, fp, out=f)  # Newton step
        y -= f
        np.divide(f, y, out=f)
        if np.abs(f).max() < _NEWTON_TOL:
            return y
    res = float(np.max(np.abs(y * np.tanh(y) / x - 1.0)))
    if res < 4e-16:
        return y
    raise ConvergenceError("dispersion Newton", _NEWTON_MAX, res, _NEWTON_TOL)  # pragma: no cover


def wavenumber(omega: ArrayLike, depth: float = np.inf, g: float = G_STANDARD) -> np.ndarray:
    """Wave number k from the linear dispersion relation ω² = g k tanh(k h).

    Parameters
    ----------
    omega : array_like
        Angular frequencies, >= 0. [rad/s]
    depth : float, default inf
        Water depth h (``np.inf`` for deep water). [m]
    g : float, default 9.80665
        Acceleration of gravity. [m/s²]

    Returns
    -------
    numpy.ndarray
        Wave number, same shape as ``omega``; k = 0 at ω = 0. [rad/m]

    Notes
    -----
    Tuah (1982), eq. 5.2.11 ff.  Deep water k = ω²/g.  Finite depth: y = kh solves
    y tanh y = ω²h/g by the Fenton–McKee (1990) explicit start and Newton iterations
    to a relative correction < 1e-15; valid for kh from below 1e-6 (shallow limit
    k → ω/√(gh)) to beyond 1e6 (tanh = 1) without overflow.
    """
    w = np.asarray(omega, dtype=float)
    if not np.isfinite(w).all():
        raise InputError("omega", omega, "rad/s", "must be finite (not NaN or inf)")
    if (w < 0).any():
        i = int(np.flatnonzero((w < 0).ravel())[0])
        raise InputError("omega", omega, "rad/s", f"must be >= 0 (entry {i} is {w.ravel()[i]:g})")
    h = _depth(depth)
    g = v.positive("g", g, "m/s²")
    # the in-place kernels need arrays: a scalar ω goes through as shape (1,)
    return _wavenumber(np.atleast_1d(w), h, g).reshape(w.shape)


def _wavenumber(w: np.ndarray, h: float, g: float) -> np.ndarray:
    k = w * w
    k /= g
    if math.isinf(h):
        return k
    x = k * h  # ω² h / g
    pos = x > 0.0
    if pos.all():
        return _solve_kh(x) / h
    out = np.zeros_like(x)
    out[pos] = _solve_kh(x[pos]) / h
    return out


@dataclass(frozen=True, eq=False)
class WaveKinematics:
    """Complex transfer functions of linear wave kinematics per unit wave amplitude.

    Attributes
    ----------
    omega : numpy.ndarray
        Frequencies, shape (n_omega,). [rad/s]
    wavenumber : numpy.ndarray
        k(ω), shape (n_omega,). [rad/m]
    points : numpy.ndarray
        Evaluation points (x, y, z), shape (n_points, 3). [m]
    heading : float
        Wave heading β from +x toward +y. [rad]
    depth : float
        Water depth (inf for deep water). [m]
    elevation : numpy.ndarray
        Elevation phase P = e^{−ik(x cos β + y sin β)}, shape (n_points, n_omega). [m/m]
    velocity : numpy.ndarray
        Fluid velocity (u_x, u_y, u_z), shape (n_points, 3, n_omega). [(m/s)/m]
    acceleration : numpy.ndarray
        Fluid acceleration iω × velocity, shape (n_points, 3, n_omega). [(m/s²)/m]
    pressure : numpy.ndarray
        Dynamic pressure head p/(ρg) = cosh k(z+h)/cosh kh · P, shape (n_points, n_omega). [m/m]
    """

    omega: np.ndarray
    wavenumber: np.ndarray
    points: np.ndarray
    heading: float
    depth: float
    elevation: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    pressure: np.ndarray


def _depth_ratios(
    k: np.ndarray, z: np.ndarray, h: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """cosh k(z+h)/sinh kh, sinh k(z+h)/sinh kh, cosh k(z+h)/cosh kh for z <= 0.

    Exponential forms (never overflow): with E = e^{kz}, a = e^{−2k(z+h)}, b = e^{−2kh},
    ch = E(1 + a)/(1 − b), sh = E(1 − a)/(1 − b), cc = E(1 + a)/(1 + b), with
    1 − a and 1 − b by expm1 (shallow water).  Shapes (n_points, n_omega).
    """
    kz = np.multiply.outer(z, k)  # (P, W), kz <= 0
    e = np.exp(kz)
    if math.isinf(h):
        return e, e.copy(), e.copy()
    kzh = np.multiply.outer(z + h, k)  # k(z+h) >= 0
    a = np.exp(-2.0 * kzh)
    one_minus_a = -np.expm1(-2.0 * kzh)
    one_minus_b = -np.expm1(-2.0 * k * h)
    one_plus_b = 1.0 + np.exp(-2.0 * k * h)
    with np.errstate(divide="ignore", invalid="ignore"):
        ch = e * (1.0 + a) / one_minus_b
        sh = e * one_minus_a / one_minus_b
    cc = e * (1.0 + a) / one_plus_b
    return ch, sh, cc


def wave_kinematics_unchecked(
    w: np.ndarray, k: np.ndarray, pts: np.ndarray, beta: float, h: float, g: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:func:`wave_kinematics` on inputs already validated, without the pressure.

    The inner kernel for callers that validated their frequencies and points once
    and already hold the wavenumbers (the engine's sea channel, on every element
    node): no checks, no dispersion solve.  Same conventions as
    :func:`wave_kinematics` (per unit wave amplitude; points above z = 0 are dry).

    Parameters
    ----------
    w : numpy.ndarray
        Angular frequencies, >= 0, shape (n_omega,). [rad/s]
    k : numpy.ndarray
        Their wavenumbers k(ω) (:func:`wavenumber` at this depth and g), shape
        (n_omega,). [rad/m]
    pts : numpy.ndarray
        Points (x, y, z), float, shape (n_points, 3), with z >= −h. [m]
    beta : float
        Wave heading β, from +x toward +y. [rad]
    h : float
        Water depth, > 0 or inf. [m]
    g : float
        Acceleration of gravity, > 0. [m/s²]

    Returns
    -------
    phase : numpy.ndarray
        Elevation phase P = e^{−ik(x cos β + y sin β)}, complex, shape
        (n_points, n_omega). [m/m]
    cc : numpy.ndarray
        cosh k(z+h)/cosh kh (z clipped to 0), shape (n_points, n_omega). [-]
    dry : numpy.ndarray
        True where the point is above the still water level, shape (n_points,). [-]
    vel : numpy.ndarray
        Fluid velocity (u_x, u_y, u_z), complex, shape (n_points, 3, n_omega).
        [(m/s)/m]
    acc : numpy.ndarray
        Fluid acceleration iω × velocity, complex, shape (n_points, 3, n_omega).
        [(m/s²)/m]
    """
    cb, sb = math.cos(beta), math.sin(beta)
    z = pts[:, 2]
    xi = pts[:, 0] * cb + pts[:, 1] * sb
    phase = np.exp(-1j * np.multiply.outer(xi, k))  # (P, W)
    wet = z <= 0.0
    zc = np.minimum(z, 0.0)
    ch, sh, cc = _depth_ratios(k, zc, h)
    zero_w = w == 0.0
    if zero_w.any():
        ch[:, zero_w] = 0.0 if math.isinf(h) else math.sqrt(g / h)
        sh[:, zero_w] = 0.0
    uh = ch * w if not zero_w.any() else np.where(zero_w, ch, ch * w)
    uh = uh * phase
    uz = 1j * (sh * w) * phase
    dry = ~wet
    uh[dry] = 0.0
    uz[dry] = 0.0
    vel = np.empty((pts.shape[0], 3, w.size), dtype=np.complex128)
    vel[:, 0] = uh * cb
    vel[:, 1] = uh * sb
    vel[:, 2] = uz
    acc = vel * (1j * w)
    return phase, cc, dry, vel, acc


def wave_kinematics(
    omega: ArrayLike,
    points: ArrayLike,
    heading: float = 0.0,
    depth: float = np.inf,
    g: float = G_STANDARD,
) -> WaveKinematics:
    """Velocity, acceleration and pressure transfer functions of linear waves.

    Parameters
    ----------
    omega : array_like
        Angular frequencies, >= 0, 1-D. [rad/s]
    points : array_like
        Points (x, y, z), shape (3,) or (n_points, 3); z up, still water z = 0,
        seabed z = −depth. [m]
    heading : float, default 0.0
        Wave heading β, from +x toward +y (β = 0 travels toward +x). [rad]
    depth : float, default inf
        Water depth h. [m]
    g : float, default 9.80665
        Acceleration of gravity. [m/s²]

    Returns
    -------
    WaveKinematics
        Transfer functions per unit wave amplitude.

    Notes
    -----
    Tuah (1982), eqs. 5.2.8–5.2.11 (Wheeler 1969) in the DESIGN.md convention:
    P = e^{−ik(x cos β + y sin β)}, horizontal velocity ω cosh k(z+h)/sinh kh · P along
    β, vertical velocity iω sinh k(z+h)/sinh kh · P, acceleration iω × velocity
    (Tuah's (1982) g k/ω · cosh/cosh equals ω cosh/sinh by the dispersion relation).
    At the surface w = iω P = ∂η/∂t.  Points above z = 0 get zero velocity,
    acceleration and pressure.  At ω = 0 the finite-depth horizontal velocity takes
    its limit √(g/h) (shallow-water long wave); everything else is 0.
    """
    w = v.float_array("omega", omega, "rad/s", nonnegative=True)
    pts = np.asarray(points, dtype=float)
    if pts.ndim == 1:
        pts = pts.reshape(1, -1)
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise InputError("points", points, "m", "must have shape (3,) or (n_points, 3)")
    pts = v.float_array("points", pts, "m", ndim=2)
    beta = v.finite_scalar("heading", heading, "rad")
    h = _depth(depth)
    g = v.positive("g", g, "m/s²")
    z = pts[:, 2]
    if not math.isinf(h) and (z < -h).any():
        i = int(np.flatnonzero(z < -h)[0])
        raise InputError(
            "points", points, "m", f"z must be >= -depth = {-h:g} (point {i} has z = {z[i]:g})"
        )

    k = _wavenumber(w, h, g)
    phase, cc, dry, vel, acc = wave_kinematics_unchecked(w, k, pts, beta, h, g)
    pressure = cc * phase
    pressure[dry] = 0.0
    for a in (w, k, pts, phase, vel, acc, pressure):
        a.setflags(write=False)
    return WaveKinematics(
        omega=w,
        wavenumber=k,
        points=pts,
        heading=beta,
        depth=h,
        elevation=phase,
        velocity=vel,
        acceleration=acc,
        pressure=pressure,
    )


def kinematics_timeseries(
    realization: SeaRealization,
    points: ArrayLike,
    heading: float = 0.0,
    depth: float = np.inf,
    g: float = G_STANDARD,
) -> tuple[np.ndarray, np.ndarray]:
    """Velocity and acceleration time series at points, from one sea realization.

    Parameters
    ----------
    realization : SeaRealization
        Sea realization (its coefficients drive every response).
    points : array_like
        Points (x, y, z), shape (3,) or (n_points, 3). [m]
    heading : float, default 0.0
        Wave heading. [rad]
    depth : float, default inf
        Water depth. [m]
    g : float, default 9.80665
        Acceleration of gravity. [m/s²]

    Returns
    -------
    velocity : numpy.ndarray
        Shape (n_points, 3, N_t). [m/s]
    acceleration : numpy.ndarray
        Shape (n_points, 3, N_t). [m/s²]

    Notes
    -----
    Tuah (1982), eqs. 5.2.8–5.2.9: V_j(t_n) = irfft(H_Vj X), a_j(t_n) = irfft(H_aj X).
    """
    kin = wave_kinematics(realization.omega, points, heading, depth, g)
    return synthesize(realization, kin.velocity), synthesize(realization, kin.acceleration)


# Former name of wave_kinematics_unchecked (ARCHITECTURE.md "Conventions"), kept importable.
nodal_kinematics = wave_kinematics_unchecked
