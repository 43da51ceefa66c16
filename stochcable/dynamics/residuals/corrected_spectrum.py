"""The end-tension spectral density with the residuals of the linear model, for what
reads a density (spectral fatigue, the load-case sets' damage).

The residuals' spectra are their variance lines (:class:`ResidualRecord` ``lines``):
uniform lines ω_j = j·Δ up to the highest order times ω_max, whose density is
v_j/Δ (each line the integral of the convolved spectra over its cell), and the drag's
linear misfit as variance changes on the analysis grid itself, whose density is
v_k/q_k (q the trapezoid weights the linear σ is summed with).  The corrected density
lives on the analysis grid extended by the residual lines outside its band (the
superharmonics above ω_max, difference frequencies below ω_min): the linear density
and the misfit's on the analysis frequencies, the uniform lines' densities
interpolated linearly onto every frequency.  The linear density stops at the grid's
ends (the linear model integrates it there): where the grid is extended, a node a
millionth of the end cell beyond ω_max (and below ω_min) carries the residuals'
density alone, so that the trapezoid does not spread the linear density's last value
over the first residual cell outside the band (on the deep catenary of the accuracy
page, whose tension density is largest at ω_max, that triangle held half the
residuals' variance, and the scale below then halved their density everywhere).  The
interpolation changes the area by a fraction of a cell; one factor on the uniform
lines' density (:attr:`CorrectedSpectrum.scale`, within 1 % of 1 on the bundled chain
and the accuracy page's lines) makes ∫S dω by the trapezoid rule equal to the
corrected variance of :func:`stochcable.dynamics.residuals.corrected.corrected_stats`
to round-off.  Its higher moments (m2, m4) then differ from the statistics' line sums
by the interpolation's error only (the fatigue methods read them), and so does its
variance above ω_max from the lines' there.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from stochcable.dynamics.model.blocks import trapezoid_weights
from stochcable.results.records import ResidualRecord

__all__ = [
    "CorrectedSpectrum",
    "corrected_spectra",
    "corrected_spectrum",
    "extended_grid",
    "spectra_with_lines",
    "spectrum_with_lines",
]

#: The gap between a grid end and the node beyond it where the linear density is zero,
#: in units of the end cell: the linear density's trapezoid over it adds this fraction
#: of a half cell (absorbed by the scale). [-]
STEP = 1e-6


@dataclass(frozen=True)
class CorrectedSpectrum:
    """One end tension's spectral density with the residuals.

    Attributes
    ----------
    omega : ndarray, shape (n,)
        The analysis grid and the residual lines outside it, increasing. [rad/s]
    density : ndarray, shape (n,)
        One-sided spectral density, >= 0. [N²·s/rad]
    scale : float
        The factor on the uniform residual lines' density that makes the area the
        corrected variance (module notes; 1 without uniform lines). [-]
    """

    omega: np.ndarray
    density: np.ndarray
    scale: float


def corrected_spectrum(
    omega: np.ndarray,
    linear: np.ndarray,
    end: str,
    records: Iterable[ResidualRecord],
) -> CorrectedSpectrum:
    """The spectral density of the tension at ``end`` with the residuals of
    ``records`` (module notes).

    Parameters
    ----------
    omega : ndarray, shape (n_omega,)
        The analysis grid. [rad/s]
    linear : ndarray, shape (n_omega,)
        The linear model's end-tension spectral density on it. [N²·s/rad]
    end : str
        "end_a" or "end_b".
    records : iterable of ResidualRecord
        The computed residuals (records not computed add nothing).

    Returns
    -------
    CorrectedSpectrum
        ∫S dω (trapezoid) = ∫S_linear dω + Σ the residuals' variances (clipped at 0, as
        the statistics' σ²).
    """
    return spectrum_with_lines(
        omega, linear, [(om, lines[end]) for rec in records for om, lines in rec.lines]
    )


def spectrum_with_lines(
    omega: np.ndarray,
    linear: np.ndarray,
    parts: Iterable[tuple[np.ndarray, np.ndarray]],
) -> CorrectedSpectrum:
    """The spectral density of one response with the residuals' variance lines
    ``parts`` (module notes; :func:`corrected_spectrum` of one end, a free body's DOF).

    Parameters
    ----------
    omega : ndarray, shape (n_omega,)
        The analysis grid. [rad/s]
    linear : ndarray, shape (n_omega,)
        The linear model's spectral density on it. [unit²·s/rad]
    parts : iterable of (ndarray (n,), ndarray (n,))
        The residuals' variance lines: frequencies [rad/s] and variances [unit²]
        (uniform lines, or the misfit's on ``omega`` itself).

    Returns
    -------
    CorrectedSpectrum
        ∫S dω (trapezoid) = ∫S_linear dω + Σ the lines' variances (clipped at 0).
    """
    return spectra_with_lines(omega, [linear], [list(parts)])[0]


def corrected_spectra(
    omega: np.ndarray,
    linear: dict[str, np.ndarray],
    records: Iterable[ResidualRecord],
) -> dict[str, CorrectedSpectrum]:
    """:func:`corrected_spectrum` of every end of ``linear`` (end → its linear
    density), the extended grid formed once for them all (the ends' lines share their
    frequencies): the same numbers."""
    records = list(records)
    ends = list(linear)
    parts = [[(om, lines[e]) for rec in records for om, lines in rec.lines] for e in ends]
    return dict(zip(ends, spectra_with_lines(omega, [linear[e] for e in ends], parts)))


def spectra_with_lines(
    omega: np.ndarray,
    linear: list[np.ndarray],
    parts: list[list[tuple[np.ndarray, np.ndarray]]],
) -> list[CorrectedSpectrum]:
    """:func:`spectrum_with_lines` of several responses whose ``parts`` have the same
    frequencies, response by response (their lines' values differ), the extended grid
    formed once."""
    w = np.asarray(omega, dtype=float)
    q = trapezoid_weights(w)
    shape = [(np.asarray(om, dtype=float), None) for om, _ in parts[0]] if parts else []
    kinds: list[float | str] = []  # (each part: "misfit" on the grid, "empty", a step)
    for om, _ in shape:
        if om.size == w.size and np.array_equal(om, w):
            kinds.append("misfit")
        elif om.size:
            kinds.append(float(om[1] - om[0]) if om.size > 1 else float(om[0]))
        else:
            kinds.append("empty")
    uniform_om = [om for (om, _), k in zip(shape, kinds, strict=True) if not isinstance(k, str)]
    grid = extended_grid(w, uniform_om)
    at = np.searchsorted(grid, w)
    qg = trapezoid_weights(grid)
    out = []
    for lin, own in zip(linear, parts, strict=True):
        base = np.asarray(lin, dtype=float).copy()
        target = float(np.sum(q * base))
        uniform: list[tuple[np.ndarray, np.ndarray]] = []
        for (om, v), kind in zip(own, kinds, strict=True):
            om = np.asarray(om, dtype=float)
            v = np.asarray(v, dtype=float)
            target += float(np.sum(v))
            if kind == "misfit":  # exact density
                base += np.divide(v, q, out=np.zeros_like(v), where=q > 0)
            elif not isinstance(kind, str):
                uniform.append((om, v / kind))
        target = max(target, 0.0)
        dens = np.zeros(grid.size)
        dens[at] = np.maximum(base, 0.0)  # (a misfit change below the linear density: 0)
        res = np.zeros(grid.size)
        for om, d in uniform:
            res += np.interp(grid, om, d, left=d[0], right=0.0)
        area = float(np.sum(qg * res))
        scale = (target - float(np.sum(qg * dens))) / area if area > 0 else 1.0
        out.append(CorrectedSpectrum(grid, np.maximum(dens + scale * res, 0.0), float(scale)))
    return out


def extended_grid(omega: np.ndarray, lines: list[np.ndarray]) -> np.ndarray:
    """The frequencies of a corrected density (module notes): the analysis grid
    ``omega``, the uniform residual lines ``lines`` (their frequencies, each an array)
    outside it, and a node just beyond each end of ``omega`` the grid extends past.
    [rad/s]"""
    w = omega
    outside = [om[(om < w[0]) | (om > w[-1])] for om in lines]
    grid = np.union1d(w, np.concatenate(outside)) if outside else w
    return _with_steps(grid, w)


def _with_steps(grid: np.ndarray, w: np.ndarray) -> np.ndarray:
    """``grid`` with a node just outside each end of ``w`` that ``grid`` extends past
    (:data:`STEP` of the end cell, or half the gap to the next node if that is closer),
    where the linear density is zero."""
    if w.size < 2:
        return grid
    extra = []
    above, below = grid[grid > w[-1]], grid[grid < w[0]]
    if above.size:
        extra.append(w[-1] + min(STEP * (w[-1] - w[-2]), 0.5 * (above[0] - w[-1])))
    if below.size:
        extra.append(w[0] - min(STEP * (w[1] - w[0]), 0.5 * (w[0] - below[-1])))
    return np.union1d(grid, extra) if extra else grid
