"""The inputs of a line alone for one sea state, reused across sea states of the same
heading (the engine's load-case sets, Tuah (1982), ch. 5 per sea state).

The channels' transfer functions — the wave kinematics integrated along the elements,
the Morison inertia loads, the end motions and vessel RAOs per unit wave amplitude —
depend on the sea's heading and the frequency grid, not on its spectrum; only the
σ weights (trapezoid × spectrum) and the weighted mean square of the fluid velocity
do.  :func:`heading_inputs` keeps a line's channels and inputs of the last headings on
its :class:`~stochcable.dynamics.model.system.LineSystem` (the engine's sea-independent
state) and gives the next sea state of a known heading its spectra on them
(:func:`~stochcable.dynamics.loads.sea_channels.with_spectrum`,
:func:`~stochcable.dynamics.solve.line_loads.with_spectra`): the same numbers as forming
them again (tested), without the kinematics.  Lines whose inputs exceed
:data:`INPUT_CACHE_BYTES` are not kept (the memory bound of large models).  The lines
of a coupled group keep their channels alone (:func:`group_line_channels`: the group
forms its inputs in the group's channel order), with their kinematics per direction of
a short-crested sea.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

from collections.abc import Hashable

from stochcable.dynamics.groups.inputs import scene_line_channels
from stochcable.dynamics.groups.model import CoupledModel
from stochcable.dynamics.loads.channels import Channel
from stochcable.dynamics.loads.sea_channels import sea_channel_densities, with_spectrum
from stochcable.dynamics.solve.line_loads import LineInputs, line_inputs, with_spectra
from stochcable.scene.model import Line, Scene, Sea

__all__ = ["INPUT_CACHE_BYTES", "group_line_channels", "heading_inputs"]

#: Largest inputs (arrays and their drag-independent caches) of one line kept for the
#: next sea state, summed over the kept headings. [bytes]
INPUT_CACHE_BYTES = 128 * 2**20

_KEY = "heading_inputs"
_GROUP_KEY = "group_channels"


def heading_inputs(
    model: CoupledModel, scene: Scene, line: Line
) -> tuple[tuple[Channel, ...], LineInputs]:
    """The channels and inputs of a line attached to no free body for the sea state of
    ``scene`` (its spectrum and heading), reusing those of an earlier sea state of the
    same heading.

    Parameters
    ----------
    model : CoupledModel
        The engine's model (systems, grid, vessels' RAOs).
    scene : Scene
        The scene with the sea state.
    line : Line
        The scene line.

    Returns
    -------
    channels : tuple of Channel
        As :func:`~stochcable.dynamics.groups.inputs.scene_line_channels`.
    inputs : LineInputs or None
        Their inputs (None when the line has no channel).
    """
    system = model.systems[line.name]
    sea = scene.sea
    heading = _directions_key(sea)
    kept: dict[Hashable, tuple[tuple[Channel, ...], LineInputs]] = system._cache.setdefault(
        _KEY, {}
    )
    if heading in kept:
        ch0, inp0 = kept[heading]
        if sea is None:
            return ch0, inp0
        ch = _respectrum(ch0, sea, scene.environment.g)
        return ch, with_spectra(system, inp0, ch)
    ch, _ = scene_line_channels(scene, line, system, model.omega, model.vessel_rao)
    if not ch:
        return ch, None
    inp = line_inputs(system, ch)
    size = _nbytes(ch, inp)
    if 2 * size <= INPUT_CACHE_BYTES:  # (its caches of the solve: about as much again)
        while kept and 2 * size * (len(kept) + 1) > INPUT_CACHE_BYTES:
            kept.pop(next(iter(kept)))  # the oldest heading
        kept[heading] = (ch, inp)
    return ch, inp


def group_line_channels(
    model: CoupledModel, scene: Scene, line: Line
) -> tuple[tuple[Channel, ...], dict[str, str]]:
    """The channels of a line of a coupled group (attached to a free body) for the sea
    state of ``scene``: :func:`~stochcable.dynamics.groups.inputs.scene_line_channels`,
    reusing the kinematics of an earlier sea state of the same directions (heading and
    spreading) with this sea's spectra
    (:func:`~stochcable.dynamics.loads.sea_channels.with_spectrum`:
    the same numbers); kept while they fit :data:`INPUT_CACHE_BYTES`.

    Returns
    -------
    channels : tuple of Channel
    attach : dict of str to str
        ``{end: body}`` of its ends on free bodies.
    """
    system = model.systems[line.name]
    sea = scene.sea
    key = _directions_key(sea)
    kept: dict[Hashable, tuple[tuple[Channel, ...], dict[str, str]]] = system._cache.setdefault(
        _GROUP_KEY, {}
    )
    if key in kept:
        ch0, att = kept[key]
        return (ch0 if sea is None else _respectrum(ch0, sea, scene.environment.g)), dict(att)
    ch, att = scene_line_channels(scene, line, system, model.omega, model.vessel_rao)
    size = _channel_bytes(ch)
    if 2 * size <= INPUT_CACHE_BYTES:  # (the nodal kinematics filled on use: as much)
        while kept and 2 * size * (len(kept) + 1) > INPUT_CACHE_BYTES:
            kept.pop(next(iter(kept)))  # the oldest directions
        kept[key] = (ch, dict(att))
    return ch, att


def _directions_key(sea: Sea | None) -> Hashable:
    """The directions of a sea state: its heading and spreading (None: no sea)."""
    if sea is None:
        return None
    return (float(sea.heading), None if sea.spreading is None else sea.spreading.model_dump_json())


def _respectrum(channels: tuple[Channel, ...], sea: Sea, g: float) -> tuple[Channel, ...]:
    """``channels`` with the sea channels' spectra of ``sea`` (by channel name)."""
    dens = {name: d for name, _, d in sea_channel_densities(sea, g)}
    return tuple(with_spectrum(c, dens[c.name]) if c.kind == "sea" else c for c in channels)


def _channel_bytes(channels: tuple[Channel, ...]) -> int:
    """Bytes of the channels' element kinematics."""
    arrays = []
    for c in channels:
        arrays += [c.element_velocity, c.element_velocity_square, c.element_end_square]
        arrays += [c.element_square, c.element_velocity_parts, c.element_ends]
    return int(sum(getattr(a, "nbytes", 0) for a in arrays if a is not None))


def _nbytes(channels: tuple[Channel, ...], inp: LineInputs) -> int:
    """Bytes of the channels' element kinematics and of the inputs' arrays."""
    arrays = [inp.velocity, inp.ub, inp.inertia_extra]
    for c in channels:
        arrays += [c.element_velocity, c.element_velocity_square, c.element_end_square]
        arrays += [c.element_square, c.element_velocity_parts, c.element_ends]
    return int(sum(getattr(a, "nbytes", 0) for a in arrays if a is not None))
