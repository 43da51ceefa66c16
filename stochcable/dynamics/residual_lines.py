"""Shared steps of the closed-form residuals of the linear model
(:mod:`stochcable.dynamics.drag_residual`, :mod:`stochcable.dynamics.geometric_residual`):
linear response quantities as spectral lines on a uniform grid, their cross-covariance
functions by FFT, covariance functions back to variance lines, and the end tensions per
unit load on the line.

The residuals are nonlinear functions of the jointly Gaussian linear response; their
cross-covariances are polynomials of the linear cross-covariances R(τ) (Mehler's formula,
Isserlis' theorem), i.e. sums of convolutions of the linear spectra.  On the periodic
lag grid of ``n_fft`` samples the convolutions are exact when ``n_fft`` exceeds twice
the highest line they reach.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from stochcable.dynamics.loads.freqblocks import frequency_slices
from stochcable.dynamics.model.blocks import (
    add_blocks,
    free_band,
    from_freq,
    line_prep,
    to_freq,
    trapezoid_weights,
)
from stochcable.dynamics.model.solvers import solve_band_stacked
from stochcable.dynamics.solve.line_loads import drag_blocks
from stochcable.dynamics.solve.line_solve import end_tension_from_support, reactions
from stochcable.results.records import ResidualRecord

__all__ = [
    "MAX_LINES",
    "UniformGrid",
    "covariance_lines",
    "cross_covariance",
    "element_directions",
    "load_transfer",
    "residual_record",
    "uniform_grid",
]

#: Most lines of the uniform grid the linear quantities are placed on (its step is the
#: analysis grid's smallest spacing, or ω_max/MAX_LINES if that is finer). [-]
MAX_LINES = 1024


class UniformGrid:
    """Lines ω_j = j·step, j = 0 … n_j − 1, that hold an analysis grid ``w`` (each
    frequency moved to its nearest line, its trapezoid weight kept).

    Frequencies sharing a line (a grid finer than the step) add their cross-spectra,
    not their amplitudes: each one of a line becomes its own channel (``ranks``)."""

    def __init__(self, w: np.ndarray) -> None:
        w = np.asarray(w, dtype=float)
        steps = np.diff(w)
        self.omega = w
        self.step = max(float(steps.min()) if steps.size else float(w[0]), float(w[-1]) / MAX_LINES)
        self.n_j = int(np.rint(w[-1] / self.step)) + 1
        self.index = np.clip(np.rint(w / self.step).astype(int), 0, self.n_j - 1)
        rank = np.zeros(w.size, dtype=int)
        for i in range(1, w.size):
            rank[i] = rank[i - 1] + 1 if self.index[i] == self.index[i - 1] else 0
        self.rank = rank
        self.ranks = int(rank.max()) + 1

    def lines(self, values: np.ndarray, spectra: np.ndarray) -> np.ndarray:
        """Amplitude lines of ``values`` (n_ch, n_x, n_w) per unit input of channels with
        ``spectra`` (n_ch, n_w): shape (n_ch · ranks, n_x, n_j), with
        E[x(t) y(t + τ)] = Σ_j Re(Σ_c x̄_{c,j} y_{c,j} e^{iω_j τ}) (:func:`cross_covariance`)."""
        n_ch, n_x, _ = values.shape
        amp = np.sqrt(np.asarray(spectra, dtype=float) * trapezoid_weights(self.omega)[None])
        out = np.zeros((n_ch, self.ranks, n_x, self.n_j), dtype=complex)
        out[:, self.rank, :, self.index] = np.moveaxis(values * amp[:, None, :], 2, 0)
        return out.reshape(n_ch * self.ranks, n_x, self.n_j)


def uniform_grid(w: Any) -> UniformGrid:
    """The :class:`UniformGrid` of the analysis frequencies ``w``. [rad/s]"""
    return UniformGrid(np.asarray(w, dtype=float))


def cross_covariance(x: np.ndarray, y: np.ndarray, n_fft: int) -> np.ndarray:
    """E[x(t) y_k(t + τ)] on the lag grid τ_m = 2πm/(n_fft·step), for one quantity's
    lines ``x`` (n_ch, n_j) and many ``y`` (n_ch, n_k, n_j): shape (n_k, n_fft)."""
    cross = np.zeros((y.shape[1], n_fft // 2 + 1), dtype=complex)
    cross[:, : y.shape[2]] = np.einsum("cj,ckj->kj", np.conj(x), y)
    cross[:, 0] *= 2.0  # (irfft halves the zero-frequency line)
    return np.fft.irfft(cross, n=n_fft, axis=1) * (0.5 * n_fft)


def covariance_lines(cov: np.ndarray, n_o: int) -> np.ndarray:
    """Lines c_j, j = 1 … n_o, of covariance functions ``cov`` (n_k, n_fft) on the lag
    grid, cov(τ) = Σ_j Re(c_j e^{iω_jτ}) (the zero-frequency line, a random constant,
    left out): shape (n_k, n_o)."""
    n_fft = cov.shape[1]
    return (2.0 / n_fft) * np.fft.rfft(cov, axis=1)[:, 1 : n_o + 1]


def load_transfer(system: Any, damping: Any, unit: np.ndarray, w: np.ndarray) -> np.ndarray:
    """End tensions (end_a, end_b) per unit of each load case ``unit`` (n_nodes, d,
    n_load) (node forces on the model's components), ends prescribed, the line's
    linear system with ``damping``, on ``w``; one banded solve per frequency block for
    all load cases: shape (2, n_load, n_w). [N/unit]"""
    model = system.model
    prep = line_prep(system)
    d = model.dim
    cd = drag_blocks(system, damping)
    c = add_blocks(prep.S, cd)
    b_c = prep.bS + free_band(cd)
    n_p = unit.shape[2]
    out = np.zeros((2, n_p, w.size), dtype=complex)
    for sl in frequency_slices(w.size, 8 * 16 * model.n_nodes * d * n_p):
        load = np.ascontiguousarray(
            np.broadcast_to(unit[:, :, None, :], (model.n_nodes, d, w[sl].size, n_p)),
            dtype=complex,
        )
        u_free = solve_band_stacked(
            prep.bK, prep.bM, b_c, to_freq(np.ascontiguousarray(load[1:-1])), w[sl],
            2 * d - 1, 2 * d - 1, (model.K, model.M),
        )  # fmt: skip
        u = np.zeros_like(load)
        u[1:-1] = from_freq(u_free, d)
        tension = end_tension_from_support(system, reactions(system, prep, c, u, load, w[sl]))
        out[0, :, sl], out[1, :, sl] = tension["end_a"], tension["end_b"]
    return out


def element_directions(system: Any) -> list[np.ndarray]:
    """The element tangent and the normals the line's model moves along, each (n_el, 3):
    (t, n) with n the normal in the plane of a planar model (t × the out-of-plane
    axis), (t, n₁, n₂) in 3-D."""
    t, n1, n2 = system.frames
    comps = list(system.model.components)
    if len(comps) == 3:
        return [t, n1, n2]
    plane = np.zeros(3)
    plane[[i for i in range(3) if i not in comps][0]] = 1.0
    normal = np.cross(plane, t)
    return [t, normal / np.linalg.norm(normal, axis=1)[:, None]]


def residual_record(
    lines: np.ndarray,
    w_out: np.ndarray,
    w: np.ndarray,
    std: dict[str, float],
    order: int,
    panels: int,
    linear: dict[str, float] | None = None,
) -> ResidualRecord:
    """The record of the end tensions' variance lines ``lines`` (end_a, end_b) at
    ``w_out``: their sums, and the sums over the analysis band [w[0], w[-1]]; plus
    ``linear`` (a variance change on the analysis grid itself, e.g. of a load
    correlated with the linear response; it may be negative). [N²]"""
    keep = (w_out >= w[0] * (1 - 1e-9)) & (w_out <= w[-1] * (1 + 1e-9))
    ends = ("end_a", "end_b")
    extra = linear or {}
    variance = {end: float(lines[k].sum()) + extra.get(end, 0.0) for k, end in enumerate(ends)}
    in_band = {end: float(lines[k][keep].sum()) + extra.get(end, 0.0) for k, end in enumerate(ends)}
    return ResidualRecord.from_variances(variance, in_band, std, order, panels)
