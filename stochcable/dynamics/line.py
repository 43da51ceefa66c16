"""The analysis pipeline: scene -> statics -> FE model -> excitation -> drag
linearization -> solve -> results (seed 001 ch. 5, Tuah 1982).

:func:`analyze` runs the whole pipeline; each stage is a public function so that an
engineer can inspect or replace it::

    statics = solve_statics(scene)                        # stochcable.line.statics
    system  = build_line_system(scene, line, statics.lines[line.name])
    chans   = line_channels(scene, line, system.positions, omega)   # excitation
    lin     = linearize(system, chans, scene.analysis)    # drag fixed point
    resp    = solve(system, chans, lin.damping)           # any grid, any drag
    out     = line_result(system, chans, lin, scene.analysis)       # spectra, stats

Lines are independent (no coupling bodies yet), so each line is linearized and solved
on its own; the sea channel of all lines shares one realization in the time series.

Choices (see the functions for details)
---------------------------------------
- Model: 2-D (x–z) when ``scene.is_planar``, else 3-D; both ends prescribed.
- Drag damping and added mass distributed like the model mass (consistent by default),
  element direction constant per element (:mod:`stochcable.dynamics.loads`).
- Wave loads (Morison inertia and linearized drag) integrated exactly along each
  element's wet part (:func:`stochcable.dynamics.loads.element_wave_kinematics`), B
  constant per element.
- The σ of the relative velocity of an element is its element mean square:
  σ² = Σ_i ∫ S_i ∫₀¹ |row·(v(ξ) − U̇(ξ))|² dξ dω, exact for the wave field and the
  structural velocity linear along the element (:func:`relative_velocity_sigmas`).
- ``modes="auto"`` (Foss): all modes up to ``AUTO_ALL_MODES`` free DOFs, else those up
  to ``AUTO_MODE_FACTOR``·ω_max; moving ends use the quasi-static split (:func:`solve`).
- Time series: the first 2048 samples go in the document (``to_document(timeseries=
  "full")`` for all); the full series are on :class:`~stochcable.results.documents.TimeSeries`.
- Drag linearization: a coarse start on a frequency subset, then the full grid
  (:func:`linearize`, "Coarse start" below).

Coarse start
------------
On a grid of at least ``COARSE_MIN_FREQUENCIES`` points the drag fixed point is first
iterated on a frequency subset: every ``COARSE_STEP``-th frequency and the last, plus
the full-resolution neighbourhood (± ``COARSE_STEP`` points) of each channel's spectral
peak and of every natural frequency inside the grid whose half-power bandwidth (at the
starting drag) is narrower than two coarse spacings, so a narrow resonance between
coarse points is not missed.  The σ integrals on the subset use the *full grid's*
trapezoid rule applied to the local cubic (4-point Lagrange) interpolant of the
integrand S_i|H|² through the subset (:func:`_interpolatory_weights`): on the DESIGN.md
chain the subset σ are within 1e-5 of the full-grid ones at the same drag, against
5e-4 for the trapezoid rule on the subset.  The coarse iteration stops at
``COARSE_TOLERANCE_RATIO`` times the tolerance; its fixed point is only the start of
the full-grid iteration, which runs (first step unmixed) until the usual test passes
on the full grid: the answer is the full-grid fixed point, and the record's iterations
and history count full-grid evaluations only (the coarse stage is
:attr:`Linearization.coarse`).  The subset solves the same modal equations per
frequency instead of by the Foss eigenproblem (:func:`_foss_free`).  On the chain: 6
coarse evaluations on 51 frequencies and one full-grid evaluation (change 1.1e-5)
instead of 6 full-grid evaluations; end-tension σ equal to 1.5e-7.  Skipped for grids
below ``COARSE_MIN_FREQUENCIES``, subsets above ``COARSE_MAX_FRACTION`` of the grid
(many narrow resonances), ``max_iterations = 1`` and the vector form with a current
(its drag, not the frequencies, dominates).  A line that converges in two full-grid
steps anyway gains nothing and pays the coarse evaluations (the taut wire example:
≈ +3 ms).

Dynamic effective tension
-------------------------
Per element δT = (EA/l0)·e·(u_b − u_a), the first-order change of T = EA(l/l0 − 1)
(seed 001 eqs. 3.1.8–3.1.11: the K_NL part of the tangent stiffness).  The "geometric"
term (T/l)(I − eeᵀ)Δu of the tangent stiffness rotates the element force; it changes
its direction, not its magnitude, and contributes to the tension only at second order,
so it is not part of δT.  Slack elements (T <= 0) use the model's reduced EA.

End tensions are the change of the magnitude of the force on each support,
δ|F| = (F0/|F0|)·δF, with δF the reaction from the finite-element rows of the end
DOFs, δF = −[(K − ω²M_T + iωC)U − F_fluid]_end: it includes the inertia, drag and
seabed forces of the end node's share of the adjacent element, and tends to the end
element's δT when those are small (tested).
"""

from __future__ import annotations

import functools
import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from stochcable import runtime
from stochcable.errors import (
    ConvergenceError,
    InputError,
    PhysicsWarning,
    ResolutionWarning,
    SolverError,
    collect_warnings,
    warn,
)
from stochcable.dynamics.loads import (
    Channel,
    current_at_elements,
    current_at_nodes,
    drag_matrix,
    element_frames,
    element_mean_square,
    element_moments,
    inertia_matrix,
    line_channels,
)
from stochcable.line.fem import FEModel, build_fe_model
from stochcable.dynamics.linearization import (
    FixedPointResult,
    _mean_abs_gaussian,
    drag_linear_current,
    drag_linear_harmonic,
    borgman_variance_ratio,
    drag_linear_vector,
    fixed_point,
)
from stochcable.line.modes import Modes, natural_modes
from stochcable.results.documents import (
    LineIndicators,
    LinearizationRecord,
    LineResult,
    Result,
    TimeSeries,
    _stats_from_validated,
)
from stochcable.scene.model import AnalysisSettings, Line, Scene, TimeSeriesSettings, load_scene
from stochcable.sea.realization import frequency_grid, simulate_sea, synthesize
from stochcable.dynamics.solvers import (
    DefectivePencilWarning,
    _band_from_blocks,
    _foss_decomposition,
    _foss_transfer_modal,
    _solve_band_stacked,
    auto_mode_count,
    solve_direct,
    tridiagonal_blocks,
)
from stochcable.line.statics import LineStatics, StaticsResult, solve_statics
from stochcable.scene.units import unit_labels

__all__ = [
    "Progress",
    "LineSystem",
    "Damping",
    "Linearization",
    "CoarseStage",
    "Response",
    "build_line_system",
    "drag_coefficients",
    "solve",
    "relative_velocity_sigmas",
    "linearize",
    "line_indicators",
    "line_result",
    "element_tension_transfer",
    "simulate_timeseries",
    "analyze",
]

Progress = Callable[[str, Mapping[str, Any]], None]
"""``progress(stage, info)``: called with the stage name ("statics", "model", "modes",
"linearization", "outputs", "timeseries", "done") and a dict of details (line name,
iteration, relative change, …)."""

# Modes kept for "auto" (Foss): every mode when the line has at most AUTO_ALL_MODES free
# DOFs, else the natural frequencies up to AUTO_MODE_FACTOR times the grid's top, with
# the static correction of the rest.  The Foss eigenproblem (2n states) is re-solved at
# every linearization iteration, so n sets the cost: on the DESIGN.md chain (40
# elements, 78 free DOFs, ω_max = 2 rad/s) all 78 modes cost ~20 ms per iteration, the
# 20 modes up to 5·ω_max ~1 ms, for an end-tension σ error of 0.05 % (end_a) and
# 0.24 % (end_b); 10 modes (2.4·ω_max) 0.2–0.4 %, 30 modes 0.02 %
# (benchmarks/bench_analysis.py, docs/BENCHMARKS.md "Response analysis").  The direct
# solver is exact and costs about as much as 20-mode Foss.
AUTO_ALL_MODES = 40
AUTO_MODE_FACTOR = 5.0
# Mixing of the Anderson-accelerated steps of the drag fixed point (the plain steps use
# analysis.linearization.relaxation): undamped Anderson saves one iteration on the
# chain, the taut wire, the guy and a 3-D chain (docs/BENCHMARKS.md "Response analysis").
ANDERSON_MIXING = 1.0
# First batch of modes computed when looking for the auto count (doubled as needed).
_MODE_BATCH = 40

#: Coarse start of the drag linearization (module docstring "Coarse start"): grids with
#: at least COARSE_MIN_FREQUENCIES points are first iterated on every COARSE_STEP-th
#: frequency (plus the neighbourhoods of spectral peaks and narrow resonances) to
#: COARSE_TOLERANCE_RATIO times the tolerance; a subset larger than
#: COARSE_MAX_FRACTION of the grid is not worth it (full grid only).
COARSE_STEP = 4
COARSE_MIN_FREQUENCIES = 80
COARSE_TOLERANCE_RATIO = 0.25
COARSE_MAX_FRACTION = 0.35


def _noop(stage: str, info: Mapping[str, Any]) -> None:
    return None


def _is_small(scene: Scene) -> bool:
    return max(3 * (line.elements + 1) for line in scene.lines) <= runtime.SMALL_MODEL_DOF


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
        Morison inertia matrix (:func:`stochcable.dynamics.loads.inertia_matrix`),
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
    environment: Any
    structural_damping: tuple[float, float] = (0.0, 0.0)

    def __post_init__(self) -> None:
        object.__setattr__(self, "_cache", {})

    @property
    def name(self) -> str:
        return self.line.name

    @property
    def b_inertia(self) -> sp.csr_array:
        """Morison inertia matrix (:func:`stochcable.dynamics.loads.inertia_matrix`),
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
    model: Any = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "_cache", {})

    @property
    def matrix(self) -> sp.csr_array:
        """Drag damping matrix C_d on all DOFs (without the seabed damping), assembled
        on first access (:func:`stochcable.dynamics.loads.drag_matrix`). [N·s/m]"""
        if "matrix" not in self._cache:
            self._cache["matrix"] = drag_matrix(self.model, self.b_normal, self.b_axial,
                                                self.b_node)
        return self._cache["matrix"]


@dataclass(frozen=True, eq=False)
class Response:
    """Harmonic response of one line per unit input of each channel.

    Attributes
    ----------
    omega : ndarray, shape (n_omega,)
        [rad/s]
    displacement : ndarray, complex, shape (n_omega, n_dof, n_ch)
        Total displacement on all model DOFs (prescribed ends included). [m/unit]
    support_force : ndarray, complex, shape (n_omega, n_fixed, n_ch)
        Dynamic force of the line on the supports at the fixed DOFs. [N/unit]
    end_tension : dict {"end_a", "end_b"} of ndarray (n_ch, n_omega)
        δ|F| at each support. [N/unit]
    """

    omega: np.ndarray
    displacement: np.ndarray
    support_force: np.ndarray
    end_tension: dict[str, np.ndarray]


@dataclass(frozen=True)
class CoarseStage:
    """The coarse start of a drag linearization (module docstring "Coarse start").

    Attributes
    ----------
    frequencies : int
        Size of the frequency subset. [-]
    iterations : int
        Response evaluations on the subset. [-]
    history : tuple of float
        Relative change of the σ after each of them (on the subset). [-]
    converged : bool
        Whether the subset iteration reached its tolerance (``COARSE_TOLERANCE_RATIO``
        times the linearization tolerance); either way its last σ only start the
        full-grid iteration.
    """

    frequencies: int
    iterations: int
    history: tuple[float, ...]
    converged: bool


@dataclass(frozen=True, eq=False)
class Linearization:
    """Outcome of :func:`linearize`: the drag, its record and the last response.

    ``record`` counts the full-grid evaluations only; ``coarse`` is the coarse start
    (None when the full grid was iterated from the start)."""

    damping: Damping
    record: LinearizationRecord
    response: Response
    coarse: CoarseStage | None = None


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
        Its static equilibrium (:func:`stochcable.line.statics.solve_statics`).
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
    return LineSystem(
        line=line,
        statics=line_statics,
        model=model,
        modes=modes,
        n_modes=n_modes,
        solver=settings.solver,
        frames=frames,
        current_el=current_at_elements(env, model.positions),
        current_node=current_at_nodes(env, model.positions),
        drag_nodes=np.flatnonzero(mesh.node_drag_area > 0),
        environment=env,
        structural_damping=(float(settings.structural_damping.alpha),
                            float(settings.structural_damping.beta)),
    )


# ------------------------------------------------------------------------- damping


def _split_sigma(system: LineSystem, x: np.ndarray, method: str) -> dict[str, np.ndarray]:
    n = system.model.n_elements
    k = 3 if method == "vector" else 1
    parts = {"normal": x[: k * n].reshape(k, n), "axial": x[k * n:(k + 1) * n],
             "node": x[(k + 1) * n:]}
    return parts


def _drag_current(rho: float, cd: Any, diameter: Any, sigma: np.ndarray,
                  mean: np.ndarray) -> np.ndarray:
    """:func:`stochcable.dynamics.linearization.drag_linear_current` without validation (finite
    σ >= 0): the same operations in the same order."""
    return rho * np.asarray(cd, dtype=float) * diameter * _mean_abs_gaussian(sigma, mean)


def drag_coefficients(system: LineSystem, sigma: np.ndarray, method: str) -> Damping:
    """Linear drag of a line from the σ of its relative velocities.

    Parameters
    ----------
    system : LineSystem
        The line.
    sigma : ndarray
        ``[σ_n (n_el), σ_t (n_el), σ_att (n_drag_nodes)]`` for "seed"/"harmonic";
        ``[s1, s2, s3 (3·n_el), σ_t, σ_att]`` for "vector", s1, s2 the σ along n1, n2
        and s3 along (n1 + n2)/√2 (which fixes the covariance). [m/s]
    method : {"seed", "vector", "harmonic"}
        Linearization form (DESIGN.md "Drag linearization").

    Returns
    -------
    Damping

    Notes
    -----
    seed: B_n = ρ Cdn D E|v_n| with v_n ~ N(|U_n|, σ_n²) (:func:`drag_linear_current`;
    = √(8/π)·½ρCdnD·σ_n without current, seed 001 eq. 5.2.2.a); axial the same with
    Cdt and πD (eq. 5.2.2.b) and the mean U·e.  vector: the exact 2×2 normal-plane
    form (:func:`drag_linear_vector`).  harmonic: (8/3π)·½ρCdD·|v̂| with |v̂| = √2 σ
    (the amplitude of a single harmonic of standard deviation σ).  Attachments:
    isotropic, ρ·CdA·E|v| with σ² the total variance of their relative velocity.
    """
    model = system.model
    mesh = model.mesh
    rho = model.rho
    e, n1, n2 = system.frames
    parts = _split_sigma(system, np.asarray(sigma, dtype=float), method)
    if "current_split" not in system._cache:  # drag-independent: once per line
        uc = system.current_el
        u_t = np.einsum("ij,ij->i", uc, e)
        u_nvec = uc - u_t[:, None] * e
        system._cache["current_split"] = (u_t, u_nvec, np.linalg.norm(u_nvec, axis=1))
    u_t, u_nvec, u_n = system._cache["current_split"]
    d = mesh.diameter
    if method == "vector":
        s1, s2, s3 = parts["normal"]
        c12 = s3**2 - 0.5 * (s1**2 + s2**2)
        c12 = np.clip(c12, -s1 * s2, s1 * s2)
        cov = np.empty((s1.size, 2, 2))
        cov[:, 0, 0], cov[:, 1, 1] = s1**2, s2**2
        cov[:, 0, 1] = cov[:, 1, 0] = c12
        mean = None
        if np.any(u_n > 0):
            mean = np.column_stack([np.einsum("ij,ij->i", u_nvec, n1),
                                    np.einsum("ij,ij->i", u_nvec, n2)])
        b_n = drag_linear_vector(rho, mesh.cd_normal, d, cov, mean)
        b_t = drag_linear_current(rho, mesh.cd_axial, math.pi * d, parts["axial"], u_t)
    elif method == "harmonic":
        b_n = drag_linear_harmonic(rho, mesh.cd_normal, d, math.sqrt(2.0) * parts["normal"][0])
        b_t = drag_linear_harmonic(rho, mesh.cd_axial, math.pi * d,
                                   math.sqrt(2.0) * parts["axial"])
    else:
        # the iteration's σ are finite and >= 0: skip the public validation (a third
        # of this function's time, called at every iteration); anything else goes
        # through drag_linear_current and its error messages
        sn, st = parts["normal"][0], parts["axial"]
        # finite and >= 0 (NaN fails the comparison; +inf is caught by the sum): the
        # normal and axial σ are the leading part of the σ vector, checked at once
        lead = np.asarray(sigma, dtype=float)[: sn.size + st.size]
        clean = bool((lead >= 0).all() and math.isfinite(float(lead.sum())))
        current = _drag_current if clean else drag_linear_current
        b_n = current(rho, mesh.cd_normal, d, parts["normal"][0], u_n)
        b_t = current(rho, mesh.cd_axial, math.pi * d, parts["axial"], u_t)
    b_node = np.zeros(model.n_nodes)
    if system.drag_nodes.size:
        idx = system.drag_nodes
        u_node = np.linalg.norm(system.current_node[idx], axis=1)
        sig = parts["node"]
        if method == "harmonic":
            b_node[idx] = drag_linear_harmonic(rho, mesh.node_drag_area[idx], 1.0,
                                               math.sqrt(2.0) * sig)
        else:
            b_node[idx] = drag_linear_current(rho, mesh.node_drag_area[idx], 1.0, sig, u_node)
    b_n = np.atleast_1d(np.asarray(b_n, dtype=float))
    b_t = np.atleast_1d(np.asarray(b_t, dtype=float))
    return Damping(
        method=method, sigma=np.asarray(sigma, dtype=float).copy(), b_normal=b_n,
        b_axial=b_t, b_node=b_node, model=model,
    )


# --------------------------------------------------------------- block-banded core
#
# One line's matrices are block-tridiagonal in node-major DOFs (element j joins nodes
# j and j+1).  They are held as node blocks D (n_nodes, d, d) and O (n_el, d, d) with
# O[j] = A[node j+1, node j] (all matrices here are symmetric, A[j, j+1] = O[j]ᵀ), so
# loads, couplings to the prescribed end nodes and reactions are a few einsums, and
# the free–free solve is one stacked banded LAPACK call over all frequencies
# (:func:`stochcable.dynamics.solvers.solve_block_tridiagonal`).  No scipy.sparse in the loop.

_Blk = tuple[np.ndarray, np.ndarray]


def _blocks_of(a: Any, d: int) -> _Blk:
    """Node blocks (D, O) of a symmetric block-tridiagonal model matrix.

    A canonical CSR matrix (sorted, no duplicates: the FE assembly's) is read from its
    index arrays directly, 5x faster than :func:`stochcable.dynamics.solvers.tridiagonal_blocks`
    (scipy's COO conversion and checks were ≈ 0.8 ms of every analysis of the
    reference chain); anything else, or entries outside the pattern, goes through
    that function (same values, its error messages)."""
    stash = getattr(a, "_node_blocks", None)  # assembled from node blocks (fem)
    if (stash is not None and stash[1].shape[1:] == (d, d) and stash[0].shape == a.data.shape
            and np.array_equal(stash[0], a.data)):
        return stash[1].copy(), stash[2].copy()
    if (isinstance(a, (sp.csr_array, sp.csr_matrix)) and a.has_canonical_format
            and a.shape[0] == a.shape[1] and a.shape[0] % d == 0):
        n = a.shape[0]
        rows = np.repeat(np.arange(n), np.diff(a.indptr))
        cols = a.indices
        bi, bj = rows // d, cols // d
        off = bi - bj
        if not np.any(np.abs(off) > 1):
            nb = n // d
            dtype = np.result_type(a.data.dtype, float)
            diag = np.zeros((nb, d, d), dtype=dtype)
            lower = np.zeros((nb, d, d), dtype=dtype)
            sel = off == 0
            diag[bi[sel], rows[sel] % d, cols[sel] % d] = a.data[sel]
            sel = off == 1
            lower[bi[sel], rows[sel] % d, cols[sel] % d] = a.data[sel]
            return diag, lower[1:]
    diag, lower, _ = tridiagonal_blocks(a, d)
    return diag, lower[1:]


def _element_blocks(model: FEModel, blocks3: np.ndarray) -> np.ndarray:
    """Per-unit-length element matrices (n_el, 3, 3) times l0 on the model components,
    (n_el, d, d)."""
    comps = list(model.components)
    return np.ascontiguousarray(blocks3[:, comps][:, :, comps] * model.l0[:, None, None])


def _element_load(b: np.ndarray, mom: np.ndarray) -> np.ndarray:
    """Node loads Σ_elements b_j·[m_a, m_b] from element blocks b (n_el, d, d) (real,
    l0 included) and consistent moments mom (n_el, 2, d, ...) (complex):
    (n_nodes, d, ...)."""
    n_el, _, d = mom.shape[:3]
    mf = np.ascontiguousarray(mom).reshape(n_el, 2, d, -1).view(float)
    # side-major output (contiguous r[0], r[1]); 5x faster than stacked d×d matmuls
    r = np.einsum("eij,esjn->sein", b, mf)
    out = np.empty((n_el + 1, d, mf.shape[-1]))
    out[:-1] = r[0]
    out[-1] = 0.0
    out[1:] += r[1]
    return out.view(complex).reshape((n_el + 1, d) + mom.shape[3:])


def _blocks_of_elements(model: FEModel, blocks3: np.ndarray,
                        node_diag: np.ndarray | None) -> _Blk:
    """Node blocks of per-unit-length element matrices (n_el, 3, 3) distributed like the
    model's mass (as :func:`stochcable.dynamics.loads.drag_matrix` assembles them)."""
    return _distribute(model, _element_blocks(model, blocks3), node_diag)


def _distribute(model: FEModel, b: np.ndarray, node_diag: np.ndarray | None) -> _Blk:
    """:func:`_blocks_of_elements` of the element blocks b (n_el, d, d) (l0
    included, :func:`_element_blocks`)."""
    pat = (np.array([[0.5, 0.0], [0.0, 0.5]]) if model.mass_matrix == "lumped" else
           np.array([[1.0 / 3.0, 1.0 / 6.0], [1.0 / 6.0, 1.0 / 3.0]]))
    D = np.zeros((model.n_nodes, model.dim, model.dim))
    D[:-1] += pat[0, 0] * b
    D[1:] += pat[1, 1] * b
    if node_diag is not None and np.any(node_diag):
        D += node_diag[:, None, None] * np.eye(model.dim)[None]
    return D, pat[1, 0] * b


def _add(*blks: _Blk, scale: tuple[float, ...] | None = None) -> _Blk:
    if scale is None and len(blks) == 2:  # the per-iteration C_s + C_d: one add each
        (d0, o0), (d1, o1) = blks
        return d0 + d1, o0 + o1
    s = (1.0,) * len(blks) if scale is None else scale
    return (sum(c * b[0] for c, b in zip(s, blks)), sum(c * b[1] for c, b in zip(s, blks)))


def _free_band(blk: _Blk) -> np.ndarray:
    """LAPACK band storage (half-bandwidth 2d − 1) of the free–free block (interior
    nodes)."""
    D, O = blk
    inner = O[1:-1]
    n_f, d = D.shape[0] - 2, D.shape[1]
    lower = np.zeros((n_f, d, d))
    upper = np.zeros((n_f, d, d))
    lower[1:] = inner
    upper[:-1] = np.swapaxes(inner, 1, 2)
    return _band_from_blocks((D[1:-1], lower, upper))


def _matvec(blk: _Blk, x: np.ndarray) -> np.ndarray:
    """A x for node vectors x (n_nodes, d, ...) -> same shape.

    The node axis leads and frequencies/channels trail, so each node block is one
    (d × d) @ (d × n_w·n_ch) product: a stacked matmul of n_nodes large products."""
    D, O = blk
    cplx = np.iscomplexobj(x) and not np.iscomplexobj(D)
    xr = np.ascontiguousarray(x).reshape(x.shape[0], x.shape[1], -1)
    if cplx:  # real blocks times complex vectors as real products (no upcast of D)
        xr = xr.view(float)
    y = D @ xr
    y[1:] += O @ xr[:-1]
    y[:-1] += np.swapaxes(O, 1, 2) @ xr[1:]
    if cplx:
        y = y.view(complex)
    return y.reshape(x.shape)


# Free DOFs up to which the residual flexibility is held as a dense matrix.
_DENSE_FLEX = 600


class _Prep:
    """Frequency-independent arrays of one line for the block-banded solves."""

    def __init__(self, system: "LineSystem") -> None:
        model = system.model
        d = model.dim
        n = model.n_nodes
        fixed_ok = np.array_equal(model.fixed, np.r_[np.arange(d), (n - 1) * d + np.arange(d)])
        if not fixed_ok or n < 3:
            raise InputError("model.fixed", model.fixed, "-",
                             "the line solve needs both end nodes prescribed and at least "
                             "one free node")
        alpha, beta = system.structural_damping
        self.d, self.n = d, n
        self._system = system
        self.K = _blocks_of(model.K, d)
        bm, bma = _blocks_of(model.M, d), _blocks_of(model.Ma, d)
        # M_T = M + Ma entry by entry (the blocks of the CSR sum, to the bit)
        self.MT = (bm[0] + bma[0], bm[1] + bma[1])
        seabed = _blocks_of(model.Cs, d)
        # structural damping: seabed dashpots + Rayleigh alpha·M_T + beta·K
        self.S = _add(seabed, self.MT, self.K, scale=(1.0, alpha, beta))
        self.bK = _free_band(self.K)
        self._modal: dict[int, Any] = {}
        self._chol: Any = None

    # used by the direct solve, its conditioning check and hand-built channels only:
    # computed on first use (≈ 0.2 ms of every Foss analysis of the reference chain)
    @functools.cached_property
    def BI(self) -> _Blk:
        """Node blocks of the Morison inertia matrix (nodal accelerations)."""
        return _blocks_of(self._system.b_inertia, self.d)

    @functools.cached_property
    def bM(self) -> np.ndarray:
        """Band storage of the free–free M_T."""
        return _free_band(self.MT)

    @functools.cached_property
    def bS(self) -> np.ndarray:
        """Band storage of the free–free structural damping."""
        return _free_band(self.S)

    @functools.cached_property
    def norm_K(self) -> float:
        return float(np.sqrt(np.sum(self.bK**2)))

    @functools.cached_property
    def norm_M(self) -> float:
        return float(np.sqrt(np.sum(self.bM**2)))

    # K_ff^-1 by banded Cholesky (K_ff is SPD: tensions > 0 or slack EA > 0)
    def k_solve(self, rhs: np.ndarray) -> np.ndarray:
        """K_ff⁻¹ rhs for rhs (n_free_dof, m) real or complex."""
        if self._chol is None:
            u = 2 * self.d - 1
            upper = self.bK[: u + 1]  # rows 0..u hold the upper band (ab[u + i - j, j])
            try:
                self._chol = sla.cholesky_banded(upper, lower=False, check_finite=False)
            except np.linalg.LinAlgError:
                raise SolverError("static correction: K_ff is not positive definite "
                                  "(check the static tensions)") from None
        c = (self._chol, False)
        if np.iscomplexobj(rhs):
            return (sla.cho_solve_banded(c, np.ascontiguousarray(rhs.real), check_finite=False)
                    + 1j * sla.cho_solve_banded(c, np.ascontiguousarray(rhs.imag),
                                                check_finite=False))
        return sla.cho_solve_banded(c, rhs, check_finite=False)

    def residual(self, system: "LineSystem", rhs: np.ndarray) -> np.ndarray:
        """Static correction of the truncated modes, (K_ff⁻¹ − Φ K̂⁻¹ Φᵀ) rhs, rhs of
        shape (n_free_dof, k) complex: an explicit dense residual flexibility (one
        matrix product) up to ``_DENSE_FLEX`` free DOFs, else the banded Cholesky."""
        phi, _, kh = self.modal(system)
        nf = phi.shape[0]
        if nf > _DENSE_FLEX:
            return self.k_solve(rhs) - phi @ np.linalg.solve(kh, phi.T @ rhs)
        key = ("flex", phi.shape[1])
        if key not in self._modal:
            flex = self.k_solve(np.eye(nf)) - phi @ np.linalg.solve(kh, phi.T)
            self._modal[key] = 0.5 * (flex + flex.T)
        flex = self._modal[key]
        k = rhs.shape[1]
        out = flex @ np.ascontiguousarray(rhs).view(float).reshape(nf, 2 * k)
        return out.view(complex)

    def follower(self) -> np.ndarray:
        """G with U_f = G u_b the static following of the end displacements,
        G = −K_ff⁻¹K_fb, shape (n_free_dof, 2d)."""
        if "follower" not in self._modal:
            d, n = self.d, self.n
            kfb = np.zeros(((n - 2) * d, 2 * d))
            kfb[:d, :d] = self.K[1][0]
            kfb[-d:, d:] = self.K[1][-1].T
            self._modal["follower"] = -self.k_solve(kfb)
        return self._modal["follower"]

    def end_basis(self, direct: bool) -> tuple[np.ndarray, ...]:
        """(G, M_T G, C_s G, K G) as (n_nodes·d, 2d) real matrices: the node
        displacements U_p = G u_b of unit end displacements u_b (end_a's d components,
        then end_b's) — zero inside for the direct solve, the static following
        (:meth:`follower`) inside for Foss — and their products with M_T, the
        structural damping and K (K G only for the direct solve)."""
        key = ("end_basis", bool(direct))
        if key not in self._modal:
            d, n = self.d, self.n
            g = np.zeros((n, d, 2 * d))
            g[0, :, :d] = np.eye(d)
            g[-1, :, d:] = np.eye(d)
            if not direct:
                g[1:-1] = self.follower().reshape(n - 2, d, 2 * d)
            flat = (n * d, 2 * d)
            self._modal[key] = (g.reshape(flat), _matvec(self.MT, g).reshape(flat),
                                _matvec(self.S, g).reshape(flat),
                                _matvec(self.K, g).reshape(flat) if direct else None)
        return self._modal[key]

    def modal(self, system: "LineSystem") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(Φ_f, M̂, K̂) of the kept modes on the free DOFs."""
        m = int(system.n_modes)
        if m not in self._modal:
            phi = np.ascontiguousarray(system.modes.shapes[system.model.free][:, :m])
            x = self._nodes(phi)
            mh = phi.T @ self._free_rows(_matvec(self.MT, x))
            kh = phi.T @ self._free_rows(_matvec(self.K, x))
            self._modal[m] = (phi, 0.5 * (mh + mh.T), 0.5 * (kh + kh.T))
        return self._modal[m]

    def _nodes(self, free: np.ndarray) -> np.ndarray:
        """(n_free_dof, k) -> node vectors (n_nodes, d, k) with zero ends."""
        k = free.shape[1]
        x = np.zeros((self.n, self.d, k), dtype=free.dtype)
        x[1:-1] = free.reshape(self.n - 2, self.d, k)
        return x

    def _free_rows(self, y: np.ndarray) -> np.ndarray:
        """Node vectors (n_nodes, d, ...) -> free rows (n_free_dof, ...)."""
        return y[1:-1].reshape(((self.n - 2) * self.d,) + y.shape[2:])


def _prep(system: "LineSystem") -> _Prep:
    cache = system._cache
    if "prep" not in cache:
        cache["prep"] = _Prep(system)
    return cache["prep"]


@dataclass(frozen=True, eq=False)
class _Inputs:
    """Channel data in the node layout (n_nodes, d, n_w, n_ch)."""

    omega: np.ndarray
    velocity: np.ndarray | None  # fluid velocity at the nodes (attachments)
    inertia_load: np.ndarray  # Morison inertia load, exact along the elements
    ub: np.ndarray | None  # prescribed end displacement, (2, d, n_w, n_ch)
    weights: np.ndarray  # trapezoid weight x spectrum, (n_w, n_ch)
    moments: np.ndarray | None = None  # ∫N_i v dξ, (n_el, 2, d, n_w, n_ch)
    square: np.ndarray | None = None  # Σ weight·∫Re(v vᴴ)dξ, (n_el, d, d)
    cache: dict = field(default_factory=dict)  # drag-independent loads per solver


def _inertia_elements(system: "LineSystem") -> tuple[np.ndarray, np.ndarray]:
    """Morison inertia l0·ρ(πD²/4)(1 + Can)(I − eeᵀ) per element on the model
    components (n_el, d, d) and the attachments' (buoyancy/g + added mass) (n_nodes,)."""
    if "inertia_el" not in system._cache:
        from stochcable.dynamics.loads import _inertia_blocks

        blocks, node = _inertia_blocks(system.model, system.environment.g, system.frames[0])
        system._cache["inertia_el"] = (_element_blocks(system.model, blocks), node)
    return system._cache["inertia_el"]


def _inputs(system: "LineSystem", channels: tuple[Channel, ...]) -> _Inputs:
    model = system.model
    prep = _prep(system)
    comps = list(model.components)
    w = channels[0].omega
    n_w, n_ch = w.size, len(channels)
    shape = (model.n_nodes, model.dim, n_w, n_ch)
    weights = _trapezoid_weights(w)[:, None] * np.stack([c.spectrum for c in channels], axis=1)
    vel = None
    mom = None
    square = None
    inertia = np.zeros(shape, dtype=complex)
    b_in, node_mass = _inertia_elements(system)
    # the nodal fluid velocity only drives the attachments' drag (b_node): without
    # attachment drag areas it is never used (and not built)
    attached = system.drag_nodes.size > 0
    for i, ch in enumerate(channels):
        if attached and ch.velocity is not None:  # (the sea's is computed on access)
            if vel is None:
                vel = np.zeros(shape, dtype=complex)
            vel[..., i] = np.transpose(ch.velocity[..., comps], (1, 2, 0))
        m = element_moments(model, ch)
        if m is not None:
            if mom is None:
                mom = np.zeros((model.n_elements, 2, model.dim, n_w, n_ch), dtype=complex)
            mom[..., i] = np.transpose(m[..., comps], (1, 2, 3, 0))
            # the d × d part in one gather (two chained ones were 0.1-0.4 ms)
            sq = element_mean_square(ch)[:, :, np.array(comps)[:, None], comps]
            sq = np.einsum("weij,w->eij", sq, weights[:, i])
            square = sq if square is None else square + sq
        if ch.element_velocity is not None:
            # exact along the elements: l0·C_I(I − eeᵀ)·iω∫N_i v dξ, plus attachments
            inertia[..., i] = _element_load(b_in, mom[..., i] * (1j * w))
            if np.any(node_mass) and ch.acceleration is not None:
                inertia[..., i] += (node_mass[:, None, None]
                                    * np.transpose(ch.acceleration[..., comps], (1, 2, 0)))
        elif ch.acceleration is not None:  # hand-built channel: nodal interpolation
            acc = np.transpose(ch.acceleration[..., comps], (1, 2, 0))[..., None]
            inertia[..., i] = _matvec(prep.BI, acc)[..., 0]
    ub = None
    for i, ch in enumerate(channels):
        for k, m in enumerate((ch.motion_a, ch.motion_b)):
            if m is not None and np.any(m):
                if ub is None:
                    ub = np.zeros((2, model.dim, n_w, n_ch), dtype=complex)
                ub[k, :, :, i] = m[:, comps].T
    return _Inputs(w, vel, inertia, ub, weights, mom, square)


def _drag_blocks(system: "LineSystem", damping: Damping) -> _Blk:
    cache = damping._cache
    if "blocks" not in cache:
        model = system.model
        bn = damping.b_normal
        if bn.ndim == 1:
            # B_n(I − eeᵀ) + B_t eeᵀ entry by entry on the model components only (the
            # same numbers as the 3×3 blocks sliced), eeᵀ cached per line
            if "eet" not in system._cache:
                comps = list(model.components)
                e = system.frames[0][:, comps]
                eet = e[:, :, None] * e[:, None, :]
                system._cache["eet"] = (eet, np.eye(len(comps))[None] - eet,
                                        model.l0[:, None, None])
            eet, ieet, l0 = system._cache["eet"]
            el = bn[:, None, None] * ieet
            el += damping.b_axial[:, None, None] * eet
            el *= l0
        else:
            e = system.frames[0]
            eet = e[:, :, None] * e[:, None, :]
            _, n1, n2 = system.frames
            nmat = np.stack([n1, n2], axis=2)
            b3 = nmat @ bn @ np.swapaxes(nmat, 1, 2)
            b3 = b3 + damping.b_axial[:, None, None] * eet
            el = _element_blocks(model, b3)
        cache["elements"] = el
        cache["blocks"] = _distribute(model, el, damping.b_node)
    return cache["blocks"]


def _drag_load(system: "LineSystem", inp: _Inputs, damping: Damping) -> np.ndarray | None:
    """Linearized drag load of the fluid velocity, Σ_el l0·B·∫N_i v dξ + b_node·V_node,
    node vectors (n_nodes, d, n_w, n_ch); None without fluid velocity."""
    if inp.velocity is None and inp.moments is None:
        return None
    _drag_blocks(system, damping)
    if inp.moments is not None:
        f = _element_load(damping._cache["elements"], inp.moments)
    else:
        f = np.zeros(inp.velocity.shape, dtype=complex)
    if inp.velocity is not None and np.any(damping.b_node):
        f += damping.b_node[:, None, None, None] * inp.velocity
    return f


def _loads(system: "LineSystem", inp: _Inputs, damping: Damping) -> np.ndarray:
    """Fluid loads (drag of the fluid velocity + Morison inertia) on all nodes,
    (n_nodes, d, n_w, n_ch)."""
    f = _drag_load(system, inp, damping)
    return inp.inertia_load if f is None else inp.inertia_load + f


def _end_loads(system: "LineSystem", inp: _Inputs, damping: Damping) -> np.ndarray:
    """:func:`_loads` at the two end nodes only, (2, d, n_w, n_ch): all that the
    reactions (:func:`_reactions`) read of it — element 0's share on node 0, the last
    element's on the last node (the whole-line load was 0.2 ms of the chain)."""
    f = None
    if inp.moments is not None:
        _drag_blocks(system, damping)
        b = damping._cache["elements"]
        f = np.stack([np.einsum("ij,jwc->iwc", b[0], inp.moments[0, 0]),
                      np.einsum("ij,jwc->iwc", b[-1], inp.moments[-1, 1])])
    if inp.velocity is not None and np.any(damping.b_node):
        fn = damping.b_node[[0, -1], None, None, None] * inp.velocity[[0, -1]]
        f = fn if f is None else f + fn
    ends = inp.inertia_load[[0, -1]]
    return ends if f is None else ends + f


def _end_nodes(inp: _Inputs, n: int, d: int) -> np.ndarray:
    """Node vectors (n_nodes, d, n_w, n_ch): the prescribed end motion at the end nodes,
    zero inside."""
    n_w, n_ch = inp.weights.shape
    x = np.zeros((n, d, n_w, n_ch), dtype=complex)
    if inp.ub is not None:
        x[0] = inp.ub[0]
        x[-1] = inp.ub[1]
    return x


def _dynamic(prep: _Prep, c: _Blk, w: np.ndarray, x: np.ndarray) -> np.ndarray:
    """(−ω²M_T + iωC) x for node vectors x (n_nodes, d, n_w, k)."""
    return (-(w * w)[:, None] * _matvec(prep.MT, x) + (1j * w)[:, None] * _matvec(c, x))


def _to_freq(x: np.ndarray) -> np.ndarray:
    """Free node vectors (n_f, d, n_w, k) -> (n_w, n_f·d, k), contiguous."""
    n_f, d, n_w, k = x.shape
    if x.dtype == complex and x.flags.c_contiguous and k > 0:
        # the k channels of one (node, component, ω) move as one block: a 2-D transpose
        # of k·16-byte items (numpy's copy of 16-byte items in k-pairs was 2x slower)
        item = np.dtype((np.void, 16 * k))
        v = x.reshape(n_f * d, n_w, k).view(item)[..., 0]  # (n_f·d, n_w)
        return np.ascontiguousarray(v.T).view(complex).reshape(n_w, n_f * d, k)
    return np.ascontiguousarray(np.transpose(x, (2, 0, 1, 3))).reshape(n_w, n_f * d, k)


def _from_freq(x: np.ndarray, d: int) -> np.ndarray:
    """(n_w, n_f·d, k) -> (n_f, d, n_w, k)."""
    n_w, nf, k = x.shape
    return np.transpose(x.reshape(n_w, nf // d, d, k), (1, 2, 0, 3))


def _base(system: "LineSystem", prep: _Prep, inp: _Inputs) -> tuple[np.ndarray, ...]:
    """Drag-independent parts of the free-row load, cached per inputs and solver.

    The load on the free rows is  F0 + F_d(V) + C_d Q  with  Q = −iω U_p, F_d(V) the
    drag load of the fluid velocity integrated along the elements (:func:`_drag_load`)
    and
        direct: U_p = the end motion (zero inside),
                F0 = F_I − (K − ω²M_T + iωC_s) U_p;
        Foss:   U_p = the end motion with the exact static following inside,
                F0 = F_I − (−ω²M_T + iωC_s) U_p   (K U_p = 0 on the free rows),
    F_I the Morison inertia load; returns (U_p, F0, Q) (Q None without end motion)."""
    key = system.solver
    if key not in inp.cache:
        w = inp.omega
        if inp.ub is None:
            u = _end_nodes(inp, prep.n, prep.d)
            f0, q = inp.inertia_load, None
        else:
            # U_p = G u_b with G (n_nodes, d, 2d) the unit end displacements (and their
            # static following): M_T U_p, C_s U_p, K U_p are (M_T G) u_b, … — small
            # products with the cached M_T G, C_s G, K G instead of block products of
            # the (n_nodes, d, n_w·n_ch) vectors (0.3 ms per grid on the chain)
            direct = system.solver == "direct"
            g, mg, sg, kg = prep.end_basis(direct)
            # only the channels that move an end (the sea without RAOs does not): the
            # others have U_p = 0, F0 = F_I
            act = _moving_channels(inp)
            ub = inp.ub if act is None else inp.ub[..., act]
            ubf = np.ascontiguousarray(ub.reshape(2 * prep.d, -1))
            shape = (prep.n, prep.d) + ub.shape[2:]

            def times(b: np.ndarray) -> np.ndarray:
                return _real_gemm(b, ubf).reshape(shape)

            inertia = inp.inertia_load if act is None else inp.inertia_load[..., act]
            u = times(g)
            f0 = inertia - (-(w * w)[:, None] * times(mg) + (1j * w)[:, None] * times(sg))
            if direct:
                f0 = f0 - times(kg)
            q = (-1j * w)[:, None] * u
            if act is not None:  # back to all channels
                full = (prep.n, prep.d) + inp.ub.shape[2:]
                u_all, q_all = np.zeros(full, dtype=complex), np.zeros(full, dtype=complex)
                f0_all = inp.inertia_load.copy()
                u_all[..., act], q_all[..., act], f0_all[..., act] = u, q, f0
                u, q, f0 = u_all, q_all, f0_all
        inp.cache[key] = (u, f0, q)
    return inp.cache[key]


def _moving_channels(inp: _Inputs) -> np.ndarray | None:
    """Indices of the channels with a nonzero end motion, or None when all have one."""
    moving = np.any(inp.ub.reshape(-1, inp.ub.shape[-1]) != 0, axis=0)
    return None if moving.all() else np.flatnonzero(moving)


def _drag_inputs(system: "LineSystem", prep: _Prep, inp: _Inputs
                 ) -> tuple[np.ndarray | None, np.ndarray | None]:
    """Drag-independent parts of the drag load on the free rows, F_d(V) + C_d Q of
    :func:`_base`, cached per inputs and solver: the element moments
    W_s = ∫N_s v dξ + Σ_t P_st Q_t (P the mass pattern of the drag,
    :func:`_blocks_of_elements`), so that both terms are ONE element load
    Σ_el l0·B·W (:func:`_element_load`), and the attachment velocity V + Q at the
    nodes (n_nodes, d, n_w, n_ch); None where absent."""
    key = ("drag_inputs", system.solver)
    if key not in inp.cache:
        _, _, q = _base(system, prep, inp)
        wm = None
        if q is not None:
            pat = (np.array([[0.5, 0.0], [0.0, 0.5]])
                   if system.model.mass_matrix == "lumped" else
                   np.array([[1.0 / 3.0, 1.0 / 6.0], [1.0 / 6.0, 1.0 / 3.0]]))
            act = _moving_channels(inp)  # Q = 0 for the others: W = the moments
            qa = q if act is None else q[..., act]
            w_q = np.empty((prep.n - 1, 2) + qa.shape[1:], dtype=complex)
            for side in range(2):
                w_q[:, side] = pat[side, 0] * qa[:-1]
                w_q[:, side] += pat[side, 1] * qa[1:]
            if inp.moments is not None:
                w_q += inp.moments if act is None else inp.moments[..., act]
            if act is None:
                wm = w_q
            else:
                wm = (inp.moments.copy() if inp.moments is not None else
                      np.zeros((prep.n - 1, 2) + q.shape[1:], dtype=complex))
                wm[..., act] = w_q
        elif inp.moments is not None:
            wm = inp.moments
        vq = inp.velocity
        if q is not None and system.drag_nodes.size:  # V + Q: attachments only
            vq = q if vq is None else vq + q
        inp.cache[key] = (wm, vq)
    return inp.cache[key]


def _free_load(system: "LineSystem", prep: _Prep, inp: _Inputs, damping: Damping
               ) -> np.ndarray:
    """The load of :func:`_solve_free`, F0 + F_d(V) + C_d Q (:func:`_base`), on all
    nodes (n_nodes, d, n_w, n_ch), a fresh array."""
    _, f0, _ = _base(system, prep, inp)
    wm, vq = _drag_inputs(system, prep, inp)
    if wm is None:
        rhs = f0.copy()
    else:
        _drag_blocks(system, damping)
        rhs = _element_load(damping._cache["elements"], wm)
        rhs += f0
    if vq is not None and np.any(damping.b_node):
        rhs += damping.b_node[:, None, None, None] * vq
    return rhs


def _solve_free(system: "LineSystem", inp: _Inputs, damping: Damping, *,
                modal_direct: bool = False) -> tuple[np.ndarray, _Blk]:
    """Dynamic part on the free nodes, (n_nodes − 2, d, n_w, n_ch), and C = C_s + C_d.

    The total displacement is U = U_p + [0; u_f; 0] with U_p of :func:`_base`.
    ``modal_direct`` (Foss systems): solve the same modal equations per frequency
    instead of by the Foss eigenproblem (:func:`_foss_free`)."""
    prep = _prep(system)
    d = prep.d
    w = inp.omega
    cd = _drag_blocks(system, damping)
    c = _add(prep.S, cd)
    rhs = _free_load(system, prep, inp, damping)
    if system.solver == "direct":
        rhs_f = _to_freq(rhs[1:-1])
        bC = prep.bS + _free_band(cd)
        u_f = _solve_band_stacked(prep.bK, prep.bM, bC, rhs_f, w, 2 * d - 1, 2 * d - 1,
                                  (system.model.K, system.model.M))
        _check_line_conditioning(system, prep, bC, w, rhs_f, u_f)
        return np.ascontiguousarray(_from_freq(u_f, d)), c
    u_f = _foss_free(system, prep, c, prep._free_rows(rhs), w, modal_direct=modal_direct)
    return u_f.reshape(prep.n - 2, d, *u_f.shape[1:]), c


def _total(system: "LineSystem", inp: _Inputs, u_free: np.ndarray) -> np.ndarray:
    """Total displacement (n_nodes, d, n_w, n_ch) from the free-node dynamic part."""
    prep = _prep(system)
    u = _base(system, prep, inp)[0].copy()
    u[1:-1] += u_free
    return u


def _solve_nodes(system: "LineSystem", inp: _Inputs, damping: Damping
                 ) -> tuple[np.ndarray, _Blk]:
    """Total displacement (n_nodes, d, n_w, n_ch) and C = C_s + C_d."""
    u_f, c = _solve_free(system, inp, damping)
    return _total(system, inp, u_f), c


def _check_line_conditioning(system, prep, bC, w, f, u) -> None:
    """SolverError where ||Z|| ||U|| / ||F|| exceeds 1e12 (undamped resonance), as
    :func:`stochcable.dynamics.solvers.solve_direct`."""
    from stochcable.dynamics.solvers import SINGULAR_CONDITION

    nc = float(np.sqrt(np.sum(bC**2)))
    nz = prep.norm_K + w**2 * prep.norm_M + w * nc
    nf = np.linalg.norm(f.reshape(w.size, -1), axis=1)
    nu = np.linalg.norm(u.reshape(w.size, -1), axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        est = np.where(np.isfinite(nu), nz * np.where(nf > 0, nu / np.where(nf > 0, nf, 1.0),
                                                      0.0), np.inf)
    bad = np.flatnonzero(est > SINGULAR_CONDITION)
    if bad.size:
        from stochcable.dynamics.solvers import _singular_error

        k = int(bad[np.argmax(est[bad])])
        K, M = system.model.partition("K")[0], system.model.partition("MT")[0]
        raise _singular_error(K, M, float(w[k]), float(est[k]))


def _real_gemm(a: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Real (p, q) matrix times complex (q, k) C-contiguous matrix as ONE real product
    on the interleaved (q, 2k) view (numpy would upcast ``a`` to complex: 4x the
    work)."""
    q, k = x.shape
    return (a @ x.view(float).reshape(q, 2 * k)).view(complex)


def _foss_free(system: "LineSystem", prep: _Prep, c: _Blk, rhs: np.ndarray,
               w: np.ndarray, modal_direct: bool = False) -> np.ndarray:
    """Foss modal solve on the free DOFs, rhs (n_free_dof, n_w, n_ch), with the static
    correction of the truncated modes (seed 001 §5.3;
    :func:`stochcable.dynamics.solvers.foss_decomposition`).

    ``modal_direct``: the modal equations (K̂ − ω²M̂ + iωĈ)z = Φᵀf solved per frequency
    (batched dense LU) instead of by the Foss eigenproblem: the same response to
    round-off, cheaper on a few dozen frequencies (the coarse start: 0.23 against
    0.48 ms for 20 modes and 51 frequencies, the 2n-state eigenproblem being
    frequency-independent); also the fallback of a defective Foss pencil."""
    phi, mh, kh = prep.modal(system)
    m = phi.shape[1]
    nf, n_w, n_ch = rhs.shape
    ch = phi.T @ prep._free_rows(_matvec(c, prep._nodes(phi)))
    ch = 0.5 * (ch + ch.T)
    flat = np.ascontiguousarray(rhs).reshape(nf, n_w * n_ch)
    fh = _real_gemm(phi.T, flat)  # (m, n_w·n_ch), mode-major
    z = None
    if not modal_direct:
        try:
            foss = _foss_decomposition(mh, ch, kh)
        except SolverError as exc:
            warn(f"{exc}; falling back to the direct solve in modal coordinates",
                 DefectivePencilWarning, stacklevel=3)
        else:
            z = _foss_transfer_modal(foss, fh, w, n_ch)
    if z is None and modal_direct:
        # batched LU without the conditioning estimate of solve_direct: a singular
        # frequency raises LinAlgError or gives non-finite σ (the coarse start then
        # falls back on the full grid, which has the checks)
        fh3 = np.moveaxis(fh.reshape(m, n_w, n_ch), 1, 0)
        wz = w[:, None, None]
        key = ("stiff_mass", m, w.tobytes())  # K̂ − ω²M̂: drag-independent, per grid
        if key not in prep._modal:
            prep._modal[key] = kh - wz * wz * mh
        # the matrices are symmetric to the bit (K̂, M̂, Ĉ symmetrized): passed as
        # their transposes, whose memory is the column-major layout LAPACK takes, so
        # numpy's copy into it is contiguous (the same matrices and bits, ≈ 10 % faster)
        z3 = np.linalg.solve((prep._modal[key] + 1j * wz * ch).transpose(0, 2, 1), fh3)
        z = np.ascontiguousarray(np.moveaxis(z3, 0, 1)).reshape(m, n_w * n_ch)
    elif z is None:
        fh3 = np.moveaxis(fh.reshape(m, n_w, n_ch), 1, 0)
        z3 = solve_direct(kh, mh, ch, fh3, w, method="dense")
        z = np.ascontiguousarray(np.moveaxis(z3, 0, 1)).reshape(m, n_w * n_ch)
    u = _real_gemm(phi, np.ascontiguousarray(z))
    if m < nf:
        u += prep.residual(system, flat)
    return u.reshape(nf, n_w, n_ch)


def _reactions(system: "LineSystem", prep: _Prep, c: _Blk, u: np.ndarray,
               f_all: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Dynamic force of the line on the supports, (n_w, 2d, n_ch):
    −[(K − ω²M_T + iωC)U − F]_end rows, u and f_all in the node layout."""
    d = u.shape[1]
    shape = u.shape[1:]  # (d, n_w, n_ch)
    ua, ua1 = (np.ascontiguousarray(u[i]).reshape(d, -1).view(float) for i in (0, 1))
    ub, ub1 = (np.ascontiguousarray(u[i]).reshape(d, -1).view(float) for i in (-1, -2))

    def rows(x: _Blk) -> tuple[np.ndarray, np.ndarray]:
        """(X U) at the end nodes' rows for real node blocks X, each (d, n_w, n_ch):
        real d × d products on the interleaved views (the complex (n_w, d, d)
        impedance blocks and their einsums were 0.3 ms of the chain)."""
        ra = x[0][0] @ ua + x[1][0].T @ ua1
        rb = x[0][-1] @ ub + x[1][-1] @ ub1
        return tuple(np.ascontiguousarray(r).view(complex).reshape(shape) for r in (ra, rb))

    ww = (w * w)[:, None]
    iw = (1j * w)[:, None]
    out = []
    for k, (rk, rm, rc) in enumerate(zip(rows(prep.K), rows(prep.MT), rows(c))):
        r = rk - ww * rm + iw * rc - f_all[0 if k == 0 else -1]
        out.append(np.moveaxis(r, 1, 0))  # (n_w, d, n_ch)
    return -np.concatenate(out, axis=1)


def _response(system: "LineSystem", inp: _Inputs, damping: Damping,
              solved: tuple[np.ndarray, _Blk] | None = None) -> Response:
    """Response with reactions and end tensions; ``solved`` = (u, C) of a solve already
    done with this ``damping`` (:func:`_solve_nodes`) skips the solve."""
    prep = _prep(system)
    u, c = _solve_nodes(system, inp, damping) if solved is None else solved
    support = _reactions(system, prep, c, u, _end_loads(system, inp, damping), inp.omega)
    disp = _to_freq(u)
    return Response(omega=inp.omega, displacement=disp, support_force=support,
                    end_tension=_end_tension(system, support))


# --------------------------------------------------------------------------- solve


def solve(
    system: LineSystem,
    channels: tuple[Channel, ...],
    damping: Damping,
    timing: dict[str, float] | None = None,
) -> Response:
    """Harmonic response of a line to every channel, for a given linear drag.

    Parameters
    ----------
    system : LineSystem
        The line (its ``solver`` and kept modes).
    channels : tuple of Channel
        Inputs sampled on a common grid.
    damping : Damping
        The linear drag.
    timing : dict, optional
        ``timing["solve_s"]`` is increased by the time spent here. [s]

    Returns
    -------
    Response

    Raises
    ------
    SolverError
        At an undamped resonance (from :mod:`stochcable.dynamics.solvers`).

    Notes
    -----
    Free rows (seed 001 eq. 5.2.6 with prescribed ends):
    (K_ff − ω²M_T,ff + iωC_ff)U_f = [C_d V + B_I A]_f − (K_fb − ω²M_T,fb + iωC_fb)u_b,
    solved directly or by Foss modal superposition (seed 001 §5.3) with the static
    correction of the truncated modes.  For Foss, a moving end is split into the exact
    quasi-static following U_qs = −K_ff⁻¹K_fb u_b and a dynamic part loaded by the
    inertia and damping forces of u_b and U_qs (the classical support-excitation
    split): the stiffness load K_fb u_b, concentrated next to the end, never meets
    the modal truncation, which cut the end-tension error of a 10-mode solve from
    17 % to 0.3 % on the DESIGN.md example.  With all modes both are the direct solve.

    C = C_d + C_s with C_s the seabed dashpots plus the Rayleigh structural damping
    alpha·M_T + beta·K (``system.structural_damping``).  Implementation: node blocks
    of the block-tridiagonal matrices, the direct solve of all frequencies in one
    stacked banded LAPACK call, the Foss transfer as matrix products over all
    frequencies and channels, K_ff⁻¹ by a cached banded Cholesky.
    """
    t0 = time.perf_counter()
    resp = _response(system, _inputs(system, channels), damping)
    if timing is not None:
        timing["solve_s"] = timing.get("solve_s", 0.0) + time.perf_counter() - t0
    return resp


def _end_direction(system: LineSystem, end: str) -> np.ndarray:
    """Unit direction of the static force on the support (3,), falling back on the end
    element direction when that force vanishes."""
    st = system.statics
    f0 = np.asarray(st.force_a if end == "end_a" else st.force_b, dtype=float)
    nrm = float(np.linalg.norm(f0))
    if nrm > 0.0:
        return f0 / nrm
    e = system.frames[0]
    return e[0] if end == "end_a" else -e[-1]


def _end_tension(system: LineSystem, support: np.ndarray) -> dict[str, np.ndarray]:
    """δ|F| = (F0/|F0|)·δF at each end, shape (n_ch, n_omega)."""
    model = system.model
    comps = list(model.components)
    d = model.dim
    out = {}
    for k, end in enumerate(("end_a", "end_b")):
        u = _end_direction(system, end)[comps]
        df = support[:, k * d:(k + 1) * d, :]  # fixed DOFs: node 0 then node n-1
        out[end] = np.einsum("c,wcr->rw", u, df)
    return out


# -------------------------------------------------------------------- linearization


def _trapezoid_weights(w: np.ndarray) -> np.ndarray:
    q = np.zeros_like(w)
    if w.size > 1:
        dw = np.diff(w)
        q[:-1] += 0.5 * dw
        q[1:] += 0.5 * dw
    return q


def relative_velocity_sigmas(
    system: LineSystem,
    channels: tuple[Channel, ...],
    response: Response | None,
    method: str,
    displacement: np.ndarray | None = None,
) -> np.ndarray:
    """σ of the relative velocity (fluid − structure) of the elements and attachments.

    Parameters
    ----------
    system : LineSystem
    channels : tuple of Channel
        With their spectra on the response grid.
    response : Response or None
        The structural response; None takes ``displacement`` (or the structure at rest).
    method : {"seed", "vector", "harmonic"}
        Layout of the returned vector (see :func:`drag_coefficients`).
    displacement : ndarray, optional
        (n_omega, n_dof, n_ch) displacement used when ``response`` is None. [m/unit]

    Returns
    -------
    ndarray
        The σ vector. [m/s]

    Notes
    -----
    Seed 001 eqs. 5.2.3–5.2.5 with an element mean in place of the seed's nodal value:
    σ² = Σ_i ∫ S_i(ω) ∫₀¹ |r·H_{v,i}(ξ, ω)|² dξ dω (trapezoid on the grid), H_v the
    transfer function of the relative velocity v(ξ) − iωU(ξ) along the element, r
    the element's e (axial) or normals n1, n2; the scalar form uses
    σ_n² = σ_n1² + σ_n2².  The fluid part is integrated exactly
    (:func:`stochcable.dynamics.loads.element_wave_kinematics`: the wet part only), the
    structural displacement U(ξ) is the element's linear interpolation, so the
    ξ-integral is closed-form (:func:`_element_variance`).  The drag coefficient B is
    then constant over the element (eq. 5.2.2 with this σ).  Attachments: the nodal
    relative velocity.
    """
    inp = _inputs(system, channels)
    u = None
    if response is not None:
        u = response.displacement
    elif displacement is not None:
        u = displacement
    if u is not None:
        u = _from_freq(u, system.model.dim)
    return _sigmas(system, inp, u, method)


def _proj_rows(system: LineSystem, method: str) -> np.ndarray:
    """Projection rows of the relative velocity, (n_el, k, d): e, n1 (and n2 in 3-D,
    and (n1 + n2)/√2 for "vector" in 3-D), on the model components."""
    key = ("rows", method)
    if key not in system._cache:
        model = system.model
        comps = list(model.components)
        e, n1, n2 = system.frames
        rows = [e, n1]
        if model.dim == 3:
            rows.append(n2)
            if method == "vector":
                rows.append((n1 + n2) / math.sqrt(2.0))
        system._cache[key] = np.ascontiguousarray(np.stack(rows, axis=1)[:, :, comps])
    return system._cache[key]


def _project_ends(pr: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Projections of node vectors x (n_nodes, d, n_w, n_ch) (complex) at the start and
    the end node of each element: real (n_el, k, 2, 2·n_w·n_ch), the interleaved
    (re, im) view of the complex projections."""
    n, d = x.shape[:2]
    xf = np.ascontiguousarray(x).reshape(n, d, -1).view(float)
    out = np.empty((n - 1, pr.shape[1], 2, xf.shape[-1]))
    np.matmul(pr, xf[:-1], out=out[:, :, 0])
    np.matmul(pr, xf[1:], out=out[:, :, 1])
    return out


def _fluid_terms(system: LineSystem, inp: _Inputs, method: str
                 ) -> tuple[np.ndarray, np.ndarray | None]:
    """Drag-independent terms of the element mean square, cached per inputs and method:
    c0 = Σ weight ∫₀¹ |r·v|² dξ (n_el, k) and the weighted projected consistent moments
    weight·(r·∫N_a v dξ, r·∫N_b v dξ) as a real (n_el, k, 2, 2·n_w·n_ch) view (None
    without fluid velocity), r the rows of :func:`_proj_rows`."""
    key = ("fluid", method)
    if key not in inp.cache:
        pr = _proj_rows(system, method)
        if inp.moments is None:
            inp.cache[key] = (np.zeros(pr.shape[:2]), None)
        else:
            c0 = np.sum((pr @ inp.square) * pr, axis=2)  # r·S·r (5x the einsum's speed)
            n_el = inp.moments.shape[0]
            mkey = ("fluid_m", method)
            if mkey not in inp.cache:  # (a subset's are sliced from its full grid's)
                d = inp.moments.shape[2]
                mf = np.ascontiguousarray(inp.moments).reshape(n_el, 2, d, -1).view(float)
                inp.cache[mkey] = pr[:, None] @ mf  # (n_el, side, k, 2N): one product
            m = inp.cache[mkey]
            mw = np.empty((n_el, pr.shape[1], 2, m.shape[-1]))
            np.multiply(np.swapaxes(m, 1, 2), _w2(inp), out=mw)
            inp.cache[key] = (c0, mw)
    return inp.cache[key]


_GRAM = np.array([[1.0, 0.5], [0.5, 1.0]]) / 3.0  # ∫N_i N_j dξ


def _element_variance(system: LineSystem, inp: _Inputs, method: str,
                      q: np.ndarray | None) -> np.ndarray:
    """Σ weight ∫₀¹ |r·(v(ξ) + N_a q_a + N_b q_b)|² dξ per element and row, (n_el, k).

    q = −iωU is minus the structural velocity at the element's two nodes, projected
    (real view (n_el, k, 2, 2N) of :func:`_project_ends`; None: the structure at rest).
    With m_i = r·∫N_i v and ∫N_a² = ∫N_b² = 1/3, ∫N_a N_b = 1/6 the integral is
    ∫|r·v|² + 2Re(m̄_a q_a + m̄_b q_b) + (|q_a|² + |q_b|² + Re(q̄_a q_b))/3: two batched
    (2 × 2N)(2N × 2) products per element and row."""
    c0, mw = _fluid_terms(system, inp, method)
    if q is None:
        return c0
    # (|q_a|² + |q_b|² + Re(q̄_a q_b))/3 = ((q_a + q_b)·q_a + q_b·q_b)/3 on the real
    # views: one elementwise pass and one matrix-vector product with the weights
    # (the stacked (2 × 2N)(2N × 2) products of the Gram matrix were 2-3x slower)
    qa, qb = q[:, :, 0], q[:, :, 1]
    t = qa + qb
    t *= qa
    t += qb * qb
    var = c0 + (t @ _w2(inp)) * _GRAM[0, 0]
    if mw is not None:
        n_el, k = q.shape[:2]
        var += 2.0 * np.einsum("ekn,ekn->ek", mw.reshape(n_el, k, -1),
                               q.reshape(n_el, k, -1))  # Σ w (m_a q_a + m_b q_b)
    return var


def _w2(inp: _Inputs) -> np.ndarray:
    """The weights repeated for the interleaved (re, im) views, (2·n_w·n_ch,)."""
    if "w2" not in inp.cache:
        inp.cache["w2"] = np.repeat(inp.weights.ravel(), 2)
    return inp.cache["w2"]


def _sigma_vector(system: LineSystem, var: np.ndarray, s_node: np.ndarray,
                  method: str) -> np.ndarray:
    """The σ vector (layout of :func:`drag_coefficients`) from the element-mean variances
    of the projected relative velocity, var (n_el, k) for the rows of
    :func:`_proj_rows`."""
    var = np.clip(var, 0.0, None)  # round-off of the expanded square
    v_t, v1 = var[:, 0], var[:, 1]
    v2 = var[:, 2] if var.shape[1] > 2 else np.zeros_like(v1)
    if method == "vector":
        v3 = var[:, 3] if var.shape[1] > 3 else 0.5 * v1
        normal = [np.sqrt(v1), np.sqrt(v2), np.sqrt(v3)]
    else:
        normal = [np.sqrt(v1 + v2)]
    return np.concatenate(normal + [np.sqrt(v_t), s_node])


def _weighted_var(x: np.ndarray, inp: _Inputs) -> np.ndarray:
    """Σ_k weight_k |x_k|² over the last axis (n_w·n_ch) of a complex array."""
    xf = x.view(float)
    return (xf * xf) @ _w2(inp)


def _node_sigmas(system: LineSystem, inp: _Inputs, vr_nodes: np.ndarray) -> np.ndarray:
    """σ of the total relative velocity of the attachment nodes, vr_nodes of shape
    (n_drag_nodes, d, n_w, n_ch)."""
    if vr_nodes.shape[0] == 0:
        return np.zeros(0)
    n, d = vr_nodes.shape[:2]
    # the weighted mean square per node and component, summed over the components
    # (flattening the components into the frequency axis mismatched the weights: every
    # scene with an attachment drag area and a sea failed)
    flat = np.ascontiguousarray(vr_nodes).reshape(n * d, -1)
    return np.sqrt(_weighted_var(flat, inp).reshape(n, d).sum(axis=1))


def _sigmas(system: LineSystem, inp: _Inputs, u: np.ndarray | None, method: str) -> np.ndarray:
    """σ vector from node displacements u (n_nodes, d, n_w, n_ch) (None: at rest)."""
    model = system.model
    n_w, n_ch = inp.weights.shape
    idx = system.drag_nodes
    if u is None:
        var = _element_variance(system, inp, method, None)
        vr = (np.zeros((idx.size, model.dim, n_w, n_ch), dtype=complex)
              if inp.velocity is None else inp.velocity[idx])
    else:
        q = (-1j * inp.omega)[:, None] * u
        var = _element_variance(system, inp, method,
                                _project_ends(_proj_rows(system, method), q))
        vr = q[idx] if inp.velocity is None else q[idx] + inp.velocity[idx]
    return _sigma_vector(system, var, _node_sigmas(system, inp, vr), method)


def _qproj(system: LineSystem, inp: _Inputs, method: str) -> tuple:
    """Drag-independent parts of :func:`_sigmas_free`, cached per inputs, solver and
    method: the projections of Q = −iω U_p at the element ends (the real view of
    :func:`_project_ends`, None without end motion), the factors −iω per column
    (n_w·n_ch,) and the attachments' V + Q (n_drag_nodes, d, n_w, n_ch)."""
    key = ("qproj", system.solver, method)
    if key not in inp.cache:
        prep = _prep(system)
        _, _, q = _base(system, prep, inp)
        wcol = np.repeat(-1j * inp.omega, inp.weights.shape[1])
        idx = system.drag_nodes
        y = np.zeros((idx.size, prep.d) + inp.weights.shape, dtype=complex)
        if inp.velocity is not None:
            y += inp.velocity[idx]
        if q is None:
            inp.cache[key] = (None, wcol, y)
        else:
            y += q[idx]
            inp.cache[key] = (_project_ends(_proj_rows(system, method), q), wcol, y)
    return inp.cache[key]


def _sigmas_free(system: LineSystem, inp: _Inputs, u_free: np.ndarray,
                 method: str) -> np.ndarray:
    """σ vector from the free-node dynamic part of :func:`_solve_free`.

    The structure's velocity is that of U_p (:func:`_base`, cached projections) plus
    iω u_f: two stacked real products per iteration."""
    prep = _prep(system)
    pr = _proj_rows(system, method)
    q_p, wcol, y = _qproj(system, inp, method)
    n_f, d = u_free.shape[:2]
    qf = np.ascontiguousarray(u_free).reshape(n_f, d, -1) * wcol
    qff = qf.view(float)
    n_el = pr.shape[0]
    qx = np.empty((n_el, pr.shape[1], 2, qff.shape[-1]))
    qx[0, :, 0] = 0.0
    qx[-1, :, 1] = 0.0
    np.matmul(pr[1:], qff, out=qx[1:, :, 0])
    np.matmul(pr[:-1], qff, out=qx[:-1, :, 1])
    if q_p is not None:
        qx += q_p
    var = _element_variance(system, inp, method, qx)
    idx = system.drag_nodes
    s_node = np.zeros(0)
    if idx.size:
        u_node = np.zeros((idx.size,) + u_free.shape[1:], dtype=complex)
        inner = (idx > 0) & (idx < prep.n - 1)
        u_node[inner] = u_free[idx[inner] - 1]
        vr = y + wcol.reshape(u_free.shape[2:]) * u_node
        s_node = _node_sigmas(system, inp, vr)
    return _sigma_vector(system, var, s_node, method)


def _rest_sigmas(system: LineSystem, inp: _Inputs, method: str) -> np.ndarray:
    """The σ of the start (step 5): the fluid velocity relative to the line following
    its ends quasi-statically, :func:`_sigmas` of :func:`_quasi_static`.  For Foss
    that motion is U_p of :func:`_base`, whose projections :func:`_qproj` has cached
    (the same numbers)."""
    if system.solver == "direct":
        return _sigmas(system, inp, _quasi_static(system, inp), method)
    q_p, _, y = _qproj(system, inp, method)
    return _sigma_vector(system, _element_variance(system, inp, method, q_p),
                         _node_sigmas(system, inp, y), method)


def _quasi_static(system: LineSystem, inp: _Inputs) -> np.ndarray | None:
    """Node displacements of the line following its prescribed ends quasi-statically,
    U_f = −K_ff⁻¹K_fb u_b, (n_omega, n_nodes, d, n_ch); None without end motion."""
    if inp.ub is None:
        return None
    prep = _prep(system)
    u = _end_nodes(inp, prep.n, prep.d)
    ub = np.ascontiguousarray(inp.ub.reshape(2 * prep.d, -1))
    u[1:-1] = _real_gemm(prep.follower(), ub).reshape(u[1:-1].shape)
    return u


# ---------------------------------------------------------------------- coarse start


def _relative_change(new: np.ndarray, x: np.ndarray) -> float:
    """max_i |new_i − x_i| / max(|new_i|, 1e-6·max|new|): the convergence measure of
    :func:`stochcable.dynamics.linearization.fixed_point`."""
    den = np.maximum(np.abs(new), 1e-6 * max(float(np.max(np.abs(new), initial=0.0)), 1e-300))
    return float(np.max(np.abs(new - x) / den, initial=0.0))


def _interpolatory_weights(omega: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """Quadrature weights on the subset ``omega[idx]`` that stand for the full grid's
    trapezoid rule, (idx.size,). [rad/s]

    W = Pᵀq with q the trapezoid weights of ``omega`` and P (n_omega × n_sub) the local
    4-point Lagrange (cubic) interpolation from the subset (two nodes on each side,
    shifted inward at the ends; exact at the subset points): Σ_a W_a f(ω_a) =
    Σ_j q_j (Pf)(ω_j), the full-grid trapezoid sum of the interpolant of f.  f is
    reproduced wherever it is cubic over a stencil, so the error is O(H⁴) in the
    subset spacing H against O(H²) for the trapezoid rule on the subset (the
    (idx.size < 4) subsets use the highest order they allow)."""
    q = _trapezoid_weights(omega)
    ws = omega[idx]
    n_sub = ws.size
    order = min(4, n_sub)
    pos = np.searchsorted(ws, omega)
    lo = np.clip(pos - order // 2, 0, n_sub - order)
    nodes = lo[:, None] + np.arange(order)  # (n_omega, order) stencil of each point
    x = ws[nodes]
    # Lagrange basis, vectorized over the frequencies and the stencil: the ratios
    # r_ab = (ω − x_b)/(x_a − x_b) (r_aa = 1), multiplied in the order b = 0, 1, …
    # (the same products as a loop over a and b)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = (omega[:, None, None] - x[:, None, :]) / (x[:, :, None] - x[:, None, :])
    idx_a = np.arange(order)
    r[:, idx_a, idx_a] = 1.0
    basis = r[:, :, 0].copy()
    for b in range(1, order):
        basis *= r[:, :, b]
    return np.bincount(nodes.ravel(), weights=(q[:, None] * basis).ravel(),
                       minlength=n_sub)


def _coarse_subset(system: LineSystem, inp: _Inputs, damping: Damping
                   ) -> np.ndarray | None:
    """Indices of the coarse-start frequencies (module docstring "Coarse start"), or
    None when the grid is too small or the subset would not be much smaller.

    Every ``COARSE_STEP``-th frequency and the last, plus ± ``COARSE_STEP`` points at
    full resolution around the narrow features, those whose half-power band is
    narrower than two coarse spacings: a channel's spectral peak (the band where
    S_i >= S_i,max/2 around its maximum) and a natural frequency inside the grid
    (bandwidth 2ζ_jω_j = φ_jᵀCφ_j, mass-normalized φ_j, C the structural damping plus
    ``damping``, the starting drag).  Broad features are left to the cubic rule
    (:func:`_interpolatory_weights`), which is most accurate on a uniform subset."""
    w = inp.omega
    n = w.size
    step = COARSE_STEP
    if n < COARSE_MIN_FREQUENCIES:
        return None
    keep = np.zeros(n, dtype=bool)
    keep[::step] = True
    keep[-1] = True
    coarse_spacing = step * np.gradient(w)
    centers = []
    spectra = inp.weights / np.maximum(_trapezoid_weights(w), 1e-300)[:, None]
    for s_i in spectra.T:  # channels: is the half-power band of the peak narrow?
        k = int(np.argmax(s_i))
        if s_i[k] <= 0:
            continue
        low = s_i < 0.5 * s_i[k]
        lo = k - int(np.argmax(low[k::-1])) if np.any(low[:k + 1]) else 0
        hi = k + int(np.argmax(low[k:])) if np.any(low[k:]) else n - 1
        if w[hi] - w[lo] < 2.0 * coarse_spacing[k]:
            centers.append(np.array([k]))
    wn = np.asarray(system.modes.omega)
    inside = np.flatnonzero((wn > w[0]) & (wn < w[-1]))
    if inside.size:
        prep = _prep(system)
        c = _add(prep.S, _drag_blocks(system, damping))
        phi = system.modes.shapes[system.model.free][:, inside]
        band = np.einsum("ij,ij->j", phi, prep._free_rows(_matvec(c, prep._nodes(phi))))
        near = np.clip(np.searchsorted(w, wn[inside]), 1, n - 1)
        near -= (wn[inside] - w[near - 1]) < (w[near] - wn[inside])  # nearest point
        centers.append(near[band < 2.0 * coarse_spacing[near]])
    centers_ = np.concatenate(centers) if centers else np.zeros(0, dtype=int)
    if centers_.size:
        span = centers_[:, None] + np.arange(-step, step + 1)
        keep[np.clip(span, 0, n - 1).ravel()] = True
    idx = np.flatnonzero(keep)
    return idx if idx.size <= COARSE_MAX_FRACTION * n else None


def _subset_inputs(system: LineSystem, channels: tuple[Channel, ...], inp: _Inputs,
                   idx: np.ndarray) -> _Inputs:
    """The inputs on the frequencies ``inp.omega[idx]``, weighted by
    :func:`_interpolatory_weights` (the same layout as :func:`_inputs`)."""
    comps = list(system.model.components)
    spectra = np.stack([c.spectrum for c in channels], axis=1)[idx]
    weights = _interpolatory_weights(inp.omega, idx)[:, None] * spectra
    square = None
    for i, ch in enumerate(channels):
        if ch.element_velocity is None and ch.velocity is None:
            continue  # as _inputs: the mean square goes with the element moments
        sq = element_mean_square(ch)[idx]
        sq = sq[:, :, np.array(comps)[:, None], comps]  # one gather of the d × d part
        sq = np.einsum("weij,w->eij", sq, weights[:, i])
        square = sq if square is None else square + sq

    def take(a: np.ndarray | None, axis: int) -> np.ndarray | None:
        return None if a is None else np.take(a, idx, axis=axis)

    sub = _Inputs(inp.omega[idx], take(inp.velocity, 2), take(inp.inertia_load, 2),
                  take(inp.ub, 2), weights, take(inp.moments, 3), square)
    # The drag-independent, per-frequency arrays the full grid has already computed
    # (:func:`_base`, :func:`_drag_inputs`, :func:`_qproj`, the projected moments of
    # :func:`_fluid_terms`) are the same numbers at the subset's frequencies: sliced,
    # not recomputed (0.3 ms of the chain's coarse start).
    n_w, n_ch = inp.weights.shape

    def take_view(a: np.ndarray | None) -> np.ndarray | None:
        """Slice the interleaved (n_w·n_ch·2) last axis of a real view."""
        if a is None:
            return None
        lead = a.shape[:-1]
        return np.ascontiguousarray(np.take(a.reshape(lead + (n_w, 2 * n_ch)), idx,
                                            axis=len(lead))).reshape(lead + (-1,))

    for key, val in inp.cache.items():
        if key in ("foss", "direct"):
            u, f0, q = val
            sub.cache[key] = (take(u, 2), take(f0, 2), take(q, 2))
        elif key[0] == "drag_inputs":
            sub.cache[key] = (take(val[0], 3), take(val[1], 2))
        elif key[0] == "fluid_m":
            sub.cache[key] = take_view(val)
        elif key[0] == "qproj":
            q_p, wcol, y = val
            sub.cache[key] = (take_view(q_p), np.ascontiguousarray(
                wcol.reshape(n_w, n_ch)[idx]).ravel(), take(y, 2))
    return sub


def _uniform_subset(n: int) -> np.ndarray:
    """Every ``COARSE_STEP``-th index of n and the last."""
    return np.unique(np.r_[np.arange(0, n, COARSE_STEP), n - 1])


def _coarse_start(
    system: LineSystem,
    channels: tuple[Channel, ...],
    inp: _Inputs,
    settings: AnalysisSettings,
    progress: Progress,
    timing: dict[str, float] | None,
) -> tuple[np.ndarray | None, CoarseStage | None]:
    """The start of the full-grid drag iteration: the fixed point on the coarse subset
    (module docstring "Coarse start"), iterated from the at-rest σ on the subset; or
    (None, None) when the grid is too small, the subset not much smaller, or the
    subset iteration breaks down (non-finite σ, a singular solve): the full-grid
    iteration then starts as without a coarse stage."""
    lin = settings.linearization
    method = lin.method
    n = inp.omega.size
    if n < COARSE_MIN_FREQUENCIES or lin.max_iterations == 1:
        return None, None  # too small, or a single response evaluation asked for
    if method == "vector" and (np.any(system.current_el) or np.any(system.current_node)):
        # the drag of the vector form with a current is a quadrature per element
        # (≈ 15 ms on the chain), not frequency work: a coarse grid saves nothing
        return None, None
    # the full grid's drag-independent arrays first (needed by its iteration anyway):
    # the subsets slice them (_subset_inputs)
    _qproj(system, inp, method)
    _drag_inputs(system, _prep(system), inp)
    _fluid_terms(system, inp, method)
    # the at-rest start on the uniform part of the subset, whose drag decides which
    # resonances are narrow
    base = _uniform_subset(n)
    sub = _subset_inputs(system, channels, inp, base)
    x_rest = _rest_sigmas(system, sub, method)
    if not np.all(np.isfinite(x_rest)):
        return None, None
    first = drag_coefficients(system, x_rest, method)
    idx = _coarse_subset(system, inp, first)
    if idx is None:
        return None, None
    if idx.size != base.size:
        sub = _subset_inputs(system, channels, inp, idx)
    count = [0]

    def update(x: np.ndarray) -> np.ndarray:
        damping = first if x is x_rest else drag_coefficients(system, x, method)
        t0 = time.perf_counter()
        u_f, _ = _solve_free(system, sub, damping, modal_direct=True)
        if timing is not None:
            timing["solve_s"] = timing.get("solve_s", 0.0) + time.perf_counter() - t0
        new = _sigmas_free(system, sub, u_f, method)
        count[0] += 1
        if progress is not _noop:  # (the change is for the callback only)
            progress("linearization", {"line": system.name, "iteration": 0,
                                       "coarse_iteration": count[0],
                                       "change": _relative_change(new, x)})
        return new

    tol = COARSE_TOLERANCE_RATIO * lin.tolerance
    try:
        x0 = update(x_rest)  # unmixed first step, as on the full grid
        change0 = _relative_change(x0, x_rest)
        if not np.all(np.isfinite(x0)):
            return None, None
        if change0 <= tol:
            fp = FixedPointResult(x0, 1, change0, True, (change0,))
        else:
            fp = fixed_point(
                update, x0, tol=tol, max_iterations=lin.max_iterations,
                relaxation=lin.relaxation,
                method="anderson" if lin.acceleration == "anderson" else "relaxed",
                mixing=ANDERSON_MIXING, allow_unconverged=True,
                name=f"coarse start of the drag linearization of line '{system.name}'",
            )
            fp = FixedPointResult(fp.x, fp.iterations + 1, fp.relative_change,
                                  fp.converged, (change0,) + fp.history)
    except (ConvergenceError, SolverError, np.linalg.LinAlgError):
        return None, None  # non-finite σ or a singular subset solve
    return fp.x, CoarseStage(int(idx.size), fp.iterations, fp.history, fp.converged)


def linearize(
    system: LineSystem,
    channels: tuple[Channel, ...],
    settings: AnalysisSettings,
    *,
    progress: Progress | None = None,
    timing: dict[str, float] | None = None,
    coarse: bool = True,
) -> Linearization:
    """Drag linearization of one line: iterate the σ of the relative velocities to a
    fixed point (seed 001 §5.3 steps 5–13).

    Parameters
    ----------
    system : LineSystem
    channels : tuple of Channel
        Inputs on the analysis grid.
    settings : AnalysisSettings
        ``linearization`` (method, tolerance, max_iterations, relaxation,
        acceleration, allow_unconverged).
    progress : callable, optional
        Called as ``progress("linearization", {"line", "iteration", "change"})``.
    timing : dict, optional
        Accumulates ``solve_s``.
    coarse : bool, optional
        Start from the fixed point on a frequency subset (module docstring "Coarse
        start"; grids of at least ``COARSE_MIN_FREQUENCIES`` points).  False iterates
        on the full grid from the at-rest start.  Both converge to the full-grid fixed
        point (the same convergence test on the full grid).

    Returns
    -------
    Linearization
        The drag of the last iteration, the record (full-grid evaluations) and the
        response computed with it (whose σ are the record's final σ: the outputs are
        exactly those of the recorded linear system); ``coarse`` the coarse stage.

    Raises
    ------
    ConvergenceError
        If the σ do not settle within ``max_iterations`` and ``allow_unconverged`` is
        false (the message names the line).
    InputError
        For the harmonic form with a current (not defined).

    Notes
    -----
    Start (step 5): the fluid velocity relative to the line at rest — or, for end
    motions, relative to the line following its ends quasi-statically, so an
    end-motion-only scene does not start undamped.  With ``coarse`` (and a large
    enough grid) the same iteration first runs on a frequency subset from there, and
    its fixed point becomes the start (module docstring "Coarse start").  The σ of the
    response to the start's drag (the first iteration) start the fixed-point
    iteration unmixed; then plain steps use ``relaxation`` and Anderson steps the
    mixing ``ANDERSON_MIXING`` (1).  Convergence: the relative change of every σ
    (:func:`stochcable.dynamics.linearization.fixed_point`) below the tolerance on the full
    grid; the record counts every full-grid response evaluation, the first included
    (the coarse ones are in :attr:`Linearization.coarse`).  The last evaluation's
    solve is reused for the outputs (no extra solve).
    """
    lin = settings.linearization
    method = lin.method
    progress = _noop if progress is None else progress
    if method == "harmonic" and (np.any(system.current_el) or np.any(system.current_node)):
        raise InputError("analysis.linearization.method", "harmonic", "-",
                         "the harmonic (regular-wave) form has no current term: use "
                         "'seed' or 'vector' with a current")
    inp = _inputs(system, channels)
    state: dict[str, Any] = {"it": 0, "change": np.inf}
    cache: dict[str, Any] = {}

    def update(x: np.ndarray) -> np.ndarray:
        damping = drag_coefficients(system, x, method)
        t0 = time.perf_counter()
        u_f, c = _solve_free(system, inp, damping)  # outputs only at the end
        if timing is not None:
            timing["solve_s"] = timing.get("solve_s", 0.0) + time.perf_counter() - t0
        new = _sigmas_free(system, inp, u_f, method)
        state["it"] += 1
        change = _relative_change(new, x)
        state["change"] = change
        progress("linearization", {"line": system.name, "iteration": state["it"],
                                   "change": change})
        cache["damping"], cache["sigma"] = damping, new
        cache["solved"] = (u_f, c)
        return new

    name = f"drag linearization of line '{system.name}'"
    hint = ("increase analysis.linearization.max_iterations, lower relaxation, or set "
            "allow_unconverged to get a flagged result")
    # Step 5: the at-rest (quasi-static) σ are a guess, not an iterate: their response
    # starts the iteration unmixed (one iteration fewer than relaxing toward the guess
    # on the chain, taut wire and 3-D benchmarks; same fixed point).  The coarse stage
    # replaces the guess by the subset's fixed point (same first full-grid step).
    x_start, stage = (_coarse_start(system, channels, inp, settings, progress, timing)
                      if coarse else (None, None))
    if x_start is None:
        x_start = _rest_sigmas(system, inp, method)
    x0 = update(x_start)
    change0 = state["change"]
    if not np.all(np.isfinite(x0)):
        raise ConvergenceError(name, 1, float("nan"), lin.tolerance,
                               hint="the first response gave non-finite σ")
    if change0 <= lin.tolerance or lin.max_iterations == 1:
        fp = FixedPointResult(x0, 1, change0, change0 <= lin.tolerance, (change0,))
        if not fp.converged and not lin.allow_unconverged:
            raise ConvergenceError(name, 1, change0, lin.tolerance, hint=hint, partial=fp)
    else:
        try:
            fp = fixed_point(
                update, x0, tol=lin.tolerance, max_iterations=lin.max_iterations - 1,
                relaxation=lin.relaxation,
                method="anderson" if lin.acceleration == "anderson" else "relaxed",
                mixing=ANDERSON_MIXING, allow_unconverged=lin.allow_unconverged,
                name=name,
            )
        except ConvergenceError as exc:
            partial = exc.partial
            if isinstance(partial, FixedPointResult):
                partial = FixedPointResult(partial.x, partial.iterations + 1,
                                           partial.relative_change, False,
                                           (change0,) + partial.history)
            raise ConvergenceError(name, exc.iterations + 1, exc.residual, exc.tolerance,
                                   hint=hint, partial=partial) from None
        fp = FixedPointResult(fp.x, fp.iterations + 1, fp.relative_change, fp.converged,
                              (change0,) + fp.history)
    if not fp.converged:
        warn(
            f"{name} did not converge: relative change {fp.relative_change:.3e} after "
            f"{fp.iterations} iterations (tolerance {lin.tolerance:.1e}); the result is "
            "flagged unconverged (increase analysis.linearization.max_iterations)",
            PhysicsWarning, stacklevel=2,
        )
    damping = cache["damping"]
    t0 = time.perf_counter()
    # transfer functions of the recorded drag: the last update() solved with it
    u_f, c = cache["solved"]
    resp = _response(system, inp, damping, (_total(system, inp, u_f), c))
    if timing is not None:
        timing["solve_s"] = timing.get("solve_s", 0.0) + time.perf_counter() - t0
    record = linearization_record(system, cache["sigma"], damping, fp, lin.tolerance, method)
    return Linearization(damping=damping, record=record, response=resp, coarse=stage)


def linearization_record(system: LineSystem, sigma: np.ndarray, damping: Damping, fp: Any,
                         tolerance: float, method: str) -> LinearizationRecord:
    """The record of a converged (or flagged) drag fixed point of one line: the
    iteration history of ``fp`` (a FixedPointResult), the final σ (the
    :func:`drag_coefficients` layout) split into normal and axial, and the linear
    drag (the vector form reports σ_n = |σ| and b_n = trace/2 of its 2×2 blocks)."""
    parts = _split_sigma(system, sigma, method)
    if method == "vector":
        sig_n = np.sqrt(parts["normal"][0] ** 2 + parts["normal"][1] ** 2)
        b_n = 0.5 * np.trace(damping.b_normal, axis1=1, axis2=2)
    else:
        sig_n, b_n = parts["normal"][0], damping.b_normal
    return LinearizationRecord(
        method=method, converged=fp.converged, iterations=fp.iterations,
        relative_change=fp.relative_change, history=fp.history, tolerance=tolerance,
        sigma_normal=sig_n, sigma_axial=parts["axial"], b_normal=b_n,
        b_axial=damping.b_axial,
    )


# ------------------------------------------------------------------------- outputs


def element_tension_transfer(system: LineSystem, response: Response) -> np.ndarray:
    """Dynamic effective tension per element, (n_ch, n_el, n_omega). [N/unit]

    δT = (EA/l0)·e·(u_{j+1} − u_j) (module docstring), EA reduced for slack elements.
    """
    from stochcable.line.fem import SLACK_EA_RATIO

    model = system.model
    mesh = model.mesh
    n_w = response.omega.size
    u = response.displacement.reshape(n_w, model.n_nodes, model.dim, -1)
    # e·(u_b − u_a) one component at a time, frequencies last (long inner loops; the
    # complex einsum was 0.4 ms on the chain, the frequency-major layout 0.25)
    u = np.ascontiguousarray(np.transpose(u, (3, 1, 2, 0)))  # (n_ch, n_nodes, dim, n_w)
    t = model.tangents
    out = t[None, :, 0, None] * (u[:, 1:, 0] - u[:, :-1, 0])  # (n_ch, n_el, n_w)
    for k in range(1, model.dim):
        out += t[None, :, k, None] * (u[:, 1:, k] - u[:, :-1, k])
    ea = np.where(model.slack, SLACK_EA_RATIO * mesh.ea, mesh.ea)
    out *= (ea / model.l0)[None, :, None]
    return out


def _modal_bandwidths(system: LineSystem, damping: Damping) -> np.ndarray:
    """φ_jᵀCφ_j of every computed mode (mass-normalized φ; C = structural damping +
    ``damping``): the half-power bandwidth 2ζ_jω_j, (n_modes,), cached on the damping
    (the resolution check and the indicators both use it). [rad/s]"""
    if "modal_band" not in damping._cache:
        prep = _prep(system)
        c = _add(prep.S, _drag_blocks(system, damping))
        phi = np.ascontiguousarray(system.modes.shapes[system.model.free])
        damping._cache["modal_band"] = np.einsum(
            "ij,ij->j", phi, prep._free_rows(_matvec(c, prep._nodes(phi))))
    return damping._cache["modal_band"]


def _nearest_spacing(omega: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distance of each x (inside the increasing grid) to its nearest grid point and
    the local spacing there, ``np.gradient(omega)`` at that point (central difference
    inside, one-sided at the ends; the same bits), without the (n_x, n_omega) argmin
    matrix: the nearest point is one of the two around the insertion point (the lower
    of two equidistant ones, as argmin). [rad/s]"""
    n = omega.size
    hi = np.searchsorted(omega, x)
    lo = np.maximum(hi - 1, 0)
    d_lo, d_hi = np.abs(omega[lo] - x), np.abs(omega[hi] - x)
    near = np.where(d_lo <= d_hi, lo, hi)
    a, b = np.maximum(near - 1, 0), np.minimum(near + 1, n - 1)
    spacing = (omega[b] - omega[a]) / np.where((near > 0) & (near < n - 1), 2.0, 1.0)
    return np.minimum(d_lo, d_hi), spacing


def _resolution_check(system: LineSystem, damping: Damping, omega: np.ndarray) -> None:
    """ResolutionWarning for natural frequencies inside the grid that the grid cannot
    resolve: nearest grid point farther than the local spacing, or a half-power
    bandwidth (2ζω_j ≈ φ_jᵀCφ_j for mass-normalized φ) narrower than the local spacing."""
    modes = system.modes
    wn = np.asarray(modes.omega)
    inside = np.flatnonzero((wn >= omega[0]) & (wn <= omega[-1]))
    if inside.size == 0 or omega.size < 2:
        return
    band = _modal_bandwidths(system, damping)[inside]
    dist, spacing = _nearest_spacing(omega, wn[inside])
    flagged = (dist > spacing) | (spacing > band)
    bad = [(j, wn[j], b, dw) for j, b, dw, f in zip(inside, band, spacing, flagged) if f]
    if not bad:
        return
    j, wj, b, dw = bad[0]
    width = omega[-1] - omega[0]
    need = int(math.ceil(width / max(b, 1e-12 * wj))) + 1 if b > 0 else None
    fix = (f"use analysis.omega.count >= {need} (or refine the grid around {wj:.4g} rad/s)"
           if need is not None and need < 10**7 else
           "the mode has no damping: add drag or seabed damping (no analysis.omega grid "
           "resolves an undamped peak)")
    more = f" and {len(bad) - 1} more mode(s)" if len(bad) > 1 else ""
    warn(
        f"line '{system.name}': the frequency grid (spacing {dw:.3g} rad/s near "
        f"{wj:.4g} rad/s) does not resolve mode {j + 1} at {wj:.4g} rad/s, whose "
        f"half-power bandwidth is {b:.3g} rad/s{more}; the resonance peak may be missed: "
        f"{fix}",
        ResolutionWarning, stacklevel=3,
    )


#: Largest ratio of the wave-velocity σ at the two ends of an element's wet part before
#: :func:`_surface_resolution_check` warns.  The drag linearization takes one B ∝ σ per
#: element (seed 001 eq. 5.2.2) while σ decays like e^{k̄z} from the surface; on the
#: inclined guy (docs/ACCURACY.md) the ratio of its top element is 2.18 / 1.59 / 1.32 /
#: 1.17 at 40 / 80 / 160 / 320 elements, and the fairlead tension σ is off its
#: 320-element value by +8.6 / +2.9 / +0.46 % (with uniform B the 40-element value is
#: within 0.7 %: the loads themselves are exact).
SURFACE_SIGMA_RATIO = 2.0
#: Ratio the warning's fix aims at (≈ 3 % on the guy's fairlead tension σ).
SURFACE_TARGET_RATIO = 1.5
#: Elements whose larger end σ is below this fraction of the line's largest are not
#: checked (their drag hardly loads the line).
SURFACE_MATTERS_FRACTION = 0.25


def _surface_resolution_check(system: LineSystem, channels: tuple[Channel, ...],
                              omega: np.ndarray, q: np.ndarray | None = None) -> None:
    """ResolutionWarning when the wave-velocity σ varies by more than
    ``SURFACE_SIGMA_RATIO`` along an element that matters (larger end σ at least
    ``SURFACE_MATTERS_FRACTION`` of the line's largest): one drag coefficient per element
    cannot follow it (the wave loads are integrated exactly; the linearized B is not).
    ``q``: the trapezoid weights of ``omega`` when the caller has them."""
    if q is None:
        q = _trapezoid_weights(omega)
    var = None
    for ch in channels:
        if ch.element_end_square is None or not np.any(ch.spectrum > 0):
            continue
        v_ = np.einsum("wes,w->es", ch.element_end_square, q * ch.spectrum)
        var = v_ if var is None else var + v_
    if var is None:
        return
    sig = np.sqrt(np.clip(var, 0.0, None))
    hi, lo = sig.max(axis=1), sig.min(axis=1)
    top = float(hi.max())
    if top <= 0.0:
        return
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(lo > 0, hi / np.where(lo > 0, lo, 1.0), np.inf)
    bad = (hi >= SURFACE_MATTERS_FRACTION * top) & (ratio > SURFACE_SIGMA_RATIO)
    if not bad.any():
        return
    j = int(np.argmax(np.where(bad, ratio, 0.0)))
    r = float(ratio[j])
    mesh = system.model.mesh
    seg = int(mesh.segment[j])
    n_seg = int(np.count_nonzero(mesh.segment == seg))
    pos = system.positions
    units = unit_labels(system.environment.g)
    za, zb = float(min(pos[j, 2], 0.0)), float(min(pos[j + 1, 2], 0.0))
    dz = abs(zb - za)
    shrink = math.log(SURFACE_TARGET_RATIO) / math.log(r) if math.isfinite(r) else 0.0
    need = (f"at least {int(math.ceil(n_seg / shrink))} elements on segment {seg} "
            f"(now {n_seg})" if shrink > 0 else "more elements")
    more = int(np.count_nonzero(bad)) - 1
    others = f" ({more} more element(s) likewise)" if more > 0 else ""
    warn(
        f"line '{system.name}': the wave-velocity σ varies by a factor {r:.3g} along "
        f"element {j + 1} (z from {za:.4g} to {zb:.4g} {units.length}; threshold "
        f"{SURFACE_SIGMA_RATIO:g}){others}, but the drag linearization takes one drag "
        "coefficient per element (seed 001 eq. 5.2.2): the element is long against the "
        "decay depth of the wave kinematics and the response there carries an error of "
        f"several %; use {need}, or elements spanning at most {dz * shrink:.3g} "
        f"{units.length} of depth near the surface",
        ResolutionWarning, stacklevel=3,
    )


# Fraction of m0 that S(ω_max)·ω_max may reach before the grid is said to cut the
# response spectrum (an ω⁻⁵ tail beyond ω_max holds S·ω/4 of it).
TAIL_FRACTION = 0.05


def _tail_check(line: str, end: str, w: np.ndarray, dens: np.ndarray, m0: float) -> None:
    """ResolutionWarning when the end-tension spectrum is still large at ω_max."""
    if m0 <= 0.0:
        return
    ratio = float(dens[-1] * w[-1] / m0)
    if ratio > TAIL_FRACTION:
        warn(
            f"line '{line}': the {end} tension spectrum at the top of the grid "
            f"(omega.max = {w[-1]:.4g} rad/s) is still S·ω = {ratio:.2g} m0 "
            f"(threshold {TAIL_FRACTION:g}): the grid cuts the response and σ is "
            "underestimated; raise analysis.omega.max (end motion spectra with an ω⁻⁵ "
            "tail drive inertia loads whose spectrum decays only like ω⁻¹)",
            ResolutionWarning, stacklevel=3,
        )


def _listed_modes(omega_n: np.ndarray, w_top: float) -> int:
    """How many natural frequencies the document lists: those up to
    2.5·ω_max, at least min(10, available)."""
    wn = np.asarray(omega_n)
    return int(max(np.count_nonzero(wn <= 2.5 * w_top), min(10, wn.size)))


# ------------------------------------------------------------------ quality indicators

#: Snap flag: mean − SNAP_SIGMAS·σ of the tension below zero at an element or end.
SNAP_SIGMAS = 3.0
#: Resonance flag: modal damping ratio below this inside the excitation band.
RESONANCE_DAMPING_RATIO = 0.01
#: The excitation band: where some input spectrum exceeds this fraction of its peak.
BAND_FRACTION = 0.01
#: Large-motion flag: node motion σ above this fraction of the line's sag.
MOTION_SAG_FRACTION = 0.1


def _normal_acceleration_sigma(system: LineSystem, channels: tuple[Channel, ...],
                               omega: np.ndarray) -> np.ndarray:
    """σ of the fluid acceleration normal to each element, element mean square
    ω²(tr S − eᵀSe), S = ∫₀¹ Re(v vᴴ) dξ (:func:`element_mean_square`). [m/s²]"""
    e = system.frames[0]
    q = _trapezoid_weights(omega)
    n_el = system.model.n_elements
    var = np.zeros(n_el)
    # tr S − eᵀSe = Σ_ij S_ij (I − eeᵀ)_ij: one product over the 9 entries (the trace
    # and a three-operand einsum were 0.2 ms on the chain)
    proj = (np.eye(3)[None] - e[:, :, None] * e[:, None, :]).reshape(n_el, 9)
    for ch in channels:
        sq = element_mean_square(ch)
        if sq is None:
            continue
        dens = np.einsum("wek,ek->we", sq.reshape(sq.shape[0], n_el, 9), proj)
        var += np.clip(dens, 0.0, None).T @ (q * ch.spectrum * omega**2)
    return np.sqrt(var)


def _modal_damping_ratios(system: LineSystem, damping: Damping) -> np.ndarray:
    """ζ_j = φ_jᵀCφ_j/(2ω_j) of the computed modes (mass-normalized φ). [-]"""
    band = _modal_bandwidths(system, damping)
    wn = np.asarray(system.modes.omega)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(wn > 0, band / (2.0 * np.where(wn > 0, wn, 1.0)), np.inf)


def line_indicators(
    system: LineSystem,
    channels: tuple[Channel, ...],
    linearization: Linearization,
    tension_std: np.ndarray,
    motion_std: np.ndarray,
    end_stats: Mapping[str, Any],
) -> LineIndicators:
    """Quality indicators of the linear model of one line, with PhysicsWarnings.

    Parameters
    ----------
    system : LineSystem
    channels : tuple of Channel
        Inputs on the analysis grid (their spectra define the excitation band).
    linearization : Linearization
        The converged drag (its record's σ and B).
    tension_std : ndarray, shape (n_el,)
        σ of the dynamic element tension. [N]
    motion_std : ndarray, shape (n_nodes, 3)
        σ of the node motions. [m]
    end_stats : mapping {"end_a", "end_b"} of ResponseStats
        End-tension statistics (mean and std). [N]

    Returns
    -------
    LineIndicators

    Warns
    -----
    PhysicsWarning
        - snap: T_mean − 3σ_T < 0 at an element or end ("snap loads likely; the
          linear model is out of its depth");
        - resonance: a mode inside the excitation band (some input spectrum above
          1 % of its peak) with modal damping ratio ζ < 1 %, named;
        - large motion: a node motion σ above 10 % of the sag.

    Notes
    -----
    Borgman ratio per element: :func:`stochcable.dynamics.linearization.borgman_variance_ratio`
    of the normal relative velocity (σ_n of the record, mean = the normal current).
    Drag/inertia: :func:`stochcable.dynamics.linearization.drag_inertia_ratio` in the form
    B_n σ_n / (ρ C_M (πD²/4) σ_an), B_n the record's normal coefficient, σ_an the σ
    of the fluid acceleration normal to the element (the sea channel).
    Modal damping ζ_j = φ_jᵀCφ_j/(2ω_j) with C = drag + seabed + structural damping
    (the diagonal of the modal damping; the coupling terms are ignored).
    Large motion: the tangent model (seed 001 §3) is linear about the static shape;
    the geometric stiffness of a sagging line depends on its sag at first order
    (T ≈ wL²/8·1/sag for a shallow catenary), so a motion σ of 10 % of the sag (a
    3σ excursion of 30 %) changes the stiffness by about as much as a linear model
    can tolerate; the sag is the largest distance of the static shape from the
    chord.  The diameter ratio is reported, not flagged (large motion over D means
    drag-dominated loading, the domain of the drag linearization).
    """
    model = system.model
    mesh = model.mesh
    rec = linearization.record
    name = system.name
    flags: list[str] = []
    if "current_split" not in system._cache:  # as drag_coefficients: once per line
        e = system.frames[0]
        uc = system.current_el
        u_t = np.einsum("ij,ij->i", uc, e)
        u_nvec = uc - u_t[:, None] * e
        system._cache["current_split"] = (u_t, u_nvec, np.linalg.norm(u_nvec, axis=1))
    u_n = system._cache["current_split"][2]
    borgman = np.atleast_1d(borgman_variance_ratio(rec.sigma_normal, u_n))
    w = linearization.response.omega
    s_an = _normal_acceleration_sigma(system, channels, w)
    drag_sigma = rec.b_normal * rec.sigma_normal
    inertia_sigma = (model.rho * (1.0 + mesh.ca_normal) * math.pi * mesh.diameter**2 / 4.0
                     * s_an)
    with np.errstate(divide="ignore", invalid="ignore"):
        d_i = np.where(inertia_sigma > 0, drag_sigma / np.where(inertia_sigma > 0,
                                                                 inertia_sigma, 1.0),
                       np.where(drag_sigma > 0, np.inf, 0.0))
    # snap
    st = system.statics
    t_mean = np.asarray(st.tension, dtype=float)
    means = np.concatenate([t_mean, [end_stats["end_a"].mean, end_stats["end_b"].mean]])
    sigmas = np.concatenate([tension_std, [end_stats["end_a"].std, end_stats["end_b"].std]])
    low = means - SNAP_SIGMAS * sigmas
    with np.errstate(divide="ignore", invalid="ignore"):
        margins = np.where(np.abs(means) > 0, low / np.abs(np.where(means != 0, means, 1.0)),
                           np.where(low < 0, -np.inf, 0.0))
    k = int(np.argmin(margins))
    snap_margin = float(margins[k])
    snap = bool(np.any(low < 0))
    units = unit_labels(system.environment.g)
    if snap:
        flags.append("snap")
        where = ("end_a" if k == t_mean.size else "end_b" if k == t_mean.size + 1
                 else f"element {k + 1} (s = {0.5 * (mesh.s0[k] + mesh.s0[k + 1]):.4g} "
                      f"{units.length})")
        warn(
            f"line '{name}': the dynamic tension σ ({sigmas[k]:.4g} {units.force} at "
            f"{where}) exceeds 1/{SNAP_SIGMAS:g} of the mean tension ({means[k]:.4g} "
            f"{units.force}): mean − {SNAP_SIGMAS:g}σ < 0, snap loads likely; the linear "
            "model is out of its depth (threshold mean − 3σ >= 0): use a nonlinear "
            "time-domain analysis "
            "(stochcable.reference.cable) or increase the pretension",
            PhysicsWarning, stacklevel=3,
        )
    # near-undamped resonance inside the excitation band
    resonances: list[dict[str, Any]] = []
    wn = np.asarray(system.modes.omega)
    spectra = [c.spectrum for c in channels if np.any(c.spectrum > 0)]
    if spectra and wn.size:
        inside = np.zeros(wn.size, dtype=bool)
        for spec in spectra:
            in_band = np.interp(wn, w, spec, left=0.0, right=0.0) >= BAND_FRACTION * spec.max()
            inside |= in_band
        zeta = _modal_damping_ratios(system, linearization.damping)
        for j in np.flatnonzero(inside & (zeta < RESONANCE_DAMPING_RATIO)):
            resonances.append({"mode": int(j + 1), "omega": float(wn[j]),
                               "damping_ratio": float(zeta[j])})
    if resonances:
        flags.append("resonance")
        r0 = resonances[0]
        more = f" and {len(resonances) - 1} more" if len(resonances) > 1 else ""
        warn(
            f"line '{name}': mode {r0['mode']} ({r0['omega']:.4g} rad/s){more} lies in the "
            f"excitation band with modal damping ratio {r0['damping_ratio']:.2%} "
            f"(threshold {RESONANCE_DAMPING_RATIO:.0%}): a near-undamped resonance whose "
            "response is set by damping the model may not represent; check the drag "
            "coefficients and add structural damping (analysis.structural_damping) or "
            "seabed damping where physical",
            PhysicsWarning, stacklevel=3,
        )
    # large motions
    if "sag" not in system._cache:  # of the static shape: once per line
        pos = model.positions
        chord = pos[-1] - pos[0]
        cn = float(np.linalg.norm(chord))
        rel = pos - pos[0]
        if cn > 0:
            rel = rel - np.outer(rel @ (chord / cn), chord / cn)
        system._cache["sag"] = float(np.max(np.linalg.norm(rel, axis=1)))
    sag = system._cache["sag"]
    m_std = np.linalg.norm(motion_std, axis=1)
    m_max = float(m_std.max()) if m_std.size else 0.0
    to_sag = m_max / sag if sag > 0 else (np.inf if m_max > 0 else 0.0)
    to_d = m_max / float(np.max(mesh.diameter))
    if to_sag > MOTION_SAG_FRACTION:
        flags.append("large_motion")
        j = int(np.argmax(m_std))
        warn(
            f"line '{name}': the motion σ at node {j + 1} ({m_max:.3g} {units.length}) "
            f"is {to_sag:.2g} of the line's sag ({sag:.3g} {units.length}), above the "
            f"threshold {MOTION_SAG_FRACTION:g}: the linearization about the static shape is "
            "doubtful; check with a nonlinear time-domain analysis "
            "(stochcable.reference.cable)",
            PhysicsWarning, stacklevel=3,
        )
    return LineIndicators(
        borgman_ratio=borgman, drag_inertia_ratio=d_i, snap_margin=snap_margin,
        snap_risk=snap, resonances=tuple(resonances), motion_std_max=m_max, sag=sag,
        motion_to_sag=float(to_sag), motion_to_diameter=to_d, flags=tuple(flags),
    )


def line_result(
    system: LineSystem,
    channels: tuple[Channel, ...],
    linearization: Linearization,
    settings: AnalysisSettings,
) -> LineResult:
    """Transfer functions, spectra and statistics of one line.

    Parameters
    ----------
    system : LineSystem
    channels : tuple of Channel
    linearization : Linearization
        Its ``response`` is used.
    settings : AnalysisSettings
        ``duration`` for the maxima.

    Returns
    -------
    LineResult
    """
    model = system.model
    resp = linearization.response
    w = resp.omega
    n_ch = len(channels)
    spectra = np.stack([c.spectrum for c in channels]) if n_ch else np.zeros((0, w.size))
    # (n_ch, n_nodes, 3, n_w) built in its own layout (embedding in the frequency-major
    # layout and transposing made every later pass strided)
    u_h = np.transpose(resp.displacement.reshape(w.size, model.n_nodes, model.dim, n_ch),
                       (3, 1, 2, 0))
    if tuple(model.components) == (0, 1, 2):  # 3-D: no zero components to embed
        motion_h = np.ascontiguousarray(u_h)
    else:
        motion_h = np.zeros((n_ch, model.n_nodes, 3, w.size), dtype=resp.displacement.dtype)
        motion_h[:, :, list(model.components)] = u_h
    tension_h = element_tension_transfer(system, resp)
    # σ² = Σ_c ∫|H_c|² S_c dω as one weighted reduction with the trapezoid weights q
    # (the response spectra are not kept; the same trapezoid rule as np.trapezoid up
    # to round-off, ≈ 0.1 ms a line less than the spectra and two trapezoids)
    q = _trapezoid_weights(w)
    sq = spectra * q
    tension_std = np.sqrt(np.einsum("cew,cw->e", np.abs(tension_h) ** 2, sq))
    motion_std = np.sqrt(np.einsum("cnkw,cw->nk", np.abs(motion_h) ** 2, sq))
    st = system.statics
    s0 = model.mesh.s0
    stats = {}
    for end, mean in (("end_a", st.tension_a), ("end_b", st.tension_b)):
        dens = np.einsum("cw,cw->w", np.abs(resp.end_tension[end]) ** 2, spectra)
        stats[end] = _stats_from_validated(w, dens, float(mean), settings.duration)
        _tail_check(system.name, end, w, dens, stats[end].m0)
    if np.any(spectra > 0):  # nothing to resolve without excitation
        _resolution_check(system, linearization.damping, w)
        _surface_resolution_check(system, channels, w, q)
    indicators = (None if linearization.record is None else
                  line_indicators(system, channels, linearization, tension_std, motion_std,
                                  stats))
    comps = list(model.components)
    d = model.dim
    end_force = {}
    for k, end in enumerate(("end_a", "end_b")):
        f = np.zeros((n_ch, 3, w.size), dtype=complex)
        f[:, comps, :] = np.transpose(resp.support_force[:, k * d:(k + 1) * d, :], (2, 1, 0))
        end_force[end] = f
    return LineResult(
        name=system.name,
        omega=w,
        channels=tuple(c.name for c in channels),
        input_spectra=spectra,
        s_nodes=s0.copy(),
        s_elements=0.5 * (s0[1:] + s0[:-1]),
        positions=model.positions.copy(),
        motion_transfer=motion_h,
        tension_transfer=tension_h,
        end_tension_transfer=dict(resp.end_tension),
        end_force_transfer=end_force,
        tension_mean=np.asarray(st.tension, dtype=float).copy(),
        tension_std=tension_std,
        motion_std=motion_std,
        end_a=stats["end_a"],
        end_b=stats["end_b"],
        linearization=linearization.record,
        modes_omega=np.asarray(system.modes.omega).copy(),
        modes_listed=_listed_modes(system.modes.omega, float(w[-1])),
        n_modes=system.n_modes if system.solver == "foss" else None,
        statics=st,
        model=model,
        modes=system.modes,
        indicators=indicators,
    )


# ---------------------------------------------------------------------- time series


def simulate_timeseries(
    scene: Scene,
    systems: Mapping[str, LineSystem],
    dampings: Mapping[str, Damping],
    settings: TimeSeriesSettings,
    *,
    coupled: tuple[Any, ...] = (),
    timing: dict[str, float] | None = None,
) -> TimeSeries:
    """One realization of every input channel and the end-tension and body-motion
    time series.

    Parameters
    ----------
    scene : Scene
    systems : mapping of LineSystem by line name
        The independent lines (not attached to a free body).
    dampings : mapping of Damping by line name
        The converged linear drag of each of them.
    settings : TimeSeriesSettings
        method (dsa/nsa), duration, dt, seed.
    coupled : tuple of CoupledGroup, optional
        The converged coupled groups of a scene with bodies
        (:attr:`stochcable.dynamics.coupled.CoupledAnalysis.groups`): their lines' end
        tensions and their free bodies' motions are synthesized too.
    timing : dict, optional
        Accumulates ``solve_s``.

    Returns
    -------
    TimeSeries

    Notes
    -----
    The sea: :func:`stochcable.sea.realization.simulate_sea` with ``rng=seed`` (so η is the
    realization a stand-alone simulation with that seed gives).  End-motion spectrum
    channels, in the order of the scene's lines (independent and coupled alike) ×
    (end_a, end_b) × (surge, sway, heave), use the independent generators
    ``np.random.default_rng(c)`` for ``c in np.random.SeedSequence(seed).spawn(n)``.
    Responses are :func:`stochcable.sea.realization.synthesize` of the transfer functions solved
    on the realization grid ω_m = mΔω, restricted to the analysis band
    [omega.min, omega.max] (zero outside, as the response spectra are), so η, end
    motions, tensions and body motions of one realization are mutually consistent
    (seed 001 §5.1, eq. 5.3.29 and step 14).  Independent lines: :func:`solve` with
    their converged drag; an end on a vessel moves with the vessel RAO in the sea
    channel.  Coupled groups: the group's linear system at its converged drag
    (lines' Damping, bodies' drag σ) solved on the band
    (:func:`stochcable.dynamics.coupled_timeseries.coupled_group_transfer`).  Vessels: their
    RAO times the sea.  The band is solved in chunks of frequencies, so only the
    end tensions and body motions of the whole band are held
    (:mod:`stochcable.dynamics.coupled_timeseries`, "Memory").
    """
    from stochcable.dynamics.coupled import _scene_line_channels
    from stochcable.dynamics.coupled_timeseries import (
        CHUNK_BYTES,
        coupled_group_transfer,
        frequency_chunks,
        line_entry_bytes,
        vessel_raos,
    )

    seed = int(settings.seed)
    omega_r, _ = frequency_grid(settings.duration, settings.dt)
    grid = scene.analysis.omega
    band = np.flatnonzero((omega_r >= grid.min) & (omega_r <= grid.max) & (omega_r > 0))
    w_band = omega_r[band]
    env = scene.environment
    sea_real = None
    if scene.sea is not None:
        spec = scene.sea.spectrum

        def sea_density(w: np.ndarray) -> np.ndarray:
            w = np.asarray(w, dtype=float)
            out = np.zeros_like(w)
            out[w > 0] = spec.spectral_density(w[w > 0], env.g)
            return out

        sea_real = simulate_sea(sea_density, settings.duration, settings.dt,
                                settings.method, rng=seed)
    groups = tuple(coupled)
    all_systems = dict(systems)
    for grp in groups:
        all_systems.update(grp.systems)
    scene_order = [ln.name for ln in scene.lines if ln.name in all_systems]
    names = scene_order + [n for n in all_systems if n not in scene_order]

    def channels_on(name: str, w: np.ndarray) -> tuple[Channel, ...]:
        """The line's channels on w (an end on a vessel moves in the sea channel)."""
        system = all_systems[name]
        ch, _ = _scene_line_channels(scene, system.line, system, w, vessel_raos(scene, w))
        return ch

    # channel names and densities of every line (scene order) from one frequency
    probe = {n: channels_on(n, w_band[:1]) if band.size else () for n in names}
    motion_keys = [(name, ch.name) for name, chs in probe.items() for ch in chs
                   if ch.kind == "end_motion"]
    children = np.random.SeedSequence(seed).spawn(len(motion_keys)) if motion_keys else []
    reals: dict[tuple[str, str], Any] = {}
    for (name, cname), child in zip(motion_keys, children):
        ch = next(c for c in probe[name] if c.name == cname)
        reals[(name, cname)] = simulate_sea(ch.density, settings.duration, settings.dt,
                                            settings.method, rng=np.random.default_rng(child))
    end_motion = {f"{name}.{cname}": np.asarray(r.elevation) for (name, cname), r in reals.items()}
    n_t = int(round(settings.duration / settings.dt))

    def full(h: np.ndarray) -> np.ndarray:
        """Band values (..., n_band) -> the realization grid (..., N+1), zero outside."""
        out = np.zeros(h.shape[:-1] + (omega_r.size,), dtype=complex)
        out[..., band] = h
        return out

    def synthesized(h: np.ndarray, kinds: tuple[str, ...],
                    sources: tuple[tuple[str, str] | None, ...]) -> np.ndarray:
        """Σ over channels of synthesize(realization, H), H (n_ch, ..., N+1)."""
        y = np.zeros(h.shape[1:-1] + (n_t,))
        for i, (kind, src) in enumerate(zip(kinds, sources)):
            real = sea_real if kind == "sea" else reals.get(src) if src else None
            if real is not None:
                y += synthesize(real, h[i])
        return y

    end_tension: dict[str, dict[str, np.ndarray]] = {}
    transfer: dict[str, dict[str, np.ndarray]] = {}
    chan_names: dict[str, tuple[str, ...]] = {}
    for name, system in systems.items():
        chs = probe.get(name, ())
        tr = {}
        if chs:
            n_ch = len(chs)
            h = {e: np.zeros((n_ch, band.size), dtype=complex) for e in ("end_a", "end_b")}
            entry = line_entry_bytes(system.model, n_ch)
            for sl in frequency_chunks(band.size, entry, CHUNK_BYTES):
                resp = solve(system, channels_on(name, w_band[sl]), dampings[name], timing)
                for e in h:
                    h[e][:, sl] = resp.end_tension[e]
            tr = {e: full(v) for e, v in h.items()}
        kinds = tuple(c.kind for c in chs)
        src = tuple((name, c.name) for c in chs)
        st = system.statics
        end_tension[name] = {
            e: float(t) + (synthesized(tr[e], kinds, src) if tr else 0.0) + np.zeros(n_t)
            for e, t in (("end_a", st.tension_a), ("end_b", st.tension_b))}
        transfer[name] = tr
        chan_names[name] = tuple(c.name for c in chs)
    body_motion: dict[str, dict[str, np.ndarray]] = {}
    body_transfer: dict[str, np.ndarray] = {}
    body_channels: dict[str, tuple[str, ...]] = {}
    for grp in groups:
        gt = coupled_group_transfer(scene, grp, w_band, timing=timing) if band.size else None
        for name in grp.lines:
            st = grp.systems[name].statics
            tr = {} if gt is None else {e: full(v) for e, v in gt.end_tension[name].items()}
            end_tension[name] = {
                e: float(t) + (synthesized(tr[e], gt.kinds, gt.sources) if tr else 0.0)
                + np.zeros(n_t) for e, t in (("end_a", st.tension_a), ("end_b", st.tension_b))}
            transfer[name] = tr
            chan_names[name] = () if gt is None else gt.channels
        for b in grp.bodies:
            mean = grp.pose[b.name]
            h = (np.zeros((0, b.n_dof, omega_r.size), dtype=complex) if gt is None
                 else full(gt.body_motion[b.name]))
            y = (synthesized(h, gt.kinds, gt.sources) if gt is not None
                 else np.zeros((b.n_dof, n_t)))
            body_motion[b.name] = {k: float(mean[i]) + y[i] for i, k in enumerate(b.dof_names)}
            body_transfer[b.name] = h
            body_channels[b.name] = () if gt is None else gt.channels
    vessels = [b for b in (getattr(scene, "bodies", ()) or ())
               if getattr(b, "prescribed", None) is not None]
    for b in vessels:
        if sea_real is None:
            continue
        h = full(vessel_raos(scene, w_band)[b.name].T)[None]      # (1, 6, N+1)
        y = synthesized(h, ("sea",), (None,))
        mean = np.concatenate([np.asarray(b.position, dtype=float), np.zeros(3)])
        body_motion[b.name] = {k: float(mean[i]) + y[i] for i, k in enumerate(
            ("surge", "sway", "heave", "roll", "pitch", "yaw"))}
        body_transfer[b.name] = h
        body_channels[b.name] = ("sea",)
    order = [n for n in names if n in end_tension]
    body_order = [b.name for b in (getattr(scene, "bodies", ()) or ()) if b.name in body_motion]
    time_axis = (np.asarray(sea_real.time) if sea_real is not None
                 else (settings.duration / n_t) * np.arange(n_t))
    return TimeSeries(
        time=time_axis, method=settings.method, seed=seed,
        elevation=None if sea_real is None else np.asarray(sea_real.elevation),
        end_motion=end_motion, end_tension={n: end_tension[n] for n in order},
        omega=omega_r, channels={n: chan_names[n] for n in order},
        end_tension_transfer={n: transfer[n] for n in order},
        body_motion={n: body_motion[n] for n in body_order},
        body_channels={n: body_channels[n] for n in body_order},
        body_motion_transfer={n: body_transfer[n] for n in body_order},
    )


# ------------------------------------------------------------------------ analyze


def analyze(
    scene: Scene | Mapping[str, Any] | str,
    *,
    statics: StaticsResult | None = None,
    progress: Progress | None = None,
) -> Result:
    """Stochastic response of every line of a scene (seed 001 ch. 5).

    Parameters
    ----------
    scene : Scene, mapping, JSON string or path
        The scene document (validated by :func:`stochcable.scene.model.load_scene`).
    statics : StaticsResult, optional
        A precomputed static equilibrium (default: :func:`solve_statics`).
    progress : callable, optional
        ``progress(stage, info)`` (see :data:`Progress`).

    Returns
    -------
    Result
        Statics, modes, linearization record, transfer functions, spectra,
        statistics, time series, timing and warnings.

    Raises
    ------
    InputError
        Invalid scene.
    ConvergenceError
        Statics or drag linearization did not converge (unless
        ``analysis.linearization.allow_unconverged``, which returns a flagged result).
    SolverError
        An undamped resonance on the frequency grid.

    Notes
    -----
    Pipeline: statics (all nonlinearities) -> FE model about the static shape (2-D
    when ``scene.is_planar``) -> modes -> input channels
    (:mod:`stochcable.dynamics.loads`) -> drag linearization (:func:`linearize`) ->
    response (direct or Foss, :func:`solve`) -> spectra S_x = Σ_i |H_{x,i}|² S_i and
    statistics -> time series.
    """
    t_start = time.perf_counter()
    scene = load_scene(scene)
    progress = _noop if progress is None else progress
    plan = None
    if scene.analysis.fidelity is not None:
        # model only what the scene needs: choose elements, grid, modes, tolerance
        from stochcable.fidelity.planner import apply_fidelity, choose_fidelity

        progress("fidelity", {})
        target = scene.analysis.fidelity.target_error
        # the planner runs pilot analyses of the scene: without the request itself
        base = scene.model_copy(update={
            "analysis": scene.analysis.model_copy(update={"fidelity": None})})
        # exact_wave_integration stays False: its element rule alone can leave a
        # short line with a single element (no free node); the surface rule is
        # conservative with the exact loads (see the closing note of issue 7)
        plan = choose_fidelity(base, target)
        scene = apply_fidelity(base, plan)
        statics = None  # the mesh changed
    settings = scene.analysis
    timing: dict[str, float] = {"statics_s": 0.0, "model_s": 0.0, "linearization_s": 0.0,
                                "solve_s": 0.0, "outputs_s": 0.0, "timeseries_s": 0.0}
    omega = settings.omega.values()
    if settings.linearization.method == "harmonic" and any(
            p.speed > 0 for p in scene.environment.current):
        raise InputError("analysis.linearization.method", "harmonic", "-",
                         "the harmonic (regular-wave) form has no current term: use "
                         "'seed' or 'vector' with a current")
    # Warnings are issued as they arise and also recorded for the result document by
    # a thread-local collector (warnings.catch_warnings is process-global before
    # Python 3.14, so concurrent analyses in service threads would swap them).
    with collect_warnings() as caught, runtime.analysis_blas(_is_small(scene)):
        progress("statics", {})
        t0 = time.perf_counter()
        if statics is None:
            # the FE equilibrium, not the closed-form catenary: the dynamic model is
            # linearized about it, so it must be an equilibrium of the same FE model
            statics = solve_statics(scene, method="fe")
        timing["statics_s"] = time.perf_counter() - t0
        systems: dict[str, LineSystem] = {}
        lines: dict[str, LineResult] = {}
        dampings: dict[str, Damping] = {}
        bodies: dict[str, Any] = {}
        if scene.bodies:
            # lines attached to bodies are solved together with them (issue 6)
            from stochcable.dynamics.coupled import analyze_coupled

            coupled = analyze_coupled(scene, statics, settings, progress, timing)
            lines, bodies, systems, dampings = coupled
        for line in (() if scene.bodies else scene.lines):
            progress("model", {"line": line.name})
            t0 = time.perf_counter()
            system = build_line_system(scene, line, statics.lines[line.name], settings=settings)
            channels = line_channels(scene, line, system.positions, omega)
            timing["model_s"] += time.perf_counter() - t0
            systems[line.name] = system
            if not channels:
                warn(
                    f"line '{line.name}' has no excitation (no sea and no end motion): its "
                    "dynamic response is zero; add a 'sea' or an end 'motion'",
                    PhysicsWarning, stacklevel=2,
                )
                channels = _silent_channel(omega)
            progress("linearization", {"line": line.name, "iteration": 0})
            t0 = time.perf_counter()
            lin = linearize(system, channels, settings, progress=progress, timing=timing)
            timing["linearization_s"] += time.perf_counter() - t0
            dampings[line.name] = lin.damping
            progress("outputs", {"line": line.name})
            t0 = time.perf_counter()
            lines[line.name] = line_result(system, channels, lin, settings)
            timing["outputs_s"] += time.perf_counter() - t0
        ts = None
        if settings.timeseries is not None:
            progress("timeseries", {})
            t0 = time.perf_counter()
            ts = simulate_timeseries(scene, systems, dampings, settings.timeseries,
                                     coupled=coupled.groups if scene.bodies else (),
                                     timing=timing)
            timing["timeseries_s"] = time.perf_counter() - t0
    messages: list[str] = []
    for w in caught:
        if str(w) not in messages:
            messages.append(str(w))
    timing["total_s"] = time.perf_counter() - t_start
    progress("done", {"total_s": timing["total_s"]})
    if plan is not None and not plan.tail_bounded:
        text = ("adaptive fidelity could not bound the response tail above "
                f"{plan.omega_max:.3g} rad/s: the target error is not guaranteed (an input "
                "spectrum with a slowly decaying tail, e.g. an end-motion spectrum without "
                "a vessel RAO, drives tension up to high frequency)")
        warn(text, PhysicsWarning)
        messages.insert(0, text)
    return Result(scene=scene, statics=statics, lines=lines, timeseries=ts, timing=timing,
                  warnings=tuple(messages), fidelity=plan, bodies=bodies)


def _silent_channel(omega: np.ndarray) -> tuple[Channel, ...]:
    """A zero-spectrum channel so a line without excitation still gets (zero) outputs."""
    def zero(w: np.ndarray) -> np.ndarray:
        return np.zeros_like(np.asarray(w, dtype=float))

    return (Channel(name="none", kind="none", omega=omega, spectrum=zero(omega),
                    density=zero),)
