"""Build once, solve per sea state: the seam between the sea-independent model of a
scene and its response to one sea state (Tuah 1982, ch. 5).

:func:`build_engine` does everything that does not depend on the sea: the static
equilibrium (all nonlinearities), the finite-element model of every line about it,
its natural modes and the drag-independent arrays of the block-banded solves
(:class:`~stochcable.dynamics.model.blocks.LinePrep`; the banded Cholesky of K_ff and the
modal matrices are computed on first use and then kept on the line's
:class:`~stochcable.dynamics.model.system.LineSystem`), and the scene as groups
(:func:`~stochcable.dynamics.groups.model.build_coupled`): free bodies with the lines
attached to them, and every other line as a group of its own without bodies, with the
vessels' RAOs and the sea-independent coupled modes.  :meth:`Engine.solve` does the
rest for one sea state (:func:`~stochcable.dynamics.groups.analysis.solve_coupled`):
the input channels (Morison loads, end motions), the one drag fixed point of every
group (:func:`~stochcable.dynamics.groups.group_fixed_point.linearize_coupled`) with its
substructured response, the outputs and the time series::

    engine = build_engine(scene)            # statics, FE models, modes, groups
    for sea in sea_states:                  # Sea documents (or None: the scene's own)
        result = engine.solve(sea)

A sea state is a :class:`~stochcable.scene.model.Sea` document (spectrum and heading);
the current, the end motions and the settings are the scene's.  ``solve`` mutates no
state that changes its answer: solving the same sea twice gives identical results, and
``engine.solve(sea)`` gives the result of ``analyze`` on the scene with that sea.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from pydantic import ValidationError

from stochcable import runtime
from stochcable.dynamics.groups.analysis import solve_coupled
from stochcable.dynamics.groups.model import CoupledModel, build_coupled
from stochcable.dynamics.model.blocks import line_prep
from stochcable.dynamics.model.strumming import with_strumming
from stochcable.dynamics.model.system import (
    LineSystem,
    Progress,
    build_line_system,
    noop_progress,
)
from stochcable.dynamics.timeseries.synthesis import simulate_timeseries
from stochcable.errors import InputError, collect_warnings
from stochcable.line.strumming.screen import StrummingTable
from stochcable.line.transport.matrices import check_travelling_lines
from stochcable.results.documents import Result
from stochcable.scene.model import Scene, Sea, input_error_from_validation, load_scene
from stochcable.statics import StaticsResult, solve_statics

__all__ = ["Engine", "build_engine"]

#: Stage times of a result, zero until the stage runs. [s]
_STAGES = ("statics_s", "model_s", "linearization_s", "solve_s", "outputs_s", "timeseries_s")


def is_small(scene: Scene) -> bool:
    """Whether every line of ``scene`` is small enough for one BLAS thread
    (:data:`stochcable.runtime.SMALL_MODEL_DOF`, 3 DOFs per node)."""
    return max(3 * (line.elements + 1) for line in scene.lines) <= runtime.SMALL_MODEL_DOF


@dataclass(frozen=True, eq=False)
class Engine:
    """The sea-independent model of a scene (:func:`build_engine`).

    Attributes
    ----------
    scene : Scene
        The scene it was built for (its sea is the default of :meth:`solve`).
    statics : StaticsResult
        Static equilibrium of every line (and body).
    systems : mapping of LineSystem by line name
        Every line's linear model (both end nodes prescribed), in scene order.
    model : CoupledModel
        The scene as groups (:func:`stochcable.dynamics.groups.model.build_coupled`):
        each line attached to no free body is a group of its own without bodies;
        free bodies with their lines; vessels' RAOs; sea-independent coupled modes.
    timing : mapping of float
        ``statics_s``, ``model_s`` and ``build_s`` (the whole build) of the build. [s]
    warnings : tuple of str
        Messages of the warnings raised by the build (repeated in every result).
    strumming : mapping of StrummingTable or None by line name
        The strumming screening of every line (:mod:`stochcable.dynamics.model.strumming`).
    check : callable, optional
        ``check(result) -> result``, applied to every result of :meth:`solve` (the
        element check of :func:`stochcable.fidelity.mesh_engine.checked_engine`, which
        this layer does not import; None: none).
    """

    scene: Scene
    statics: StaticsResult
    systems: Mapping[str, LineSystem]
    model: CoupledModel
    timing: Mapping[str, float]
    warnings: tuple[str, ...]
    strumming: Mapping[str, StrummingTable | None] = field(default_factory=dict)
    check: Callable[[Result], Result] | None = None

    def solve(
        self, sea: Sea | Mapping[str, Any] | None = None, *, progress: Progress | None = None
    ) -> Result:
        """Stochastic response of the scene to one sea state.

        Parameters
        ----------
        sea : Sea, mapping or None, optional
            The sea state (a ``Sea`` document: spectrum and heading); None takes the
            scene's own sea.
        progress : callable, optional
            ``progress(stage, info)`` (:data:`~stochcable.dynamics.model.system.Progress`):
            "linearization", "outputs", "timeseries", "done".

        Returns
        -------
        Result
            As :func:`stochcable.analysis.analyze` of the scene with this sea;
            ``timing`` holds the build's ``statics_s`` and ``model_s`` (the channel
            assembly of this sea added to ``model_s``) and ``total_s`` = build + solve.

        Raises
        ------
        InputError
            An invalid sea document.
        ConvergenceError, SolverError
            As :func:`stochcable.analysis.analyze`.
        """
        t_start = time.perf_counter()
        scene = _with_sea(self.scene, sea)
        if self.scene.is_planar and not scene.is_planar:
            # the models were built 2-D (in the plane of the lines): out-of-plane waves
            # would be projected onto it without a word
            raise InputError(
                "sea.heading",
                scene.sea.heading,
                "deg",
                "sends the waves out of the plane of a scene whose engine was built with "
                "in-plane (2-D) models; build the engine from the scene with a sea of an "
                "out-of-plane heading (3-D models) to solve every heading",
            )
        progress = noop_progress if progress is None else progress
        timing = {k: 0.0 for k in _STAGES}
        timing.update(self.timing)
        with collect_warnings() as caught, runtime.analysis_blas(is_small(scene)):
            solved = solve_coupled(self.model, scene, scene.analysis, progress, timing)
            ts = None
            if scene.analysis.timeseries is not None:
                progress("timeseries", {})
                t0 = time.perf_counter()
                ts = simulate_timeseries(
                    scene,
                    scene.analysis.timeseries,
                    solved.alone + solved.groups,
                    timing=timing,
                    lines=solved.lines,
                    bodies=solved.bodies,
                )
                timing["timeseries_s"] = time.perf_counter() - t0
        messages = _messages(self.warnings, caught)
        timing["total_s"] = timing.pop("build_s") + time.perf_counter() - t_start
        progress("done", {"total_s": timing["total_s"]})
        result = Result(
            scene=scene,
            statics=self.statics,
            lines={k: v.with_strumming(self.strumming.get(k)) for k, v in solved.lines.items()},
            timeseries=ts,
            timing=timing,
            warnings=tuple(messages),
            bodies=solved.bodies,
        )
        return result if self.check is None else self.check(result)


def build_engine(
    scene: Scene | Mapping[str, Any] | str,
    *,
    statics: StaticsResult | None = None,
    progress: Progress | None = None,
) -> Engine:
    """The sea-independent model of a scene: statics, FE models, modes.

    Parameters
    ----------
    scene : Scene, mapping, JSON string or path
        The scene document (validated by :func:`stochcable.scene.model.load_scene`).
    statics : StaticsResult, optional
        A precomputed static equilibrium (default: the FE equilibrium of
        :func:`stochcable.statics.solve_statics`).
    progress : callable, optional
        ``progress(stage, info)``: "statics", then "model" per independent line.

    Returns
    -------
    Engine

    Raises
    ------
    InputError
        Invalid scene, or the harmonic drag form with a current.
    ConvergenceError
        The statics did not converge.
    """
    t_start = time.perf_counter()
    scene = load_scene(scene)
    progress = noop_progress if progress is None else progress
    settings = scene.analysis
    current = any(p.speed > 0 for p in scene.environment.current)
    if settings.linearization.method == "harmonic" and current:
        raise InputError(
            "analysis.linearization.method",
            "harmonic",
            "-",
            "the harmonic (regular-wave) form has no current term: use "
            "'seed' or 'vector' with a current",
        )
    timing = {"statics_s": 0.0, "model_s": 0.0}
    systems: dict[str, LineSystem] = {}
    strumming: dict[str, StrummingTable | None] = {}
    with collect_warnings() as caught, runtime.analysis_blas(is_small(scene)):
        progress("statics", {})
        t0 = time.perf_counter()
        if statics is None:
            # the FE equilibrium, not the closed-form catenary: the dynamic model is
            # linearized about it, so it must be an equilibrium of the same FE model
            statics = solve_statics(scene, method="fe")
        timing["statics_s"] = time.perf_counter() - t0
        check_travelling_lines(scene, statics)  # below c_crit, not on a body
        for line in scene.lines:
            progress("model", {"line": line.name})
            t0 = time.perf_counter()
            system = build_line_system(scene, line, statics.lines[line.name], settings=settings)
            system, strumming[line.name] = with_strumming(scene, system)  # docs/strumming.md
            line_prep(system)  # node blocks and band storage of K, M_T, C_s
            systems[line.name] = system
            timing["model_s"] += time.perf_counter() - t0
        # bodies, vessels' RAOs, groups and their coupled modes (sea-independent)
        model = build_coupled(scene, statics, settings, systems=systems, timing=timing)
    timing["build_s"] = time.perf_counter() - t_start  # (in each result's total_s)
    return Engine(
        scene=scene,
        statics=statics,
        systems=systems,
        model=model,
        timing=timing,
        warnings=tuple(_messages((), caught)),
        strumming=strumming,
    )


def _with_sea(scene: Scene, sea: Sea | Mapping[str, Any] | None) -> Scene:
    """``scene`` with its sea replaced by ``sea`` (validated); None: unchanged."""
    if sea is None:
        return scene
    if not isinstance(sea, Sea):
        try:
            sea = Sea.model_validate(sea)
        except ValidationError as exc:
            raise input_error_from_validation(exc, Sea, prefix="sea") from None
    return scene.model_copy(update={"sea": sea})


def _messages(first: tuple[str, ...], caught: list[Warning]) -> list[str]:
    """The distinct warning messages, ``first`` (the build's) leading."""
    messages = list(first)
    for w in caught:
        if str(w) not in messages:
            messages.append(str(w))
    return messages
