"""Block-banded numerics of one line and its frequency-independent arrays.

One line's matrices are block-tridiagonal in node-major DOFs (element j joins nodes j
and j+1).  They are held as node blocks D (n_nodes, d, d) and O (n_el, d, d) with
O[j] = A[node j+1, node j] (all matrices here are symmetric, A[j, j+1] = O[j]ᵀ), so
loads, couplings to the prescribed end nodes and reactions are a few einsums, and the
free–free solve is one stacked banded LAPACK call over all frequencies
(:func:`stochcable.dynamics.model.solvers.solve_block_tridiagonal`).  No scipy.sparse in the
loop.  :class:`LinePrep` (one per :class:`~stochcable.dynamics.model.system.LineSystem`,
:func:`line_prep`) holds the blocks of K, M_T and the structural damping, their band
storage, the banded Cholesky of K_ff and the modal matrices: everything the solves
need that depends neither on the sea nor on the drag.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from stochcable.compiled import KERNEL_MIN_ENTRIES, optional_kernel
from stochcable.dynamics.model.solvers import MatrixLike, band_from_blocks, tridiagonal_blocks
from stochcable.dynamics.model.system import (
    LineSystem,
)
from stochcable.errors import (
    InputError,
    SolverError,
)
from stochcable.line.fem import FEModel


def _band_kernel() -> Callable[[np.ndarray, np.ndarray], np.ndarray] | None:
    """:func:`stochcable.dynamics.model.band_kernels.cholesky_band_solve`, or None without
    numba or with ``STOCHCABLE_NUMBA=0`` (SciPy's ``cho_solve_banded`` then)."""
    return optional_kernel("stochcable.dynamics.model.band_kernels", "cholesky_band_solve")


# -------------------------------------------------------------------- linearization


def trapezoid_weights(w: np.ndarray) -> np.ndarray:
    """Trapezoid-rule weights q of the grid w (Σ q_j f(w_j) ≈ ∫f dω), (n_omega,). [rad/s]"""
    q = np.zeros_like(w)
    if w.size > 1:
        dw = np.diff(w)
        q[:-1] += 0.5 * dw
        q[1:] += 0.5 * dw
    return q


# --------------------------------------------------------------- block-banded core
#
# One line's matrices are block-tridiagonal in node-major DOFs (element j joins nodes
# j and j+1).  They are held as node blocks D (n_nodes, d, d) and O (n_el, d, d) with
# O[j] = A[node j+1, node j] (all matrices here are symmetric, A[j, j+1] = O[j]ᵀ), so
# loads, couplings to the prescribed end nodes and reactions are a few einsums, and
# the free–free solve is one stacked banded LAPACK call over all frequencies
# (:func:`stochcable.dynamics.model.solvers.solve_block_tridiagonal`).  No scipy.sparse in the loop.

NodeBlocks = tuple[np.ndarray, np.ndarray]


def node_blocks(a: MatrixLike, d: int) -> NodeBlocks:
    """Node blocks (D, O) of a symmetric block-tridiagonal model matrix.

    A canonical CSR matrix (sorted, no duplicates: the FE assembly's) is read from its
    index arrays directly, 5x faster than
    :func:`stochcable.dynamics.model.solvers.tridiagonal_blocks`
    (scipy's COO conversion and checks were ≈ 0.8 ms of every analysis of the
    reference chain); anything else, or entries outside the pattern, goes through
    that function (same values, its error messages)."""
    stash = getattr(a, "_node_blocks", None)  # assembled from node blocks (fem)
    if (
        stash is not None
        and stash[1].shape[1:] == (d, d)
        and stash[0].shape == a.data.shape
        and np.array_equal(stash[0], a.data)
    ):
        return stash[1].copy(), stash[2].copy()
    if (
        isinstance(a, (sp.csr_array, sp.csr_matrix))
        and a.has_canonical_format
        and a.shape[0] == a.shape[1]
        and a.shape[0] % d == 0
    ):
        n = a.shape[0]
        rows = np.repeat(np.arange(n), np.diff(a.indptr))
        cols = a.indices
        bi, bj = rows // d, cols // d
        off = bi - bj
        if not np.any(np.abs(off) > 1):
            nb = n // d
            dtype = np.result_type(a.data.dtype, float)
            diag = np.zeros((nb, d, d), dtype=dtype)
            lower = np.zeros((nb, d, d), dtype=dtype)
            sel = off == 0
            diag[bi[sel], rows[sel] % d, cols[sel] % d] = a.data[sel]
            sel = off == 1
            lower[bi[sel], rows[sel] % d, cols[sel] % d] = a.data[sel]
            return diag, lower[1:]
    diag, lower, _ = tridiagonal_blocks(a, d)
    return diag, lower[1:]


def element_blocks(model: FEModel, blocks3: np.ndarray) -> np.ndarray:
    """Per-unit-length element matrices (n_el, 3, 3) times l0 on the model components,
    (n_el, d, d)."""
    comps = list(model.components)
    return np.ascontiguousarray(blocks3[:, comps][:, :, comps] * model.l0[:, None, None])


def element_load(b: np.ndarray, mom: np.ndarray) -> np.ndarray:
    """Node loads Σ_elements b_j·[m_a, m_b] from element blocks b (n_el, d, d) (real,
    l0 included) and consistent moments mom (n_el, 2, d, ...) (complex):
    (n_nodes, d, ...)."""
    n_el, _, d = mom.shape[:3]
    mf = np.ascontiguousarray(mom).reshape(n_el, 2, d, -1).view(float)
    # side-major output (contiguous r[0], r[1]); 5x faster than stacked d×d matmuls
    r = np.einsum("eij,esjn->sein", b, mf)
    out = np.empty((n_el + 1, d, mf.shape[-1]))
    out[:-1] = r[0]
    out[-1] = 0.0
    out[1:] += r[1]
    return out.view(complex).reshape((n_el + 1, d) + mom.shape[3:])


def blocks_of_elements(
    model: FEModel, blocks3: np.ndarray, node_diag: np.ndarray | None
) -> NodeBlocks:
    """Node blocks of per-unit-length element matrices (n_el, 3, 3) distributed like the
    model's mass (as :func:`stochcable.dynamics.loads.channels.drag_matrix` assembles them)."""
    return distribute(model, element_blocks(model, blocks3), node_diag)


def distribute(model: FEModel, b: np.ndarray, node_diag: np.ndarray | None) -> NodeBlocks:
    """:func:`blocks_of_elements` of the element blocks b (n_el, d, d) (l0
    included, :func:`element_blocks`)."""
    pat = (
        np.array([[0.5, 0.0], [0.0, 0.5]])
        if model.mass_matrix == "lumped"
        else np.array([[1.0 / 3.0, 1.0 / 6.0], [1.0 / 6.0, 1.0 / 3.0]])
    )
    D = np.zeros((model.n_nodes, model.dim, model.dim))
    D[:-1] += pat[0, 0] * b
    D[1:] += pat[1, 1] * b
    if node_diag is not None and np.any(node_diag):
        D += node_diag[:, None, None] * np.eye(model.dim)[None]
    return D, pat[1, 0] * b


def add_blocks(*blks: NodeBlocks, scale: tuple[float, ...] | None = None) -> NodeBlocks:
    """Σ scale_i·A_i of node blocks (D, O) (scale 1 by default)."""
    if scale is None and len(blks) == 2:  # the per-iteration C_s + C_d: one add each
        (d0, o0), (d1, o1) = blks
        return d0 + d1, o0 + o1
    s = (1.0,) * len(blks) if scale is None else scale
    return (sum(c * b[0] for c, b in zip(s, blks)), sum(c * b[1] for c, b in zip(s, blks)))


def free_band(blk: NodeBlocks) -> np.ndarray:
    """LAPACK band storage (half-bandwidth 2d − 1) of the free–free block (interior
    nodes)."""
    D, O = blk
    inner = O[1:-1]
    n_f, d = D.shape[0] - 2, D.shape[1]
    lower = np.zeros((n_f, d, d))
    upper = np.zeros((n_f, d, d))
    lower[1:] = inner
    upper[:-1] = np.swapaxes(inner, 1, 2)
    return band_from_blocks((D[1:-1], lower, upper))


def block_matvec(blk: NodeBlocks, x: np.ndarray) -> np.ndarray:
    """A x for node vectors x (n_nodes, d, ...) -> same shape.

    The node axis leads and frequencies/channels trail, so each node block is one
    (d × d) @ (d × n_w·n_ch) product: a stacked matmul of n_nodes large products."""
    D, O = blk
    cplx = np.iscomplexobj(x) and not np.iscomplexobj(D)
    xr = np.ascontiguousarray(x).reshape(x.shape[0], x.shape[1], -1)
    if cplx:  # real blocks times complex vectors as real products (no upcast of D)
        xr = xr.view(float)
    y = D @ xr
    y[1:] += O @ xr[:-1]
    y[:-1] += np.swapaxes(O, 1, 2) @ xr[1:]
    if cplx:
        y = y.view(complex)
    return y.reshape(x.shape)


def real_gemm(a: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Real (p, q) matrix times complex (q, k) C-contiguous matrix as ONE real product
    on the interleaved (q, 2k) view (numpy would upcast ``a`` to complex: 4x the
    work)."""
    q, k = x.shape
    return (a @ x.view(float).reshape(q, 2 * k)).view(complex)


def to_freq(x: np.ndarray) -> np.ndarray:
    """Free node vectors (n_f, d, n_w, k) -> (n_w, n_f·d, k), contiguous."""
    n_f, d, n_w, k = x.shape
    if x.dtype == complex and x.flags.c_contiguous and k > 0:
        # the k channels of one (node, component, ω) move as one block: a 2-D transpose
        # of k·16-byte items (numpy's copy of 16-byte items in k-pairs was 2x slower)
        item = np.dtype((np.void, 16 * k))
        v = x.reshape(n_f * d, n_w, k).view(item)[..., 0]  # (n_f·d, n_w)
        return np.ascontiguousarray(v.T).view(complex).reshape(n_w, n_f * d, k)
    return np.ascontiguousarray(np.transpose(x, (2, 0, 1, 3))).reshape(n_w, n_f * d, k)


def from_freq(x: np.ndarray, d: int) -> np.ndarray:
    """(n_w, n_f·d, k) -> (n_f, d, n_w, k)."""
    n_w, nf, k = x.shape
    return np.transpose(x.reshape(n_w, nf // d, d, k), (1, 2, 0, 3))


# Free DOFs up to which the residual flexibility is held as a dense matrix.
_DENSE_FLEX = 600


class LinePrep:
    """Frequency-independent arrays of one line for the block-banded solves."""

    def __init__(self, system: LineSystem) -> None:
        model = system.model
        d = model.dim
        n = model.n_nodes
        fixed_ok = np.array_equal(model.fixed, np.r_[np.arange(d), (n - 1) * d + np.arange(d)])
        if not fixed_ok or n < 3:
            raise InputError(
                "model.fixed",
                model.fixed,
                "-",
                "the line solve needs both end nodes prescribed and at least one free node",
            )
        alpha, beta = system.structural_damping
        self.d, self.n = d, n
        self._system = system
        self.K = node_blocks(model.K, d)
        bm, bma = node_blocks(model.M, d), node_blocks(model.Ma, d)
        # M_T = M + Ma entry by entry (the blocks of the CSR sum, to the bit)
        self.MT = (bm[0] + bma[0], bm[1] + bma[1])
        seabed = node_blocks(model.Cs, d)
        # structural damping: seabed dashpots + Rayleigh alpha·M_T + beta·K
        self.S = add_blocks(seabed, self.MT, self.K, scale=(1.0, alpha, beta))
        self.bK = free_band(self.K)
        #: frequency-independent arrays computed on first use (modal matrices, residual
        #: flexibility, end basis, …), keyed by what they depend on
        self.cache: dict[Any, Any] = {}
        self._chol: np.ndarray | None = None

    # used by the direct solve, its conditioning check and hand-built channels only:
    # computed on first use (≈ 0.2 ms of every Foss analysis of the reference chain)
    @functools.cached_property
    def BI(self) -> NodeBlocks:
        """Node blocks of the Morison inertia matrix (nodal accelerations)."""
        return node_blocks(self._system.b_inertia, self.d)

    @functools.cached_property
    def bM(self) -> np.ndarray:
        """Band storage of the free–free M_T."""
        return free_band(self.MT)

    @functools.cached_property
    def bS(self) -> np.ndarray:
        """Band storage of the free–free structural damping."""
        return free_band(self.S)

    @functools.cached_property
    def norm_K(self) -> float:
        """Frobenius norm of the free–free K band (the conditioning estimate). [N/m]"""
        return float(np.sqrt(np.sum(self.bK**2)))

    @functools.cached_property
    def norm_M(self) -> float:
        """Frobenius norm of the free–free M_T band (the conditioning estimate). [kg]"""
        return float(np.sqrt(np.sum(self.bM**2)))

    # K_ff^-1 by banded Cholesky (K_ff is SPD: tensions > 0 or slack EA > 0)
    def k_solve(self, rhs: np.ndarray) -> np.ndarray:
        """K_ff⁻¹ rhs for rhs (n_free_dof, m) real or complex."""
        if self._chol is None:
            u = 2 * self.d - 1
            upper = self.bK[: u + 1]  # rows 0..u hold the upper band (ab[u + i - j, j])
            try:
                self._chol = sla.cholesky_banded(upper, lower=False, check_finite=False)
            except np.linalg.LinAlgError:
                raise SolverError(
                    "static correction: K_ff is not positive definite (check the static tensions)"
                ) from None
        kernel = _band_kernel() if rhs.size >= KERNEL_MIN_ENTRIES else None
        if kernel is not None and rhs.ndim == 2:  # row sweeps, no transposes (band_kernels)
            return kernel(self._chol, rhs)
        c = (self._chol, False)
        if np.iscomplexobj(rhs):
            # real K: the (re, im) columns of the interleaved real view in one solve
            n, k = rhs.shape
            x = np.ascontiguousarray(rhs, dtype=complex).view(float).reshape(n, 2 * k)
            y = sla.cho_solve_banded(c, x, check_finite=False)
            return np.ascontiguousarray(y).view(complex)
        return sla.cho_solve_banded(c, rhs, check_finite=False)

    def residual(
        self, system: LineSystem, rhs: np.ndarray, modal: np.ndarray | None = None
    ) -> np.ndarray:
        """Static correction of the truncated modes, (K_ff⁻¹ − Φ K̂⁻¹ Φᵀ) rhs, rhs of
        shape (n_free_dof, k) complex (C-contiguous): an explicit dense residual
        flexibility (one matrix product) up to ``_DENSE_FLEX`` free DOFs, else the
        banded Cholesky with the modal part as real products (``modal``: Φᵀ rhs, (m,
        k), when the caller has it)."""
        phi, _, kh = self.modal(system)
        nf = phi.shape[0]
        if nf > _DENSE_FLEX:
            fh = real_gemm(phi.T, rhs) if modal is None else modal
            zh = np.linalg.solve(kh, fh.view(float))
            out = self.k_solve(rhs)
            out -= real_gemm(phi, np.ascontiguousarray(zh).view(complex))
            return out
        key = ("flex", phi.shape[1])
        if key not in self.cache:
            flex = self.k_solve(np.eye(nf)) - phi @ np.linalg.solve(kh, phi.T)
            self.cache[key] = 0.5 * (flex + flex.T)
        flex = self.cache[key]
        k = rhs.shape[1]
        out = flex @ np.ascontiguousarray(rhs).view(float).reshape(nf, 2 * k)
        return out.view(complex)

    def follower(self) -> np.ndarray:
        """G with U_f = G u_b the static following of the end displacements,
        G = −K_ff⁻¹K_fb, shape (n_free_dof, 2d)."""
        if "follower" not in self.cache:
            d, n = self.d, self.n
            kfb = np.zeros(((n - 2) * d, 2 * d))
            kfb[:d, :d] = self.K[1][0]
            kfb[-d:, d:] = self.K[1][-1].T
            self.cache["follower"] = -self.k_solve(kfb)
        return self.cache["follower"]

    def end_basis(self, direct: bool) -> tuple[np.ndarray, ...]:
        """(G, M_T G, C_s G, K G) as (n_nodes·d, 2d) real matrices: the node
        displacements U_p = G u_b of unit end displacements u_b (end_a's d components,
        then end_b's) — zero inside for the direct solve, the static following
        (:meth:`follower`) inside for Foss — and their products with M_T, the
        structural damping and K (K G only for the direct solve)."""
        key = ("end_basis", bool(direct))
        if key not in self.cache:
            d, n = self.d, self.n
            g = np.zeros((n, d, 2 * d))
            g[0, :, :d] = np.eye(d)
            g[-1, :, d:] = np.eye(d)
            if not direct:
                g[1:-1] = self.follower().reshape(n - 2, d, 2 * d)
            flat = (n * d, 2 * d)
            self.cache[key] = (
                g.reshape(flat),
                block_matvec(self.MT, g).reshape(flat),
                block_matvec(self.S, g).reshape(flat),
                block_matvec(self.K, g).reshape(flat) if direct else None,
            )
        return self.cache[key]

    def modal(
        self, system: LineSystem, m: int | None = None
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(Φ_f, M̂, K̂) of the first ``m`` computed modes on the free DOFs (default the
        kept ones, ``system.n_modes``)."""
        m = int(system.n_modes) if m is None else int(m)
        if m not in self.cache:
            phi = np.ascontiguousarray(system.modes.shapes[system.model.free][:, :m])
            x = self.nodes(phi)
            mh = phi.T @ self.free_rows(block_matvec(self.MT, x))
            kh = phi.T @ self.free_rows(block_matvec(self.K, x))
            self.cache[m] = (phi, 0.5 * (mh + mh.T), 0.5 * (kh + kh.T))
        return self.cache[m]

    def nodes(self, free: np.ndarray) -> np.ndarray:
        """(n_free_dof, k) -> node vectors (n_nodes, d, k) with zero ends."""
        k = free.shape[1]
        x = np.zeros((self.n, self.d, k), dtype=free.dtype)
        x[1:-1] = free.reshape(self.n - 2, self.d, k)
        return x

    def free_rows(self, y: np.ndarray) -> np.ndarray:
        """Node vectors (n_nodes, d, ...) -> free rows (n_free_dof, ...)."""
        return y[1:-1].reshape(((self.n - 2) * self.d,) + y.shape[2:])


def line_prep(system: LineSystem) -> LinePrep:
    """The :class:`LinePrep` of a line, built on first use and cached on the system."""
    cache = system._cache
    if "prep" not in cache:
        cache["prep"] = LinePrep(system)
    return cache["prep"]
