"""Frequency-domain solves of ``M_T U'' + C U' + K U = F`` (Tuah 1982, §5.3; DESIGN.md
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
- the modal solves (:func:`modal_basis`, :func:`foss_decomposition`,
  :func:`foss_transfer`, :func:`solve_modal`, :func:`auto_mode_count`) are in
  :mod:`stochcable.dynamics.model.modal_solvers`.

Singular dynamic matrices (undamped resonance) raise :class:`SolverError` naming the
frequency and the mode; no function returns inf or NaN.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
from numpy.typing import ArrayLike

from stochcable import validation as _v
from stochcable.errors import InputError, SolverError

__all__ = [
    "matrix_bandwidth",
    "solve_block_tridiagonal",
    "solve_direct",
    "tridiagonal_blocks",
]

#: A solve whose estimated condition number exceeds this is treated as singular.
SINGULAR_CONDITION = 1e12
_CHUNK_BYTES = 64 * 2**20


#: A validated matrix: dense or CSR.
Matrix = np.ndarray | sp.csr_matrix
#: A matrix as given: array-like or any scipy.sparse matrix or array.
MatrixLike = ArrayLike | sp.spmatrix | sp.sparray


# ---------------------------------------------------------------------------------
# helpers
# ---------------------------------------------------------------------------------


def as_matrix(name: str, a: MatrixLike, n: int | None = None) -> Matrix:
    """``a`` as a float matrix (CSR when sparse), square and of size ``n`` when given
    (InputError naming ``name`` otherwise)."""
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


def system_matrices(
    K: MatrixLike, M: MatrixLike, C: MatrixLike | None
) -> tuple[Matrix, Matrix, Matrix | None]:
    """K, M and C (or None) validated by :func:`as_matrix`, all of K's size."""
    K_ = as_matrix("K", K)
    n = K_.shape[0]
    M_ = as_matrix("M", M, n)
    C_ = None if C is None else as_matrix("C", C, n)
    return K_, M_, C_


def load_array(F: ArrayLike, n: int, n_omega: int) -> tuple[np.ndarray, bool]:
    """The load as a complex (n_omega, n, n_rhs) array and whether it had no n_rhs axis."""
    f = np.asarray(F)
    if not np.iscomplexobj(f):
        f = f.astype(float)
    f = f.astype(complex)
    if f.ndim not in (2, 3) or f.shape[0] != n_omega or f.shape[1] != n:
        raise InputError(
            "F",
            f,
            "N",
            f"must have shape (n_omega={n_omega}, n_dof={n}[, n_rhs]) (got {f.shape})",
        )
    if not np.all(np.isfinite(f)):
        raise InputError("F", f, "N", "must be finite (not NaN or inf)")
    squeeze = f.ndim == 2
    return (f[:, :, None] if squeeze else f), squeeze


def dense_matrix(a: Matrix | None, n: int) -> np.ndarray:
    """``a`` as a dense (n, n) array (zeros for None)."""
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
        ab[up - d, max(0, d) : n + min(0, d)] = diag
    return ab


def _fro(a: Matrix | None) -> float:
    if a is None:
        return 0.0
    if sp.issparse(a):
        return float(sp.linalg.norm(a))
    return float(np.linalg.norm(a))


def _nearest_mode_text(K: Matrix, M: Matrix, w: float) -> str:
    """Describe the natural frequency nearest to ``w`` (used in error messages only)."""
    import scipy.sparse.linalg as spla  # (here: ~10 ms of import most analyses skip)

    try:
        n = K.shape[0]
        if n <= 2000:
            lam = sla.eigh(dense_matrix(K, n), dense_matrix(M, n), eigvals_only=True)
        else:  # pragma: no cover - large models
            lam = spla.eigsh(
                sp.csc_matrix(K), k=6, M=sp.csc_matrix(M), sigma=w * w, return_eigenvectors=False
            )
            lam = np.sort(lam)
        wn = np.sqrt(np.clip(lam, 0.0, None))
        j = int(np.argmin(np.abs(wn - w)))
        return f"mode {j + 1} (natural frequency {wn[j]:.6g} rad/s)"
    except Exception:  # noqa: BLE001 - message helper must not mask the real error
        return "a mode of (K, M)"


def singular_error(K: Matrix, M: Matrix, w: float, cond: float | None) -> SolverError:
    """The SolverError of a singular dynamic matrix at ``w`` [rad/s], naming the nearest
    natural frequency of (K, M)."""
    what = f"estimated condition number {cond:.2e}" if cond is not None else "exactly singular"
    return SolverError(
        f"dynamic matrix K - w^2 M + i w C is singular at omega = {w:.6g} rad/s ({what}): "
        f"undamped resonance of {_nearest_mode_text(K, M, w)}; add damping "
        "(drag, structural) or remove this frequency from the grid"
    )


def check_conditioning(K, M, C, omega, F, U) -> None:
    """Raise SolverError where ||Z|| ||U|| / ||F|| (a lower bound of cond Z) is huge."""
    nz = _fro(K) + omega**2 * _fro(M) + omega * _fro(C)
    nf = np.linalg.norm(F.reshape(F.shape[0], -1), axis=1)
    nu = np.linalg.norm(U.reshape(U.shape[0], -1), axis=1)
    finite = np.isfinite(nu)
    est = np.where(finite, nz * np.where(nf > 0, nu / np.where(nf > 0, nf, 1.0), 0.0), np.inf)
    bad = np.flatnonzero(est > SINGULAR_CONDITION)
    if bad.size:
        k = int(bad[np.argmax(est[bad])])
        raise singular_error(K, M, float(omega[k]), float(est[k]) if finite[k] else None)


# ---------------------------------------------------------------------------------
# direct solve
# ---------------------------------------------------------------------------------


def solve_dense_batched(K, M, C, F, omega):
    """Z(ω)⁻¹F for all frequencies by one batched dense LU (dense K, M, C)."""
    n = F.shape[1]
    Kd, Md = dense_matrix(K, n), dense_matrix(M, n)
    Cd = None if C is None else dense_matrix(C, n)
    out = np.empty_like(F)
    chunk = max(1, _CHUNK_BYTES // (16 * n * n))
    for lo in range(0, omega.size, chunk):
        w = omega[lo : lo + chunk, None, None]
        Z = Kd - w**2 * Md + (0j if Cd is None else 1j * w * Cd)
        try:
            out[lo : lo + chunk] = np.linalg.solve(Z, F[lo : lo + chunk])
        except np.linalg.LinAlgError:
            for k in range(Z.shape[0]):  # error path only: find the singular frequency
                try:
                    np.linalg.solve(Z[k], F[lo + k])
                except np.linalg.LinAlgError:
                    raise singular_error(K, M, float(omega[lo + k]), None) from None
            raise  # pragma: no cover
    return out


def _solve_banded(K, M, C, F, omega, lo_bw, up_bw):
    n = F.shape[1]
    bK, bM = _band(K, n, lo_bw, up_bw), _band(M, n, lo_bw, up_bw)
    bC = None if C is None else _band(C, n, lo_bw, up_bw)
    # all frequencies in one stacked LAPACK gbsv call (see solve_band_stacked)
    return solve_band_stacked(bK, bM, bC, F, omega, lo_bw, up_bw, (K, M))


def _solve_sparse(K, M, C, F, omega):
    import scipy.sparse.linalg as spla  # (here: ~10 ms of import most analyses skip)

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
            raise singular_error(K, M, float(w), None) from None
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
    The reference solution of DESIGN.md "Solution: direct and Foss" (Tuah
    1982, eq. 5.2.6 in the frequency domain).
    """
    K_, M_, C_ = system_matrices(K, M, C)
    n = K_.shape[0]
    w = _v.float_array("omega", omega, "rad/s", nonnegative=True)
    f, squeeze = load_array(F, n, w.size)
    if method == "auto":
        method, lo_bw, up_bw = _choose_method(K_, M_, C_, n)
    elif method == "banded":
        lo_bw, up_bw = matrix_bandwidth(K_, M_, C_)
    elif method not in ("dense", "sparse"):
        raise InputError("method", method, "-", "must be 'auto', 'dense', 'banded' or 'sparse'")
    if method == "dense":
        u = solve_dense_batched(K_, M_, C_, f, w)
    elif method == "banded":
        u = _solve_banded(K_, M_, C_, f, w, lo_bw, up_bw)
    else:
        u = _solve_sparse(K_, M_, C_, f, w)
    check_conditioning(K_, M_, C_, w, f, u)
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
        raise InputError(
            "A",
            f"entry ({rows[k]}, {cols[k]})",
            "-",
            f"must be block-tridiagonal with {b}x{b} blocks",
        )
    out = []
    for sel in (off == 0, off == 1, off == -1):
        blk = np.zeros((nb, b, b), dtype=dtype)
        np.add.at(blk, (bi[sel], rows[sel] % b, cols[sel] % b), data[sel])
        out.append(blk)
    return out[0], out[1], out[2]


def band_from_blocks(blocks: Blocks) -> np.ndarray:
    """LAPACK band storage ab[u + i - j, j] (u = l = 2b - 1) from (diag, lower, upper)."""
    diag, lower, upper = blocks
    nb, b, _ = diag.shape
    u = 2 * b - 1
    ab = np.zeros((2 * u + 1, nb * b), dtype=np.result_type(diag.dtype, float))
    p, q = np.meshgrid(np.arange(b), np.arange(b), indexing="ij")
    i = np.arange(nb)[:, None, None]
    for blk, shift in ((diag, 0), (lower, -1), (upper, 1)):
        rows = i * b + p
        cols = (i + shift) * b + q
        ok = np.broadcast_to((cols >= 0) & (cols < nb * b), blk.shape)
        ab[(u + rows - cols)[ok], cols[ok]] = blk[ok]
    return ab


def _blocks_sparse(blocks: Blocks) -> sp.csr_array:
    """CSR matrix from (diag, lower, upper) blocks (error messages only)."""
    ab = band_from_blocks(blocks)
    u = (ab.shape[0] - 1) // 2
    n = ab.shape[1]
    return sp.csr_array(
        sp.diags_array(
            [ab[u - d, max(0, d) : n + min(0, d)] for d in range(-u, u + 1)],
            offsets=list(range(-u, u + 1)),
            shape=(n, n),
        )
    )


def solve_band_stacked(
    bK: np.ndarray,
    bM: np.ndarray,
    bC: np.ndarray | None,
    f: np.ndarray,
    omega: np.ndarray,
    lo_bw: int,
    up_bw: int,
    mats: tuple | None = None,
) -> np.ndarray:
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
        w = omega[lo : lo + chunk]
        m = w.size
        # Fortran-ordered band storage of the stack (no copy in the LAPACK wrapper):
        # column j of frequency k is column k·n + j
        ab = np.zeros((lo_bw + rows, m * n), dtype=complex, order="F")
        z = ab.reshape((lo_bw + rows, n, m), order="F")[lo_bw:]
        z += bK[:, :, None]
        z -= bM[:, :, None] * (w * w)
        if bC is not None:
            z += bC[:, :, None] * (1j * w)
        rhs = np.array(f[lo : lo + chunk].reshape(m * n, r), order="F")  # a copy
        _, _, x, info = gbsv(lo_bw, up_bw, ab, rhs, overwrite_ab=True, overwrite_b=True)
        if info > 0:
            k = lo + (info - 1) // n
            K, M = mats if mats is not None else (np.zeros((1, 1)), np.eye(1))
            raise singular_error(K, M, float(omega[k]), None)
        if info < 0:  # pragma: no cover - argument error
            raise SolverError(f"LAPACK gbsv argument {-info} is invalid")
        out[lo : lo + chunk] = x.reshape(m, n, r)
    return out


def _as_blocks(name: str, a: Blocks | MatrixLike, b: int, n: int | None) -> Blocks:
    if isinstance(a, tuple):
        if len(a) != 3:
            raise InputError(
                name,
                f"tuple of {len(a)}",
                "-",
                "must be a matrix or the (diag, lower, upper) blocks",
            )
        arrs = [_v.float_array(f"{name}[{k}]", x, "-", ndim=3) for k, x in enumerate(a)]
        shape = arrs[0].shape
        if shape[1:] != (b, b) or any(x.shape != shape for x in arrs):
            raise InputError(
                name,
                [x.shape for x in arrs],
                "-",
                f"blocks must all have shape (n_blocks, {b}, {b})",
            )
        blocks = (arrs[0], arrs[1], arrs[2])
    else:
        m = as_matrix(name, a)
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
        mats = list(system_matrices(K, M, C))
        if mats[0].shape[0] % b:
            raise InputError(
                "K", mats[0].shape, "-", f"size must be a multiple of block_size = {b}"
            )
        lo_bw, up_bw = matrix_bandwidth(*mats)
        if max(lo_bw, up_bw) > bw:
            raise InputError(
                "K, M, C",
                f"bandwidth ({lo_bw}, {up_bw})",
                "-",
                f"must be block-tridiagonal with {b}x{b} blocks (bandwidth <= {bw})",
            )
    n = mats[0].shape[0]
    f, squeeze = load_array(F, n, w.size)
    bands = [None if x is None else _band(x, n, bw, bw) for x in mats]
    u = solve_band_stacked(bands[0], bands[1], bands[2], f, w, bw, bw, (mats[0], mats[1]))
    check_conditioning(mats[0], mats[1], mats[2], w, f, u)
    return u[:, :, 0] if squeeze else u
