"""A scene built for the frequency-domain analysis, independent of the sea
state: the build half of :func:`stochcable.dynamics.groups.analysis.analyze_coupled`.

:func:`build_coupled` makes everything that does not depend on the sea (its spectrum
and heading): every line's system about its static shape (both end nodes prescribed,
natural modes), the free bodies at their static pose with their gravity restoring,
the vessels' RAOs on the grid, the connected groups of free bodies and their lines,
and the coupled modes of the groups whose added mass is constant over ω.
:func:`stochcable.dynamics.groups.analysis.solve_coupled` drives it with a sea state.
The environment (depth, current, density) belongs to the model: the statics depend on
it.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from stochcable.bodies.rigid import PLANAR_INDEX, FrequencyTable, RigidBody
from stochcable.dynamics.groups.inputs import CoupledLine, body_gravity_stiffness
from stochcable.dynamics.groups.modes import CoupledModes, coupled_modes
from stochcable.dynamics.groups.vessels import VesselRaos
from stochcable.dynamics.model.system import LineSystem
from stochcable.errors import InputError, PhysicsWarning, warn
from stochcable.scene.model import AnalysisSettings, Line, Scene
from stochcable.statics import StaticsResult

__all__ = ["STATIC_ROTATION_LIMIT", "CoupledModel", "ModelGroup", "build_coupled"]

#: Static body rotation above which the body's data (given at its input orientation)
#: are flagged: the rigid-body matrices, hydrodynamic coefficients, hydrostatics,
#: excitation and drag point are used unrotated, only the line attachment arms follow
#: the static rotation. 5° moves a body-fixed direction by sin 5° ≈ 9 % of its length.
STATIC_ROTATION_LIMIT = math.radians(5.0)


@dataclass(frozen=True, eq=False)
class ModelGroup:
    """One connected group of free bodies and the lines attached to them.

    Attributes
    ----------
    lines : tuple of str
        The group's lines in scene order.
    bodies : tuple of str
        Its free bodies in scene order.
    modes : CoupledModes or None
        The coupled modes when they do not depend on the sea (no body's added mass is
        tabulated over ω: A(ω_ref) is the same for every ω_ref; ``omega_ref`` is set
        by the solve); None: computed by each solve at the sea's spectral peak.
    """

    lines: tuple[str, ...]
    bodies: tuple[str, ...]
    modes: CoupledModes | None


@dataclass(frozen=True, eq=False)
class CoupledModel:
    """A scene with bodies, built once and solved for any number of sea states.

    Attributes
    ----------
    scene : Scene
        The scene it was built from (environment, lines, bodies; its ``sea`` is the
        default sea state of a solve).
    settings : AnalysisSettings
        The settings it was built with (grid, solver, modes).
    omega : ndarray, shape (n_omega,)
        The analysis grid. [rad/s]
    systems : dict of str to LineSystem
        Every line about its static shape, both end nodes prescribed, in scene order.
    attach : dict of str to dict of str to str
        Per line ``{end: body}`` of its ends on free bodies.
    free : dict of str to RigidBody
        The free bodies at their static pose (``position``), with the gravity
        restoring of :func:`~stochcable.dynamics.groups.inputs.body_gravity_stiffness`
        in ``extra_stiffness`` when they have no hydrostatic matrix.
    pose : dict of str to ndarray, shape (d,)
        Static value of each free body DOF (position and rotation). [m, rad]
    prescribed : tuple of str
        The prescribed bodies (vessels).
    vessel_rao : VesselRaos
        Their motion RAOs on the grid, per wave heading. [m/m, rad/m]
    groups : tuple of ModelGroup
        The coupled groups, in the scene order of their first line.
    independent : tuple of str
        The lines attached to no free body (solved alone).
    lonely : tuple of str
        The free bodies without lines (solved alone).
    """

    scene: Scene
    settings: AnalysisSettings
    omega: np.ndarray
    systems: dict[str, LineSystem]
    attach: dict[str, dict[str, str]]
    free: dict[str, RigidBody]
    pose: dict[str, np.ndarray]
    prescribed: tuple[str, ...]
    vessel_rao: VesselRaos
    groups: tuple[ModelGroup, ...]
    independent: tuple[str, ...]
    lonely: tuple[str, ...]


def build_coupled(
    scene: Scene,
    statics: StaticsResult,
    settings: AnalysisSettings,
    *,
    rigid_bodies: Mapping[str, RigidBody] | None = None,
    timing: dict[str, float] | None = None,
    systems: Mapping[str, LineSystem] | None = None,
) -> CoupledModel:
    """Build the sea-independent part of the analysis of a scene with bodies.

    Parameters
    ----------
    scene : Scene
        A validated scene with ``bodies``.
    statics : StaticsResult
        Its static equilibrium (lines with attached ends at the body poses, and
        ``statics.bodies``).
    settings : AnalysisSettings
        Grid, solver and modes of the line systems.
    rigid_bodies : mapping of str to RigidBody, optional
        The bodies as RigidBody (default
        :func:`stochcable.bodies.from_scene.scene_rigid_bodies`); their ``position`` is
        replaced by the static pose of ``statics.bodies`` when present.
    timing : dict, optional
        Accumulates ``model_s``. [s]
    systems : mapping of str to LineSystem, optional
        The lines' systems already built (:func:`stochcable.dynamics.model.system.
        build_line_system` about ``statics``); default built here.

    Returns
    -------
    CoupledModel

    Raises
    ------
    InputError
        A free body without a RigidBody.

    Warns
    -----
    PhysicsWarning
        A body's static rotation above ``STATIC_ROTATION_LIMIT``.
    """
    from stochcable.dynamics.model.system import build_line_system

    t0 = time.perf_counter()
    omega = settings.omega.values()
    body_docs = {b.name: b for b in scene.bodies}
    prescribed = tuple(
        n for n, b in body_docs.items() if getattr(b, "prescribed", None) is not None
    )
    free, pose = _free_bodies(scene, statics, prescribed, rigid_bodies)
    raos = VesselRaos(omega, {n: body_docs[n].prescribed for n in prescribed})
    given = {} if systems is None else systems
    systems = {}
    attach: dict[str, dict[str, str]] = {}
    for line in scene.lines:
        systems[line.name] = given.get(line.name) or build_line_system(
            scene, line, statics.lines[line.name], settings=settings
        )
        attach[line.name] = _free_ends(line, prescribed)
    groups = _connected_groups(scene, free, attach)
    in_group = {b for lnames, bnames in groups for b in bnames}
    mgroups = tuple(
        ModelGroup(
            lnames,
            bnames,
            _static_modes(
                [
                    CoupledLine(
                        systems[n], (), end_a=attach[n].get("end_a"), end_b=attach[n].get("end_b")
                    )
                    for n in lnames
                ],
                [free[b] for b in bnames],
                omega,
            ),
        )
        for lnames, bnames in groups
    )
    if timing is not None:
        timing["model_s"] = timing.get("model_s", 0.0) + time.perf_counter() - t0
    return CoupledModel(
        scene=scene,
        settings=settings,
        omega=omega,
        systems=systems,
        attach=attach,
        free=free,
        pose=pose,
        prescribed=prescribed,
        vessel_rao=raos,
        groups=mgroups,
        independent=tuple(ln.name for ln in scene.lines if not attach[ln.name]),
        lonely=tuple(n for n in free if n not in in_group),
    )


def _free_bodies(
    scene: Scene,
    statics: StaticsResult,
    prescribed: tuple[str, ...],
    rigid_bodies: Mapping[str, RigidBody] | None,
) -> tuple[dict[str, RigidBody], dict[str, np.ndarray]]:
    """The free bodies at their static pose with their gravity restoring, and the
    pose of each DOF."""
    env = scene.environment
    if rigid_bodies is None:
        from stochcable.bodies.from_scene import scene_rigid_bodies

        rigid_bodies = scene_rigid_bodies(scene)
    rigid = dict(rigid_bodies)
    body_docs = {b.name: b for b in scene.bodies}
    bstat = getattr(statics, "bodies", {}) or {}
    free: dict[str, RigidBody] = {}
    pose: dict[str, np.ndarray] = {}
    for name, doc in body_docs.items():
        if name in prescribed:
            continue
        if name not in rigid:
            raise InputError("rigid_bodies", name, "-", "a free body has no RigidBody")
        body = rigid[name]
        if name in bstat:
            pos = np.asarray(bstat[name].position, dtype=float)
            rot = np.asarray(bstat[name].rotation, dtype=float)
        else:
            pos, rot = np.asarray(body.position, dtype=float), np.zeros(3)
        _static_rotation_check(name, rot)
        full = np.concatenate([pos, rot])
        pose[name] = full[list(PLANAR_INDEX)] if body.planar else full
        extra = body.extra_stiffness
        if not np.any(body.hydrostatic_stiffness):
            # no hydrostatic matrix: the statics apply the weight at the CoG and the
            # buoyancy (if a displaced volume is given) at the CoB exactly
            # (stochcable.bodies.statics), so their rotation restoring belongs to the
            # linearization (body_gravity_stiffness); a hydrostatic matrix already
            # holds these gravity terms (WAMIT convention)
            vol = getattr(doc, "displaced_volume", None) or 0.0
            cob = getattr(doc, "centre_of_buoyancy", None)
            extra = extra + body_gravity_stiffness(
                body, vol, np.zeros(3) if cob is None else cob, env.rho, env.g
            )
        free[name] = dataclasses.replace(body, position=pos, extra_stiffness=extra)
    return free, pose


def _static_rotation_check(name: str, rotation: np.ndarray) -> None:
    """PhysicsWarning when a body's static rotation exceeds STATIC_ROTATION_LIMIT."""
    angle = float(np.linalg.norm(rotation))
    if angle > STATIC_ROTATION_LIMIT:
        warn(
            f"body '{name}': its static rotation is {math.degrees(angle):.3g}° "
            f"(rotation vector {np.round(np.degrees(rotation), 3).tolist()} deg), above "
            f"{math.degrees(STATIC_ROTATION_LIMIT):g}°: the dynamics use its mass, inertia, "
            "added mass, damping, hydrostatic stiffness, excitation and drag point at the "
            "input orientation (only the line attachment arms follow the rotation), so "
            "they are off by about the sine of that angle; give the body's data at its "
            "static orientation (rotate them and the attachment points) and re-run",
            PhysicsWarning,
            stacklevel=4,
        )


def _free_ends(line: Line, prescribed: tuple[str, ...]) -> dict[str, str]:
    """``{end: body}`` of a scene line's ends attached to free (not prescribed) bodies
    (as :func:`~stochcable.dynamics.groups.inputs.scene_line_channels`)."""
    att: dict[str, str] = {}
    for end in ("end_a", "end_b"):
        a = getattr(getattr(line, end), "attach", None)
        if a is not None and a.body not in prescribed:
            att[end] = a.body
    return att


def _connected_groups(
    scene: Scene, free: Mapping[str, RigidBody], attach: Mapping[str, Mapping[str, str]]
) -> list[tuple[tuple[str, ...], tuple[str, ...]]]:
    """Each connected component of free bodies and their lines (union–find over the
    lines' attached ends): (lines in scene order, bodies in scene order), in the scene
    order of the first line."""
    parent = {n: n for n in free}

    def root(n: str) -> str:
        while parent[n] != n:
            n = parent[n]
        return n

    for line in scene.lines:
        bs = list(attach[line.name].values())
        for b in bs[1:]:
            parent[root(b)] = root(bs[0])
    groups: dict[str, list[str]] = {}
    for line in scene.lines:
        if attach[line.name]:
            groups.setdefault(root(next(iter(attach[line.name].values()))), []).append(line.name)
    return [(tuple(lnames), tuple(n for n in free if root(n) == r)) for r, lnames in groups.items()]


def _static_modes(
    lines: list[CoupledLine], bodies: list[RigidBody], omega: np.ndarray
) -> CoupledModes | None:
    """The group's coupled modes when no body's added mass is tabulated over ω (then
    A(ω_ref) is the same array for every ω_ref: the same modes to the bit; ``omega_ref``
    is set by the solve); else None."""
    if any(isinstance(b.added_mass, FrequencyTable) for b in bodies):
        return None
    return coupled_modes(lines, bodies, float(omega[omega.size // 2]), float(omega[-1]))
