"""The lines of a coupled group before the body solve (Tuah 1982, §3.3, §5.3).

Each attached line keeps its own finite-element model with both end nodes prescribed
(:func:`stochcable.dynamics.model.system.build_line_system`); its response is linear in the
motion u_e of its attached end nodes,

    U = U_0 + G u_e,        F_end = R_0 + R_e u_e,

U_0, R_0 with the attached ends held, G, R_e those of unit end motions (the "unit
channels", :func:`stochcable.dynamics.groups.inputs.unit_channels`).  A *line part*
holds them until the body solve has given u_e, then forms the combined response.
Three forms, the same linear system to round-off (tests/dynamics/test_coupled_reduction.py):

- node level (``solver="direct"``, and the reference): the banded direct solve of the
  physical and the unit channels, or under Foss :func:`foss_unit_split` (one Foss
  decomposition; the unit columns' loads ω²·M_T U_p − iω·C U_p in closed form);
- :class:`FossLine` (``solver="foss"``): the line stays in the coordinates of its Foss
  (state) modes; R_0 and R_e need the end nodes and their neighbours only, and the one
  combined response P_0 + P_e u_e is reconstructed on the nodes afterwards;
- :class:`ModalLine` (the coarse stage of the fixed point): the modal equations of the
  kept modes solved per frequency, no Foss eigenproblem.

The lines' Foss decompositions of one evaluation (:func:`foss_state`) may run on a
thread pool, opt-in with ``STOCHCABLE_THREADS`` (:mod:`stochcable.runtime`; the same
bits as serially).

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

from collections.abc import Mapping
from contextvars import ContextVar
from typing import TYPE_CHECKING

import numpy as np

from stochcable.dynamics.groups.freeline import FreeLine
from stochcable.dynamics.groups.inputs import CoupledLine
from stochcable.dynamics.groups.modal_parts import (
    FossLine,
    FossState,
    ModalLine,
    foss_state,
)
from stochcable.dynamics.model.blocks import (
    NodeBlocks,
    block_matvec,
    line_prep,
    real_gemm,
)
from stochcable.dynamics.model.modal_solvers import foss_transfer_modal
from stochcable.dynamics.model.system import Damping, LineSystem
from stochcable.dynamics.solve.line_loads import end_following, end_loads, free_load
from stochcable.dynamics.solve.line_solve import (
    reactions,
    solve_free,
    total_displacement,
)
from stochcable.dynamics.solve.node_inputs import LineInputs
from stochcable.errors import SolverError
from stochcable.runtime import line_map

if TYPE_CHECKING:  # pragma: no cover
    from stochcable.dynamics.groups.group import GroupSystem

__all__ = ["LinePart", "SMALL_MODAL_DOFS", "foss_unit_split", "line_parts"]

#: Below this many free DOFs a line alone whose Foss solve keeps every mode solves its
#: modal equations per frequency (one batched dense LU, :func:`_free_part`) instead of
#: by the Foss eigenproblem at every evaluation: set by a load-case set's chunk
#: (:func:`stochcable.cases.chunk.solve_chunk`), 0 (off) elsewhere, so ``analyze()``
#: keeps its numbers.  The same equations (every mode kept: no static correction), so
#: the same σ to round-off: Tuah's single leg (4 free DOFs) within 2e-14, its linear
#: set's case 0.90 × the Foss solve's (docs/benchmarks/cases.md). [-]
SMALL_MODAL_DOFS: ContextVar[int] = ContextVar("SMALL_MODAL_DOFS", default=0)


def line_parts(
    g: GroupSystem, line_damping: Mapping[str, Damping]
) -> list[tuple[LinePart, np.ndarray, np.ndarray]]:
    """Every line of a group before the body solve.

    Parameters
    ----------
    g : GroupSystem
        The group (:class:`stochcable.dynamics.groups.group.GroupSystem`).
    line_damping : mapping of str to Damping
        Each line's linear drag.

    Returns
    -------
    list of (part, R_0, R_e)
        In line order: the line part (a :class:`FossLine`, a :class:`ModalLine`, a
        :class:`~stochcable.dynamics.groups.freeline.FreeLine` for a line without
        attached ends, or the node-level ``(u, support)`` with the unit columns) and
        its end reactions R_0 (n_w, |rows|, n_ch) [N/unit], R_e (n_w, |rows|, n_e)
        [N/m] on the attached rows.

    Notes
    -----
    The lines are independent until the body solve: their Foss decompositions (the
    LAPACK eigenproblems, GIL released) may run on the thread pool (opt-in,
    :mod:`stochcable.runtime`), the rest serially (many small NumPy steps that hold the
    GIL: pooled they cost more CPU than they overlap, docs/BENCHMARKS.md pass E4);
    the same bits with or without the pool.
    """
    modal = [
        cl
        for cl in g.lines
        if cl.system.solver != "direct" and _MODAL_FOSS and not g.modal_direct and cl.attached()
    ]
    states = (
        dict(
            zip(
                [cl.name for cl in modal],
                line_map(lambda cl: foss_state(cl.system, line_damping[cl.name]), modal),
            )
        )
        if modal
        else {}
    )
    return [_line_part(g, cl, line_damping[cl.name], states.get(cl.name)) for cl in g.lines]


def _line_part(
    g: GroupSystem, cl: CoupledLine, damping: Damping, state: FossState | None = None
) -> tuple[LinePart, np.ndarray, np.ndarray]:
    """One line of :func:`line_parts`; ``state``: the line's :func:`foss_state` when
    already computed."""
    system = cl.system
    rows = g.rows[cl.name]
    n_ch = g.n_ch
    if not cl.attached():  # a line alone: its own response (no end motion to combine)
        part = _free_part(system, g.inp_phys[cl.name], damping, g.modal_direct)
        return (part, *part.reactions(rows))
    if system.solver != "direct" and g.modal_direct:
        part = ModalLine(
            system,
            g.inp_phys[cl.name],
            damping,
            tuple(k for k, _ in cl.attached()),
            g.modal_cache.setdefault(cl.name, {}),
        )
        r0, re = part.reactions(rows)
        return part, r0, re
    if system.solver != "direct" and _MODAL_FOSS:
        try:
            part = FossLine(
                system,
                g.inp_phys[cl.name],
                damping,
                tuple(k for k, _ in cl.attached()),
                state,
                g.foss_cache.setdefault(cl.name, {}),
            )
        except SolverError:  # defective pencil: the plain solve's fallback
            pass
        else:
            r0, re = part.reactions(rows)
            return part, r0, re
    inp = g.inp[cl.name]
    solved = None
    if system.solver != "direct":
        solved = foss_unit_split(system, g.inp_phys[cl.name], inp, damping)
    u_f, c = solve_free(system, inp, damping) if solved is None else solved
    u = total_displacement(system, inp, u_f)
    sup = reactions(system, line_prep(system), c, u, end_loads(system, inp, damping), g.omega)
    return (u, sup), sup[:, rows, :n_ch], sup[:, rows, n_ch:]


def _free_part(
    system: LineSystem, inp: LineInputs, damping: Damping, modal_direct: bool
) -> FreeLine:
    """A line alone (:class:`FreeLine`): by its modal equations per frequency where
    ``modal_direct`` (the coarse stage) or where :data:`SMALL_MODAL_DOFS` asks for it
    (a Foss line keeping every mode, fewer free DOFs than it), else by the Foss
    eigenproblem; the latter also where such a set's solve meets a singular or
    non-finite frequency (the Foss solve's checks then speak)."""
    n_free = system.model.free.size
    small = (
        not modal_direct
        and system.solver == "foss"
        and system.n_modes >= n_free
        and n_free < SMALL_MODAL_DOFS.get()
    )
    if small:
        try:
            part = FreeLine(system, inp, damping, True)
        except np.linalg.LinAlgError:
            pass
        else:
            if np.all(np.isfinite(part.u_free)):
                return part
    return FreeLine(system, inp, damping, modal_direct)


def foss_unit_split(
    system: LineSystem, inp_phys: LineInputs, inp: LineInputs, damping: Damping
) -> tuple[np.ndarray, NodeBlocks] | None:
    """:func:`stochcable.dynamics.solve.line_solve.solve_free` (Foss) of the physical channels plus
    the unit end-motion channels, the unit columns in closed form.

    Parameters
    ----------
    system : LineSystem
    inp_phys : inputs
        The line's inputs of the physical channels.
    inp : inputs
        The same plus the unit end-motion channels (their last columns).
    damping : Damping

    Returns
    -------
    (u, C) or None
        Free-node displacement (n − 2, d, n_w, n_ch + n_e) [m/unit] and the damping
        matrix C = S + C_d; None when the Foss pencil is defective.

    Notes
    -----
    A unit end motion e_j moves the line by the constant U_p,j (the end and its exact
    static following, :func:`stochcable.dynamics.solve.line_loads.base_motion`), so its free-row
    load is ω²·[M_T U_p,j]_f − iω·[C U_p,j]_f: its modal load, its static correction and the
    drag load need no per-frequency products over the nodes; one Foss decomposition
    serves both.  The same linear system as the plain call to round-off; None (use the
    plain call) when the pencil is defective (its fallback and warning).
    """
    prep = line_prep(system)
    w = inp.omega
    n_ch = inp_phys.weights.shape[1]
    n_e = inp.weights.shape[1] - n_ch
    _, c, foss, rc = foss_state(system, damping)
    if foss is None:
        return None
    phi, _, _ = prep.modal(system)
    m, nf = phi.shape[1], phi.shape[0]
    n_w = w.size
    # physical channels: the free-row load of solve_free
    rhs = free_load(system, prep, inp_phys, damping)
    flat = np.ascontiguousarray(prep.free_rows(rhs)).reshape(nf, n_w * n_ch)
    z_p = np.ascontiguousarray(foss_transfer_modal(foss, real_gemm(phi.T, flat), w, n_ch))
    u_p = real_gemm(phi, z_p)
    # unit channels: U_p,j constant (node vectors (n, d, n_e))
    key = ("unit_up", n_ch)
    if key not in inp.cache:
        up = np.ascontiguousarray(end_following(system, prep, inp)[0][:, :, 0, n_ch:].real)
        inp.cache[key] = (up, prep.free_rows(block_matvec(prep.MT, up)))
    up, a = inp.cache[key]
    b = prep.free_rows(block_matvec(c, up))
    ah, bh = phi.T @ a, phi.T @ b  # (m, n_e)
    fe = (w * w)[None, :, None] * ah[:, None, :] - (1j * w)[None, :, None] * bh[
        :, None, :
    ]  # (m, n_w, n_e)
    z_e = np.ascontiguousarray(foss_transfer_modal(foss, fe.reshape(m, n_w * n_e), w, n_e))
    u_e = real_gemm(phi, z_e).reshape(nf, n_w, n_e)
    if rc is not None:
        u_p += prep.residual(system, flat)
        u_p -= real_gemm(rc, z_p * np.repeat(1j * w, n_ch))
        u_e -= real_gemm(rc, z_e * np.repeat(1j * w, n_e)).reshape(nf, n_w, n_e)
        st = prep.residual(system, np.concatenate([a, b], axis=1).astype(complex))
        u_e += (w * w)[None, :, None] * st[:, None, :n_e] - (1j * w)[None, :, None] * st[
            :, None, n_e:
        ]
    u = np.concatenate([u_p.reshape(nf, n_w, n_ch), u_e], axis=2)
    return u.reshape(prep.n - 2, prep.d, n_w, n_ch + n_e), c


#: Foss lines of a group kept in modal coordinates until the body solve
#: (:class:`FossLine`); False: the node-level path of :func:`foss_unit_split` (the
#: reference of the tests, the same linear system).
_MODAL_FOSS = True


#: A line's part of a group solve (:func:`line_parts`).
LinePart = FossLine | ModalLine | FreeLine | tuple[np.ndarray, np.ndarray]
