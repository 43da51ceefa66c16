"""Stacked banded solves of many right-hand sides with the LU factors kept:
:class:`BandFactors` (Z(ω_k) = K − ω_k²M + iω_kC factored once per frequency by
:func:`band_factors`, solved for any right-hand sides at any of them later).

The compiled kernels (:mod:`stochcable.dynamics.model.band_lu_kernels`: the pivoted
banded LU of ``zgbtf2`` per frequency, the substitutions over all right-hand sides of
a row at once, written straight into the caller's (rows, DOFs, frequencies) layout)
where numba is available and the problem is large enough to pay its import
(:func:`compiled_band_lu`); the callers keep LAPACK's ``gbsv`` on the stack
(:func:`~stochcable.dynamics.model.solvers.solve_band_stacked`) otherwise.  The
residuals' adjoint rows of a short line (the deep catenary: 2 end, 7 element and 14
node rows on up to 189 frequencies) were ≈ 8 ms of ``gbsv`` calls, each set
refactored and substituted one column at a time (docs/benchmarks/residual_cost.md).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from stochcable.compiled import kernel_min_entries, optional_kernel
from stochcable.dynamics.model.solvers import singular_error

__all__ = ["BandFactors", "band_factors", "band_solve", "compiled_band_lu"]

_KERNELS = "stochcable.dynamics.model.band_lu_kernels"


def compiled_band_lu(entries: int) -> bool:
    """Whether a banded job of ``entries`` right-hand-side entries (n_w · n · r) takes
    the compiled kernels: numba available (and not ``STOCHCABLE_NUMBA=0``) and
    ``entries`` ≥ :data:`~stochcable.compiled.KERNEL_MIN_ENTRIES` (numba's import, ≈
    0.3–0.6 s once per process, is paid above it only; by the job's size alone, so the
    same document takes the same path, to the bit, in any process); inside
    :func:`~stochcable.compiled.kernels_paid` (a load-case set's chunk) from
    :data:`~stochcable.compiled.SET_KERNEL_MIN_ENTRIES`. [-]"""
    if entries < kernel_min_entries():
        return False
    return optional_kernel(_KERNELS, "band_lu_factor") is not None


class BandFactors:
    """Z(ω_k) = K − ω_k²M + iω_kC of a banded system at the frequencies ``omega``, its
    LU factors kept (:func:`band_factors`); :meth:`solve_into` at any of them.

    Attributes
    ----------
    omega : ndarray, shape (n_w,)
        The frequencies factored. [rad/s]
    """

    def __init__(self, factors: tuple[np.ndarray, ...], omega: np.ndarray, kl: int) -> None:
        self.factors = factors
        self.omega = omega
        self.kl = kl

    def solve_into(
        self,
        terms: np.ndarray,
        out: np.ndarray,
        at: np.ndarray | None = None,
        offset: int = 0,
        loads: Any = None,
    ) -> np.ndarray:
        """Z(ω)⁻¹b(ω), b = T₀ − ω²T₁ + iωT₂ of ``terms`` (3, n, r), at the frequencies
        ``at`` (indices into :attr:`omega`; all by default), written into rows
        ``offset`` … ``offset + n − 1`` of ``out`` (r, N, n_at), complex and
        C-contiguous (returned); with ``loads`` (a real (L, n) array of load cases on
        the n unknowns, taken by its nonzero entries) their products instead, ``out``
        (r, L, n_at). [m] or [m·unit/N]"""
        at = np.arange(self.omega.size) if at is None else np.asarray(at, dtype=np.int64)
        csr = None
        if loads is not None:  # (CSR by hand: scipy.sparse's constructor ≈ 40 µs a call)
            rows, cols = np.nonzero(loads)
            csr = (np.searchsorted(rows, np.arange(loads.shape[0] + 1)), cols, loads[rows, cols])
        if out.size:
            kernel = optional_kernel(_KERNELS, "band_lu_substitute")
            kernel(self.factors, self.kl, self.omega, at, terms, out, offset, csr)
        return out


def band_factors(
    bk: np.ndarray,
    bm: np.ndarray,
    bc: np.ndarray | None,
    omega: np.ndarray,
    kl: int,
    ku: int,
    mats: tuple | None = None,
) -> BandFactors:
    """The LU factors of Z(ω_k) at every frequency by the compiled kernel (the caller
    checks :func:`compiled_band_lu`).

    Parameters
    ----------
    bk, bm : ndarray, shape (kl + ku + 1, n)
        K [N/m] and M [kg] in LAPACK band storage ``b[ku + i − j, j]``.
    bc : ndarray or None, shape (kl + ku + 1, n)
        C in band storage, real or complex (None: no damping). [N·s/m]
    omega : ndarray, shape (n_w,)
        Angular frequencies. [rad/s]
    kl, ku : int
        Lower and upper bandwidth. [-]
    mats : tuple, optional
        (K, M) as matrices: the singular-matrix error names their nearest mode.

    Returns
    -------
    BandFactors

    Raises
    ------
    SolverError
        Where Z(ω_k) is exactly singular (a zero pivot, as ``gbsv``'s).
    """
    w = np.ascontiguousarray(omega, dtype=float)
    factor = optional_kernel(_KERNELS, "band_lu_factor")
    factors, info = factor(bk, bm, bc, w, kl, ku)
    if info > 0:
        K, M = mats if mats is not None else (np.zeros((1, 1)), np.eye(1))
        raise singular_error(K, M, float(w[(info - 1) // np.shape(bk)[1]]), None)
    return BandFactors(factors, w, kl)


def band_solve(
    bk: np.ndarray,
    bm: np.ndarray,
    bc: np.ndarray | None,
    f: np.ndarray,
    omega: np.ndarray,
    kl: int,
    ku: int,
    mats: tuple | None = None,
) -> np.ndarray:
    """Z(ω_k)⁻¹F_k at every frequency by the compiled LU (the caller checks
    :func:`compiled_band_lu`): what :func:`~stochcable.dynamics.model.solvers.
    solve_band_stacked` gives (its arguments), to round-off.

    Parameters
    ----------
    bk, bm, bc, omega, kl, ku, mats
        As :func:`band_factors`.
    f : ndarray, complex, shape (n_w, n, r)
        The right-hand sides per frequency. [N]

    Returns
    -------
    ndarray, complex, shape (n_w, n, r)
        The solutions. [m]

    Raises
    ------
    SolverError
        Where Z(ω_k) is exactly singular.
    """
    fac = band_factors(bk, bm, bc, omega, kl, ku, mats)
    solve = optional_kernel(_KERNELS, "band_lu_solve_each")
    return solve(fac.factors, kl, f)
