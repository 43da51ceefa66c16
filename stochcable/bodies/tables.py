"""Frequency-dependent coefficient tables of a body: matrices over ω (added mass,
radiation damping) and the wave excitation over ω and heading, linearly interpolated.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from stochcable.errors import InputError
from stochcable.scene.tables import heading_weights
from stochcable.validation import finite_scalar, float_array

__all__ = ["FrequencyTable", "ExcitationTable"]


def _interp_weights(
    table: np.ndarray, x: np.ndarray, name: str, unit: str, extrapolation: str
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Indices i, i+1 and weight t of the linear interpolation of x in a sorted table."""
    n = table.size
    if n == 1:
        z = np.zeros(x.shape, dtype=int)
        return z, z, np.zeros(x.shape)
    lo, hi = table[0], table[-1]
    slack = 1e-9 * max(abs(lo), abs(hi), 1e-300)
    if extrapolation == "error":
        out = (x < lo - slack) | (x > hi + slack)
        if out.any():
            bad = float(x[np.flatnonzero(out)[0]])
            raise InputError(
                name,
                bad,
                unit,
                f"is outside the table [{lo:g}, {hi:g}]: extend the table or "
                "use extrapolation='hold'",
            )
    xc = np.clip(x, lo, hi)
    i = np.clip(np.searchsorted(table, xc, side="right") - 1, 0, n - 2)
    t = (xc - table[i]) / (table[i + 1] - table[i])
    return i, i + 1, t


@dataclass(frozen=True, eq=False)
class FrequencyTable:
    """Real matrices tabulated over angular frequency, linearly interpolated.

    Parameters
    ----------
    omega : array_like, shape (n,)
        Strictly increasing angular frequencies, >= 0. [rad/s]
    values : array_like, shape (n, d, d)
        A matrix per frequency (added mass [kg, kg·m, kg·m²] or radiation damping
        [N·s/m, N·s, N·m·s]).
    extrapolation : {"error", "hold"}
        Outside [omega[0], omega[-1]]: raise InputError, or hold the end values.
        A one-frequency table is constant everywhere.
    """

    omega: np.ndarray
    values: np.ndarray
    extrapolation: Literal["error", "hold"] = "error"

    def __post_init__(self) -> None:
        w = float_array("omega", self.omega, "rad/s", nonnegative=True, increasing=True)
        v = float_array("values", self.values, "-", ndim=3)
        if v.shape[0] != w.size or v.shape[1] != v.shape[2]:
            raise InputError(
                "values",
                v.shape,
                "-",
                f"must have shape ({w.size}, d, d): one square matrix per omega",
            )
        if self.extrapolation not in ("error", "hold"):
            raise InputError("extrapolation", self.extrapolation, "-", "must be 'error' or 'hold'")
        object.__setattr__(self, "omega", w.copy())
        object.__setattr__(self, "values", v.copy())

    @property
    def size(self) -> int:
        """Matrix size d."""
        return int(self.values.shape[1])

    def at(self, omega: Any) -> np.ndarray:
        """Matrices at ``omega`` (n_w,), linear in ω, shape (n_w, d, d)."""
        x = np.atleast_1d(np.asarray(omega, dtype=float))
        i, j, t = _interp_weights(self.omega, x, "omega", "rad/s", self.extrapolation)
        return (1.0 - t)[:, None, None] * self.values[i] + t[:, None, None] * self.values[j]


@dataclass(frozen=True, eq=False)
class ExcitationTable:
    """Wave excitation force RAOs over frequency and heading.

    Parameters
    ----------
    omega : array_like, shape (n_w,)
        Strictly increasing angular frequencies. [rad/s]
    heading : array_like, shape (n_h,)
        Strictly increasing wave headings, direction of travel from +x toward +y, in
        [heading[0], heading[0] + 2π). [rad]
    values : array_like, complex, shape (n_h, d, n_w)
        Force and moment per unit wave amplitude, time convention Re{X e^{iωt}}, phase
        relative to the incident wave elevation at the table's phase point (see
        :class:`RigidBody` ``excitation_point``). [N/m, N·m/m]
    extrapolation : {"error", "hold"}
        Outside the frequency range: raise, or hold the end values.

    Notes
    -----
    Linear interpolation of the real and imaginary parts in ω and in heading; headings
    wrap around when the table covers the full circle (its closing gap is no larger
    than its largest step), else a heading outside the table is an InputError.
    """

    omega: np.ndarray
    heading: np.ndarray
    values: np.ndarray
    extrapolation: Literal["error", "hold"] = "error"

    def __post_init__(self) -> None:
        w = float_array("omega", self.omega, "rad/s", nonnegative=True, increasing=True)
        h = float_array("heading", self.heading, "rad", increasing=True)
        if h.size > 1 and h[-1] - h[0] >= 2.0 * math.pi:
            raise InputError("heading", h, "rad", "must span less than 2π")
        v = np.asarray(self.values, dtype=complex)
        if v.ndim != 3 or v.shape[0] != h.size or v.shape[2] != w.size:
            raise InputError(
                "values", v.shape, "-", f"must have shape (n_heading={h.size}, d, n_omega={w.size})"
            )
        if not np.isfinite(v).all():
            raise InputError("values", "non-finite", "N/m", "must be finite")
        if self.extrapolation not in ("error", "hold"):
            raise InputError("extrapolation", self.extrapolation, "-", "must be 'error' or 'hold'")
        object.__setattr__(self, "omega", w.copy())
        object.__setattr__(self, "heading", h.copy())
        object.__setattr__(self, "values", v.copy())

    @property
    def size(self) -> int:
        """Number of DOFs d."""
        return int(self.values.shape[1])

    def at(self, omega: Any, heading: float) -> np.ndarray:
        """Excitation at ``omega`` (n_w,) and one ``heading`` [rad], shape (d, n_w)."""
        x = np.atleast_1d(np.asarray(omega, dtype=float))
        beta = finite_scalar("heading", heading, "rad")
        a, b, s = heading_weights(self.heading, beta, "excitation table")
        v = (1.0 - s) * self.values[a] + s * self.values[b]  # (d, n_w_table)
        i, j, t = _interp_weights(self.omega, x, "omega", "rad/s", self.extrapolation)
        return (1.0 - t)[None, :] * v[:, i] + t[None, :] * v[:, j]
