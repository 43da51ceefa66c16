"""A periodic fairlead motion for checks of the time-domain reference: a deterministic
spectral amplitude (DSA) realization whose variance over one whole period is the
spectrum's Riemann sum exactly, with its closed-form derivatives and its FFT
coefficients on any record of whole periods (:mod:`stochcable.reference.moordyn`).

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from stochcable import validation as _v
from stochcable.errors import InputError

__all__ = ["SurgeMotion", "periodic_dsa_surge"]


@dataclass(frozen=True, eq=False)
class SurgeMotion:
    """A periodic surge x(t) = Σ_j a_j cos(ω_j t − θ_j), ω_j = 2πj/T.

    Attributes
    ----------
    omega : ndarray, shape (n,)
        Component frequencies, multiples of 2π/period. [rad/s]
    amplitude : ndarray, shape (n,)
        Amplitudes a_j. [m]
    phase : ndarray, shape (n,)
        Phases θ_j. [rad]
    period : float
        The period T. [s]
    harmonic : ndarray of int, shape (n,)
        j = ω_j·T/2π. [-]
    """

    omega: np.ndarray
    amplitude: np.ndarray
    phase: np.ndarray
    period: float
    harmonic: np.ndarray

    @property
    def std(self) -> float:
        """Standard deviation over one whole period, √(Σ a_j²/2). [m]"""
        return float(math.sqrt(0.5 * float(np.sum(self.amplitude**2))))

    def displacement(self, t: np.ndarray) -> np.ndarray:
        """x(t). [m]"""
        arg = np.multiply.outer(np.asarray(t, float), self.omega) - self.phase
        return np.cos(arg) @ self.amplitude

    def velocity(self, t: np.ndarray) -> np.ndarray:
        """ẋ(t). [m/s]"""
        arg = np.multiply.outer(np.asarray(t, float), self.omega) - self.phase
        return -np.sin(arg) @ (self.amplitude * self.omega)

    def acceleration(self, t: np.ndarray) -> np.ndarray:
        """ẍ(t). [m/s²]"""
        arg = np.multiply.outer(np.asarray(t, float), self.omega) - self.phase
        return -np.cos(arg) @ (self.amplitude * self.omega**2)

    def coefficients(self, n_periods: int, n_samples: int) -> np.ndarray:
        """FFT coefficients X_m (m = 0 … n_samples/2) of x on a record of ``n_periods``
        periods sampled ``n_samples`` times, with x(t_n) = irfft(X)[n]: X_m =
        (n_samples/2)·a_j·e^{−iθ_j} at m = n_periods·j (DESIGN.md "FFT"). [m]"""
        m = n_periods * self.harmonic
        if m.size and int(m.max()) >= n_samples // 2:
            raise InputError(
                "n_samples", n_samples, "-", f"must exceed 2·{int(m.max())} (the top harmonic)"
            )
        out = np.zeros(n_samples // 2 + 1, dtype=complex)
        out[m] = 0.5 * n_samples * self.amplitude * np.exp(-1j * self.phase)
        return out


def periodic_dsa_surge(
    density: Callable[[np.ndarray], np.ndarray],
    period: float,
    band: tuple[float, float],
    rng: np.random.Generator | int,
) -> SurgeMotion:
    """A periodic DSA realization of a motion spectrum over a band.

    Parameters
    ----------
    density : callable
        One-sided motion spectrum S(ω). [m²·s/rad]
    period : float
        Period T of the realization; Δω = 2π/T. [s]
    band : (float, float)
        Components with band[0] <= ω_j <= band[1] are kept. [rad/s]
    rng : Generator or int
        Source of the phases θ_j, uniform on (−π, π]. [-]

    Returns
    -------
    SurgeMotion

    Notes
    -----
    DSA (Tuah (1982), eq. 5.1.1 with DESIGN.md's correction): a_j = √(2 S(ω_j) Δω), so the
    variance over a whole period is Σ S(ω_j)Δω exactly, for every seed.
    """
    period = _v.positive("period", period, "s")
    lo = _v.nonnegative("band[0]", band[0], "rad/s")
    hi = _v.positive("band[1]", band[1], "rad/s")
    if hi <= lo:
        raise InputError("band", band, "rad/s", "must be (low, high) with high > low")
    dw = 2.0 * math.pi / period
    j = np.arange(max(1, int(math.ceil(lo / dw - 1e-9))), int(math.floor(hi / dw + 1e-9)) + 1)
    if j.size == 0:
        raise InputError("period", period, "s", f"gives no component in the band {band} rad/s")
    w = j * dw
    a = np.sqrt(2.0 * np.asarray(density(w), float) * dw)
    gen = np.random.default_rng(rng)
    theta = gen.uniform(-math.pi, math.pi, size=j.size)
    return SurgeMotion(w, a, theta, period, j)
