"""Natural modes of a line about its static shape: K φ = ω² M_T φ (DESIGN.md "Modes").

The generalized symmetric eigenproblem on the free DOFs of an :class:`~stochcable.line.fem.FEModel`
is solved by one of three methods:

- ``"dense"``: LAPACK ``eigh`` with ``subset_by_index`` (robust; O(n³)).
- ``"banded"``: ARPACK shift-invert Lanczos (``eigsh``) with the shifted matrix
  factored by banded Cholesky (``cholesky_banded``; O(n·b²) per factorization and
  O(n·b) per solve).
- ``"sparse"``: ARPACK shift-invert with a sparse LU (``splu``).

``"auto"`` takes ``"dense"`` up to ``DENSE_MAX_DOF`` free DOFs (in the largest
decoupled block) and ``"banded"`` above (crossover measured in
benchmarks/bench_modes.py).  When every block is solved densely (``"dense"``, or
``"auto"`` with at most ``DENSE_MAX_DOF`` free DOFs) the free–free matrices are taken
dense from the start and rotated by node blocks, in the order of the sparse products
of the other path (the same numbers to the bit, docs/BENCHMARKS.md pass E6).
Before solving, the DOF components that the matrices do not couple (for a line in the
x–z plane, y is decoupled from x and z; for a vertical line all three are) are split
into independent smaller problems, which also makes exact in-plane/out-of-plane
degeneracies harmless.  The Lanczos results are checked with a
Sturm count (the inertia of K − θM_T, Sylvester's law): if the number of eigenvalues
below the gap after the last requested mode differs from the number found, the block is
re-solved densely, so modes near a crossover are never dropped or duplicated.

References
----------
Bliet, A. (1984), Dynamic analysis of single span cables, PhD thesis, Massachusetts
Institute of Technology.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from stochcable.errors import InputError, PhysicsWarning, SolverError, warn
from stochcable.line.fem import FEModel
from stochcable.validation import positive_int

__all__ = ["DENSE_MAX_DOF", "Modes", "natural_modes", "plane_normal"]

#: Largest free-DOF block solved densely by ``method="auto"`` (benchmarks/bench_modes.py:
#: dense eigh wins below ~250 DOFs for 30 modes on 2 cores).
DENSE_MAX_DOF = 250
#: Energy fraction thresholds of the plane classification.
PLANE_TOL = 1.0e-3
# Relative size below which a matrix entry is round-off, not a coupling.
_COUPLING_TOL = 1.0e-13


@dataclass(frozen=True, eq=False)
class Modes:
    """Natural modes of one line.

    Attributes
    ----------
    omega : ndarray, shape (count,)
        Natural angular frequencies, ascending. [rad/s]
    shapes : ndarray, shape (n_dof, count)
        Mode shapes on all model DOFs (zeros at prescribed DOFs), normalized so that
        φᵀ M_T φ = 1 with M_T the mass used (M, plus Ma when ``added_mass``). [kg^-1/2]
    plane : ndarray of str, shape (count,)
        "in-plane", "out-of-plane" or "mixed" with respect to the vertical plane of the
        line (normal :attr:`normal`); every mode of a 2-D model is "in-plane".
    out_of_plane : ndarray, shape (count,)
        Fraction of the modal kinetic energy in the out-of-plane component. [-]
    normal : ndarray, shape (3,)
        Unit normal of the line's vertical plane. [-]
    method : str
        Eigen-solver used ("dense", "banded", "sparse", or a combination "a+b").
    added_mass : bool
        Whether the added mass is in M_T.
    """

    omega: np.ndarray
    shapes: np.ndarray
    plane: np.ndarray
    out_of_plane: np.ndarray
    normal: np.ndarray
    method: str
    added_mass: bool

    @property
    def count(self) -> int:
        """Number of modes."""
        return int(self.omega.size)

    @property
    def period(self) -> np.ndarray:
        """Natural periods 2π/ω (inf for a zero frequency). [s]"""
        with np.errstate(divide="ignore"):
            return np.where(
                self.omega > 0, 2.0 * np.pi / np.where(self.omega > 0, self.omega, 1.0), np.inf
            )

    def to_document(self) -> dict[str, list]:
        """{"omega": [rad/s], "period": [s] (null for a zero frequency), "plane": [...]}."""
        period = [float(p) if np.isfinite(p) else None for p in self.period]
        return {
            "omega": [float(w) for w in self.omega],
            "period": period,
            "plane": [str(p) for p in self.plane],
        }


# ------------------------------------------------------------------ plane geometry


def plane_normal(positions: np.ndarray) -> np.ndarray:
    """Unit normal of the vertical plane of a line.

    Parameters
    ----------
    positions : array_like, shape (n_nodes, 3)
        Node positions. [m]

    Returns
    -------
    ndarray, shape (3,)
        ẑ × (horizontal chord), normalized; for a vertical chord, the horizontal
        direction of least spread of the nodes; +y when the line has no horizontal
        extent at all.
    """
    p = np.asarray(positions, dtype=float)
    scale = max(float(np.ptp(p, axis=0).max()), 1.0)
    chord = p[-1] - p[0]
    h = np.array([chord[0], chord[1], 0.0])
    if np.linalg.norm(h) > 1e-9 * scale:
        # ẑ × h written out: the products and differences of np.cross([0, 0, 1], h)
        # in its order (the same bits, signed zeros included), without its generic path
        h0, h1 = float(h[0]), float(h[1])
        n = np.array([0.0 * 0.0 - 1.0 * h1, 1.0 * h0 - 0.0 * 0.0, 0.0 * h1 - 0.0 * h0])
        return n / np.linalg.norm(n)
    q = p[:, :2] - p[:, :2].mean(axis=0)
    if np.abs(q).max() <= 1e-9 * scale:
        return np.array([0.0, 1.0, 0.0])
    _, vecs = np.linalg.eigh(q.T @ q)
    return np.array([vecs[0, 0], vecs[1, 0], 0.0])  # least-spread horizontal direction


# ------------------------------------------------------------------------ solvers


def _component_groups(d: int, a: sp.csr_array, b: sp.csr_array) -> list[list[int]]:
    """Components (DOF index mod d) grouped by coupling in A or B (union-find)."""
    parent = list(range(d))

    def find(i: int) -> int:
        while parent[i] != i:
            i = parent[i]
        return i

    for mat in (a, b):
        if isinstance(mat, (sp.csr_array, sp.csr_matrix)):
            # the row of every stored entry straight from the CSR pointers (the COO
            # conversion and its checks were half of this function's time)
            rows = np.repeat(np.arange(mat.shape[0]), np.diff(mat.indptr))
            cols, data = mat.indices, mat.data
        elif isinstance(mat, np.ndarray) and mat.shape[0] % d == 0:
            # dense: the largest magnitude of each component pair (i, j) in one
            # reduction (np.nonzero of the matrix was 40 µs)
            nb = mat.shape[0] // d
            big = (
                np.abs(mat)
                .reshape(nb, d, nb, d)
                .transpose(1, 3, 0, 2)
                .reshape(d, d, -1)
                .max(axis=-1)
            )  # (a reduction over two strided axes is 10x slower)
            strong = big > _COUPLING_TOL * big.max(initial=0.0)
            for i, j in zip(*np.nonzero(strong)):
                ri, rj = find(int(i)), find(int(j))
                if ri != rj:
                    parent[ri] = rj
            continue
        else:
            coo = sp.coo_array(mat)
            rows, cols, data = coo.row, coo.col, coo.data
        ci, cj = rows % d, cols % d
        # entries at round-off level (after the rotation into the line's plane) do
        # not couple
        nz = np.abs(data) > _COUPLING_TOL * np.abs(data).max(initial=0.0)
        # the distinct component pairs (i, j) as flat indices i·d + j (a 1-D count is
        # ~10x faster than np.unique(axis=1) on the stacked pairs)
        flat = np.flatnonzero(np.bincount((ci[nz] * d + cj[nz]).astype(np.intp), minlength=d * d))
        for i, j in zip(*np.divmod(flat, d)):
            ri, rj = find(int(i)), find(int(j))
            if ri != rj:
                parent[ri] = rj
    groups: dict[int, list[int]] = {}
    for c in range(d):
        groups.setdefault(find(c), []).append(c)
    return list(groups.values())


#: Up to this many DOFs (or when a quarter of the spectrum or more is requested) the
#: dense path computes the whole spectrum (LAPACK sygvd) and keeps the lowest k: about
#: 2x faster than the subset driver (sygvr) on the 78-DOF reference chain.
_DENSE_FULL_DOF = 200


#: LAPACK dsygvd: the driver of ``scipy.linalg.eigh(a, b)`` for the whole spectrum.
_SYGVD = sla.get_lapack_funcs(("sygvd",), (np.zeros((1, 1)),))[0]


def _solve_dense(a: Any, b: Any, k: int) -> tuple[np.ndarray, np.ndarray]:
    n = a.shape[0]
    a = a.toarray() if sp.issparse(a) else a
    b = b.toarray() if sp.issparse(b) else b
    if k < n and (n > _DENSE_FULL_DOF and 4 * k < n):
        return sla.eigh(a, b, subset_by_index=[0, k - 1], check_finite=False)
    if n == 0 or a.dtype != np.float64 or b.dtype != np.float64:
        lam, vec = sla.eigh(a, b, check_finite=False)
        return lam[:k], vec[:, :k]
    # the call scipy.linalg.eigh(a, b) makes (dsygvd, lower triangle, no workspace
    # arguments): the same numbers without ≈ 40 µs of its argument handling
    lam, vec, info = _SYGVD(a, b, itype=1, jobz="V", uplo="L")
    if info != 0:
        raise np.linalg.LinAlgError(
            f"dsygvd failed (info = {info}): the mass matrix is not positive definite "
            "or the eigenvalue iteration did not converge"
        )
    return lam[:k], vec[:, :k]


def _shift(a: sp.csr_array, b: sp.csr_array) -> float:
    """A negative shift of the order of the lowest eigenvalue (A − σB is then SPD)."""
    da, db = a.diagonal(), b.diagonal()
    ratio = da / np.where(db > 0, db, np.inf)
    pos = ratio[ratio > 0]
    if pos.size == 0:
        return -1.0
    n = max(a.shape[0], 1)
    return -float(pos.min()) / n**2 - 1e-300


def _banded_opinv(a: sp.csr_array, b: sp.csr_array, sigma: float, u: int) -> Any:
    import scipy.sparse.linalg as spla  # (here: ~10 ms of import most analyses skip)

    from stochcable.line.fem import _to_upper_banded

    ab = _to_upper_banded((a - sigma * b).tocsr(), u)
    c = sla.cholesky_banded(ab, lower=False, check_finite=False)
    n = a.shape[0]
    return spla.LinearOperator(
        (n, n),
        dtype=float,
        matvec=lambda x: sla.cho_solve_banded((c, False), x, check_finite=False),
    )


def _solve_lanczos(
    a: sp.csr_array, b: sp.csr_array, k: int, method: str, u: int
) -> tuple[np.ndarray, np.ndarray]:
    import scipy.sparse.linalg as spla  # (here: ~10 ms of import most analyses skip)

    n = a.shape[0]
    sigma = _shift(a, b)
    kk = min(k + 2, n - 1)  # two beyond the request: a gap for the Sturm check
    if method == "banded":
        try:
            opinv = _banded_opinv(a, b, sigma, u)
        except np.linalg.LinAlgError:
            opinv = None  # not SPD (should not happen with T >= 0): use LU
    else:
        opinv = None
    v0 = np.ones(n) / np.sqrt(n)  # deterministic start vector
    ncv = min(n, max(2 * kk + 1, kk + 20))
    lam, vec = spla.eigsh(
        a, k=kk, M=b, sigma=sigma, which="LM", OPinv=opinv, v0=v0, ncv=ncv, tol=1e-13, mode="normal"
    )
    order = np.argsort(lam)
    lam, vec = lam[order], vec[:, order]
    # Sturm check: exactly k eigenvalues below the gap after the k-th.
    theta = 0.5 * (lam[k - 1] + lam[k]) if kk > k else lam[k - 1] * (1 + 1e-8) + 1e-300
    if _count_below(a, b, theta) != k or lam[k - 1] == lam[k]:
        raise _SturmMismatch
    return lam[:k], vec[:, :k]


class _SturmMismatch(Exception):
    pass


def _count_below(a: sp.csr_array, b: sp.csr_array, theta: float) -> int:
    """Number of eigenvalues of (A, B) below theta: negative pivots of LDLᵀ(A − θB)."""
    import scipy.sparse.linalg as spla  # (here: ~10 ms of import most analyses skip)

    s = (a - theta * b).tocsc()
    lu = spla.splu(s, permc_spec="NATURAL", diag_pivot_thresh=0.0, options={"SymmetricMode": True})
    if not (
        np.array_equal(lu.perm_r, np.arange(s.shape[0]))
        and np.array_equal(lu.perm_c, np.arange(s.shape[0]))
    ):
        return int((sla.eigvalsh(s.toarray(), b.toarray()) < theta).sum())
    return int((lu.U.diagonal() < 0).sum())


def _solve_block(a, b, k, method, u):
    n = a.shape[0]
    if method == "auto":
        method = "dense" if n <= DENSE_MAX_DOF else "banded"
    if method == "dense" or k >= n - 2:
        lam, vec = _solve_dense(a, b, k)
        return lam, vec, "dense"
    import scipy.sparse.linalg as spla  # (here: ~10 ms of import most analyses skip)

    try:
        lam, vec = _solve_lanczos(a, b, k, method, u)
        return lam, vec, method
    except (_SturmMismatch, spla.ArpackNoConvergence, spla.ArpackError):
        lam, vec = _solve_dense(a, b, k)
        return lam, vec, "dense"


def _dense_free(model: FEModel, matrix: Any) -> np.ndarray:
    """Dense free–free block of a sparse model matrix (a slice when the free DOFs are
    one contiguous range, as with both ends prescribed)."""
    full = matrix.toarray() if sp.issparse(matrix) else np.asarray(matrix)
    free = model.free
    if int(free[-1]) - int(free[0]) + 1 == free.size:
        lo, hi = int(free[0]), int(free[-1]) + 1
        return np.ascontiguousarray(full[lo:hi, lo:hi])
    return full[np.ix_(free, free)]


def _rotate_dense(a: np.ndarray, r: np.ndarray) -> np.ndarray:
    """Rᵀ A R with R = diag(r, r, …) (3×3 node blocks), A dense (3·n_b)².

    The sums run in the order of the sparse products ``(rot.T @ a) @ rot`` of the
    sparse path (ascending inner index, left to right), so the result is that
    product's to the bit: a term with a zero entry of r adds a signed zero, which
    leaves a sum unchanged."""
    nb = a.shape[0] // 3
    a4 = a.reshape(nb, 3, nb, 3)
    t = np.empty_like(a4)
    for i in range(3):  # (Rᵀ A)[·, i, ·, l] = Σ_k r[k, i] A[·, k, ·, l]
        t[:, i] = r[0, i] * a4[:, 0] + r[1, i] * a4[:, 1] + r[2, i] * a4[:, 2]
    out = np.empty_like(a4)
    for j in range(3):  # (T R)[·, i, ·, j] = Σ_l T[·, i, ·, l] r[l, j]
        out[:, :, :, j] = (
            t[:, :, :, 0] * r[0, j] + t[:, :, :, 1] * r[1, j] + t[:, :, :, 2] * r[2, j]
        )
    return out.reshape(a.shape)


def _unrotate_dense(x: np.ndarray, r: np.ndarray) -> np.ndarray:
    """R x with R = diag(r, r, …), x (3·n_b, k): the sums of the sparse ``rot @ x``."""
    nb = x.shape[0] // 3
    x3 = x.reshape(nb, 3, -1)
    out = np.empty_like(x3)
    for i in range(3):
        out[:, i] = r[i, 0] * x3[:, 0] + r[i, 1] * x3[:, 1] + r[i, 2] * x3[:, 2]
    return out.reshape(x.shape)


def natural_modes(
    model: FEModel,
    count: int | None = None,
    added_mass: bool = True,
    method: Literal["auto", "dense", "banded", "sparse"] = "auto",
) -> Modes:
    """Lowest natural modes of a line model.

    Parameters
    ----------
    model : FEModel
        The linear model (:func:`stochcable.line.fem.assemble`).
    count : int, optional
        Number of modes, lowest first; default all free DOFs (min(count, n_free) are
        returned).
    added_mass : bool
        Include the added mass in the modal mass (modes in water) or not (in air).
    method : {"auto", "dense", "banded", "sparse"}
        Eigen-solver; see the module docstring.

    Returns
    -------
    Modes
        Frequencies, mass-normalized shapes and plane classification.

    Notes
    -----
    Solves K_ff φ = ω² M_T,ff φ on the free DOFs (DESIGN.md "Modes"; Bliet (1984), ch. 3
    for the closed forms it reproduces).  Eigenvalues below zero by round-off are
    reported as ω = 0.  The out-of-plane fraction of a mode is
    E_n/(E_n + E_p), E = uᵀ M_T u of the displacement projected on the plane normal n
    (E_n) and on the plane (E_p); "in-plane" below ``PLANE_TOL``, "out-of-plane"
    above 1 − ``PLANE_TOL``, "mixed" between.
    """
    if not isinstance(model, FEModel):
        raise InputError("model", type(model).__name__, "-", "must be an FEModel")
    if model.mesh.axial_speed != 0.0:  # docs/travelling.md
        warn(f"line '{model.mesh.name}' travels: these are its modes at rest", PhysicsWarning)
    if method not in ("auto", "dense", "banded", "sparse"):
        raise InputError("method", method, "-", "must be auto, dense, banded or sparse")
    n_free = model.free.size
    if n_free == 0:
        raise InputError("model", "no free DOFs", "-", "needs at least one free node")
    k_req = n_free if count is None else positive_int("count", count)
    mt = model._mass_total if added_mass else model.M
    d = model.dim
    normal = plane_normal(model.positions)
    # the rotation below is the identity to 1e-15 (np.allclose(r, I, rtol=0,
    # atol=1e-15) written out: |ny − 1|, |nx| <= 1e-15)
    planar_frame = d == 2 or (abs(normal[1] - 1.0) <= 1e-15 and abs(normal[0]) <= 1e-15)
    dense = method == "dense" or (method == "auto" and n_free <= DENSE_MAX_DOF)
    rz = (
        np.array([[normal[1], normal[0], 0.0], [-normal[0], normal[1], 0.0], [0.0, 0.0, 1.0]])
        if d == 3
        else None
    )  # columns: local x, y (= normal), z
    rotate = d == 3 and not planar_frame
    a, b, rot, method = _free_matrices(model, mt, dense, method, rz if rotate else None)
    lams, vecs, idxs, used = _solve_groups(a, b, d, k_req, method)
    lam_all = np.concatenate(lams)
    order = np.argsort(lam_all, kind="stable")[: min(k_req, n_free)]
    k = order.size
    local = _group_columns(vecs, idxs, lam_all, order, n_free)
    shapes = np.zeros((model.n_dof, k))
    if rotate:
        local = _unrotate_dense(local, rz) if rot is None else rot @ local
    shapes[model.free] = local
    lam = lam_all[order]
    scale = max(float(np.abs(lam).max()), 1e-300)
    if (lam < -1e-8 * scale).any():
        raise SolverError(
            f"negative eigenvalue {lam.min():.3e} rad²/s²: the stiffness is not positive "
            "semi-definite (check the static tensions)"
        )
    omega = np.sqrt(np.clip(lam, 0.0, None))

    # Mass normalization and a deterministic sign (largest component positive).
    mts = mt @ shapes
    norm = np.sqrt(np.einsum("ij,ij->j", shapes, mts))
    shapes = shapes / norm
    big = np.argmax(np.abs(shapes), axis=0)
    shapes = shapes * np.sign(shapes[big, np.arange(k)])

    frac = _out_of_plane_fraction(model, mt, shapes, normal)
    plane = np.where(
        frac <= PLANE_TOL, "in-plane", np.where(frac >= 1.0 - PLANE_TOL, "out-of-plane", "mixed")
    )
    return Modes(
        omega=omega,
        shapes=shapes,
        plane=plane.astype(str),
        out_of_plane=frac,
        normal=normal,
        method="+".join(sorted(set(used))),
        added_mass=bool(added_mass),
    )


def _free_matrices(
    model: FEModel, mt: Any, dense: bool, method: str, rz: Any
) -> tuple[Any, Any, Any, str]:
    """K_ff and M_T,ff, dense or sparse, rotated about z by ``rz`` (3-D lines off the
    x–z plane; None: not rotated) so that the line's vertical plane is the local x–z
    plane: a planar line's out-of-plane DOFs then decouple exactly from the in-plane
    ones.  Returns (a, b, the sparse rotation or None, the method)."""
    rot = None
    if dense:
        # every block is solved densely: dense free–free matrices from the start (the
        # same numbers as the sparse slices' toarray()), rotated by node blocks in
        # _rotate_dense (the same sums as the sparse R^T A R); no sparse slicing,
        # Kronecker product or sparse products (≈ 2 ms per 40-element 3-D line)
        a = _dense_free(model, model.K)
        b = _dense_free(model, mt)
        method = "dense"
        if rz is not None:
            a = _rotate_dense(a, rz)
            b = _rotate_dense(b, rz)
    else:
        a = model._free_free(model.K)
        b = model._free_free(mt)
        if rz is not None:
            rot = sp.csr_array(sp.kron(sp.eye_array(model.free.size // 3), rz, format="csr"))
            a = (rot.T @ a @ rot).tocsr()
            b = (rot.T @ b @ rot).tocsr()
    return a, b, rot, method


def _solve_groups(a: Any, b: Any, d: int, k_req: int, method: str) -> tuple[list, list, list, list]:
    """The lowest ``k_req`` eigenpairs of every group of coupled components
    (:func:`_component_groups`): eigenvalues, vectors, their free-DOF indices and the
    solver used, per group."""
    n_free = a.shape[0]
    comp_of_free = np.arange(n_free) % d
    lams, vecs, idxs, used = [], [], [], []
    for group in _component_groups(d, a, b):
        in_group = np.zeros(d, dtype=bool)
        in_group[group] = True
        sel = np.flatnonzero(in_group[comp_of_free])
        if sel.size == n_free:  # one coupled group: no slicing
            ag, bg = a, b
        elif not sp.issparse(a):
            ag, bg = a[np.ix_(sel, sel)], b[np.ix_(sel, sel)]
        else:
            ag = a[sel][:, sel].tocsr()
            bg = b[sel][:, sel].tocsr()
        k = min(k_req, sel.size)
        u = 2 * len(group) - 1
        lam, vec, m = _solve_block(ag, bg, k, method, u)
        lams.append(lam)
        vecs.append(vec)
        idxs.append(sel)
        used.append(m)
    return lams, vecs, idxs, used


def _group_columns(
    vecs: list, idxs: list, lam_all: np.ndarray, order: np.ndarray, n_free: int
) -> np.ndarray:
    """The kept group eigenvectors as columns (n_free, k) in the order ``order`` of
    the concatenated eigenvalues: one block copy per group (not per column)."""
    k = order.size
    local = np.zeros((n_free, k))
    starts = np.cumsum([0] + [v.shape[1] for v in vecs])
    rank = np.full(lam_all.size, -1)
    rank[order] = np.arange(k)  # output column of each group eigenvector (-1: dropped)
    for g, vec in enumerate(vecs):
        r = rank[starts[g] : starts[g + 1]]
        kept = np.flatnonzero(r >= 0)
        local[np.ix_(idxs[g], r[kept])] = vec[:, kept]
    return local


def _out_of_plane_fraction(
    model: FEModel, mt: Any, shapes: np.ndarray, normal: np.ndarray
) -> np.ndarray:
    if model.dim == 2:
        return np.zeros(shapes.shape[1])
    d = model.dim
    u = shapes.reshape(model.n_nodes, d, -1)
    un = np.einsum("c,ncj->nj", normal, u)
    pn = (normal[None, :, None] * un[:, None, :]).reshape(model.n_dof, -1)
    pp = shapes - pn
    en = np.einsum("ij,ij->j", pn, mt @ pn)
    ep = np.einsum("ij,ij->j", pp, mt @ pp)
    tot = en + ep
    return np.where(tot > 0, en / np.where(tot > 0, tot, 1.0), 0.0)
