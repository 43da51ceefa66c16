"""The banded Cholesky solve K_ff⁻¹ X of the Foss static correction as one compiled
sweep over the rows (:func:`cholesky_band_solve`).

X is node-major (n_free_dof, k): one row per DOF, the frequencies and channels (real
and imaginary parts side by side) along the row.  LAPACK's ``dpbtrs`` solves column by
column and takes the columns contiguous, so SciPy transposed X in and out at every
call (two strided copies of the whole block) around a level-2 solve.  Here the forward
(Uᵀy = x) and the backward (Ux = y) substitutions run row by row, each step a
contiguous multiply-add over the whole row, in place, no copy (measured in
docs/benchmarks/dynamics.md, "Banded Cholesky solve").  The same operations in another
order: equal to round-off (≈ 1e-16 relative).

Imported lazily (numba's import is slow); compiled with ``cache=True``
(:func:`stochcable.compiled.jit_cached`).
"""

from __future__ import annotations

import numpy as np
from numba import types

from stochcable.compiled import jit_cached

__all__ = ["cholesky_band_solve"]


def _solve(cb, x):  # noqa: ANN001 - numba kernel
    """x ← (UᵀU)⁻¹x in place, U upper banded in LAPACK storage cb[u + i − j, j]."""
    u = cb.shape[0] - 1
    n, m = x.shape
    for j in range(n):  # Uᵀ y = x, y in x
        for i in range(max(0, j - u), j):
            a = cb[u + i - j, j]
            for c in range(m):
                x[j, c] -= a * x[i, c]
        d = cb[u, j]
        for c in range(m):
            x[j, c] /= d
    for i in range(n - 1, -1, -1):  # U x = y
        for j in range(i + 1, min(n, i + u + 1)):
            a = cb[u + i - j, j]
            for c in range(m):
                x[i, c] -= a * x[j, c]
        d = cb[u, i]
        for c in range(m):
            x[i, c] /= d


_SIGNATURE = types.void(
    types.Array(types.float64, 2, "C", readonly=True), types.Array(types.float64, 2, "C")
)
"""(the factor in band storage, the right-hand sides solved in place)."""

_kernel, _ = jit_cached(_solve, _SIGNATURE, "banded Cholesky solve")


def cholesky_band_solve(factor: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """K⁻¹ rhs from the upper banded Cholesky factor of K.

    Parameters
    ----------
    factor : ndarray, shape (u + 1, n)
        U of K = UᵀU in LAPACK upper band storage (``scipy.linalg.cholesky_banded``,
        ``lower=False``). [√(N/m)]
    rhs : ndarray, shape (n, k), real or complex
        Right-hand sides (a fresh array is returned). [N]

    Returns
    -------
    ndarray, shape (n, k)
        The solutions, the dtype of ``rhs``. [m]
    """
    cplx = np.iscomplexobj(rhs)
    x = np.array(rhs, dtype=complex if cplx else float, order="C", copy=True)
    xr = x.view(float).reshape(x.shape[0], -1) if cplx else x
    if xr.size:
        _kernel(np.ascontiguousarray(factor, dtype=float), xr)
    return x
