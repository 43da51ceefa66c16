"""Inputs of a coupled group: its lines, the body loads, vessel-driven ends and the
group's channels (Tuah 1982, §3.2.c, §3.3).

A coupled group (:mod:`stochcable.dynamics.groups`) is solved on one list of input
channels: the sea's first (``"sea"``; a short-crested sea's ``"sea@<heading in deg>"``,
one per direction, :mod:`stochcable.dynamics.loads.sea_channels`), then
``"<line>.<end>.<dof>"`` for the end-motion spectra of the lines' unattached ends
(:func:`group_channels`).  Each line sees every channel of
the group (the ones that do not concern it carry only their spectrum).

Vessel-driven ends
------------------
An end attached to a *prescribed* body (a vessel with a motion RAO ξ_RAO) moves with
the RAO u = T(r)·ξ_RAO (three translations; the rotations move it through the arm r)
coherently with the sea: it is the sea channel's end motion of an otherwise
independent line (:func:`fairlead_motion`, :func:`scene_line_channels`), no coupling
back.  In a short-crested sea each direction channel θ_k carries the RAO of its
direction (:class:`VesselRaos`; a table without headings the same in every direction,
so the fairlead's motion spectrum is |RAO|² Σ_k w_k S = |RAO|² S).

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from stochcable.bodies.rigid import (
    RigidBody,
    attachment_geometric_stiffness,
)
from stochcable.dynamics.groups.vessels import VesselRaos, fairlead_motion
from stochcable.dynamics.loads.channels import Channel
from stochcable.dynamics.loads.sea_channels import sea_channel_densities, sea_channel_headings
from stochcable.dynamics.model.system import LineSystem
from stochcable.errors import InputError
from stochcable.scene.model import Environment, Line, Scene, Sea

__all__ = [
    "BodyLoads",
    "CoupledLine",
    "body_gravity_stiffness",
    "body_loads",
    "group_channels",
    "reference_omega",
    "scene_line_channels",
    "sea_only_channels",
    "unit_channels",
]


@dataclass(frozen=True, eq=False)
class CoupledLine:
    """A line of a coupled group: its system, channels and body attachments.

    Parameters
    ----------
    system : LineSystem
        The line about its static shape, both end nodes prescribed
        (:func:`stochcable.dynamics.model.system.build_line_system`).
    channels : tuple of Channel
        The group's input channels in the group order, sampled on the analysis grid,
        as seen by this line: fluid kinematics and the motion of its *unattached*
        ends (channels that do not concern the line carry only the spectrum).
    end_a, end_b : str, optional
        Name of the (free) body the end is attached to; None: the end stays
        prescribed (fixed or moving with its channels).
    """

    system: LineSystem
    channels: tuple[Channel, ...]
    end_a: str | None = None
    end_b: str | None = None

    @property
    def name(self) -> str:
        return self.system.name

    def attached(self) -> list[tuple[int, str]]:
        """(end index 0/1, body name) of the attached ends."""
        return [(k, b) for k, b in enumerate((self.end_a, self.end_b)) if b is not None]


@dataclass(frozen=True, eq=False)
class BodyLoads:
    """Wave inputs of one body per channel.

    Parameters
    ----------
    force : ndarray, complex, shape (n_omega, d, n_ch)
        Wave excitation per unit input (:func:`stochcable.bodies.rigid.body_excitation`).
        [N/m, N·m/m]
    velocity : ndarray, complex, shape (n_omega, 3, n_ch)
        Fluid velocity at the drag point per unit input. [(m/s)/m]
    current : ndarray, shape (3,)
        Current at the drag point (the mean relative velocity). [m/s]
    """

    force: np.ndarray
    velocity: np.ndarray
    current: np.ndarray


def body_loads(
    body: RigidBody,
    channels: Sequence[Channel],
    omega: np.ndarray,
    sea: Sea | None,
    environment: Environment,
) -> BodyLoads:
    """Excitation force and drag-point fluid velocity of a body per channel.

    Parameters
    ----------
    body : RigidBody
    channels : sequence of Channel
        The group's channels (only ``kind == "sea"`` loads the body).
    omega : ndarray, shape (n_omega,)
        [rad/s]
    sea : Sea or None
        The scene's sea (heading and spreading).
    environment : Environment
        depth, g, current.

    Returns
    -------
    BodyLoads
        Each sea channel at its heading β (the sea's heading; a direction of a
        short-crested sea, :func:`~stochcable.dynamics.loads.sea_channels.sea_channel_headings`):
        ``body_excitation(body, ω, β, k)`` (phase moved to the global wave phase) and
        the linear wave velocity at the drag point
        (:func:`stochcable.sea.kinematics.wave_kinematics`, zero above z = 0).

    Raises
    ------
    InputError
        ``heading``: a direction outside the body's excitation table (for a
        short-crested sea the message names the direction and its channel).
    """
    from stochcable.sea.kinematics import wave_kinematics, wavenumber

    w = np.asarray(omega, dtype=float)
    n_ch = len(channels)
    d = body.n_dof
    force = np.zeros((w.size, d, n_ch), dtype=complex)
    vel = np.zeros((w.size, 3, n_ch), dtype=complex)
    point = body.position + body.drag_point
    headings = {} if sea is None else sea_channel_headings(sea)
    k = None
    for i, ch in enumerate(channels):
        if ch.kind != "sea" or sea is None:
            continue
        beta = headings[ch.name]
        if k is None:  # (the same for every direction)
            k = wavenumber(w, environment.depth, environment.g)
        force[:, :, i] = _excitation(body, w, beta, k, ch.name, sea)
        if np.any(body.drag_area > 0):
            p = point.copy()
            p[2] = max(p[2], -environment.depth)
            kin = wave_kinematics(w, p, beta, environment.depth, environment.g)
            vel[:, :, i] = kin.velocity[0].T
    cur = np.asarray(environment.current_velocity(np.array([min(point[2], 0.0)]))[0], dtype=float)
    return BodyLoads(force=force, velocity=vel, current=cur)


def _excitation(
    body: RigidBody, w: np.ndarray, beta: float, k: np.ndarray, channel: str, sea: Sea | None
) -> np.ndarray:
    """:func:`~stochcable.bodies.rigid.body_excitation` at heading ``beta`` [rad]; a
    heading outside the table of a short-crested sea's direction names the direction."""
    from stochcable.bodies.rigid import body_excitation

    try:
        return body_excitation(body, w, beta, wavenumber=k)
    except InputError as exc:
        if exc.parameter != "heading" or sea.spreading is None:
            raise
        ds = sea.direction_set()
        j = int(np.argmin(np.abs(ds.heading - beta)))
        raise InputError(
            "heading",
            exc.value,
            exc.unit,
            f"{exc.constraint} of body '{body.name}' — direction {j + 1} of {ds.count} "
            f"(channel '{channel}', weight {ds.weight[j]:.3g}) of sea.spreading "
            f"({sea.spreading.type}) about sea.heading = {sea.heading:g} deg: give the "
            "body's excitation at every direction of the spreading (a table over the "
            "whole circle) or narrow the spreading",
        ) from None


def body_gravity_stiffness(
    body: RigidBody, displaced_volume: float, centre_of_buoyancy: ArrayLike, rho: float, g: float
) -> np.ndarray:
    """Restoring of the weight and the buoyancy of a body when it rotates.

    Parameters
    ----------
    body : RigidBody
        Mass and centre of gravity ``cog`` (relative to the reference point).
    displaced_volume : float
        Displaced volume ∇. [m³]
    centre_of_buoyancy : array_like, shape (3,)
        Centre of buoyancy relative to the reference point. [m]
    rho, g : float
        Water density [kg/m³] and gravity [m/s²].

    Returns
    -------
    ndarray, shape (d, d)
        Σ −[F]×[r]× over the weight F = (0, 0, −m g) at the CoG and the buoyancy
        (0, 0, ρ g ∇) at the CoB (:func:`stochcable.bodies.rigid.attachment_geometric_stiffness`):
        roll and pitch restoring ρ g ∇ z_B − m g z_G (the metacentric terms of a
        fully submerged body, option (a) of docs/BODIES.md "Symmetry"). [N·m/rad]

    Notes
    -----
    No waterplane terms: a surface-piercing body needs its ``hydrostatic_stiffness``
    (which already contains these gravity terms, WAMIT convention).
    """
    w = np.array([0.0, 0.0, -body.mass * g])
    b = np.array([0.0, 0.0, rho * g * float(displaced_volume)])
    cob = np.asarray(centre_of_buoyancy, dtype=float)
    return attachment_geometric_stiffness(
        w, body.cog, body.planar
    ) + attachment_geometric_stiffness(b, cob, body.planar)


def _zero_density(w: np.ndarray) -> np.ndarray:
    return np.zeros_like(np.asarray(w, dtype=float))


def sea_only_channels(sea: Sea, omega: np.ndarray, g: float) -> tuple[Channel, ...]:
    """The sea's channels on ``omega`` [rad/s] without line kinematics, the inputs of
    a free-floating body: "sea", or one "sea@<deg>" per direction of a short-crested
    sea with its share of the spectrum
    (:func:`~stochcable.dynamics.loads.sea_channels.sea_channel_densities`); ``g`` [m/s²]."""
    return tuple(
        Channel(name=name, kind="sea", omega=omega, spectrum=d(omega), density=d)
        for name, _, d in sea_channel_densities(sea, g)
    )


def unit_channels(cl: CoupledLine) -> tuple[Channel, ...]:
    """The unit end-motion channels of a line's attached ends.

    Parameters
    ----------
    cl : CoupledLine

    Returns
    -------
    tuple of Channel
        d channels per attached end (``"unit.<end index>.<component>"``, kind
        ``"end_motion"``, zero spectrum): a unit motion [m] of one component of the
        end node at every frequency, the extra right-hand sides G, R_e of the
        substructuring (:mod:`stochcable.dynamics.groups.group`).
    """
    model = cl.system.model
    comps = list(model.components)
    w = cl.channels[0].omega
    out = []
    for k, _ in cl.attached():
        for j, c in enumerate(comps):
            m = np.zeros((w.size, 3), dtype=complex)
            m[:, c] = 1.0
            out.append(
                Channel(
                    name=f"unit.{k}.{j}",
                    kind="end_motion",
                    omega=w,
                    spectrum=np.zeros(w.size),
                    density=_zero_density,
                    motion_a=m if k == 0 else None,
                    motion_b=m if k == 1 else None,
                )
            )
    return tuple(out)


def reference_omega(channels: Sequence[Channel], omega: np.ndarray) -> float:
    """Frequency at which frequency-dependent added mass is frozen for the modes.

    Parameters
    ----------
    channels : sequence of Channel
        The group's channels (their spectra on ``omega``).
    omega : ndarray, shape (n_omega,)
        The analysis grid. [rad/s]

    Returns
    -------
    float
        The peak of the sea spectrum on the grid, else of the first channel with a
        nonzero spectrum, else the grid middle. [rad/s]
    """
    for c in channels:
        if c.kind == "sea" and np.any(c.spectrum > 0):
            return float(omega[int(np.argmax(c.spectrum))])
    for c in channels:
        if np.any(c.spectrum > 0):
            return float(omega[int(np.argmax(c.spectrum))])
    return float(omega[omega.size // 2])


def group_channels(
    lnames: Sequence[str], chans: Mapping[str, tuple[Channel, ...]], omega: np.ndarray
) -> dict[str, tuple[Channel, ...]]:
    """Align the lines' channels on the group's channel list.

    Parameters
    ----------
    lnames : sequence of str
        The group's lines in scene order.
    chans : mapping of str to tuple of Channel
        Each line's own channels (:func:`scene_line_channels`).
    omega : ndarray, shape (n_omega,)
        The grid (for the ``"none"`` channel of a group without excitation). [rad/s]

    Returns
    -------
    dict of str to tuple of Channel
        Per line the group's list: the sea's channels (``"sea"`` or one
        ``"sea@<deg>"`` per direction), then ``"<line>.<end>.<dof>"`` of every
        line's end motions; channels of another line carry only their spectrum.
    """
    order: list[tuple[str, str, Channel]] = []
    seas: dict[str, Channel] = {}  # the sea's channels (one per direction), in order
    for n in lnames:
        for c in chans[n]:
            if c.kind == "sea":
                seas[c.name] = c
            else:
                order.append((n, f"{n}.{c.name}", c))
    out = {}
    for n in lnames:
        own = {c.name: c for c in chans[n]}
        lst = [
            own.get(
                name,
                dataclasses.replace(
                    sea,
                    velocity=None,
                    acceleration=None,
                    motion_a=None,
                    motion_b=None,
                    element_velocity=None,
                    element_velocity_square=None,
                    element_square=None,
                    element_velocity_parts=None,
                    element_ends=None,
                    element_end_square=None,
                ),
            )
            for name, sea in seas.items()
        ]
        for owner, full, c in order:
            if owner == n:
                lst.append(dataclasses.replace(c, name=full))
            else:
                lst.append(
                    Channel(
                        name=full,
                        kind="end_motion",
                        omega=c.omega,
                        spectrum=c.spectrum,
                        density=c.density,
                    )
                )
        if not lst:
            lst = [
                Channel(
                    name="none",
                    kind="none",
                    omega=omega,
                    spectrum=np.zeros(omega.size),
                    density=_zero_density,
                )
            ]
        out[n] = tuple(lst)
    return out


def scene_line_channels(
    scene: Scene,
    line: Line,
    system: LineSystem,
    omega: np.ndarray,
    vessels: VesselRaos,
) -> tuple[tuple[Channel, ...], dict[str, str]]:
    """A scene line's input channels on ``omega`` and its ends on free bodies.

    Parameters
    ----------
    scene : Scene
        Environment, sea, bodies.
    line : Line
        The scene line (its end attachments and motions).
    system : LineSystem
        Its system (static node positions).
    omega : ndarray, shape (n_omega,)
        [rad/s]
    vessels : VesselRaos
        The prescribed bodies' RAOs on ``omega``.

    Returns
    -------
    channels : tuple of Channel
        As :func:`stochcable.dynamics.loads.channels.line_channels`, each end attached to a
        prescribed body moving with :func:`fairlead_motion` inside every sea channel,
        with the vessel's RAO of that channel's direction.
    attach : dict of str to str
        ``{end: body}`` of the ends attached to free bodies (solved with the body).
    """
    from stochcable.dynamics.loads.channels import line_channels

    body_docs = {b.name: b for b in getattr(scene, "bodies", ()) or ()}
    ch = line_channels(scene, line, system.positions, omega)
    att: dict[str, str] = {}
    for k, end in enumerate(("end_a", "end_b")):
        a = getattr(getattr(line, end), "attach", None)
        if a is None:
            continue
        if a.body not in vessels:
            att[end] = a.body
            continue
        if scene.sea is None:
            raise InputError(
                f"bodies[{a.body}].prescribed",
                "RAO table",
                "-",
                "a vessel motion RAO is relative to the sea: the scene needs a 'sea'",
            )
        headings = sea_channel_headings(scene.sea)
        node = 0 if k == 0 else system.model.n_nodes - 1
        r = system.positions[node] - np.asarray(body_docs[a.body].position, float)
        ch = tuple(
            dataclasses.replace(
                c, **{f"motion_{end[-1]}": fairlead_motion(vessels.at(a.body, headings[c.name]), r)}
            )
            if c.kind == "sea"
            else c
            for c in ch
        )
    return ch, att
