"""A start for the body statics from straight elastic bars (docs/BODIES.md, "Statics").

The body statics Newton (:mod:`stochcable.bodies.statics`) solves every line at the
input body positions first.  Where a line cannot be solved there (a slack, nearly
weightless line hanging a weight, as in a MoorDyn file whose free point sits a line's
slack above its equilibrium) or the Newton does not converge from there, it starts
again from the poses of a simpler model: every line a straight, tension-only elastic
bar between its ends, EA_eq = L / Σ(l0/EA) over its segments, its weight and its
attachments' net weight lumped half on each end, and the bodies' own loads
(:func:`stochcable.bodies.static_loads.body_static_load`).  Only the translations are
solved for (rotations held at the input pose); the equilibrium of this closed-form
model is found by SciPy's trust-region least squares (``least_squares``, "trf"), with
a continuation in the bars' stiffness: soft series springs, and weak zero-length
springs drawing slack bars taut, removed in four steps.
At those poses the lines are taut or nearly so, where the FE line statics converge.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy.optimize import least_squares

from stochcable.bodies.mooring import pose_map
from stochcable.bodies.static_loads import body_static_load

__all__ = ["bar_start_poses"]


def bar_start_poses(
    scene: Any,
    poses: dict[str, np.ndarray],
    free: list[str],
    meshes: dict[str, Any],
    rigid: dict[str, Any],
) -> dict[str, np.ndarray]:
    """Body poses at the equilibrium of the straight-bar model (module docstring).

    Parameters
    ----------
    scene : Scene
    poses : dict of str to ndarray (6,)
        Input poses (X, θ) of every body; the free bodies' translations are the start
        of the least squares, their rotations are kept.
    free : list of str
        The free bodies.
    meshes : dict of str to LineMesh
        The meshes of the lines attached to a free body, by line name (their lengths,
        axial stiffnesses and loads).
    rigid : dict of str to RigidBody
        The bodies' rigid models (hydrostatics).

    Returns
    -------
    dict of str to ndarray (6,)
        ``poses`` with the free bodies' translations moved to the bar model's
        equilibrium (unchanged where the least squares makes no progress).
    """
    g = scene.environment.g
    planar = scene.is_planar
    comps = [0, 2] if planar else [0, 1, 2]
    unknowns = []
    for nm in free:
        held = set(scene.body(nm).fixed_dofs)
        for k, dof in zip(range(3), ("surge", "sway", "heave"), strict=True):
            if k in comps and dof not in held:
                unknowns.append((nm, k))
    if not unknowns:
        return poses
    bars = []
    for ln in scene.lines:
        mesh = meshes.get(ln.name)
        if mesh is None:
            continue
        length = float(np.sum(mesh.l0))
        compliance = float(np.sum(mesh.l0 / mesh.ea))
        weight = float(np.sum(mesh.weight * mesh.l0) - np.sum(mesh.node_buoyancy))
        weight += float(np.sum(mesh.node_mass)) * g
        bars.append((ln, length, compliance, weight))
    fref = max([abs(w) for *_, w in bars] + [scene.body(nm).mass * g for nm in free] + [1.0])

    def trial(x: np.ndarray) -> dict[str, np.ndarray]:
        pz = {nm: p.copy() for nm, p in poses.items()}
        for (nm, k), v in zip(unknowns, x, strict=True):
            pz[nm][k] = v
        return pz

    def residual(x: np.ndarray, soft: float, pull: float) -> np.ndarray:
        pz = trial(x)
        pm = pose_map(pz)
        force = {nm: body_static_load(scene, nm, pz[nm], rigid[nm])[0][:3] for nm in free}
        for nm in free:
            # extra stiffness on the translations (planar: surge, heave of 3 DOFs)
            kx = np.asarray(rigid[nm].extra_stiffness, float)
            idx = [0, 1] if kx.shape[0] == 3 else [0, 1, 2]
            kt = np.zeros((3, 3))
            kt[np.ix_(comps, comps)] = kx[np.ix_(idx, idx)]
            force[nm] = force[nm] - kt @ (pz[nm][:3] - np.asarray(scene.body(nm).position, float))
        for ln, length, compliance, weight in bars:
            a = scene.end_position(ln, "end_a", pm)
            b = scene.end_position(ln, "end_b", pm)
            d = b - a
            chord = float(np.linalg.norm(d))
            stretch = chord - length
            flex = compliance + soft * length / fref
            # tension-only, plus a weak zero-length spring that draws a slack bar's
            # ends together (``pull`` of its stiffness: no compression to push a body
            # through the anchor, no flat slack region to stall in)
            tension = (max(stretch, 0.0) + pull * chord) / flex
            u = d / chord if chord > 0.0 else np.zeros(3)
            half = np.array([0.0, 0.0, -0.5 * weight])
            for end, sign in (("end_a", 1.0), ("end_b", -1.0)):
                att = getattr(ln, end).attach
                if att is not None and att.body in force:
                    force[att.body] = force[att.body] + sign * tension * u + half
        return np.array([force[nm][k] for nm, k in unknowns]) / fref

    x0 = np.array([poses[nm][k] for nm, k in unknowns])
    x = x0
    # continuation in the bar stiffness: each bar in series with a soft spring that
    # stretches it by 10 %, 1 %, 0.1 % of its length under the reference load, then
    # alone; a stiff bar on its own turns about its anchor in tiny trust-region steps
    # (a pendulum started 5 m off its vertical: 200 evaluations and 19 m further off)
    for soft, pull in ((0.1, 1e-2), (0.01, 1e-3), (0.001, 1e-4), (0.0, 0.0)):
        sol = least_squares(
            residual, x, args=(soft, pull), method="trf", x_scale=1.0, xtol=1e-12, ftol=1e-12
        )
        if np.all(np.isfinite(sol.x)):
            x = sol.x
    if float(np.sum(residual(x, 0.0, 0.0) ** 2)) >= float(np.sum(residual(x0, 0.0, 0.0) ** 2)):
        return poses
    return trial(x)
