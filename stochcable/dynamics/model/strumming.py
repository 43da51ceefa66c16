"""Strumming screening of a line system at engine build (docs/strumming.md).

One function, :func:`with_strumming`, called once per line by
:func:`stochcable.dynamics.engine.build_engine`: the current is sea-independent, so the
screening (:func:`stochcable.line.strumming.screen.strumming_screen`) runs once, and the
amplified normal drag coefficient it returns replaces the mesh's in the line system
every drag linearization reads (``system.model.mesh.cd_normal``).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from stochcable.dynamics.loads.channels import current_at_elements
from stochcable.dynamics.model.system import LineSystem
from stochcable.errors import ResolutionWarning, warn
from stochcable.line.modes import natural_modes
from stochcable.line.strumming.modes import modes_by_node, out_of_plane_modes
from stochcable.line.strumming.screen import (
    LIFT_DEFAULT,
    STROUHAL_DEFAULT,
    StrummingInput,
    StrummingTable,
    strumming_screen,
)
from stochcable.scene.model import Scene

__all__ = ["MAX_MODES", "strumming_inputs", "with_strumming"]

#: Most natural modes of a 3-D model computed for the screening. [-]
MAX_MODES = 512


def strumming_inputs(
    scene: Scene, system: LineSystem
) -> tuple[StrummingInput, np.ndarray, np.ndarray] | None:
    """What :func:`with_strumming` screens: the line's data and its modes.

    Parameters
    ----------
    scene : Scene
    system : LineSystem

    Returns
    -------
    (StrummingInput, omega [rad/s], shapes (n_nodes, 3, count) [kg^-1/2]) or None
        None without current or with every segment suppressed.
    """
    env = scene.environment
    if not any(p.speed > 0 for p in env.current):
        return None
    model, mesh, line = system.model, system.model.mesh, system.line
    settings = [sg.strumming for sg in line.segments]
    on = np.array([s is None or s.suppression == "none" for s in settings])[mesh.segment]
    if not on.any():
        return None
    pick = np.asarray(mesh.segment)

    def per_el(attr: str, default: float) -> np.ndarray:
        vals = [default if s is None else getattr(s, attr) for s in settings]
        return np.array([math.nan if v == "reynolds" else v for v in vals], dtype=float)[pick]

    # the current itself (a travelling line's current_el is the relative flow U − c e,
    # whose axial part sheds no vortices)
    current = system.current_el
    if system.gyro is not None:
        current = current_at_elements(system.environment, model.positions)
    u_max = float(np.max(np.linalg.norm(current, axis=1)))
    w_top = 2.0 * math.pi * u_max / (3.0 * float(np.min(mesh.diameter)))
    modes = system.modes
    n_free = int(model.free.size)
    while modes.omega.size < min(n_free, MAX_MODES) and modes.omega[-1] < w_top:
        modes = natural_modes(model, min(n_free, MAX_MODES, 2 * modes.omega.size))
    if modes.omega.size < n_free and modes.omega[-1] < w_top:
        warn(
            f"line {line.name!r}: the strumming screening stops at mode {modes.omega.size} "
            f"({modes.omega[-1]:.4g} rad/s, MAX_MODES = {MAX_MODES}) below "
            f"{w_top:.4g} rad/s, the highest natural frequency the current can lock in "
            "(reduced velocity 3): modes above it are not screened; screen the line "
            "alone with fewer elements or check its high modes separately",
            ResolutionWarning,
        )
    omega, shapes = modes.omega, modes_by_node(model, modes)
    if model.dim == 2:
        w_out, s_out = out_of_plane_modes(model, w_top)
        order = np.argsort(np.concatenate([omega, w_out]), kind="stable")
        omega = np.concatenate([omega, w_out])[order]
        shapes = np.concatenate([shapes, s_out], axis=2)[:, :, order]
    inp = StrummingInput(
        positions=model.positions,
        current=current,
        diameter=mesh.diameter,
        cd_normal=mesh.cd_normal,
        mass=mesh.mass,
        ca_normal=mesh.ca_normal,
        ea=mesh.ea,
        l0=mesh.l0,
        strouhal=per_el("strouhal", STROUHAL_DEFAULT),  # NaN: from Re
        lift=np.where(on, per_el("lift_coefficient", LIFT_DEFAULT), 0.0),
        rho=env.rho,
        viscosity=env.viscosity,
        structural_damping=per_el("damping_ratio", 0.0),
    )
    return inp, omega, shapes


def with_strumming(scene: Scene, system: LineSystem) -> tuple[LineSystem, StrummingTable | None]:
    """Screen ``system`` for strumming; the system with the amplified drag.

    Parameters
    ----------
    scene : Scene
        The scene (environment: density, viscosity, current).
    system : LineSystem
        The line's linear model about its static shape (modes with added mass).

    Returns
    -------
    system : LineSystem
        ``system`` with ``model.mesh.cd_normal`` amplified where the line strums (the
        same object when nothing strums).
    table : StrummingTable or None
        The screening; None without current or with every segment suppressed.

    Notes
    -----
    Modes: the system's (global x, y, z per node), computed further up when they stop
    below the highest frequency a lock-in band can reach (V_R = 3: ω_n = 2π U/(3D));
    a 2-D model adds its out-of-plane modes
    (:func:`~stochcable.line.strumming.modes.out_of_plane_modes`).  A physics warning
    names every locked-in mode, the band and the fix.
    """
    got = strumming_inputs(scene, system)
    if got is None:
        return system, None
    inp, omega, shapes = got
    mesh, line = system.model.mesh, system.line
    table = strumming_screen(inp, omega, shapes)
    cd0 = np.asarray(mesh.cd_normal, dtype=float)
    gain = float(np.max(np.divide(table.cd_normal, cd0, out=np.ones_like(cd0), where=cd0 > 0)))
    for m in table.locked:
        warn(
            f"line {line.name!r}: strumming "
            f"{'lock-in' if m.locked else 'resonance with the free wakes'} predicted for "
            f"mode {m.index} "
            f"(ω_n = {m.omega_n:.4g} rad/s, shedding ω_s = {m.omega_s:.4g} rad/s, reduced "
            f"velocity V_R = {m.reduced_velocity:.3g} inside the cross-flow band 3-16 of "
            f"DNV-RP-C205): cross-flow amplitude A/D = {m.amplitude_over_d:.3g}, normal "
            f"drag amplified up to x{gain:.3g}; "
            "fit strakes or fairings (segments[i].strumming.suppression) or move the mode "
            "out of the band (tension, diameter)"
        )
    if table.governing is None or np.array_equal(table.cd_normal, mesh.cd_normal):
        return system, table
    new_model = replace(system.model, mesh=replace(mesh, cd_normal=table.cd_normal))
    return replace(system, model=new_model), table
