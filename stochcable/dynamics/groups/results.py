"""Results of a coupled group: the lines' results and the bodies' motion statistics
(Tuah 1982, §5.1, spectral moments and maxima).

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from stochcable.bodies.rigid import PLANAR_INDEX, RigidBody
from stochcable.dynamics.groups.group_fixed_point import CoupledLinearization
from stochcable.dynamics.groups.inputs import CoupledLine
from stochcable.dynamics.groups.modes import (
    CoupledModes,
    coupled_modal_bandwidths,
    line_mode_shares,
)
from stochcable.dynamics.loads.channels import Channel
from stochcable.dynamics.outputs.line_result import line_result
from stochcable.dynamics.outputs.resolution import LineModes
from stochcable.dynamics.residuals.along_line import stations
from stochcable.dynamics.residuals.along_line_motion import motion_stations
from stochcable.dynamics.residuals.body_drag_residual import body_drag_residual, with_body_drag
from stochcable.dynamics.residuals.body_motion import (
    BodyCoupledInfluence,
    body_motion_parts,
    body_rows,
)
from stochcable.dynamics.residuals.body_residual import coupled_influences
from stochcable.dynamics.residuals.corrected_spectrum import spectrum_with_lines
from stochcable.dynamics.residuals.group_motion import body_rows_of
from stochcable.dynamics.residuals.group_stations import with_group_stations
from stochcable.results.documents import BodyResult, LineResult, stats_from_spectrum
from stochcable.results.records import stats_from_moments
from stochcable.scene.model import AnalysisSettings
from stochcable.scene.residual_kinds import asked_residuals

__all__ = ["LINE_MODE_SHARE", "body_result", "coupled_results", "line_modes"]

#: A coupled mode counts for a line's resolution check and resonance indicator when at
#: least this share of its kinetic energy is in the line (u_lᵀ(M + M_a)_l u_l of the
#: mass-normalized mode).  A mode the line hardly takes part in (a body mode, a mode
#: of another line) gives the line little response at its frequency: its resonance is
#: not the line's.  Below 5 % the line's own motion in it is under ≈ 22 % of the
#: mode's amplitude scale (√0.05); each line's fixed-end-like modes carry most of
#: their energy in the line and pass by far.
LINE_MODE_SHARE = 0.05


def coupled_results(
    lines: Sequence[CoupledLine],
    bodies: Sequence[RigidBody],
    linearization: CoupledLinearization,
    settings: AnalysisSettings,
    *,
    static_pose: Mapping[str, np.ndarray] | None = None,
    modes: CoupledModes | None = None,
    channels: Sequence[Channel] | None = None,
    loads: Mapping[str, Any] | None = None,
) -> tuple[dict[str, LineResult], dict[str, BodyResult]]:
    """Line and body results of a coupled group.

    Parameters
    ----------
    lines : sequence of CoupledLine
    bodies : sequence of RigidBody
    linearization : CoupledLinearization
    settings : AnalysisSettings
        ``duration`` for the maxima.
    static_pose : mapping of body name to ndarray (d,), optional
        Static value of each body DOF (position and rotation components), the
        statistics' mean (default: the body position, zero rotation). [m, rad]
    modes : CoupledModes, optional
        Listed on every body result; the modes of the lines' resolution check and
        resonance indicator (:func:`line_modes`; default each line's fixed-end modes).
    channels : sequence of Channel, optional
        The group's channels (default those of the first line).
    loads : mapping of str to BodyLoads, optional
        The bodies' wave inputs (their drag points' fluid velocity and current): with
        them and the drag residual asked for, the residual of the bodies' own drag
        enters their motions and the lines' end tensions
        (:mod:`stochcable.dynamics.residuals.body_drag_residual`).

    Returns
    -------
    (lines, bodies) : dict of LineResult, dict of BodyResult
    """
    counted = {} if modes is None else line_modes(modes, lines, bodies, linearization)
    # the lines' residuals through the group (residuals.body_residual)
    influence = (
        coupled_influences(
            lines,
            bodies,
            {cl.name: linearization.lines[cl.name].damping for cl in lines},
            linearization.body_drag,
            {cl.name: linearization.lines[cl.name] for cl in lines},
        )
        if asked_residuals(settings.linearization)
        else {}
    )
    ch = tuple(lines[0].channels if channels is None else channels)
    spectra = np.stack([c.spectrum for c in ch])
    w = ch[0].omega
    rows = body_rows(bodies)
    transfer = np.concatenate(
        [np.transpose(linearization.body_motion[b.name], (2, 1, 0)) for b in bodies], axis=1
    ) if bodies else np.zeros((len(ch), 0, w.size))  # fmt: skip
    # the bodies' residual lines: a group of one line from its own loads
    # (residuals.body_motion); of several, as output rows of the joint sums over every
    # line's loads, cross terms included (residuals.group_motion: summing the lines'
    # variances would lose the cancellation of symmetric legs)
    # (and the lines' stations: their element tensions and node motions take every
    # line's loads, the line's own from its along-line records, the others' and the
    # cross terms as the group's part)
    group_rows = (
        body_rows_of(
            influence,
            {
                cl.name: (stations(cl.system.model), motion_stations(cl.system.model))
                for cl in lines
            },
        )  # fmt: skip
        if bodies
        else None
    )
    by_line: dict[str, list[tuple[np.ndarray, np.ndarray]]] = {}
    out_lines = {}
    for cl in lines:

        def collect(applied, taps, cl=cl):  # noqa: ANN001, ANN202
            lin = linearization.lines[cl.name]
            by_line[cl.name] = list(
                body_motion_parts(
                    cl.system, lin.damping, applied, taps,
                    BodyCoupledInfluence(influence[cl.name]), transfer, spectra,
                )
            )  # fmt: skip

        out_lines[cl.name] = line_result(
            cl.system,
            cl.channels,
            linearization.lines[cl.name],
            settings,
            counted.get(cl.name),
            alone=False,
            influence=influence.get(cl.name),
            on_residuals=collect
            if cl.name in influence and bodies and group_rows is None
            else None,
        )
    parts = next(iter(by_line.values())) if len(by_line) == 1 else []
    if group_rows is not None:
        out_lines = {k: with_group_stations(r, group_rows) for k, r in out_lines.items()}
    if group_rows is not None:  # (several lines: the joint sums' body rows)
        parts = group_rows.body_parts(transfer, spectra, w)
    lin_set = settings.linearization
    if loads is not None and influence and lin_set.drag_residual and lin_set.method != "harmonic":
        own = body_drag_residual(
            influence, lines[0].system.model.rho, loads, linearization.body_motion, w, spectra,
            stations={k: _stations(r) for k, r in out_lines.items()},
        )  # fmt: skip
        if own is not None:  # the bodies' own drag: one more part of every body DOF
            parts = [*parts, (own.w_out, own.body)] if parts else [(own.w_out, own.body)]
            out_lines = {k: with_body_drag(r, own, settings.duration) for k, r in out_lines.items()}
    out_bodies = {}
    for b in bodies:
        h = np.transpose(linearization.body_motion[b.name], (2, 1, 0))  # (n_ch, d, n_w)
        if static_pose is not None and b.name in static_pose:
            mean = np.asarray(static_pose[b.name], dtype=float)
        else:
            full = np.concatenate([b.position, np.zeros(3)])
            mean = full[list(PLANAR_INDEX)] if b.planar else full
        out_bodies[b.name] = body_result(
            b.name,
            b.dof_names,
            w,
            tuple(c.name for c in ch),
            spectra,
            h,
            mean,
            settings.duration,
            sigma=linearization.body_sigma.get(b.name),
            drag=linearization.body_drag.get(b.name),
            modes=modes,
            prescribed=False,
            residual=[(om, v[rows[b.name]]) for om, v in parts],
        )
    return out_lines, out_bodies


def _stations(result: LineResult) -> tuple[np.ndarray, np.ndarray]:
    """A line result's element and node stations where its along-line residuals were
    computed (empty where not)."""
    along, moves = result.along_line, result.motion_residual
    none = np.zeros(0, dtype=int)
    return (
        along.stations if along is not None and along.computed else none,
        moves.stations if moves is not None and moves.computed else none,
    )


def line_modes(
    modes: CoupledModes,
    lines: Sequence[CoupledLine],
    bodies: Sequence[RigidBody],
    linearization: CoupledLinearization,
) -> dict[str, LineModes]:
    """The coupled modes that count for each line of a group, with their bandwidths.

    Parameters
    ----------
    modes : CoupledModes
        The group's coupled modes (with ``line_shapes``).
    lines : sequence of CoupledLine
    bodies : sequence of RigidBody
    linearization : CoupledLinearization
        The converged drag of the lines and the bodies.

    Returns
    -------
    dict of str to LineModes
        Per line the modes with at least ``LINE_MODE_SHARE`` of their kinetic energy
        in it (:func:`~stochcable.dynamics.groups.modes.line_mode_shares`) and their
        half-power bandwidths over the group at the converged drag
        (:func:`~stochcable.dynamics.groups.modes.coupled_modal_bandwidths`), the
        modes numbered in the group's list.  Empty when the modes have no line shapes.
    """
    if not lines or any(cl.name not in modes.line_shapes for cl in lines):
        return {}
    damping = {cl.name: linearization.lines[cl.name].damping for cl in lines}
    band = coupled_modal_bandwidths(modes, lines, bodies, damping, linearization.body_drag)
    out = {}
    for name, share in line_mode_shares(modes, lines).items():
        j = np.flatnonzero(share >= LINE_MODE_SHARE)
        out[name] = LineModes(j + 1, modes.omega[j], band[j])
    return out


def body_result(
    name: str,
    dofs: Sequence[str],
    omega: np.ndarray,
    channels: tuple[str, ...],
    spectra: np.ndarray,
    transfer: np.ndarray,
    mean: np.ndarray,
    duration: float,
    *,
    sigma: np.ndarray | None = None,
    drag: np.ndarray | None = None,
    modes: CoupledModes | None = None,
    prescribed: bool = False,
    residual: Sequence[tuple[np.ndarray, np.ndarray]] = (),
) -> BodyResult:
    """Statistics of a body's motion from its transfer functions (see BodyResult);
    ``residual``: the residuals' variance lines of its DOFs, parts (frequencies
    [rad/s] (n,), variance (d, n) [m², rad²]) added to the spectral moments
    (:mod:`stochcable.dynamics.residuals.body_motion`; a DOF whose total variance
    would not be positive keeps its linear statistics) and folded into each DOF's
    spectral density (``corrected_spectra``,
    :func:`~stochcable.dynamics.residuals.corrected_spectrum.spectrum_with_lines`)."""
    dens = np.einsum("cdw,cw->dw", np.abs(transfer) ** 2, spectra)
    stats = {
        dof: stats_from_spectrum(omega, dens[i], float(mean[i]), duration)
        for i, dof in enumerate(dofs)
    }
    linear = corrected = None
    if len(residual):
        linear = stats
        stats, corrected = dict(stats), {}
        for i, dof in enumerate(dofs):
            lin = linear[dof]
            m = np.array([lin.m0, lin.m1, lin.m2, lin.m4])
            for om, v in residual:
                m = m + np.array([np.sum(v[i] * om**k) for k in (0, 1, 2, 4)])
            kept = bool(np.all(m[[0, 2, 3]] > 0.0))
            if kept:
                stats[dof] = stats_from_moments(tuple(m), float(mean[i]), duration)
            lines = [(om, v[i]) for om, v in residual] if kept else []
            corrected[dof] = spectrum_with_lines(omega, dens[i], lines)
    return BodyResult(
        name=name,
        dofs=tuple(dofs),
        omega=np.asarray(omega).copy(),
        channels=tuple(channels),
        input_spectra=np.asarray(spectra).copy(),
        motion_transfer=transfer,
        motion=stats,
        motion_linear=linear,
        prescribed=prescribed,
        drag_sigma=None if sigma is None else np.asarray(sigma).copy(),
        drag_coefficient=None if drag is None else np.asarray(drag).copy(),
        modes=modes,
        corrected_spectra=corrected,
    )
