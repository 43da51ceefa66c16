"""Banded linear solves of block-tridiagonal line tangents (LAPACK gbsv directly).

The tangent of a line's statics, over its interior nodes, is block tridiagonal with
blocks dim × dim (dim = 2 planar, 3 in 3-D): a banded matrix with 2·dim − 1 sub- and
super-diagonals, solved in O(n) (the line statics Newton, the static condensation of
the body statics).
"""

from __future__ import annotations

import functools

import numpy as np
from scipy.linalg import LinAlgError, get_lapack_funcs

__all__ = ["banded_solve", "block_band_indices"]

#: LAPACK dgbsv (general banded LU with partial pivoting and solve).
_GBSV = get_lapack_funcs(("gbsv",), (np.zeros(1),))[0]


def banded_solve(ab: np.ndarray, b: np.ndarray, bw: int) -> np.ndarray:
    """x of A x = b, A banded with ``bw`` sub- and super-diagonals, given as ``ab`` of
    shape (3·bw + 1, N): rows ``bw:`` its general banded storage
    (``A[i, j] -> ab[2·bw + i − j, j]``), rows ``:bw`` zeros; ``ab`` is overwritten.

    LAPACK gbsv directly: the call ``scipy.linalg.solve_banded((bw, bw), ab[bw:], b)``
    makes after its validation and copy into that layout (bw >= 2), so the same
    numbers, without ≈ 30 µs of wrapper per solve (≈ 40 solves per body statics).
    N >= 2.  Raises LinAlgError when A is singular."""
    _, _, x, info = _GBSV(bw, bw, ab, b, overwrite_ab=True, overwrite_b=False)
    if info > 0:
        raise LinAlgError("singular matrix")
    if info < 0:
        raise ValueError(f"illegal value in {-info}-th argument of internal gbsv")
    return x


@functools.lru_cache(maxsize=64)
def block_band_indices(nf: int, dim: int) -> tuple[np.ndarray, np.ndarray]:
    """Rows and columns in LAPACK general banded storage (l = u = 2·dim − 1) of the
    entries of a block-tridiagonal matrix of nf × nf blocks dim × dim, in the order:
    the diagonal blocks, the upper blocks (q, q + 1), the lower blocks (q + 1, q), each
    block row-major (``A[i, j] -> ab[bw + i − j, j]``).  Cached (read-only arrays)."""
    bw = 2 * dim - 1
    p = np.arange(nf)[:, None, None]
    a = np.arange(dim)[None, :, None]
    b = np.arange(dim)[None, None, :]
    rd = np.broadcast_to(bw + a - b, (nf, dim, dim))
    cd = np.broadcast_to(p * dim + b, (nf, dim, dim))
    q = np.arange(max(nf - 1, 0))[:, None, None]
    ru = np.broadcast_to(bw + a - b - dim, (q.shape[0], dim, dim))
    cu = np.broadcast_to((q + 1) * dim + b, (q.shape[0], dim, dim))
    rl = np.broadcast_to(bw + dim + a - b, (q.shape[0], dim, dim))
    cl = np.broadcast_to(q * dim + b, (q.shape[0], dim, dim))
    rows = np.concatenate([rd.ravel(), ru.ravel(), rl.ravel()])
    cols = np.concatenate([cd.ravel(), cu.ravel(), cl.ravel()])
    rows.flags.writeable = False
    cols.flags.writeable = False
    return rows, cols
