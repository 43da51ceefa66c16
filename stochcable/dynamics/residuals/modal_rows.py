"""The rows of the end tensions' and stations' influence through a line's complex
(Foss) modes (:func:`~stochcable.dynamics.residuals.influence.modal_influence`): the
modal sums of fixed right-hand sides over the frequencies (:func:`modal_sums`) and the
rows kept factored (:class:`ModalRows`)."""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy import sparse

from stochcable.dynamics.model.blocks import real_gemm

__all__ = ["PAIR_TOL", "STATIC_ROWS", "ModalRows", "ModalSums", "modal_sums", "static_rows"]

#: Relative tolerance to which two modes are taken as a complex-conjugate pair
#: (eigenvalues and χ_j p_j) in :func:`modal_sums`. [-]
PAIR_TOL = 1e-10


def modal_sums(chi: np.ndarray, p: np.ndarray, lambdas: np.ndarray, w: np.ndarray) -> np.ndarray:
    """z_k(ω) = Σ_j χ_j p_jk/(iω − λ_j) of the complex modes (χ (m, 2m), λ (2m,)) and the
    modal loads ``p`` (2m, k) of real right-hand sides on ``w``: shape (m, k, n_w)
    (:class:`ModalSums`, which gives them right-hand side first)."""
    return np.moveaxis(ModalSums(chi, p, lambdas)(w), 0, 1)


class ModalSums:
    """z_k(ω) = Σ_j χ_j p_jk/(iω − λ_j) (:func:`modal_sums`), its frequency-independent
    part formed once: the terms χ_j p_j (k·m, 2m: right-hand side first), paired.

    One product over the modes of the terms and the denominators (no (2m, k, n_w)
    array), in real arithmetic: a real system's modes come in conjugate pairs (λ', χ'
    p') = (λ̄, conj(χ p)) (the underdamped ones), whose two terms are Re(χp)·(d + d') +
    Im(χp)·i(d − d'), d = 1/(iω − λ), d' = 1/(iω − λ̄): half the work of the complex
    product.  The modes without such a partner (overdamped: real λ; complex right-hand
    sides) keep their own term.  [as χ·p]"""

    def __init__(self, chi: np.ndarray, p: np.ndarray, lambdas: np.ndarray) -> None:
        m, k = chi.shape[0], p.shape[1]
        terms = (p.T[:, None, :] * chi[None]).reshape(k * m, -1)  # (k·m, 2m): χ_j p_j
        first, second = _conjugate_pairs(terms, lambdas, (chi, p))
        used = np.zeros(lambdas.size, dtype=bool)
        used[first] = used[second] = True
        alone = np.flatnonzero(~used)
        coef = np.concatenate([terms[:, first], terms[:, alone]], axis=1)
        self.lhs = np.ascontiguousarray(np.concatenate([coef.real, coef.imag], axis=1))
        self.lambdas, self.first, self.second, self.alone = lambdas, first, second, alone
        self.shape = (k, m)

    def __call__(self, w: np.ndarray, cols: slice | None = None, const: int = 0) -> np.ndarray:
        """The sums on ``w``, right-hand side first: shape (k, m, n_w); of the
        right-hand sides ``cols`` (a slice, step 1) alone, if given: (k_cols, m, n_w);
        with ``const`` (0 … 3) more rows of each, 1, −ω², iω (:data:`STATIC_ROWS`):
        (k, m + const, n_w), formed by the same product."""
        w = np.asarray(w, dtype=float)
        iw = 1j * w[None, :]
        lam = self.lambdas[:, None]
        first, alone = self.first.size, self.alone.size
        n_t = first + alone
        # (2·n_terms, n_w): the real parts' factors, then the imaginary parts'
        den = np.empty((2 * n_t, iw.size), dtype=complex)
        d, d2 = 1.0 / (iw - lam[self.first]), 1.0 / (iw - lam[self.second])
        np.add(d, d2, out=den[:first])
        np.subtract(d, d2, out=den[n_t : n_t + first])
        den[n_t : n_t + first] *= 1j
        if alone:
            np.divide(1.0, iw - lam[self.alone], out=den[first:n_t])
            np.multiply(den[first:n_t], 1j, out=den[n_t + first : 2 * n_t])
        (k, m), lhs = self.shape, self.lhs
        at = range(k)[slice(None) if cols is None else cols]
        lhs = lhs[at.start * m : at.stop * m]  # (their terms: a run of rows, a view)
        if not const:
            return (lhs @ den.view(float)).view(complex).reshape((len(at), m, -1))
        # (each right-hand side's sums written beside its static coordinates)
        out = np.empty((len(at), m + const, iw.size), dtype=complex)
        np.matmul(lhs.reshape(len(at), m, -1), den.view(float), out=out.view(float)[:, :m])
        static_rows(np.moveaxis(out[:, m:], 1, 0), w)
        return out


#: The modal rows' static coordinates (:class:`ModalRows`): r₀, r₁, r₂ of the static
#: correction r₀ − ω²r₁ + iωr₂ enter as modes whose coordinates are 1, −ω², iω. [-]
STATIC_ROWS = 3


def static_rows(out: np.ndarray, w: np.ndarray) -> np.ndarray:
    """The static coordinates 1, −ω², iω (the first ``out.shape[0]``) on ``w``, into
    ``out`` (c, n_w) complex."""
    for j, v in enumerate((1.0, -(w * w), 1j * w)[: out.shape[0]]):
        out[j] = v
    return out


def _conjugate_pairs(
    terms: np.ndarray, lambdas: np.ndarray, factors: tuple | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """The modes (j, j') that are conjugate pairs: λ_j' = conj(λ_j) and the terms
    χ_j' p_j' = conj(χ_j p_j) to :data:`PAIR_TOL` (indices, Im λ_j > 0).  ``factors``
    (χ (m, 2m), p (2m, k)) of ``terms``, if given: the terms' test is taken as met
    where their factors' bound meets it (|χ'p' − conj(χp)| ≤ |χ' − conj χ|·|p'| +
    |χ|·|p' − conj p| elementwise), every term compared only for the others."""
    pos = np.flatnonzero(lambdas.imag > 0)
    if pos.size == 0:
        return pos, pos
    gap = np.abs(lambdas[None, :] - np.conj(lambdas[pos])[:, None])  # (n_pos, 2m)
    partner = np.argmin(gap, axis=1)
    scale = np.abs(lambdas[pos])
    ok = (gap[np.arange(pos.size), partner] <= PAIR_TOL * scale) & (lambdas[partner].imag < 0)
    size = np.max(np.abs(terms[:, pos]), axis=0)
    check = np.ones(pos.size, dtype=bool)
    if factors is not None:
        chi, p = factors
        e_chi = np.max(np.abs(chi[:, partner] - np.conj(chi[:, pos])), axis=0)
        e_p = np.max(np.abs(p[partner] - np.conj(p[pos])), axis=1)
        big_chi, big_p = np.max(np.abs(chi[:, pos]), axis=0), np.max(np.abs(p[partner]), axis=1)
        check = e_chi * big_p + big_chi * e_p > 0.5 * PAIR_TOL * size  # (half: round-off)
    at = np.flatnonzero(check & ok)
    if at.size:
        diff = np.abs(terms[:, partner[at]] - np.conj(terms[:, pos[at]]))
        ok[at] &= np.all(diff <= PAIR_TOL * size[at][None], axis=0)
    ok &= np.bincount(partner[ok], minlength=lambdas.size)[partner] <= 1  # (each one partner)
    return pos[ok], partner[ok]


class ModalRows:
    """The rows of :func:`modal_influence` kept factored, x(ω) = Φ_f z(ω) + r₀ − ω²r₁
    + iωr₂ on the free nodes and ê on the end nodes (the end rows'), shape (R, n_nodes,
    d, n_w) as an array (``np.asarray``) but sliced by rows (``g[a:b]``) and lines
    (``g[..., idx]``) without forming it, and contracted with load cases through the m
    modes (:meth:`transfer`: the chain's 27 rows on 189 lines, 6.7 MB, never formed).
    The modal coordinates ``z`` row first, (R, m + c, n_w): a run of rows and the
    leading lines are views the products read in place; its last c rows the static
    coordinates 1, −ω², iω (:func:`static_rows`: c = 1 where only r₀ enters, 3 with
    the end rows' r₁, r₂, 0 without a static correction), so that the static rows
    contracted with the loads enter the same product as the modes' (:meth:`transfer`).
    [N/N]"""

    def __init__(self, phi, z, w, rc, ends, n_nodes, marks=None) -> None:  # noqa: ANN001
        m = phi.shape[1]
        if rc is not None and z.shape[1] == m:  # (no static coordinates given: appended)
            z = np.concatenate([z, np.zeros((z.shape[0], STATIC_ROWS, w.size), dtype=complex)], 1)
            static_rows(np.moveaxis(z[:, m:], 1, 0), w)
        elif rc is not None and marks is None and np.any(rc[z.shape[1] - m :]):
            raise ValueError(
                f"ModalRows: z has {z.shape[1] - m} static coordinate rows (1, −ω², iω) "
                f"but the static rows rc carry terms beyond them; give all {STATIC_ROWS}"
            )
        self.phi, self.z, self.w, self.rc, self.ends = phi, z, w, rc, ends
        self.n_nodes = n_nodes
        d = ends.shape[2]
        self.shape = (z.shape[0], n_nodes, d, w.size)
        self.ndim, self.dtype = 4, np.dtype(complex)
        if marks is None:  # (the rows with r₁, r₂ and those with ê: the end rows)
            dyn = np.zeros(z.shape[0], dtype=bool) if rc is None else np.any(rc[1:] != 0, (0, 1))
            marks = (dyn, np.any(ends != 0, axis=(0, 2)))
        self.marks = marks
        self._rows: tuple | None = None  # (the marked rows, when first asked: _marked)

    def _marked(self) -> tuple[Any, Any]:
        """The rows with r₁, r₂ and those with ê (:func:`_rows_of` of the marks)."""
        if self._rows is None:
            self._rows = (_rows_of(self.marks[0]), _rows_of(self.marks[1]))
        return self._rows

    def __getitem__(self, key: Any) -> ModalRows:
        rows, lines = (slice(None), key[1]) if isinstance(key, tuple) else (key, slice(None))
        if isinstance(key, tuple) and key[0] is not Ellipsis:
            raise IndexError("ModalRows: g[rows] or g[..., lines] only")
        if isinstance(rows, slice) and rows == slice(None):  # (the lines only: the same rows)
            out = ModalRows(
                self.phi, self.z[:, :, lines], self.w[lines], self.rc, self.ends, self.n_nodes,
                self.marks,
            )  # fmt: skip
            out._rows = self._rows
            return out
        rc = None if self.rc is None else self.rc[:, :, rows]
        return ModalRows(
            self.phi, self.z[rows][:, :, lines], self.w[lines], rc,
            self.ends[:, rows], self.n_nodes, (self.marks[0][rows], self.marks[1][rows]),
        )  # fmt: skip

    def _add_static(self, x: np.ndarray, rc: np.ndarray) -> np.ndarray:
        """``x`` (R, X, n_w) plus r₀ − ω²r₁ + iωr₂ of static rows ``rc`` (3, R, X), in
        place (r₁, r₂ on the end rows only)."""
        x += rc[0][..., None]
        dyn = self._marked()[0]
        if dyn is not None:
            w = self.w
            x[dyn] += rc[2][dyn, :, None] * (1j * w) - rc[1][dyn, :, None] * (w * w)
        return x

    def __array__(self, dtype: Any = None, copy: Any = None) -> np.ndarray:
        n_r, n, d, n_w = self.shape
        out = np.zeros(self.shape, dtype=complex)
        out[:, 0] = self.ends[0][..., None]
        out[:, -1] = self.ends[1][..., None]
        m = self.phi.shape[1]
        x = np.matmul(self.phi, _float_view(self.z[:, :m])).view(complex)  # (R, n_f·d, n_w)
        if self.rc is not None:
            self._add_static(x, np.transpose(self.rc, (0, 2, 1)))
        out[:, 1:-1] = x.reshape(n_r, n - 2, d, n_w)
        return out if dtype is None else out.astype(dtype)

    def transfer(self, unit: np.ndarray) -> np.ndarray:
        """The rows per unit load case ``unit`` (n_nodes, d, n_load) (real node forces,
        dense or a scipy sparse (n_load, n_nodes·d) matrix of them): shape (R, n_load,
        n_w), the cases projected on the modes first. [N/unit]"""
        n_r, n, d, n_w = self.shape
        if sparse.issparse(unit):
            u_t = sparse.csr_matrix(unit)
            u_end = (u_t[:, :d].toarray(), u_t[:, (n - 1) * d :].toarray())  # (L, d)
            u_f = u_t[:, d : (n - 1) * d]
            a = np.asarray(u_f @ self.phi)  # (L, m)
        else:
            unit = np.asarray(unit, dtype=float)
            u_end = (unit[0].T, unit[-1].T)
            u_f = unit[1:-1].reshape((n - 2) * d, -1).T  # (L, n_f·d)
            a = u_f @ self.phi
        m = a.shape[1]
        c = self.z.shape[1] - m  # (the static coordinates' rows)
        rows = self._marked()[1]  # (ê on the end rows only: the others' are 0)
        if c == 0:
            h = np.matmul(a, _float_view(self.z)).view(complex)  # (R, L, n_w)
            if rows is not None:
                end = self.ends[:, rows]
                h[rows] += (end[0] @ u_end[0].T + end[1] @ u_end[1].T)[..., None]
            return h
        # each row's loads on the modes and on its static rows r₀ (+ ê), r₁, r₂: their
        # coordinates z's last c rows, all in one product per row
        three = np.ascontiguousarray(np.transpose(self.rc[:c], (1, 0, 2))).reshape(
            self.rc.shape[1], -1
        )
        prod = u_f @ three if np.isrealobj(three) or sparse.issparse(u_f) else real_gemm(u_f, three)
        coef = np.asarray(prod).reshape(-1, c, n_r)  # (L, c, R)
        a_r = np.empty((n_r, a.shape[0], m + c), dtype=coef.dtype)  # (R, L, m + c)
        a_r[:, :, :m] = a
        a_r[:, :, m:] = np.transpose(coef, (2, 0, 1))
        if rows is not None:
            end = self.ends[:, rows]
            a_r[rows, :, m] += end[0] @ u_end[0].T + end[1] @ u_end[1].T
        if np.isrealobj(a_r):
            return np.matmul(a_r, _float_view(self.z)).view(complex)  # (R, L, n_w)
        return np.matmul(a_r, self.z)  # (complex static rows: a complex product)


def _float_view(z: np.ndarray) -> np.ndarray:
    """Complex ``z`` (…, n) as floats (…, 2n), a view where its last axis is contiguous
    (a run of rows, the leading lines), else of a contiguous copy (every step-th
    line)."""
    if z.strides[-1] != z.itemsize:
        z = np.ascontiguousarray(z)
    return z.view(float)


def _rows_of(mark: np.ndarray) -> slice | np.ndarray | None:
    """The rows ``mark`` (bool) holds: None where none, a slice where they are a run (a
    view, not a copy), else their indices."""
    at = np.flatnonzero(mark)
    if at.size == 0:
        return None
    if at[-1] - at[0] + 1 == at.size:
        return slice(int(at[0]), int(at[-1]) + 1)
    return at
