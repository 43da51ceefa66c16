"""The residual of a free body's own quadratic drag: what the statistical linearization
of its Morison drag drops, in the body's motions and its lines' end tensions.

A body with a drag area takes F_i = c_i|v_i|v_i at its drag point along each global
axis i (c_i = ½ρ·C_dA_i, v the fluid velocity less the drag point's), linearized as
b_i·v_i (:func:`stochcable.dynamics.linearization.bodydrag.linear_body_drag`: b_i =
c_i·σ_i·a₁(U_i/σ_i), the Borgman form with the current U).  The rest is the residual
of :mod:`.drag_residual` with the same Hermite closed forms: with x = (v_i − U_i)/σ_i,
r_i = c_iσ_i² Σ_{k≥2} a_k(U_i/σ_i) He_k(x) (:func:`~.drag_residual.lumped_coefficients`),
and for jointly Gaussian velocities Mehler's formula gives the cross-covariances of
every pair of components through ρ^k — the body's three directions among themselves
and with the panels of its planar lines (their velocities share the sea and the body
motion).  Each direction is one more load channel of the coupled group: a force f at
the drag point along i moves the free body DOFs by ξ = S⁻¹T_dᵀe_i f (S the group's
condensed body impedance, T_d the drag point's rigid link; Tuah 1982, eqs. 3.3.6,
3.3.8–3.3.10) and every line's support forces by R_e,L T_L ξ
(:class:`~.body_residual.CoupledInfluence`'s solves).  Its lines are what the body's
components add to the joint sum over the lines' drag panels: the body's own pairs and
its cross terms with every panel (planar lines: the joint sum less the panels' own,
:func:`~.drag_residual.residual_output_lines` twice, the same panels kept; 3-D lines:
the pairs whose first component is the body's,
:func:`~.drag_residual_3d.vector_residual_output_lines` with ``first``).  The residual is
uncorrelated with the linear response (Hermite orthogonality), so its variance lines
add to the body DOFs' and the end tensions' as the lines' residuals do, and to the
lines' element tensions and node motions at their stations (a line's stations move
with its ends on the bodies, c_att·T_L ξ: :func:`~.group_influence.station_body_rows`;
the panels' through :class:`~.group_influence.StationInfluence`), one more part of
their along-line records (:func:`~.group_stations.with_station_parts`).

Validation: the drag point's transfer against the assembled lines–body system loaded
at the drag point, the linearization's b against c·σ·a₁, and the closed form against a
Monte Carlo of the Hermite expansion (tests/dynamics/test_body_drag_residual.py); the
answer against the nonlinear time domain of a drag-driven planar buoy
(docs/accuracy/bodies.md, "The body's own drag residual").

Scope: the drag residual asked for, a body with a drag area and the stochastic
linearization (``method`` not "harmonic"), lines without gyroscopic or lift terms.
The cross terms with the lines' panels are those of planar lines (a 3-D line's vector
drag components, :mod:`.drag_residual_3d`, are left out of the joint sum: the body's
residual alone, its three directions jointly).  The lines are summed on the lines'
uniform grid without the cell integration of narrow resonances
(:func:`~.drag_residual.cell_factor`).

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from stochcable.bodies.rigid import PLANAR_INDEX, RigidBody, rigid_link_matrix
from stochcable.dynamics.residuals.along_line_bodies import (
    ElementCoupledInfluence,
    NodeCoupledInfluence,
)
from stochcable.dynamics.residuals.body_residual import (
    CoupledInfluence,
    end_tension_rows,
    untapped,
    with_group_lines,
)
from stochcable.dynamics.residuals.corrected import corrected_stats
from stochcable.dynamics.residuals.corrected_spectrum import corrected_spectrum
from stochcable.dynamics.residuals.drag_residual import (
    LUMPED_ORDER,
    _live_panels,
    lumped_coefficients,
    residual_output_lines,
)
from stochcable.dynamics.residuals.drag_residual_3d import vector_residual_output_lines
from stochcable.dynamics.residuals.group_influence import (
    GroupBodyInfluence,
    StationInfluence,
    station_body_rows,
)
from stochcable.dynamics.residuals.group_motion import ROUND_OFF
from stochcable.dynamics.residuals.group_stations import with_station_parts
from stochcable.dynamics.residuals.residual_lines import fft_length, load_transfer, uniform_grid

__all__ = [
    "BodyDragComponents",
    "BodyDragResidual",
    "body_drag_components",
    "body_drag_residual",
    "drag_point_link",
    "drag_point_transfer",
    "with_body_drag",
]


@dataclass(frozen=True, eq=False)
class BodyDragComponents:
    """The residual components of the bodies' drag (one per body and direction with a
    drag): the velocity lines (n_ch·ranks, n_c, n_j) on the uniform grid [m/s], c =
    ½ρ·C_dA [N·s²/m²], the Hermite coefficients (n_c, K + 1), each component's body and
    direction, and the uniform grid's output lines ``w_out`` [rad/s] with their lag
    grid ``n_fft``."""

    lines: np.ndarray
    scale: np.ndarray
    coeffs: np.ndarray
    where: tuple[tuple[str, int], ...]
    w_out: np.ndarray
    n_fft: int


@dataclass(frozen=True, eq=False)
class BodyDragResidual:
    """The body drag residual's variance lines at ``w_out`` [rad/s]: of every body DOF
    (group order) ``body`` (nb, n_o) [m², rad²] and of each line's end tensions
    ``ends`` {line: (2, n_o)} [N²]; ``components`` the bodies' components, ``panels``
    how many line panel components joined the sum, ``stations`` {line: {"elements":
    (n_st, n_o) [N²], "nodes": (n_st·d, n_o) [m²]}} of the stations asked for."""

    w_out: np.ndarray
    body: np.ndarray
    ends: dict[str, np.ndarray]
    components: BodyDragComponents
    panels: int
    stations: dict[str, dict[str, np.ndarray]] = dataclasses.field(default_factory=dict)


def drag_point_link(body: RigidBody) -> np.ndarray:
    """The drag point's velocity per unit body DOF velocity, shape (3, d): its rigid
    link (Tuah 1982, eq. 3.3.6) on the body's DOFs (a planar body's three). [m/m, m/rad]"""
    t = rigid_link_matrix(np.asarray(body.drag_point, dtype=float))
    return t[:, list(PLANAR_INDEX)] if body.planar else t


def body_drag_components(
    bodies: Sequence[RigidBody],
    rho: float,
    loads: Mapping[str, Any],
    motion: Mapping[str, np.ndarray],
    omega: np.ndarray,
    spectra: np.ndarray,
    order: int = LUMPED_ORDER,
    by_spectra: bool = True,
) -> BodyDragComponents | None:
    """The residual components of the drag of ``bodies`` (module notes; None: no body
    with a drag and a relative velocity).

    Parameters
    ----------
    bodies : sequence of RigidBody
    rho : float
        Water density. [kg/m³]
    loads : mapping of str to BodyLoads
        Per body its drag point's fluid ``velocity`` (n_w, 3, n_ch) [(m/s)/unit] and
        ``current`` (3,) [m/s].
    motion : mapping of str to ndarray, complex, shape (n_w, d, n_ch)
        The bodies' linear motion per unit input. [m/unit, rad/unit]
    omega : ndarray, shape (n_w,)
        The analysis grid. [rad/s]
    spectra : ndarray, shape (n_ch, n_w)
        The inputs' spectra.
    order : int
        Highest Hermite order (the two highest carry the rest of their parity).
    by_spectra : bool
        The uniform grid over the frequencies that carry the inputs (the planar lines'
        drag residual's); False: over the whole analysis grid (the 3-D lines').
    """
    w = np.asarray(omega, dtype=float)
    grid = uniform_grid(w, spectra=spectra) if by_spectra else uniform_grid(w)
    vel, scale, mean, where = [], [], [], []
    for b in bodies:
        area = np.broadcast_to(np.asarray(b.drag_area, dtype=float), (3,))
        if b.name not in loads or not np.any(area > 0):
            continue
        t = drag_point_link(b)
        xi = np.asarray(motion[b.name])  # (n_w, d, n_ch)
        v = loads[b.name].velocity - (1j * w)[:, None, None] * np.einsum("ij,wjc->wic", t, xi)
        for i in np.flatnonzero(area > 0):
            vel.append(np.transpose(v[:, i, :]))  # (n_ch, n_w)
            scale.append(0.5 * rho * float(area[i]))
            mean.append(float(np.asarray(loads[b.name].current, dtype=float)[i]))
            where.append((b.name, int(i)))
    if not vel:
        return None
    lines = grid.lines(np.stack(vel, axis=1), spectra)  # (n_ch·ranks, n_c, n_j)
    sig = np.sqrt(np.sum(np.abs(lines) ** 2, axis=(0, 2)))
    if not np.any(sig > 0):
        return None
    mu = np.where(sig > 0, np.asarray(mean) / np.where(sig > 0, sig, 1.0), 0.0)
    coeffs = lumped_coefficients(np.clip(mu, -10.0, 10.0), order)
    n_o = order * (grid.n_j - 1)
    w_out = grid.step * np.arange(1, n_o + 1)
    n_fft = fft_length(2 * order * (grid.n_j - 1) + 1)
    return BodyDragComponents(lines, np.asarray(scale), coeffs, tuple(where), w_out, n_fft)


def drag_point_transfer(
    influences: Mapping[str, CoupledInfluence],
    where: Sequence[tuple[str, int]],
    w: np.ndarray,
    targets: Sequence[Any] = (),
) -> np.ndarray:
    """The outputs per unit force at the drag points (module notes): rows every line's
    end tensions (end_a, end_b; in the order of ``influences``), every body DOF (group
    order, zero on the held ones), then the rows of each of ``targets`` (the stations
    of a line: :class:`~.along_line_bodies.ElementCoupledInfluence`,
    :class:`~.along_line_bodies.NodeCoupledInfluence`), columns the components
    ``where`` (body, direction): shape (2·n_lines + nb + n_st, n_c, n_w). [N/N, m/N,
    rad/N]"""
    w = np.asarray(w, dtype=float)
    base = next(iter(influences.values()))
    off, s, links, solved = base._state(w)
    bodies = {b.name: b for b in base.bodies}
    nb = s.shape[1]
    f = np.zeros((nb, len(where)))
    for k, (name, i) in enumerate(where):
        b = bodies[name]
        f[off[name] : off[name] + b.n_dof, k] = drag_point_link(b)[i]
    free = np.array([off[b.name] + i for b in base.bodies for i in b.free_index], int)
    xi = np.zeros((w.size, nb, len(where)), dtype=complex)
    rhs = np.broadcast_to(f[free], (w.size, free.size, len(where)))
    xi[:, free] = np.linalg.solve(s[:, free[:, None], free[None, :]], rhs)
    rows = []
    for name, infl in influences.items():
        t, att = links[name]
        y = np.zeros((w.size, 2, len(where)), dtype=complex)
        if att.size:
            e_hat = end_tension_rows(infl.line.system)
            y = e_hat[None] @ solved[name][1][:, :, att] @ t[None] @ xi
        rows.append(np.transpose(y, (1, 2, 0)))
    rows.append(np.transpose(xi, (1, 2, 0)))
    for target in targets:
        c = station_body_rows(target, (links, solved), w)  # (n_w, n_out, nb)
        if c is None:
            c = np.zeros((w.size, _rows(target), nb), dtype=complex)
        rows.append(np.transpose(c @ xi, (1, 2, 0)))
    return np.concatenate(rows)


def _rows(target: Any) -> int:
    """The output rows of a station target (an element a row, a node d rows)."""
    n = target.elements.size
    return n * target.line.system.model.dim if isinstance(target, NodeCoupledInfluence) else n


def _panel_sets(
    influences: Mapping[str, CoupledInfluence],
) -> tuple[Any, list[tuple[str, Any]]]:
    """The drag residual's joint key and the lines' panel components the group kept
    under it (:meth:`~.body_residual.CoupledInfluence.joint_lines`): the planar lines'
    (``"drag"``) or the 3-D lines' (``"drag_3d"``); (None, []) where none were kept."""
    base = next(iter(influences.values()))
    kept = base.shared.get("components", {})
    for kind in ("drag", "drag_3d"):
        keys = [k for k in kept if k[0][0] == kind and kept[k] is not None]
        if keys:
            key = keys[0][0]
            return key, [(n, kept[key, n]) for n in influences if kept.get((key, n)) is not None]
    return None, []


def _panel_transfer(
    influences: Mapping[str, CoupledInfluence],
    src: str,
    c: Any,
    w_out: np.ndarray,
    targets: Sequence[Any] = (),
) -> np.ndarray:
    """Every output of :func:`drag_point_transfer` per unit load of line ``src``'s
    panel components ``c`` on ``w_out``: (n_out, n_load, n_o)."""
    base = next(iter(influences.values()))
    ln = influences[src].line
    body = GroupBodyInfluence(influences[src], base._state)
    with untapped():
        h = [
            load_transfer(ln.system, ln.damping, c.unit, w_out, CoupledInfluence(
                src, base.lines, base.bodies, base.body_drag, tgt, base.shared))
            for tgt in influences
        ]  # fmt: skip
        h.append(load_transfer(ln.system, ln.damping, c.unit, w_out, body))
        h += [
            load_transfer(ln.system, ln.damping, c.unit, w_out,
                          StationInfluence(t, body, base._state))
            for t in targets
        ]  # fmt: skip
    return np.concatenate(h)


def _planar_sum(
    influences: Mapping[str, CoupledInfluence],
    comp: BodyDragComponents,
    t_body: np.ndarray,
    panels: list[tuple[str, Any]],
    targets: Sequence[Any] = (),
) -> tuple[np.ndarray, int]:
    """The body's lines with the planar lines' panels (module notes): (n_out, n_o) and
    how many panels joined."""
    k1 = comp.coeffs.shape[1]
    panels = [(n, c) for n, c in panels if c.coeffs.shape[1] == k1]  # (another order: not)
    lines = np.concatenate([comp.lines, *[c.lines for _, c in panels]], axis=1)
    scale = np.concatenate([comp.scale, *[c.scale for _, c in panels]])
    coeffs = np.concatenate([comp.coeffs, *[c.coeffs for _, c in panels]])
    t = np.concatenate(
        [t_body, *[_panel_transfer(influences, n, c, comp.w_out, targets) for n, c in panels]],
        axis=1,
    )
    n_c = comp.scale.size
    # the panels the lines' own sum keeps (their end tensions' floor), every body component
    keep = np.union1d(np.arange(n_c), n_c + _live_panels(
        lines[:, n_c:], scale[n_c:], coeffs[n_c:], t[: 2 * len(influences), n_c:]))  # fmt: skip
    with untapped():
        out = residual_output_lines(
            lines[:, keep], scale[keep], coeffs[keep], t[:, keep], comp.n_fft
        )
        joined = keep[keep >= n_c]
        if joined.size:
            out = out - residual_output_lines(
                lines[:, joined], scale[joined], coeffs[joined], t[:, joined], comp.n_fft
            )
    return out, int(joined.size)


def _vector_sum(
    influences: Mapping[str, CoupledInfluence],
    comp: BodyDragComponents,
    t_body: np.ndarray,
    panels: list[tuple[str, Any]],
    targets: Sequence[Any] = (),
) -> tuple[np.ndarray, int]:
    """The body's lines with the 3-D lines' panels: each body component a panel of the
    vector form (:func:`~.drag_residual_3d.vector_residual_output_lines`) whose third
    variable is its whitened velocity and whose third force direction its drag (as a
    panel's tangential drag), the others zero: (n_out, n_o) and the panels joined."""
    n_c, n_j = comp.scale.size, comp.lines.shape[2]
    k1 = comp.coeffs.shape[1]
    sig = np.sqrt(np.sum(np.abs(comp.lines) ** 2, axis=(0, 2)))
    inv = np.where(sig > 0, 1.0 / np.where(sig > 0, sig, 1.0), 0.0)
    z = np.zeros((comp.lines.shape[0], n_c, 3, n_j), dtype=complex)
    z[:, :, 2] = comp.lines * inv[None, :, None]
    coeffs = np.zeros((n_c, 3) + (k1,) * 3)
    coeffs[:, 2, 0, 0, :] = (comp.scale * sig**2)[:, None] * comp.coeffs
    t = np.zeros((t_body.shape[0], n_c, 3, t_body.shape[2]), dtype=complex)
    t[:, :, 2] = t_body
    zs, cs, ts = [z], [coeffs], [t]
    for name, c in panels:
        if c.coeffs.shape[2] != k1 or c.z.shape[0] != z.shape[0] or c.z.shape[3] != n_j:
            continue  # (another order or grid: not joined)
        n_p = c.z.shape[1]
        h = _panel_transfer(influences, name, c, comp.w_out, targets)
        zs.append(c.z)
        cs.append(c.coeffs)
        ts.append(np.transpose(h.reshape(h.shape[0], 3, n_p, -1), (0, 2, 1, 3)))
    with untapped():  # (the pairs with a body component: the sum's growth by them)
        out = vector_residual_output_lines(
            np.concatenate(zs, axis=1), np.concatenate(cs), np.concatenate(ts, axis=1),
            comp.n_fft, first=n_c,
        )  # fmt: skip
    return out, int(sum(x.shape[1] for x in zs[1:]))


def body_drag_residual(
    influences: Mapping[str, CoupledInfluence],
    rho: float,
    loads: Mapping[str, Any],
    motion: Mapping[str, np.ndarray],
    omega: np.ndarray,
    spectra: np.ndarray,
    *,
    cross_terms: bool = True,
    order: int = LUMPED_ORDER,
    stations: Mapping[str, tuple[np.ndarray, np.ndarray]] | None = None,
) -> BodyDragResidual | None:
    """The body drag residual's lines in a group's body DOFs and end tensions (module
    notes; None: no body drag).

    Parameters
    ----------
    influences : mapping of str to CoupledInfluence
        The group's coupled influences, one per line (one shared state).
    rho, loads, motion, omega, spectra
        As :func:`body_drag_components`.
    cross_terms : bool
        Join the lines' drag panels the group's drag residual kept (their cross terms
        with the body's components); False: the body's components alone.
    order : int
        Highest Hermite order of the body's components (the lines' panels of another
        order are not joined).
    stations : mapping of str to (ndarray, ndarray), optional
        Per line its element stations and node stations (indices; either may be
        empty): their tensions and motions are outputs too (``stations``).
    """
    if not influences:
        return None
    base = next(iter(influences.values()))
    key, panels = _panel_sets(influences) if cross_terms else (None, [])
    vector = key is not None and key[0] == "drag_3d"
    comp = body_drag_components(
        base.bodies, rho, loads, motion, omega, spectra, order, by_spectra=not vector
    )
    if comp is None:
        return None
    targets, layout = [], []
    for name, (el, nodes) in (stations or {}).items():
        for kind, idx, cls in (("elements", el, ElementCoupledInfluence),
                               ("nodes", nodes, NodeCoupledInfluence)):  # fmt: skip
            if np.size(idx):
                targets.append(cls(influences[name], np.asarray(idx, dtype=int)))
                layout.append((name, kind))
    t_body = drag_point_transfer(influences, comp.where, comp.w_out, targets)
    if vector:
        out, joined = _vector_sum(influences, comp, t_body, panels, targets)
    else:
        out, joined = _planar_sum(influences, comp, t_body, panels, targets)
    n_l = 2 * len(influences)
    nb = sum(b.n_dof for b in base.bodies)
    ends = {name: out[2 * i : 2 * i + 2] for i, name in enumerate(influences)}
    at, st = n_l + nb, {}
    for (name, kind), target in zip(layout, targets):
        st.setdefault(name, {})[kind] = out[at : at + _rows(target)]
        at += _rows(target)
    body = out[n_l : n_l + nb]
    # a DOF whose part is round-off (a symmetric mooring's sway, roll, yaw) gets none
    total = np.abs(body.sum(axis=1))
    body = np.where((total <= ROUND_OFF * np.max(total, initial=0.0))[:, None], 0.0, body)
    return BodyDragResidual(comp.w_out, body, ends, comp, joined, st)


def with_body_drag(result: Any, own: BodyDragResidual, duration: float) -> Any:
    """``result`` (a line's LineResult on the bodies) with the body drag residual
    ``own``'s lines of its end tensions as one more part of its drag residual record,
    its end statistics and corrected spectra formed again with it, and those of its
    stations added to its element tensions' and node motions' drag residual records
    (:func:`~.group_stations.with_station_parts`); unchanged where the line's drag
    residual is not applied."""
    rec = result.residuals.get("drag_residual")
    if rec is None or not rec.computed or result.linear is None:
        return result
    w = np.asarray(result.omega, dtype=float)
    std = {e: result.linear[e].std for e in ("end_a", "end_b")}
    residuals = dict(result.residuals)
    residuals["drag_residual"] = with_group_lines(rec, own.w_out, own.ends[result.name], w, std)
    applied = [r for r in residuals.values() if r.computed]
    stats = {e: corrected_stats(result.linear[e], e, applied, duration) for e in std}
    spectra = {e: corrected_spectrum(w, result.end_tension_spectrum(e), e, applied) for e in std}
    out = dataclasses.replace(result, residuals=residuals, corrected_spectra=spectra, **stats)
    parts = {
        kind: {"drag_residual": (own.w_out, x)}
        for kind, x in own.stations.get(result.name, {}).items()
    }
    return with_station_parts(out, parts) if parts else out
