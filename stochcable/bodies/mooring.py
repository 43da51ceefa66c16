"""Quasi-static stiffness of the lines on the bodies they hold (docs/BODIES.md §Statics).

The condensed end stiffness of every line attached to a free body, K_e = −dF_end/dx_end:
for an FE-solved line the Schur complement K_bb − K_bf K_ff⁻¹ K_fb of its FE tangent
over the interior DOFs (one banded solve, :mod:`stochcable.line.banded`), for a
catenary-solved line the central differences of the closed form; carried to the body
DOFs through the rigid link T(r) with the attachment geometric term −[F]×[r]× (Tuah
(1982), eqs. 3.3.8–3.3.10).  The interior map S = K_ff⁻¹ K_fb is the first-order interior motion
−S δx_ends of an FE line when its ends move, the predictor of the body statics' warm
start.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from stochcable.bodies.rigid import geometric_stiffness, link_matrix
from stochcable.line.banded import banded_solve, block_band_indices
from stochcable.line.elements import stiffness_blocks
from stochcable.line.statics import check_statics_options, solve_line_statics_unchecked
from stochcable.scene.model import Scene

__all__ = ["mooring_stiffness", "mooring_stiffness_and_maps", "end_condensation", "pose_map"]


def mooring_stiffness(
    scene: Scene,
    lines: dict[str, Any],
    poses: dict[str, np.ndarray],
    bodies: list[str],
    planar: bool,
    method: str = "auto",
    tolerance: float = 1e-10,
) -> np.ndarray:
    """Quasi-static stiffness of the lines on the free bodies' DOFs.

    Parameters
    ----------
    scene : Scene
    lines : dict of str to LineStatics
        The lines' statics at the poses.
    poses : dict of str to ndarray (6,)
        Body poses (X, θ).
    bodies : list of str
        The free bodies, in the order of the result's blocks.
    planar : bool
    method : str
        Line statics method, for the finite differences of catenary lines.
    tolerance : float
        Their statics tolerance. [-]

    Returns
    -------
    ndarray, shape (n_b·d, n_b·d)
        −dQ_lines/dq = Σ Tᵀ K_e T − [F]×[r]× (Tuah (1982), eqs. 3.3.8–3.3.10 and the
        attachment geometric term, :func:`stochcable.bodies.rigid.attachment_geometric_stiffness`),
        K_e = −dF_end/dx_end the condensed end stiffness of each line: the Schur
        complement of its FE tangent over the interior DOFs for an FE-solved line, the
        central differences of the closed-form catenary for a catenary-solved one (so
        that the stiffness is that of the statics actually solved). [N/m, N, N·m/rad]
    """
    method, tolerance, _ = check_statics_options(method, tolerance, 500)
    return mooring_stiffness_and_maps(scene, lines, poses, bodies, planar, method, tolerance)[0]


def mooring_stiffness_and_maps(
    scene: Scene,
    lines: dict[str, Any],
    poses: dict[str, np.ndarray],
    bodies: list[str],
    planar: bool,
    method: str,
    tolerance: float,
    end_position: Any = None,
) -> tuple[np.ndarray, dict[str, tuple[list[str], np.ndarray]]]:
    """:func:`mooring_stiffness` and, by line name, the ends on the bodies and the
    interior map S of :func:`end_condensation` (FE-solved lines only); ``method`` and
    ``tolerance`` checked (:func:`stochcable.line.statics.check_statics_options`).
    ``end_position(line, end, poses)``: the end positions (default
    ``scene.end_position`` at ``poses``)."""
    maps: dict[str, tuple[list[str], np.ndarray]] = {}
    d = 3 if planar else 6
    n = len(bodies) * d
    K = np.zeros((n, n))
    block = {nm: i * d for i, nm in enumerate(bodies)}
    pm = pose_map(poses)
    for ln in scene.lines:
        ends = [
            (end, getattr(ln, end).attach.body)
            for end in ("end_a", "end_b")
            if getattr(ln, end).attach is not None and getattr(ln, end).attach.body in block
        ]
        if not ends:
            continue
        ls = lines[ln.name]
        names = [e for e, _ in ends]
        ke, smap = end_condensation(scene, ln, ls, names, planar, method, tolerance)
        if smap is not None:
            maps[ln.name] = (names, smap)
        c = 2 if planar else 3
        comps = [0, 2] if planar else [0, 1, 2]
        tmat = []
        for end, bname in ends:
            r = (
                scene.end_position(ln, end, pm)
                if end_position is None
                else end_position(ln, end, poses)
            ) - poses[bname][:3]
            t = link_matrix(r, planar)
            tmat.append(t[comps] if t.shape[0] == 3 and planar else t)
            f = ls.force_a if end == "end_a" else ls.force_b
            i = block[bname]
            K[i : i + d, i : i + d] += geometric_stiffness(f, r, planar)
        for p_, (_, bp) in enumerate(ends):
            for q_, (_, bq) in enumerate(ends):
                kpq = ke[p_ * c : (p_ + 1) * c, q_ * c : (q_ + 1) * c]
                i, j = block[bp], block[bq]
                K[i : i + d, j : j + d] += tmat[p_].T @ kpq @ tmat[q_]
    return K, maps


def end_condensation(
    scene: Scene, line: Any, ls: Any, ends: list[str], planar: bool, method: str, tolerance: float
) -> tuple[np.ndarray, np.ndarray | None]:
    """Condensed end stiffness K_e = −dF/dx of the given ends of a line (2 or 3
    components each, the other end held) and, for an FE-solved line, the interior map S.

    K_e = K_bb − K_bf K_ff⁻¹ K_fb over the FE tangent K of :mod:`stochcable.line.fem`
    (the matrix :func:`stochcable.line.fem.build_fe_model` assembles: element tangents
    (EA/l0) e eᵀ + (T/l)(I − e eᵀ), slack elements with EA·``SLACK_EA_RATIO`` and no
    tension, seabed springs on the grounded nodes), in the global components (x, z)
    planar or (x, y, z); S = K_ff⁻¹ K_fb, shape (n_interior·c, c·n_ends), gives the
    first-order interior displacement −S δx_ends when the ends move (the predictor of
    the warm start).  K_ff is block tridiagonal: one banded solve.  For a
    catenary-solved line, central differences of the closed form and S = None.
    """
    env = scene.environment
    comps = [0, 2] if planar else [0, 1, 2]
    c = len(comps)
    if ls.method == "fe":
        return _fe_condensation(ls, env, ends, comps)
    # closed form: central differences of the end forces
    mesh = ls.mesh
    h = 1e-5 * max(mesh.length, 1.0)
    out = np.zeros((len(ends) * c, len(ends) * c))
    for q_, e in enumerate(ends):
        for k, comp in enumerate(comps):
            fs = []
            for sgn in (1.0, -1.0):
                pos = getattr(mesh, e).copy()
                pos[comp] += sgn * h
                m2 = dataclasses.replace(mesh, **{e: pos})
                l2 = solve_line_statics_unchecked(m2, env, method, None, tolerance, 500)
                fs.append(
                    np.concatenate(
                        [(l2.force_a if p == "end_a" else l2.force_b)[comps] for p in ends]
                    )
                )
            out[:, q_ * c + k] = -(fs[0] - fs[1]) / (2.0 * h)
    return out, None


def _fe_condensation(
    ls: Any, env: Any, ends: list[str], comps: list[int]
) -> tuple[np.ndarray, np.ndarray]:
    """K_e and S of :func:`end_condensation` for an FE-solved line.

    Besides the FE tangent, the vertical derivative of the weight of the elements
    that cross the water surface (their wet fraction moves with their end heights,
    the term of the statics' own tangent, :class:`stochcable.line.equilibrium.StaticsModel`):
    without it the stiffness of a float piercing the surface was a tenth of the true
    one and the body Newton of a float on a tether stalled."""
    c = len(comps)
    mesh = ls.mesh
    n = mesh.n_nodes
    pos = np.asarray(ls.positions, dtype=float)[:, comps]
    dd = pos[1:] - pos[:-1]
    ll = np.sqrt(np.einsum("ij,ij->i", dd, dd))
    k = stiffness_blocks(
        dd / ll[:, None], ll, mesh.l0, mesh.ea, np.asarray(ls.tension, dtype=float)
    )  # (n_el, c, c)
    diag = np.zeros((n, c, c))
    diag[:-1] += k
    diag[1:] += k
    upper, lower = -k, -k.copy()  # K[i, i+1] and K[i+1, i] of element i
    trib = np.zeros(n)
    half = 0.5 * mesh.diameter * mesh.l0
    trib[:-1] += half
    trib[1:] += half
    zc = comps.index(2)
    diag[:, zc, zc] += env.seabed.stiffness * np.where(ls.grounded, trib, 0.0)
    z = np.asarray(ls.positions, dtype=float)[:, 2]
    za, zb = z[:-1], z[1:]
    mixed = (np.minimum(za, zb) < 0.0) & (np.maximum(za, zb) > 0.0)
    if mixed.any():
        # W = l0 (w_dry + f (w_sub − w_dry)), f = −min(za, zb)/|zb − za| lumped half
        # to each node: −dR/dz as in StaticsModel._tangent
        dz = np.where(mixed, zb - za, 1.0)
        dw = 0.5 * mesh.l0 * (mesh.weight - mesh.mass * env.g)
        dwa = dw * np.where(mixed, np.where(za < zb, -zb, zb) / dz**2, 0.0)
        dwb = dw * np.where(mixed, np.where(za < zb, za, -za) / dz**2, 0.0)
        diag[:-1, zc, zc] += dwa
        diag[1:, zc, zc] += dwb
        upper[:, zc, zc] += dwb
        lower[:, zc, zc] += dwa
    node = {"end_a": 0, "end_b": n - 1}
    ne = len(ends)
    kbb = np.zeros((ne * c, ne * c))
    for p_, e in enumerate(ends):
        kbb[p_ * c : (p_ + 1) * c, p_ * c : (p_ + 1) * c] = diag[node[e]]
    nf = n - 2
    if nf == 0:
        if ne == 2:
            kbb[:c, c:] = upper[0]
            kbb[c:, :c] = lower[0]
        return kbb, np.zeros((0, ne * c))
    # K_fb and K_bf: the element next to each end couples it to its neighbour node
    kfb = np.zeros((nf * c, ne * c))
    kbf = np.zeros((ne * c, nf * c))
    for p_, e in enumerate(ends):
        if e == "end_a":
            kfb[:c, p_ * c : (p_ + 1) * c] = lower[0]
            kbf[p_ * c : (p_ + 1) * c, :c] = upper[0]
        else:
            kfb[(nf - 1) * c :, p_ * c : (p_ + 1) * c] = upper[-1]
            kbf[p_ * c : (p_ + 1) * c, (nf - 1) * c :] = lower[-1]
    bw = 2 * c - 1
    rows, cols = block_band_indices(nf, c)
    ab = np.zeros((3 * bw + 1, nf * c), order="F")  # gbsv's layout (banded_solve)
    # diagonal blocks of the interior nodes, then the couplings of elements 1 … n−3
    ab[rows + bw, cols] = np.concatenate(
        [diag[1:-1].ravel(), upper[1:-1].ravel(), lower[1:-1].ravel()]
    )
    S = banded_solve(ab, kfb, bw)
    return kbb - kbf @ S, S


def pose_map(poses: dict[str, np.ndarray]) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """(X, θ) pairs of :meth:`stochcable.scene.model.Scene.end_position` from poses (6,)."""
    return {nm: (p[:3], p[3:]) for nm, p in poses.items()}
