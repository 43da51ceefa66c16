"""The stacked banded solves Z(ω_k) X_k = B_k, Z = K − ω²M + iωC, of many right-hand
sides, compiled: each frequency's LU factored once (:func:`band_lu_factor`), the
right-hand sides substituted at any of them later (:func:`band_lu_substitute`).

LAPACK's ``zgbsv`` (:func:`stochcable.dynamics.model.solvers.solve_band_stacked`)
takes the stack as one block-diagonal banded matrix, formed as a copy, refactors it at
every call and substitutes one right-hand side column at a time (``zgbtrs``: a level-2
band solve per column).  Here each frequency's band is formed from K, M and C in its
slot of the kept factors and factored by the same partially pivoted LU (``zgbtf2``: the
pivot the largest |Re| + |Im| of the column, LAPACK's ``izamax``; Z is complex
symmetric and indefinite above the first resonance, so the pivoting is needed), and
the forward and backward substitutions run row by row, each step a contiguous
multiply-add over all right-hand sides of the row, in place.  The same operations, the
divisions by the pivots taken as products with their reciprocals: equal to round-off
(tests/dynamics/test_band_lu_kernels.py).

Imported lazily (numba's import is slow); compiled with ``cache=True``
(:func:`stochcable.compiled.jit_cached`).
"""

from __future__ import annotations

import numpy as np
from numba import types

from stochcable.compiled import jit_cached

__all__ = ["band_lu_factor", "band_lu_solve_each", "band_lu_substitute"]


def _factor(bk, bm, bc, w, kl, ku, lu, inv, piv):  # noqa: ANN001 - numba kernel
    """LU of Z(w[k]) = K − w²M + iwC (LAPACK band storage b[ku + i − j, j] of K, M, C)
    into lu[k, 0/1 (Re/Im), j, kv + i − j] (kv = kl + ku; column j contiguous, rows i ≤
    j + kl, the fill-in from j − kv), the reciprocal pivots inv[k, 0/1, j] and the row
    interchanges piv[k, j].  Returns 0, or k·n + j + 1 for an exactly zero pivot j of
    Z(w[k]) (``gbtrf``'s info, the frequency first)."""
    n = bk.shape[1]
    kv = kl + ku
    for k in range(w.size):
        wk = w[k]
        w2 = wk * wk
        a_re = lu[k, 0]
        a_im = lu[k, 1]
        for j in range(n):
            for q in range(kl):
                a_re[j, q] = 0.0
                a_im[j, q] = 0.0
            for q in range(kl + ku + 1):
                a_re[j, kl + q] = bk[q, j] - w2 * bm[q, j] - wk * bc[q, j].imag
                a_im[j, kl + q] = wk * bc[q, j].real
        ju = 0
        for j in range(n):
            km = min(kl, n - 1 - j)
            jp = 0
            amax = abs(a_re[j, kv]) + abs(a_im[j, kv])
            for q in range(1, km + 1):
                v = abs(a_re[j, kv + q]) + abs(a_im[j, kv + q])
                if v > amax:
                    amax = v
                    jp = q
            piv[k, j] = j + jp
            if amax == 0.0:
                return k * n + j + 1
            ju = max(ju, min(j + ku + jp, n - 1))
            if jp != 0:  # rows j and j + jp, columns j … ju
                for c in range(j, ju + 1):
                    p, s = kv + j - c, kv + j + jp - c
                    t = a_re[c, p]
                    a_re[c, p] = a_re[c, s]
                    a_re[c, s] = t
                    t = a_im[c, p]
                    a_im[c, p] = a_im[c, s]
                    a_im[c, s] = t
            pr, pi = a_re[j, kv], a_im[j, kv]
            den = pr * pr + pi * pi
            ir, ii = pr / den, -pi / den
            inv[k, 0, j] = ir
            inv[k, 1, j] = ii
            for q in range(1, km + 1):  # the multipliers l = a / pivot
                lr, li = a_re[j, kv + q], a_im[j, kv + q]
                a_re[j, kv + q] = lr * ir - li * ii
                a_im[j, kv + q] = lr * ii + li * ir
            for c in range(j + 1, ju + 1):  # the rank-one update of rows j + 1 … j + km
                ur, ui = a_re[c, kv + j - c], a_im[c, kv + j - c]
                for q in range(1, km + 1):
                    lr, li = a_re[j, kv + q], a_im[j, kv + q]
                    a_re[c, kv + j + q - c] -= lr * ur - li * ui
                    a_im[c, kv + j + q - c] -= lr * ui + li * ur
    return 0


def _substitute(lu, inv, piv, kl, at, w, terms, out, offset, indptr, indices, data):  # noqa: ANN001, PLR0913 - numba kernel
    """out[c, offset + i, m] (as (Re, Im) pairs along the last axis) ← x_i,c = (Z⁻¹b)_i,c
    at ω = w[at[m]] from :func:`_factor`'s factors, b = T₀ − ω²T₁ + iωT₂ of ``terms``
    (3, n, 2r), the complex right-hand sides as (Re, Im) pairs; the substitutions in
    scratch rows of one frequency (real and imaginary parts apart: contiguous runs over
    all right-hand sides, 20–25 % faster than pairs at 14–23 of them).  With a load
    matrix (CSR ``indptr``, ``indices``, ``data``: L rows over the n unknowns, not
    empty): out[c, l, m] ← Σ_p data[p]·x_indices[p],c over row l instead (the rows
    contracted with the loads, never written)."""
    n = lu.shape[2]
    kv = lu.shape[3] - 1 - kl
    r = terms.shape[2] // 2
    # the scratch rows padded to whole runs of 4 (no remainder loop: 14 rows 0.77 → 0.68
    # ms on 189 lines, 7 rows 0.63 → 0.50; 2 rows not: twice the work)
    rp = r if r < 4 else ((r + 3) // 4) * 4
    xr = np.empty((n, rp))
    xi = np.empty((n, rp))
    t0r = np.zeros((n, rp))  # (T₀ apart, once; the columns with ω terms listed)
    t0i = np.zeros((n, rp))
    sum_r = np.empty(rp)  # (a load's sums over its entries, with loads)
    sum_i = np.empty(rp)
    dyn = np.zeros(r, dtype=np.bool_)
    for i in range(n):
        for c in range(r):
            t0r[i, c] = terms[0, i, 2 * c]
            t0i[i, c] = terms[0, i, 2 * c + 1]
            for h in range(2 * c, 2 * c + 2):
                if terms[1, i, h] != 0.0 or terms[2, i, h] != 0.0:
                    dyn[c] = True
    cols = np.flatnonzero(dyn)
    for m in range(at.size):
        k = at[m]
        wk = w[k]
        w2 = wk * wk
        a_re = lu[k, 0]
        a_im = lu[k, 1]
        for i in range(n):
            for c in range(rp):
                xr[i, c] = t0r[i, c]
                xi[i, c] = t0i[i, c]
        for c in cols:
            for i in range(n):
                t1r, t1i = terms[1, i, 2 * c], terms[1, i, 2 * c + 1]
                t2r, t2i = terms[2, i, 2 * c], terms[2, i, 2 * c + 1]
                xr[i, c] = (t0r[i, c] - w2 * t1r) - wk * t2i
                xi[i, c] = (t0i[i, c] - w2 * t1i) + wk * t2r
        for j in range(n - 1):  # L y = P b
            p = piv[k, j]
            if p != j:
                for c in range(rp):
                    t = xr[j, c]
                    xr[j, c] = xr[p, c]
                    xr[p, c] = t
                    t = xi[j, c]
                    xi[j, c] = xi[p, c]
                    xi[p, c] = t
            for q in range(1, min(kl, n - 1 - j) + 1):
                lr, li = a_re[j, kv + q], a_im[j, kv + q]
                if lr == 0.0 and li == 0.0:  # (outside the blocks, or no fill-in)
                    continue
                for c in range(rp):
                    yr, yi = xr[j, c], xi[j, c]
                    xr[j + q, c] -= lr * yr - li * yi
                    xi[j + q, c] -= lr * yi + li * yr
        for i in range(n - 1, -1, -1):  # U x = y
            ir, ii = inv[k, 0, i], inv[k, 1, i]
            for c in range(rp):
                yr, yi = xr[i, c], xi[i, c]
                xr[i, c] = yr * ir - yi * ii
                xi[i, c] = yr * ii + yi * ir
            for q in range(1, min(kv, i) + 1):
                ur, ui = a_re[i, kv - q], a_im[i, kv - q]
                if ur == 0.0 and ui == 0.0:
                    continue
                for c in range(rp):
                    yr, yi = xr[i, c], xi[i, c]
                    xr[i - q, c] -= ur * yr - ui * yi
                    xi[i - q, c] -= ur * yi + ui * yr
        if indptr.size:
            for load in range(indptr.size - 1):
                for c in range(rp):
                    sum_r[c] = 0.0
                    sum_i[c] = 0.0
                for p in range(indptr[load], indptr[load + 1]):
                    v, i = data[p], indices[p]
                    for c in range(rp):
                        sum_r[c] += v * xr[i, c]
                        sum_i[c] += v * xi[i, c]
                for c in range(r):
                    out[c, load, 2 * m] = sum_r[c]
                    out[c, load, 2 * m + 1] = sum_i[c]
            continue
        for i in range(n):
            for c in range(r):
                out[c, offset + i, 2 * m] = xr[i, c]
                out[c, offset + i, 2 * m + 1] = xi[i, c]


def _solve_each(lu, inv, piv, kl, rhs, out):  # noqa: ANN001 - numba kernel
    """out[k, i, (Re, Im) of c] ← (Z(ω_k)⁻¹b_k)_i,c from :func:`_factor`'s factors of
    every frequency k, b_k = rhs[k] ((n, 2r): the complex right-hand sides as (Re, Im)
    pairs, a different one at each frequency: the drag fixed point's loads); the
    substitutions of :func:`_substitute`, in scratch rows of one frequency."""
    n = lu.shape[2]
    kv = lu.shape[3] - 1 - kl
    r = rhs.shape[2] // 2
    xr = np.empty((n, r))
    xi = np.empty((n, r))
    for k in range(rhs.shape[0]):
        a_re = lu[k, 0]
        a_im = lu[k, 1]
        for i in range(n):
            for c in range(r):
                xr[i, c] = rhs[k, i, 2 * c]
                xi[i, c] = rhs[k, i, 2 * c + 1]
        for j in range(n - 1):  # L y = P b
            p = piv[k, j]
            if p != j:
                for c in range(r):
                    t = xr[j, c]
                    xr[j, c] = xr[p, c]
                    xr[p, c] = t
                    t = xi[j, c]
                    xi[j, c] = xi[p, c]
                    xi[p, c] = t
            for q in range(1, min(kl, n - 1 - j) + 1):
                lr, li = a_re[j, kv + q], a_im[j, kv + q]
                if lr == 0.0 and li == 0.0:
                    continue
                for c in range(r):
                    yr, yi = xr[j, c], xi[j, c]
                    xr[j + q, c] -= lr * yr - li * yi
                    xi[j + q, c] -= lr * yi + li * yr
        for i in range(n - 1, -1, -1):  # U x = y
            ir, ii = inv[k, 0, i], inv[k, 1, i]
            for c in range(r):
                yr, yi = xr[i, c], xi[i, c]
                xr[i, c] = yr * ir - yi * ii
                xi[i, c] = yr * ii + yi * ir
            for q in range(1, min(kv, i) + 1):
                ur, ui = a_re[i, kv - q], a_im[i, kv - q]
                if ur == 0.0 and ui == 0.0:
                    continue
                for c in range(r):
                    yr, yi = xr[i, c], xi[i, c]
                    xr[i - q, c] -= ur * yr - ui * yi
                    xi[i - q, c] -= ur * yi + ui * yr
        for i in range(n):
            for c in range(r):
                out[k, i, 2 * c] = xr[i, c]
                out[k, i, 2 * c + 1] = xi[i, c]


_F2 = types.Array(types.float64, 2, "C", readonly=True)
_FACTOR_SIGNATURE = types.int64(
    _F2,
    _F2,
    types.Array(types.complex128, 2, "C", readonly=True),
    types.Array(types.float64, 1, "C", readonly=True),
    types.int64,
    types.int64,
    types.Array(types.float64, 4, "C"),
    types.Array(types.float64, 3, "C"),
    types.Array(types.int64, 2, "C"),
)
"""(K, M, C band, ω, kl, ku, the factors, the reciprocal pivots, the interchanges) →
info."""
_SUBSTITUTE_SIGNATURE = types.void(
    types.Array(types.float64, 4, "C", readonly=True),
    types.Array(types.float64, 3, "C", readonly=True),
    types.Array(types.int64, 2, "C", readonly=True),
    types.int64,
    types.Array(types.int64, 1, "C", readonly=True),
    types.Array(types.float64, 1, "C", readonly=True),
    types.Array(types.float64, 3, "C", readonly=True),
    types.Array(types.float64, 3, "C"),
    types.int64,
    types.Array(types.int64, 1, "C", readonly=True),
    types.Array(types.int64, 1, "C", readonly=True),
    types.Array(types.float64, 1, "C", readonly=True),
)
"""(the factors, the reciprocal pivots, the interchanges, kl, the frequencies solved
(indices), the frequencies factored, the right-hand sides' terms, the solutions, the
first row written, the loads' CSR arrays or empty ones)."""

_SOLVE_EACH_SIGNATURE = types.void(
    types.Array(types.float64, 4, "C", readonly=True),
    types.Array(types.float64, 3, "C", readonly=True),
    types.Array(types.int64, 2, "C", readonly=True),
    types.int64,
    types.Array(types.float64, 3, "C", readonly=True),
    types.Array(types.float64, 3, "C"),
)
"""(the factors, the reciprocal pivots, the interchanges, kl, the right-hand sides per
frequency, the solutions)."""

_factor_kernel, _ = jit_cached(_factor, _FACTOR_SIGNATURE, "banded LU factorization")
_solve_each_kernel, _ = jit_cached(_solve_each, _SOLVE_EACH_SIGNATURE, "banded LU solves")
_substitute_kernel, _ = jit_cached(_substitute, _SUBSTITUTE_SIGNATURE, "banded LU substitution")


def band_lu_factor(
    bk: np.ndarray,
    bm: np.ndarray,
    bc: np.ndarray | None,
    omega: np.ndarray,
    kl: int,
    ku: int,
) -> tuple[tuple[np.ndarray, np.ndarray, np.ndarray], int]:
    """The LU factors of Z(ω_k) = K − ω_k²M + iω_kC at every frequency.

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

    Returns
    -------
    factors : tuple of ndarray
        (the L and U factors (n_w, 2, n, 2·kl + ku + 1), their reciprocal pivots (n_w,
        2, n), the row interchanges (n_w, n)) for :func:`band_lu_substitute`.
    info : int
        0, or k·n + j + 1 where the pivot j of Z(ω_k) is exactly zero (the factors
        then incomplete).
    """
    bk = np.ascontiguousarray(bk, dtype=float)
    n = bk.shape[1]
    c = np.zeros(bk.shape, dtype=complex) if bc is None else bc
    w = np.ascontiguousarray(omega, dtype=float)
    lu = np.empty((w.size, 2, n, 2 * kl + ku + 1))
    inv = np.empty((w.size, 2, n))
    piv = np.empty((w.size, n), dtype=np.int64)
    info = _factor_kernel(
        bk,
        np.ascontiguousarray(bm, dtype=float),
        np.ascontiguousarray(c, dtype=complex),
        w,
        int(kl),
        int(ku),
        lu,
        inv,
        piv,
    )
    return (lu, inv, piv), int(info)


def band_lu_substitute(
    factors: tuple[np.ndarray, np.ndarray, np.ndarray],
    kl: int,
    omega: np.ndarray,
    at: np.ndarray,
    terms: np.ndarray,
    out: np.ndarray,
    offset: int = 0,
    loads: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
) -> None:
    """Z(ω)⁻¹b(ω) at the frequencies ``omega[at]`` from :func:`band_lu_factor`'s
    ``factors``, b(ω) = T₀ − ω²T₁ + iωT₂, written into ``out`` (or contracted with
    ``loads`` first).

    Parameters
    ----------
    factors : tuple of ndarray
        :func:`band_lu_factor`'s.
    kl : int
        The lower bandwidth they were factored with. [-]
    omega : ndarray, shape (n_w,)
        The frequencies factored. [rad/s]
    at : ndarray of int, shape (n_at,)
        The frequencies solved (indices into ``omega``). [-]
    terms : ndarray, complex, shape (3, n, r)
        (T₀, T₁, T₂) of the right-hand sides. [N, N·s²/m², N·s/m]
    out : ndarray, complex, shape (r, N, n_at), C-contiguous
        Rows ``offset`` … ``offset + n − 1`` overwritten by the solutions (the others
        untouched); with ``loads``, shape (r, L, n_at), all overwritten by the
        solutions' products with the loads. [m] or [m·unit/N]
    offset : int
        The first row of ``out`` written (without ``loads``). [-]
    loads : tuple of ndarray, optional
        A real (L, n) CSR matrix (``indptr``, ``indices``, ``data``): each load case's
        weights on the n unknowns. [unit]
    """
    if not out.flags.c_contiguous or out.dtype != complex:
        raise ValueError("band_lu_substitute: out must be a C-contiguous complex array")
    lu, inv, piv = factors
    t = np.ascontiguousarray(terms, dtype=complex)
    if loads is not None and len(loads[0]) < 2:
        return  # (no load case: nothing to write)
    if loads is None:
        none = np.zeros(0, dtype=np.int64)
        loads = (none, none, np.zeros(0))
    _substitute_kernel(
        lu,
        inv,
        piv,
        int(kl),
        np.ascontiguousarray(at, dtype=np.int64),
        np.ascontiguousarray(omega, dtype=float),
        t.view(float).reshape(3, t.shape[1], -1),
        out.view(float).reshape(out.shape[0], out.shape[1], -1),
        int(offset),
        np.ascontiguousarray(loads[0], dtype=np.int64),
        np.ascontiguousarray(loads[1], dtype=np.int64),
        np.ascontiguousarray(loads[2], dtype=float),
    )


def band_lu_solve_each(
    factors: tuple[np.ndarray, np.ndarray, np.ndarray], kl: int, rhs: np.ndarray
) -> np.ndarray:
    """Z(ω_k)⁻¹b_k at every frequency factored by :func:`band_lu_factor`, a different
    right-hand side block b_k at each.

    Parameters
    ----------
    factors : tuple of ndarray
        :func:`band_lu_factor`'s, of n_w frequencies.
    kl : int
        The lower bandwidth they were factored with. [-]
    rhs : ndarray, complex, shape (n_w, n, r)
        The right-hand sides per frequency. [N]

    Returns
    -------
    ndarray, complex, shape (n_w, n, r)
        The solutions. [m]
    """
    lu, inv, piv = factors
    b = np.ascontiguousarray(rhs, dtype=complex)
    out = np.empty(b.shape, dtype=complex)
    n_w, n = b.shape[:2]
    _solve_each_kernel(
        lu,
        inv,
        piv,
        int(kl),
        b.view(float).reshape(n_w, n, -1),
        out.view(float).reshape(n_w, n, -1),
    )
    return out
