"""Time-domain wake oscillator coupled to one natural mode: the independent check of
the frequency-domain strumming balance (a validation tool, not a pipeline stage).

The same equations as :mod:`stochcable.line.strumming.balance` (Tuah (1982), eqs.
3.2.b.3 and 3.2.b.7–9, C_L0² in the bracket), integrated in time by
:func:`scipy.integrate.solve_ivp` (DOP853) as Tuah (1982) integrates them (by mode
superposition, its §3.2.b steps (5)–(10)) instead of balanced by harmonics::

    z̈ + 2ξω_n ż + ω_n² z = Σ_e q_e ψ_e C_e
    C̈_e + ω_s,e² C_e − [C_L0,e² − C_e² − (Ċ_e/ω_s,e)²]·(ω_s,e Ḡ Ċ_e − ω_s,e² H̄ C_e)
        = ω_s,e F̄ ψ_e ż / D_e

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from stochcable.errors import InputError
from stochcable.line.strumming.balance import WakeParameters

__all__ = ["WakeHistory", "simulate_wake_oscillator"]


@dataclass(frozen=True, eq=False)
class WakeHistory:
    """Time history of a mode and its wakes.

    Attributes
    ----------
    t : ndarray, shape (n_t,)
        Time. [s]
    z : ndarray, shape (n_t,)
        Modal coordinate (mass-normalized shapes). [kg^1/2·m]
    lift : ndarray, shape (n_el, n_t)
        Lift coefficient of every element. [-]
    """

    t: np.ndarray
    z: np.ndarray
    lift: np.ndarray

    def amplitude(self, start: float) -> float:
        """Largest |z| from time ``start`` on. [kg^1/2·m]"""
        return float(np.max(np.abs(self.z[self.t >= start])))


def simulate_wake_oscillator(
    omega_n: float,
    damping_ratio: float,
    psi: np.ndarray,
    q: np.ndarray,
    diameter: np.ndarray,
    omega_s: np.ndarray,
    lift0: np.ndarray,
    params: WakeParameters,
    duration: float,
    *,
    dt_out: float | None = None,
    z0: float = 0.0,
    lift_start: np.ndarray | None = None,
) -> WakeHistory:
    """Integrate the coupled mode and wake oscillators from a given start.

    Parameters
    ----------
    omega_n, damping_ratio : float
        Natural frequency [rad/s] and damping ratio [-] of the mode.
    psi, q, diameter, omega_s, lift0 : ndarray, shape (n_el,)
        As :func:`stochcable.line.strumming.balance.lock_in_balance`.
    params : WakeParameters
    duration : float
        Simulated time (> 0). [s]
    dt_out : float, optional
        Output step (default 1/40 of the shortest shedding period). [s]
    z0 : float, optional
        Initial modal displacement (velocity zero). [kg^1/2·m]
    lift_start : ndarray, optional
        Initial lift coefficients (default C_L0, rates zero: Tuah's (1982) start). [-]

    Returns
    -------
    WakeHistory
    """
    if not duration > 0:
        raise InputError("duration", duration, "s", "must be > 0")
    psi = np.asarray(psi, dtype=float)
    live = np.asarray(q) > 0
    ws = np.where(live, np.asarray(omega_s, dtype=float), 1.0)
    c0sq = np.asarray(lift0, dtype=float) ** 2
    coef = np.where(live, np.asarray(q) * psi, 0.0)
    drive = np.where(live, ws * params.f * psi / np.asarray(diameter, dtype=float), 0.0)
    n = psi.size
    g, h = params.g, params.big_h

    def rhs(_t: float, y: np.ndarray) -> np.ndarray:
        z, zd = y[0], y[1]
        c, cd = y[2 : 2 + n], y[2 + n :]
        zdd = coef @ c - 2.0 * damping_ratio * omega_n * zd - omega_n**2 * z
        b = c0sq - c**2 - (cd / ws) ** 2
        cdd = -(ws**2) * c + b * (ws * g * cd - ws**2 * h * c) + drive * zd
        return np.concatenate(([zd, zdd], cd, np.where(live, cdd, 0.0)))

    start = np.asarray(lift0, dtype=float) if lift_start is None else np.asarray(lift_start)
    y0 = np.concatenate(([z0, 0.0], np.where(live, start, 0.0), np.zeros(n)))
    step = dt_out if dt_out is not None else 2 * np.pi / float(ws[live].max()) / 40.0
    t_eval = np.arange(0.0, duration + 0.5 * step, step)
    sol = solve_ivp(
        rhs, (0.0, float(t_eval[-1])), y0, method="DOP853", t_eval=t_eval, rtol=1e-8, atol=1e-10
    )
    return WakeHistory(t=sol.t, z=sol.y[0], lift=sol.y[2 : 2 + n])
