"""The inputs of one line in the node layout and its load assembly (the right-hand
side of seed 001 eq. 5.2.6 with prescribed ends).

:func:`line_inputs` turns the channels (:class:`~stochcable.dynamics.loads.Channel`:
sea, end motions) into node-layout arrays (:class:`LineInputs`: fluid velocity, exact
Morison inertia load, end displacements, consistent element moments of the wave
velocity); :func:`base_motion` and :func:`drag_inputs` cache their drag-independent
parts per solver; :func:`drag_blocks`, :func:`free_load` and :func:`end_loads`
assemble the drag-dependent loads at every iteration of the drag fixed point.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from stochcable.dynamics.blocks import (
    LinePrep,
    NodeBlocks,
    block_matvec,
    distribute,
    element_blocks,
    element_load,
    line_prep,
    real_gemm,
    trapezoid_weights,
)
from stochcable.dynamics.freqblocks import working_memory_bytes
from stochcable.dynamics.loads import (
    Channel,
    element_mean_square,
    element_moments,
    inertia_blocks,
)
from stochcable.dynamics.system import (
    Damping,
    LineSystem,
)


@dataclass(frozen=True, eq=False)
class LineInputs:
    """Channel data in the node layout (n_nodes, d, n_w, n_ch)."""

    omega: np.ndarray
    velocity: np.ndarray | None  # fluid velocity at the nodes (attachments)
    inertia_load: np.ndarray  # Morison inertia load, exact along the elements
    ub: np.ndarray | None  # prescribed end displacement, (2, d, n_w, n_ch)
    weights: np.ndarray  # trapezoid weight x spectrum, (n_w, n_ch)
    moments: np.ndarray | None = None  # ∫N_i v dξ, (n_el, 2, d, n_w, n_ch)
    square: np.ndarray | None = None  # Σ weight·∫Re(v vᴴ)dξ, (n_el, d, d)
    cache: dict = field(default_factory=dict)  # drag-independent loads per solver


def _inertia_elements(system: LineSystem) -> tuple[np.ndarray, np.ndarray]:
    """Morison inertia l0·ρ(πD²/4)(1 + Can)(I − eeᵀ) per element on the model
    components (n_el, d, d) and the attachments' (buoyancy/g + added mass) (n_nodes,)."""
    if "inertia_el" not in system._cache:
        blocks, node = inertia_blocks(system.model, system.environment.g, system.frames[0])
        system._cache["inertia_el"] = (element_blocks(system.model, blocks), node)
    return system._cache["inertia_el"]


def line_inputs(system: LineSystem, channels: tuple[Channel, ...]) -> LineInputs:
    """The channels of a line in the node layout (:class:`LineInputs`), sampled on the
    channels' common grid: fluid velocity at the attachment nodes, Morison inertia load
    (exact along the elements, seed 001 eq. 5.2.6), end displacements, trapezoid ×
    spectrum weights and the consistent element moments of the fluid velocity."""
    model = system.model
    prep = line_prep(system)
    comps = list(model.components)
    w = channels[0].omega
    n_w, n_ch = w.size, len(channels)
    shape = (model.n_nodes, model.dim, n_w, n_ch)
    weights = trapezoid_weights(w)[:, None] * np.stack([c.spectrum for c in channels], axis=1)
    vel = None
    mom = None
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
        if ch.element_velocity is not None:
            # exact along the elements: l0·C_I(I − eeᵀ)·iω∫N_i v dξ, plus attachments
            inertia[..., i] = element_load(b_in, mom[..., i] * (1j * w))
            if np.any(node_mass) and ch.acceleration is not None:
                inertia[..., i] += node_mass[:, None, None] * np.transpose(
                    ch.acceleration[..., comps], (1, 2, 0)
                )
        elif ch.acceleration is not None:  # hand-built channel: nodal interpolation
            acc = np.transpose(ch.acceleration[..., comps], (1, 2, 0))[..., None]
            inertia[..., i] = block_matvec(prep.BI, acc)[..., 0]
    ub = None
    for i, ch in enumerate(channels):
        for k, m in enumerate((ch.motion_a, ch.motion_b)):
            if m is not None and np.any(m):
                if ub is None:
                    ub = np.zeros((2, model.dim, n_w, n_ch), dtype=complex)
                ub[k, :, :, i] = m[:, comps].T
    return LineInputs(w, vel, inertia, ub, weights, mom, _weighted_square(model, channels, weights))


def _weighted_square(
    model: Any, channels: tuple[Channel, ...], weights: np.ndarray
) -> np.ndarray | None:
    """Σ_i weight_i·∫Re(v vᴴ)dξ over the channels with a fluid velocity, on the model
    components, (n_el, d, d) (None without fluid velocity)."""
    comps = np.array(model.components)
    square = None
    for i, ch in enumerate(channels):
        if ch.element_velocity is None and ch.velocity is None:
            continue
        # the d × d part in one gather (two chained ones were 0.1-0.4 ms)
        sq = element_mean_square(ch)[:, :, comps[:, None], comps]
        sq = np.einsum("weij,w->eij", sq, weights[:, i])
        square = sq if square is None else square + sq
    return square


#: Caches of :class:`LineInputs` that do not depend on the channels' spectra (kept by
#: :func:`with_spectra`): the base motion per solver, the end-motion projections and
#: the attachments' velocity.  Every other cache is formed again.
def _spectrum_free(key: Any) -> bool:
    return key in ("foss", "direct") or (
        isinstance(key, tuple) and key[0] in ("qproj", "attached_velocity", "drag_moments")
    )


def with_spectra(system: LineSystem, inp: LineInputs, channels: tuple[Channel, ...]) -> LineInputs:
    """The inputs of ``channels`` when ``inp`` are those of channels with the same
    transfer functions (kinematics, end motions, grid) under other spectra: the arrays
    and the spectrum-independent caches shared, the weights and the weighted mean
    square formed for the new spectra.  The same numbers as :func:`line_inputs` of
    ``channels``."""
    w = channels[0].omega
    weights = trapezoid_weights(w)[:, None] * np.stack([c.spectrum for c in channels], axis=1)
    out = LineInputs(
        inp.omega,
        inp.velocity,
        inp.inertia_load,
        inp.ub,
        weights,
        inp.moments,
        _weighted_square(system.model, channels, weights),
    )
    out.cache.update({k: v for k, v in inp.cache.items() if _spectrum_free(k)})
    return out


def drag_blocks(system: LineSystem, damping: Damping) -> NodeBlocks:
    """Node blocks of the drag damping C_d (:func:`stochcable.dynamics.loads.drag_matrix`
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
    if inp.velocity is None and inp.moments is None:
        return None
    drag_blocks(system, damping)
    if inp.moments is not None:
        f = element_load(damping._cache["elements"], inp.moments)
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
    if inp.moments is not None:
        drag_blocks(system, damping)
        b = damping._cache["elements"]
        f = np.stack(
            [
                np.einsum("ij,jwc->iwc", b[0], inp.moments[0, 0]),
                np.einsum("ij,jwc->iwc", b[-1], inp.moments[-1, 1]),
            ]
        )
    if inp.velocity is not None and np.any(damping.b_node):
        fn = damping.b_node[[0, -1], None, None, None] * inp.velocity[[0, -1]]
        f = fn if f is None else f + fn
    ends = inp.inertia_load[[0, -1]]
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


def base_motion(system: LineSystem, prep: LinePrep, inp: LineInputs) -> tuple[np.ndarray, ...]:
    """Drag-independent parts of the free-row load, cached per inputs and solver.

    The load on the free rows is  F0 + F_d(V) + C_d Q  with  Q = −iω U_p, F_d(V) the
    drag load of the fluid velocity integrated along the elements (:func:`_drag_load`)
    and
        direct: U_p = the end motion (zero inside),
                F0 = F_I − (K − ω²M_T + iωC_s) U_p;
        Foss:   U_p = the end motion with the exact static following inside,
                F0 = F_I − (−ω²M_T + iωC_s) U_p   (K U_p = 0 on the free rows),
    F_I the Morison inertia load; returns (U_p, F0, moving): ``moving`` False without
    end motion (Q is formed where it is used, block by block: :func:`drag_inputs`)."""
    key = system.solver
    if key not in inp.cache:
        w = inp.omega
        if inp.ub is None:
            u = end_nodes(inp, prep.n, prep.d)
            f0, moving = inp.inertia_load, False
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
                return real_gemm(b, ubf).reshape(shape)

            inertia = inp.inertia_load if act is None else inp.inertia_load[..., act]
            u = times(g)
            f0 = inertia - (-(w * w)[:, None] * times(mg) + (1j * w)[:, None] * times(sg))
            if direct:
                f0 = f0 - times(kg)
            moving = True
            if act is not None:  # back to all channels
                u_all = np.zeros((prep.n, prep.d) + inp.ub.shape[2:], dtype=complex)
                f0_all = inp.inertia_load.copy()
                u_all[..., act], f0_all[..., act] = u, f0
                u, f0 = u_all, f0_all
        inp.cache[key] = (u, f0, moving)
    return inp.cache[key]


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
    u, _, moving = base_motion(system, prep, inp)
    moments = None if inp.moments is None else inp.moments[..., freq, :]
    wm = moments
    key = ("drag_moments", system.solver)
    whole = freq == slice(None)
    if moving and whole and key in inp.cache:
        wm = inp.cache[key]
    elif moving:
        pat = (
            np.array([[0.5, 0.0], [0.0, 0.5]])
            if system.model.mass_matrix == "lumped"
            else np.array([[1.0 / 3.0, 1.0 / 6.0], [1.0 / 6.0, 1.0 / 3.0]])
        )
        act = _moving_channels(inp)  # Q = 0 for the others: W = the moments
        qa = u[:, :, freq] if act is None else u[:, :, freq][..., act]
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
                else np.zeros((prep.n - 1, 2) + u[:, :, freq].shape[1:], dtype=complex)
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
        u, _, moving = base_motion(system, prep, inp)
        vq = inp.velocity
        if moving and system.drag_nodes.size:  # V + Q: attachments only
            q = (-1j * inp.omega)[:, None] * u
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
    """The load of :func:`solve_free`, F0 + F_d(V) + C_d Q (:func:`base_motion`), on all
    nodes (n_nodes, d, n_w, n_ch), a fresh array; ``freq`` selects a block of the
    frequencies (:mod:`stochcable.dynamics.freqblocks`)."""
    _, f0, _ = base_motion(system, prep, inp)
    wm, vq = drag_inputs(system, prep, inp, freq)
    if wm is None:
        rhs = f0[:, :, freq].copy()
    else:
        drag_blocks(system, damping)
        rhs = element_load(damping._cache["elements"], wm)
        rhs += f0[:, :, freq]
    if vq is not None and np.any(damping.b_node):
        rhs += damping.b_node[:, None, None, None] * vq
    return rhs


def silent_channel(omega: np.ndarray) -> tuple[Channel, ...]:
    """A zero-spectrum channel so a line without excitation still gets (zero) outputs."""

    def zero(w: np.ndarray) -> np.ndarray:
        return np.zeros_like(np.asarray(w, dtype=float))

    return (Channel(name="none", kind="none", omega=omega, spectrum=zero(omega), density=zero),)
