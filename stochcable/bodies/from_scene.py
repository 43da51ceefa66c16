"""Scene bodies to :class:`stochcable.bodies.rigid.RigidBody` (docs/BODIES.md).

The scene document's :class:`stochcable.scene.model.Body` carries the data as given; the
numerical code works on :class:`~stochcable.bodies.rigid.RigidBody` (Tuah (1982), eq. 3.2.c.20
coefficients about the body reference point).  The hydrodynamic table (inline or a
file) is read with :mod:`stochcable.bodies.data`; explicit constant matrices of the body
replace the table's corresponding matrix.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from stochcable.bodies.data import body_from_hydrodynamics, load_hydrodynamics, read_table
from stochcable.bodies.rigid import RigidBody
from stochcable.errors import InputError
from stochcable.scene.model import Body, BodyHydrodynamicsFile, Environment, Scene

__all__ = ["rigid_body_from_scene", "scene_rigid_bodies"]


def rigid_body_from_scene(
    body: Body, *, planar: bool, environment: Environment, base_path: str | Path | None = None
) -> RigidBody:
    """The :class:`~stochcable.bodies.rigid.RigidBody` of a scene body.

    Parameters
    ----------
    body : Body
        The validated scene body.
    planar : bool
        Three DOFs (surge, heave, pitch): ``scene.is_planar``.  6×6 data are reduced.
    environment : Environment
        The scene environment (kept for the fluid properties; the coefficients are
        used as given).
    base_path : str or path, optional
        Folder a relative ``hydrodynamics.file`` is relative to (default the working
        folder; :func:`stochcable.scene.model.load_scene` already makes paths absolute).

    Returns
    -------
    RigidBody
        Position = ``body.position`` (the static pose is in the statics result), mass,
        inertia about the CoG, cog, added mass and radiation damping (tables over ω
        when ``hydrodynamics`` is given, else the constant matrices), hydrostatic
        stiffness, excitation table, drag area and point, extra stiffness and damping,
        fixed DOFs (held in the coupled dynamics as in the statics).

    Raises
    ------
    InputError
        Naming ``bodies[<name>].<field>`` for unreadable files or inconsistent data.
    """
    kw: dict[str, Any] = {
        "inertia": None if body.inertia is None else [list(r) for r in body.inertia],
        "cog": body.cog,
        "drag_area": body.drag_area,
        "drag_point": body.drag_point,
        "extra_stiffness": body.extra_stiffness,
        "extra_damping": body.extra_damping,
        "fixed_dofs": tuple(body.fixed_dofs),
    }
    for k in ("added_mass", "radiation_damping", "hydrostatic_stiffness"):
        if getattr(body, k) is not None:
            kw[k] = getattr(body, k)
    h = body.hydrodynamics
    where = f"bodies[{body.name}]"
    try:
        if h is None:
            return RigidBody(
                name=body.name, position=body.position, mass=body.mass, planar=planar, **kw
            )
        if isinstance(h, BodyHydrodynamicsFile):
            p = Path(h.file)
            if not p.is_absolute() and base_path is not None:
                p = Path(base_path) / p
            hydro = load_hydrodynamics(p)
        else:
            hydro = read_table(h.table())
        override = {k: kw.pop(k) for k in ("added_mass", "radiation_damping") if k in kw}
        rb = body_from_hydrodynamics(
            hydro,
            body.name,
            body.position,
            body.mass,
            planar=planar,
            extrapolation=body.extrapolation,
            **kw,
        )
        if override:
            rb = RigidBody(**{**{f: getattr(rb, f) for f in _FIELDS}, **override})
        return rb
    except InputError as exc:
        raise InputError(f"{where}.{exc.parameter}", exc.value, exc.unit, exc.constraint) from None


_FIELDS = (
    "name",
    "position",
    "mass",
    "inertia",
    "cog",
    "added_mass",
    "radiation_damping",
    "hydrostatic_stiffness",
    "excitation",
    "excitation_point",
    "drag_area",
    "drag_point",
    "extra_stiffness",
    "extra_damping",
    "planar",
    "fixed_dofs",
)


def scene_rigid_bodies(scene: Scene, base_path: str | Path | None = None) -> dict[str, RigidBody]:
    """Every body of a scene as a RigidBody, by name (:func:`rigid_body_from_scene`).

    Parameters
    ----------
    scene : Scene
    base_path : str or path, optional
        Folder for relative hydrodynamics files.

    Returns
    -------
    dict of str to RigidBody
        In scene order; planar (3 DOF) when ``scene.is_planar``.
    """
    planar = scene.is_planar
    return {
        b.name: rigid_body_from_scene(
            b, planar=planar, environment=scene.environment, base_path=base_path
        )
        for b in scene.bodies
    }
