"""Natural modes of a coupled group: lines and rigid bodies (undamped, constant
matrices; Tuah (1982), §3.3, eqs. 3.3.8–3.3.10).

The coupled modes need constant matrices: K and M + A(ω_ref) of
:func:`stochcable.bodies.coupling.constant_matrices`, ω_ref the peak of the sea spectrum
(:func:`stochcable.dynamics.groups.inputs.reference_omega`; documented on
:class:`CoupledModes`).  ``RigidBody.fixed_dofs`` are constraints: the modes are those
of the constrained system.  Two ways, the same listed frequencies to 1e-4 on the
three-leg benchmark: the assembled system (:func:`stochcable.bodies.coupling.couple`) and
the Craig–Bampton reduction on each line's fixed-end modes and static following.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.linalg as sla

from stochcable.bodies.coupling import LineLink, constant_matrices, couple
from stochcable.bodies.rigid import RigidBody, attachment_geometric_stiffness, rigid_link_matrix
from stochcable.dynamics.groups.group import body_drag_matrix
from stochcable.dynamics.groups.inputs import CoupledLine
from stochcable.dynamics.model.blocks import add_blocks, block_matvec, line_prep
from stochcable.dynamics.model.system import Damping
from stochcable.dynamics.solve.line_loads import drag_blocks
from stochcable.errors import InputError

__all__ = [
    "LISTED_MODE_FACTOR",
    "MIN_LISTED_MODES",
    "CoupledModes",
    "coupled_modal_bandwidths",
    "coupled_modes",
    "line_mode_shares",
]

#: Modes listed: those up to this factor times the top of the grid, at least
#: ``MIN_LISTED_MODES`` (as the line listing of :mod:`stochcable.dynamics`).
LISTED_MODE_FACTOR = 2.5
MIN_LISTED_MODES = 10
# Coupled DOFs up to which the modes are a dense generalized eigenproblem.
_DENSE_MODES = 1500
# Dense eigenproblems up to this size are solved whole (LAPACK divide and conquer)
# and the listed modes kept; larger ones by the subset driver (``_listed_eigh``).
_ALL_EIGH_MAX = 256


@dataclass(frozen=True, eq=False)
class CoupledModes:
    """Natural modes of a coupled group (undamped, constant matrices).

    Attributes
    ----------
    omega : ndarray, shape (n,)
        Natural frequencies, lowest first. [rad/s]
    body_fraction : ndarray, shape (n,)
        Share of each mass-normalized mode's kinetic energy in the body DOFs,
        φ_Jᵀ(Mφ)_J. [-]
    body_shapes : dict of str to ndarray, shape (d, n)
        Body part of each mode shape (mass-normalized). [m·kg^-1/2, rad·kg^-1/2]
    omega_ref : float
        Frequency at which the bodies' added mass was frozen. [rad/s]
    asymmetry : float
        max|K − Kᵀ|/max|K| of the coupled stiffness (its symmetric part is used). [-]
    line_shapes : dict of str to ndarray, shape (n_nodes, d, n)
        Line part of each mode shape on all the line's nodes (attached ends moving
        with the bodies, the others at rest; mass-normalized over the group).
        [m·kg^-1/2]
    """

    omega: np.ndarray
    body_fraction: np.ndarray
    body_shapes: dict[str, np.ndarray]
    omega_ref: float
    asymmetry: float
    line_shapes: dict[str, np.ndarray] = field(default_factory=dict)

    def as_dict(self) -> dict[str, Any]:
        return {
            "omega": self.omega.tolist(),
            "body_fraction": self.body_fraction.tolist(),
            "omega_ref": float(self.omega_ref),
            "asymmetry": float(self.asymmetry),
        }


def coupled_modes(
    lines: Sequence[CoupledLine],
    bodies: Sequence[RigidBody],
    omega_ref: float,
    omega_top: float,
    *,
    method: str = "auto",
) -> CoupledModes:
    """Natural modes of lines and bodies coupled by rigid links.

    Parameters
    ----------
    lines : sequence of CoupledLine
    bodies : sequence of RigidBody
        Their ``fixed_dofs`` are constraints (ξ_j ≡ 0): the modes are those of the
        constrained system, the fixed rows of ``body_shapes`` are zero.
    omega_ref : float
        Frequency of the added mass A(ω_ref) (spectral peak). [rad/s]
    omega_top : float
        Top of the analysis grid: modes up to 2.5·omega_top are listed, at least 10.
        [rad/s]
    method : {"auto", "full", "reduced"}
        "full": the assembled system; "reduced": the Craig–Bampton reduction;
        "auto": reduced when every line's highest fixed-end mode is at least
        ``_CB_MIN_RATIO`` times the listing top, else full.

    Returns
    -------
    CoupledModes

    Notes
    -----
    K φ = ω²(M + A(ω_ref)) φ on the assembled system of
    :func:`stochcable.bodies.coupling.couple`
    (:func:`~stochcable.bodies.coupling.constant_matrices`),
    the symmetric part of K (the attachment geometric stiffness is antisymmetric by
    ½[Σ r × F]× when the static moments on a body are not balanced by the model's own
    terms; :attr:`CoupledModes.asymmetry`).  Full: dense LAPACK up to 1500 DOFs, else
    shift-invert Lanczos.  Reduced (Craig–Bampton): each line's free DOFs are
    x_f = Φ q + G T ξ, Φ its fixed-end modes (all computed), G = −K_ff⁻¹K_fe its
    static following of the attached ends, T the rigid links; the eigenproblem of
    Lᵀ K L, Lᵀ M L over (q of every line, ξ) is a Rayleigh–Ritz projection of the
    full one (upper bounds; on the three-leg benchmark the listed frequencies agree
    within 1e-4 relative, tests/dynamics/test_coupled_analysis.py).
    """
    if method not in ("auto", "full", "reduced"):
        raise InputError("method", method, "-", "must be 'auto', 'full' or 'reduced'")
    top = (LISTED_MODE_FACTOR * omega_top) ** 2
    if method == "auto":
        ok = bool(lines) and all(
            cl.system.modes is not None
            and cl.system.modes.count
            and float(np.max(cl.system.modes.omega)) >= _CB_MIN_RATIO * math.sqrt(top)
            and cl.system.model.free.size == (cl.system.model.n_nodes - 2) * cl.system.model.dim
            for cl in lines
        )
        method = "reduced" if ok else "full"
    if method == "reduced":
        return _coupled_modes_reduced(lines, bodies, omega_ref, top)
    return _coupled_modes_full(lines, bodies, omega_ref, top)


#: Craig–Bampton coupled modes ("auto") when every line's highest fixed-end mode is at
#: least this factor above the top listed frequency.
_CB_MIN_RATIO = 1.5


def _fixed_body_rows(
    bodies: Sequence[RigidBody], body_dofs: Mapping[str, np.ndarray]
) -> np.ndarray:
    """Coupled indices of the fixed body DOFs."""
    out = [
        body_dofs[b.name][i] for b in bodies for i, n in enumerate(b.dof_names) if n in b.fixed_dofs
    ]
    return np.asarray(out, dtype=int)


def _listed_eigh(kd: np.ndarray, md: np.ndarray, top: float) -> tuple[np.ndarray, np.ndarray]:
    n = kd.shape[0]
    if n == 0:
        return np.zeros(0), np.zeros((0, 0))
    if n <= _ALL_EIGH_MAX:
        # every eigenpair by divide and conquer, then the listed ones: on the
        # benchmark's 126-DOF reduction 1.2 ms against 2.5 ms for the subset driver
        # (the same eigenvalues to 3e-13; docs/BENCHMARKS.md "Bodies", pass E5b)
        lam, phi = sla.eigh(kd, md, driver="gvd")
        k = max(int(np.searchsorted(lam, top, side="right")), min(MIN_LISTED_MODES, n))
        return lam[:k], phi[:, :k]
    lam, phi = sla.eigh(kd, md, subset_by_value=(-np.inf, top), driver="gvx")
    if lam.size < min(MIN_LISTED_MODES, n):
        lam, phi = sla.eigh(kd, md, subset_by_index=(0, min(MIN_LISTED_MODES, n) - 1))
    return lam, phi


def _coupled_modes_full(
    lines: Sequence[CoupledLine], bodies: Sequence[RigidBody], omega_ref: float, top: float
) -> CoupledModes:
    """:func:`coupled_modes` on the assembled system (the reference)."""
    links = [
        LineLink(
            cl.name,
            cl.system.model,
            end_a=cl.end_a,
            end_b=cl.end_b,
            force_a=cl.system.statics.force_a if cl.end_a else None,
            force_b=cl.system.statics.force_b if cl.end_b else None,
        )
        for cl in lines
    ]
    system = couple(links, bodies)
    K, M, _ = constant_matrices(system, omega_ref)
    asym = system.asymmetry()
    ks = 0.5 * (K + K.T)
    n = system.n_dof
    keep = np.setdiff1d(np.arange(n), _fixed_body_rows(bodies, system.body_dofs))
    ks, M = ks[keep][:, keep], M[keep][:, keep]
    nk = keep.size
    if nk <= _DENSE_MODES:
        kd, md = ks.toarray(), M.toarray()
        md = 0.5 * (md + md.T)
        lam, phi = _listed_eigh(kd, md, top)
    else:
        from scipy.sparse.linalg import eigsh

        k = min(max(MIN_LISTED_MODES, 20), nk - 2)
        lam, phi = eigsh(ks.tocsc(), k=k, M=M.tocsc(), sigma=0.0, which="LM")
        order = np.argsort(lam)
        lam, phi = lam[order], phi[:, order]
    mphi = M @ phi
    full = np.zeros((n, lam.size))
    full[keep] = phi
    mfull = np.zeros((n, lam.size))
    mfull[keep] = mphi
    J = system.body_index
    frac = np.einsum("jn,jn->n", full[J], mfull[J]) if J.size else np.zeros(lam.size)
    shapes = {b.name: full[system.body_dofs[b.name]].copy() for b in bodies}
    lshapes = {
        cl.name: np.asarray(system.link_maps[cl.name][0] @ full).reshape(
            cl.system.model.n_nodes, cl.system.model.dim, lam.size
        )
        for cl in lines
    }
    return CoupledModes(
        omega=np.sqrt(np.clip(lam, 0.0, None)),
        body_fraction=np.clip(frac, 0.0, 1.0),
        body_shapes=shapes,
        omega_ref=float(omega_ref),
        asymmetry=asym,
        line_shapes=lshapes,
    )


def _coupled_modes_reduced(
    lines: Sequence[CoupledLine], bodies: Sequence[RigidBody], omega_ref: float, top: float
) -> CoupledModes:
    """:func:`coupled_modes` by the Craig–Bampton reduction (its Notes)."""
    by_name = {b.name: b for b in bodies}
    off, nb = {}, 0
    for b in bodies:
        off[b.name] = nb
        nb += b.n_dof
    kb, mb = np.zeros((nb, nb)), np.zeros((nb, nb))
    for b in bodies:
        sl = slice(off[b.name], off[b.name] + b.n_dof)
        kb[sl, sl] = b.hydrostatic_stiffness + b.extra_stiffness
        mb[sl, sl] = b.mass_matrix() + b.added_mass_at(np.array([omega_ref]))[0]
    parts = []  # per line: (L (n_dof, m + nb), K, M, end rows, T, offset, m)
    top_k = 0.0
    kb_lines = np.zeros((nb, nb))
    m_tot = 0
    for cl in lines:
        part, k_top, k_ends = _reduced_line(cl, by_name, off, nb, kb, m_tot)
        top_k = max(top_k, k_top)
        kb_lines += k_ends
        parts.append(part)
        m_tot += part[-1]
    kfull_b = kb_lines + kb
    top_k = max(top_k, float(np.abs(kfull_b).max(initial=0.0)))
    asym = float(np.abs(kfull_b - kfull_b.T).max(initial=0.0) / top_k) if top_k > 0 else 0.0
    n = m_tot + nb
    kr, mr = np.zeros((n, n)), np.zeros((n, n))
    for ell, kd_, md_, _, _, o, m in parts:
        idx = np.r_[np.arange(o, o + m), np.arange(m_tot, n)]
        kr[np.ix_(idx, idx)] += ell.T @ kd_ @ ell
        mr[np.ix_(idx, idx)] += ell.T @ md_ @ ell
    kr[m_tot:, m_tot:] += kb
    mr[m_tot:, m_tot:] += mb
    fixed = m_tot + _fixed_body_rows(
        bodies, {b.name: np.arange(off[b.name], off[b.name] + b.n_dof) for b in bodies}
    )
    keep = np.setdiff1d(np.arange(n), fixed)
    ks = 0.5 * (kr + kr.T)[np.ix_(keep, keep)]
    ms = 0.5 * (mr + mr.T)[np.ix_(keep, keep)]
    lam, z = _listed_eigh(ks, ms, top)
    zf = np.zeros((n, lam.size))
    zf[keep] = z
    xi = zf[m_tot:]
    # (M φ) on the body DOFs of the full system: Σ Tᵀ (M_line u)_ends + M_B ξ
    mxi = mb @ xi
    lshapes = {}
    for cl, (ell, _, md_, ends, t, o, m) in zip(lines, parts):
        u = ell @ np.r_[zf[o : o + m], xi]
        mxi += t.T @ (md_[ends] @ u)
        lshapes[cl.name] = u.reshape(cl.system.model.n_nodes, cl.system.model.dim, lam.size)
    frac = np.einsum("jn,jn->n", xi, mxi) if nb else np.zeros(lam.size)
    shapes = {b.name: xi[off[b.name] : off[b.name] + b.n_dof].copy() for b in bodies}
    return CoupledModes(
        omega=np.sqrt(np.clip(lam, 0.0, None)),
        body_fraction=np.clip(frac, 0.0, 1.0),
        body_shapes=shapes,
        omega_ref=float(omega_ref),
        asymmetry=asym,
        line_shapes=lshapes,
    )


def _reduced_line(
    cl: CoupledLine,
    by_name: Mapping[str, RigidBody],
    off: Mapping[str, int],
    nb: int,
    kb: np.ndarray,
    offset: int,
) -> tuple[tuple[Any, ...], float, np.ndarray]:
    """One line of the Craig–Bampton reduction: its part (L (n_dof, m + nb) = [Φ, G T]
    on the free rows and T on the end rows, K, M + M_a, end rows, T, ``offset`` of its
    modal coordinates, m), the largest entry of its free rows' assembled stiffness and
    its ends' stiffness Tᵀ K_ends T on the body DOFs (the asymmetry measure); adds the
    attachment geometric stiffness of its static end forces to ``kb`` in place."""
    model = cl.system.model
    d, nn = model.dim, model.n_nodes
    phi = np.asarray(cl.system.modes.shapes)[model.free]
    m = phi.shape[1]
    t = np.zeros((2 * d, nb))
    for k, bname in cl.attached():
        body = by_name[bname]
        node = 0 if k == 0 else nn - 1
        r = model.positions[node] - body.position
        t[k * d : (k + 1) * d, off[bname] : off[bname] + body.n_dof] = rigid_link_matrix(
            r, planar=body.planar
        )
        st = cl.system.statics
        f = np.asarray(st.force_a if k == 0 else st.force_b, dtype=float)
        sl = slice(off[bname], off[bname] + body.n_dof)
        kb[sl, sl] += attachment_geometric_stiffness(f, r, body.planar)
    ends = np.r_[np.arange(d), np.arange((nn - 1) * d, nn * d)]
    kd_ = model.K.toarray()
    md_ = model.M.toarray() + model.Ma.toarray()
    # the assembled (physical) coupling Lᵀ K L, L = [free selection, ends → T],
    # for the asymmetry measure of the full K: its free rows K[free] L and body
    # block Tᵀ K_ends T (the selection rows of Lᵀ taken by indexing)
    lp = np.zeros((model.n_dof, model.free.size + nb))
    lp[model.free, np.arange(model.free.size)] = 1.0
    lp[ends, model.free.size :] = t
    k_top = float(np.abs(kd_[model.free] @ lp).max(initial=0.0))
    k_ends = t.T @ kd_[np.ix_(ends, ends)] @ t
    ell = np.zeros((model.n_dof, m + nb))
    ell[model.free, :m] = phi
    ell[model.free, m:] = line_prep(cl.system).follower() @ t
    ell[ends, m:] = t
    return (ell, kd_, md_, ends, t, offset, m), k_top, k_ends


# ------------------------------------------------- modal damping of the coupled modes


def coupled_modal_bandwidths(
    modes: CoupledModes,
    lines: Sequence[CoupledLine],
    bodies: Sequence[RigidBody],
    line_damping: Mapping[str, Damping],
    body_drag: Mapping[str, np.ndarray] | None = None,
) -> np.ndarray:
    """Half-power bandwidths 2ζ_nω_n of the coupled modes: the diagonal of the modal
    damping.

    Parameters
    ----------
    modes : CoupledModes
        With ``line_shapes`` (:func:`coupled_modes`).
    lines : sequence of CoupledLine
        The group's lines.
    bodies : sequence of RigidBody
        Its free bodies (``extra_damping``, radiation damping, drag point).
    line_damping : mapping of str to Damping
        The converged linear drag of each line.
    body_drag : mapping of str to ndarray, shape (3,), optional
        The converged linear drag per direction at each body's drag point. [N·s/m]

    Returns
    -------
    ndarray, shape (n,)
        φ_nᵀCφ_n over the group (mass-normalized φ): per line its structural, seabed
        and drag damping on all its nodes (the attached ends moving with the bodies,
        as :func:`stochcable.dynamics.outputs.resolution.modal_bandwidths` does on the free nodes of
        a line with fixed ends), per body C_B + B(ω_ref) + Tdᵀ diag(b) Td. [rad/s]

    Notes
    -----
    ζ_n = bandwidth/(2ω_n) is the modal damping ratio of the coupled mode (the
    coupling terms of the modal damping ignored, as for a single line).  The
    radiation damping is frozen at ``modes.omega_ref`` with the added mass.
    """
    band = np.zeros(modes.omega.size)
    for cl in lines:
        u = modes.line_shapes[cl.name]
        prep = line_prep(cl.system)
        c = add_blocks(prep.S, drag_blocks(cl.system, line_damping[cl.name]))
        band += np.einsum("ndk,ndk->k", u, block_matvec(c, u))
    body_drag = {} if body_drag is None else body_drag
    for b in bodies:
        c = b.extra_damping + b.radiation_damping_at(np.array([modes.omega_ref]))[0]
        if b.name in body_drag:
            c = c + body_drag_matrix(b, np.asarray(body_drag[b.name], dtype=float))
        xi = modes.body_shapes[b.name]
        band += np.einsum("jk,jk->k", xi, c @ xi)
    return band


def line_mode_shares(modes: CoupledModes, lines: Sequence[CoupledLine]) -> dict[str, np.ndarray]:
    """Share of each coupled mode's kinetic energy in each line.

    Parameters
    ----------
    modes : CoupledModes
        With ``line_shapes``.
    lines : sequence of CoupledLine

    Returns
    -------
    dict of str to ndarray, shape (n,)
        u_lᵀ (M + M_a)_l u_l of each mass-normalized mode over the line's nodes;
        Σ_l share_l + ξᵀ(M_B + A(ω_ref))ξ = 1. [-]
    """
    out = {}
    for cl in lines:
        model = cl.system.model
        u = modes.line_shapes[cl.name].reshape(model.n_dof, -1)
        out[cl.name] = np.einsum("ik,ik->k", u, (model.M + model.Ma) @ u)
    return out
