"""The static load on a body from everything but its lines (docs/BODIES.md §Statics).

Body loads (Tuah (1982), eq. 3.2.c.20, the static F̄):

- with ``displaced_volume`` ∇ and a non-zero ``hydrostatic_stiffness`` K_h (a floating
  body): weight −m g ẑ at the CoG and buoyancy ρ g ∇ ẑ at the CoB evaluated at zero
  rotation, plus the linear restoring −K_h (q − q₀) about ``position`` (K_h holds the
  rotation terms of weight and buoyancy, as WAMIT/Capytaine give it);
- with ∇ and no K_h (a submerged body): weight at R·r_G and buoyancy at R·r_B, exact;
- without ∇ but with K_h: the body is taken as freely floating in equilibrium at
  ``position`` (weight balanced by buoyancy), restored by −K_h (q − q₀) only;
- without ∇ and K_h: the weight alone at R·r_G (no buoyancy);
- ``wind_force``/``wind_moment`` at the reference point (Tuah (1982), §6.5's 100 lb wind);
- current drag ½ ρ (Cd·A)_i |U| U_i at R·``drag_point`` with U the current there.

The load is a generalized force (F, M) about the body's reference point in global axes,
with its stiffness −d load/d pose; :func:`stochcable.bodies.statics.solve_body_statics`
adds the lines' forces and solves the equilibrium.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from stochcable.bodies.from_scene import rigid_body_from_scene
from stochcable.bodies.rigid import PLANAR_INDEX, RigidBody, geometric_stiffness
from stochcable.scene.model import Scene, rotate

__all__ = ["body_static_load"]


def _full(q: np.ndarray, planar: bool) -> np.ndarray:
    """6-vector (X, θ) from a body DOF vector."""
    if not planar:
        return np.asarray(q, dtype=float)
    out = np.zeros(6)
    out[list(PLANAR_INDEX)] = q
    return out


def _reduce(v6: np.ndarray, planar: bool) -> np.ndarray:
    return v6[list(PLANAR_INDEX)] if planar else v6


def body_static_load(
    scene: Scene, name: str, pose: Any, rigid: RigidBody | None = None
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
    return geometric_stiffness(force, arm, False)
