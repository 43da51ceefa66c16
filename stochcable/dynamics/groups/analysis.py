"""Frequency-domain analysis of a scene: a built model
(:mod:`stochcable.dynamics.groups.model`) solved for a sea state.

:func:`analyze_coupled` is :func:`~stochcable.dynamics.groups.model.build_coupled`
then :func:`solve_coupled`.  A line attached to no free body is a group of its own
without bodies (the same fixed point, :func:`linearize_coupled`, then
:func:`~stochcable.dynamics.outputs.line_result.line_result`), an end on a prescribed body moving
with :func:`~stochcable.dynamics.groups.vessels.fairlead_motion` in the sea channel.
Each connected component of free bodies and their lines is one coupled group
(:func:`~stochcable.dynamics.groups.group_fixed_point.linearize_coupled`,
:func:`~stochcable.dynamics.groups.modes.coupled_modes`,
:func:`~stochcable.dynamics.groups.results.coupled_results`).
"""

from __future__ import annotations

import copy
import dataclasses
import time
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from stochcable.bodies.rigid import RigidBody
from stochcable.dynamics.groups.group_fixed_point import (
    CoupledLinearization,
    linearize_coupled,
)
from stochcable.dynamics.groups.inputs import (
    CoupledLine,
    body_loads,
    group_channels,
    reference_omega,
    sea_only_channels,
)
from stochcable.dynamics.groups.model import CoupledModel, ModelGroup, build_coupled
from stochcable.dynamics.groups.modes import coupled_modes
from stochcable.dynamics.groups.results import body_result, coupled_results
from stochcable.dynamics.groups.seainputs import group_line_channels, heading_inputs
from stochcable.dynamics.loads.channels import Channel
from stochcable.dynamics.loads.sea_channels import sea_channel_densities
from stochcable.dynamics.model.lift import check_lift_stability
from stochcable.dynamics.model.system import Damping, LineSystem, Progress, noop_progress
from stochcable.dynamics.outputs.line_result import line_result
from stochcable.dynamics.solve.line_loads import LineInputs, silent_channel
from stochcable.errors import InputError, PhysicsWarning, warn
from stochcable.results.documents import BodyResult, LineResult
from stochcable.scene.model import AnalysisSettings, Scene, Sea
from stochcable.statics import StaticsResult

__all__ = ["CoupledAnalysis", "CoupledGroup", "analyze_coupled", "solve_coupled"]

_TIMES = ("model_s", "linearization_s", "solve_s", "outputs_s")


@dataclass(frozen=True, eq=False)
class CoupledGroup:
    """Converged state of one coupled group: what re-solving it on another frequency
    grid needs (the time series, :mod:`stochcable.dynamics.timeseries.group_transfer`).

    Attributes
    ----------
    lines : tuple of str
        The group's lines in scene order (empty for a free-floating body).
    systems : dict of str to LineSystem
        Their systems (both end nodes prescribed).
    attach : dict of str to dict
        Per line ``{end: body}`` of its ends on the group's free bodies.
    bodies : tuple of RigidBody
        The free bodies at their static pose (``position``), with the gravity
        restoring of :func:`body_gravity_stiffness` in ``extra_stiffness``.
    pose : dict of str to ndarray, shape (d,)
        Static value of each body DOF (position and rotation). [m, rad]
    dampings : dict of str to Damping
        The converged linear drag of each line.
    body_drag : dict of str to ndarray, shape (3,)
        Linear drag per direction at the drag point of each body with a drag area,
        the one the converged response was solved with
        (:attr:`CoupledLinearization.body_drag`). [N·s/m]
    """

    lines: tuple[str, ...]
    systems: dict[str, LineSystem]
    attach: dict[str, dict[str, str]]
    bodies: tuple[RigidBody, ...]
    pose: dict[str, np.ndarray]
    dampings: dict[str, Damping]
    body_drag: dict[str, np.ndarray]


@dataclass(frozen=True, eq=False)
class CoupledAnalysis:
    """Outcome of :func:`analyze_coupled`; unpacks as the 4-tuple
    ``lines, bodies, systems, dampings``.

    Attributes
    ----------
    lines : dict of str to LineResult
        Every line of the scene, in scene order.
    bodies : dict of str to BodyResult
        Every body (prescribed ones with their RAO motion).
    systems : dict of str to LineSystem
        The lines NOT coupled to a free body (independent path).
    dampings : dict of str to Damping
        Their converged drag.
    groups : tuple of CoupledGroup
        Each coupled group, then each free-floating body without lines.
    alone : tuple of CoupledGroup
        Each line attached to no free body as a group without bodies, in scene order.
    """

    lines: dict[str, LineResult]
    bodies: dict[str, BodyResult]
    systems: dict[str, LineSystem]
    dampings: dict[str, Damping]
    groups: tuple[CoupledGroup, ...] = ()
    alone: tuple[CoupledGroup, ...] = ()

    def __iter__(self) -> Iterator[Mapping[str, object]]:
        return iter((self.lines, self.bodies, self.systems, self.dampings))


def analyze_coupled(
    scene: Scene,
    statics: StaticsResult,
    settings: AnalysisSettings,
    progress: Progress | None = None,
    timing: dict[str, float] | None = None,
    *,
    rigid_bodies: Mapping[str, RigidBody] | None = None,
) -> CoupledAnalysis:
    """Frequency-domain analysis of a scene with bodies (the ``analyze`` branch).

    Parameters
    ----------
    scene : Scene
        A validated scene with ``bodies``.
    statics : StaticsResult
        Its static equilibrium (lines with attached ends at the body poses, and
        ``statics.bodies``).
    settings : AnalysisSettings
    progress : callable, optional
    timing : dict, optional
        Accumulates ``model_s``, ``linearization_s``, ``solve_s``, ``outputs_s``. [s]
    rigid_bodies : mapping of str to RigidBody, optional
        The bodies as RigidBody (default
        :func:`stochcable.bodies.from_scene.scene_rigid_bodies`); their ``position`` is
        replaced by the static pose of ``statics.bodies`` when present.

    Returns
    -------
    CoupledAnalysis
        Unpacks as ``lines, bodies, systems, dampings``:  every line's LineResult in
        scene order; every body's BodyResult (prescribed ones with their RAO motion);
        the LineSystem and converged Damping of the lines NOT coupled to a free body.
        ``groups`` holds the converged state of each coupled group (and of each
        free-floating body without lines) for the time series
        (:func:`stochcable.dynamics.timeseries.group_transfer.coupled_group_transfer`).

    Notes
    -----
    :func:`~stochcable.dynamics.groups.model.build_coupled` then
    :func:`solve_coupled` for the scene's sea (module docstring).
    """
    timing = {} if timing is None else timing
    for key in _TIMES:
        timing.setdefault(key, 0.0)
    model = build_coupled(scene, statics, settings, rigid_bodies=rigid_bodies, timing=timing)
    return solve_coupled(model, None, settings, progress, timing)


def solve_coupled(
    model: CoupledModel,
    sea: Sea | Scene | None = None,
    settings: AnalysisSettings | None = None,
    progress: Progress | None = None,
    timing: dict[str, float] | None = None,
) -> CoupledAnalysis:
    """Solve a built scene with bodies for one sea state.

    Parameters
    ----------
    model : CoupledModel
        From :func:`~stochcable.dynamics.groups.model.build_coupled`; not changed by
        the solve (its line systems fill their caches of sea-independent arrays on
        first use).
    sea : Sea or Scene, optional
        The sea state (spectrum and heading; of a Scene its ``sea`` alone is used).
        Default: the sea of ``model.scene``.
    settings : AnalysisSettings, optional
        Linearization and ``duration`` (default ``model.settings``); its grid must be
        the model's.
    progress : callable, optional
        ``progress("linearization", {...})`` per iteration.
    timing : dict, optional
        Accumulates ``model_s`` (channels), ``linearization_s``, ``solve_s``,
        ``outputs_s``. [s]

    Returns
    -------
    CoupledAnalysis
        As :func:`analyze_coupled`.

    Raises
    ------
    InputError
        ``settings`` on another grid than the model; a vessel RAO without a sea.
    """
    settings = model.settings if settings is None else settings
    if not np.array_equal(settings.omega.values(), model.omega):
        raise InputError(
            "settings.omega", settings.omega, "rad/s", "must be the grid the model was built on"
        )
    scene = _with_sea(model.scene, sea)
    progress = noop_progress if progress is None else progress
    timing = {} if timing is None else timing
    for key in _TIMES:
        timing.setdefault(key, 0.0)
    t0 = time.perf_counter()
    chans: dict[str, tuple[Channel, ...]] = {}
    inputs: dict[str, LineInputs] = {}
    alone = set(model.independent)
    for line in scene.lines:
        if line.name in alone:
            chans[line.name], inputs[line.name] = heading_inputs(model, scene, line)
        else:
            chans[line.name], _ = group_line_channels(model, scene, line)
    timing["model_s"] += time.perf_counter() - t0
    lines_out: dict[str, LineResult] = {}
    bodies_out: dict[str, BodyResult] = {}
    dampings: dict[str, Damping] = {}
    alone: list[CoupledGroup] = []
    for name in model.independent:
        lines_out[name], state = _solve_line(
            model, name, chans[name], settings, progress, timing, inputs.pop(name, None)
        )
        dampings[name] = state.dampings[name]
        alone.append(state)
    index = {line.name: i for i, line in enumerate(scene.lines)}
    for name in model.independent:  # a galloping line has no stationary response
        check_lift_stability(model.systems[name], dampings[name], index[name])
    states: list[CoupledGroup] = []
    for group in model.groups:
        lo, bo, state = _solve_group(model, scene, group, chans, settings, progress, timing)
        lines_out.update(lo)
        bodies_out.update(bo)
        states.append(state)
    for n in model.lonely:  # free-floating bodies without lines: the body alone
        solved = _solve_lonely(model, scene, n, settings, progress, timing)
        if solved is not None:
            bodies_out[n], state = solved
            states.append(state)
    if scene.sea is not None:
        bodies_out.update(_vessel_results(model, scene, settings))
    ordered = {line.name: lines_out[line.name] for line in scene.lines}
    ordered_b = {b.name: bodies_out[b.name] for b in scene.bodies if b.name in bodies_out}
    systems = {n: model.systems[n] for n in model.independent}
    return CoupledAnalysis(ordered, ordered_b, systems, dampings, tuple(states), tuple(alone))


def _with_sea(scene: Scene, sea: Sea | Scene | None) -> Scene:
    """The model's scene with the sea state ``sea`` (a Sea, a Scene or None)."""
    if sea is None:
        return scene
    if hasattr(sea, "lines"):  # a Scene: its sea
        sea = sea.sea
    if hasattr(scene, "model_copy"):  # the frozen pydantic Scene
        return scene.model_copy(update={"sea": sea})
    out = copy.copy(scene)  # a stand-in scene object
    out.sea = sea
    return out


def _solve_line(
    model: CoupledModel,
    name: str,
    ch: tuple[Channel, ...],
    settings: AnalysisSettings,
    progress: Progress,
    timing: dict[str, float],
    inputs: LineInputs | None = None,
) -> tuple[LineResult, CoupledGroup]:
    """A line attached to no free body: the group of this line alone (no bodies),
    its own channels (a silent one without excitation, with a PhysicsWarning) and
    their ``inputs`` when already formed (:func:`heading_inputs`)."""
    if not ch:
        warn(
            f"line '{name}' has no excitation (no sea and no end motion): its "
            "dynamic response is zero; add a 'sea' or an end 'motion'",
            PhysicsWarning,
            stacklevel=4,
        )
        ch = silent_channel(model.omega)
    cl = CoupledLine(model.systems[name], ch)
    progress("linearization", {"line": name, "iteration": 0})
    t1 = time.perf_counter()
    clin = linearize_coupled(
        [cl],
        [],
        settings,
        rho=model.scene.environment.rho,
        progress=progress,
        timing=timing,
        inputs=None if inputs is None or not ch else {name: inputs},
    )
    inputs = None  # (not held through the outputs: the heading cache keeps small ones)
    timing["linearization_s"] += time.perf_counter() - t1
    progress("outputs", {"line": name})
    t1 = time.perf_counter()
    out = line_result(cl.system, ch, clin.lines[name], settings)
    timing["outputs_s"] += time.perf_counter() - t1
    return out, _group_state([name], model, [], clin)


def _solve_group(
    model: CoupledModel,
    scene: Scene,
    group: ModelGroup,
    chans: Mapping[str, tuple[Channel, ...]],
    settings: AnalysisSettings,
    progress: Progress,
    timing: dict[str, float],
) -> tuple[dict[str, LineResult], dict[str, BodyResult], CoupledGroup]:
    """A coupled group: its fixed point, modes and results."""
    omega, env = model.omega, scene.environment
    lnames, attach = group.lines, model.attach
    gbodies = [model.free[n] for n in group.bodies]
    group_ch = group_channels(lnames, chans, omega)
    cls = [
        CoupledLine(
            model.systems[n],
            group_ch[n],
            end_a=attach[n].get("end_a"),
            end_b=attach[n].get("end_b"),
        )
        for n in lnames
    ]
    first = cls[0].channels
    loads = {b.name: body_loads(b, first, omega, scene.sea, env) for b in gbodies}
    t1 = time.perf_counter()
    clin = linearize_coupled(
        cls, gbodies, settings, rho=env.rho, loads=loads, progress=progress, timing=timing
    )
    timing["linearization_s"] += time.perf_counter() - t1
    t1 = time.perf_counter()
    w_ref = reference_omega(first, omega)
    if group.modes is None:
        modes = coupled_modes(cls, gbodies, w_ref, float(omega[-1]))
    else:  # sea-independent (constant added mass): the model's, at this sea's ω_ref
        modes = dataclasses.replace(group.modes, omega_ref=float(w_ref))
    lo, bo = coupled_results(
        cls, gbodies, clin, settings, static_pose=model.pose, modes=modes, loads=loads
    )
    timing["outputs_s"] += time.perf_counter() - t1
    return lo, bo, _group_state(lnames, model, gbodies, clin)


def _solve_lonely(
    model: CoupledModel,
    scene: Scene,
    name: str,
    settings: AnalysisSettings,
    progress: Progress,
    timing: dict[str, float],
) -> tuple[BodyResult, CoupledGroup] | None:
    """A free-floating body without lines: the body alone in the sea (None without
    a sea)."""
    if scene.sea is None:
        warn(
            f"body '{name}' has no lines and there is no sea: its motion is zero",
            PhysicsWarning,
            stacklevel=4,
        )
        return None
    omega, env = model.omega, scene.environment
    sea_ch = sea_only_channels(scene.sea, omega, env.g)
    b = model.free[name]
    t1 = time.perf_counter()
    clin = linearize_coupled(
        [],
        [b],
        settings,
        rho=env.rho,
        channels=sea_ch,
        loads={name: body_loads(b, sea_ch, omega, scene.sea, env)},
        progress=progress,
        timing=timing,
    )
    timing["linearization_s"] += time.perf_counter() - t1
    _, bo = coupled_results([], [b], clin, settings, static_pose=model.pose, channels=sea_ch)
    return bo[name], _group_state([], model, [b], clin)


def _vessel_results(
    model: CoupledModel, scene: Scene, settings: AnalysisSettings
) -> dict[str, BodyResult]:
    """The prescribed bodies' motion statistics from their RAOs in the sea: one channel
    per sea channel (each direction of a short-crested sea with the RAO of its
    heading), the spectra summed over them."""
    omega, env = model.omega, scene.environment
    body_docs = {b.name: b for b in scene.bodies}
    if scene.sea.spreading is None:
        dens = [("sea", scene.sea.heading_rad, None)]
        sea = np.atleast_2d(scene.sea.spectrum.spectral_density(omega, env.g))
    else:
        dens = sea_channel_densities(scene.sea, env.g)
        sea = np.stack([d(omega) for _, _, d in dens])
    names = tuple(n for n, _, _ in dens)
    out = {}
    for n in model.prescribed:
        h = np.stack([model.vessel_rao.at(n, beta).T for _, beta, _ in dens])
        dofs = ("surge", "sway", "heave", "roll", "pitch", "yaw")
        mean = np.concatenate([np.asarray(body_docs[n].position, float), np.zeros(3)])
        out[n] = body_result(
            n, dofs, omega, names, sea, h, mean, settings.duration, prescribed=True
        )
    return out


def _group_state(
    lnames: Sequence[str],
    model: CoupledModel,
    bodies: Sequence[RigidBody],
    clin: CoupledLinearization,
) -> CoupledGroup:
    return CoupledGroup(
        lines=tuple(lnames),
        systems={n: model.systems[n] for n in lnames},
        attach={n: dict(model.attach[n]) for n in lnames},
        bodies=tuple(bodies),
        pose={b.name: np.asarray(model.pose[b.name], dtype=float).copy() for b in bodies},
        dampings={n: clin.lines[n].damping for n in lnames},
        body_drag={k: np.asarray(v, dtype=float).copy() for k, v in clin.body_drag.items()},
    )
