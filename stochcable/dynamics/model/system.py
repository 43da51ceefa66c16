"""The assembled linear system of one line (Tuah 1982, ch. 3 and §5.2): the
frequency-independent model (:class:`LineSystem`, :func:`build_line_system`), the choice
of the modes the Foss solve keeps, and the objects the later stages exchange: the
linearized drag (:class:`Damping`), the harmonic response (:class:`Response`) and the
outcome of the drag fixed point (:class:`Linearization`).

Pipeline position: statics -> **system** -> loads (:mod:`~stochcable.dynamics.solve.line_loads`)
-> drag fixed point (:mod:`~stochcable.dynamics.groups.line_fixed_point`) -> solve
(:mod:`~stochcable.dynamics.solve.line_solve`) -> outputs
(:mod:`~stochcable.dynamics.outputs.line_result`).

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.sparse as sp

from stochcable.dynamics.loads.channels import (
    current_at_elements,
    current_at_nodes,
    drag_matrix,
    element_frames,
    inertia_matrix,
)
from stochcable.dynamics.model.lift import lift_blocks
from stochcable.dynamics.model.modal_solvers import auto_mode_count
from stochcable.dynamics.model.transport import travelling_system
from stochcable.line.fem import FEModel, build_fe_model
from stochcable.line.modes import Modes, natural_modes
from stochcable.line.statics import LineStatics
from stochcable.results.documents import (
    FormedOnAccess,
    LinearizationRecord,
)
from stochcable.scene.model import AnalysisSettings, Environment, Line, Scene

Progress = Callable[[str, Mapping[str, Any]], None]
"""``progress(stage, info)``: called with the stage name ("statics", "model", "modes",
"linearization", "outputs", "timeseries", "done") and a dict of details (line name,
iteration, relative change, …)."""

# Modes kept for "auto" (Foss): every mode when the line has at most AUTO_ALL_MODES free
# DOFs, else the natural frequencies up to AUTO_MODE_FACTOR times the grid's top, with
# the rest by mode acceleration (their static response to the loads and to the kept
# modes' damping forces: dynamics.solve.line_solve.damping_coupling).  The Foss
# eigenproblem (2n states) is re-solved at every linearization iteration, so n sets the
# cost: on the DESIGN.md chain (40 elements, 78 free DOFs, ω_max = 2 rad/s) all 78
# modes cost ~20 ms per iteration, the 20 modes up to 5·ω_max ~1 ms; on the bundled
# chain their end-tension σ is within 0.02 % of the direct solve (0.2 % without the
# damping coupling), on a chain + synthetic rope line (17 of 78 modes) within 0.02 %
# (4.7 % without it: tests/test_hard_cases.py).  The direct solver is exact and costs
# about as much as 20-mode Foss.
AUTO_ALL_MODES = 40
AUTO_MODE_FACTOR = 5.0
# First batch of modes computed when looking for the auto count (doubled as needed).
_MODE_BATCH = 40


def noop_progress(stage: str, info: Mapping[str, Any]) -> None:
    """The progress callback that does nothing (the default of every stage)."""


# ------------------------------------------------------------------------ the system


@dataclass(frozen=True, eq=False)
class LineSystem:
    """Frequency-independent parts of one line's linear problem.

    Attributes
    ----------
    line : Line
        The scene line.
    statics : LineStatics
        Its static equilibrium.
    model : FEModel
        Finite-element model about the static shape (2-D when the scene is planar).
    modes : Modes
        Natural modes kept (with added mass), lowest first.
    n_modes : int
        Number of modes the Foss solve keeps (all computed ones for ``"auto"``).
    solver : str
        ``"foss"`` or ``"direct"``.
    b_inertia : scipy.sparse.csr_array
        Morison inertia matrix (:func:`stochcable.dynamics.loads.channels.inertia_matrix`),
        a property assembled on first access. [kg]
    frames : tuple of ndarray
        Element tangent and normals (e, n1, n2), each (n_el, 3).
    current_el : ndarray, shape (n_el, 3)
        Current at element midpoints. [m/s]
    current_node : ndarray, shape (n_nodes, 3)
        Current at the nodes. [m/s]
    drag_nodes : ndarray of int
        Nodes with an attachment drag area.
    environment : Environment
    structural_damping : (float, float)
        Rayleigh coefficients (alpha [1/s], beta [s]) of C_s = alpha·M_T + beta·K,
        M_T = structural + added mass, K the full tangent stiffness (seabed springs
        included); added to the drag and the seabed damping.
    gyro : ndarray, shape (n_el,), or None
        A travelling line's gyroscopic coefficient m c per element (its K holds K_c and
        ``current_el`` the relative flow U − c e; :mod:`stochcable.dynamics.model.
        transport`); None at rest. [N·s/m]
    lift : ndarray, shape (n_el, d, d), or None
        Element blocks l0·A of the linearized steady lift (``cl_steady`` in a current;
        :mod:`stochcable.dynamics.model.lift`); None without. [N·s/m]

    Notes
    -----
    Frequency-independent arrays of the solves (node blocks, band storage, banded
    Cholesky of K_ff, modal matrices) are computed on first use and cached on the
    instance (``dataclasses.replace`` gives a fresh cache).
    """

    line: Line
    statics: LineStatics
    model: FEModel
    modes: Modes
    n_modes: int
    solver: str
    frames: tuple[np.ndarray, np.ndarray, np.ndarray]
    current_el: np.ndarray
    current_node: np.ndarray
    drag_nodes: np.ndarray
    environment: Environment
    structural_damping: tuple[float, float] = (0.0, 0.0)
    gyro: np.ndarray | None = None
    lift: np.ndarray | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "_cache", {})

    @property
    def name(self) -> str:
        """The line's name."""
        return self.line.name

    @property
    def b_inertia(self) -> sp.csr_array:
        """Morison inertia matrix (:func:`stochcable.dynamics.loads.channels.inertia_matrix`),
        assembled on first access (the solves use element blocks; only hand-built
        channels with nodal accelerations need it). [kg]"""
        if "b_inertia" not in self._cache:
            self._cache["b_inertia"] = inertia_matrix(self.model, self.environment.g)
        return self._cache["b_inertia"]

    @property
    def positions(self) -> np.ndarray:
        """Static node positions, (n_nodes, 3). [m]"""
        return self.model.positions


@dataclass(frozen=True, eq=False)
class Damping:
    """Linearized drag of one line.

    Attributes
    ----------
    method : str
        ``"seed"``, ``"vector"`` or ``"harmonic"``.
    sigma : ndarray
        The σ vector the drag was built from (the fixed-point variable). [m/s]
    b_normal : ndarray, shape (n_el,) or (n_el, 2, 2)
        Normal drag per unit length (matrix in the (n1, n2) basis for "vector"). [N·s/m²]
    b_axial : ndarray, shape (n_el,)
        Axial drag per unit length. [N·s/m²]
    b_node : ndarray, shape (n_nodes,)
        Attachment drag. [N·s/m]
    model : FEModel
        The line model the drag belongs to (for :attr:`matrix`).

    Notes
    -----
    The solves use node blocks of the drag, never a sparse matrix;
    :attr:`matrix` is assembled on first access only (it used to be built at
    every linearization iteration).
    """

    method: str
    sigma: np.ndarray
    b_normal: np.ndarray
    b_axial: np.ndarray
    b_node: np.ndarray
    model: FEModel | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "_cache", {})

    @property
    def matrix(self) -> sp.csr_array:
        """Drag damping matrix C_d on all DOFs (without the seabed damping), assembled
        on first access (:func:`stochcable.dynamics.loads.channels.drag_matrix`). [N·s/m]"""
        if "matrix" not in self._cache:
            self._cache["matrix"] = drag_matrix(
                self.model, self.b_normal, self.b_axial, self.b_node
            )
        return self._cache["matrix"]


@dataclass(frozen=True, eq=False)
class Response:
    """Harmonic response of one line per unit input of each channel.

    Attributes
    ----------
    omega : ndarray, shape (n_omega,)
        [rad/s]
    displacement : ndarray, complex, shape (n_omega, n_dof, n_ch)
        Total displacement on all model DOFs (prescribed ends included); may be given
        as a zero-argument callable, then formed on first access. [m/unit]
    support_force : ndarray, complex, shape (n_omega, n_fixed, n_ch)
        Dynamic force of the line on the supports at the fixed DOFs. [N/unit]
    end_tension : dict {"end_a", "end_b"} of ndarray (n_ch, n_omega)
        δ|F| at each support. [N/unit]
    nodes : callable or None
        ``nodes(freq)``: the total displacement in the node layout (n_nodes, d, n_f,
        n_ch) on a slice of the frequencies, what the outputs read block by block
        without forming ``displacement`` (None: read ``displacement``). [m/unit]
    """

    omega: np.ndarray
    displacement: np.ndarray = FormedOnAccess()  # type: ignore[assignment]
    support_force: np.ndarray
    end_tension: dict[str, np.ndarray]
    nodes: Callable[[slice], np.ndarray] | None = None


@dataclass(frozen=True, eq=False)
class Linearization:
    """Outcome of the drag fixed point of one line
    (:func:`stochcable.dynamics.groups.line_fixed_point.linearize`, or its share of a group's,
    :func:`stochcable.dynamics.groups.group_fixed_point.linearize_coupled`).

    Attributes
    ----------
    damping : Damping
        The drag of the last response evaluation.
    record : LinearizationRecord
        The iteration record: every response evaluation in order (coarse and
        full-grid), the final σ and B.
    response : Response
        The response solved with ``damping`` (no extra solve).
    """

    damping: Damping
    record: LinearizationRecord
    response: Response


def _choose_modes(model: FEModel, settings: AnalysisSettings) -> tuple[Modes, int]:
    """Natural modes for the modal solve and the listing, and the count kept."""
    n_free = int(model.free.size)
    w_top = float(settings.omega.values()[-1])
    if settings.modes != "auto":
        count = min(int(settings.modes), n_free)
        modes = natural_modes(model, count)
        return modes, count
    if n_free <= AUTO_ALL_MODES:
        return natural_modes(model, n_free), n_free
    count = min(_MODE_BATCH, n_free)
    while True:
        modes = natural_modes(model, count)
        keep = auto_mode_count(modes.omega, w_top, AUTO_MODE_FACTOR)
        if keep < modes.omega.size or count >= n_free:
            return modes, keep
        count = min(2 * count, n_free)


def build_line_system(
    scene: Scene,
    line: Line,
    line_statics: LineStatics,
    *,
    dim: int | None = None,
    settings: AnalysisSettings | None = None,
) -> LineSystem:
    """Assemble the linear model of one line about its static equilibrium.

    Parameters
    ----------
    scene : Scene
        The scene (environment, planarity).
    line : Line
        The line.
    line_statics : LineStatics
        Its static equilibrium (:func:`stochcable.statics.solve_statics`).
    dim : {2, 3}, optional
        Model dimension; default 2 when ``scene.is_planar`` else 3.
    settings : AnalysisSettings, optional
        Solver and modes (default: ``scene.analysis``).

    Returns
    -------
    LineSystem
    """
    settings = scene.analysis if settings is None else settings
    env = scene.environment
    if dim is None:
        dim = 2 if scene.is_planar else 3
    model = build_fe_model(line_statics, env, dim=dim)
    modes, n_modes = _choose_modes(model, settings)
    frames = element_frames(model.positions)
    mesh = model.mesh
    current_el, gyro, solver = current_at_elements(env, model.positions), None, settings.solver
    if line.axial_speed != 0.0:  # transport terms, the direct solve (docs/travelling.md)
        model, current_el, gyro = travelling_system(model, line.axial_speed, frames[0], current_el)
        solver = "direct"
    lift = lift_blocks(model, frames[0], current_el, mesh.cl_steady)
    if lift is not None:  # not symmetric: the direct solve (dynamics.model.lift)
        solver = "direct"
    return LineSystem(
        line=line,
        statics=line_statics,
        model=model,
        modes=modes,
        n_modes=n_modes,
        solver=solver,
        frames=frames,
        current_el=current_el,
        current_node=current_at_nodes(env, model.positions),
        drag_nodes=np.flatnonzero(mesh.node_drag_area > 0),
        environment=env,
        structural_damping=(
            float(settings.structural_damping.alpha),
            float(settings.structural_damping.beta),
        ),
        gyro=gyro,
        lift=lift,
    )
