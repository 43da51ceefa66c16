"""The inputs of one line in the node layout (:class:`LineInputs`), with the fluid's
per-frequency arrays formed block by block from the channels.

:func:`line_inputs` turns the channels (:class:`~stochcable.dynamics.loads.channels.Channel`:
sea, end motions) into what the load assembly and the variance sums of one line read:
the σ weights (trapezoid × spectrum), the weighted mean square of the fluid velocity,
the end displacements and, on any block of frequencies, the consistent element moments
of the fluid velocity (:meth:`LineInputs.moments_at`) and the exact Morison inertia
load (:meth:`LineInputs.inertia_at`, Tuah (1982), eq. 5.2.6).  Those two are not kept for
the whole grid: they are gathered from the channels' element kinematics (which the
channels hold once) for the block at hand, so the drag fixed point holds one block of
them at a time (:mod:`stochcable.dynamics.loads.freqblocks`); where the whole grid fits a
quarter of the working-memory target they are kept after the first use (a small model
forms them once).  :attr:`LineInputs.moments` and :attr:`LineInputs.inertia_load`
give the whole grid (kept after the first access: the solves of the lines of a coupled
group read them at once).

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

from collections.abc import Hashable
from dataclasses import dataclass, field

import numpy as np

from stochcable.dynamics.loads.channels import (
    Channel,
    element_mean_square,
    element_moments,
    inertia_blocks,
)
from stochcable.dynamics.loads.element_parts import ArrayMoments, Components, MomentParts
from stochcable.dynamics.loads.freqblocks import FrequencyIndex, whole_grid, working_memory_bytes
from stochcable.dynamics.model.blocks import (
    block_matvec,
    element_blocks,
    element_load,
    line_prep,
    trapezoid_weights,
)
from stochcable.dynamics.model.system import LineSystem
from stochcable.line.fem import FEModel

__all__ = ["LineInputs", "line_inputs", "weighted_mean_square", "with_spectra"]

#: Frequency selections: a slice of the grid or an index array (the coarse subset).
Freq = slice | np.ndarray


@dataclass(frozen=True, eq=False)
class LineInputs:
    """Channel data of one line in the node layout (n_nodes, d, n_w, n_ch).

    Attributes
    ----------
    omega : ndarray, shape (n_w,)
        Frequencies. [rad/s]
    velocity : ndarray or None, complex, shape (n_nodes, d, n_w, n_ch)
        Fluid velocity at the nodes (what the attachments' drag reads; None without
        attachment drag areas). [(m/s)/unit]
    ub : ndarray or None, complex, shape (2, d, n_w, n_ch)
        Prescribed end displacements. [m/unit]
    weights : ndarray, shape (n_w, n_ch)
        Trapezoid weight × spectrum. [unit²]
    square : ndarray or None, shape (n_el, d, d)
        Σ weight·∫Re(v vᴴ)dξ of the fluid velocity. [(m/s)²]
    fluid : tuple of (MomentParts, ArrayMoments or None)
        Per channel its consistent element moments ∫N_i v dξ
        (:mod:`stochcable.dynamics.loads.element_parts`: the sea's parts, the channel's own
        arrays; None without fluid velocity). [(m/s)/unit]
    comps : tuple of int
        The model's components among x, y, z.
    inertia_el : ndarray, shape (n_el, d, d)
        Morison inertia l0·ρ(πD²/4)(1 + Can)(I − eeᵀ) per element. [kg]
    moment_inertia : tuple of bool
        Per channel: its inertia load is the element load of iω times its moments.
    inertia_extra : ndarray or None, complex, shape (n_nodes, d, n_w, n_ch)
        The rest of the inertia load: the attachments' (buoyancy/g + added mass)·A and
        hand-built channels' nodal interpolation (None: nothing). [N/unit]
    cache : dict
        Drag-independent arrays per solver (:mod:`stochcable.dynamics.solve.line_loads`).
    """

    omega: np.ndarray
    velocity: np.ndarray | None
    ub: np.ndarray | None
    weights: np.ndarray
    square: np.ndarray | None
    fluid: tuple[MomentParts | ArrayMoments | None, ...]
    comps: tuple[int, ...]
    inertia_el: np.ndarray
    moment_inertia: tuple[bool, ...]
    inertia_extra: np.ndarray | None = None
    cache: dict = field(default_factory=dict)

    @property
    def has_fluid(self) -> bool:
        """Whether a channel has a fluid velocity (element moments)."""
        return any(f is not None for f in self.fluid)

    def moments_at(self, freq: Freq = slice(None)) -> np.ndarray | None:
        """Consistent element moments on the frequencies ``freq``, (n_el, 2, d, n_f,
        n_ch), a fresh array or a view of the kept whole grid (None without fluid
        velocity). [(m/s)/unit]"""
        if not self.has_fluid:
            return None
        if "moments" in self.cache:
            return self.cache["moments"][..., freq, :]
        out = None
        for i, src in enumerate(self.fluid):
            if src is None:
                continue
            m = src.block(self.comps, freq)  # (n_el, 2, d, n_f)
            if out is None:
                out = np.empty(m.shape + (len(self.fluid),), dtype=complex)
                for k, f in enumerate(self.fluid):
                    if f is None:  # (no fluid velocity: zero moments)
                        out[..., k] = 0.0
            out[..., i] = m
        if whole_grid(freq, self.omega.size) and out.nbytes <= working_memory_bytes() // 4:
            self.cache["moments"] = out
        return out

    def fluid_views(self, freq: slice) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """The moments of the channels with a fluid velocity on the frequencies
        ``freq`` as views of their element-major parts, (n_fc, n_el, 2, P, n_f), the
        model's components as combinations of the parts (n_fc, d, P) and those
        channels' indices (the variance kernel's form; stacked, a copy, only with
        several fluid channels); None without fluid velocity. [(m/s)/unit]"""
        idx = [i for i, f in enumerate(self.fluid) if f is not None]
        if not idx:
            return None
        srcs = [self.fluid[i] for i in idx]
        if len({s.stacked(slice(0, 0)).shape[2] for s in srcs}) > 1:  # mixed kinds
            views = [np.moveaxis(s.full(), 0, -1)[..., freq] for s in srcs]
            mix = np.stack([np.eye(3)[list(self.comps)]] * len(srcs))
        else:
            views = [s.stacked(freq) for s in srcs]
            mix = np.stack([s.mix(self.comps) for s in srcs])
        stacked = views[0][None] if len(views) == 1 else np.stack(views)
        return stacked, mix, np.asarray(idx, dtype=np.int64)

    def fluid_block(self, i: int, freq: Freq = slice(None)) -> np.ndarray:
        """The moments of channel ``i`` (one with a fluid velocity) on the frequencies
        ``freq``, (n_el, 2, d, n_f), contiguous (one run per element end and
        component from the sea's element-major storage). [(m/s)/unit]"""
        if "moments" in self.cache:
            return np.ascontiguousarray(self.cache["moments"][..., freq, i])
        tag = (i, freq.start, freq.stop) if isinstance(freq, slice) else None
        last = self.cache.get("last_fluid")
        if tag is not None and last is not None and last[0] == tag:
            return last[1]
        out = self.fluid[i].block(self.comps, freq)
        if tag is not None:  # read twice per block (inertia and drag loads)
            self.cache["last_fluid"] = (tag, out)
        return out

    def inertia_at(self, freq: Freq = slice(None)) -> np.ndarray:
        """The Morison inertia load on all nodes on the frequencies ``freq``,
        (n_nodes, d, n_f, n_ch), a fresh array or a view of the kept whole grid.
        [N/unit]"""
        if "inertia" in self.cache:
            return self.cache["inertia"][:, :, freq]
        w = self.omega[freq]
        n_el, d = self.inertia_el.shape[:2]
        if self.inertia_extra is not None:
            out = self.inertia_extra[:, :, freq].copy()
        else:
            out = np.zeros((n_el + 1, d, w.size, len(self.fluid)), dtype=complex)
        for i, use in enumerate(self.moment_inertia):
            if use:  # exact along the elements: l0·C_I(I − eeᵀ)·iω∫N_i v dξ
                out[..., i] += element_load(self.inertia_el, self.fluid_block(i, freq) * (1j * w))
        if whole_grid(freq, self.omega.size) and out.nbytes <= working_memory_bytes() // 4:
            self.cache["inertia"] = out
        return out

    def inertia_ends(self) -> np.ndarray:
        """:meth:`inertia_at` of all frequencies at the two end nodes, (2, d, n_w,
        n_ch): element 0's share on node 0, the last element's on the last node.
        [N/unit]"""
        if "inertia" in self.cache:
            return self.cache["inertia"][[0, -1]]
        n_el, d = self.inertia_el.shape[:2]
        out = (
            self.inertia_extra[[0, -1]].copy()
            if self.inertia_extra is not None
            else np.zeros((2, d) + self.weights.shape, dtype=complex)
        )
        if any(self.moment_inertia):
            ma, mb = self.moment_ends()
            iw = (1j * self.omega)[:, None]
            for k, (b, m) in enumerate(((self.inertia_el[0], ma), (self.inertia_el[-1], mb))):
                use = np.array(self.moment_inertia)
                out[k][..., use] += np.einsum("ij,jwc->iwc", b, m[..., use] * iw)
        return out

    def moment_ends(self) -> tuple[np.ndarray, np.ndarray] | None:
        """The moments ∫N_a v dξ of the first element and ∫N_b v dξ of the last, each
        (d, n_w, n_ch) (None without fluid velocity). [(m/s)/unit]"""
        if not self.has_fluid:
            return None
        if "moments" in self.cache:
            mom = self.cache["moments"]
            return mom[0, 0], mom[-1, 1]
        out = np.zeros((2, len(self.comps)) + self.weights.shape, dtype=complex)
        for i, src in enumerate(self.fluid):
            if src is not None:
                out[0, :, :, i], out[1, :, :, i] = src.ends(self.comps)
        return out[0], out[1]

    @property
    def moments(self) -> np.ndarray | None:
        """:meth:`moments_at` of the whole grid, kept after the first access."""
        if not self.has_fluid:
            return None
        if "moments" not in self.cache:
            self.cache["moments"] = self.moments_at()
        return self.cache["moments"]

    @property
    def inertia_load(self) -> np.ndarray:
        """:meth:`inertia_at` of the whole grid, kept after the first access."""
        if "inertia" not in self.cache:
            self.cache["inertia"] = self.inertia_at()
        return self.cache["inertia"]

    def subset(self, idx: np.ndarray, weights: np.ndarray, square: np.ndarray | None) -> LineInputs:
        """These inputs on the frequencies ``omega[idx]`` with the σ ``weights`` and
        mean ``square`` given
        (:func:`stochcable.dynamics.linearization.coarse_grid.subset_inputs`)."""

        def take(a: np.ndarray | None, axis: int) -> np.ndarray | None:
            return None if a is None else np.take(a, idx, axis=axis)

        return LineInputs(
            self.omega[idx],
            take(self.velocity, 2),
            take(self.ub, 2),
            weights,
            square,
            tuple(None if f is None else f[idx] for f in self.fluid),
            self.comps,
            self.inertia_el,
            self.moment_inertia,
            take(self.inertia_extra, 2),
        )


def _inertia_elements(system: LineSystem) -> tuple[np.ndarray, np.ndarray]:
    """Morison inertia l0·ρ(πD²/4)(1 + Can)(I − eeᵀ) per element on the model
    components (n_el, d, d) and the attachments' (buoyancy/g + added mass) (n_nodes,)."""
    if "inertia_el" not in system._cache:
        blocks, node = inertia_blocks(system.model, system.environment.g, system.frames[0])
        system._cache["inertia_el"] = (element_blocks(system.model, blocks), node)
    return system._cache["inertia_el"]


def line_inputs(system: LineSystem, channels: tuple[Channel, ...]) -> LineInputs:
    """The channels of a line in the node layout (:class:`LineInputs`), sampled on the
    channels' common grid: fluid velocity at the attachment nodes, the channels'
    element moments (the Morison inertia load formed from them, exact along the
    elements, Tuah (1982), eq. 5.2.6), end displacements, trapezoid × spectrum weights and
    the weighted mean square of the fluid velocity."""
    model = system.model
    comps = list(model.components)
    w = channels[0].omega
    n_w, n_ch = w.size, len(channels)
    shape = (model.n_nodes, model.dim, n_w, n_ch)
    weights = trapezoid_weights(w)[:, None] * np.stack([c.spectrum for c in channels], axis=1)
    vel = None
    extra = None
    b_in, node_mass = _inertia_elements(system)
    # the nodal fluid velocity only drives the attachments' drag (b_node): without
    # attachment drag areas it is never used (and not built)
    attached = system.drag_nodes.size > 0
    fluid, by_moments = [], []
    for i, ch in enumerate(channels):
        if attached and ch.velocity is not None:  # (the sea's is computed on access)
            if vel is None:
                vel = np.zeros(shape, dtype=complex)
            vel[..., i] = np.transpose(ch.velocity[..., comps], (1, 2, 0))
        src = _moment_source(model, ch)
        fluid.append(src)
        by_moments.append(_has_element_moments(ch))
        if _has_element_moments(ch):
            if np.any(node_mass) and ch.acceleration is not None:
                if extra is None:
                    extra = np.zeros(shape, dtype=complex)
                extra[..., i] = node_mass[:, None, None] * np.transpose(
                    ch.acceleration[..., comps], (1, 2, 0)
                )
        elif ch.acceleration is not None:  # hand-built channel: nodal interpolation
            if extra is None:
                extra = np.zeros(shape, dtype=complex)
            acc = np.transpose(ch.acceleration[..., comps], (1, 2, 0))[..., None]
            extra[..., i] = block_matvec(line_prep(system).BI, acc)[..., 0]
    ub = None
    for i, ch in enumerate(channels):
        for k, m in enumerate((ch.motion_a, ch.motion_b)):
            if m is not None and np.any(m):
                if ub is None:
                    ub = np.zeros((2, model.dim, n_w, n_ch), dtype=complex)
                ub[k, :, :, i] = m[:, comps].T
    return LineInputs(
        w,
        vel,
        ub,
        weights,
        _weighted_square(model, channels, weights),
        tuple(fluid),
        tuple(comps),
        b_in,
        tuple(by_moments),
        extra,
    )


def _weighted_square(
    model: FEModel, channels: tuple[Channel, ...], weights: np.ndarray
) -> np.ndarray | None:
    """Σ_i weight_i·∫Re(v vᴴ)dξ over the channels with a fluid velocity, on the model
    components, (n_el, d, d) (None without fluid velocity)."""
    square = None
    for i, ch in enumerate(channels):
        if not _has_element_moments(ch) and ch.velocity is None:
            continue
        sq = weighted_mean_square(ch, weights[:, i], model.components)
        square = sq if square is None else square + sq
    return square


def _has_element_moments(ch: Channel) -> bool:
    """Whether a channel carries moments integrated along the elements (the sea's
    parts or a given array; else its nodal kinematics are interpolated)."""
    return ch.element_velocity is not None or ch.element_velocity_parts is not None


def _moment_source(model: FEModel, ch: Channel) -> MomentParts | ArrayMoments | None:
    """A channel's element moments as :class:`MomentParts` or :class:`ArrayMoments`
    (None without fluid velocity)."""
    if ch.element_velocity is None and ch.element_velocity_parts is not None:
        return ch.element_velocity_parts
    m = element_moments(model, ch)
    return None if m is None else ArrayMoments(m)


def weighted_mean_square(
    channel: Channel, weights: np.ndarray, comps: Components, idx: FrequencyIndex = slice(None)
) -> np.ndarray | None:
    """Σ_ω weight·∫₀¹ Re(v vᴴ) dξ of a channel on the frequencies ``idx``, on the
    components ``comps``, (n_el, d, d) (None without fluid velocity): from the sea's
    two parts (:class:`~stochcable.dynamics.loads.element_parts.SquareParts`) without
    forming the 3 × 3 matrices where it has them. [(m/s)²·weight]"""
    comps = np.asarray(comps)
    if channel.element_velocity_square is None and channel.element_square is not None:
        return channel.element_square[idx].weighted(weights, comps)
    sq = element_mean_square(channel)
    if sq is None:
        return None
    # the d × d part in one gather (two chained ones were 0.1-0.4 ms)
    sq = sq[idx][:, :, comps[:, None], comps]
    return np.einsum("weij,w->eij", sq, weights)


def _spectrum_free(key: Hashable) -> bool:
    """Caches of :class:`LineInputs` that do not depend on the channels' spectra (kept by
    :func:`with_spectra`): the base motion and load per solver, the end-motion
    projections, the attachments' velocity, the kept moments and inertia load.  Every
    other cache is formed again."""
    return key in ("foss", "direct", "moments", "inertia") or (
        isinstance(key, tuple)
        and key[0] in ("qproj", "attached_velocity", "drag_moments", "following", "base_load")
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
        inp.ub,
        weights,
        _weighted_square(system.model, channels, weights),
        inp.fluid,
        inp.comps,
        inp.inertia_el,
        inp.moment_inertia,
        inp.inertia_extra,
    )
    out.cache.update({k: v for k, v in inp.cache.items() if _spectrum_free(k)})
    return out
