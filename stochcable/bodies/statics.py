"""Static equilibrium of bodies and their lines (docs/BODIES.md, "Statics").

The unknowns are the poses q = (X, θ) of the free bodies (6 DOF; planar scenes 3:
surge, heave, pitch), X the reference point [m] and θ a rotation vector [rad].  The
generalized force on a body about its reference point is

    Q(q) = Σ_lines [F_ℓ; (R r_ℓ) × F_ℓ] + Q_grav + Q_hydro + Q_wind + Q_drag,

F_ℓ the static force a line exerts on its end at X + R(θ)·r_ℓ (each line solved by
:func:`stochcable.line.statics.solve_line_statics` with that end fixed), and Newton's
method solves Q = 0 with the tangent stiffness K = −dQ/dq: the condensed end stiffness
of every line (Schur complement K_bb − K_bf K_ff⁻¹ K_fb of its FE tangent, the matrix
of :func:`stochcable.line.fem.build_fe_model`, over the interior DOFs: one banded solve)
including the attachment geometric term −[F]×[r]× (Tuah (1982), eqs. 3.3.8–3.3.10
linearized about the static state), the hydrostatic matrix, and the geometric terms
of the point forces whose moment arm rotates (weight, buoyancy, drag).  K is exact, so
the iteration converges quadratically.  K at the solution is reported as the
quasi-static mooring + hydrostatic stiffness.  Each FE line of a Newton trial is
warm-started from its shape at the current iterate plus the first-order interior motion
−K_ff⁻¹ K_fb δx_ends of the same condensation (the static-condensation predictor), which
usually leaves one or two line Newton steps (a cold start if that start fails).

Body loads: :mod:`stochcable.bodies.static_loads` (weight, buoyancy, hydrostatic
restoring, wind and current drag; :func:`body_static_load`).

Prescribed bodies (vessels) are not solved for: their pose is ``position``, no rotation.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from stochcable.bodies.from_scene import scene_rigid_bodies
from stochcable.bodies.mooring import mooring_stiffness, mooring_stiffness_and_maps, pose_map
from stochcable.bodies.rigid import (
    PLANAR_DOFS,
    PLANAR_INDEX,
    SPATIAL_DOFS,
)
from stochcable.bodies.start import bar_start_poses
from stochcable.bodies.static_loads import _cross3, _full, _reduce, body_static_load
from stochcable.errors import ConvergenceError, InputError
from stochcable.line.mesh import mesh_line
from stochcable.line.statics import check_statics_options, solve_line_statics_unchecked
from stochcable.scene.model import Scene
from stochcable.validation import positive, positive_int

__all__ = ["BodyStatics", "solve_body_statics", "body_static_load", "mooring_stiffness"]


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


# ---------------------------------------------------------------------- the solver


def solve_body_statics(
    scene: Scene,
    method: str = "auto",
    *,
    tolerance: float = 1e-10,
    max_iterations: int = 500,
    body_tolerance: float = 1e-8,
    max_body_iterations: int = 60,
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
    Module docstring; docs/BODIES.md §Statics.  Tuah (1982), §4.1 (static configuration
    as the starting state), eq. 3.2.c.20 (static force F̄), eqs. 3.3.6–3.3.10.
    """
    body_tolerance = positive("body_tolerance", body_tolerance, "-")
    max_body_iterations = positive_int("max_body_iterations", max_body_iterations)
    method, tolerance, max_iterations = check_statics_options(method, tolerance, max_iterations)
    pb = _BodyPoses(scene, method, tolerance, max_iterations)
    poses = {
        b.name: np.concatenate([np.asarray(b.position, float), np.zeros(3)]) for b in scene.bodies
    }
    fixed = pb.fixed_lines(poses)
    try:
        state, it, stalled = _solve_poses(pb, fixed, poses, body_tolerance, max_body_iterations)
    except (ConvergenceError, InputError) as exc:
        # the lines cannot be solved at the input poses: from the bar model's poses
        retry = _from_bar_start(pb, fixed, poses, body_tolerance, max_body_iterations)
        if retry is None:
            raise exc from None
        state, it, stalled = retry
    else:
        if stalled:
            # no Newton step lowers the residual: once more from the bar model's poses
            retry = _from_bar_start(pb, fixed, poses, body_tolerance, max_body_iterations)
            if retry is not None and retry[0].r < state.r:
                state, it, stalled = retry
    if state.r > body_tolerance:
        raise ConvergenceError(
            "body statics Newton",
            it,
            state.r,
            body_tolerance,
            hint=(
                "check that the lines can hold the bodies (weight, buoyancy, wind): "
                "a body held only by lines slack on the frictionless seabed has an "
                "undetermined position; give initial positions near equilibrium, "
                "raise max_body_iterations or give fixed_dofs for DOFs without "
                "restoring"
            ),
            partial={nm: state.poses[nm].copy() for nm in pb.free},
        )
    lines = {**fixed, **state.lines}
    return {ln.name: lines[ln.name] for ln in scene.lines}, pb.results(state, it)


def _solve_poses(
    pb: _BodyPoses,
    fixed: dict[str, Any],
    poses: dict[str, np.ndarray],
    body_tolerance: float,
    max_body_iterations: int,
) -> tuple[_State, int, bool]:
    """The Newton from ``poses``: its last state, iteration count and whether it
    stalled (no step accepted) short of the tolerance."""
    state = pb.first_state(poses, fixed)
    if pb.free and pb.sel.size:
        _check_determined(state.K, pb.sel, pb.active, pb.free, pb.d, pb.planar, pb.lref, pb.dofs)
    it = 0
    while state.r > body_tolerance and it < max_body_iterations and pb.sel.size:
        it += 1
        trial = _newton_step(pb, fixed, state)
        if trial is None:
            return state, it, True
        state = trial
    return state, it, False


def _from_bar_start(
    pb: _BodyPoses,
    fixed: dict[str, Any],
    poses: dict[str, np.ndarray],
    body_tolerance: float,
    max_body_iterations: int,
) -> tuple[_State, int, bool] | None:
    """The Newton from the straight-bar model's poses (:mod:`stochcable.bodies.start`),
    or None when that start is the input or the lines cannot be solved there either."""
    if not pb.free or not pb.sel.size:
        return None
    start = bar_start_poses(pb.scene, poses, pb.free, pb.meshes, pb.rigid)
    if all(np.array_equal(start[nm], poses[nm]) for nm in pb.free):
        return None
    try:
        return _solve_poses(pb, fixed, start, body_tolerance, max_body_iterations)
    except (ConvergenceError, InputError):
        return None


@dataclass(frozen=True, eq=False)
class _State:
    """An iterate of the body statics Newton: the poses (X, θ) by body, the moving
    lines' statics there, the generalized force Q and stiffness K on the free DOFs,
    the line forces on every body, the lines' interior maps and the scaled residual."""

    poses: dict[str, np.ndarray]
    lines: dict[str, Any]
    Q: np.ndarray
    K: np.ndarray
    line_forces: dict[str, dict[str, np.ndarray]]
    maps: dict[str, tuple[list[str], np.ndarray]]
    r: float


class _BodyPoses:
    """The body statics of a scene: unknowns, lines, forces and scales.

    The free bodies (not prescribed) carry d = 6 DOFs (3 planar), minus their
    ``fixed_dofs`` (the active unknowns ``sel``); the moving lines are those attached to
    a free body, re-solved at every trial pose; the other lines are solved once.
    """

    def __init__(self, scene: Scene, method: str, tolerance: float, max_iterations: int) -> None:
        self.scene = scene
        self.method, self.tolerance, self.max_iterations = method, tolerance, max_iterations
        self.env = env = scene.environment
        self.planar = planar = scene.is_planar
        self.d = d = 3 if planar else 6
        self.dofs = PLANAR_DOFS if planar else SPATIAL_DOFS
        self.rigid = scene_rigid_bodies(scene)
        self.free = free = [b.name for b in scene.bodies if b.prescribed is None]
        self.attached = {
            ln.name: {
                end: getattr(ln, end).attach.body
                for end in ("end_a", "end_b")
                if getattr(ln, end).attach is not None
            }
            for ln in scene.lines
        }
        self.moving = [
            ln for ln in scene.lines if any(b in free for b in self.attached[ln.name].values())
        ]
        self.meshes = {
            ln.name: mesh_line(scene.resolved_line(ln), env.rho, env.g) for ln in self.moving
        }
        self.comps = [0, 2] if planar else [0, 1, 2]
        self.c = len(self.comps)
        self._end_memo: dict[tuple, np.ndarray] = {}
        # active unknowns
        self.active: list[tuple[str, int]] = []
        for nm in free:
            fixed = set(scene.body(nm).fixed_dofs)
            for k, dn in enumerate(self.dofs):
                if dn not in fixed:
                    self.active.append((nm, k))
        self.pos_in_block = {nm: i for i, nm in enumerate(free)}
        self.sel = np.array([self.pos_in_block[nm] * d + k for nm, k in self.active], dtype=int)
        self.fref, self.lref = self._scales()

    def _scales(self) -> tuple[float, float]:
        """Reference force (the largest body load; the line tensions are added by
        :meth:`first_state`) and reference length (the largest body arm). [N, m]"""
        env = self.env
        fref = 0.0
        lref = 0.0
        for b in self.scene.bodies:
            fref = max(
                fref,
                b.mass * env.g,
                env.rho * env.g * (b.displaced_volume or 0.0),
                float(np.linalg.norm(b.wind_force)),
            )
            for v in (b.cog, b.centre_of_buoyancy, b.drag_point):
                lref = max(lref, float(np.linalg.norm(v)))
        for ln in self.scene.lines:
            for end in ("end_a", "end_b"):
                a = getattr(ln, end).attach
                if a is not None:
                    lref = max(lref, float(np.linalg.norm(a.point)))
        return fref, (lref if lref > 0.0 else 1.0)

    def _line(self, mesh: Any, initial: np.ndarray | None = None) -> Any:
        return solve_line_statics_unchecked(
            mesh, self.env, self.method, initial, self.tolerance, self.max_iterations
        )

    def fixed_lines(self, poses: dict[str, np.ndarray]) -> dict[str, Any]:
        """The statics of the lines no free body moves, solved once."""
        env = self.env
        return {
            ln.name: self._line(
                mesh_line(self.scene.resolved_line(ln, pose_map(poses)), env.rho, env.g)
            )
            for ln in self.scene.lines
            if ln not in self.moving
        }

    def end_pos(self, ln: Any, end: str, pz: dict[str, np.ndarray]) -> np.ndarray:
        """``scene.end_position(ln, end, pose_map(pz))``, memoized on the attached
        body's pose (the lines' solve, the forces and the stiffness ask for the same
        ends at the same trial pose)."""
        a = getattr(ln, end).attach
        key = (ln.name, end, None if a is None or a.body not in pz else pz[a.body].tobytes())
        hit = self._end_memo.get(key)
        if hit is None:
            hit = self._end_memo[key] = self.scene.end_position(ln, end, pose_map(pz))
        return hit.copy()

    def solve_lines(
        self,
        pz: dict[str, np.ndarray],
        base: dict[str, Any] | None = None,
        maps: dict[str, tuple[list[str], np.ndarray]] | None = None,
    ) -> dict[str, Any]:
        """The moving lines at the poses pz, each FE line warm-started from its shape
        in ``base`` plus the first-order interior motion −S δx_ends (``maps``, the
        static condensation of its tangent); a cold start if that fails."""
        comps, c = self.comps, self.c
        out = {}
        for ln in self.moving:
            mesh = replace(
                self.meshes[ln.name],
                end_a=self.end_pos(ln, "end_a", pz),
                end_b=self.end_pos(ln, "end_b", pz),
            )
            prev = None if base is None else base.get(ln.name)
            init = None
            if prev is not None and prev.method == "fe":
                init = prev.positions.copy()
                m = None if maps is None else maps.get(ln.name)
                if m is not None and m[1].size:
                    ends, smap = m
                    dxb = np.concatenate(
                        [
                            (mesh.end_a if e == "end_a" else mesh.end_b)[comps]
                            - prev.positions[0 if e == "end_a" else -1, comps]
                            for e in ends
                        ]
                    )
                    init[1:-1, comps] -= (smap @ dxb).reshape(-1, c)
                init[0], init[-1] = mesh.end_a, mesh.end_b
            try:
                out[ln.name] = self._line(mesh, init)
            except ConvergenceError:
                if init is None:
                    raise
                out[ln.name] = self._line(mesh)
        return out

    def first_state(self, poses: dict[str, np.ndarray], fixed: dict[str, Any]) -> _State:
        """The moving lines at the initial poses (InputError naming the poses when a
        line cannot hang there), the reference force raised to their tensions, and the
        forces there."""
        try:
            ls = self.solve_lines(poses)
        except InputError as exc:
            where = ", ".join(f"{nm} at {np.round(poses[nm][:3], 6).tolist()}" for nm in self.free)
            raise InputError(
                exc.parameter,
                exc.value,
                exc.unit,
                f"{exc.constraint} (at the initial body positions: {where}; "
                "give positions near equilibrium with the lines neither slack "
                "on the seabed nor over-stretched)",
            ) from None
        fref = self.fref
        for ln in self.moving:
            s = ls[ln.name]
            fref = max(
                fref, float(s.tension.max(initial=0.0)), float(s.tension_a), float(s.tension_b)
            )
        self.fref = fref if fref > 0.0 else 1.0
        return self.state(poses, ls, fixed)

    def state(self, pz: dict[str, np.ndarray], ls: dict[str, Any], fixed: dict[str, Any]) -> _State:
        """The iterate at the poses pz with the moving lines ``ls`` solved there."""
        Q, K, lf, maps = self.forces(pz, ls, fixed)
        return _State(poses=pz, lines=ls, Q=Q, K=K, line_forces=lf, maps=maps, r=self.scaled(Q))

    def forces(
        self, pz: dict[str, np.ndarray], ls: dict[str, Any], fixed: dict[str, Any]
    ) -> tuple[
        np.ndarray,
        np.ndarray,
        dict[str, dict[str, np.ndarray]],
        dict[str, tuple[list[str], np.ndarray]],
    ]:
        """Generalized forces (n_free·d,), stiffness (n_free·d)², line forces, and the
        lines' interior maps (:func:`stochcable.bodies.mooring.mooring_stiffness_and_maps`)."""
        scene, planar, d = self.scene, self.planar, self.d
        free, pos_in_block, rigid = self.free, self.pos_in_block, self.rigid
        Q = np.zeros(len(free) * d)
        K = np.zeros((len(free) * d, len(free) * d))
        lf: dict[str, dict[str, np.ndarray]] = {b.name: {} for b in scene.bodies}
        allls = {**fixed, **ls}
        for ln in scene.lines:
            attached = self.attached[ln.name]
            for end, bname in attached.items():
                f = np.asarray(getattr(allls[ln.name], "force_" + end[-1]), dtype=float)
                key = (
                    ln.name
                    if len(attached) == 1 or len(set(attached.values())) == 2
                    else f"{ln.name}.{end}"
                )
                lf[bname][key] = f
                if bname not in pos_in_block:
                    continue
                p = pz[bname]
                arm = self.end_pos(ln, end, pz) - p[:3]
                i = pos_in_block[bname] * d
                Q[i : i + d] += _reduce(np.concatenate([f, _cross3(arm, f)]), planar)
        for nm in free:
            i = pos_in_block[nm] * d
            load, st = body_static_load(scene, nm, pz[nm], rigid[nm])
            Q[i : i + d] += _reduce(load, planar)
            K[i : i + d, i : i + d] += st[np.ix_(PLANAR_INDEX, PLANAR_INDEX)] if planar else st
            K[i : i + d, i : i + d] += np.asarray(rigid[nm].extra_stiffness, float)
            Q[i : i + d] -= np.asarray(rigid[nm].extra_stiffness, float) @ (
                _reduce(pz[nm], planar)
                - _reduce(
                    np.concatenate([np.asarray(scene.body(nm).position, float), np.zeros(3)]),
                    planar,
                )
            )
        maps: dict[str, tuple[list[str], np.ndarray]] = {}
        if free:
            km, maps = mooring_stiffness_and_maps(
                scene,
                allls,
                pz,
                free,
                planar,
                self.method,
                self.tolerance,
                end_position=self.end_pos,
            )
            K += km
        return Q, K, lf, maps

    def scaled(self, Q: np.ndarray) -> float:
        """max |Q| over the active DOFs / the reference force, the moments divided by
        the reference length too. [-]"""
        if Q.size == 0:
            return 0.0
        qq = Q.reshape(len(self.free), self.d).copy()
        rot = [2] if self.planar else [3, 4, 5]
        qq[:, rot] /= self.lref
        sel = self.sel
        qq = qq.reshape(-1)[sel] if sel.size else qq.reshape(-1)[:0]
        return float(np.abs(qq).max(initial=0.0)) / self.fref

    def results(self, state: _State, iterations: int) -> dict[str, BodyStatics]:
        """The BodyStatics of every body at the final iterate."""
        d = self.d
        out: dict[str, BodyStatics] = {}
        for b in self.scene.bodies:
            p = state.poses[b.name]
            if b.name in self.pos_in_block:
                i = self.pos_in_block[b.name] * d
                st = state.K[i : i + d, i : i + d].copy()
                res, iters = state.r, iterations
            else:
                st, res, iters = np.zeros((d, d)), 0.0, 0
            out[b.name] = BodyStatics(
                name=b.name,
                position=p[:3].copy(),
                rotation=p[3:].copy(),
                line_forces=state.line_forces[b.name],
                iterations=iters,
                residual=res,
                stiffness=st,
                dofs=self.dofs,
                prescribed=b.prescribed is not None,
            )
        return out


def _newton_step(pb: _BodyPoses, fixed: dict[str, Any], state: _State) -> _State | None:
    """One Newton step on the active DOFs, K δq = Q, with a backtracking line search
    (halving up to 12 times) that accepts a lower residual (or the last, tiny step);
    a trial pose where a line cannot reach or goes slack is a shorter step.  None when
    no step is accepted."""
    sel, d = pb.sel, pb.d
    Ka = state.K[np.ix_(sel, sel)]
    try:
        dq_a = np.linalg.solve(Ka, state.Q[sel])
    except np.linalg.LinAlgError:
        dq_a = np.linalg.lstsq(Ka, state.Q[sel], rcond=None)[0]
    dq = np.zeros(len(pb.free) * d)
    dq[sel] = dq_a
    step = 1.0
    for _ in range(12):
        trial = {nm: p.copy() for nm, p in state.poses.items()}
        for nm in pb.free:
            i = pb.pos_in_block[nm] * d
            trial[nm] = trial[nm] + _full(step * dq[i : i + d], pb.planar)
        try:
            ls_t = pb.solve_lines(trial, state.lines, state.maps)
            new = pb.state(trial, ls_t, fixed)
        except (ConvergenceError, InputError):
            # a line that cannot reach or goes slack at the trial pose: shorter step
            step *= 0.5
            continue
        if new.r < state.r or step < 1.0 / 1024:
            return new
        step *= 0.5
    return None


def _check_determined(
    K: np.ndarray,
    sel: np.ndarray,
    active: list[tuple[str, int]],
    free: list[str],
    d: int,
    planar: bool,
    lref: float,
    dofs: tuple[str, ...],
) -> None:
    """InputError naming a body DOF without restoring (singular K on the unknowns)."""
    scale = np.ones(len(free) * d)
    rot = [2] if planar else [3, 4, 5]
    for i in range(len(free)):
        scale[i * d + np.array(rot)] = 1.0 / lref
    Ks = (scale[:, None] * K * scale[None, :])[np.ix_(sel, sel)]
    big = float(np.abs(Ks).max(initial=0.0))
    if big == 0.0:
        nm, k = active[0]
        raise InputError(
            f"bodies[{nm}].{dofs[k]}",
            0.0,
            "N/m",
            "has no restoring force "
            "(no line, hydrostatic or extra stiffness): the static pose is "
            "undetermined; hold the DOF with fixed_dofs or add a stiffness",
        )
    u, s, vt = np.linalg.svd(Ks)
    if s[-1] <= 1e-10 * s[0]:
        j = int(np.argmax(np.abs(vt[-1])))
        nm, k = active[j]
        raise InputError(
            f"bodies[{nm}].{dofs[k]}",
            float(s[-1] / s[0]),
            "-",
            "has no restoring force (the stiffness matrix is singular in "
            "this DOF): the static pose is undetermined; hold the DOF with "
            "fixed_dofs or add a hydrostatic or extra stiffness",
        )
