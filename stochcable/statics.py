"""The statics stage of the pipeline: static equilibrium of a scene (Tuah (1982), §4.1).

Above :mod:`stochcable.line` (one line's statics) and :mod:`stochcable.bodies` (the
body poses): a scene without bodies is its lines, each solved alone
(:func:`stochcable.line.statics.solve_line_statics`); a scene with bodies is solved by
Newton on the free body poses with the lines attached
(:func:`stochcable.bodies.statics.solve_body_statics`).  Then, about the static shape,
the finite-element model and the natural modes of every line
(:func:`scene_fe_models`, :func:`natural_modes`).

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

from stochcable.line.fem import FEModel, build_fe_model, check_dim
from stochcable.line.mesh import mesh_line
from stochcable.line.modes import Modes
from stochcable.line.modes import natural_modes as line_modes
from stochcable.line.statics import (
    LineStatics,
    Method,
    check_statics_options,
    solve_line_statics_unchecked,
)
from stochcable.scene.model import Scene, load_scene
from stochcable.validation import positive_int

if TYPE_CHECKING:  # pragma: no cover
    from stochcable.bodies.statics import BodyStatics

__all__ = [
    "StaticsResult",
    "solve_statics",
    "scene_fe_models",
    "natural_modes",
    "modes_of_scene",
]


@dataclass(frozen=True)
class StaticsResult:
    """Static equilibrium of every line of a scene, by line name, and of its bodies
    (:class:`stochcable.bodies.statics.BodyStatics`, by body name; empty without bodies)."""

    lines: dict[str, LineStatics] = field(default_factory=dict)
    bodies: dict[str, BodyStatics] = field(default_factory=dict)

    def to_document(self) -> dict[str, Any]:
        """The ``statics`` part of the result document (DESIGN.md v1); ``"bodies"``
        only when the scene has bodies."""
        doc: dict[str, Any] = {"lines": {name: ls.to_document() for name, ls in self.lines.items()}}
        if self.bodies:
            doc["bodies"] = {name: b.to_document() for name, b in self.bodies.items()}
        return doc


def solve_statics(
    scene: Scene | Mapping[str, Any] | str | Path,
    method: Method = "auto",
    *,
    tolerance: float = 1e-10,
    max_iterations: int = 500,
) -> StaticsResult:
    """Static equilibrium of every line of a scene.

    Parameters
    ----------
    scene : Scene, mapping, JSON string or path
        The scene document (validated by :func:`stochcable.scene.model.load_scene`).
    method : {"auto", "fe", "catenary"}, optional
        Solution method, see :func:`stochcable.line.statics.solve_line_statics`.
    tolerance : float, optional
        Relative residual force at convergence (FE). [-]
    max_iterations : int, optional
        Iteration budget per line (FE). [-]

    Returns
    -------
    StaticsResult
        One :class:`~stochcable.line.statics.LineStatics` per line, by name; with
        bodies, one :class:`~stochcable.bodies.statics.BodyStatics` per body and the
        lines solved with their attached ends at the body poses
        (:func:`stochcable.bodies.statics.solve_body_statics`).

    Raises
    ------
    InputError
        Invalid options (:func:`stochcable.line.statics.check_statics_options`), a
        line whose static shape is undetermined, a body DOF without restoring.
    ConvergenceError
        A line or the body poses did not converge.
    """
    scene = load_scene(scene)
    method, tolerance, max_iterations = check_statics_options(method, tolerance, max_iterations)
    env = scene.environment
    if scene.bodies:
        from stochcable.bodies.statics import solve_body_statics  # the heavier import

        lines, bodies = solve_body_statics(
            scene, method, tolerance=tolerance, max_iterations=max_iterations
        )
        return StaticsResult(lines=lines, bodies=bodies)
    out = {}
    for line in scene.lines:
        mesh = mesh_line(line, env.rho, env.g)
        out[line.name] = solve_line_statics_unchecked(
            mesh, env, method, None, tolerance, max_iterations
        )
    return StaticsResult(lines=out)


def scene_fe_models(
    scene: Any,
    dim: int | None = None,
    mass_matrix: Literal["consistent", "lumped"] = "consistent",
) -> dict[str, FEModel]:
    """Solve the statics of a scene and build the model of every line.

    Parameters
    ----------
    scene : Scene, mapping, JSON string or path
        The scene document (:func:`stochcable.scene.model.load_scene`).
    dim : {2, 3}, optional
        Model dimension; when None, 2 if ``scene.is_planar`` else 3.
    mass_matrix : {"consistent", "lumped"}
        Mass distribution.

    Returns
    -------
    dict of str to FEModel
        Per line name, in scene order.
    """
    sc = load_scene(scene)
    if dim is None:
        dim = 2 if sc.is_planar else 3
    dim = check_dim(dim)
    statics = solve_statics(sc)
    return {
        line.name: build_fe_model(
            statics.lines[line.name], sc.environment, dim=dim, mass_matrix=mass_matrix
        )
        for line in sc.lines
    }


def natural_modes(
    scene: Scene | Mapping[str, Any] | str | Path | FEModel,
    count: int | None = None,
    dim: int = 3,
    added_mass: bool = True,
) -> dict[str, Modes] | Modes:
    """Natural modes of every line of a scene about its static equilibrium.

    Parameters
    ----------
    scene : Scene, mapping, JSON string, path or FEModel
        The scene document (:func:`stochcable.scene.model.load_scene`); an
        :class:`~stochcable.line.fem.FEModel` gives that one model's modes
        (:func:`stochcable.line.modes.natural_modes`, ``dim`` unused).
    count : int, optional
        Modes per line; default all.
    dim : {2, 3}
        3 (default) lists in-plane and out-of-plane modes, classified; 2 keeps the
        in-plane modes of lines in the x–z plane only.
    added_mass : bool
        Modes in water (with added mass) or in air.

    Returns
    -------
    dict of str to Modes
        Per line name, in scene order (a :class:`~stochcable.line.modes.Modes` for an
        FEModel).
    """
    if count is not None:
        count = positive_int("count", count)
    if isinstance(scene, FEModel):
        return line_modes(scene, count=count, added_mass=added_mass)
    models = scene_fe_models(scene, dim=dim)
    return {
        name: line_modes(model, count=count, added_mass=added_mass)
        for name, model in models.items()
    }


#: The former name of :func:`natural_modes` on a scene (kept for the callers of it).
modes_of_scene = natural_modes
