"""The residuals of a line on free bodies: its residual loads through the coupled (lines
and bodies) system instead of the line with its ends held.

The closed-form residuals (:mod:`.drag_residual`, :mod:`.drag_residual_3d`,
:mod:`.geometric_residual`) reach the end tensions through the line's end influence,
the end tension per unit force on every node (:func:`.residual_lines.end_influence`,
ends held).  On a line of a coupled group the ends attached to free bodies move:
a load F on the line changes the support forces R = G_R F (ends held), which load the
bodies, which move the attached ends by T ξ and change every support force by
R_e T ξ.  With the group's body equation condensed as in the group solve (Tuah
1982, eqs. 3.2.c.20, 3.3.8–3.3.10; :mod:`stochcable.dynamics.groups.group`),

    S ξ = T_Lᵀ (G_R F)_att,   S = Z_B + iω C_drag − Σ_ℓ T_ℓᵀ R_e,ℓ T_ℓ,

the line's coupled support forces are (I + R_e,L T_L S⁻¹ T_Lᵀ E_att) G_R F and its
end tensions ê·R (:class:`CoupledInfluence`, the coupled end influence of the same
shape).  Both G_R and R_e come from one factorization per frequency and line: the
adjoint solves x_i = A⁻¹ Z_f,end e_i for the 2d end components (A the free–free
impedance, symmetric), G_R = [e_i on the end node; −x_i on the free nodes] and
R_e,ij = (Z_f,end e_i)ᵀ x_j − Z_end,end,ij.

The residual loads of the group's other lines reach a line's ends as well, through the
bodies (the ``target`` form: R_e,L T_L S⁻¹ T_Sᵀ (G_R,S F)_att).  The drag residuals
(:mod:`.drag_residual`, :mod:`.drag_residual_3d`) take all the lines' panels as one set
of jointly Gaussian components with every line's end tensions as outputs
(:meth:`CoupledInfluence.joint_lines`, formed once for the group): the cross terms
between panels of different lines follow Mehler's formula with their
cross-correlation like any pair of one line (the lines' velocities are correlated
through the common sea and the common body motion, not independent: on a planar
two-leg buoy the cross terms move a leg's part by −10 to −14 %, Monte Carlo agrees).
The linear misfit loads of every line are summed through their influences
(:meth:`CoupledInfluence.sources`) before the variance is formed.  A line's own lines
stay its record's first part (its element tensions' own records carry its own loads,
the others' reach them as the group's part of :mod:`.group_motion`, which also gives
the bodies' DOFs as more rows of these joint sums); the group's part is one more
(:func:`with_group_lines`).  The geometric residual
(:mod:`.geometric_residual`) joins the lines' quadratic forces alike.

Validation: against the assembled coupled system (:func:`stochcable.bodies.coupling.couple`,
:func:`stochcable.reference.bodies.solve_coupled_direct`) loaded by unit node forces
(tests/dynamics/test_body_residual.py).

Scope: lines that do not travel (no gyroscopic term) and have no steady lift.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from stochcable.bodies.rigid import (
    RigidBody,
    attachment_geometric_stiffness,
    rigid_link_matrix,
)
from stochcable.dynamics.linearization.bodydrag import body_drag_matrix
from stochcable.dynamics.loads.freqblocks import frequency_slices
from stochcable.dynamics.model.blocks import add_blocks, free_band, line_prep
from stochcable.dynamics.model.solvers import solve_band_stacked
from stochcable.dynamics.residuals.residual_lines import RESIDUAL_TAP
from stochcable.dynamics.solve.line_loads import drag_blocks
from stochcable.dynamics.solve.line_solve import end_tension_from_support
from stochcable.results.records import ResidualRecord

__all__ = [
    "CoupledInfluence",
    "GroupLine",
    "coupled_influences",
    "end_solves",
    "end_tension_rows",
    "untapped",
    "with_group_lines",
]

#: Grids whose group solves (:meth:`CoupledInfluence._state`) a group keeps: the drag
#: residual's lines, a cell sub-sample and the analysis grid of the misfit. [-]
_KEPT_GRIDS = 3


@dataclass(frozen=True, eq=False)
class GroupLine:
    """A line of a coupled group as the coupled influence reads it.

    Attributes
    ----------
    name : str
    system : LineSystem
        The line (both end nodes prescribed).
    damping : Damping
        Its converged linear drag.
    attached : tuple of (int, str)
        Its ends on free bodies: (0 for end_a, 1 for end_b; the body's name).
    channels : tuple of Channel
        Its inputs, the group's channels in the group order (empty: its residual loads
        are not given to the other lines).
    linearization : Linearization, optional
        Its converged fixed point (None: as empty ``channels``).
    """

    name: str
    system: Any
    damping: Any
    attached: tuple[tuple[int, str], ...]
    channels: tuple[Any, ...] = ()
    linearization: Any = None


def end_solves(system: Any, damping: Any, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The line's end adjoint solves and end impedance on ``w`` (module notes).

    Parameters
    ----------
    system : LineSystem
        A line without gyroscopic term.
    damping : Damping
        Its linear drag.
    w : ndarray, shape (n_w,)
        Frequencies. [rad/s]

    Returns
    -------
    x : ndarray, complex, shape (n_w, n_nodes − 2, d, 2d)
        x_i = A⁻¹ Z_f,end e_i of each end component i (end_a's then end_b's). [-]
    r_e : ndarray, complex, shape (n_w, 2d, 2d)
        Support forces per unit end motion, the other ends held (the group solve's
        R_e). [N/m]
    """
    model = system.model
    prep = line_prep(system)
    d, n = model.dim, model.n_nodes
    cd = drag_blocks(system, damping)
    c = add_blocks(prep.S, cd)
    b_c = prep.bS + free_band(cd)
    x_all = np.zeros((w.size, n - 2, d, 2 * d), dtype=complex)
    r_e = np.zeros((w.size, 2 * d, 2 * d), dtype=complex)
    for sl in frequency_slices(w.size, 16 * 16 * n * d * d):
        ws = w[sl]
        ww, iw = (ws * ws)[:, None, None], (1j * ws)[:, None, None]
        rhs = np.zeros((ws.size, (n - 2) * d, 2 * d), dtype=complex)
        zee = np.zeros((ws.size, 2 * d, 2 * d), dtype=complex)
        for k, (node, rows, tr) in enumerate(
            ((0, slice(0, d), False), (-1, slice((n - 3) * d, None), True))
        ):
            kk, mm, cc = (blk[1][node].T if tr else blk[1][node] for blk in (prep.K, prep.MT, c))
            cols = slice(k * d, (k + 1) * d)
            rhs[:, rows, cols] = kk[None] - ww * mm[None] + iw * cc[None]  # Z_f,end
            kd, md, cdg = (blk[0][node] for blk in (prep.K, prep.MT, c))
            zee[:, cols, cols] = kd[None] - ww * md[None] + iw * cdg[None]
        x = solve_band_stacked(
            prep.bK, prep.bM, b_c, rhs, ws, 2 * d - 1, 2 * d - 1, (model.K, model.M)
        )  # (n_w, (n − 2)·d, 2d)
        x_all[sl] = x.reshape(ws.size, n - 2, d, 2 * d)
        r_e[sl] = np.swapaxes(rhs, 1, 2) @ x - zee
    return x_all, r_e


def end_tension_rows(system: Any) -> np.ndarray:
    """The end tensions (end_a, end_b) per unit support force (end_a's d components
    then end_b's), shape (2, 2d): the dynamic change of the magnitude of each support
    force (:func:`~stochcable.dynamics.solve.line_solve.end_tension_from_support`). [N/N]"""
    d = system.model.dim
    ten = end_tension_from_support(system, np.eye(2 * d)[None].astype(complex))
    return np.real(np.stack([ten["end_a"][:, 0], ten["end_b"][:, 0]]))


class CoupledInfluence:
    """The end influence of one line of a coupled group (module notes): end tensions
    (of this line, or of another ``target`` line) per unit force on each node and
    component of this line, through the group.

    Parameters
    ----------
    name : str
        The line.
    lines : sequence of GroupLine
        Every line of the group (the line among them).
    bodies : sequence of RigidBody
        The group's free bodies at their static pose.
    body_drag : mapping of str to ndarray, shape (3,)
        Linear drag per direction of each body with a drag area. [N·s/m]
    target : str, optional
        The line whose end tensions are the outputs (default ``name``: its own); another
        line of the group is reached through the bodies only.

    Notes
    -----
    :meth:`on` keeps the grid it was first asked for (the drag residual's output lines)
    and serves a leading part of it (the geometric residual's) from it; other grids
    (the cell sub-samples, the analysis grid of a misfit) are computed afresh.
    """

    def __init__(
        self,
        name: str,
        lines: Sequence[GroupLine],
        bodies: Sequence[RigidBody],
        body_drag: Mapping[str, np.ndarray],
        target: str | None = None,
        shared: dict[str, Any] | None = None,
    ) -> None:
        self.name = name
        self.target = name if target is None else target
        self.lines = tuple(lines)
        self.line = next(ln for ln in self.lines if ln.name == name)
        self.bodies = tuple(bodies)
        self.body_drag = dict(body_drag)
        # (the group's solves per grid and the lines' residual components, shared by
        # the influences of one group)
        self.shared: dict[str, Any] = {} if shared is None else shared
        self._kept: tuple[np.ndarray, np.ndarray] | None = None

    def sources(self) -> list[tuple[GroupLine, CoupledInfluence]]:
        """The group's other lines whose loads reach this line's end tensions (an end on
        a body, channels and linearization given), each with the coupled influence of
        its node forces on this line's end tensions (``target`` this line)."""
        if not self.line.attached:
            return []
        return [
            (
                ln,
                CoupledInfluence(
                    ln.name, self.lines, self.bodies, self.body_drag, self.name, self.shared
                ),
            )  # fmt: skip
            for ln in self.lines
            if ln.name != self.name and ln.attached and ln.channels and ln.linearization
        ]

    def joint_lines(
        self,
        key: Any,
        components: Callable[[GroupLine], Any],
        transfer: Callable[[GroupLine, Any, CoupledInfluence], np.ndarray],
        outputs: Callable[[list[Any], np.ndarray], np.ndarray],
    ) -> tuple[np.ndarray, list[tuple[GroupLine, Any, CoupledInfluence]]] | None:
        """A residual's variance lines of this line's end tensions from the panels of
        every line of the group that ``components`` gives (None: a line left out), as
        one set of components, formed once for every line of the group and kept on it
        (``key``: the residual and its options).

        ``transfer(source, its components, influence)`` gives the source's end
        tensions of the influence's target per unit component, (2, n_comp, …);
        ``outputs(components, transfer)`` the variance lines of the stacked outputs,
        (2·n_lines, n_o), from the sources' transfers concatenated along axis 1.
        Returns (the lines (2, n_o), the other sources with their components and
        influence on this line), or None where this line is not among them (or alone).
        """
        joint = self.shared.setdefault("joint", {})
        if key not in joint:
            kept = self.shared.setdefault("components", {})
            parts = []
            for ln in self.lines:
                if not (ln.attached and ln.channels and ln.linearization):
                    continue
                if (key, ln.name) not in kept:
                    kept[key, ln.name] = components(ln)
                if kept[key, ln.name] is not None:
                    parts.append((ln, kept[key, ln.name]))
            if len(parts) < 2:
                joint[key] = {}
            else:
                infl = {
                    (src.name, tgt.name): CoupledInfluence(
                        src.name, self.lines, self.bodies, self.body_drag, tgt.name, self.shared
                    )
                    for src, _ in parts
                    for tgt, _ in parts
                }
                h = np.concatenate(
                    [
                        np.concatenate(
                            [transfer(src, c, infl[src.name, tgt.name]) for src, c in parts], 1
                        )
                        for tgt, _ in parts
                    ]
                )
                # (more output rows a registered hook asks for: group_motion.BodyRows)
                rows = self.shared.get("extra_rows")
                more = [] if rows is None else rows.transfers(key, parts, transfer, h)
                lines = outputs([c for _, c in parts], np.concatenate([h, *more]))
                if more:
                    rows.keep(key, lines[h.shape[0] :], outputs)
                    lines = lines[: h.shape[0]]
                joint[key] = {
                    tgt.name: (
                        lines[2 * i : 2 * i + 2],
                        [(s_, c, infl[s_.name, tgt.name]) for s_, c in parts if s_ is not tgt],
                    )
                    for i, (tgt, _) in enumerate(parts)
                }
        return joint[key].get(self.name)

    def on(self, w: np.ndarray) -> np.ndarray:
        """The coupled influence on ``w``, shape (2, n_nodes, d, n_w). [N/N]"""
        w = np.asarray(w, dtype=float)
        kept = self._kept
        if kept is not None and w.size <= kept[0].size and np.array_equal(kept[0][: w.size], w):
            return kept[1][..., : w.size]
        g = self.compute(w)
        if kept is None:
            self._kept = (w.copy(), g)
        return g

    def compute(self, w: np.ndarray) -> np.ndarray:
        """The coupled influence on ``w`` (not kept), shape (2, n_nodes, d, n_w). [N/N]"""
        w = np.asarray(w, dtype=float)
        off, s, links, solved = self._state(w)
        if self.name not in solved:  # (a line on no body: its own solve)
            solved[self.name] = end_solves(self.line.system, self.line.damping, w)
        system = self.line.system
        d, n = system.model.dim, system.model.n_nodes
        x = solved[self.name][0]
        t, att = links[self.name]
        target = next(ln for ln in self.lines if ln.name == self.target).system
        e_hat = end_tension_rows(target)
        y = np.zeros((w.size, 2, 2 * d), dtype=complex)
        if self.target == self.name:
            y += e_hat[None]
        t_l, att_l = links[self.target]
        if att.size and att_l.size:
            free = np.array([off[b.name] + i for b in self.bodies for i in b.free_index], int)
            tf = t[:, free]
            xi = np.linalg.solve(s[:, free[:, None], free[None, :]], np.broadcast_to(
                tf.T, (w.size,) + tf.T.shape))  # fmt: skip
            p = solved[self.target][1][:, :, att_l] @ t_l[:, free][None] @ xi  # (n_w, 2d, |att|)
            y[:, :, att] += e_hat[None] @ p
        # G_R: e_i on the end nodes, −x_i on the free nodes
        g = np.zeros((2, n, d, w.size), dtype=complex)
        g[:, 0] = np.transpose(y[:, :, :d], (1, 2, 0))
        g[:, -1] = np.transpose(y[:, :, d:], (1, 2, 0))
        g[:, 1:-1] = -np.einsum("wei,wnki->enkw", y, x)
        return g

    def _state(self, w: np.ndarray) -> tuple[dict[str, int], np.ndarray, dict, dict]:
        """The group's body offsets, condensed body impedance S, links and the attached
        lines' end solves on ``w``, shared by the group's influences (the last
        :data:`_KEPT_GRIDS` grids)."""
        cache = self.shared.setdefault("state", {})
        key = w.tobytes()
        if key in cache:
            return cache[key]
        off, nb = {}, 0
        for b in self.bodies:
            off[b.name] = nb
            nb += b.n_dof
        by_name = {b.name: b for b in self.bodies}
        s = self._body_impedance(w, off, nb)
        links, solved = {}, {}
        for ln in self.lines:
            t, att = self._link(ln, by_name, off, nb)
            links[ln.name] = (t, att)
            if not att.size:
                continue
            x, r_e = end_solves(ln.system, ln.damping, w)
            solved[ln.name] = (x, r_e)
            s = s - t.T[None] @ r_e[:, att[:, None], att[None, :]] @ t[None]
        if len(cache) >= _KEPT_GRIDS:
            cache.pop(next(iter(cache)))
        cache[key] = (off, s, links, solved)
        return cache[key]

    def _body_impedance(self, w: np.ndarray, off: dict[str, int], nb: int) -> np.ndarray:
        """Z_B + iω C_drag of the bodies with the lines' attachment geometric stiffness,
        (n_w, nb, nb), before the lines are condensed (as the group solve's)."""
        kb, mb, cb = np.zeros((nb, nb)), np.zeros((nb, nb)), np.zeros((nb, nb))
        a = np.zeros((w.size, nb, nb))
        bb = np.zeros((w.size, nb, nb))
        for b in self.bodies:
            sl = slice(off[b.name], off[b.name] + b.n_dof)
            kb[sl, sl] = b.hydrostatic_stiffness + b.extra_stiffness
            mb[sl, sl] = b.mass_matrix()
            cb[sl, sl] = b.extra_damping
            if b.name in self.body_drag and np.any(b.drag_area > 0):
                cb[sl, sl] += body_drag_matrix(b, np.asarray(self.body_drag[b.name], float))
            a[:, sl, sl] = b.added_mass_at(w)
            bb[:, sl, sl] = b.radiation_damping_at(w)
        for ln in self.lines:
            model, st = ln.system.model, ln.system.statics
            for k, bname in ln.attached:
                body = next(b for b in self.bodies if b.name == bname)
                node = 0 if k == 0 else model.n_nodes - 1
                r = model.positions[node] - body.position
                f = np.asarray(st.force_a if k == 0 else st.force_b, dtype=float)
                sl = slice(off[bname], off[bname] + body.n_dof)
                kb[sl, sl] += attachment_geometric_stiffness(f, r, body.planar)
        w2 = (w * w)[:, None, None]
        return kb[None] - w2 * (mb[None] + a) + (1j * w)[:, None, None] * (cb[None] + bb)

    @staticmethod
    def _link(
        ln: GroupLine, by_name: Mapping[str, RigidBody], off: Mapping[str, int], nb: int
    ) -> tuple[np.ndarray, np.ndarray]:
        """The rigid links T (d·n_att, nb) of a line's attached ends and their rows
        among its 2d support forces."""
        model = ln.system.model
        d = model.dim
        t = np.zeros((d * len(ln.attached), nb))
        rows = []
        for i, (k, bname) in enumerate(ln.attached):
            body = by_name[bname]
            node = 0 if k == 0 else model.n_nodes - 1
            tl = rigid_link_matrix(model.positions[node] - body.position, planar=body.planar)
            t[i * d : (i + 1) * d, off[bname] : off[bname] + body.n_dof] = tl
            rows.extend(range(k * d, (k + 1) * d))
        return t, np.asarray(rows, dtype=int)


def coupled_influences(
    lines: Sequence[Any],
    bodies: Sequence[RigidBody],
    dampings: Mapping[str, Any],
    body_drag: Mapping[str, np.ndarray],
    linearizations: Mapping[str, Any] | None = None,
) -> dict[str, CoupledInfluence]:
    """The coupled influence of every line of a group (none for a group with a
    travelling line or a line with a steady lift: not covered).

    Parameters
    ----------
    lines : sequence
        The group's lines (``name``, ``system`` and ``attached()`` as
        :class:`stochcable.dynamics.groups.inputs.CoupledLine`).
    bodies : sequence of RigidBody
    dampings : mapping of str to Damping
        The converged linear drag of each line.
    body_drag : mapping of str to ndarray, shape (3,)
        The bodies' linear drag. [N·s/m]
    linearizations : mapping of str to Linearization, optional
        The lines' converged fixed points: with them (and the lines' ``channels``) the
        residual loads of every line reach the others' end tensions
        (:meth:`CoupledInfluence.sources`); without, each line carries its own.

    Returns
    -------
    dict of str to CoupledInfluence
    """
    if any(cl.system.gyro is not None or cl.system.lift is not None for cl in lines):
        return {}
    lin = {} if linearizations is None else linearizations
    group = [
        GroupLine(cl.name, cl.system, dampings[cl.name], tuple(cl.attached()),
                  tuple(cl.channels) if cl.name in lin else (), lin.get(cl.name))
        for cl in lines
    ]  # fmt: skip
    shared: dict[str, Any] = {}
    return {ln.name: CoupledInfluence(ln.name, group, bodies, body_drag, shared=shared)
            for ln in group}  # fmt: skip


def with_group_lines(
    record: ResidualRecord,
    w_out: np.ndarray,
    lines: np.ndarray,
    w: np.ndarray,
    std: dict[str, float],
) -> ResidualRecord:
    """``record`` (a line's own residual) with the variance lines ``lines`` (end_a,
    end_b) at ``w_out`` the group's other lines add through the bodies (their panels
    and the cross terms with this line's) as one more part of its ``lines``; the
    variances and in-band parts summed. [N²]"""
    keep = (w_out >= w[0] * (1 - 1e-9)) & (w_out <= w[-1] * (1 + 1e-9))
    ends = ("end_a", "end_b")
    variance = {e: record.variance[e] + float(lines[k].sum()) for k, e in enumerate(ends)}
    in_band = {e: record.in_band[e] + float(lines[k][keep].sum()) for k, e in enumerate(ends)}
    part = (np.asarray(w_out, dtype=float), {e: lines[k] for k, e in enumerate(ends)})
    return ResidualRecord.from_variances(
        variance, in_band, std, record.order, record.panels, record.lines + (part,)
    )


@contextlib.contextmanager
def untapped() -> Iterator[None]:
    """No :data:`~stochcable.dynamics.residuals.residual_lines.RESIDUAL_TAP` inside:
    another line's loads, and the group's joint sums, are not a line's own (its element
    tensions' records take its own loads; the group's part: :mod:`.group_motion`)."""
    token = RESIDUAL_TAP.set(None)
    try:
        yield
    finally:
        RESIDUAL_TAP.reset(token)
