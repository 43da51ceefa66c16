"""Statistical (and harmonic) linearization of Morison drag.

Per unit length the drag force on a cable element is ``f = 1/2 rho Cd D |v| v`` with
``v`` the relative fluid velocity (Tuah 1982, eq. 3.2.a.6, §5.2).  Statistical
linearization (Borgman 1972) replaces it by ``f ~ B v`` with ``B = E[df/dv]`` for a
Gaussian ``v`` (equivalently the least-squares fit ``E[(f - B v)^2] -> min``).
``B`` depends on the statistics of ``v``, which depend on the response: the
standard deviations are iterated to a fixed point (Tuah 1982, §5.3, steps 5-13) with
:func:`stochcable.dynamics.linearization.iteration.fixed_point`.

All formulas are pure, vectorized over elements (broadcasting over leading axes).

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from stochcable import validation as _v
from stochcable.errors import InputError

__all__ = [
    "borgman_variance_ratio",
    "drag_inertia_ratio",
    "drag_linear_current",
    "drag_linear_harmonic",
    "drag_linear_seed",
    "drag_linear_vector",
    "mean_drag_gaussian",
]

_SQRT_2_OVER_PI = math.sqrt(2.0 / math.pi)
_SQRT_8_OVER_PI = math.sqrt(8.0 / math.pi)

# The error function element by element with the standard library's (the C library's)
# erf: ``scipy.special`` costs ~25 ms to import, more than the first analysis of a
# small line spends in erf in all (a few hundred values, ~0.2 µs each); it agrees with
# ``scipy.special.erf`` to 2 ulp (tests/dynamics/test_linearization.py).
_ERF = np.frompyfunc(math.erf, 1, 1)


def _erf(x: np.ndarray) -> np.ndarray:
    """erf(x) element by element, a float array of the shape of ``x``."""
    return np.asarray(_ERF(x), dtype=float)


def _nonneg_array(name: str, value: ArrayLike, unit: str) -> np.ndarray:
    return _v.float_array(name, value, unit, ndim=None, nonnegative=True)


def _finite_array(name: str, value: ArrayLike, unit: str) -> np.ndarray:
    return _v.float_array(name, value, unit, ndim=None)


def _out(x: np.ndarray) -> np.ndarray | float:
    return float(x) if np.ndim(x) == 0 else x


# ---------------------------------------------------------------------------------
# scalar forms
# ---------------------------------------------------------------------------------


def drag_linear_seed(
    rho: float | np.ndarray,
    cd: float | np.ndarray,
    diameter: float | np.ndarray,
    sigma: float | np.ndarray,
) -> np.ndarray | float:
    r"""Linearized drag coefficient for a zero-mean Gaussian relative velocity (seed form).

    Parameters
    ----------
    rho : float or array_like
        Fluid density. [kg/m³]
    cd : float or array_like
        Drag coefficient referred to ``diameter``. [-]
    diameter : float or array_like
        Reference width per unit length.  For normal drag the hydrodynamic
        diameter ``D``; for axial (skin-friction) drag pass the wetted perimeter
        ``pi D`` with the axial coefficient ``Cdt`` (seed eq. 5.2.2.b). [m]
    sigma : float or array_like
        Standard deviation of the relative velocity component. [m/s]

    Returns
    -------
    float or ndarray
        Linear drag coefficient ``B`` per unit length. [N·s/m²]

    Notes
    -----
    Tuah (1982), eq. (5.2.2.a): ``B = sqrt(8/pi) * 1/2 rho Cd D sigma
    = sqrt(2/pi) rho Cd D sigma``.  Eq. (5.2.2.b) is the same formula with
    ``D -> pi D``: ``sqrt(2 pi) Ct rho D sigma = sqrt(2/pi) rho Ct (pi D) sigma``.
    This is ``E[d f/d v]`` for ``f = 1/2 rho Cd D |v| v`` and ``v ~ N(0, sigma^2)``
    (Borgman 1972).
    """
    rho_ = _nonneg_array("rho", rho, "kg/m^3")
    cd_ = _nonneg_array("cd", cd, "-")
    d_ = _nonneg_array("diameter", diameter, "m")
    s_ = _nonneg_array("sigma", sigma, "m/s")
    return _out(_SQRT_8_OVER_PI * 0.5 * rho_ * cd_ * d_ * s_)


def mean_abs_gaussian(sigma: np.ndarray, mean: np.ndarray) -> np.ndarray:
    """E|v| for v ~ N(mean, sigma^2); sigma >= 0, handles sigma = 0 exactly."""
    sigma, mean = np.broadcast_arrays(sigma, mean)
    if not mean.any():
        # no current: σ·√(2/π), the general form's value to the bit (exp(0) = 1,
        # mean·erf(0) = +0) without its exp and erf (most of the drag update's time)
        return np.where(sigma > 0, sigma * _SQRT_2_OVER_PI, 0.0)
    pos = sigma > 0
    s_safe = np.where(pos, sigma, 1.0)
    ratio = np.where(pos, mean / s_safe, 0.0)
    val = s_safe * _SQRT_2_OVER_PI * np.exp(-0.5 * ratio**2) + mean * _erf(ratio / math.sqrt(2.0))
    return np.where(pos, val, np.abs(mean))


def drag_linear_current(
    rho: float | np.ndarray,
    cd: float | np.ndarray,
    diameter: float | np.ndarray,
    sigma: float | np.ndarray,
    mean: float | np.ndarray,
) -> np.ndarray | float:
    r"""Linearized drag coefficient for a Gaussian relative velocity with a mean (current).

    Parameters
    ----------
    rho : float or array_like
        Fluid density. [kg/m³]
    cd : float or array_like
        Drag coefficient referred to ``diameter``. [-]
    diameter : float or array_like
        Reference width per unit length (``pi D`` for axial drag, see
        :func:`drag_linear_seed`). [m]
    sigma : float or array_like
        Standard deviation of the relative velocity component. [m/s]
    mean : float or array_like
        Mean of the relative velocity component (current minus mean cable
        velocity). [m/s]

    Returns
    -------
    float or ndarray
        Linear drag coefficient ``B`` per unit length. [N·s/m²]

    Notes
    -----
    ``B = E[d f/d v] = rho Cd D E|v|`` with ``v ~ N(U, sigma^2)``:

    ``B = rho Cd D [sigma sqrt(2/pi) exp(-U^2/(2 sigma^2)) + U erf(U/(sigma sqrt 2))]``

    (DESIGN.md "Drag linearization").  For ``U = 0`` it is Tuah (1982), eq. (5.2.2);
    for ``sigma -> 0`` it tends to ``rho Cd D |U|`` (the tangent of the steady
    drag), which is returned exactly for ``sigma = 0``; ``sigma = U = 0`` gives 0.
    The mean force that goes with it is :func:`mean_drag_gaussian`.
    """
    rho_ = _nonneg_array("rho", rho, "kg/m^3")
    cd_ = _nonneg_array("cd", cd, "-")
    d_ = _nonneg_array("diameter", diameter, "m")
    s_ = _nonneg_array("sigma", sigma, "m/s")
    u_ = _finite_array("mean", mean, "m/s")
    return _out(rho_ * cd_ * d_ * mean_abs_gaussian(s_, u_))


def mean_drag_gaussian(
    rho: float | np.ndarray,
    cd: float | np.ndarray,
    diameter: float | np.ndarray,
    sigma: float | np.ndarray,
    mean: float | np.ndarray,
) -> np.ndarray | float:
    r"""Mean drag force per unit length for a Gaussian relative velocity.

    Parameters
    ----------
    rho : float or array_like
        Fluid density. [kg/m³]
    cd : float or array_like
        Drag coefficient referred to ``diameter``. [-]
    diameter : float or array_like
        Reference width per unit length. [m]
    sigma : float or array_like
        Standard deviation of the relative velocity. [m/s]
    mean : float or array_like
        Mean relative velocity. [m/s]

    Returns
    -------
    float or ndarray
        ``E[1/2 rho Cd D |v| v]``, signed like ``mean``. [N/m]

    Notes
    -----
    For ``v ~ N(U, sigma^2)``:
    ``E[|v| v] = (U^2 + sigma^2) erf(U/(sigma sqrt 2))
    + U sigma sqrt(2/pi) exp(-U^2/(2 sigma^2))``.
    It tends to ``U |U|`` for ``sigma -> 0`` (exact at ``sigma = 0``) and is 0 for
    ``U = 0``.  The fluctuation increases the steady drag of a current: this force
    belongs in the statics (DESIGN.md "Drag linearization").
    """
    rho_ = _nonneg_array("rho", rho, "kg/m^3")
    cd_ = _nonneg_array("cd", cd, "-")
    d_ = _nonneg_array("diameter", diameter, "m")
    s_ = _nonneg_array("sigma", sigma, "m/s")
    u_ = _finite_array("mean", mean, "m/s")
    s_, u_ = np.broadcast_arrays(s_, u_)
    pos = s_ > 0
    s_safe = np.where(pos, s_, 1.0)
    ratio = np.where(pos, u_ / s_safe, 0.0)
    e = (u_**2 + s_**2) * _erf(ratio / math.sqrt(2.0)) + u_ * s_safe * (
        _SQRT_2_OVER_PI * np.exp(-0.5 * ratio**2)
    )
    e = np.where(pos, e, u_ * np.abs(u_))
    return _out(0.5 * rho_ * cd_ * d_ * e)


def drag_linear_harmonic(
    rho: float | np.ndarray,
    cd: float | np.ndarray,
    diameter: float | np.ndarray,
    amplitude: float | np.ndarray,
) -> np.ndarray | float:
    r"""Linearized drag coefficient for a harmonic relative velocity (regular waves).

    Parameters
    ----------
    rho : float or array_like
        Fluid density. [kg/m³]
    cd : float or array_like
        Drag coefficient referred to ``diameter``. [-]
    diameter : float or array_like
        Reference width per unit length. [m]
    amplitude : float or array_like
        Amplitude ``|v_hat|`` of the relative velocity. [m/s]

    Returns
    -------
    float or ndarray
        Linear drag coefficient per unit length. [N·s/m²]

    Notes
    -----
    Lorentz' equivalent linearization (equal dissipation over a cycle):
    ``B = (8 / (3 pi)) * 1/2 rho Cd D |v_hat|`` (DESIGN.md "Drag linearization").
    """
    rho_ = _nonneg_array("rho", rho, "kg/m^3")
    cd_ = _nonneg_array("cd", cd, "-")
    d_ = _nonneg_array("diameter", diameter, "m")
    a_ = _nonneg_array("amplitude", amplitude, "m/s")
    return _out(8.0 / (3.0 * math.pi) * 0.5 * rho_ * cd_ * d_ * a_)


# ---------------------------------------------------------------------------------
# vector (normal-plane) form
# ---------------------------------------------------------------------------------


def _vector_zero_mean(s1: np.ndarray, s2: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Diagonal of E[|v| I + v v^T/|v|] in the principal frame, v ~ N(0, diag(s1², s2²)).

    Closed form with complete elliptic integrals (parameter m = 1 - s2²/s1², s1 >= s2).
    """
    a = s1
    pos = a > 0
    a_safe = np.where(pos, a, 1.0)
    m = np.where(pos, 1.0 - (s2 / a_safe) ** 2, 0.0)
    m = np.clip(m, 0.0, 1.0)
    small = m < 1e-4
    one = m >= 1.0
    m_mid = np.where(small | one, 0.5, m)
    from scipy import special  # (here: only a 3-D line's drag needs it)

    kk = special.ellipk(m_mid)
    ee = special.ellipe(m_mid)
    # (E - (1-m) K)/m and (K - E)/m, with series near m = 0 and the limit at m = 1
    q_c = np.where(
        small,
        0.25 * math.pi * (1.0 + m / 8.0 + 3.0 * m**2 / 64.0),
        (ee - (1.0 - m_mid) * kk) / m_mid,
    )
    q_c = np.where(one, 1.0, q_c)
    q_s = np.where(
        small,
        0.25 * math.pi * (1.0 + 3.0 * m / 8.0 + 15.0 * m**2 / 64.0),
        (kk - ee) / m_mid,
    )
    q_s = np.where(one, 0.0, q_s)  # multiplied by s2 = 0 anyway
    e_m = np.where(small, 0.5 * math.pi * (1.0 - m / 4.0 - 3.0 * m**2 / 64.0), ee)
    e_m = np.where(one, 1.0, e_m)
    c = math.sqrt(math.pi / 2.0) * (2.0 / math.pi)
    mean_abs = c * a * e_m
    e11 = c * a * q_c
    e22 = c * np.where(pos, s2**2 / a_safe, 0.0) * q_s
    return mean_abs + e11, mean_abs + e22


def _graded_gauss_nodes(
    center: np.ndarray, radius: float, step: float, ratio: float, levels: int, order: int
) -> tuple[np.ndarray, np.ndarray]:
    """Composite Gauss-Legendre nodes on [-radius, radius], geometrically graded toward
    ``center`` (per element), weighted by the standard normal density.

    Returns nodes (n_el, n_nodes) and weights (n_el, n_nodes) summing to 1.
    """
    n_el = center.shape[0]
    uniform = np.arange(-radius, radius + 0.5 * step, step)
    offsets = step * ratio ** np.arange(levels)
    c = np.clip(center, -2.0 * radius, 2.0 * radius)[:, None]
    graded = np.concatenate([c - offsets, c, c + offsets], axis=1)
    pts = np.concatenate([np.broadcast_to(uniform, (n_el, uniform.size)), graded], axis=1)
    pts = np.sort(np.clip(pts, -radius, radius), axis=1)
    lo, hi = pts[:, :-1], pts[:, 1:]
    xg, wg = np.polynomial.legendre.leggauss(order)
    half = 0.5 * (hi - lo)
    mid = 0.5 * (hi + lo)
    nodes = (mid[..., None] + half[..., None] * xg).reshape(n_el, -1)
    w = (half[..., None] * wg).reshape(n_el, -1) * np.exp(-0.5 * nodes**2)
    w /= w.sum(axis=1, keepdims=True)
    return nodes, w


def _vector_quadrature(s1, s2, mu1, mu2, chunk: int = 64):
    """E[|v| I + v v^T/|v|] (3 entries: 11, 12, 22) in the principal frame by graded
    tensor Gauss-Legendre quadrature against the Gaussian weight."""
    n = s1.shape[0]
    out = np.empty((n, 3))
    radius, step, ratio, levels, order = 8.5, 1.5, 0.15, 10, 5
    for lo in range(0, n, chunk):
        sl = slice(lo, min(n, lo + chunk))
        a1, a2, m1, m2 = s1[sl], s2[sl], mu1[sl], mu2[sl]
        c1 = np.where(a1 > 0, -m1 / np.where(a1 > 0, a1, 1.0), 2 * radius)
        c2 = np.where(a2 > 0, -m2 / np.where(a2 > 0, a2, 1.0), 2 * radius)
        x, wx = _graded_gauss_nodes(c1, radius, step, ratio, levels, order)
        y, wy = _graded_gauss_nodes(c2, radius, step, ratio, levels, order)
        v1 = (m1[:, None] + a1[:, None] * x)[:, :, None]
        v2 = (m2[:, None] + a2[:, None] * y)[:, None, :]
        r = np.sqrt(v1**2 + v2**2)
        inv = np.divide(1.0, r, out=np.zeros_like(r), where=r > 0)
        w = wx[:, :, None] * wy[:, None, :]
        e_abs = np.einsum("kij,kij->k", w, r)
        out[sl, 0] = e_abs + np.einsum("kij,kij->k", w, v1**2 * inv)
        out[sl, 1] = np.einsum("kij,kij->k", w, v1 * v2 * inv)
        out[sl, 2] = e_abs + np.einsum("kij,kij->k", w, v2**2 * inv)
    return out


def drag_linear_vector(
    rho: float | np.ndarray,
    cd: float | np.ndarray,
    diameter: float | np.ndarray,
    cov: np.ndarray,
    mean: np.ndarray | None = None,
) -> np.ndarray:
    r"""Exact linearized drag matrix for a Gaussian velocity in the plane normal to an element.

    Parameters
    ----------
    rho : float or array_like
        Fluid density, broadcast over elements. [kg/m³]
    cd : float or array_like
        Normal drag coefficient, broadcast over elements. [-]
    diameter : float or array_like
        Hydrodynamic diameter, broadcast over elements. [m]
    cov : array_like, shape (..., 2, 2)
        Covariance of the two normal-plane components of the relative velocity
        (symmetric positive semi-definite). [m²/s²]
    mean : array_like, shape (..., 2), optional
        Mean relative velocity in the normal plane (current).  ``None`` means zero
        mean and selects the closed form. [m/s]

    Returns
    -------
    ndarray, shape (..., 2, 2)
        Linear drag matrix ``B`` per unit length, in the same 2-D basis as
        ``cov``. [N·s/m²]

    Notes
    -----
    For ``f = 1/2 rho Cd D |v| v`` and Gaussian ``v``,
    ``B = E[d f/d v] = 1/2 rho Cd D E[|v| I + v v^T / |v|]``
    (DESIGN.md "Drag linearization"; it is also Borgman's least-squares fit,
    by Stein's lemma).  In the principal frame of ``cov`` (standard deviations
    ``s1 >= s2``) and for zero mean, with ``m = 1 - s2²/s1²`` and complete elliptic
    integrals ``K(m), E(m)``:

    - ``E|v| = sqrt(2/pi) s1 E(m)``,
    - ``E[v1²/|v|] = sqrt(2/pi) s1 (E - (1-m) K)/m``,
    - ``E[v2²/|v|] = sqrt(2/pi) (s2²/s1) (K - E)/m``, ``E[v1 v2/|v|] = 0``.

    With velocity in one direction only (``s2 = 0``, ``m = 1``):
    ``B11 = 1/2 rho Cd D * 2 sqrt(2/pi) s1 = sqrt(8/pi) 1/2 rho Cd D sigma``, the seed
    form (Tuah 1982, eq. 5.2.2.a), and ``B22 = B11 / 2``: the out-of-line
    fluctuation is damped at half the in-line rate.  For an isotropic velocity
    (``s1 = s2 = sigma``) ``B = (3/2) sqrt(pi/2) 1/2 rho Cd D sigma I``, 18 % more
    than the seed form applied to each component separately (the magnitude
    ``|v|`` sees both components).

    With a mean the expectation is integrated numerically in the principal frame:
    a tensor Gauss-Legendre rule on ``[-8.5, 8.5]`` standard deviations,
    geometrically graded (ratio 0.15, 10 levels) toward the point where ``v = 0``,
    so the kink of ``|v|`` is resolved; the relative error is below about 5e-8
    (checked against the closed form and the scalar current form).
    """
    rho_ = _nonneg_array("rho", rho, "kg/m^3")
    cd_ = _nonneg_array("cd", cd, "-")
    d_ = _nonneg_array("diameter", diameter, "m")
    cov_ = _v.float_array("cov", cov, "m^2/s^2", ndim=None)
    if cov_.ndim < 2 or cov_.shape[-2:] != (2, 2):
        raise InputError("cov", cov_, "m^2/s^2", "must have shape (..., 2, 2)")
    if not np.allclose(cov_, np.swapaxes(cov_, -1, -2), rtol=1e-10, atol=0.0):
        raise InputError("cov", cov_, "m^2/s^2", "must be symmetric")
    lead = cov_.shape[:-2]
    lam, q = np.linalg.eigh(cov_.reshape(-1, 2, 2))
    scale = np.maximum(np.abs(lam).max(axis=1), np.finfo(float).tiny)
    if (lam[:, 0] < -1e-10 * scale).any():
        raise InputError("cov", cov_, "m^2/s^2", "must be positive semi-definite")
    lam = np.clip(lam, 0.0, None)
    s2, s1 = np.sqrt(lam[:, 0]), np.sqrt(lam[:, 1])
    qm = q[:, :, ::-1]  # columns: major, minor principal directions
    if mean is None:
        d11, d22 = _vector_zero_mean(s1, s2)
        e = np.zeros((s1.size, 2, 2))
        e[:, 0, 0], e[:, 1, 1] = d11, d22
    else:
        mu = _finite_array("mean", mean, "m/s")
        if mu.shape[-1:] != (2,):
            raise InputError("mean", mu, "m/s", "must have shape (..., 2)")
        mu = np.broadcast_to(mu, lead + (2,)).reshape(-1, 2)
        mu_p = np.einsum("kji,kj->ki", qm, mu)
        ent = _vector_quadrature(s1, s2, mu_p[:, 0], mu_p[:, 1])
        e = np.empty((s1.size, 2, 2))
        e[:, 0, 0], e[:, 0, 1], e[:, 1, 0], e[:, 1, 1] = ent[:, 0], ent[:, 1], ent[:, 1], ent[:, 2]
    b = qm @ e @ np.swapaxes(qm, -1, -2)
    b = b.reshape(lead + (2, 2))
    kappa = np.asarray(0.5 * rho_ * cd_ * d_)
    return kappa[..., None, None] * b


# ---------------------------------------------------------------------------------
# quality indicators
# ---------------------------------------------------------------------------------

# |U|/sigma above which erf = 1 and exp(-U^2/2 sigma^2) = 0 in double precision
_MU_LARGE = 8.5


def borgman_variance_ratio(
    sigma: float | np.ndarray, mean: float | np.ndarray = 0.0
) -> np.ndarray | float:
    r"""Variance of the linearized drag force over that of the quadratic drag force.

    Parameters
    ----------
    sigma : float or array_like
        Standard deviation of the Gaussian relative velocity. [m/s]
    mean : float or array_like, optional
        Its mean (current). [m/s]

    Returns
    -------
    float or ndarray
        ``Var(B v) / Var(c |v| v)`` with ``B = 2 c E|v|`` the statistically
        linearized coefficient (:func:`drag_linear_current`), between 0.822 (at
        ``|mean| = 0.76 sigma``) and 1. [-]

    Notes
    -----
    For ``v ~ N(U, sigma^2)`` and ``mu = U/sigma`` (``c`` cancels):
    ``Var(B v) = 4 (E|v|)^2 sigma^2`` and
    ``Var(v|v|) = E[v^4] - (E[v|v|])^2`` with
    ``E[v^4] = U^4 + 6 U^2 sigma^2 + 3 sigma^4`` and ``E[v|v|]`` of
    :func:`mean_drag_gaussian`.  Zero mean: ``(8/pi) sigma^4 / (3 sigma^4)
    = 8/(3 pi) = 0.8488`` — the linear model carries 85 % of the variance of the
    drag force (the rest is in its odd harmonics, Borgman 1972).  It tends to 1 for
    ``|mu| -> inf`` (a small fluctuation about a current is linear to first order:
    ``Var = 4 U^2 sigma^2 + 2 sigma^4``); beyond ``|mu| = 8.5`` that form is used (no
    cancellation).  ``sigma = 0`` gives the limits: 1 with a current, 8/(3 pi)
    without.
    """
    s_ = _nonneg_array("sigma", sigma, "m/s")
    u_ = _finite_array("mean", mean, "m/s")
    s_, u_ = np.broadcast_arrays(s_, u_)
    pos = s_ > 0
    mu = np.abs(np.where(pos, u_ / np.where(pos, s_, 1.0), np.where(u_ != 0, np.inf, 0.0)))
    large = mu > _MU_LARGE
    m = np.where(large, 0.0, mu)
    erf = _erf(m / math.sqrt(2.0))
    ex = _SQRT_2_OVER_PI * np.exp(-0.5 * m**2)
    e_abs = m * erf + ex  # E|v| / sigma
    e_vv = (m**2 + 1.0) * erf + m * ex  # E[v|v|] / sigma^2
    var_q = m**4 + 6.0 * m**2 + 3.0 - e_vv**2
    small_ratio = 4.0 * e_abs**2 / var_q
    ml = np.where(large & np.isfinite(mu), mu, 1.0)
    large_ratio = np.where(np.isfinite(mu), 4.0 * ml**2 / (4.0 * ml**2 + 2.0), 1.0)
    return _out(np.where(large, large_ratio, small_ratio))


def drag_inertia_ratio(
    rho: float | np.ndarray,
    cd: float | np.ndarray,
    cm: float | np.ndarray,
    diameter: float | np.ndarray,
    sigma_velocity: float | np.ndarray,
    sigma_acceleration: float | np.ndarray,
    mean: float | np.ndarray = 0.0,
) -> np.ndarray | float:
    r"""Size of the linearized drag force relative to the Morison inertia force.

    Parameters
    ----------
    rho : float or array_like
        Fluid density. [kg/m³]
    cd : float or array_like
        Normal drag coefficient. [-]
    cm : float or array_like
        Inertia coefficient ``C_M = 1 + Ca``. [-]
    diameter : float or array_like
        Hydrodynamic diameter. [m]
    sigma_velocity : float or array_like
        σ of the normal relative velocity. [m/s]
    sigma_acceleration : float or array_like
        σ of the normal fluid acceleration. [m/s²]
    mean : float or array_like, optional
        Mean normal relative velocity (current). [m/s]

    Returns
    -------
    float or ndarray
        ``sigma(B v) / sigma(rho C_M (pi D²/4) a)`` (inf where the acceleration is
        zero and the drag is not). [-]

    Notes
    -----
    ``B = rho Cd D E|v|`` (:func:`drag_linear_current`), so without current the ratio
    is ``sqrt(8/pi) (1/2) rho Cd D sigma_v^2 / (rho C_M (pi D²/4) sigma_a)
    = (2 sqrt(8/pi)/pi) (Cd/C_M) sigma_v^2/(sigma_a D)``.  For a narrow-band wave
    of frequency ω (``sigma_a = ω sigma_v``) this is
    ``(sqrt(8/pi)/pi²) (Cd/C_M) KC_sigma`` with the Keulegan–Carpenter number
    ``KC_sigma = sigma_v T / D``: drag dominates (ratio > 1) on thin members in
    large motions, inertia on thick ones (ratio << 1), where the drag
    linearization hardly matters.
    """
    rho_ = _nonneg_array("rho", rho, "kg/m^3")
    cd_ = _nonneg_array("cd", cd, "-")
    cm_ = _nonneg_array("cm", cm, "-")
    d_ = _nonneg_array("diameter", diameter, "m")
    sv = _nonneg_array("sigma_velocity", sigma_velocity, "m/s")
    sa = _nonneg_array("sigma_acceleration", sigma_acceleration, "m/s^2")
    u_ = _finite_array("mean", mean, "m/s")
    drag = rho_ * cd_ * d_ * mean_abs_gaussian(sv, u_) * sv
    inertia = rho_ * cm_ * math.pi * d_**2 / 4.0 * sa
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(
            inertia > 0, drag / np.where(inertia > 0, inertia, 1.0), np.where(drag > 0, np.inf, 0.0)
        )
    return _out(ratio)
