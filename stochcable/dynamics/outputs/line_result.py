"""Outputs of one line: transfer functions, spectra and statistics
(:func:`line_result`) and the dynamic effective tension per element.

Dynamic effective tension
-------------------------
Per element δT = (EA/l0)·e·(u_b − u_a), the first-order change of T = EA(l/l0 − 1)
(Tuah 1982, eqs. 3.1.8–3.1.11: the K_NL part of the tangent stiffness).  The "geometric"
term (T/l)(I − eeᵀ)Δu of the tangent stiffness rotates the element force; it changes
its direction, not its magnitude, and contributes to the tension only at second order,
so it is not part of δT.  Slack elements (T <= 0) use the model's reduced EA.  The end
tensions are computed with the response (:mod:`stochcable.dynamics.solve.line_solve`).

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from contextvars import ContextVar
from typing import Any

import numpy as np

from stochcable.dynamics.loads.channels import (
    Channel,
)
from stochcable.dynamics.loads.freqblocks import frequency_slices
from stochcable.dynamics.model.blocks import (
    trapezoid_weights,
)
from stochcable.dynamics.model.system import (
    Linearization,
    LineSystem,
    Response,
)
from stochcable.dynamics.outputs.indicators import line_indicators
from stochcable.dynamics.outputs.resolution import (
    LineModes,
    excitation_end,
    resolution_check,
    surface_resolution_check,
    tail_check,
)
from stochcable.dynamics.residuals.along_line import (
    along_line_residual,
    end_station_influence,
    residual_tap,
)
from stochcable.dynamics.residuals.along_line_bodies import (
    node_station_influence,
    station_influence,
)
from stochcable.dynamics.residuals.along_line_motion import (
    NodeInfluence,
    motion_residual,
    node_rows,
    solved_stations,
)
from stochcable.dynamics.residuals.body_residual import CoupledInfluence
from stochcable.dynamics.residuals.corrected import corrected_stats, residuals_in_range
from stochcable.dynamics.residuals.corrected_spectrum import corrected_spectra
from stochcable.dynamics.residuals.registry import residual_parts
from stochcable.dynamics.residuals.residual_lines import EndInfluence, shared_rows
from stochcable.dynamics.residuals.second_order import second_order_tension, with_second_order
from stochcable.line.fem import SLACK_EA_RATIO, FEModel
from stochcable.results.documents import (
    LineResult,
    stats_from_spectrum_unchecked,
)
from stochcable.results.records import ResidualRecord
from stochcable.scene.model import AnalysisSettings

#: Whether :func:`line_result` computes the node motions' residuals (and through them
#: a free body's): a load-case set, which reports neither, switches them off
#: (:mod:`stochcable.cases.chunk`); the end and element tensions are the same.
MOTION_RESIDUALS: ContextVar[bool] = ContextVar("motion_residuals", default=True)

# ------------------------------------------------------------------------- outputs


def element_tension_transfer(
    system: LineSystem, response: Response, motion: np.ndarray | None = None
) -> np.ndarray:
    """Dynamic effective tension per element, (n_ch, n_el, n_omega). [N/unit]

    δT = (EA/l0)·e·(u_{j+1} − u_j) (module docstring), EA reduced for slack elements;
    the rows of :attr:`stochcable.line.fem.FEModel.tension_rows` (the touchdown element
    split at the static touchdown has its suspended part's).  ``motion``: the node
    motion transfer (n_ch, n_nodes, 3, n_omega) of ``response`` when already formed
    (read in place: the same numbers without a transposed copy of the response).
    """

    model = system.model
    n_w = response.omega.size
    comps = list(range(model.dim))
    if motion is not None:  # (n_ch, n_nodes, 3, n_w): the model's components in place
        u, comps = motion, list(model.components)
    else:
        u = response.displacement.reshape(n_w, model.n_nodes, model.dim, -1)
        # rows·(u_a, u_b) one component at a time, frequencies last (long inner loops;
        # the complex einsum was 0.4 ms on the chain, the frequency-major layout 0.25)
        u = np.ascontiguousarray(np.transpose(u, (3, 1, 2, 0)))
    rows = model.tension_rows
    if rows is None:
        ea = np.where(model.slack, SLACK_EA_RATIO * model.mesh.ea, model.mesh.ea)
        t = model.tangents * (ea / model.l0)[:, None]
        rows = np.stack([-t, t], axis=1)
    c = comps[0]
    out = rows[None, :, 0, 0, None] * u[:, :-1, c] + rows[None, :, 1, 0, None] * u[:, 1:, c]
    for k in range(1, model.dim):
        c = comps[k]
        out += rows[None, :, 0, k, None] * u[:, :-1, c] + rows[None, :, 1, k, None] * u[:, 1:, c]
    return out


def _listed_modes(omega_n: np.ndarray, w_top: float) -> int:
    """How many natural frequencies the document lists: those up to
    2.5·ω_max, at least min(10, available)."""
    wn = np.asarray(omega_n)
    return int(max(np.count_nonzero(wn <= 2.5 * w_top), min(10, wn.size)))


#: Why a travelling line or a line with a steady lift on free bodies has no residuals.
NOT_ON_BODIES = (
    "a travelling line or a line with a steady lift on free bodies is not covered (the "
    "coupled influence leaves out the transport and lift terms)"
)


def _shared_influence(
    system: LineSystem, damping: Any, influence: CoupledInfluence | None, alone: bool
) -> Any:
    """The residual kinds' shared influence: one solve for both kinds; a planar line
    alone with the element tensions' and node motions' station rows in the same
    factorization; a line on bodies through the coupled group (``influence``)."""
    if influence is not None:
        return influence
    model = system.model
    if alone and model.dim == 2:
        more = node_rows(model, solved_stations(model)) if MOTION_RESIDUALS.get() else None
        return end_station_influence(system, damping, more=more)
    return EndInfluence(system, damping)


def line_result(
    system: LineSystem,
    channels: tuple[Channel, ...],
    linearization: Linearization,
    settings: AnalysisSettings,
    modes: LineModes | None = None,
    *,
    alone: bool = True,
    influence: CoupledInfluence | None = None,
    on_residuals: Callable[[Mapping[str, Any], Mapping[str, Any]], None] | None = None,
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
    modes : LineModes, optional
        The natural modes of the resolution check and the resonance indicator
        (default the line's fixed-end modes; a line on bodies: the coupled modes that
        count for it, :func:`stochcable.dynamics.groups.results.line_modes`).
    alone : bool
        False for a line of a coupled group (on free bodies): its residuals (the kinds
        of :mod:`stochcable.scene.residual_kinds` ``settings.linearization`` asks
        for) are computed through ``influence``, not computed without it.
    influence : CoupledInfluence, optional
        A line on free bodies: its end influence through the coupled group
        (:mod:`stochcable.dynamics.residuals.body_residual`).
    on_residuals : callable, optional
        Called with the computed residual records and their taps (by kind) when the
        node motions carry the residuals (the bodies' motions:
        :mod:`stochcable.dynamics.residuals.body_motion`).

    Returns
    -------
    LineResult
    """
    model = system.model
    resp = linearization.response
    w = resp.omega
    n_ch = len(channels)
    spectra = np.stack([c.spectrum for c in channels]) if n_ch else np.zeros((0, w.size))
    # σ² = Σ_c ∫|H_c|² S_c dω as weighted reductions with the trapezoid weights q
    # (the response spectra are not kept), the node motion and the element tensions
    # over blocks of frequencies: their transfer functions are formed only when read
    # (LineResult.motion_transfer, .tension_transfer)
    q = trapezoid_weights(w)
    sq = spectra * q
    tension_var, motion_var = _blocked_variances(system, resp, n_ch, sq)
    tension_std = np.sqrt(tension_var)
    motion_std = np.sqrt(motion_var)

    def motion(freq: slice = slice(None)) -> np.ndarray:
        return _motion_transfer(model, resp, n_ch, freq)

    def tension() -> np.ndarray:
        return _tension_transfer(system, resp, n_ch)

    st = system.statics
    s0 = model.mesh.s0
    stats, dens = {}, {}
    input_end = excitation_end(channels, w)
    for end, mean in (("end_a", st.tension_a), ("end_b", st.tension_b)):
        dens[end] = np.einsum("cw,cw->w", np.abs(resp.end_tension[end]) ** 2, spectra)
        stats[end] = stats_from_spectrum_unchecked(w, dens[end], float(mean), settings.duration)
        tail_check(system.name, end, w, dens[end], stats[end].m0, input_end)
    if np.any(spectra > 0):  # nothing to resolve without excitation
        resolution_check(system, linearization.damping, w, modes)
        surface_resolution_check(system, channels, w, q)
    indicators = (
        None
        if linearization.record is None
        else line_indicators(system, channels, linearization, tension_std, motion_std, stats, modes)
    )
    if indicators is not None:
        so = second_order_tension(
            motion,
            spectra,
            q,
            model.positions,
            model.mesh,
            st.tension,
            tension_std,
            tuple(model.components),
        )
        indicators = with_second_order(system.name, indicators, so)
    end_force = _end_force_transfer(model, resp, n_ch)
    residual = {}
    std = {e: stats[e].std for e in stats}
    kinds = residual_parts(settings.linearization) if linearization.record is not None else ()
    # (formed only where a kind reads it: a linear case of a set skips the station rows)
    shared = _shared_influence(system, linearization.damping, influence, alone) if kinds else None
    taps = {}  # (each kind's loads and load cross-spectra, for the element tensions)
    for kind, fn in kinds:
        with residual_tap() as taps[kind.name]:
            residual[kind.name] = (
                fn(system, channels, linearization, std, influence=shared)
                if alone or influence is not None
                else ResidualRecord.not_computed(NOT_ON_BODIES, std)
            )
    residual = residuals_in_range(system.name, residual, std)
    applied = [r for r in residual.values() if r.computed]
    along = moves = None
    if applied:  # the element tensions with the residuals (a line on bodies: through them)
        computed = {k: r for k, r in residual.items() if r.computed}
        along = along_line_residual(
            system,
            linearization.damping,
            computed,
            taps,
            resp,
            spectra,
            influence_of=None if influence is None else station_influence(influence),
            shared=shared if influence is None else None,
        )
        if MOTION_RESIDUALS.get():  # (not in a load-case set)
            moves = motion_residual(
                system,
                linearization.damping,
                computed,
                taps,
                motion,
                spectra,
                motion_std,
                influence_of=(
                    node_station_influence(influence)
                    if influence is not None
                    else _shared_nodes(shared, system, linearization.damping)
                ),
                ends_held=influence is None,
            )
        if on_residuals is not None and moves is not None and moves.computed:
            on_residuals(computed, taps)
    linear = {e: stats[e] for e in ("end_a", "end_b")} if applied else None
    corrected = None
    if applied:  # the end statistics and densities with the residuals' spectra
        stats = {e: corrected_stats(stats[e], e, applied, settings.duration) for e in linear}
        corrected = corrected_spectra(w, {e: dens[e] for e in linear}, applied)
    return LineResult(
        name=system.name,
        omega=w,
        channels=tuple(c.name for c in channels),
        input_spectra=spectra,
        s_nodes=s0.copy(),
        s_elements=0.5 * (s0[1:] + s0[:-1]),
        positions=model.positions.copy(),
        motion_transfer=motion,  # formed when read
        tension_transfer=tension,  # formed when read
        end_tension_transfer=dict(resp.end_tension),
        end_force_transfer=end_force,
        tension_mean=np.asarray(st.tension, dtype=float).copy(),
        tension_std=tension_std if along is None else along.std(tension_std),
        motion_std=motion_std if moves is None else moves.std(motion_std),
        end_a=stats["end_a"],
        end_b=stats["end_b"],
        linear=linear,
        corrected_spectra=corrected,
        linearization=linearization.record,
        modes_omega=np.asarray(system.modes.omega).copy(),
        modes_listed=_listed_modes(system.modes.omega, float(w[-1])),
        n_modes=system.n_modes if system.solver == "foss" else None,
        statics=st,
        model=model,
        modes=system.modes,
        indicators=indicators,
        residuals=residual,
        tension_std_linear=None if along is None or not along.computed else tension_std,
        along_line=along,
        motion_std_linear=None if moves is None or not moves.computed else motion_std,
        motion_residual=moves,
    )


def _blocked_variances(
    system: LineSystem, resp: Response, n_ch: int, sq: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The element tension variances (n_el,) and the node motion variances (n_nodes,
    3) over the σ weights ``sq`` (n_ch, n_omega), from the motion transfer of blocks
    of frequencies (no transfer function formed for the whole grid)."""
    model = system.model
    n_w = resp.omega.size
    t_var = np.zeros(model.n_elements)
    var = np.zeros((model.n_nodes, 3))
    # a block's motion transfer, its squares and the tension temporaries
    for sl in frequency_slices(n_w, 16 * n_ch * model.n_nodes * 8):
        m = _motion_transfer(model, resp, n_ch, sl)
        t = element_tension_transfer(system, resp, m)
        t_var += np.einsum("cew,cw->e", np.abs(t) ** 2, sq[:, sl])
        var += np.einsum("cnkw,cw->nk", np.abs(m) ** 2, sq[:, sl])
    return t_var, var


def _tension_transfer(system: LineSystem, resp: Response, n_ch: int) -> np.ndarray:
    """The element tension transfer (n_ch, n_el, n_omega), formed over blocks of
    frequencies (the node motion transfer of a block at a time). [N/unit]"""
    model = system.model
    n_w = resp.omega.size
    tension = np.empty((n_ch, model.n_elements, n_w), dtype=complex)
    for sl in frequency_slices(n_w, 16 * n_ch * model.n_nodes * 8):
        tension[:, :, sl] = element_tension_transfer(
            system, resp, _motion_transfer(model, resp, n_ch, sl)
        )
    return tension


def _motion_transfer(
    model: FEModel, resp: Response, n_ch: int, freq: slice = slice(None)
) -> np.ndarray:
    """Node motion transfer functions on x, y, z on the frequencies ``freq``, (n_ch,
    n_nodes, 3, n_f) (zero on the components a 2-D model lacks). [m/unit]"""
    if resp.nodes is not None:  # the node layout (n_nodes, d, n_f, n_ch) of a block
        u_h = np.transpose(resp.nodes(freq), (3, 0, 1, 2))
    else:
        disp = resp.displacement[freq]
        # (n_ch, n_nodes, 3, n_w) built in its own layout (embedding in the
        # frequency-major layout and transposing made every later pass strided)
        u_h = np.transpose(
            disp.reshape(disp.shape[0], model.n_nodes, model.dim, n_ch), (3, 1, 2, 0)
        )
    n_f = u_h.shape[-1]
    if tuple(model.components) == (0, 1, 2):  # 3-D: no zero components to embed
        return np.ascontiguousarray(u_h)
    motion_h = np.zeros((n_ch, model.n_nodes, 3, n_f), dtype=complex)
    motion_h[:, :, list(model.components)] = u_h
    return motion_h


def _end_force_transfer(model: FEModel, resp: Response, n_ch: int) -> dict[str, np.ndarray]:
    """Support force transfer functions on x, y, z per end, (n_ch, 3, n_omega). [N/unit]"""
    comps = list(model.components)
    d = model.dim
    w = resp.omega
    end_force = {}
    for k, end in enumerate(("end_a", "end_b")):
        f = np.zeros((n_ch, 3, w.size), dtype=complex)
        f[:, comps, :] = np.transpose(resp.support_force[:, k * d : (k + 1) * d, :], (2, 1, 0))
        end_force[end] = f
    return end_force


def _shared_nodes(shared: EndInfluence, system: LineSystem, damping: Any) -> Any:
    """The node motions' stations' influence (from their node indices): a
    :class:`NodeInfluence` that takes its rows from the kinds' shared influence where
    it holds them (solved with the end and element rows:
    :func:`end_station_influence`'s ``more``), its own solve elsewhere (the motions'
    cells: one node's rows, :func:`~stochcable.dynamics.residuals.along_line_motion.
    motion_cells`)."""
    extra = getattr(shared, "extra", None)

    def of(nodes: np.ndarray) -> Any:
        rhs = node_rows(system.model, nodes)
        rows = None if extra is None else shared_rows(shared, rhs, extra.shape[1] - rhs.shape[1])
        return _SharedNodeInfluence(system, damping, nodes, rows)

    return of


class _SharedNodeInfluence(NodeInfluence):
    """A :class:`NodeInfluence` reading the shared rows ``rows`` (a
    :class:`~stochcable.dynamics.residuals.residual_lines.SharedRows`) where they are
    kept (or modal), solving its own elsewhere."""

    def __init__(self, system: Any, damping: Any, nodes: np.ndarray, rows: Any) -> None:
        super().__init__(system, damping, nodes)
        self.rows = rows

    def on(self, w: np.ndarray) -> np.ndarray:
        if self.rows is not None:
            g = self.rows.shared.extra_kept(w, self.rows.cols)
            if g is not None:
                return g
        return super().on(w)
