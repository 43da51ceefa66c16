"""How many residual lines an output needs, with a bound on the variance left above them.

The residual's cross-spectral lines G(ω_j) of n components are a positive semi-definite
Hermitian matrix at every line (the drag residual's Σ_k b_k b_kᵀ ∘ ρ^k: Schur powers
of the velocities' covariance, a positive-definite matrix function of the lag, with
non-negative weights — their transforms are positive semi-definite), so
|G_ef| ≤ √(G_ee G_ff) line by line, and an output's variance line
T^H G T = Σ_ef conj(T_e) G_ef T_f is at most B_j = (Σ_e |T_e| √G_ee)², from the
components' own (diagonal) lines alone.  :func:`line_top` keeps the lines up to the
highest J whose tail Σ_{j>J} B_j (times the cells' factors) stays within a variance
budget at every output: the variance left out is at most the budget, whatever the
correlations.  The superharmonic lines (the top order's K·ω reach) of a line whose
ends do not pass them (the bundled chain: lines 127–189 of 189 carry 4e-5 of its σ)
are then not formed, contracted nor read by the stations.  Used by
:func:`~.drag_residual.residual_output_lines` (``budget``).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from stochcable.dynamics.model.blocks import trapezoid_weights

__all__ = ["line_bound", "line_top", "spectral_moments"]


def line_bound(g_diag: np.ndarray, transfer: np.ndarray) -> np.ndarray:
    """B_j = (Σ_e |T_e(ω_j)| √G_ee(ω_j))², the bound of every output's variance line
    (module notes): shape (n_out, n_o).

    Parameters
    ----------
    g_diag : ndarray, complex, shape (n, n_o)
        Each component's own variance lines G_ee(ω_j) (real and non-negative up to
        round-off: their magnitude is taken).
    transfer : ndarray, complex, shape (n_out, n, n_o)
        The outputs per unit component on the same lines.
    """
    amp = np.sqrt(transfer.real**2 + transfer.imag**2)  # (n_out, n, n_o)
    return np.einsum("oej,ej->oj", amp, np.sqrt(np.abs(g_diag))) ** 2


def line_top(bound: np.ndarray, budget: np.ndarray, floor: int = 0) -> int:
    """The fewest leading lines (at least ``floor``, at most all) whose left-out tail
    ``bound[:, J:]`` sums to at most ``budget`` at every output.

    Parameters
    ----------
    bound : ndarray, shape (n_out, n_o)
        Upper bounds of the outputs' variance lines (:func:`line_bound`, times any
        non-negative factor the lines are scaled by). [N²]
    budget : ndarray, shape (n_out,)
        Variance each output may leave out. [N²]
    floor : int
        Lines always kept.
    """
    n_o = bound.shape[1]
    # tail[:, J] = Σ_{j ≥ J} bound[:, j]; tail[:, n_o] = 0
    tail = np.zeros((bound.shape[0], n_o + 1))
    tail[:, :n_o] = np.cumsum(bound[:, ::-1], axis=1)[:, ::-1]
    fits = np.all(tail <= np.asarray(budget, dtype=float)[:, None], axis=0)  # (n_o + 1,)
    top = int(np.argmax(fits))  # (fits[n_o] is True: the first J that fits)
    return min(max(top, floor), n_o)


def spectral_moments(resp: Any, spectra: np.ndarray, orders: np.ndarray) -> np.ndarray:
    """The linear end tensions' spectral moments m_k = Σ_c ∫ ω^k |H_c|² S_c dω (the
    trapezoid rule of the linear σ) of a line's ``resp`` (its ``omega`` and
    ``end_tension`` transfer per end (n_ch, n_w)) and inputs ``spectra`` (n_ch, n_w):
    shape (2, n_orders), end_a then end_b. [N²·(rad/s)^k]"""
    w = np.asarray(resp.omega, dtype=float)
    q = trapezoid_weights(w)[None] * spectra  # (n_ch, n_w)
    power = np.stack(
        [
            np.sum(q * np.abs(np.asarray(resp.end_tension[e])) ** 2, axis=0)
            for e in ("end_a", "end_b")
        ]
    )  # (2, n_w)
    return power @ (w[:, None] ** np.asarray(orders, dtype=float)[None])
