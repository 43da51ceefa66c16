"""Shared steps of the closed-form residuals of the linear model (:mod:`.drag_residual`,
:mod:`.geometric_residual`):
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
    line_prep,
    trapezoid_weights,
)
from stochcable.dynamics.model.solvers import solve_band_stacked
from stochcable.dynamics.model.transport import gyro_band
from stochcable.dynamics.solve.line_loads import drag_blocks
from stochcable.dynamics.solve.line_solve import end_tension_from_support
from stochcable.results.records import ResidualRecord

__all__ = [
    "MAX_LINES",
    "UniformGrid",
    "covariance_lines",
    "cross_covariance",
    "element_directions",
    "fft_length",
    "EndInfluence",
    "end_influence",
    "load_transfer",
    "residual_record",
    "uniform_grid",
]

#: Most lines of the uniform grid the linear quantities are placed on (its step is the
#: analysis grid's smallest spacing, or ω_max/MAX_LINES if that is finer). [-]
MAX_LINES = 63


class UniformGrid:
    """Lines ω_j = j·step, j = 0 … n_j − 1, that hold an analysis grid ``w`` (each
    frequency moved to its nearest line, its trapezoid weight kept).

    Frequencies sharing a line (a grid finer than the step) add their cross-spectra,
    not their amplitudes: each one of a line becomes its own channel (``ranks``)."""

    def __init__(self, w: np.ndarray, max_lines: int | None = None) -> None:
        w = np.asarray(w, dtype=float)
        steps = np.diff(w)
        self.omega = w
        top = MAX_LINES if max_lines is None else max_lines
        self.step = max(float(steps.min()) if steps.size else float(w[0]), float(w[-1]) / top)
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


def uniform_grid(w: Any, max_lines: int | None = None) -> UniformGrid:
    """The :class:`UniformGrid` of the analysis frequencies ``w`` [rad/s], of at most
    ``max_lines`` lines (:data:`MAX_LINES` by default)."""
    return UniformGrid(np.asarray(w, dtype=float), max_lines)


def cross_covariance(x: np.ndarray, y: np.ndarray, n_fft: int) -> np.ndarray:
    """E[x(t) y_k(t + τ)] on the lag grid τ_m = 2πm/(n_fft·step), for one quantity's
    lines ``x`` (n_ch, n_j) and many ``y`` (n_ch, n_k, n_j): shape (n_k, n_fft)."""
    cross = np.zeros((y.shape[1], n_fft // 2 + 1), dtype=complex)
    # Σ_c x̄_c·y_ck per line: one matrix product per line
    cross[:, : y.shape[2]] = (np.conj(x).T[:, None, :] @ y.transpose(2, 0, 1))[:, 0].T
    cross[:, 0] *= 2.0  # (irfft halves the zero-frequency line)
    return np.fft.irfft(cross, n=n_fft, axis=1) * (0.5 * n_fft)


def fft_length(n: int) -> int:
    """The shortest lag grid of at least ``n`` ≥ 1 samples whose real FFT is fast: the
    least 5-smooth number ≥ n (763 → 768, 769 → 800), as ``scipy.fft.next_fast_len(n,
    real=True)`` gives it (equal for every n, tests/dynamics/test_drag_residual.py),
    without importing ``scipy.fft`` and the ``scipy.special`` it loads (~35 ms)."""
    n = int(n)
    best = 1 << (n - 1).bit_length()  # the least power of two ≥ n
    p5 = 1
    while p5 < best:
        p35 = p5
        while p35 < best:  # p35 = 3^b 5^c: the least p35·2^a ≥ n
            best = min(best, p35 << max(0, -(-n // p35) - 1).bit_length())
            p35 *= 3
        p5 *= 5
    return best


def covariance_lines(cov: np.ndarray, n_o: int) -> np.ndarray:
    """Lines c_j, j = 1 … n_o, of covariance functions ``cov`` (n_k, n_fft) on the lag
    grid, cov(τ) = Σ_j Re(c_j e^{iω_jτ}) (the zero-frequency line, a random constant,
    left out): shape (n_k, n_o)."""
    n_fft = cov.shape[1]
    return (2.0 / n_fft) * np.fft.rfft(cov, axis=1)[:, 1 : n_o + 1]


def load_transfer(
    system: Any,
    damping: Any,
    unit: np.ndarray,
    w: np.ndarray,
    influence: EndInfluence | None = None,
) -> np.ndarray:
    """End tensions (end_a, end_b) per unit of each load case ``unit`` (n_nodes, d,
    n_load) (node forces on the model's components), ends prescribed, the line's
    linear system with ``damping``, on ``w``: the load cases contracted with the end
    tensions' influence (:func:`end_influence`; from ``influence`` where given, shared
    by the residuals of one line), shape (2, n_load, n_w). [N/unit]"""
    g = end_influence(system, damping, w) if influence is None else influence.on(w)
    n = g.shape[1] * g.shape[2]
    flat = np.moveaxis(g.reshape(2, n, w.size), 2, 1)  # (2, n_w, n_nodes·d)
    return np.moveaxis(flat @ unit.reshape(n, -1).astype(complex), 2, 1)


class EndInfluence:
    """The end influence (:func:`end_influence`) of one line and drag, kept for the
    last frequencies asked: a later request for a leading part of them (the geometric
    residual's 2·n_j lines after the drag residual's 3·n_j) is a slice of it."""

    def __init__(self, system: Any, damping: Any) -> None:
        self.system = system
        self.damping = damping
        self._kept: tuple[np.ndarray, np.ndarray] | None = None

    def on(self, w: np.ndarray) -> np.ndarray:
        """The influence on ``w``, shape (2, n_nodes, d, n_w). [N/N]"""
        w = np.asarray(w, dtype=float)
        kept = self._kept
        if kept is not None and w.size <= kept[0].size and np.array_equal(kept[0][: w.size], w):
            return kept[1][..., : w.size]
        g = end_influence(self.system, self.damping, w)
        self._kept = (w.copy(), g)
        return g


def end_influence(system: Any, damping: Any, w: np.ndarray) -> np.ndarray:
    """End tensions (end_a, end_b) per unit force on each node and component, ends
    prescribed, the line's linear system with ``damping``: shape (2, n_nodes, d, n_w).
    [N/N]

    By the adjoint: with the ends held, T = ê·F_end − ê·Z_end,f u_f and u_f = A⁻¹F_f,
    A = Z_ff = K − ω²M + iωC the free–free impedance; A is symmetric (not Hermitian),
    so T = ê·F_end − (A⁻¹g)ᵀF_f, g = Z_f,end ê: two solves per frequency (one
    factorization) whatever the number of load cases.  A travelling line's A has the
    skew G (:mod:`stochcable.dynamics.model.transport`): then Aᵀ (C − G) is solved, with
    g = Z_end,fᵀ ê."""
    model = system.model
    prep = line_prep(system)
    d = model.dim
    n = model.n_nodes
    cd = drag_blocks(system, damping)
    c = add_blocks(prep.S, cd)
    b_c = prep.bS + free_band(cd)
    if system.gyro is not None:  # a travelling line: Aᵀ has C − G (dynamics.model.transport)
        b_c = b_c - gyro_band(system.gyro, d)
    # ê of each end: the end tension of a unit support force along each component
    eye = np.eye(2 * d)[None].astype(complex)
    ten = end_tension_from_support(system, eye)
    e_hat = [np.real(ten[end][:, 0]) for end in ("end_a", "end_b")]  # (2d,) each
    e_a, e_b = e_hat[0][:d], e_hat[1][d:]
    out = np.zeros((2, n, d, w.size), dtype=complex)
    out[0, 0] = e_a[:, None]
    out[1, -1] = e_b[:, None]
    for sl in frequency_slices(w.size, 8 * 16 * n * d * 2):
        ws = w[sl]
        # the end rows' coupling blocks Z(1, 0) and Z(n − 2, n − 1) at each frequency
        o_first = [blk[1][0] for blk in (prep.K, prep.MT, c)]
        o_last = [blk[1][-1] for blk in (prep.K, prep.MT, c)]
        rhs = np.zeros((ws.size, (n - 2) * d, 2), dtype=complex)
        for k, (o, vec, rows, tr) in enumerate(
            ((o_first, e_a, slice(0, d), False), (o_last, e_b, slice((n - 3) * d, None), True))
        ):
            blocks = [b.T if tr else b for b in o]
            g = [b @ vec for b in blocks]  # (d,) of K, M, C
            rhs[:, rows, k] = (
                g[0][None] - (ws * ws)[:, None] * g[1][None] + (1j * ws)[:, None] * g[2][None]
            )
            if system.gyro is not None:  # Z_end,fᵀ ê: G[0, 1]ᵀ = g_0 I, G[n−1, n−2]ᵀ = −g I
                gy = system.gyro[-1 if tr else 0] * (-1.0 if tr else 1.0)
                rhs[:, rows, k] += (1j * ws)[:, None] * gy * vec[None]
        x = solve_band_stacked(
            prep.bK, prep.bM, b_c, rhs, ws, 2 * d - 1, 2 * d - 1, (model.K, model.M)
        )  # (n_w, n_f·d, 2)
        out[:, 1:-1, :, sl] = -np.transpose(x.reshape(ws.size, n - 2, d, 2), (3, 1, 2, 0))
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
    linear: dict[str, np.ndarray] | None = None,
) -> ResidualRecord:
    """The record of the end tensions' variance lines ``lines`` (end_a, end_b) at
    ``w_out``: their sums, and the sums over the analysis band [w[0], w[-1]]; plus
    ``linear`` (variance-change lines on the analysis grid ``w`` itself, e.g. of a load
    correlated with the linear response; they may be negative), the lines kept in the
    record. [N²]"""
    keep = (w_out >= w[0] * (1 - 1e-9)) & (w_out <= w[-1] * (1 + 1e-9))
    ends = ("end_a", "end_b")
    extra = {e: float(np.sum(v)) for e, v in (linear or {}).items()}
    variance = {end: float(lines[k].sum()) + extra.get(end, 0.0) for k, end in enumerate(ends)}
    in_band = {end: float(lines[k][keep].sum()) + extra.get(end, 0.0) for k, end in enumerate(ends)}
    parts = [(np.asarray(w_out, dtype=float), {end: lines[k] for k, end in enumerate(ends)})]
    if linear:
        parts.append((np.asarray(w, dtype=float), {e: np.asarray(v) for e, v in linear.items()}))
    return ResidualRecord.from_variances(variance, in_band, std, order, panels, tuple(parts))
