"""Frequency-domain solves of ``M_T U'' + C U' + K U = F`` (seed 001 §5.3; DESIGN.md
"Solution: direct and Foss").

Harmonic quantities are ``Re{X e^{i omega t}}``, so the dynamic matrix is
``Z(omega) = K - omega^2 M + i omega C``.

Layout (all functions): ``omega`` has shape ``(n_omega,)``; a load ``F`` has shape
``(n_omega, n_dof)`` or ``(n_omega, n_dof, n_rhs)`` (frequency first, so a batch of
frequencies is a batch of linear systems); the response has the same layout as
``F``.  ``K``, ``M``, ``C`` are real symmetric ``(n_dof, n_dof)`` arrays, dense
``numpy.ndarray`` or ``scipy.sparse`` matrices; ``C`` may be ``None`` (no damping).
``C`` is constant in frequency (linearized drag, constant radiation damping).

- :func:`solve_direct` — the reference: ``U = Z(omega)^{-1} F`` at every omega,
  batched dense LAPACK or banded LU, auto-selected.
- :func:`solve_block_tridiagonal` — the same for block-tridiagonal matrices (one
  cable line, node-major DOFs), block cyclic reduction vectorized over all
  frequencies and right-hand sides at once, with a backward-error check and a
  pivoted banded LAPACK fallback; :func:`tridiagonal_blocks` extracts the blocks.
- :func:`modal_basis` — lowest modes of ``(K, M)``, mass-normalized.
- :func:`foss_decomposition`, :func:`foss_transfer` — Foss' state-space
  decoupling of the (non-proportionally damped) modal equations.
- :func:`solve_modal` — truncated modal solve (Foss or direct in modal
  coordinates) with static correction for the truncated modes.
- :func:`auto_mode_count` — how many modes a frequency range needs.

Singular dynamic matrices (undamped resonance) raise :class:`SolverError` naming the
frequency and the mode; no function returns inf or NaN.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.linalg import lapack

from stochcable import validation as _v
from stochcable.errors import InputError, PhysicsWarning, SolverError, warn

__all__ = [
    "DefectivePencilWarning",
    "solve_direct",
    "tridiagonal_blocks",
    "solve_block_tridiagonal",
    "modal_basis",
    "FossModes",
    "foss_decomposition",
    "foss_transfer",
    "solve_modal",
    "auto_mode_count",
    "matrix_bandwidth",
]

#: A solve whose estimated condition number exceeds this is treated as singular.
SINGULAR_CONDITION = 1e12
#: Eigenvector condition number above which the Foss pencil is treated as defective.
DEFECTIVE_CONDITION = 1e7
_CHUNK_BYTES = 64 * 2**20


class DefectivePencilWarning(PhysicsWarning):
    """The Foss eigenproblem is (nearly) defective, e.g. a critically damped mode."""


Matrix = Any  # numpy.ndarray or scipy.sparse matrix


# ---------------------------------------------------------------------------------
# helpers
# ---------------------------------------------------------------------------------


def _as_matrix(name: str, a: Any, n: int | None = None) -> Matrix:
    if sp.issparse(a):
        a = sp.csr_matrix(a, dtype=float)
        data = a.data
    else:
        a = _v.float_array(name, a, "-", ndim=2)
        data = a
    if a.shape[0] != a.shape[1]:
        raise InputError(name, a, "-", f"must be square (got shape {a.shape})")
    if n is not None and a.shape[0] != n:
        raise InputError(name, a, "-", f"must have shape ({n}, {n}) like K (got {a.shape})")
    if not np.all(np.isfinite(data)):
        raise InputError(name, a, "-", "must be finite (not NaN or inf)")
    return a


def _matrices(K: Any, M: Any, C: Any) -> tuple[Matrix, Matrix, Matrix | None]:
    K_ = _as_matrix("K", K)
    n = K_.shape[0]
    M_ = _as_matrix("M", M, n)
    C_ = None if C is None else _as_matrix("C", C, n)
    return K_, M_, C_


def _loads(F: Any, n: int, n_omega: int) -> tuple[np.ndarray, bool]:
    f = np.asarray(F)
    if not np.iscomplexobj(f):
        f = f.astype(float)
    f = f.astype(complex)
    if f.ndim not in (2, 3) or f.shape[0] != n_omega or f.shape[1] != n:
        raise InputError(
            "F", f, "N", f"must have shape (n_omega={n_omega}, n_dof={n}[, n_rhs]) "
            f"(got {f.shape})",
        )
    if not np.all(np.isfinite(f)):
        raise InputError("F", f, "N", "must be finite (not NaN or inf)")
    squeeze = f.ndim == 2
    return (f[:, :, None] if squeeze else f), squeeze


def _dense(a: Matrix | None, n: int) -> np.ndarray:
    if a is None:
        return np.zeros((n, n))
    return a.toarray() if sp.issparse(a) else np.asarray(a)


def matrix_bandwidth(*mats: Matrix | None) -> tuple[int, int]:
    """Lower and upper bandwidth ``(l, u)`` of the union of the sparsity patterns.

    Parameters
    ----------
    *mats : ndarray or scipy.sparse matrix or None
        Square matrices of equal shape (``None`` entries are skipped).

    Returns
    -------
    (int, int)
        ``l = max(i - j)``, ``u = max(j - i)`` over the nonzero entries. [-]
    """
    lo = up = 0
    for a in mats:
        if a is None:
            continue
        if sp.issparse(a):
            c = a.tocoo()
            i, j = c.row[c.data != 0], c.col[c.data != 0]
        else:
            i, j = np.nonzero(a)
        if i.size:
            lo = max(lo, int((i - j).max()))
            up = max(up, int((j - i).max()))
    return lo, up


def _band(a: Matrix | None, n: int, lo: int, up: int) -> np.ndarray:
    """LAPACK band storage ab[up + i - j, j] = a[i, j]."""
    ab = np.zeros((lo + up + 1, n))
    if a is None:
        return ab
    for d in range(-lo, up + 1):
        diag = a.diagonal(d) if sp.issparse(a) else np.diagonal(a, d)
        ab[up - d, max(0, d): n + min(0, d)] = diag
    return ab


def _fro(a: Matrix | None) -> float:
    if a is None:
        return 0.0
    if sp.issparse(a):
        return float(sp.linalg.norm(a))
    return float(np.linalg.norm(a))


def _nearest_mode_text(K: Matrix, M: Matrix, w: float) -> str:
    """Describe the natural frequency nearest to ``w`` (used in error messages only)."""
    try:
        n = K.shape[0]
        if n <= 2000:
            lam = sla.eigh(_dense(K, n), _dense(M, n), eigvals_only=True)
        else:  # pragma: no cover - large models
            lam = spla.eigsh(sp.csc_matrix(K), k=6, M=sp.csc_matrix(M), sigma=w * w,
                             return_eigenvectors=False)
            lam = np.sort(lam)
        wn = np.sqrt(np.clip(lam, 0.0, None))
        j = int(np.argmin(np.abs(wn - w)))
        return f"mode {j + 1} (natural frequency {wn[j]:.6g} rad/s)"
    except Exception:  # noqa: BLE001 - message helper must not mask the real error
        return "a mode of (K, M)"


def _singular_error(K: Matrix, M: Matrix, w: float, cond: float | None) -> SolverError:
    what = f"estimated condition number {cond:.2e}" if cond is not None else "exactly singular"
    return SolverError(
        f"dynamic matrix K - w^2 M + i w C is singular at omega = {w:.6g} rad/s ({what}): "
        f"undamped resonance of {_nearest_mode_text(K, M, w)}; add damping "
        "(drag, structural) or remove this frequency from the grid"
    )


def _check_conditioning(K, M, C, omega, F, U) -> None:
    """Raise SolverError where ||Z|| ||U|| / ||F|| (a lower bound of cond Z) is huge."""
    nz = _fro(K) + omega**2 * _fro(M) + omega * _fro(C)
    nf = np.linalg.norm(F.reshape(F.shape[0], -1), axis=1)
    nu = np.linalg.norm(U.reshape(U.shape[0], -1), axis=1)
    finite = np.isfinite(nu)
    est = np.where(finite, nz * np.where(nf > 0, nu / np.where(nf > 0, nf, 1.0), 0.0), np.inf)
    bad = np.flatnonzero(est > SINGULAR_CONDITION)
    if bad.size:
        k = int(bad[np.argmax(est[bad])])
        raise _singular_error(K, M, float(omega[k]), float(est[k]) if finite[k] else None)


# ---------------------------------------------------------------------------------
# direct solve
# ---------------------------------------------------------------------------------


def _solve_dense_batched(K, M, C, F, omega):
    n = F.shape[1]
    Kd, Md = _dense(K, n), _dense(M, n)
    Cd = None if C is None else _dense(C, n)
    out = np.empty_like(F)
    chunk = max(1, _CHUNK_BYTES // (16 * n * n))
    for lo in range(0, omega.size, chunk):
        w = omega[lo: lo + chunk, None, None]
        Z = Kd - w**2 * Md + (0j if Cd is None else 1j * w * Cd)
        try:
            out[lo: lo + chunk] = np.linalg.solve(Z, F[lo: lo + chunk])
        except np.linalg.LinAlgError:
            for k in range(Z.shape[0]):  # error path only: find the singular frequency
                try:
                    np.linalg.solve(Z[k], F[lo + k])
                except np.linalg.LinAlgError:
                    raise _singular_error(K, M, float(omega[lo + k]), None) from None
            raise  # pragma: no cover
    return out


def _solve_banded(K, M, C, F, omega, lo_bw, up_bw):
    n = F.shape[1]
    bK, bM = _band(K, n, lo_bw, up_bw), _band(M, n, lo_bw, up_bw)
    bC = None if C is None else _band(C, n, lo_bw, up_bw)
    # all frequencies in one stacked LAPACK gbsv call (see _solve_band_stacked)
    return _solve_band_stacked(bK, bM, bC, F, omega, lo_bw, up_bw, (K, M))


def _solve_sparse(K, M, C, F, omega):
    Ks, Ms = sp.csc_matrix(K), sp.csc_matrix(M)
    Cs = None if C is None else sp.csc_matrix(C)
    out = np.empty_like(F)
    for k, w in enumerate(omega):
        Z = (Ks - w * w * Ms).astype(complex)
        if Cs is not None:
            Z = Z + 1j * w * Cs
        try:
            out[k] = spla.splu(sp.csc_matrix(Z)).solve(F[k])
        except RuntimeError:
            raise _singular_error(K, M, float(w), None) from None
    return out


def _choose_method(K, M, C, n: int) -> tuple[str, int, int]:
    lo_bw, up_bw = matrix_bandwidth(K, M, C)
    width = lo_bw + up_bw + 1
    if n <= 24 or 4 * width > n:
        # band too wide to pay the per-frequency call overhead
        return ("sparse" if sp.issparse(K) and n > 2000 else "dense"), lo_bw, up_bw
    return "banded", lo_bw, up_bw


def solve_direct(
    K: Matrix,
    M: Matrix,
    C: Matrix | None,
    F: np.ndarray,
    omega: np.ndarray,
    method: Literal["auto", "dense", "banded", "sparse"] = "auto",
) -> np.ndarray:
    r"""Harmonic response ``U = (K - omega^2 M + i omega C)^{-1} F`` at every frequency.

    Parameters
    ----------
    K : ndarray or scipy.sparse matrix, shape (n_dof, n_dof)
        Stiffness matrix (tangent about the static equilibrium). [N/m]
    M : ndarray or scipy.sparse matrix, shape (n_dof, n_dof)
        Total mass matrix ``M_T`` (structural + added mass). [kg]
    C : ndarray or scipy.sparse matrix or None, shape (n_dof, n_dof)
        Damping matrix (linearized drag + radiation/structural damping);
        ``None`` for none. [N·s/m]
    F : array_like, shape (n_omega, n_dof) or (n_omega, n_dof, n_rhs)
        Complex load amplitudes, e.g. per unit wave amplitude. [N]
    omega : array_like, shape (n_omega,)
        Angular frequencies, >= 0. [rad/s]
    method : {"auto", "dense", "banded", "sparse"}, optional
        ``"dense"``: batched ``numpy.linalg.solve`` over frequencies (chunks of
        at most 64 MB).  ``"banded"``: LAPACK banded LU (``gbsv``) on the band of
        ``K, M, C``, all frequencies stacked in one call.  ``"sparse"``: SuperLU per frequency.
        ``"auto"`` takes the banded path when the band is narrower than a
        quarter of ``n_dof`` (and ``n_dof > 24``), else dense (sparse for
        wide-band sparse input above 2000 DOF); see benchmarks/bench_solvers.py.

    Returns
    -------
    ndarray, complex, same shape as ``F``
        Response amplitudes. [m]

    Raises
    ------
    SolverError
        If ``Z(omega)`` is singular to working precision at some frequency
        (estimated condition number above 1e12; undamped resonance); the message
        names the frequency and the nearest natural frequency and mode.

    Notes
    -----
    The reference solution of DESIGN.md "Solution: direct and Foss" (seed 001
    eq. 5.2.6 in the frequency domain).
    """
    K_, M_, C_ = _matrices(K, M, C)
    n = K_.shape[0]
    w = _v.float_array("omega", omega, "rad/s", nonnegative=True)
    f, squeeze = _loads(F, n, w.size)
    if method == "auto":
        method, lo_bw, up_bw = _choose_method(K_, M_, C_, n)
    elif method == "banded":
        lo_bw, up_bw = matrix_bandwidth(K_, M_, C_)
    elif method not in ("dense", "sparse"):
        raise InputError("method", method, "-", "must be 'auto', 'dense', 'banded' or 'sparse'")
    if method == "dense":
        u = _solve_dense_batched(K_, M_, C_, f, w)
    elif method == "banded":
        u = _solve_banded(K_, M_, C_, f, w, lo_bw, up_bw)
    else:
        u = _solve_sparse(K_, M_, C_, f, w)
    _check_conditioning(K_, M_, C_, w, f, u)
    return u[:, :, 0] if squeeze else u


# ---------------------------------------------------------------------------------
# block-tridiagonal direct solve (one cable line)
# ---------------------------------------------------------------------------------

Blocks = tuple[np.ndarray, np.ndarray, np.ndarray]


def tridiagonal_blocks(A: Matrix, block_size: int) -> Blocks:
    r"""Blocks of a block-tridiagonal matrix.

    Parameters
    ----------
    A : ndarray or scipy.sparse matrix, shape (n, n)
        Matrix whose nonzeros lie in the block-tridiagonal pattern, ``n`` a multiple
        of ``block_size`` (a cable line with node-major DOFs). [any]
    block_size : int
        Size ``b`` of the square blocks (DOFs per node: 2 in-plane, 3 in 3-D). [-]

    Returns
    -------
    diag, lower, upper : ndarray, shape (n/b, b, b)
        ``diag[i] = A[i, i]``, ``lower[i] = A[i, i-1]`` (``lower[0] = 0``) and
        ``upper[i] = A[i, i+1]`` (``upper[-1] = 0``) in block indices. [any]

    Raises
    ------
    InputError
        If ``n`` is not a multiple of ``b`` or ``A`` has entries outside the pattern.
    """
    b = _v.positive_int("block_size", block_size)
    if sp.issparse(A):
        coo = sp.coo_array(A)
        n = coo.shape[0]
        if coo.shape[1] != n:
            raise InputError("A", coo.shape, "-", "must be square")
        rows, cols, data = coo.row, coo.col, coo.data
        dtype = np.result_type(data.dtype, float)
    else:
        a = np.asarray(A)
        if a.ndim != 2 or a.shape[0] != a.shape[1]:
            raise InputError("A", a.shape, "-", "must be a square 2-D array")
        n = a.shape[0]
        rows, cols = np.nonzero(a)
        data = a[rows, cols]
        dtype = np.result_type(a.dtype, float)
    if n % b:
        raise InputError("A", A.shape, "-", f"size must be a multiple of block_size = {b}")
    nb = n // b
    bi, bj = rows // b, cols // b
    off = bi - bj
    if np.any(np.abs(off) > 1):
        k = int(np.flatnonzero(np.abs(off) > 1)[0])
        raise InputError("A", f"entry ({rows[k]}, {cols[k]})", "-",
                         f"must be block-tridiagonal with {b}x{b} blocks")
    out = []
    for sel in (off == 0, off == 1, off == -1):
        blk = np.zeros((nb, b, b), dtype=dtype)
        np.add.at(blk, (bi[sel], rows[sel] % b, cols[sel] % b), data[sel])
        out.append(blk)
    return out[0], out[1], out[2]


def _band_from_blocks(blocks: Blocks) -> np.ndarray:
    """LAPACK band storage ab[u + i - j, j] (u = l = 2b - 1) from (diag, lower, upper)."""
    diag, lower, upper = blocks
    nb, b, _ = diag.shape
    u = 2 * b - 1
    ab = np.zeros((2 * u + 1, nb * b), dtype=np.result_type(diag.dtype, float))
    p, q = np.meshgrid(np.arange(b), np.arange(b), indexing="ij")
    i = np.arange(nb)[:, None, None]
    for blk, shift in ((diag, 0), (lower, -1), (upper, 1)):
        rows = (i * b + p)
        cols = ((i + shift) * b + q)
        ok = np.broadcast_to((cols >= 0) & (cols < nb * b), blk.shape)
        ab[(u + rows - cols)[ok], cols[ok]] = blk[ok]
    return ab


def _blocks_sparse(blocks: Blocks) -> sp.csr_array:
    """CSR matrix from (diag, lower, upper) blocks (error messages only)."""
    ab = _band_from_blocks(blocks)
    u = (ab.shape[0] - 1) // 2
    n = ab.shape[1]
    return sp.csr_array(sp.diags_array([ab[u - d, max(0, d): n + min(0, d)]
                                        for d in range(-u, u + 1)],
                                       offsets=list(range(-u, u + 1)), shape=(n, n)))


def _solve_band_stacked(bK: np.ndarray, bM: np.ndarray, bC: np.ndarray | None,
                        f: np.ndarray, omega: np.ndarray, lo_bw: int, up_bw: int,
                        mats: tuple | None = None) -> np.ndarray:
    """All frequencies in one LAPACK ``gbsv`` call per chunk (no validation).

    bK, bM, bC: band storage ``ab[up + i - j, j]`` (lo + up + 1, n) of K, M, C; f of
    shape (n_omega, n, r).  The systems Z(w_k) U_k = F_k are stacked into one
    block-diagonal banded matrix of size n_omega·n with the same bandwidth (the
    entries of the band that would couple neighbouring frequencies are zero), so
    one partially pivoted banded LU solves every frequency at once.  ``mats``
    (K, M) names the nearest mode in the singular-matrix error.
    """
    n_w, n, r = f.shape
    rows = lo_bw + up_bw + 1
    out = np.empty((n_w, n, r), dtype=complex)
    chunk = max(1, _CHUNK_BYTES // (16 * n * (rows + lo_bw + r)))
    gbsv = sla.get_lapack_funcs("gbsv", dtype=complex)
    for lo in range(0, n_w, chunk):
        w = omega[lo: lo + chunk]
        m = w.size
        # Fortran-ordered band storage of the stack (no copy in the LAPACK wrapper):
        # column j of frequency k is column k·n + j
        ab = np.zeros((lo_bw + rows, m * n), dtype=complex, order="F")
        z = ab.reshape((lo_bw + rows, n, m), order="F")[lo_bw:]
        z += bK[:, :, None]
        z -= bM[:, :, None] * (w * w)
        if bC is not None:
            z += bC[:, :, None] * (1j * w)
        rhs = np.array(f[lo: lo + chunk].reshape(m * n, r), order="F")  # a copy
        _, _, x, info = gbsv(lo_bw, up_bw, ab, rhs, overwrite_ab=True, overwrite_b=True)
        if info > 0:
            k = lo + (info - 1) // n
            K, M = mats if mats is not None else (np.zeros((1, 1)), np.eye(1))
            raise _singular_error(K, M, float(omega[k]), None)
        if info < 0:  # pragma: no cover - argument error
            raise SolverError(f"LAPACK gbsv argument {-info} is invalid")
        out[lo: lo + chunk] = x.reshape(m, n, r)
    return out


def _as_blocks(name: str, a: Any, b: int, n: int | None) -> Blocks:
    if isinstance(a, tuple):
        if len(a) != 3:
            raise InputError(name, f"tuple of {len(a)}", "-",
                             "must be a matrix or the (diag, lower, upper) blocks")
        arrs = [_v.float_array(f"{name}[{k}]", x, "-", ndim=3) for k, x in enumerate(a)]
        shape = arrs[0].shape
        if shape[1:] != (b, b) or any(x.shape != shape for x in arrs):
            raise InputError(name, [x.shape for x in arrs], "-",
                             f"blocks must all have shape (n_blocks, {b}, {b})")
        blocks = (arrs[0], arrs[1], arrs[2])
    else:
        m = _as_matrix(name, a)
        blocks = tridiagonal_blocks(m, b)
    if n is not None and blocks[0].shape[0] != n:
        raise InputError(name, blocks[0].shape, "-", f"must have {n} blocks like K")
    return blocks


def solve_block_tridiagonal(
    K: Matrix | Blocks,
    M: Matrix | Blocks,
    C: Matrix | Blocks | None,
    F: np.ndarray,
    omega: np.ndarray,
    block_size: int,
) -> np.ndarray:
    r"""Harmonic response ``U = (K - omega^2 M + i omega C)^{-1} F`` of a block-tridiagonal
    model (one cable line), all frequencies and right-hand sides at once.

    Parameters
    ----------
    K, M : ndarray or scipy.sparse matrix or (diag, lower, upper)
        Stiffness [N/m] and total mass [kg], block-tridiagonal with ``block_size``
        blocks (node-major DOFs of a line), or their blocks from
        :func:`tridiagonal_blocks`.
    C : same or None
        Damping. [N·s/m]
    F : array_like, shape (n_omega, n_dof) or (n_omega, n_dof, n_rhs)
        Complex load amplitudes. [N]
    omega : array_like, shape (n_omega,)
        Angular frequencies, >= 0. [rad/s]
    block_size : int
        DOFs per node (2 in-plane, 3 in 3-D). [-]

    Returns
    -------
    ndarray, complex, same shape as ``F``
        Response amplitudes. [m]

    Raises
    ------
    InputError
        Matrices not block-tridiagonal, or shapes inconsistent.
    SolverError
        At an undamped resonance (estimated condition number above 1e12, as
        :func:`solve_direct`).

    Notes
    -----
    The matrix of one line is block-tridiagonal, i.e. banded with half-bandwidth
    ``2·block_size − 1``.  All frequencies are solved by ONE partially pivoted banded
    LU (LAPACK ``gbsv``) of the block-diagonal stack ``diag(Z(w_1), …, Z(w_n))``,
    whose band has the same width because the couplings between consecutive
    frequencies are zero: O(n_omega·n_dof·b²) work in one call (64 MB chunks), no
    Python loop over frequencies or nodes, and the stability of pivoted LU (no
    conditioning criterion or fallback needed).  A vectorized block cyclic reduction
    without pivoting (log2 n levels of stacked 2×2 numpy operations) was measured
    10× slower on the 40-element chain (numpy's stacked small-matrix products cost
    ~0.1 µs each), and a loop of one ``gbsv`` per frequency 1.5–2× slower
    (docs/BENCHMARKS.md, "Response analysis").
    """
    b = _v.positive_int("block_size", block_size)
    bw = 2 * b - 1
    w = _v.float_array("omega", omega, "rad/s", nonnegative=True)
    if isinstance(K, tuple):
        kb = _as_blocks("K", K, b, None)
        nb = kb[0].shape[0]
        mb = _as_blocks("M", M, b, nb)
        cb = None if C is None else _as_blocks("C", C, b, nb)
        for name, blk in (("K", kb), ("M", mb), ("C", cb)):
            if blk is not None and not all(np.all(np.isfinite(x)) for x in blk):
                raise InputError(name, "non-finite", "-", "must be finite (not NaN or inf)")
        mats = [_blocks_sparse(kb), _blocks_sparse(mb), None if cb is None else _blocks_sparse(cb)]
    else:
        mats = list(_matrices(K, M, C))
        if mats[0].shape[0] % b:
            raise InputError("K", mats[0].shape, "-",
                             f"size must be a multiple of block_size = {b}")
        lo_bw, up_bw = matrix_bandwidth(*mats)
        if max(lo_bw, up_bw) > bw:
            raise InputError("K, M, C", f"bandwidth ({lo_bw}, {up_bw})", "-",
                             f"must be block-tridiagonal with {b}x{b} blocks "
                             f"(bandwidth <= {bw})")
    n = mats[0].shape[0]
    f, squeeze = _loads(F, n, w.size)
    bands = [None if x is None else _band(x, n, bw, bw) for x in mats]
    u = _solve_band_stacked(bands[0], bands[1], bands[2], f, w, bw, bw, (mats[0], mats[1]))
    _check_conditioning(mats[0], mats[1], mats[2], w, f, u)
    return u[:, :, 0] if squeeze else u


# ---------------------------------------------------------------------------------
# modes
# ---------------------------------------------------------------------------------


def modal_basis(
    K: Matrix, M: Matrix, n_modes: int | None = None
) -> tuple[np.ndarray, np.ndarray]:
    r"""Lowest natural frequencies and mass-normalized mode shapes of ``(K, M)``.

    Parameters
    ----------
    K : ndarray or scipy.sparse matrix, shape (n_dof, n_dof)
        Symmetric positive definite stiffness. [N/m]
    M : ndarray or scipy.sparse matrix, shape (n_dof, n_dof)
        Symmetric positive definite mass. [kg]
    n_modes : int, optional
        Number of modes (default all). [-]

    Returns
    -------
    omega_n : ndarray, shape (n_modes,)
        Natural frequencies, ascending. [rad/s]
    phi : ndarray, shape (n_dof, n_modes)
        Mode shapes with ``phi^T M phi = I``; sign fixed so that the entry of
        largest magnitude of each mode is positive. [kg^-1/2]

    Raises
    ------
    SolverError
        If ``K`` has a clearly negative eigenvalue (unstable equilibrium) or
        ``M`` is not positive definite.

    Notes
    -----
    ``K phi = omega_n^2 M phi`` (DESIGN.md "Cable model", modes).  Dense input (or
    sparse up to 2000 DOF, or more than half the modes) uses LAPACK ``eigh``
    with an index subset; larger sparse models use ARPACK shift-invert about 0.
    """
    K_ = _as_matrix("K", K)
    n = K_.shape[0]
    M_ = _as_matrix("M", M, n)
    m = n if n_modes is None else _v.positive_int("n_modes", n_modes)
    if m > n:
        raise InputError("n_modes", n_modes, "-", f"must be <= n_dof = {n}")
    if sp.issparse(K_) and n > 2000 and 2 * m < n:
        lam, phi = spla.eigsh(sp.csc_matrix(K_), k=m, M=sp.csc_matrix(M_), sigma=0.0,
                              which="LM")
        order = np.argsort(lam)
        lam, phi = lam[order], phi[:, order]
        mm = np.einsum("ij,ij->j", phi, M_ @ phi)
        phi = phi / np.sqrt(mm)
    else:
        try:
            lam, phi = sla.eigh(_dense(K_, n), _dense(M_, n), subset_by_index=[0, m - 1])
        except np.linalg.LinAlgError as exc:
            raise SolverError(
                f"modal analysis failed: M is not positive definite ({exc})"
            ) from None
    scale = max(float(np.max(np.abs(lam))), np.finfo(float).tiny)
    if lam[0] < -1e-9 * scale:
        raise SolverError(
            f"K has a negative eigenvalue ({lam[0]:.3e} (rad/s)^2): the equilibrium is "
            "unstable or the model is not restrained; check the end conditions and statics"
        )
    omega_n = np.sqrt(np.clip(lam, 0.0, None))
    idx = np.argmax(np.abs(phi), axis=0)
    sign = np.sign(phi[idx, np.arange(phi.shape[1])])
    return omega_n, phi * np.where(sign == 0, 1.0, sign)


def auto_mode_count(omega_n: np.ndarray, omega_max: float, factor: float = 2.5) -> int:
    """Number of modes with natural frequency up to ``factor * omega_max``.

    Parameters
    ----------
    omega_n : array_like
        Natural frequencies, ascending. [rad/s]
    omega_max : float
        Highest frequency of the excitation (where its spectrum is significant). [rad/s]
    factor : float, optional
        Safety factor (> 1); the modes above contribute quasi-statically and are
        covered by the static correction of :func:`solve_modal`. [-]

    Returns
    -------
    int
        Mode count, at least 1 and at most ``len(omega_n)``. [-]
    """
    wn = _v.float_array("omega_n", omega_n, "rad/s", nonnegative=True)
    wmax = _v.positive("omega_max", omega_max, "rad/s")
    fac = _v.in_range("factor", factor, "-", 1.0)
    return int(min(wn.size, max(1, np.count_nonzero(wn <= fac * wmax))))


# ---------------------------------------------------------------------------------
# Foss
# ---------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class FossModes:
    """Complex modes of the first-order (Foss) form of the modal equations.

    Attributes
    ----------
    lambdas : ndarray, complex, shape (2n,)
        Eigenvalues ``lambda_j`` of ``lambda A theta + B theta = 0``. [rad/s]
    chi : ndarray, complex, shape (n, 2n)
        Lower halves ``chi_j`` of the eigenvectors ``theta_j = [lambda_j chi_j; chi_j]``.
    a : ndarray, complex, shape (2n,)
        ``a_j = theta_j^T A theta_j`` (plain transpose).
    weights : ndarray, complex, shape (2n, n)
        ``G^{-1} chi^T`` with ``G = Theta^T A Theta`` (``= diag(a)`` up to
        round-off; the full ``G`` keeps repeated eigenvalues exact), computed as
        ``Theta^{-1} [Mhat^{-1}; 0]`` (the same matrix, see
        :func:`foss_decomposition`).
    condition : float
        LAPACK ``gecon`` estimate of the 1-norm condition number of the
        column-normalized eigenvector matrix (within a factor ``2n`` of the
        2-norm one). [-]
    """

    lambdas: np.ndarray
    chi: np.ndarray
    a: np.ndarray
    weights: np.ndarray
    condition: float


def foss_decomposition(
    Mhat: np.ndarray, Chat: np.ndarray, Khat: np.ndarray
) -> FossModes:
    r"""Foss state-space decoupling of ``Mhat z'' + Chat z' + Khat z = Fhat``.

    Parameters
    ----------
    Mhat : array_like, shape (n, n)
        Modal mass (``I`` for mass-normalized modes). [kg]
    Chat : array_like, shape (n, n)
        Modal damping, full (non-proportional). [N·s/m]
    Khat : array_like, shape (n, n)
        Modal stiffness. [N/m]

    Returns
    -------
    FossModes

    Raises
    ------
    SolverError
        If the pencil is (nearly) defective — estimated eigenvector matrix condition
        number above ``DEFECTIVE_CONDITION`` (1e7), e.g. a critically damped mode, where
        some ``a_j`` vanish — or ``Mhat`` is not positive definite.

    Notes
    -----
    Seed 001 eqs. (5.3.4)-(5.3.20), as fixed in DESIGN.md: ``q = [z'; z]``,
    ``A = [[0, M], [M, C]]``, ``B = [[-M, 0], [0, K]]``, ``A q' + B q = [0; F]``.
    Eigenpairs of ``lambda A theta + B theta = 0``, computed as the standard
    eigenproblem of ``A^{-1}(-B) = [[-M^{-1} C, -M^{-1} K], [I, 0]]`` (``Mhat`` is
    SPD; LAPACK geev), ``theta_j = [lambda_j chi_j; chi_j]``,
    ``a_j = theta_j^T A theta_j``.
    Overdamped (real) eigenvalues and ``C = 0`` (``lambda = +-i omega_n``) need no
    special case.  For repeated eigenvalues (mode crossover) LAPACK returns some basis
    of the eigenspace, not necessarily ``A``-orthogonal; the transfer therefore
    uses ``G^{-1}`` with the full ``G = Theta^T A Theta`` — the exact identity
    ``(i w A + B)^{-1} = Theta (i w - Lambda)^{-1} G^{-1} Theta^T`` valid for any
    non-defective pencil — which reduces to ``1/a_j`` when the eigenvalues are
    distinct.

    Cost: one real ``geev`` of size 2n and one complex LU of ``Theta``.  The LU
    serves twice: ``gecon`` estimates the condition number from it (O(n²), instead
    of an SVD, which cost as much as the eigenproblem), and the weights are
    ``G^{-1} chi^T = Theta^{-1} A^{-1} Theta^{-T} Theta^T [0; I]
    = Theta^{-1} [Mhat^{-1}; 0]``, so ``G`` is never formed;
    ``a_j = 2 lambda_j chi_j^T Mhat chi_j + chi_j^T Chat chi_j`` (seed eq. 5.3.18).
    """
    Mh = _v.float_array("Mhat", Mhat, "kg", ndim=2)
    n = Mh.shape[0]
    Ch = _v.float_array("Chat", Chat, "N*s/m", ndim=2)
    Kh = _v.float_array("Khat", Khat, "N/m", ndim=2)
    for name, arr in (("Mhat", Mh), ("Chat", Ch), ("Khat", Kh)):
        if arr.shape != (n, n):
            raise InputError(name, arr, "-", f"must have shape ({n}, {n})")
    return _foss_decomposition(Mh, Ch, Kh)


def _foss_decomposition(Mh: np.ndarray, Ch: np.ndarray, Kh: np.ndarray) -> FossModes:
    """:func:`foss_decomposition` without validation (float arrays of shape (n, n))."""
    n = Mh.shape[0]
    try:
        mc = sla.cho_factor(Mh, check_finite=False)
    except np.linalg.LinAlgError:
        raise SolverError("Foss eigenproblem: Mhat is not positive definite") from None
    # A^{-1}(-B) = [[-M^-1 C, -M^-1 K], [I, 0]] acting on theta = [lambda chi; chi]:
    # a standard eigenproblem (LAPACK geev), 3-5x faster than QZ on the pencil
    # one triangular solve for M^-1 [C, K, I] (M^-1 also gives the weights below)
    minv = sla.cho_solve(mc, np.hstack([Ch, Kh, np.eye(n)]), check_finite=False)
    S = np.zeros((2 * n, 2 * n))
    S[:n] = -minv[:, : 2 * n]
    S[n:, :n] = np.eye(n)
    # NumPy's geev: the same LAPACK routine as scipy.linalg.eig, but its gufunc
    # releases the GIL (SciPy's f2py wrapper holds it, scipy/scipy#12436), so the
    # lines of a coupled group decompose concurrently (stochcable.runtime)
    lam, theta = np.linalg.eig(S)
    if not np.all(np.isfinite(lam)):  # pragma: no cover - S is finite
        raise SolverError("Foss eigenproblem produced non-finite eigenvalues")
    # SciPy's layout (complex, Fortran order), so the column norms sum in the same
    # order as before the switch: the decomposition is the same to the bit
    theta = np.asfortranarray(theta, dtype=complex)
    lam = lam.astype(complex, copy=False)
    theta /= np.linalg.norm(theta, axis=0)
    # One LU of the column-normalized eigenvector matrix gives both the condition
    # estimate (LAPACK gecon, 1-norm) and the weights Theta^{-1} A^{-1} [0; I].
    lu, piv = sla.lu_factor(theta, check_finite=False)
    if np.any(np.diagonal(lu) == 0.0):
        cond = np.inf
    else:
        rcond, _ = lapack.zgecon(lu, float(np.abs(theta).sum(axis=0).max()), norm="1")
        cond = 1.0 / rcond if rcond > 0 else np.inf
    if not np.isfinite(cond) or cond > DEFECTIVE_CONDITION:
        raise SolverError(
            f"Foss eigenproblem is (nearly) defective: eigenvector condition number "
            f"{cond:.2e} > {DEFECTIVE_CONDITION:.0e} (a critically damped mode, a_j ~ 0); "
            "use the direct modal solve (solve_modal(method='modal_direct'))"
        )
    chi = theta[n:]
    # A^{-1} [0; I] = [M^{-1}; 0] (A = [[0, M], [M, C]])
    rhs = np.zeros((2 * n, n), dtype=complex)
    rhs[:n] = minv[:, 2 * n:]
    weights = sla.lu_solve((lu, piv), rhs, check_finite=False)
    # a_j = theta_j^T A theta_j = 2 lambda_j chi_j^T M chi_j + chi_j^T C chi_j
    a = (2.0 * lam * np.einsum("ij,ij->j", chi, Mh @ chi)
         + np.einsum("ij,ij->j", chi, Ch @ chi))
    return FossModes(lam, chi, a, weights, float(cond))


def _mode_of_pair(foss: FossModes, j: int) -> int:
    return int(np.argmax(np.abs(foss.chi[:, j]))) + 1


def foss_transfer(foss: FossModes, F_hat: np.ndarray, omega: np.ndarray) -> np.ndarray:
    r"""Modal response ``z(omega)`` from the Foss modes.

    Parameters
    ----------
    foss : FossModes
        From :func:`foss_decomposition`.
    F_hat : array_like, complex, shape (n_omega, n) or (n_omega, n, n_rhs)
        Modal loads ``Phi^T F``. [N·kg^-1/2 for mass-normalized modes]
    omega : array_like, shape (n_omega,)
        Angular frequencies. [rad/s]

    Returns
    -------
    ndarray, complex, same shape as ``F_hat``
        Modal coordinates ``z``. [kg^1/2·m]

    Raises
    ------
    SolverError
        At an undamped resonance: ``|i omega - lambda_j| < 1e-12 max(|lambda_j|,
        omega)``; the message names omega, ``lambda_j`` and the mode.

    Notes
    -----
    ``z(omega) = sum_j chi_j (chi_j^T F_hat) / (a_j (i omega - lambda_j))`` (DESIGN.md;
    seed 001 eqs. 5.3.27-5.3.29), evaluated as ``chi diag(1/(i w - lambda)) G^{-1}
    chi^T F_hat`` (see :func:`foss_decomposition`): ``O(n^2)`` per frequency.
    """
    w = _v.float_array("omega", omega, "rad/s", nonnegative=True)
    n = foss.chi.shape[0]
    f, squeeze = _loads(F_hat, n, w.size)
    n_w, _, r = f.shape
    fm = np.ascontiguousarray(np.moveaxis(f, 0, 1)).reshape(n, n_w * r)
    z = _foss_transfer_modal(foss, fm, w, r)
    z = np.moveaxis(z.reshape(n, n_w, r), 1, 0)
    return z[:, :, 0] if squeeze else z


def _foss_transfer_modal(foss: FossModes, f: np.ndarray, w: np.ndarray, r: int) -> np.ndarray:
    """:func:`foss_transfer` in the mode-major layout, no validation.

    ``f`` complex (n, n_w·r) with column ``k·r + c`` = frequency k, right-hand side c;
    returns z in the same layout: two matrix products (BLAS gemm) for all
    frequencies and right-hand sides."""
    lam = foss.lambdas
    den = 1j * w[None, :] - lam[:, None]  # (2n, n_w)
    scale = np.maximum(np.abs(lam)[:, None], w[None, :])
    bad = np.abs(den) <= 1e-12 * scale
    if bad.any():
        j, k = (int(x[0]) for x in np.nonzero(bad))
        raise SolverError(
            f"undamped resonance at omega = {w[k]:.6g} rad/s: Foss eigenvalue "
            f"lambda = {lam[j]:.6g} of modal coordinate {_mode_of_pair(foss, j)} has no "
            "damping; add damping or remove this frequency from the grid"
        )
    p = foss.weights @ f  # (2n, n_w·r)
    p = p.reshape(lam.size, w.size, r)
    p /= den[:, :, None]
    return foss.chi @ p.reshape(lam.size, -1)


# ---------------------------------------------------------------------------------
# modal solve
# ---------------------------------------------------------------------------------


def _residual_flexibility_times(
    K: Matrix, phi: np.ndarray, Kh: np.ndarray, f: np.ndarray
) -> np.ndarray:
    """(K^{-1} - phi Kh^{-1} phi^T) f for f of shape (n_omega, n, r)."""
    n = K.shape[0]
    modal = phi @ np.linalg.solve(Kh, phi.T)
    if sp.issparse(K) and n > 2000:
        lu = spla.splu(sp.csc_matrix(K))
        rhs = np.moveaxis(f, 0, 1).reshape(n, -1)
        full = lu.solve(np.ascontiguousarray(rhs.real)) + 1j * lu.solve(
            np.ascontiguousarray(rhs.imag))
        return np.moveaxis(full.reshape(n, f.shape[0], -1), 1, 0) - modal @ f
    try:
        cf = sla.cho_factor(_dense(K, n))
    except np.linalg.LinAlgError:
        raise SolverError("static correction: K is not positive definite") from None
    flex = sla.cho_solve(cf, np.eye(n)) - modal
    return 0.5 * (flex + flex.T) @ f


def solve_modal(
    K: Matrix,
    M: Matrix,
    C: Matrix | None,
    F: np.ndarray,
    omega: np.ndarray,
    n_modes: int | None = None,
    method: Literal["foss", "modal_direct"] = "foss",
    static_correction: bool = True,
    basis: tuple[np.ndarray, np.ndarray] | None = None,
) -> np.ndarray:
    r"""Truncated modal solution of ``M U'' + C U' + K U = F``, Foss or direct in modal space.

    Parameters
    ----------
    K, M : ndarray or scipy.sparse matrix, shape (n_dof, n_dof)
        Stiffness [N/m] and total mass [kg].
    C : ndarray or scipy.sparse matrix or None
        Damping (need not be proportional). [N·s/m]
    F : array_like, shape (n_omega, n_dof) or (n_omega, n_dof, n_rhs)
        Complex load amplitudes. [N]
    omega : array_like, shape (n_omega,)
        Angular frequencies. [rad/s]
    n_modes : int, optional
        Number of lowest modes kept (default: all, or all of ``basis``). [-]
    method : {"foss", "modal_direct"}, optional
        ``"foss"``: Foss decoupling (:func:`foss_decomposition`), falling back to
        ``"modal_direct"`` with a :class:`DefectivePencilWarning` when the pencil
        is defective (critically damped mode).  ``"modal_direct"``: batched solve
        of ``(Khat - w^2 Mhat + i w Chat) z = Phi^T F`` (n_modes x n_modes).
    static_correction : bool, optional
        Add the quasi-static response of the truncated modes,
        ``(K^{-1} - Phi Khat^{-1} Phi^T) F``.
    basis : (omega_n, phi), optional
        Precomputed :func:`modal_basis` output (reuse it across the iterations of
        the drag linearization, where only ``C`` changes).

    Returns
    -------
    ndarray, complex, same shape as ``F``
        Response amplitudes ``U = Phi z (+ static correction)``. [m]

    Raises
    ------
    SolverError
        At an undamped resonance (message names omega and the mode).

    Notes
    -----
    Seed 001 §5.3: ``U = Phi z`` (eq. 5.3.1), ``Mhat = Phi^T M Phi``, ``Chat =
    Phi^T C Phi`` (full), ``Khat = Phi^T K Phi`` (eq. 5.3.3).  With all modes kept
    this equals :func:`solve_direct` to round-off.  The static correction is the
    residual-flexibility (mode-acceleration) correction; it neglects the damping
    coupling of the truncated modes.
    """
    K_, M_, C_ = _matrices(K, M, C)
    n = K_.shape[0]
    w = _v.float_array("omega", omega, "rad/s", nonnegative=True)
    f, squeeze = _loads(F, n, w.size)
    if method not in ("foss", "modal_direct"):
        raise InputError("method", method, "-", "must be 'foss' or 'modal_direct'")
    if basis is None:
        _, phi = modal_basis(K_, M_, n_modes)
    else:
        phi = _v.float_array("basis[1]", basis[1], "kg^-1/2", ndim=2)
        if phi.shape[0] != n:
            raise InputError("basis[1]", phi, "-", f"must have {n} rows")
        if n_modes is not None:
            m = _v.positive_int("n_modes", n_modes)
            if m > phi.shape[1]:
                raise InputError("n_modes", n_modes, "-", f"must be <= {phi.shape[1]}")
            phi = phi[:, :m]
    m = phi.shape[1]
    Mh = phi.T @ (M_ @ phi)
    Kh = phi.T @ (K_ @ phi)
    Ch = np.zeros((m, m)) if C_ is None else phi.T @ (C_ @ phi)
    Mh, Kh, Ch = 0.5 * (Mh + Mh.T), 0.5 * (Kh + Kh.T), 0.5 * (Ch + Ch.T)
    fh = phi.T @ f  # (m, n) @ (n_omega, n, r) -> (n_omega, m, r)
    z = None
    if method == "foss":
        try:
            foss = foss_decomposition(Mh, Ch, Kh)
        except SolverError as exc:
            warn(
                f"{exc}; falling back to the direct solve in modal coordinates",
                DefectivePencilWarning, stacklevel=2,
            )
        else:
            z = foss_transfer(foss, fh, w)
    if z is None:
        z = _solve_dense_batched(Kh, Mh, Ch, fh, w)
        _check_conditioning(Kh, Mh, Ch, w, fh, z)
    u = phi @ z
    if static_correction and m < n:
        u = u + _residual_flexibility_times(K_, phi, Kh, f)
    if not np.all(np.isfinite(u)):  # pragma: no cover - guarded above
        raise SolverError("modal solve produced non-finite values")
    return u[:, :, 0] if squeeze else u

