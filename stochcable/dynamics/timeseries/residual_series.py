"""The residuals of the linear model in the end-tension time series: an independent
Gaussian component with the residuals' spectral density.

The end tension's spectrum with the residuals is the linear spectrum plus the
residuals' spectra (:mod:`stochcable.dynamics.residuals.corrected`): the residuals are
uncorrelated with the linear response at every lag (Hermite orthogonality for the drag's
orders ≥ 2, odd Gaussian moments for the geometric forces; Roberts and Spanos, "Random
Vibration and Statistical Linearization", §5).  A record whose σ and spectrum are the
corrected ones is therefore the linear record (the transfer functions times the sea's
and end motions' realizations, :mod:`.synthesis`) plus a process with the residuals'
density S_r = S_corrected − S_linear, uncorrelated with it.  It is synthesized here as a
Gaussian process (random phases, DSA or NSA amplitudes as the record's method,
:func:`stochcable.sea.realization.simulate_sea`) from its own generator: its second-order
statistics are the residuals', its skewness and kurtosis are not (the residuals are
non-Gaussian: a record for extremes or rainflow counting carries the corrected σ and
spectrum, not the residuals' higher moments).  Each end's component is drawn
independently (the residuals' cross-spectrum between the ends is not formed).

S_r is read from the line's corrected density
(:meth:`stochcable.results.documents.LineResult.end_tension_density`, the analysis grid
and the residual lines outside it) less its linear density on the analysis grid (zero
outside it), clipped at zero: the drag's linear misfit may lower the density at a
frequency (a change of the linear part, not an independent process), which the
component cannot; its share is below 1e-3 of the residual variance on the bundled lines.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from stochcable.errors import ResolutionWarning, warn
from stochcable.sea.realization import frequency_grid, simulate_sea

__all__ = [
    "NYQUIST_SHARE",
    "residual_density",
    "residual_motion_density",
    "residual_series",
    "residual_tension_series",
]

#: Share of the residuals' variance above the Nyquist frequency π/dt of the record
#: beyond which a ResolutionWarning says the record's σ falls short of the corrected
#: one (as the sea realization's own check). [-]
NYQUIST_SHARE = 1e-3


def residual_density(line: Any, end: str) -> tuple[np.ndarray, np.ndarray] | None:
    """The residuals' spectral density of the tension at ``end`` (module notes).

    Parameters
    ----------
    line : LineResult
        The line's result (its ``corrected_spectra`` and linear end-tension spectrum).
    end : str
        "end_a" or "end_b".

    Returns
    -------
    tuple of ndarray or None
        Frequencies [rad/s] and one-sided density S_r ≥ 0 [N²·s/rad]; None where no
        residual was applied (the series is the linear one).
    """
    if getattr(line, "corrected_spectra", None) is None:
        return None
    return _less_linear(*line.end_tension_density(end), line.omega, line.end_tension_spectrum(end))


def residual_tension_series(
    line: Any,
    end: str,
    duration: float,
    dt: float,
    method: str,
    rng: np.random.Generator,
) -> np.ndarray | None:
    """One Gaussian realization of the residuals' part of the tension at ``end``.

    Parameters
    ----------
    line : LineResult
        The line's result.
    end : str
        "end_a" or "end_b".
    duration : float
        Record length. [s]
    dt : float
        Time step. [s]
    method : {"dsa", "nsa"}
        Spectral amplitude model of the record.
    rng : numpy.random.Generator
        The component's generator (its phases, and its amplitudes with NSA).

    Returns
    -------
    ndarray, shape (duration/dt,) or None
        The zero-mean component [N], None where no residual was applied.

    Warns
    -----
    ResolutionWarning
        When more than 0.1 % of the residuals' variance lies above the Nyquist
        frequency π/dt (their superharmonics reach three times the analysis grid's top).
    """
    dens = residual_density(line, end)
    if dens is None:
        return None
    label = f"line '{getattr(line, 'name', '?')}' {end}"
    return residual_series(dens[0], dens[1], duration, dt, method, rng, label)


def residual_motion_density(body: Any, dof: str) -> tuple[np.ndarray, np.ndarray] | None:
    """The residuals' spectral density of a free body's ``dof`` (as
    :func:`residual_density` of an end: its density with the residuals,
    :meth:`stochcable.results.documents.BodyResult.motion_density`, less its linear
    one, clipped at zero); None where its motion carries no residual."""
    if getattr(body, "corrected_spectra", None) is None:
        return None
    linear = body.motion_spectrum[body.dofs.index(dof)]
    return _less_linear(*body.motion_density(dof), body.omega, linear)


def _less_linear(
    omega: np.ndarray, density: np.ndarray, w: np.ndarray, linear: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """``density`` on ``omega`` less the ``linear`` density on the analysis grid ``w``
    (zero outside it), clipped at zero (module notes)."""
    omega = np.asarray(omega, dtype=float)
    w = np.asarray(w, dtype=float)
    lin = np.interp(omega, w, linear, left=0.0, right=0.0)
    inside = (omega >= w[0]) & (omega <= w[-1])
    return omega, np.maximum(np.asarray(density, dtype=float) - np.where(inside, lin, 0.0), 0.0)


def residual_series(
    omega: np.ndarray,
    s_r: np.ndarray,
    duration: float,
    dt: float,
    method: str,
    rng: np.random.Generator,
    label: str,
) -> np.ndarray | None:
    """One Gaussian realization of a process of one-sided density ``s_r`` on ``omega``
    (the residuals' part of a response, module notes): as
    :func:`residual_tension_series`, ``label`` naming the response in the warning;
    None where the density has nothing on the record's lines."""
    if not np.any(s_r > 0):
        return None
    grid, _ = frequency_grid(duration, dt)
    top = float(grid[-1])  # (π/dt: what lies above is said in the residuals' terms)

    def density(w: np.ndarray) -> np.ndarray:
        w = np.asarray(w, dtype=float)
        return np.where(w <= top, np.interp(w, omega, s_r, left=0.0, right=0.0), 0.0)

    if not np.any(density(grid[1:-1]) > 0):  # (nothing on the record's lines)
        return None
    _nyquist_check(label, omega, s_r, dt)
    return np.asarray(simulate_sea(density, duration, dt, method, rng=rng).elevation)


def _nyquist_check(label: str, omega: np.ndarray, s_r: np.ndarray, dt: float) -> None:
    """ResolutionWarning when more than :data:`NYQUIST_SHARE` of the residuals'
    variance lies above π/dt."""
    top = math.pi / dt
    total = float(np.trapezoid(s_r, omega))
    above = omega >= top
    if total <= 0.0 or not np.any(above):
        return
    w = np.concatenate(([top], omega[above]))
    share = float(np.trapezoid(np.interp(w, omega, s_r), w)) / total
    if share > NYQUIST_SHARE:
        keep = float(omega[np.flatnonzero(s_r > 0)[-1]])
        warn(
            f"{label}: {share:.2%} of the residuals' "
            f"variance (their superharmonics, up to {keep:.3g} rad/s) lies above the "
            f"time series' Nyquist frequency π/dt = {top:.3g} rad/s: the record's σ is "
            "below the corrected one; use analysis.timeseries.dt ≤ "
            f"{math.pi / keep:.3g} s",
            ResolutionWarning,
            stacklevel=4,
        )
