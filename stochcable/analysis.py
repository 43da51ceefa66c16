"""The analysis pipeline: scene -> statics -> FE model -> excitation -> drag
linearization -> solve -> results (seed 001 ch. 5, Tuah 1982).

:func:`analyze` runs the whole pipeline; each stage is a public function so that an
engineer can inspect or replace it::

    statics = solve_statics(scene)                        # stochcable.statics
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
- Drag and Morison inertia distributed like the model mass (consistent by default),
  element direction constant per element (:mod:`stochcable.excitation`).
- Relative velocities evaluated at element midpoints (mean of the two nodes).
- ``modes="auto"`` (Foss): all modes up to ``AUTO_ALL_MODES`` free DOFs, else those up
  to ``AUTO_MODE_FACTOR``·ω_max; moving ends use the quasi-static split (:func:`solve`).
- Time series: the first 2048 samples go in the document (``to_document(timeseries=
  "full")`` for all); the full series are on :class:`~stochcable.results.TimeSeries`.

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

import math
import time
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .errors import ConvergenceError, InputError, PhysicsWarning, ResolutionWarning
from .excitation import (
    Channel,
    channel_loads,
    current_at_elements,
    current_at_nodes,
    drag_matrix,
    element_frames,
    embed,
    inertia_matrix,
    line_channels,
    prescribed_motion,
)
from .fem import FEModel, build_fe_model
from .linearization import (
    drag_linear_current,
    drag_linear_harmonic,
    drag_linear_vector,
    fixed_point,
)
from .modes import Modes, natural_modes
from .results import (
    LinearizationRecord,
    LineResult,
    Result,
    TimeSeries,
    stats_from_spectrum,
)
from .scene import AnalysisSettings, Line, Scene, TimeSeriesSettings, load_scene
from .sea import frequency_grid, simulate_sea, synthesize
from .solvers import auto_mode_count, solve_direct, solve_modal
from .statics import LineStatics, StaticsResult, solve_statics

__all__ = [
    "Progress",
    "LineSystem",
    "Damping",
    "Linearization",
    "Response",
    "build_line_system",
    "drag_coefficients",
    "solve",
    "relative_velocity_sigmas",
    "linearize",
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
# DOFs (the Foss solve then equals the direct one; the 2n-state QZ costs < 0.2 s per
# linearization iteration), else the natural frequencies up to AUTO_MODE_FACTOR times
# the grid's top.  The factor is large because the static correction of the truncated
# modes ignores their drag coupling: on drag-dominated chains the end-tension σ with
# modes up to 2.5 ω_max was 5 % off, up to 10 ω_max still 4 % (tests/test_analysis.py,
# test_truncated_foss_converges_to_direct, 16-element chain); the direct solver is exact
# and, for these banded models, faster.
AUTO_ALL_MODES = 150
AUTO_MODE_FACTOR = 10.0
# First batch of modes computed when looking for the auto count (doubled as needed).
_MODE_BATCH = 40


def _noop(stage: str, info: Mapping[str, Any]) -> None:
    return None


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
        Morison inertia matrix (:func:`stochcable.excitation.inertia_matrix`). [kg]
    frames : tuple of ndarray
        Element tangent and normals (e, n1, n2), each (n_el, 3).
    current_el : ndarray, shape (n_el, 3)
        Current at element midpoints. [m/s]
    current_node : ndarray, shape (n_nodes, 3)
        Current at the nodes. [m/s]
    drag_nodes : ndarray of int
        Nodes with an attachment drag area.
    environment : Environment
    """

    line: Line
    statics: LineStatics
    model: FEModel
    modes: Modes
    n_modes: int
    solver: str
    b_inertia: sp.csr_array
    frames: tuple[np.ndarray, np.ndarray, np.ndarray]
    current_el: np.ndarray
    current_node: np.ndarray
    drag_nodes: np.ndarray
    environment: Any

    @property
    def name(self) -> str:
        return self.line.name

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
    matrix : scipy.sparse.csr_array
        Drag damping matrix C_d on all DOFs (without the seabed damping). [N·s/m]
    """

    method: str
    sigma: np.ndarray
    b_normal: np.ndarray
    b_axial: np.ndarray
    b_node: np.ndarray
    matrix: sp.csr_array


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


@dataclass(frozen=True, eq=False)
class Linearization:
    """Outcome of :func:`linearize`: the drag, its record and the last response."""

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
    return LineSystem(
        line=line,
        statics=line_statics,
        model=model,
        modes=modes,
        n_modes=n_modes,
        solver=settings.solver,
        b_inertia=inertia_matrix(model, env.g),
        frames=frames,
        current_el=current_at_elements(env, model.positions),
        current_node=current_at_nodes(env, model.positions),
        drag_nodes=np.flatnonzero(mesh.node_drag_area > 0),
        environment=env,
    )


# ------------------------------------------------------------------------- damping


def _split_sigma(system: LineSystem, x: np.ndarray, method: str) -> dict[str, np.ndarray]:
    n = system.model.n_elements
    k = 3 if method == "vector" else 1
    parts = {"normal": x[: k * n].reshape(k, n), "axial": x[k * n:(k + 1) * n],
             "node": x[(k + 1) * n:]}
    return parts


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
    uc = system.current_el
    u_t = np.einsum("ij,ij->i", uc, e)
    u_nvec = uc - u_t[:, None] * e
    u_n = np.linalg.norm(u_nvec, axis=1)
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
        b_n = drag_linear_current(rho, mesh.cd_normal, d, parts["normal"][0], u_n)
        b_t = drag_linear_current(rho, mesh.cd_axial, math.pi * d, parts["axial"], u_t)
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
        b_axial=b_t, b_node=b_node, matrix=drag_matrix(model, b_n, b_t, b_node),
    )


# --------------------------------------------------------------------------- solve


def _rows_times(a: Any, x: np.ndarray) -> np.ndarray:
    """Sparse/dense (m, n) times (n_omega, n, k) -> (n_omega, m, k)."""
    n_w, n, k = x.shape
    flat = np.moveaxis(x, 0, 1).reshape(n, n_w * k)
    out = a @ flat
    return np.moveaxis(np.asarray(out).reshape(-1, n_w, k), 1, 0)


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
        At an undamped resonance (from :mod:`stochcable.solvers`).

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
    """
    t0 = time.perf_counter()
    model = system.model
    w = channels[0].omega
    n_w, n_ch = w.size, len(channels)
    free, fixed = model.free, model.fixed
    C = (damping.matrix + model.Cs).tocsr()
    MT = (model.M + model.Ma).tocsr()
    K = model.K
    f_all = channel_loads(model, channels, damping.matrix, system.b_inertia)
    ub = prescribed_motion(model, channels, n_w)  # (n_w, n_fixed, n_ch)
    iw = (1j * w)[:, None, None]
    w2 = (w**2)[:, None, None]

    def dynamic(rows: np.ndarray, cols: np.ndarray, x: np.ndarray) -> np.ndarray:
        """(−ω²M_T + iωC)[rows, cols] x, frequency by frequency."""
        return -w2 * _rows_times(MT[rows][:, cols], x) + iw * _rows_times(C[rows][:, cols], x)

    def coupled(rows: np.ndarray, cols: np.ndarray, x: np.ndarray) -> np.ndarray:
        """(K − ω²M_T + iωC)[rows, cols] x."""
        return _rows_times(K[rows][:, cols], x) + dynamic(rows, cols, x)

    rhs = f_all[:, free, :]
    K_ff, M_ff, C_ff = K[free][:, free], MT[free][:, free], C[free][:, free]
    moving = bool(np.any(ub))
    if system.solver == "direct":
        if moving:
            rhs = rhs - coupled(free, fixed, ub)
        u_f = solve_direct(K_ff, M_ff, C_ff, rhs, w)
    else:
        u_qs = None
        if moving:
            # support excitation split into the exact quasi-static following of the
            # ends, U_qs = -K_ff^-1 K_fb u_b, and a dynamic part driven by the inertia
            # and damping forces of the moving ends and of U_qs: the large, short-
            # wavelength stiffness load K_fb u_b never meets the truncated modes
            u_qs = _quasi_static(system, channels)[:, free, :]
            rhs = rhs - dynamic(free, fixed, ub) - dynamic(free, free, u_qs)
        basis = (system.modes.omega, system.modes.shapes[free])
        u_f = solve_modal(K_ff, M_ff, C_ff, rhs, w, n_modes=system.n_modes, method="foss",
                          static_correction=True, basis=basis)
        if u_qs is not None:
            u_f = u_f + u_qs
    u = np.zeros((n_w, model.n_dof, n_ch), dtype=complex)
    u[:, free] = u_f
    u[:, fixed] = ub
    all_dofs = np.arange(model.n_dof)
    reaction = coupled(fixed, all_dofs, u) - f_all[:, fixed, :]
    support = -reaction
    end_t = _end_tension(system, support)
    if timing is not None:
        timing["solve_s"] = timing.get("solve_s", 0.0) + time.perf_counter() - t0
    return Response(omega=w, displacement=u, support_force=support, end_tension=end_t)


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
    """σ of the relative velocity (fluid − structure) at element midpoints and attachments.

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
    Seed 001 eqs. 5.2.3–5.2.5: σ² = Σ_i ∫ S_i(ω)|H_{v,i}(ω)|² dω (trapezoid on the
    grid), H_v the transfer function of the relative velocity component
    V − iωU at the element midpoint (mean of its nodes), projected on e (axial) and on
    the normals n1, n2; the scalar form uses σ_n² = σ_n1² + σ_n2².
    """
    model = system.model
    w = channels[0].omega
    n_w, n_ch = w.size, len(channels)
    vr = np.zeros((n_w, n_ch, model.n_nodes, 3), dtype=complex)
    for i, ch in enumerate(channels):
        if ch.velocity is not None:
            vr[:, i] = ch.velocity
    u = response.displacement if response is not None else displacement
    if u is not None:
        un = embed(model, np.moveaxis(u, 2, 1))  # (n_w, n_ch, n_nodes, 3)
        vr -= (1j * w)[:, None, None, None] * un
    weights = _trapezoid_weights(w)[:, None] * np.stack([c.spectrum for c in channels], axis=1)
    mid = 0.5 * (vr[:, :, 1:] + vr[:, :, :-1])
    e, n1, n2 = system.frames

    def var(x: np.ndarray) -> np.ndarray:  # x (n_w, n_ch, m)
        return np.einsum("wc,wcm->m", weights, np.abs(x) ** 2)

    p_t = np.einsum("wcnk,nk->wcn", mid, e)
    p_1 = np.einsum("wcnk,nk->wcn", mid, n1)
    p_2 = np.einsum("wcnk,nk->wcn", mid, n2)
    s_t = np.sqrt(var(p_t))
    if method == "vector":
        normal = [np.sqrt(var(p_1)), np.sqrt(var(p_2)), np.sqrt(var((p_1 + p_2) / math.sqrt(2.0)))]
    else:
        normal = [np.sqrt(var(p_1) + var(p_2))]
    idx = system.drag_nodes
    if idx.size:
        s_node = np.sqrt(var(vr[:, :, idx, :].reshape(n_w, n_ch, -1)).reshape(idx.size, 3).sum(axis=1))
    else:
        s_node = np.zeros(0)
    return np.concatenate(normal + [s_t, s_node])


def _quasi_static(system: LineSystem, channels: tuple[Channel, ...]) -> np.ndarray | None:
    """Displacement of the line following its prescribed ends quasi-statically,
    U_f = −K_ff⁻¹K_fb u_b, (n_omega, n_dof, n_ch); None without end motion."""
    model = system.model
    w = channels[0].omega
    ub = prescribed_motion(model, channels, w.size)
    if not np.any(ub):
        return None
    free, fixed = model.free, model.fixed
    K = model.K
    rhs = -_rows_times(K[free][:, fixed], ub)  # (n_w, n_free, n_ch)
    lu = spla.splu(sp.csc_matrix(K[free][:, free]))
    flat = np.moveaxis(rhs, 0, 1).reshape(free.size, -1)
    sol = lu.solve(np.ascontiguousarray(flat.real)) + 1j * lu.solve(np.ascontiguousarray(flat.imag))
    u = np.zeros((w.size, model.n_dof, len(channels)), dtype=complex)
    u[:, free] = np.moveaxis(sol.reshape(free.size, w.size, -1), 1, 0)
    u[:, fixed] = ub
    return u


def linearize(
    system: LineSystem,
    channels: tuple[Channel, ...],
    settings: AnalysisSettings,
    *,
    progress: Progress | None = None,
    timing: dict[str, float] | None = None,
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

    Returns
    -------
    Linearization
        The drag of the last iteration, the record and the response computed with it
        (whose σ are the record's final σ: the outputs are exactly those of the
        recorded linear system).

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
    end-motion-only scene does not start undamped.  Convergence: the relative change
    of every σ (:func:`stochcable.linearization.fixed_point`) below the tolerance.
    """
    lin = settings.linearization
    method = lin.method
    progress = _noop if progress is None else progress
    if method == "harmonic" and (np.any(system.current_el) or np.any(system.current_node)):
        raise InputError("analysis.linearization.method", "harmonic", "-",
                         "the harmonic (regular-wave) form has no current term: use "
                         "'seed' or 'vector' with a current")
    qs = _quasi_static(system, channels)
    x0 = relative_velocity_sigmas(system, channels, None, method, displacement=qs)
    state: dict[str, Any] = {"it": 0}
    cache: dict[str, Any] = {}

    def update(x: np.ndarray) -> np.ndarray:
        damping = drag_coefficients(system, x, method)
        resp = solve(system, channels, damping, timing)
        new = relative_velocity_sigmas(system, channels, resp, method)
        state["it"] += 1
        den = np.maximum(np.abs(new), 1e-6 * max(float(np.max(np.abs(new), initial=0.0)), 1e-300))
        change = float(np.max(np.abs(new - x) / den, initial=0.0))
        progress("linearization", {"line": system.name, "iteration": state["it"],
                                   "change": change})
        cache["damping"], cache["response"], cache["sigma"] = damping, resp, new
        return new

    name = f"drag linearization of line '{system.name}'"
    try:
        fp = fixed_point(
            update, x0, tol=lin.tolerance, max_iterations=lin.max_iterations,
            relaxation=lin.relaxation,
            method="anderson" if lin.acceleration == "anderson" else "relaxed",
            allow_unconverged=lin.allow_unconverged, name=name,
        )
    except ConvergenceError as exc:
        raise ConvergenceError(
            name, exc.iterations, exc.residual, exc.tolerance,
            hint="increase analysis.linearization.max_iterations, lower relaxation, or "
                 "set allow_unconverged to get a flagged result",
            partial=exc.partial,
        ) from None
    if not fp.converged:
        warnings.warn(
            f"{name} did not converge: relative change {fp.relative_change:.3e} after "
            f"{fp.iterations} iterations (tolerance {lin.tolerance:.1e}); the result is "
            "flagged unconverged (increase analysis.linearization.max_iterations)",
            PhysicsWarning, stacklevel=2,
        )
    damping, resp = cache["damping"], cache["response"]
    parts = _split_sigma(system, cache["sigma"], method)
    if method == "vector":
        sig_n = np.sqrt(parts["normal"][0] ** 2 + parts["normal"][1] ** 2)
        b_n = 0.5 * np.trace(damping.b_normal, axis1=1, axis2=2)
    else:
        sig_n, b_n = parts["normal"][0], damping.b_normal
    record = LinearizationRecord(
        method=method, converged=fp.converged, iterations=fp.iterations,
        relative_change=fp.relative_change, history=fp.history, tolerance=lin.tolerance,
        sigma_normal=sig_n, sigma_axial=parts["axial"], b_normal=b_n,
        b_axial=damping.b_axial,
    )
    return Linearization(damping=damping, record=record, response=resp)


# ------------------------------------------------------------------------- outputs


def element_tension_transfer(system: LineSystem, response: Response) -> np.ndarray:
    """Dynamic effective tension per element, (n_ch, n_el, n_omega). [N/unit]

    δT = (EA/l0)·e·(u_{j+1} − u_j) (module docstring), EA reduced for slack elements.
    """
    from .fem import SLACK_EA_RATIO

    model = system.model
    mesh = model.mesh
    u = response.displacement.reshape(response.omega.size, model.n_nodes, model.dim, -1)
    du = u[:, 1:] - u[:, :-1]  # (n_w, n_el, dim, n_ch)
    ea = np.where(model.slack, SLACK_EA_RATIO * mesh.ea, mesh.ea)
    stretch = np.einsum("wedc,ed->cew", du, model.tangents)
    return (ea / model.l0)[None, :, None] * stretch


def _resolution_check(system: LineSystem, damping: Damping, omega: np.ndarray) -> None:
    """ResolutionWarning for natural frequencies inside the grid that the grid cannot
    resolve: nearest grid point farther than the local spacing, or a half-power
    bandwidth (2ζω_j ≈ φ_jᵀCφ_j for mass-normalized φ) narrower than the local spacing."""
    model = system.model
    modes = system.modes
    wn = np.asarray(modes.omega)
    inside = np.flatnonzero((wn >= omega[0]) & (wn <= omega[-1]))
    if inside.size == 0 or omega.size < 2:
        return
    C = (damping.matrix + model.Cs).tocsr()[model.free][:, model.free]
    phi = modes.shapes[model.free][:, inside]
    band = np.einsum("ij,ij->j", phi, C @ phi)
    spacing = np.gradient(omega)
    bad = []
    for j, b in zip(inside, band):
        k = int(np.argmin(np.abs(omega - wn[j])))
        dist = abs(omega[k] - wn[j])
        if dist > spacing[k] or spacing[k] > b:
            bad.append((j, wn[j], b, spacing[k]))
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
    warnings.warn(
        f"line '{system.name}': the frequency grid (spacing {dw:.3g} rad/s near "
        f"{wj:.4g} rad/s) does not resolve mode {j + 1} at {wj:.4g} rad/s, whose "
        f"half-power bandwidth is {b:.3g} rad/s{more}; the resonance peak may be missed: "
        f"{fix}",
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
        warnings.warn(
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
    u_nodes = embed(model, np.moveaxis(resp.displacement, 2, 1))  # (n_w, n_ch, n_nodes, 3)
    motion_h = np.transpose(u_nodes, (1, 2, 3, 0))  # (n_ch, n_nodes, 3, n_w)
    tension_h = element_tension_transfer(system, resp)
    s_mot = np.einsum("cnkw,cw->nkw", np.abs(motion_h) ** 2, spectra)
    s_ten = np.einsum("cew,cw->ew", np.abs(tension_h) ** 2, spectra)
    st = system.statics
    s0 = model.mesh.s0
    stats = {}
    for end, mean in (("end_a", st.tension_a), ("end_b", st.tension_b)):
        dens = np.einsum("cw,cw->w", np.abs(resp.end_tension[end]) ** 2, spectra)
        stats[end] = stats_from_spectrum(w, dens, float(mean), settings.duration)
        _tail_check(system.name, end, w, dens, stats[end].m0)
    if np.any(spectra > 0):  # nothing to resolve without excitation
        _resolution_check(system, linearization.damping, w)
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
        tension_std=np.sqrt(np.trapezoid(s_ten, w, axis=-1)),
        motion_std=np.sqrt(np.trapezoid(s_mot, w, axis=-1)),
        end_a=stats["end_a"],
        end_b=stats["end_b"],
        linearization=linearization.record,
        modes_omega=np.asarray(system.modes.omega).copy(),
        modes_listed=_listed_modes(system.modes.omega, float(w[-1])),
        n_modes=system.n_modes if system.solver == "foss" else None,
        statics=st,
        model=model,
        modes=system.modes,
    )


# ---------------------------------------------------------------------- time series


def simulate_timeseries(
    scene: Scene,
    systems: Mapping[str, LineSystem],
    dampings: Mapping[str, Damping],
    settings: TimeSeriesSettings,
    *,
    timing: dict[str, float] | None = None,
) -> TimeSeries:
    """One realization of every input channel and the end-tension time series.

    Parameters
    ----------
    scene : Scene
    systems : mapping of LineSystem by line name
    dampings : mapping of Damping by line name
        The converged linear drag of each line.
    settings : TimeSeriesSettings
        method (dsa/nsa), duration, dt, seed.
    timing : dict, optional
        Accumulates ``solve_s``.

    Returns
    -------
    TimeSeries

    Notes
    -----
    The sea: :func:`stochcable.sea.simulate_sea` with ``rng=seed`` (so η is the
    realization a stand-alone simulation with that seed gives).  End-motion spectrum
    channels, in the order lines × (end_a, end_b) × (surge, sway, heave), use the
    independent generators ``np.random.default_rng(c)`` for
    ``c in np.random.SeedSequence(seed).spawn(n)``.  Responses are
    :func:`stochcable.sea.synthesize` of the transfer functions solved on the
    realization grid ω_m = mΔω, restricted to the analysis band [omega.min, omega.max]
    (zero outside, as the response spectra are), so η, end motions and tensions of one
    realization are mutually consistent (seed 001 §5.1, eq. 5.3.29 and step 14).
    """
    seed = int(settings.seed)
    omega_r, _ = frequency_grid(settings.duration, settings.dt)
    grid = scene.analysis.omega
    band = np.flatnonzero((omega_r >= grid.min) & (omega_r <= grid.max) & (omega_r > 0))
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
    # channels per line on the band of the realization grid
    chans = {}
    for name, system in systems.items():
        chans[name] = line_channels(scene, system.line, system.positions, omega_r[band]) \
            if band.size else ()
    motion_keys = [(name, ch.name) for name in systems for ch in chans[name]
                   if ch.kind == "end_motion"]
    children = np.random.SeedSequence(seed).spawn(len(motion_keys)) if motion_keys else []
    reals: dict[tuple[str, str], Any] = {}
    for (name, cname), child in zip(motion_keys, children):
        ch = next(c for c in chans[name] if c.name == cname)
        reals[(name, cname)] = simulate_sea(ch.density, settings.duration, settings.dt,
                                            settings.method, rng=np.random.default_rng(child))
    end_motion = {f"{name}.{cname}": np.asarray(r.elevation) for (name, cname), r in reals.items()}
    end_tension: dict[str, dict[str, np.ndarray]] = {}
    transfer: dict[str, dict[str, np.ndarray]] = {}
    n_t = int(round(settings.duration / settings.dt))
    for name, system in systems.items():
        st = system.statics
        series = {"end_a": np.full(n_t, float(st.tension_a)),
                  "end_b": np.full(n_t, float(st.tension_b))}
        tr = {}
        if chans[name]:
            resp = solve(system, chans[name], dampings[name], timing)
            for end in ("end_a", "end_b"):
                h = np.zeros((len(chans[name]), omega_r.size), dtype=complex)
                h[:, band] = resp.end_tension[end]
                tr[end] = h
                for i, ch in enumerate(chans[name]):
                    real = sea_real if ch.kind == "sea" else reals[(name, ch.name)]
                    series[end] = series[end] + synthesize(real, h[i])
        end_tension[name] = series
        transfer[name] = tr
    time_axis = (np.asarray(sea_real.time) if sea_real is not None
                 else (settings.duration / n_t) * np.arange(n_t))
    return TimeSeries(
        time=time_axis, method=settings.method, seed=seed,
        elevation=None if sea_real is None else np.asarray(sea_real.elevation),
        end_motion=end_motion, end_tension=end_tension, omega=omega_r,
        channels={name: tuple(c.name for c in chans[name]) for name in systems},
        end_tension_transfer=transfer,
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
        The scene document (validated by :func:`stochcable.scene.load_scene`).
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
    (:mod:`stochcable.excitation`) -> drag linearization (:func:`linearize`) ->
    response (direct or Foss, :func:`solve`) -> spectra S_x = Σ_i |H_{x,i}|² S_i and
    statistics -> time series.
    """
    t_start = time.perf_counter()
    scene = load_scene(scene)
    progress = _noop if progress is None else progress
    settings = scene.analysis
    timing: dict[str, float] = {"statics_s": 0.0, "model_s": 0.0, "linearization_s": 0.0,
                                "solve_s": 0.0, "outputs_s": 0.0, "timeseries_s": 0.0}
    omega = settings.omega.values()
    if settings.linearization.method == "harmonic" and any(
            p.speed > 0 for p in scene.environment.current):
        raise InputError("analysis.linearization.method", "harmonic", "-",
                         "the harmonic (regular-wave) form has no current term: use "
                         "'seed' or 'vector' with a current")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        progress("statics", {})
        t0 = time.perf_counter()
        if statics is None:
            statics = solve_statics(scene)
        timing["statics_s"] = time.perf_counter() - t0
        systems: dict[str, LineSystem] = {}
        lines: dict[str, LineResult] = {}
        dampings: dict[str, Damping] = {}
        for line in scene.lines:
            progress("model", {"line": line.name})
            t0 = time.perf_counter()
            system = build_line_system(scene, line, statics.lines[line.name], settings=settings)
            channels = line_channels(scene, line, system.positions, omega)
            timing["model_s"] += time.perf_counter() - t0
            systems[line.name] = system
            if not channels:
                warnings.warn(
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
                                     timing=timing)
            timing["timeseries_s"] = time.perf_counter() - t0
    messages: list[str] = []
    for w in caught:
        text = str(w.message)
        if text not in messages:
            messages.append(text)
            module = None
            if "stochcable" in str(w.filename):
                from pathlib import Path

                module = "stochcable." + Path(str(w.filename)).stem
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno, module=module)
    timing["total_s"] = time.perf_counter() - t_start
    progress("done", {"total_s": timing["total_s"]})
    return Result(scene=scene, statics=statics, lines=lines, timeseries=ts, timing=timing,
                  warnings=tuple(messages))


def _silent_channel(omega: np.ndarray) -> tuple[Channel, ...]:
    """A zero-spectrum channel so a line without excitation still gets (zero) outputs."""
    def zero(w: np.ndarray) -> np.ndarray:
        return np.zeros_like(np.asarray(w, dtype=float))

    return (Channel(name="none", kind="none", omega=omega, spectrum=zero(omega),
                    density=zero),)
