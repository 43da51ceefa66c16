"""Statistical linearization of the Hu & Jin normal drag ½ρC_dD|V|V_n.

A line with ``drag_form = "hu_jin"`` (docs/travelling.md) loads each element with the
normal drag of the whole relative flow V = (V_n, W), W the axial relative flow (the
current's axial part minus the transport speed c):

    f_n = ½ ρ C_d D |V| V_n,    |V| = √(V_n² + W²)        (Hu & Jin 2001, eq. 6)

instead of the cross-flow ½ρC_dD|V_n|V_n.  Along the mean normal flow the normal
relative velocity is v ~ N(U, σ²) (U = |U_n|, the seed's one-component model,
Tuah 1982, §5.2) and W is taken at its mean.  Statistical linearization (Borgman 1972;
Roberts & Spanos 1990, §5.2: B = E[∂f/∂v] for a Gaussian v) gives

    ∂f/∂v = ½ρC_dD (2v² + W²)/√(v² + W²),
    B = ½ρC_dD E[(2v² + W²)/√(v² + W²)].

Checks: W = 0 gives ½ρC_dD·2E|v| = ρC_dD E|v|, the cross-flow coefficient
(:func:`stochcable.dynamics.linearization.formulas.drag_linear_current`); σ = 0 gives
the tangent ½ρC_dD (2U² + W²)/√(U² + W²) of the steady drag; |W| ≫ |v| gives ½ρC_dD|W|
(the drag becomes linear in v, the axial flow's "linearizing" effect).  The expectation
has no elementary closed form: Gauss–Legendre quadrature in the standardized variable
z = (v − U)/σ over [−9, 9] (the Gaussian tail beyond 9σ is below 1e-18), split at the
kink-like point v = 0 (z₀ = −U/σ), 96 nodes on each side.

Left out: the fluctuating axial flow's contribution to the normal force
(∂f_n/∂W = ½ρC_dD V_n W/|V|, a normal force from axial motion), a cross-coupling the
line's scalar normal/axial damping has no room for; it is second order where the mean
normal flow U is small against σ.

References
----------
Hu, J. & Jin, W. (2001), Non-linear dynamics of a suspended travelling cable subject to
transverse fluid excitation, eq. 6.
Roberts, J.B. & Spanos, P.D. (1990), Random Vibration and Statistical Linearization, §5.2.
"""

from __future__ import annotations

import numpy as np

from stochcable import validation as _v

__all__ = ["drag_linear_hu_jin", "hu_jin_slope"]

_Z_MAX = 9.0  # standardized half-width: the Gaussian tail beyond 9σ is < 1e-18
_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(96)


def hu_jin_slope(v: np.ndarray, axial: np.ndarray) -> np.ndarray:
    """∂(|V| v)/∂v = (2v² + W²)/√(v² + W²) (0 at v = W = 0). [m/s]"""
    r = np.sqrt(v * v + axial * axial)
    return np.divide(2.0 * v * v + axial * axial, r, out=np.zeros_like(r), where=r > 0.0)


def _expect_slope(sigma: np.ndarray, mean: np.ndarray, axial: np.ndarray) -> np.ndarray:
    """E[(2v² + W²)/√(v² + W²)] for v ~ N(mean, σ²), σ > 0 (quadrature, module notes)."""
    z0 = np.clip(-mean / sigma, -_Z_MAX, _Z_MAX)[..., None]
    out = np.zeros(sigma.shape)
    for lo, hi in ((-_Z_MAX, z0), (z0, _Z_MAX)):
        half = 0.5 * (hi - lo)
        z = 0.5 * (hi + lo) + half * _NODES
        pdf = np.exp(-0.5 * z * z) / np.sqrt(2.0 * np.pi)
        v = mean[..., None] + sigma[..., None] * z
        f = hu_jin_slope(v, axial[..., None])
        out = out + np.sum(_WEIGHTS * half * pdf * f, axis=-1)
    return out


def drag_linear_hu_jin(
    rho: float | np.ndarray,
    cd: float | np.ndarray,
    diameter: float | np.ndarray,
    sigma: float | np.ndarray,
    mean: float | np.ndarray,
    axial: float | np.ndarray,
) -> np.ndarray:
    """Linear normal-drag coefficient of ½ρC_dD|V|V_n for a Gaussian normal relative
    velocity (module notes).

    Parameters
    ----------
    rho : float or array_like
        Fluid density. [kg/m³]
    cd : float or array_like
        Normal drag coefficient. [-]
    diameter : float or array_like
        Hydrodynamic diameter. [m]
    sigma : float or array_like
        Standard deviation of the normal relative velocity. [m/s]
    mean : float or array_like
        Mean normal relative velocity (the current's normal magnitude). [m/s]
    axial : float or array_like
        Mean axial relative velocity W = U·e − c (current along the element minus the
        transport speed). [m/s]

    Returns
    -------
    ndarray
        Linear drag coefficient B per unit length. [N·s/m²]

    Notes
    -----
    B = ½ρC_dD E[(2v² + W²)/√(v² + W²)], v ~ N(mean, σ²); W = 0 reduces to ρC_dD E|v|
    (the cross-flow coefficient).  The quadrature's error is below 1e-6 relative for
    |W| ≥ 0.01σ and below 1e-4 for smaller |W| (tests/dynamics/test_linearization_hu_jin.py).
    """
    rho_ = np.asarray(_v.float_array("rho", rho, "kg/m³", nonnegative=True, ndim=None))
    cd_ = np.asarray(_v.float_array("cd", cd, "-", nonnegative=True, ndim=None))
    d_ = np.asarray(_v.float_array("diameter", diameter, "m", nonnegative=True, ndim=None))
    s_ = np.asarray(_v.float_array("sigma", sigma, "m/s", nonnegative=True, ndim=None))
    u_ = np.asarray(_v.float_array("mean", mean, "m/s", ndim=None))
    w_ = np.asarray(_v.float_array("axial", axial, "m/s", ndim=None))
    s_, u_, w_ = np.broadcast_arrays(s_, u_, w_)
    pos = s_ > 0.0
    e = hu_jin_slope(u_, w_)  # σ = 0: the steady tangent
    if pos.any():
        e = np.where(pos, _expect_slope(np.where(pos, s_, 1.0), u_, w_), e)
    return 0.5 * rho_ * cd_ * d_ * e
