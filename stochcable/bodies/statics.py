"""Static equilibrium of bodies and their lines (issue 6; docs/BODIES.md §Statics).

The unknowns are the poses q = (X, θ) of the free bodies (6 DOF; planar scenes 3:
surge, heave, pitch), X the reference point [m] and θ a rotation vector [rad].  The
generalized force on a body about its reference point is

    Q(q) = Σ_lines [F_ℓ; (R r_ℓ) × F_ℓ] + Q_grav + Q_hydro + Q_wind + Q_drag,

F_ℓ the static force a line exerts on its end at X + R(θ)·r_ℓ (each line solved by
:func:`stochcable.line.statics.solve_line_statics` with that end fixed), and Newton's
method solves Q = 0 with the tangent stiffness K = −dQ/dq: the condensed end stiffness
of every line (Schur complement K_bb − K_bf K_ff⁻¹ K_fb of its FE tangent, the matrix
of :func:`stochcable.line.fem.build_fe_model`, over the interior DOFs: one banded solve)
including the attachment geometric term −[F]×[r]× (seed 001 eqs. 3.3.8–3.3.10
linearized about the static state), the hydrostatic matrix, and the geometric terms
of the point forces whose moment arm rotates (weight, buoyancy, drag).  K is exact, so
the iteration converges quadratically.  K at the solution is reported as the
quasi-static mooring + hydrostatic stiffness.  Each FE line of a Newton trial is
warm-started from its shape at the current iterate plus the first-order interior motion
−K_ff⁻¹ K_fb δx_ends of the same condensation (the static-condensation predictor), which
usually leaves one or two line Newton steps (a cold start if that start fails).

Body loads (seed 001 eq. 3.2.c.20, the static F̄):

- with ``displaced_volume`` ∇ and a non-zero ``hydrostatic_stiffness`` K_h (a floating
  body): weight −m g ẑ at the CoG and buoyancy ρ g ∇ ẑ at the CoB evaluated at zero
  rotation, plus the linear restoring −K_h (q − q₀) about ``position`` (K_h holds the
  rotation terms of weight and buoyancy, as WAMIT/Capytaine give it);
- with ∇ and no K_h (a submerged body): weight at R·r_G and buoyancy at R·r_B, exact;
- without ∇ but with K_h: the body is taken as freely floating in equilibrium at
  ``position`` (weight balanced by buoyancy), restored by −K_h (q − q₀) only;
- without ∇ and K_h: the weight alone at R·r_G (no buoyancy);
- ``wind_force``/``wind_moment`` at the reference point (seed 001 §6.5's 100 lb wind);
- current drag ½ ρ (Cd·A)_i |U| U_i at R·``drag_point`` with U the current there.

Prescribed bodies (vessels) are not solved for: their pose is ``position``, no rotation.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from stochcable.bodies.rigid import (
    PLANAR_DOFS,
    PLANAR_INDEX,
    SPATIAL_DOFS,
    RigidBody,
    attachment_geometric_stiffness,
)
from stochcable.validation import positive, positive_int
from stochcable.errors import ConvergenceError, InputError
from stochcable.line.fem import _stiffness_blocks
from stochcable.line.mesh import mesh_line
from stochcable.scene.model import Scene, rotate
from stochcable.line.statics import _banded_solve, _block_band_indices

__all__ = ["BodyStatics", "solve_body_statics", "body_static_load",
           "mooring_stiffness"]


@dataclass(frozen=True, eq=False)
class BodyStatics:
    """Static equilibrium of one body.

    Attributes
    ----------
    name : str
    position : ndarray, shape (3,)
        Reference point at equilibrium. [m]
    rotation : ndarray, shape (3,)
        Rotation vector from the input orientation (planar: only θ_y). [rad]
    line_forces : dict of str to ndarray (3,)
        Force each attached line exerts on the body at its attachment, by line name
        (``"<line>.end_a"``/``".end_b"`` when both ends of a line are on the body). [N]
    iterations : int
        Newton iterations (0 for a prescribed body).
    residual : float
        Final max |generalized force| / reference force (moments divided by the
        reference length too). [-]
    stiffness : ndarray, shape (d, d)
        −dQ/dq at equilibrium: quasi-static line stiffness (with the attachment
        geometric terms) + hydrostatics + extra stiffness + geometric terms of weight,
        buoyancy and drag, over the body DOFs ``dofs`` (zeros for a prescribed body),
        for translations and small *global* rotations about the static pose (the DOFs
        of the dynamics); the derivative in the rotation vector differs from it by
        O(|rotation|) in 3-D. [N/m, N, N·m/rad]
    dofs : tuple of str
        The DOF names (6, or surge, heave, pitch when planar).
    prescribed : bool
        True for a vessel (pose imposed).
    """

    name: str
    position: np.ndarray
    rotation: np.ndarray
    line_forces: dict[str, np.ndarray] = field(default_factory=dict)
    iterations: int = 0
    residual: float = 0.0
    stiffness: np.ndarray = field(default_factory=lambda: np.zeros((6, 6)))
    dofs: tuple[str, ...] = SPATIAL_DOFS
    prescribed: bool = False

    def to_document(self) -> dict[str, Any]:
        """The body's entry of the result document's ``statics.bodies``."""
        return {
            "position": [float(v) for v in self.position],
            "rotation": [float(v) for v in self.rotation],
            "line_forces": {k: [float(x) for x in v] for k, v in self.line_forces.items()},
            "iterations": int(self.iterations),
            "residual": float(self.residual),
            "dofs": list(self.dofs),
            "stiffness": np.asarray(self.stiffness, dtype=float).tolist(),
            "prescribed": bool(self.prescribed),
        }


# ------------------------------------------------------------------------- helpers


def _full(q: np.ndarray, planar: bool) -> np.ndarray:
    """6-vector (X, θ) from a body DOF vector."""
    if not planar:
        return np.asarray(q, dtype=float)
    out = np.zeros(6)
    out[list(PLANAR_INDEX)] = q
    return out


def _reduce(v6: np.ndarray, planar: bool) -> np.ndarray:
    return v6[list(PLANAR_INDEX)] if planar else v6


def body_static_load(scene: Scene, name: str, pose: Any, rigid: RigidBody | None = None
                     ) -> tuple[np.ndarray, np.ndarray]:
    """Generalized static force on a body from everything but its lines.

    Parameters
    ----------
    scene : Scene
    name : str
        The body.
    pose : array_like, shape (6,)
        (X, θ): reference point [m] and rotation vector [rad].
    rigid : RigidBody, optional
        The body's RigidBody (for its hydrostatic matrix); default from the scene.

    Returns
    -------
    load : ndarray, shape (6,)
        (F, M) about the reference point, global axes. [N, N·m]
    stiffness : ndarray, shape (6, 6)
        −d load/d pose: K_h plus the geometric terms −[F]×[r]× of the point forces
        whose arm rotates. [N/m, N, N·m/rad]

    Notes
    -----
    Load model: module docstring.
    """
    from stochcable.bodies.from_scene import rigid_body_from_scene

    b = scene.body(name)
    env = scene.environment
    rho, g = env.rho, env.g
    if rigid is None:
        rigid = rigid_body_from_scene(b, planar=False, environment=env)
    pose = np.asarray(pose, dtype=float)
    x, th = pose[:3], pose[3:]
    kh = np.asarray(rigid.hydrostatic_stiffness, dtype=float)
    if kh.shape == (3, 3):
        k6 = np.zeros((6, 6))
        k6[np.ix_(PLANAR_INDEX, PLANAR_INDEX)] = kh
        kh = k6
    has_kh = bool(np.any(kh != 0.0))
    q0 = np.concatenate([np.asarray(b.position, dtype=float), np.zeros(3)])
    load = np.concatenate([np.asarray(b.wind_force, float), np.asarray(b.wind_moment, float)])
    stiff = np.zeros((6, 6))

    def point(force: np.ndarray, r_body: Any, rotates: bool) -> None:
        nonlocal load, stiff
        r = np.asarray(r_body, dtype=float)
        arm = rotate(th, r) if rotates else r
        load = load + np.concatenate([force, np.cross(arm, force)])
        if rotates:
            stiff = stiff + _geo6(force, arm)

    weight = np.array([0.0, 0.0, -b.mass * g])
    if b.displaced_volume is not None:
        buoy = np.array([0.0, 0.0, rho * g * b.displaced_volume])
        point(weight, b.cog, not has_kh)
        point(buoy, b.centre_of_buoyancy, not has_kh)
    elif not has_kh:
        point(weight, b.cog, True)
    if has_kh:
        load = load - kh @ (pose - q0)
        stiff = stiff + kh
    cda = np.asarray(b.drag_area, dtype=float)
    if np.any(cda > 0.0) and env.current:
        dp = x + rotate(th, np.asarray(b.drag_point, float))
        u = env.current_velocity(np.array([dp[2]]))[0]
        fd = 0.5 * rho * cda * float(np.linalg.norm(u)) * u
        point(fd, b.drag_point, True)
    return load, stiff


def _cross3(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a × b of two 3-vectors: np.cross's products and differences in its order (the
    same bits) without its generic broadcasting path (≈ 40 µs per call)."""
    a0, a1, a2 = float(a[0]), float(a[1]), float(a[2])
    b0, b1, b2 = float(b[0]), float(b[1]), float(b[2])
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


def _geo6(force: np.ndarray, arm: np.ndarray) -> np.ndarray:
    return attachment_geometric_stiffness(force, arm, False)


def mooring_stiffness(scene: Scene, lines: dict[str, Any], poses: dict[str, np.ndarray],
                      bodies: list[str], planar: bool, method: str = "auto",
                      tolerance: float = 1e-10) -> np.ndarray:
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
        −dQ_lines/dq = Σ Tᵀ K_e T − [F]×[r]× (seed 001 eqs. 3.3.8–3.3.10 and the
        attachment geometric term, :func:`stochcable.bodies.rigid.attachment_geometric_stiffness`),
        K_e = −dF_end/dx_end the condensed end stiffness of each line: the Schur
        complement of its FE tangent over the interior DOFs for an FE-solved line, the
        central differences of the closed-form catenary for a catenary-solved one (so
        that the stiffness is that of the statics actually solved). [N/m, N, N·m/rad]
    """
    return _mooring_stiffness(scene, lines, poses, bodies, planar, method, tolerance)[0]


def _mooring_stiffness(scene: Scene, lines: dict[str, Any], poses: dict[str, np.ndarray],
                       bodies: list[str], planar: bool, method: str, tolerance: float,
                       end_position: Any = None
                       ) -> tuple[np.ndarray, dict[str, tuple[list[str], np.ndarray]]]:
    """:func:`mooring_stiffness` and, by line name, the ends on the bodies and the
    interior map S of :func:`_end_condensation` (FE-solved lines only).
    ``end_position(line, end, poses)``: the end positions (default
    ``scene.end_position`` at ``poses``)."""
    from stochcable.bodies.rigid import rigid_link_matrix

    maps: dict[str, tuple[list[str], np.ndarray]] = {}
    d = 3 if planar else 6
    n = len(bodies) * d
    K = np.zeros((n, n))
    block = {nm: i * d for i, nm in enumerate(bodies)}
    pm = _pose_map(poses)
    for ln in scene.lines:
        ends = [(end, getattr(ln, end).attach.body) for end in ("end_a", "end_b")
                if getattr(ln, end).attach is not None
                and getattr(ln, end).attach.body in block]
        if not ends:
            continue
        ls = lines[ln.name]
        names = [e for e, _ in ends]
        ke, smap = _end_condensation(scene, ln, ls, names, planar, method, tolerance)
        if smap is not None:
            maps[ln.name] = (names, smap)
        c = 2 if planar else 3
        comps = [0, 2] if planar else [0, 1, 2]
        tmat = []
        for end, bname in ends:
            r = (scene.end_position(ln, end, pm) if end_position is None
                 else end_position(ln, end, poses)) - poses[bname][:3]
            t = rigid_link_matrix(r, planar)
            tmat.append(t[comps] if t.shape[0] == 3 and planar else t)
            f = ls.force_a if end == "end_a" else ls.force_b
            i = block[bname]
            K[i:i + d, i:i + d] += attachment_geometric_stiffness(f, r, planar)
        for p_, (_, bp) in enumerate(ends):
            for q_, (_, bq) in enumerate(ends):
                kpq = ke[p_ * c:(p_ + 1) * c, q_ * c:(q_ + 1) * c]
                i, j = block[bp], block[bq]
                K[i:i + d, j:j + d] += tmat[p_].T @ kpq @ tmat[q_]
    return K, maps


def _end_condensation(scene: Scene, line: Any, ls: Any, ends: list[str], planar: bool,
                      method: str, tolerance: float
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
    from stochcable.line.statics import solve_line_statics

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
                l2 = solve_line_statics(m2, env, method=method, tolerance=tolerance)
                fs.append(np.concatenate([(l2.force_a if p == "end_a" else l2.force_b)[comps]
                                          for p in ends]))
            out[:, q_ * c + k] = -(fs[0] - fs[1]) / (2.0 * h)
    return out, None


def _fe_condensation(ls: Any, env: Any, ends: list[str], comps: list[int]
                     ) -> tuple[np.ndarray, np.ndarray]:
    """K_e and S of :func:`_end_condensation` for an FE-solved line."""
    c = len(comps)
    mesh = ls.mesh
    n = mesh.n_nodes
    pos = np.asarray(ls.positions, dtype=float)[:, comps]
    dd = pos[1:] - pos[:-1]
    ll = np.sqrt(np.einsum("ij,ij->i", dd, dd))
    k = _stiffness_blocks(dd / ll[:, None], ll, mesh.l0, mesh.ea,
                          np.asarray(ls.tension, dtype=float))  # (n_el, c, c)
    diag = np.zeros((n, c, c))
    diag[:-1] += k
    diag[1:] += k
    trib = np.zeros(n)
    half = 0.5 * mesh.diameter * mesh.l0
    trib[:-1] += half
    trib[1:] += half
    zc = comps.index(2)
    diag[:, zc, zc] += env.seabed.stiffness * np.where(ls.grounded, trib, 0.0)
    node = {"end_a": 0, "end_b": n - 1}
    ne = len(ends)
    kbb = np.zeros((ne * c, ne * c))
    for p_, e in enumerate(ends):
        kbb[p_ * c:(p_ + 1) * c, p_ * c:(p_ + 1) * c] = diag[node[e]]
    nf = n - 2
    if nf == 0:
        if ne == 2:
            kbb[:c, c:] = -k[0]
            kbb[c:, :c] = -k[0]
        return kbb, np.zeros((0, ne * c))
    # K_fb: the element next to each end couples it to its neighbour node
    kfb = np.zeros((nf * c, ne * c))
    for p_, e in enumerate(ends):
        if e == "end_a":
            kfb[:c, p_ * c:(p_ + 1) * c] = -k[0]
        else:
            kfb[(nf - 1) * c:, p_ * c:(p_ + 1) * c] = -k[-1]
    bw = 2 * c - 1
    rows, cols = _block_band_indices(nf, c)
    ab = np.zeros((3 * bw + 1, nf * c), order="F")  # gbsv's layout (_banded_solve)
    # diagonal blocks of the interior nodes, then the couplings −k_i (i = 1 … n−3)
    ab[rows + bw, cols] = np.concatenate([diag[1:-1].ravel(), (-k[1:-1]).ravel(),
                                          (-k[1:-1]).ravel()])
    S = _banded_solve(ab, kfb, bw)
    return kbb - kfb.T @ S, S


# ---------------------------------------------------------------------- the solver


def solve_body_statics(scene: Scene, method: str = "auto", *, tolerance: float = 1e-10,
                       max_iterations: int = 500, body_tolerance: float = 1e-8,
                       max_body_iterations: int = 60
                       ) -> tuple[dict[str, Any], dict[str, BodyStatics]]:
    """Static equilibrium of a scene with bodies: Newton on the free body poses.

    Parameters
    ----------
    scene : Scene
        A validated scene with ``bodies``.
    method : {"auto", "fe", "catenary"}
        Line statics method (:func:`stochcable.line.statics.solve_line_statics`).
    tolerance, max_iterations
        Line statics tolerance [-] and iteration budget.
    body_tolerance : float
        Relative residual of the body equilibrium (forces / reference force, moments /
        (reference force · reference length)). [-]
    max_body_iterations : int
        Newton iterations on the poses.

    Returns
    -------
    lines : dict of str to LineStatics
        Every line, attached ends at X + R(θ)·r.
    bodies : dict of str to BodyStatics

    Raises
    ------
    InputError
        A free body DOF without restoring (named), e.g. yaw of a buoy on one line:
        hold it with ``fixed_dofs`` or give a stiffness.
    ConvergenceError
        Newton did not reach ``body_tolerance`` (residual and partial poses given).

    Notes
    -----
    Module docstring; docs/BODIES.md §Statics.  Seed 001 §4.1 (static configuration
    as the starting state), eq. 3.2.c.20 (static force F̄), eqs. 3.3.6–3.3.10.
    """
    from stochcable.bodies.from_scene import scene_rigid_bodies
    from stochcable.line.statics import solve_line_statics

    body_tolerance = positive("body_tolerance", body_tolerance, "-")
    max_body_iterations = positive_int("max_body_iterations", max_body_iterations)
    env = scene.environment
    planar = scene.is_planar
    d = 3 if planar else 6
    dofs = PLANAR_DOFS if planar else SPATIAL_DOFS
    rigid = scene_rigid_bodies(scene)
    free = [b.name for b in scene.bodies if b.prescribed is None]
    poses = {b.name: np.concatenate([np.asarray(b.position, float), np.zeros(3)])
             for b in scene.bodies}
    attached = {ln.name: {end: getattr(ln, end).attach.body for end in ("end_a", "end_b")
                          if getattr(ln, end).attach is not None} for ln in scene.lines}
    moving = [ln for ln in scene.lines if any(b in free for b in attached[ln.name].values())]
    lines: dict[str, Any] = {}
    for ln in scene.lines:
        if ln not in moving:
            mesh = mesh_line(scene.resolved_line(ln, _pose_map(poses)), env.rho, env.g)
            lines[ln.name] = solve_line_statics(mesh, env, method=method, tolerance=tolerance,
                                                max_iterations=max_iterations)
    meshes = {ln.name: mesh_line(scene.resolved_line(ln), env.rho, env.g) for ln in moving}

    comps = [0, 2] if planar else [0, 1, 2]
    c = len(comps)
    end_memo: dict[tuple, np.ndarray] = {}

    def end_pos(ln: Any, end: str, pz: dict[str, np.ndarray]) -> np.ndarray:
        """``scene.end_position(ln, end, _pose_map(pz))``, memoized on the attached
        body's pose (the lines' solve, the forces and the stiffness ask for the same
        ends at the same trial pose)."""
        a = getattr(ln, end).attach
        key = (ln.name, end, None if a is None or a.body not in pz
               else pz[a.body].tobytes())
        hit = end_memo.get(key)
        if hit is None:
            hit = end_memo[key] = scene.end_position(ln, end, _pose_map(pz))
        return hit.copy()

    def solve_lines(pz: dict[str, np.ndarray], base: dict[str, Any] | None = None,
                    maps: dict[str, tuple[list[str], np.ndarray]] | None = None
                    ) -> dict[str, Any]:
        """The moving lines at the poses pz, each FE line warm-started from its shape
        in ``base`` plus the first-order interior motion −S δx_ends (``maps``, the
        static condensation of its tangent); a cold start if that fails."""
        out = {}
        for ln in moving:
            mesh = dataclasses.replace(meshes[ln.name],
                                       end_a=end_pos(ln, "end_a", pz),
                                       end_b=end_pos(ln, "end_b", pz))
            prev = None if base is None else base.get(ln.name)
            init = None
            if prev is not None and prev.method == "fe":
                init = prev.positions.copy()
                m = None if maps is None else maps.get(ln.name)
                if m is not None and m[1].size:
                    ends, smap = m
                    dxb = np.concatenate([
                        (mesh.end_a if e == "end_a" else mesh.end_b)[comps]
                        - prev.positions[0 if e == "end_a" else -1, comps] for e in ends])
                    init[1:-1, comps] -= (smap @ dxb).reshape(-1, c)
                init[0], init[-1] = mesh.end_a, mesh.end_b
            try:
                out[ln.name] = solve_line_statics(mesh, env, method=method, initial=init,
                                                  tolerance=tolerance,
                                                  max_iterations=max_iterations)
            except ConvergenceError:
                if init is None:
                    raise
                out[ln.name] = solve_line_statics(mesh, env, method=method,
                                                  tolerance=tolerance,
                                                  max_iterations=max_iterations)
        return out

    # active unknowns
    active: list[tuple[str, int]] = []
    for nm in free:
        fixed = set(scene.body(nm).fixed_dofs)
        for k, dn in enumerate(dofs):
            if dn not in fixed:
                active.append((nm, k))
    pos_in_block = {nm: i for i, nm in enumerate(free)}
    sel = np.array([pos_in_block[nm] * d + k for nm, k in active], dtype=int)

    def q_of(pz: dict[str, np.ndarray]) -> np.ndarray:
        return np.concatenate([_reduce(pz[nm], planar) for nm in free]) if free else \
            np.zeros(0)

    def forces(pz: dict[str, np.ndarray], ls: dict[str, Any]
               ) -> tuple[np.ndarray, np.ndarray, dict[str, dict[str, np.ndarray]],
                          dict[str, tuple[list[str], np.ndarray]]]:
        """Generalized forces (n_free·d,), stiffness (n_free·d)², line forces, and the
        lines' interior maps (:func:`_mooring_stiffness`)."""
        Q = np.zeros(len(free) * d)
        K = np.zeros((len(free) * d, len(free) * d))
        lf: dict[str, dict[str, np.ndarray]] = {b.name: {} for b in scene.bodies}
        allls = {**lines, **ls}
        for ln in scene.lines:
            for end, bname in attached[ln.name].items():
                f = np.asarray(getattr(allls[ln.name], "force_" + end[-1]), dtype=float)
                key = ln.name if len(attached[ln.name]) == 1 or \
                    len(set(attached[ln.name].values())) == 2 else f"{ln.name}.{end}"
                lf[bname][key] = f
                if bname not in pos_in_block:
                    continue
                p = pz[bname]
                arm = end_pos(ln, end, pz) - p[:3]
                i = pos_in_block[bname] * d
                Q[i:i + d] += _reduce(np.concatenate([f, _cross3(arm, f)]), planar)
        for nm in free:
            i = pos_in_block[nm] * d
            load, st = body_static_load(scene, nm, pz[nm], rigid[nm])
            Q[i:i + d] += _reduce(load, planar)
            K[i:i + d, i:i + d] += st[np.ix_(PLANAR_INDEX, PLANAR_INDEX)] if planar else st
            K[i:i + d, i:i + d] += np.asarray(rigid[nm].extra_stiffness, float)
            Q[i:i + d] -= np.asarray(rigid[nm].extra_stiffness, float) @ (
                _reduce(pz[nm], planar) - _reduce(
                    np.concatenate([np.asarray(scene.body(nm).position, float),
                                    np.zeros(3)]), planar))
        maps: dict[str, tuple[list[str], np.ndarray]] = {}
        if free:
            km, maps = _mooring_stiffness(scene, allls, pz, free, planar, method, tolerance,
                                          end_position=end_pos)
            K += km
        return Q, K, lf, maps

    # scales
    fref = 0.0
    lref = 0.0
    for b in scene.bodies:
        fref = max(fref, b.mass * env.g, env.rho * env.g * (b.displaced_volume or 0.0),
                   float(np.linalg.norm(b.wind_force)))
        for v in (b.cog, b.centre_of_buoyancy, b.drag_point):
            lref = max(lref, float(np.linalg.norm(v)))
    for ln in scene.lines:
        for end in ("end_a", "end_b"):
            a = getattr(ln, end).attach
            if a is not None:
                lref = max(lref, float(np.linalg.norm(a.point)))
    lref = lref if lref > 0.0 else 1.0

    def scaled(Q: np.ndarray) -> float:
        if Q.size == 0:
            return 0.0
        qq = Q.reshape(len(free), d).copy()
        rot = [2] if planar else [3, 4, 5]
        qq[:, rot] /= lref
        qq = qq.reshape(-1)[sel] if sel.size else qq.reshape(-1)[:0]
        return float(np.abs(qq).max(initial=0.0)) / fref

    try:
        ls = solve_lines(poses)
    except InputError as exc:
        where = ", ".join(f"{nm} at {np.round(poses[nm][:3], 6).tolist()}" for nm in free)
        raise InputError(exc.parameter, exc.value, exc.unit,
                         f"{exc.constraint} (at the initial body positions: {where}; give "
                         "positions near equilibrium with the lines neither slack on the "
                         "seabed nor over-stretched)") from None
    lines_all = {**lines, **ls}
    for ln in moving:
        fref = max(fref, float(lines_all[ln.name].tension.max(initial=0.0)),
                   float(lines_all[ln.name].tension_a), float(lines_all[ln.name].tension_b))
    fref = fref if fref > 0.0 else 1.0
    Q, K, lf, maps = forces(poses, ls)
    it = 0
    r = scaled(Q)
    if free and sel.size:
        _check_determined(K, sel, active, free, d, planar, lref, dofs)
    while r > body_tolerance and it < max_body_iterations and sel.size:
        it += 1
        Ka = K[np.ix_(sel, sel)]
        try:
            dq_a = np.linalg.solve(Ka, Q[sel])
        except np.linalg.LinAlgError:
            dq_a = np.linalg.lstsq(Ka, Q[sel], rcond=None)[0]
        dq = np.zeros(len(free) * d)
        dq[sel] = dq_a
        step, accepted = 1.0, False
        for _ in range(12):
            trial = {nm: p.copy() for nm, p in poses.items()}
            for nm in free:
                i = pos_in_block[nm] * d
                trial[nm] = trial[nm] + _full(step * dq[i:i + d], planar)
            try:
                ls_t = solve_lines(trial, ls, maps)
                Q_t, K_t, lf_t, maps_t = forces(trial, ls_t)
            except (ConvergenceError, InputError):
                # a line that cannot reach or goes slack at the trial pose: shorter step
                step *= 0.5
                continue
            r_t = scaled(Q_t)
            if r_t < r or step < 1.0 / 1024:
                poses, ls, Q, K, lf, maps, r = trial, ls_t, Q_t, K_t, lf_t, maps_t, r_t
                accepted = True
                break
            step *= 0.5
        if not accepted:
            break
        lines.update(ls)
    lines.update(ls)
    if r > body_tolerance:
        raise ConvergenceError(
            "body statics Newton", it, r, body_tolerance,
            hint=("check that the lines can hold the bodies (weight, buoyancy, wind): "
                  "a body held only by lines slack on the frictionless seabed has an "
                  "undetermined position; give initial positions near equilibrium, "
                  "raise max_body_iterations or give fixed_dofs for DOFs without "
                  "restoring"),
            partial={nm: poses[nm].copy() for nm in free},
        )
    out: dict[str, BodyStatics] = {}
    for b in scene.bodies:
        p = poses[b.name]
        if b.name in pos_in_block:
            i = pos_in_block[b.name] * d
            st = K[i:i + d, i:i + d].copy()
            res, iters = r, it
        else:
            st, res, iters = np.zeros((d, d)), 0.0, 0
        out[b.name] = BodyStatics(
            name=b.name, position=p[:3].copy(), rotation=p[3:].copy(),
            line_forces=lf[b.name], iterations=iters, residual=res, stiffness=st,
            dofs=dofs, prescribed=b.prescribed is not None)
    return {ln.name: lines[ln.name] for ln in scene.lines}, out


def _pose_map(poses: dict[str, np.ndarray]) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    return {nm: (p[:3], p[3:]) for nm, p in poses.items()}


def _check_determined(K: np.ndarray, sel: np.ndarray, active: list[tuple[str, int]],
                      free: list[str], d: int, planar: bool, lref: float,
                      dofs: tuple[str, ...]) -> None:
    """InputError naming a body DOF without restoring (singular K on the unknowns)."""
    scale = np.ones(len(free) * d)
    rot = [2] if planar else [3, 4, 5]
    for i in range(len(free)):
        scale[i * d + np.array(rot)] = 1.0 / lref
    Ks = (scale[:, None] * K * scale[None, :])[np.ix_(sel, sel)]
    big = float(np.abs(Ks).max(initial=0.0))
    if big == 0.0:
        nm, k = active[0]
        raise InputError(f"bodies[{nm}].{dofs[k]}", 0.0, "N/m", "has no restoring force "
                         "(no line, hydrostatic or extra stiffness): the static pose is "
                         "undetermined; hold the DOF with fixed_dofs or add a stiffness")
    u, s, vt = np.linalg.svd(Ks)
    if s[-1] <= 1e-10 * s[0]:
        j = int(np.argmax(np.abs(vt[-1])))
        nm, k = active[j]
        raise InputError(f"bodies[{nm}].{dofs[k]}", float(s[-1] / s[0]), "-",
                         "has no restoring force (the stiffness matrix is singular in "
                         "this DOF): the static pose is undetermined; hold the DOF with "
                         "fixed_dofs or add a hydrostatic or extra stiffness")
