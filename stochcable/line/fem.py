"""Linear finite-element model of a line about its static shape (Tuah (1982), ch. 3.1).

The line is discretized into 2-node straight elements (:mod:`stochcable.line.mesh`); about a
static shape (node positions and element effective tensions) the small-motion model is

    M_T ü + C u̇ + K u = F,   M_T = M + Ma,

with K the exact tangent stiffness (elastic + geometric) plus linear seabed springs, M the
structural mass (consistent, Tuah (1982), eq. 3.1.12) plus lumped attachment masses, Ma the
normal added mass of the line plus attachment added masses, and Cs the seabed contact
damping.  The response engine adds drag damping and loads; :mod:`stochcable.line.modes` solves
K φ = ω² M_T φ.

Degrees of freedom are node-major: DOF ``dim·i + c`` is component ``c`` of node ``i``.
In 3-D the components are (x, y, z); in 2-D (in-plane, the x–z plane) they are (x, z).
Element ``j`` joins nodes ``j`` and ``j + 1``, so every matrix is block-tridiagonal
with ``dim × dim`` blocks: its half-bandwidth (number of super-diagonals) is
``2·dim − 1`` (5 in 3-D, 3 in 2-D), full bandwidth ``4·dim − 1``.  Fixed DOFs are whole
nodes, so the free–free block keeps that bandwidth.  Matrices are stored as
``scipy.sparse.csr_array`` (assembly and partitioning are O(n)); :meth:`FEModel.banded`
gives LAPACK upper banded storage and :meth:`FEModel.dense` a dense copy.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
import scipy.sparse as sp

from stochcable.errors import InputError
from stochcable.line.elements import (
    CONSISTENT_PATTERN,
    LUMPED_PATTERN,
    SLACK_EA_RATIO,
    STIFFNESS_PATTERN,
    added_mass_elements,
    check_dim,
    element_added_mass,
    element_mass,
    element_stiffness,
    expand_blocks,
    stiffness_blocks,
)
from stochcable.line.mesh import LineMesh
from stochcable.line.seabed import bed_contact, split_touchdown_element, tension_rows
from stochcable.scene.model import Environment, Seabed
from stochcable.validation import float_array, positive

__all__ = [
    "SLACK_EA_RATIO",
    "FEModel",
    "element_stiffness",
    "element_mass",
    "element_added_mass",
    "assemble",
    "build_fe_model",
    "chain_csr",
]

_AXES = {"x": 0, "y": 1, "z": 2}
# Tolerance (relative to the line's size) for "the line lies in the x–z plane".
_PLANE_TOL = 1.0e-9


# ---------------------------------------------------------------------- the model


@dataclass(frozen=True, eq=False)
class FEModel:
    """Linear finite-element model of one line about its static shape.

    Attributes
    ----------
    dim : int
        Components per node: 2 (x, z: in-plane) or 3 (x, y, z).
    n_nodes : int
        Number of nodes.
    components : tuple of int
        Global axes of the model components: (0, 2) in 2-D, (0, 1, 2) in 3-D.
    positions : ndarray, shape (n_nodes, 3)
        Static node positions, global frame. [m]
    tangents : ndarray, shape (n_el, dim)
        Unit vector along each element (node j to j+1), model components. [-]
    length : ndarray, shape (n_el,)
        Current (stretched) element length. [m]
    l0 : ndarray, shape (n_el,)
        Unstretched element length. [m]
    tension : ndarray, shape (n_el,)
        Static effective tension per element, as given (may be <= 0 when slack). [N]
    slack : ndarray of bool, shape (n_el,)
        Elements treated as slack (T <= 0: T -> 0, EA -> SLACK_EA_RATIO·EA).
    grounded : ndarray of bool, shape (n_nodes,)
        Nodes in seabed contact (next to the touchdown: the nodes before it).
    K : scipy.sparse.csr_array, shape (n_dof, n_dof)
        Tangent stiffness: elastic + geometric + vertical seabed springs. [N/m]
    M : scipy.sparse.csr_array
        Structural mass + lumped attachment masses. [kg]
    Ma : scipy.sparse.csr_array
        Added mass: normal added mass of the elements + attachment added masses. [kg]
    Cs : scipy.sparse.csr_array
        Seabed contact damping, vertical. [N·s/m]
    free : ndarray of int
        Free DOF indices, ascending.
    fixed : ndarray of int
        Prescribed (end) DOF indices, ascending.
    mesh : LineMesh
        The mesh (section and hydrodynamic properties per element).
    rho : float
        Water density. [kg/m³]
    mass_matrix : str
        "consistent" or "lumped".
    tension_rows : ndarray, shape (n_el, 2, dim) or None
        Dynamic effective tension δT_j = rows[j, 0]·u_j + rows[j, 1]·u_j+1: (EA/l0)(−e, e),
        EA reduced when slack; the element split at the touchdown its suspended part's
        (:attr:`stochcable.line.seabed.BedContact.tension_row`). [N/m]
    bed : BedContact or None
        The seabed's share (its split touchdown element's parts and condensation).

    Notes
    -----
    Seabed contact (DESIGN.md "Scene"): a grounded node gets a vertical spring
    stiffness·D·(tributary length) and a vertical dashpot damping·D·(tributary length),
    the tributary length being half the unstretched length of each adjacent element and
    D the diameter of that element; the element that contains the static touchdown
    point is split there by a condensed node carrying the bed of its grounded part
    (:func:`stochcable.line.seabed.bed_contact`), so the suspended span ends at the
    touchdown whatever the mesh.  Horizontal seabed friction is ignored (no
    horizontal stiffness or damping from the seabed).
    """

    dim: int
    n_nodes: int
    components: tuple[int, ...]
    positions: np.ndarray
    tangents: np.ndarray
    length: np.ndarray
    l0: np.ndarray
    tension: np.ndarray
    slack: np.ndarray
    grounded: np.ndarray
    K: sp.csr_array
    M: sp.csr_array
    Ma: sp.csr_array
    Cs: sp.csr_array
    free: np.ndarray
    fixed: np.ndarray
    mesh: LineMesh
    rho: float
    mass_matrix: str = "consistent"
    tension_rows: np.ndarray | None = None
    bed: Any = None

    @property
    def n_dof(self) -> int:
        """Total number of DOFs, free and fixed."""
        return self.dim * self.n_nodes

    @property
    def n_elements(self) -> int:
        """Number of elements."""
        return int(self.l0.size)

    @property
    def bandwidth(self) -> int:
        """Half-bandwidth (super-diagonals) of every matrix: 2·dim − 1."""
        return 2 * self.dim - 1

    def dof(self, node: int, component: int | str) -> int:
        """Global DOF index of ``component`` of ``node``.

        ``component`` is a model component index (0 … dim−1) or an axis name "x",
        "y", "z" ("y" only in 3-D).  Negative ``node`` counts from the end.
        """
        if isinstance(component, str):
            axis = _AXES.get(component)
            if axis is None or axis not in self.components:
                raise InputError(
                    "component",
                    component,
                    "-",
                    f"must be one of the model axes "
                    f"{[k for k, v in _AXES.items() if v in self.components]}",
                )
            c = self.components.index(axis)
        else:
            c = int(component)
            if not 0 <= c < self.dim:
                raise InputError("component", component, "-", f"must be in 0…{self.dim - 1}")
        i = int(node)
        if not -self.n_nodes <= i < self.n_nodes:
            raise InputError("node", node, "-", f"must be in 0…{self.n_nodes - 1}")
        return self.dim * (i % self.n_nodes) + c

    @functools.cached_property
    def _mass_total(self) -> sp.csr_array:
        """M + Ma (CSR), computed once per model (the modes and the solves use it).

        Assembled matrices share one pattern: the sum entry by entry on it (the same
        numbers as scipy's sum, which also drops the entries that cancel to 0; 0.1 ms)."""
        m, ma = self.M, self.Ma
        if (
            isinstance(m, sp.csr_array)
            and isinstance(ma, sp.csr_array)
            and m.shape == ma.shape
            and np.array_equal(m.indptr, ma.indptr)
            and np.array_equal(m.indices, ma.indices)
        ):
            return sp.csr_array(
                (m.data + ma.data, m.indices.copy(), m.indptr.copy()), shape=m.shape
            )
        return (m + ma).tocsr()

    def _matrix(self, matrix: str | Any) -> Any:
        if isinstance(matrix, str):
            if matrix not in ("K", "M", "Ma", "Cs", "MT"):
                raise InputError("matrix", matrix, "-", "must be K, M, Ma, Cs or MT")
            if matrix == "MT":
                return self._mass_total.copy()
            return getattr(self, matrix)
        return matrix

    def _free_free(self, matrix: Any) -> Any:
        """The free–free block of :meth:`partition` (no validation); by slicing when
        the free DOFs are one contiguous range (both ends prescribed), ≈ 3x faster
        than the fancy indexing."""
        free = self.free
        if sp.issparse(matrix) and free.size and int(free[-1]) - int(free[0]) + 1 == free.size:
            lo, hi = int(free[0]), int(free[-1]) + 1
            return matrix.tocsr()[lo:hi][:, lo:hi].tocsr()
        return self.partition(matrix)[0]

    def partition(self, matrix: str | Any) -> tuple[Any, Any]:
        """Free–free and free–prescribed blocks of a model matrix.

        Parameters
        ----------
        matrix : {"K", "M", "Ma", "Cs", "MT"} or matrix of shape (n_dof, n_dof)
            A model matrix by name ("MT" = M + Ma) or any matrix on the model DOFs
            (sparse or dense; the blocks keep its type).

        Returns
        -------
        ff, fp
            Rows and columns ``free``; rows ``free``, columns ``fixed``.
        """
        a = self._matrix(matrix)
        if sp.issparse(a):
            rows = a.tocsr()[self.free]
            return rows[:, self.free].tocsr(), rows[:, self.fixed].tocsr()
        a = np.asarray(a)
        return a[np.ix_(self.free, self.free)], a[np.ix_(self.free, self.fixed)]

    def dense(self, matrix: str = "K") -> np.ndarray:
        """Dense copy of a model matrix ("K", "M", "Ma", "Cs" or "MT"), all DOFs."""
        return self._matrix(matrix).toarray()

    def banded(self, matrix: str | Any = "K") -> np.ndarray:
        """Free–free block in LAPACK upper banded storage.

        Returns ``ab`` of shape (bandwidth + 1, n_free) with ``ab[u + i − j, j] =
        A[i, j]`` for ``max(0, j − u) <= i <= j``, u = :attr:`bandwidth`, as taken by
        ``scipy.linalg.eig_banded``, ``solveh_banded`` and ``cholesky_banded``.
        """
        ff, _ = self.partition(matrix)
        return _to_upper_banded(ff, self.bandwidth)


def _to_upper_banded(a: Any, u: int) -> np.ndarray:
    """Upper banded storage of a symmetric sparse or dense matrix."""
    coo = sp.coo_array(a)
    n = coo.shape[0]
    ab = np.zeros((u + 1, n))
    keep = (coo.col >= coo.row) & (coo.col - coo.row <= u)
    ab[u + coo.row[keep] - coo.col[keep], coo.col[keep]] = coo.data[keep]
    return ab


def _element_dofs(n_el: int, dim: int) -> np.ndarray:
    """(n_el, 2·dim) global DOFs of each element."""
    base = dim * np.arange(n_el)[:, None] + np.arange(dim)[None, :]
    return np.hstack([base, base + dim])


def _assemble_sparse(
    blocks: np.ndarray, dofs: np.ndarray, n_dof: int, node_diag: np.ndarray | None = None
) -> sp.csr_array:
    """Sum element matrices (n_el, 2d, 2d) into a CSR matrix, plus a diagonal."""
    k = dofs.shape[1]
    rows = np.broadcast_to(dofs[:, :, None], (dofs.shape[0], k, k)).ravel()
    cols = np.broadcast_to(dofs[:, None, :], (dofs.shape[0], k, k)).ravel()
    data = blocks.ravel()
    if node_diag is not None:
        nz = np.flatnonzero(node_diag)
        rows = np.concatenate([rows, nz])
        cols = np.concatenate([cols, nz])
        data = np.concatenate([data, node_diag[nz]])
    a = sp.coo_array((data, (rows, cols)), shape=(n_dof, n_dof)).tocsr()
    a.sum_duplicates()
    return a


@functools.lru_cache(maxsize=64)
def _chain_pattern(n: int, d: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """CSR pattern of :func:`chain_csr` for n nodes of d DOFs (the same for K, M and
    Ma and for every model of that size; read-only, cached): the flat positions of the
    kept entries in the (node, row comp, side, comp) array, the column indices and the
    row pointers (int64)."""
    cols = (np.arange(-1, 2)[:, None] + np.arange(n)[:, None, None]) * d + np.arange(d)
    cols = np.broadcast_to(cols[:, None], (n, d, 3, d))  # (node, row comp, side, comp)
    keep = np.ones((n, d, 3, d), dtype=bool)
    keep[0, :, 0] = False
    keep[-1, :, 2] = False
    counts = keep.reshape(n * d, -1).sum(axis=1)
    indptr = np.zeros(n * d + 1, dtype=np.int64)
    np.cumsum(counts, out=indptr[1:])
    out = (np.flatnonzero(keep), cols[keep].astype(np.int64), indptr)
    for x in out:
        x.setflags(write=False)
    return out


def chain_csr(
    blocks: np.ndarray, n_nodes: int, dim: int, diag: np.ndarray | None = None
) -> sp.csr_array:
    """Canonical CSR of element matrices (n_el, 2d, 2d) on consecutive nodes (element j
    joins nodes j and j + 1, node-major DOFs), plus a diagonal (n_dof,).

    The same matrix as the COO assembly of :func:`_assemble_sparse` (same pattern: the
    full node blocks of the block-tridiagonal band, explicit zeros kept), built from
    the node blocks directly: no COO conversion or duplicate sorting (≈ 0.1 ms per
    matrix on the 40-element chain against ≈ 0.3)."""
    d = dim
    n = n_nodes
    diag_b = np.zeros((n, d, d))
    diag_b[:-1] += blocks[:, :d, :d]  # node a of element j: node j
    diag_b[1:] += blocks[:, d:, d:]  # node b of element j: node j + 1
    if diag is not None:
        diag_b[:, np.arange(d), np.arange(d)] += diag.reshape(n, d)
    # rows of node i: [lower (node i-1) | diagonal (node i) | upper (node i+1)]
    data = np.zeros((n, d, 3, d))
    data[1:, :, 0] = blocks[:, d:, :d]
    data[:, :, 1] = diag_b
    data[:-1, :, 2] = blocks[:, :d, d:]
    sel, indices, indptr = _chain_pattern(n, d)
    a = sp.csr_array((data.reshape(-1)[sel], indices.copy(), indptr.copy()), shape=(n * d, n * d))
    # the node blocks (diagonal, O[j] = A[j+1, j]) for the analysis' block solves, with
    # a copy of the entries to detect a later in-place change (then they are re-read)
    a._node_blocks = (a.data.copy(), diag_b, np.ascontiguousarray(blocks[:, d:, :d]))
    return a


def assemble(
    mesh: LineMesh,
    positions: np.ndarray,
    tension: np.ndarray,
    rho: float,
    dim: int = 3,
    grounded: np.ndarray | None = None,
    seabed: Seabed | None = None,
    fixed_nodes: Sequence[int] = (0, -1),
    mass_matrix: Literal["consistent", "lumped"] = "consistent",
    touchdown: float | None = None,
) -> FEModel:
    """Assemble the linear finite-element model of a line about a static shape.

    Parameters
    ----------
    mesh : LineMesh
        Elements and nodes of the line (:func:`stochcable.line.mesh.mesh_line`).
    positions : array_like, shape (n_nodes, 3) or (n_nodes, 2)
        Static node positions, (x, y, z), or (x, z) for an in-plane line. [m]
    tension : array_like, shape (n_el,)
        Static effective tension of each element. [N]
    rho : float
        Water density. [kg/m³]
    dim : {2, 3}
        3 for the full model; 2 for in-plane (x–z) motion only, which needs a line in
        the x–z plane (y constant).
    grounded : array_like of bool, shape (n_nodes,), optional
        Nodes resting on the seabed; they get vertical seabed springs and dashpots.
    seabed : Seabed, optional
        Contact stiffness and damping per unit area; default ``Seabed()``.
    fixed_nodes : sequence of int
        Nodes whose every component is prescribed (ends); negative counts from the
        end.  ``(0, -1)`` both ends, ``(0,)`` a free lower end, ``()`` free–free.
    mass_matrix : {"consistent", "lumped"}
        Distribution of the line's mass and added mass over the element's nodes.
    touchdown : float, optional
        Static touchdown point, unstretched arc length from end_a where the line
        leaves the seabed toward end_b; the element that contains it is split there
        (:func:`stochcable.line.seabed.bed_contact`).  None: contact at the grounded
        nodes only. [m]

    Returns
    -------
    FEModel
        Stiffness, mass, added mass and seabed damping with the DOF partition.

    Notes
    -----
    Element stiffness: :func:`element_stiffness` (Tuah (1982), eqs. 3.1.8–3.1.11);
    structural mass: :func:`element_mass` (eq. 3.1.12); normal added mass:
    :func:`element_added_mass`; attachment masses and added masses (isotropic) are
    lumped on their nodes.  Seabed: see :class:`FEModel` and
    :func:`stochcable.line.seabed.bed_contact`.
    """
    dim = check_dim(dim)
    if mass_matrix not in ("consistent", "lumped"):
        raise InputError("mass_matrix", mass_matrix, "-", "must be 'consistent' or 'lumped'")
    rho = positive("rho", rho, "kg/m³")
    n_nodes, n_el = mesh.n_nodes, mesh.n_elements
    pos = float_array("positions", positions, "m", ndim=2)
    if pos.shape == (n_nodes, 2) and dim == 2:
        pos = np.column_stack([pos[:, 0], np.zeros(n_nodes), pos[:, 1]])
    if pos.shape != (n_nodes, 3):
        raise InputError(
            "positions",
            pos.shape,
            "m",
            f"must have shape ({n_nodes}, 3), one (x, y, z) row per node",
        )
    ten = float_array("tension", tension, "N")
    if ten.shape != (n_el,):
        raise InputError("tension", ten.shape, "N", f"must have one value per element ({n_el})")
    comps = (0, 2) if dim == 2 else (0, 1, 2)
    if dim == 2:
        scale = max(float(np.ptp(pos, axis=0).max()), 1.0)
        dy = float(np.ptp(pos[:, 1]))
        if dy > _PLANE_TOL * scale:
            raise InputError(
                "dim",
                2,
                "-",
                f"needs a line in the x–z plane; line '{mesh.name}' spans "
                f"{dy:.3g} m in y: use dim=3",
            )
    if grounded is None:
        gr = np.zeros(n_nodes, dtype=bool)
    else:
        gr = np.asarray(grounded, dtype=bool)
        if gr.shape != (n_nodes,):
            raise InputError("grounded", gr.shape, "-", f"must have one flag per node ({n_nodes})")
    fixed_set = set()
    for f in fixed_nodes:
        if (
            isinstance(f, bool)
            or not isinstance(f, (int, np.integer))
            or not -n_nodes <= f < n_nodes
        ):
            raise InputError("fixed_nodes", f, "-", f"must be node indices in 0…{n_nodes - 1}")
        fixed_set.add(int(f) % n_nodes)
    seabed = Seabed() if seabed is None else seabed

    p = pos[:, comps]
    d = p[1:] - p[:-1]
    l = np.linalg.norm(d, axis=1)
    if (l <= 0.0).any():
        i = int(np.flatnonzero(l <= 0.0)[0])
        raise InputError(
            "positions",
            pos[i],
            "m",
            f"element {i} has zero length (nodes {i} and {i + 1} coincide)",
        )
    e = d / l[:, None]
    lumped = mass_matrix == "lumped"
    n_dof = dim * n_nodes

    k_el = expand_blocks(stiffness_blocks(e, l, mesh.l0, mesh.ea, ten), STIFFNESS_PATTERN)
    m_el = expand_blocks(
        (mesh.l0 * mesh.mass)[:, None, None] * np.eye(dim)[None],
        LUMPED_PATTERN if lumped else CONSISTENT_PATTERN,
    )
    ma_el = added_mass_elements(e, mesh.l0, mesh.ca_normal, mesh.diameter, rho, lumped)

    # Seabed: vertical springs/dashpots of the contact length, the touchdown element
    # split at the static touchdown (stochcable.line.seabed)
    bed = bed_contact(
        mesh.s0,
        mesh.l0,
        mesh.diameter,
        e,
        l,
        mesh.ea,
        ten,
        gr,
        touchdown,
        seabed.stiffness,
        seabed.damping,
        comps.index(2),
    )
    k_el, m_el, ma_el = split_touchdown_element(bed, k_el, m_el, ma_el, mesh, rho, lumped)
    m_diag = np.repeat(mesh.node_mass, dim)
    ma_diag = np.repeat(mesh.node_added_mass, dim)

    K = chain_csr(k_el, n_nodes, dim, bed.k_diag)
    M = chain_csr(m_el, n_nodes, dim, m_diag)
    Ma = chain_csr(ma_el, n_nodes, dim, ma_diag)
    c_diag = bed.c_diag
    if bed.c_block is not None and bed.c_block.any():
        c_el = np.zeros((n_el, 2 * dim, 2 * dim))
        c_el[bed.element] = bed.c_block
        Cs = chain_csr(c_el, n_nodes, dim, c_diag)
    elif c_diag.any():  # the nonzero diagonal entries only (as sp.diags_array gave)
        nz = c_diag != 0.0
        Cs = sp.csr_array(
            (
                c_diag[nz],
                np.flatnonzero(nz).astype(np.int32),
                np.r_[0, np.cumsum(nz)].astype(np.int32),
            ),
            shape=(n_dof, n_dof),
        )
    else:
        Cs = sp.csr_array((n_dof, n_dof))

    fixed_mask = np.zeros(n_nodes, dtype=bool)
    fixed_mask[list(fixed_set)] = True
    dof_fixed = np.repeat(fixed_mask, dim)
    return FEModel(
        dim=dim,
        n_nodes=n_nodes,
        components=comps,
        positions=pos.copy(),
        tangents=e,
        length=l,
        l0=mesh.l0.copy(),
        tension=ten.copy(),
        slack=ten <= 0.0,
        grounded=bed.grounded,
        K=K,
        M=M,
        Ma=Ma,
        Cs=Cs,
        free=np.flatnonzero(~dof_fixed),
        fixed=np.flatnonzero(dof_fixed),
        mesh=mesh,
        rho=rho,
        mass_matrix=mass_matrix,
        tension_rows=tension_rows(e, mesh.l0, mesh.ea, ten, bed),
        bed=bed,
    )


def build_fe_model(
    line_statics: Any,
    environment: Environment,
    dim: int | None = None,
    mass_matrix: Literal["consistent", "lumped"] = "consistent",
) -> FEModel:
    """Finite-element model of a line about its solved static shape.

    Parameters
    ----------
    line_statics : LineStatics
        One line of :func:`stochcable.statics.solve_statics`: ``mesh``, ``positions``
        (n_nodes, 3), ``tension`` (n_el,) effective tension, ``grounded`` (n_nodes,).
    environment : Environment
        Water density and seabed contact model.
    dim : {2, 3}, optional
        Model dimension.  When None: 2 if the line lies in the x–z plane, else 3.
        A caller that has the scene should pass ``2 if scene.is_planar else 3`` (a
        line in the x–z plane under an oblique sea needs 3-D), and natural-mode
        listings want 3 (out-of-plane modes exist even when nothing excites them).
    mass_matrix : {"consistent", "lumped"}
        Mass distribution.

    Returns
    -------
    FEModel
        Both ends prescribed (``fixed_nodes=(0, -1)``).
    """
    pos = np.asarray(line_statics.positions, dtype=float)
    if dim is None:
        scale = max(float(np.ptp(pos, axis=0).max()), 1.0)
        dim = 2 if float(np.abs(pos[:, 1]).max()) <= _PLANE_TOL * scale else 3
    grounded = getattr(line_statics, "grounded", None)
    if grounded is None:
        grounded = pos[:, 2] <= -environment.depth * (1.0 - 1e-9)
    touchdown = getattr(line_statics, "touchdown", None)
    return assemble(
        line_statics.mesh,
        pos,
        line_statics.tension,
        environment.rho,
        dim=dim,
        grounded=grounded,
        seabed=environment.seabed,
        fixed_nodes=(0, -1),
        mass_matrix=mass_matrix,
        touchdown=touchdown,
    )
