"""Lines and rigid bodies assembled into one linear system (Tuah (1982), §3.3).

The coupled system
------------------
:func:`couple` assembles lines (:class:`stochcable.line.fem.FEModel`) and bodies into one
linear system over x = [line free DOFs …, body DOFs …].  With L_ℓ the sparse map from
x to all DOFs of line ℓ (identity on its free DOFs, T(r) on a body-attached end,
zero on a still-prescribed end) and P_ℓ the map from the prescribed DOFs p,

    K = Σ L_ℓᵀ K_ℓ L_ℓ + K_body,   K_p = Σ L_ℓᵀ K_ℓ P_ℓ      (Tuah (1982), eq. 3.3.10)

and the same for M and C: the line end DOFs are eliminated in favour of the body DOFs
(K_cc = Tᵀ K_bb T, K_fc = K_fb T).  The frequency response is
Z(ω) x = F with Z(ω) = K − ω²(M + A(ω)) + iω(C + B(ω))
(:func:`stochcable.reference.bodies.solve_coupled_direct`, the independent dense/Schur
check of the engine).

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import scipy.sparse as sp

from stochcable.bodies.coupled_system import CoupledSystem, LineLink
from stochcable.bodies.rigid import (
    RigidBody,
    attachment_geometric_stiffness,
    rigid_link_matrix,
    square_matrix,
)
from stochcable.errors import InputError
from stochcable.line.fem import FEModel
from stochcable.validation import float_array, nonnegative

__all__ = [
    "LineLink",
    "CoupledSystem",
    "couple",
    "coupled_load",
    "expand_line",
    "constant_matrices",
]

# Relative tolerance for a body-attached end node to lie where the body says.
_SYM_TOL = 1.0e-9


def _model_end_force(model: FEModel, end: str, g: float | None) -> np.ndarray:
    """Force a line exerts on the support at ``end`` from the model alone (no drag)."""
    mesh = model.mesh
    comps = list(model.components)
    e = np.zeros((model.n_elements, 3))
    e[:, comps] = model.tangents
    t = np.where(model.slack, 0.0, model.tension)
    if end == "end_a":
        f = t[0] * e[0]
        w_el, node = mesh.weight[0] * mesh.l0[0], 0
    else:
        f = -t[-1] * e[-1]
        w_el, node = mesh.weight[-1] * mesh.l0[-1], -1
    f = f.copy()
    f[2] -= 0.5 * w_el
    gg = 9.80665 if g is None else g
    f[2] += mesh.node_buoyancy[node] - mesh.node_mass[node] * gg
    return f


def couple(
    lines: Sequence[LineLink],
    bodies: Sequence[RigidBody],
    *,
    body_damping: Mapping[str, Any] | None = None,
    geometric_stiffness: bool = True,
    g: float | None = None,
) -> CoupledSystem:
    """Assemble lines and bodies into one linear system with rigid links.

    Parameters
    ----------
    lines : sequence of LineLink
        Line models and their body attachments.
    bodies : sequence of RigidBody
        The bodies (unique names); their dimensions must match the line models'
        (planar bodies with 2-D models, 6-DOF bodies with 3-D models).
    body_damping : mapping of str to array_like (d, d), optional
        Additional damping per body name (e.g.
        :func:`stochcable.reference.bodies.body_drag_damping`). [N·s/m, …]
    geometric_stiffness : bool
        Add the attachment geometric stiffness of the line end forces
        (:func:`attachment_geometric_stiffness`); default True.
    g : float, optional
        Gravity for the end forces computed from a model (default 9.80665). [m/s²]

    Returns
    -------
    CoupledSystem

    Raises
    ------
    InputError
        Duplicate names, an unknown body, an attached end that is not a prescribed
        node of its model, or a dimension mismatch.

    Notes
    -----
    Tuah (1982), §3.3: the attached end node's displacement is slaved to the body by
    u_end = T(r) ξ (eqs. 3.3.6–3.3.7, :func:`rigid_link_matrix`), and the line's
    equations are premultiplied by the transpose of the transformation (eqs.
    3.3.8–3.3.10): with L_ℓ the map from x to the line's DOFs,
    K = Σ L_ℓᵀ K_ℓ L_ℓ + K_B (so K_cc = Tᵀ K_bb T, K_fc = K_fb T), likewise M and C,
    and a line load f_ℓ enters as L_ℓᵀ f_ℓ (:func:`coupled_load`).  The rotation block
    of each body gets −[F]×[r]× for each attached end (F the static end force on the
    body), the linearization of the moment of a force whose arm rotates with the body.
    """
    bodies = tuple(bodies)
    lines = tuple(lines)
    names = [b.name for b in bodies]
    if len(set(names)) != len(names):
        raise InputError("bodies", names, "-", "body names must be unique")
    lnames = [ln.name for ln in lines]
    if len(set(lnames)) != len(lnames):
        raise InputError("lines", lnames, "-", "line names must be unique")
    by_name = {b.name: b for b in bodies}
    line_dofs, body_dofs, n = _dof_layout(lines, bodies)

    geo = {b.name: np.zeros((b.n_dof, b.n_dof)) for b in bodies}
    plans = []
    for ln in lines:
        attached, geometric = _attachments(ln, by_name, g, geometric_stiffness)
        for bname, kg in geometric:
            geo[bname] = geo[bname] + kg
        plans.append((ln, attached))
    pres: dict[str, np.ndarray] = {}
    maps: dict[str, tuple[sp.csr_array, sp.csr_array]] = {}
    n_p = 0
    for ln, attached in plans:
        L, P = _link_maps(ln.model, attached, line_dofs[ln.name], body_dofs, n)
        pres[ln.name] = np.arange(n_p, n_p + P.shape[1])
        n_p += P.shape[1]
        maps[ln.name] = (L, P)

    bd = {} if body_damping is None else dict(body_damping)
    for key in bd:
        if key not in by_name:
            raise InputError("body_damping", key, "-", f"is not a body; bodies: {names}")

    def total(getter: Any, body_part: Any) -> tuple[sp.csr_array, sp.csr_array]:
        return _sum_links(getter, body_part, lines, bodies, maps, pres, body_dofs, n, n_p)

    K, K_p = total(
        lambda ln: ln.model.K, lambda b: b.hydrostatic_stiffness + b.extra_stiffness + geo[b.name]
    )
    M, M_p = total(lambda ln: (ln.model.M + ln.model.Ma).tocsr(), lambda b: b.mass_matrix())
    C, C_p = total(
        _line_damping,
        lambda b: (
            b.extra_damping
            + (
                square_matrix(f"body_damping[{b.name}]", bd[b.name], b.n_dof, "N·s/m")
                if b.name in bd
                else 0.0
            )
        ),
    )
    for a in (K, M, C, K_p, M_p, C_p):
        a.eliminate_zeros()
    return CoupledSystem(
        K=K,
        M=M,
        C=C,
        K_p=K_p,
        M_p=M_p,
        C_p=C_p,
        bodies=bodies,
        lines=lines,
        line_dofs=line_dofs,
        body_dofs=body_dofs,
        prescribed_dofs=pres,
        link_maps=maps,
        geometric=geo,
    )


def _dof_layout(
    lines: tuple[LineLink, ...], bodies: tuple[RigidBody, ...]
) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray], int]:
    """Indices in x of each line's free DOFs and each body's DOFs (lines first), and
    the number n of coupled DOFs."""
    n_free = sum(int(ln.model.free.size) for ln in lines)
    n = n_free + sum(b.n_dof for b in bodies)
    line_dofs: dict[str, np.ndarray] = {}
    body_dofs: dict[str, np.ndarray] = {}
    k = 0
    for ln in lines:
        line_dofs[ln.name] = np.arange(k, k + ln.model.free.size)
        k += int(ln.model.free.size)
    for b in bodies:
        body_dofs[b.name] = np.arange(k, k + b.n_dof)
        k += b.n_dof
    return line_dofs, body_dofs, n


def _attachments(
    ln: LineLink, by_name: dict[str, RigidBody], g: float | None, geometric_stiffness: bool
) -> tuple[dict[int, tuple[RigidBody, np.ndarray]], list[tuple[str, np.ndarray]]]:
    """The checked body attachments of a line: end node -> (body, arm r), and, with
    ``geometric_stiffness``, per attached end the body's attachment geometric stiffness
    of the static end force (:func:`stochcable.bodies.rigid.attachment_geometric_stiffness`)."""
    model = ln.model
    if not isinstance(model, FEModel):
        raise InputError(
            f"lines[{ln.name}].model",
            type(model).__name__,
            "-",
            "must be a stochcable.line.fem.FEModel",
        )
    names = list(by_name)
    fixed_nodes = set((model.fixed // model.dim).tolist())
    attached: dict[int, tuple[RigidBody, np.ndarray]] = {}
    geometric: list[tuple[str, np.ndarray]] = []
    for end, node in (("end_a", 0), ("end_b", model.n_nodes - 1)):
        bname = getattr(ln, end)
        if bname is None:
            continue
        if bname not in by_name:
            raise InputError(
                f"lines[{ln.name}].{end}", bname, "-", f"is not a body; bodies: {names}"
            )
        body = by_name[bname]
        if node not in fixed_nodes:
            raise InputError(
                f"lines[{ln.name}].{end}",
                bname,
                "-",
                "the end node is free in the model: build it with the end prescribed (fixed_nodes)",
            )
        if (model.dim == 2) != body.planar:
            raise InputError(
                f"lines[{ln.name}].{end}",
                bname,
                "-",
                f"a {model.dim}-D line model needs a "
                f"{'planar' if model.dim == 2 else '6-DOF'} body",
            )
        r = model.positions[node] - body.position
        if body.planar and abs(r[1]) > _SYM_TOL * max(1.0, float(np.abs(r).max())):
            raise InputError(
                f"lines[{ln.name}].{end}",
                r.tolist(),
                "m",
                "a planar body's attachment must lie in its x–z plane",
            )
        fgiven = getattr(ln, "force_a" if end == "end_a" else "force_b")
        f = (
            _model_end_force(model, end, g)
            if fgiven is None
            else float_array(f"lines[{ln.name}].force_{end[-1]}", fgiven, "N")
        )
        if f.shape != (3,):
            raise InputError(
                f"lines[{ln.name}].force_{end[-1]}", f.shape, "N", "must have 3 components"
            )
        if geometric_stiffness:
            geometric.append((bname, attachment_geometric_stiffness(f, r, body.planar)))
        attached[node] = (body, r)
    return attached, geometric


def _link_maps(
    model: FEModel,
    attached: dict[int, tuple[RigidBody, np.ndarray]],
    free_dofs: np.ndarray,
    body_dofs: dict[str, np.ndarray],
    n: int,
) -> tuple[sp.csr_array, sp.csr_array]:
    """The sparse maps u_line = L x + P p of a line: identity from its free DOFs,
    T(r) from the body DOFs on an attached end node (Tuah (1982), eqs. 3.3.6–3.3.7), P on
    its still-prescribed DOFs (model order)."""
    d = model.dim
    rows, cols, vals = [], [], []
    # free DOFs: identity
    rows.append(model.free)
    cols.append(free_dofs)
    vals.append(np.ones(model.free.size))
    still = []
    for dof in model.fixed:
        node = int(dof // d)
        if node in attached:
            continue
        still.append(int(dof))
    for node, (body, r) in attached.items():
        t = rigid_link_matrix(r, planar=body.planar)  # (d, n_b)
        ii, jj = np.nonzero(t)
        rows.append(d * node + ii)
        cols.append(body_dofs[body.name][jj])
        vals.append(t[ii, jj])
    L = sp.csr_array(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(model.n_dof, n)
    )
    still_arr = np.asarray(still, dtype=int)
    P = sp.csr_array(
        (np.ones(still_arr.size), (still_arr, np.arange(still_arr.size))),
        shape=(model.n_dof, still_arr.size),
    )
    return L, P


def _sum_links(
    getter: Any,
    body_part: Any,
    lines: tuple[LineLink, ...],
    bodies: tuple[RigidBody, ...],
    maps: dict[str, tuple[sp.csr_array, sp.csr_array]],
    pres: dict[str, np.ndarray],
    body_dofs: dict[str, np.ndarray],
    n: int,
    n_p: int,
) -> tuple[sp.csr_array, sp.csr_array]:
    """Σ L_ℓᵀ A_ℓ L_ℓ + the body blocks, and Σ L_ℓᵀ A_ℓ P_ℓ (Tuah (1982), eq. 3.3.10),
    A_ℓ = ``getter(line)``, the body blocks ``body_part(body)``."""
    acc = sp.csr_array((n, n))
    acc_p = sp.csr_array((n, n_p))
    for ln in lines:
        L, P = maps[ln.name]
        a = getter(ln)
        LtA = (L.T @ a).tocsr()
        acc = acc + LtA @ L
        pp = sp.csr_array((n, n_p))
        if P.shape[1]:
            blk = (LtA @ P).tocoo()
            off = int(pres[ln.name][0])
            pp = sp.csr_array((blk.data, (blk.row, blk.col + off)), shape=(n, n_p))
        acc_p = acc_p + pp
    for b in bodies:
        idx = body_dofs[b.name]
        blk = sp.coo_array(body_part(b))
        acc = acc + sp.csr_array((blk.data, (idx[blk.row], idx[blk.col])), shape=(n, n))
    return acc.tocsr(), acc_p.tocsr()


def _line_damping(ln: LineLink) -> Any:
    """The line's seabed damping plus its link damping (all model DOFs)."""
    if ln.damping is None:
        return ln.model.Cs
    c = ln.damping
    if c.shape != (ln.model.n_dof, ln.model.n_dof):
        raise InputError(
            f"lines[{ln.name}].damping",
            c.shape,
            "N·s/m",
            f"must be ({ln.model.n_dof}, {ln.model.n_dof})",
        )
    return sp.csr_array(ln.model.Cs + sp.csr_array(c))


# ------------------------------------------------------------------------- loads


def _rows_apply(a: Any, x: np.ndarray) -> np.ndarray:
    """Sparse (m, n) times x (n_w, n, ...) -> (n_w, m, ...)."""
    n_w, n = x.shape[:2]
    rest = x.shape[2:]
    flat = np.moveaxis(x.reshape(n_w, n, -1), 0, 1).reshape(n, -1)
    out = np.asarray(a @ flat)
    return np.moveaxis(out.reshape(out.shape[0], n_w, -1), 1, 0).reshape(n_w, out.shape[0], *rest)


def coupled_load(
    system: CoupledSystem,
    omega: Any,
    line_loads: Mapping[str, Any] | None = None,
    body_loads: Mapping[str, Any] | None = None,
    line_motions: Mapping[str, Any] | None = None,
) -> np.ndarray:
    """Load vector of the coupled system at every frequency.

    Parameters
    ----------
    system : CoupledSystem
    omega : array_like, shape (n_w,)
        Angular frequencies. [rad/s]
    line_loads : mapping of line name to array_like (n_w, n_dof_line[, k]), optional
        Loads on all model DOFs of a line (fluid loads); the share on a body-attached
        end node is carried to the body as Tᵀ f. [N]
    body_loads : mapping of body name to array_like (n_w, d[, k]), optional
        Generalized forces on a body (:func:`body_excitation`). [N, N·m]
    line_motions : mapping of line name to array_like (n_w, n_dof_line[, k]), optional
        Prescribed displacements on a line's model DOFs; the entries at its
        still-prescribed DOFs load the system by −(K_p − ω²M_p + iωC_p) p. [m]

    Returns
    -------
    ndarray, complex, shape (n_w, n[, k])
    """
    w = float_array("omega", omega, "rad/s", nonnegative=True)
    n_w, n = w.size, system.n_dof
    out = None

    def add(acc, v):
        return v if acc is None else acc + v

    for name, f in (line_loads or {}).items():
        if name not in system.link_maps:
            raise InputError("line_loads", name, "-", "is not a coupled line")
        f = np.asarray(f, dtype=complex)
        L, _ = system.link_maps[name]
        if f.shape[:2] != (n_w, L.shape[0]):
            raise InputError(
                f"line_loads[{name}]", f.shape, "N", f"must start with ({n_w}, {L.shape[0]})"
            )
        out = add(out, _rows_apply(L.T.tocsr(), f))
    for name, f in (body_loads or {}).items():
        if name not in system.body_dofs:
            raise InputError("body_loads", name, "-", "is not a coupled body")
        f = np.asarray(f, dtype=complex)
        idx = system.body_dofs[name]
        if f.shape[:2] != (n_w, idx.size):
            raise InputError(
                f"body_loads[{name}]", f.shape, "N", f"must start with ({n_w}, {idx.size})"
            )
        v = np.zeros((n_w, n) + f.shape[2:], dtype=complex)
        v[:, idx] = f
        out = add(out, v)
    if line_motions:
        p = None
        for name, u in line_motions.items():
            if name not in system.link_maps:
                raise InputError("line_motions", name, "-", "is not a coupled line")
            u = np.asarray(u, dtype=complex)
            _, P = system.link_maps[name]
            if u.shape[:2] != (n_w, P.shape[0]):
                raise InputError(
                    f"line_motions[{name}]", u.shape, "m", f"must start with ({n_w}, {P.shape[0]})"
                )
            if p is None:
                p = np.zeros((n_w, system.n_prescribed) + u.shape[2:], dtype=complex)
            p[:, system.prescribed_dofs[name]] = _rows_apply(P.T.tocsr(), u)
        if p is not None:
            extra = (1,) * (p.ndim - 2)
            ww = w.reshape((n_w, 1) + extra)
            z = (
                _rows_apply(system.K_p, p)
                - ww**2 * _rows_apply(system.M_p, p)
                + 1j * ww * _rows_apply(system.C_p, p)
            )
            out = add(out, -z)
    if out is None:
        return np.zeros((n_w, n), dtype=complex)
    return out


def expand_line(system: CoupledSystem, name: str, x: Any, p: Any | None = None) -> np.ndarray:
    """Displacement of all model DOFs of a line, u = L x + P p.

    Parameters
    ----------
    system : CoupledSystem
    name : str
        Line name.
    x : array_like, shape (n_w, n[, k])
        Coupled response (:func:`stochcable.reference.bodies.solve_coupled_direct`).
        [m, rad]
    p : array_like, shape (n_w, n_p[, k]), optional
        Prescribed displacements (zero when None). [m]

    Returns
    -------
    ndarray, complex, shape (n_w, n_dof_line[, k])
    """
    if name not in system.link_maps:
        raise InputError("name", name, "-", "is not a coupled line")
    L, P = system.link_maps[name]
    x = np.asarray(x, dtype=complex)
    u = _rows_apply(L, x)
    if p is not None and P.shape[1]:
        pp = np.asarray(p, dtype=complex)[:, system.prescribed_dofs[name]]
        u = u + _rows_apply(P, pp)
    return u


# ------------------------------------------------------------------------- solve


def constant_matrices(
    system: CoupledSystem, omega_ref: float
) -> tuple[sp.csr_array, sp.csr_array, sp.csr_array]:
    """K, M + A(ω_ref) and C + B(ω_ref): constant matrices for modes and Foss.

    Parameters
    ----------
    system : CoupledSystem
    omega_ref : float
        Frequency at which the body added mass and radiation damping are frozen
        (typically the spectral peak or the body's natural frequency). [rad/s]

    Returns
    -------
    K, M_T, C_T : scipy.sparse.csr_array

    Notes
    -----
    Modal superposition and the Foss decomposition (Tuah (1982), §5.3) need constant
    matrices; with A(ω), B(ω) varying they are exact only at ω_ref, so the direct
    solve (:func:`stochcable.reference.bodies.solve_coupled_direct`) is the reference
    whenever ``system.frequency_dependent``.
    """
    w = nonnegative("omega_ref", omega_ref, "rad/s")
    a, b = system.body_hydrodynamics(np.array([w]))
    idx = system.body_index
    n = system.n_dof

    def emb(blk: np.ndarray) -> sp.csr_array:
        c = sp.coo_array(blk)
        return sp.csr_array((c.data, (idx[c.row], idx[c.col])), shape=(n, n))

    return system.K, (system.M + emb(a[0])).tocsr(), (system.C + emb(b[0])).tocsr()
