"""The load assembly of one line (the right-hand side of Tuah (1982), eq. 5.2.6 with
prescribed ends) from its inputs (:class:`~stochcable.dynamics.solve.node_inputs.LineInputs`,
re-exported here with :func:`line_inputs` and :func:`with_spectra`).

:func:`end_following` keeps the drag-independent motion of the ends (and its static
following) per solver; :func:`base_load` and :func:`drag_inputs` form the
drag-independent loads on any block of frequencies (kept for the whole grid only where
they fit the working-memory target); :func:`drag_blocks`, :func:`free_load` and
:func:`end_loads` assemble the drag-dependent loads at every iteration of the drag
fixed point.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import numpy as np

from stochcable.dynamics.loads.channels import Channel
from stochcable.dynamics.loads.freqblocks import whole_grid, working_memory_bytes
from stochcable.dynamics.model.blocks import (
    LinePrep,
    NodeBlocks,
    block_matvec,
    distribute,
    element_blocks,
    element_load,
    real_gemm,
)
from stochcable.dynamics.model.system import (
    Damping,
    LineSystem,
)
from stochcable.dynamics.solve.node_inputs import LineInputs, line_inputs, with_spectra

__all__ = [
    "LineInputs",
    "attached_velocity",
    "base_load",
    "base_motion",
    "drag_blocks",
    "drag_inputs",
    "end_following",
    "end_following_at",
    "end_loads",
    "end_nodes",
    "fluid_loads",
    "free_load",
    "line_inputs",
    "silent_channel",
    "with_spectra",
]


def drag_blocks(system: LineSystem, damping: Damping) -> NodeBlocks:
    """Node blocks of the drag damping C_d (:func:`stochcable.dynamics.loads.channels.drag_matrix`
    on the model components), cached on ``damping`` with its element blocks
    (``damping._cache["elements"]``). [N·s/m]"""
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
                system._cache["eet"] = (
                    eet,
                    np.eye(len(comps))[None] - eet,
                    model.l0[:, None, None],
                )
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
            el = element_blocks(model, b3)
        cache["elements"] = el
        cache["blocks"] = distribute(model, el, damping.b_node)
    return cache["blocks"]


def _drag_load(system: LineSystem, inp: LineInputs, damping: Damping) -> np.ndarray | None:
    """Linearized drag load of the fluid velocity, Σ_el l0·B·∫N_i v dξ + b_node·V_node,
    node vectors (n_nodes, d, n_w, n_ch); None without fluid velocity."""
    if inp.velocity is None and not inp.has_fluid:
        return None
    drag_blocks(system, damping)
    if inp.has_fluid:
        el = damping._cache["elements"]
        f = element_load(el if system.lift is None else el + system.lift, inp.moments)
    else:
        f = np.zeros(inp.velocity.shape, dtype=complex)
    if inp.velocity is not None and np.any(damping.b_node):
        f += damping.b_node[:, None, None, None] * inp.velocity
    return f


def fluid_loads(system: LineSystem, inp: LineInputs, damping: Damping) -> np.ndarray:
    """Fluid loads (drag of the fluid velocity + Morison inertia) on all nodes,
    (n_nodes, d, n_w, n_ch)."""
    f = _drag_load(system, inp, damping)
    return inp.inertia_load if f is None else inp.inertia_load + f


def end_loads(system: LineSystem, inp: LineInputs, damping: Damping) -> np.ndarray:
    """:func:`fluid_loads` at the two end nodes only, (2, d, n_w, n_ch): all that the
    reactions (:func:`reactions`) read of it — element 0's share on node 0, the last
    element's on the last node (the whole-line load was 0.2 ms of the chain)."""
    f = None
    ends = inp.moment_ends()
    if ends is not None:
        drag_blocks(system, damping)
        b = damping._cache["elements"]
        if system.lift is not None:  # the lift of the waves (dynamics.model.lift)
            b = b[[0, -1]] + system.lift[[0, -1]]
        f = np.stack(
            [
                np.einsum("ij,jwc->iwc", b[0], ends[0]),
                np.einsum("ij,jwc->iwc", b[-1], ends[1]),
            ]
        )
    if inp.velocity is not None and np.any(damping.b_node):
        fn = damping.b_node[[0, -1], None, None, None] * inp.velocity[[0, -1]]
        f = fn if f is None else f + fn
    ends = inp.inertia_ends()
    return ends if f is None else ends + f


def end_nodes(inp: LineInputs, n: int, d: int) -> np.ndarray:
    """Node vectors (n_nodes, d, n_w, n_ch): the prescribed end motion at the end nodes,
    zero inside."""
    n_w, n_ch = inp.weights.shape
    x = np.zeros((n, d, n_w, n_ch), dtype=complex)
    if inp.ub is not None:
        x[0] = inp.ub[0]
        x[-1] = inp.ub[1]
    return x


def end_following(system: LineSystem, prep: LinePrep, inp: LineInputs) -> tuple[np.ndarray, bool]:
    """The prescribed motion U_p of :func:`base_load` on all nodes and frequencies,
    (n_nodes, d, n_w, n_ch), and whether an end moves (:func:`end_following_at`; zero
    without end motion)."""
    if inp.ub is None:
        return end_nodes(inp, prep.n, prep.d), False
    return end_following_at(system, prep, inp), True


def end_following_at(
    system: LineSystem,
    prep: LinePrep,
    inp: LineInputs,
    freq: slice = slice(None),
    nodes: np.ndarray | None = None,
) -> np.ndarray | None:
    """The prescribed motion U_p on the frequencies ``freq``, (n_nodes, d, n_f, n_ch)
    (``nodes``: those nodes only), None without end motion:

        direct: U_p = the end motion (zero inside);
        Foss:   U_p = the end motion with the exact static following inside,

    U_p = G u_b with G (n_nodes·d, 2d) the unit end displacements (and their static
    following) of :meth:`~stochcable.dynamics.model.blocks.LinePrep.end_basis`, formed for
    the channels that move an end (the others are zero); the whole grid kept when it
    fits a quarter of the working-memory target. [m/unit]"""
    if inp.ub is None:
        return None
    key = ("following", system.solver)
    if key in inp.cache:
        u = inp.cache[key]
        return (u if nodes is None else u[nodes])[:, :, freq]
    g = prep.end_basis(system.solver == "direct")[0]
    n = prep.n
    if nodes is not None:
        g = g.reshape(n, prep.d, -1)[nodes].reshape(-1, 2 * prep.d)
        n = g.shape[0] // prep.d
    act = _moving_channels(inp)
    ub = inp.ub[:, :, freq] if act is None else inp.ub[:, :, freq][..., act]
    u = real_gemm(g, np.ascontiguousarray(ub.reshape(2 * prep.d, -1)))
    u = u.reshape((n, prep.d) + ub.shape[2:])
    if act is not None:  # back to all channels
        u_all = np.zeros((n, prep.d) + ub.shape[2:-1] + inp.ub.shape[-1:], dtype=complex)
        u_all[..., act] = u
        u = u_all
    whole = whole_grid(freq, inp.omega.size)
    if nodes is None and whole and u.nbytes <= working_memory_bytes() // 4:
        inp.cache[key] = u
    return u


def base_load(
    system: LineSystem, prep: LinePrep, inp: LineInputs, freq: slice = slice(None)
) -> np.ndarray:
    """The drag-independent part F0 of the free-row load on the frequencies ``freq``,
    on all nodes (n_nodes, d, n_f, n_ch): a fresh array, or a view of the whole grid
    kept when it fits a quarter of the working-memory target.

    The load on the free rows is  F0 + F_d(V) + C_d Q  with  Q = −iω U_p
    (:func:`end_following`), F_d(V) the drag load of the fluid velocity integrated
    along the elements (:func:`_drag_load`) and
        direct: F0 = F_I − (K − ω²M_T + iωC_s) U_p,
        Foss:   F0 = F_I − (−ω²M_T + iωC_s) U_p   (K U_p = 0 on the free rows),
    F_I the Morison inertia load (:meth:`LineInputs.inertia_at`)."""
    key = ("base_load", system.solver)
    if key in inp.cache:
        return inp.cache[key][:, :, freq]
    f0 = inp.inertia_at(freq)
    if inp.ub is not None:
        if "inertia" in inp.cache:  # a view of the kept inertia load: not changed
            f0 = f0.copy()
        # M_T U_p, C_s U_p, K U_p as (M_T G) u_b, … — small products with the cached
        # M_T G, C_s G, K G instead of block products of the node vectors
        direct = system.solver == "direct"
        _, mg, sg, kg = prep.end_basis(direct)
        w = inp.omega[freq]
        act = _moving_channels(inp)
        ub = inp.ub[:, :, freq] if act is None else inp.ub[:, :, freq][..., act]
        ubf = np.ascontiguousarray(ub.reshape(2 * prep.d, -1))
        shape = (prep.n, prep.d) + ub.shape[2:]

        def times(b: np.ndarray) -> np.ndarray:
            return real_gemm(b, ubf).reshape(shape)

        dyn = -(w * w)[:, None] * times(mg) + (1j * w)[:, None] * times(sg)
        if direct:
            dyn = dyn + times(kg)
        if act is None:
            f0 -= dyn
        else:
            f0[..., act] -= dyn
    if whole_grid(freq, inp.omega.size) and f0.nbytes <= working_memory_bytes() // 4:
        inp.cache[key] = f0
    return f0


def base_motion(system: LineSystem, prep: LinePrep, inp: LineInputs) -> tuple[np.ndarray, ...]:
    """(U_p, F0, moving) of :func:`end_following` and :func:`base_load` on the whole
    grid (F0 formed for all frequencies: the solves run over blocks of
    :func:`base_load`)."""
    u, moving = end_following(system, prep, inp)
    return u, base_load(system, prep, inp), moving


def _moving_channels(inp: LineInputs) -> np.ndarray | None:
    """Indices of the channels with a nonzero end motion, or None when all have one."""
    moving = np.any(inp.ub.reshape(-1, inp.ub.shape[-1]) != 0, axis=0)
    return None if moving.all() else np.flatnonzero(moving)


def drag_inputs(
    system: LineSystem, prep: LinePrep, inp: LineInputs, freq: slice = slice(None)
) -> tuple[np.ndarray | None, np.ndarray | None]:
    """Drag-independent parts of the drag load on the free rows, F_d(V) + C_d Q of
    :func:`base_motion`, on the frequencies ``freq``: the element moments
    W_s = ∫N_s v dξ + Σ_t P_st Q_t (P the mass pattern of the drag,
    :func:`blocks_of_elements`), so that both terms are ONE element load
    Σ_el l0·B·W (:func:`element_load`), formed per block (not kept: one complex
    number per element end, component, frequency and channel), and the attachment
    velocity V + Q at the nodes (n_nodes, d, n_w, n_ch) (:func:`attached_velocity`);
    None where absent."""
    moving = inp.ub is not None
    moments = inp.moments_at(freq)
    wm = moments
    key = ("drag_moments", system.solver)
    whole = whole_grid(freq, inp.omega.size)
    if moving and whole and key in inp.cache:
        wm = inp.cache[key]
    elif moving:
        pat = (
            np.array([[0.5, 0.0], [0.0, 0.5]])
            if system.model.mass_matrix == "lumped"
            else np.array([[1.0 / 3.0, 1.0 / 6.0], [1.0 / 6.0, 1.0 / 3.0]])
        )
        act = _moving_channels(inp)  # Q = 0 for the others: W = the moments
        u = end_following_at(system, prep, inp, freq)
        qa = u if act is None else u[..., act]
        qa = qa * (-1j * inp.omega[freq])[:, None]  # Q = −iω U_p
        w_q = np.empty((prep.n - 1, 2) + qa.shape[1:], dtype=complex)
        for side in range(2):
            np.multiply(pat[side, 0], qa[:-1], out=w_q[:, side])
            w_q[:, side] += pat[side, 1] * qa[1:]
        if moments is not None:
            w_q += moments if act is None else moments[..., act]
        if act is None:
            wm = w_q
        else:
            wm = (
                moments.copy()
                if moments is not None
                else np.zeros((prep.n - 1, 2) + u.shape[1:], dtype=complex)
            )
            wm[..., act] = w_q
        if whole and wm.nbytes <= working_memory_bytes() // 4:
            # drag-independent: kept for the next evaluations (and the next sea
            # states of the heading, :func:`with_spectra`) when small
            inp.cache[key] = wm
    vq = attached_velocity(system, prep, inp)
    return wm, None if vq is None else vq[:, :, freq]


def attached_velocity(system: LineSystem, prep: LinePrep, inp: LineInputs) -> np.ndarray | None:
    """The fluid velocity plus Q = −iω U_p at the nodes (n_nodes, d, n_w, n_ch), what
    the attachments' drag loads (None without fluid velocity and end motion), cached
    per inputs and solver (formed only for a line with attachment drag areas when it
    moves)."""
    key = ("attached_velocity", system.solver)
    if key not in inp.cache:
        vq = inp.velocity
        if inp.ub is not None and system.drag_nodes.size:  # V + Q: attachments only
            q = (-1j * inp.omega)[:, None] * end_following(system, prep, inp)[0]
            vq = q if vq is None else vq + q
        inp.cache[key] = vq
    return inp.cache[key]


def free_load(
    system: LineSystem,
    prep: LinePrep,
    inp: LineInputs,
    damping: Damping,
    freq: slice = slice(None),
) -> np.ndarray:
    """The load of :func:`solve_free`, F0 + F_d(V) + C_d Q (:func:`base_load`), on all
    nodes (n_nodes, d, n_w, n_ch), a fresh array; ``freq`` selects a block of the
    frequencies (:mod:`stochcable.dynamics.loads.freqblocks`).

    F_d(V) = Σ_el l0·B·∫N_i v dξ is formed per channel with a fluid velocity from its
    moments (:meth:`LineInputs.fluid_block`), the elements' part of C_d Q as
    (C_d G)(−iω u_b) with U_p = G u_b (:func:`end_following_at`; C_d G a small
    (n_nodes·d, 2d) matrix per drag) and the attachments' b·(V + Q) at their nodes:
    the same sums as one element load of the moments W = ∫N v dξ + P Q
    (:func:`drag_inputs`) to round-off, without forming W."""
    kept = ("base_load", system.solver) in inp.cache
    if kept:  # (a view of the kept F0)
        rhs = base_load(system, prep, inp, freq).copy()
    else:  # F_I, the end motion's part of F0 below with C_d Q
        rhs = inp.inertia_at(freq)
        if "inertia" in inp.cache:
            rhs = rhs.copy()  # (a view of the kept inertia load)
    drag_blocks(system, damping)
    el = damping._cache["elements"]
    for i, f in enumerate(inp.fluid):
        if f is not None:
            mom = inp.fluid_block(i, freq)
            rhs[..., i] += element_load(el, mom)
            if system.lift is not None:  # the lift of the waves (dynamics.model.lift)
                rhs[..., i] += element_load(system.lift, mom)
    if inp.ub is not None:
        act = _moving_channels(inp)
        ub = inp.ub[:, :, freq] if act is None else inp.ub[:, :, freq][..., act]
        w = inp.omega[freq][:, None]
        # the end motion's loads as ONE product of a (n_nodes·d, ·) basis per drag:
        # M_T G (ω² u_b) + (C_s + C_d) G (−iω u_b) − K G u_b (the last for the direct
        # solve), or C_d G (−iω u_b) alone beside a kept F0
        h = _end_load_basis(system, prep, damping, el, kept)
        parts = [-1j * w * ub] if kept else [w * w * ub, -1j * w * ub]
        if h.shape[1] > 2 * prep.d * len(parts):  # (direct: − K G u_b)
            parts.append(-ub)
        x = np.ascontiguousarray(np.concatenate(parts, axis=0).reshape(h.shape[1], -1))
        q = real_gemm(h, x).reshape((prep.n, prep.d) + ub.shape[2:])
        if act is None:
            rhs += q
        else:
            rhs[..., act] += q
    vq = attached_velocity(system, prep, inp)
    if vq is not None and np.any(damping.b_node):
        rhs += damping.b_node[:, None, None, None] * vq[:, :, freq]
    return rhs


def _end_load_basis(
    system: LineSystem, prep: LinePrep, damping: Damping, el: np.ndarray, kept: bool
) -> np.ndarray:
    """[M_T G, (C_s + C_d) G (, K G)] (n_nodes·d, 4d or 6d), or C_d G alone (``kept``):
    the end motion's loads of :func:`free_load` per unit (ω² u_b, −iω u_b (, −u_b)),
    cached on ``damping`` (C_d G: the elements' drag, the attachments' in
    :func:`attached_velocity`)."""
    direct = system.solver == "direct"
    key = ("end_load_basis", system.solver, kept)
    if key not in damping._cache:
        g, mg, sg, kg = prep.end_basis(direct)
        dg = block_matvec(distribute(system.model, el, None), g.reshape(prep.n, prep.d, -1))
        dg = dg.reshape(prep.n * prep.d, -1)
        parts = [dg] if kept else [mg, sg + dg] + ([kg] if direct else [])
        damping._cache[key] = np.ascontiguousarray(np.concatenate(parts, axis=1))
    return damping._cache[key]


def silent_channel(omega: np.ndarray) -> tuple[Channel, ...]:
    """A zero-spectrum channel so a line without excitation still gets (zero) outputs."""

    def zero(w: np.ndarray) -> np.ndarray:
        return np.zeros_like(np.asarray(w, dtype=float))

    return (Channel(name="none", kind="none", omega=omega, spectrum=zero(omega), density=zero),)
