"""The bound that proves a lock-in start grid holds no start, in NumPy (no numba).

:func:`stochcable.line.strumming.kernels.balance_grid` evaluates the modal residual of
the lock-in balance on an (amplitude × frequency) grid, except where a bound proves it
is at least 0.5 (its module notes): |L| ≤ min(S₁ + S₂A^(1/3), S_lin A) per frequency,
and a point where that is at most |Z A|/3 holds 1.0.  :func:`grid_is_proven` checks
that bound on the whole grid first: when every point is proven, the grid holds no
start and the compiled kernel (and numba) is not needed — the common case (the bundled
chain's three candidate modes: every point proven).  The same formulas as the kernel's,
evaluated for all frequencies and elements at once.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["LockInGrid", "grid_is_proven"]


@dataclass(frozen=True)
class LockInGrid:
    """The (amplitude × frequency) start grid of one mode's lock-in balance.

    Parameters
    ----------
    amps : ndarray, shape (n_a,)
        Modal amplitudes A. [kg^1/2·m]
    omegas : ndarray, shape (n_w,)
        Response frequencies ω. [rad/s]
    omega_n : float
        Natural frequency. [rad/s]
    damping_ratio : float
        ξ of the mode. [-]
    psi, q, diameter, omega_s, lift0 : ndarray, shape (n,)
        Mode displacement along the lift [kg^-1/2], ½ρDU_n²L [N], diameter [m],
        shedding frequency [rad/s] and C_L0 [-] of the shedding elements.
    g, big_h, f : float
        Ḡ, H̄, F̄ of the wake oscillator. [-]
    """

    amps: np.ndarray
    omegas: np.ndarray
    omega_n: float
    damping_ratio: float
    psi: np.ndarray
    q: np.ndarray
    diameter: np.ndarray
    omega_s: np.ndarray
    lift0: np.ndarray
    g: float
    big_h: float
    f: float


def grid_is_proven(grid: LockInGrid) -> bool:
    """Whether the bound proves the balance's residual at least 0.5 at every grid point.

    Parameters
    ----------
    grid : LockInGrid
        The start grid and the mode's shedding elements.

    Returns
    -------
    bool
        True when :func:`~stochcable.line.strumming.kernels.balance_grid` would hold
        1.0 at every point (no start).
    """
    omega_n, big_h, g, f = grid.omega_n, grid.big_h, grid.g, grid.f
    omegas, omega_s, psi, q = grid.omegas, grid.omega_s, grid.psi, grid.q
    w = np.asarray(omegas, float)[:, None]  # (n_w, 1)
    ws = np.asarray(omega_s, float)[None, :]  # (1, n)
    psi, q = np.asarray(psi, float), np.asarray(q, float)
    lift0sq = np.asarray(grid.lift0, float) ** 2
    r2 = (w / ws) ** 2
    a0r = ws * ws - w * w + ws * ws * big_h * lift0sq
    a0i = -w * ws * g * lift0sq
    a1r = -ws * ws * big_h * (3.0 + r2) / 4.0
    a1i = w * ws * g * (1.0 + 3.0 * r2) / 4.0
    rhs_unit = ws * f * w * psi / np.asarray(grid.diameter, float)
    weight = np.abs(q * psi)
    alpha = w * ws * g * lift0sq
    with np.errstate(divide="ignore", invalid="ignore"):
        s1 = np.sum(weight * np.sqrt(2.0 * alpha / a1i), axis=1)
        s2 = np.sum(
            weight * (4.0 / (a1i * a1i)) ** (1.0 / 6.0) * np.abs(rhs_unit) ** (1 / 3), axis=1
        )
        dot = a0r * a1r + a0i * a1i
        dist = np.where(
            dot >= 0.0,
            np.hypot(a0r, a0i),
            np.abs(a0r * a1i - a0i * a1r) / np.sqrt(a1r * a1r + a1i * a1i),
        )
        s_lin = np.sum(np.where(dist > 0.0, weight * np.abs(rhs_unit) / dist, np.inf), axis=1)
    w = w[:, 0]
    z_abs = np.hypot(omega_n * omega_n - w * w, 2.0 * grid.damping_ratio * omega_n * w)
    a = np.asarray(grid.amps, float)[:, None]
    bound = np.minimum(s1 + s2 * a ** (1.0 / 3.0), s_lin * a)
    return bool(np.all(bound <= z_abs * a / 3.0))
