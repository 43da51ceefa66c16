"""The Foss and modal line parts of a group solve
(:mod:`~stochcable.dynamics.groups.lineparts`): a line kept in the coordinates of its
Foss (state) modes until the body solve (:class:`FossLine`, Tuah (1982), §5.3), or its
modal equations solved per frequency in the coarse stage (:class:`ModalLine`); the
drag-dependent start of a Foss line (:func:`foss_state`) and the drag-independent
arrays each keeps across the evaluations of the fixed point (:data:`PartCache`).

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from stochcable.dynamics.model.blocks import (
    LinePrep,
    NodeBlocks,
    add_blocks,
    block_matvec,
    line_prep,
    real_gemm,
)
from stochcable.dynamics.model.modal_solvers import FossModes, foss_modes, foss_transfer_modal
from stochcable.dynamics.model.system import Damping, LineSystem
from stochcable.dynamics.solve.line_loads import drag_blocks, end_following, end_loads, free_load
from stochcable.dynamics.solve.line_solve import damping_coupling, reactions
from stochcable.dynamics.solve.node_inputs import LineInputs
from stochcable.errors import SolverError

__all__ = ["FossLine", "FossState", "ModalLine", "PartCache", "foss_state"]

#: The drag-dependent, frequency-independent start of a Foss line
#: (:func:`foss_state`): the drag blocks C_d, the damping C, the Foss decomposition and
#: the truncated modes' damping coupling R C Φ (None with every mode kept).
FossState = tuple[NodeBlocks, NodeBlocks, FossModes | None, np.ndarray | None]
#: The drag-independent arrays of one line's part, kept across the evaluations of
#: the fixed point (:class:`FossLine`, :class:`ModalLine`): arrays and tuples of
#: arrays by name.
PartCache = dict[str, Any]


def foss_state(system: LineSystem, damping: Damping) -> FossState:
    """The drag-dependent, frequency-independent start of a Foss line.

    Parameters
    ----------
    system : LineSystem
    damping : Damping

    Returns
    -------
    (C_d, C, foss, rc)
        The drag blocks C_d, the damping C = S + C_d [N·s/m], the Foss
        decomposition of the line's kept modes (None when the pencil is defective,
        Tuah (1982), §5.3) and R C Φ of
        :func:`~stochcable.dynamics.solve.line_solve.damping_coupling` (None with
        every mode kept).

    Notes
    -----
    The part :func:`line_parts` runs on the thread pool (NumPy's LAPACK ``geev`` in
    :func:`stochcable.dynamics.model.modal_solvers.foss_modes` releases the GIL).
    """
    prep = line_prep(system)
    cd = drag_blocks(system, damping)
    c = add_blocks(prep.S, cd)
    phi, mh, kh = prep.modal(system)
    cphi = prep.free_rows(block_matvec(c, prep.nodes(phi)))
    ch = phi.T @ cphi
    try:
        foss = foss_modes(mh, 0.5 * (ch + ch.T), kh)
    except SolverError:
        foss = None
    return cd, c, foss, damping_coupling(system, prep, c, cphi)


def _unit_follow(
    system: LineSystem, inp: LineInputs, ends: tuple[int, ...]
) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """The unit end motions of the attached ends ``ends`` of a Foss line: their
    constant static following U_p (n_nodes, d, n_e), the modal mass load
    âh = Φᵀ[M_T U_p]_f (m, n_e) and its static correction (None with all modes kept),
    cached on the inputs ``inp``."""
    key = ("unit_follow", ends)
    if key not in inp.cache:
        prep = line_prep(system)
        d, n = prep.d, prep.n
        phi, _, _ = prep.modal(system)
        m, nf = phi.shape[1], phi.shape[0]
        n_e = d * len(ends)
        ub = np.zeros((2 * d, n_e))
        for i, k in enumerate(ends):
            ub[k * d : (k + 1) * d, i * d : (i + 1) * d] = np.eye(d)
        up = np.zeros((n, d, n_e))
        up[0], up[-1] = ub[:d], ub[d:]
        up[1:-1] = (prep.follower() @ ub).reshape(n - 2, d, n_e)
        a = prep.free_rows(block_matvec(prep.MT, up))
        st_a = prep.residual(system, a.astype(complex)).real if m < nf else None
        inp.cache[key] = (up, phi.T @ a, st_a)
    return inp.cache[key]


class FossLine:
    """A Foss line of a group in the coordinates of its Foss (state) modes (Tuah
    1982, §5.3).

    The same linear system as :func:`foss_unit_split` +
    :func:`stochcable.dynamics.solve.line_solve.reactions`,
    reordered: the physical channels' state-modal response P_0 (2m, n_w,
    n_ch) and the unit end motions' P_e (2m, n_w, n_e) are kept (the latter in closed
    form, ``(ω²·W âh − iω·W b̂h)/(iω − λ)``, W the Foss weights); the end reactions
    need the displacement of the end nodes and their neighbours only (two rows of
    Φχ); after the body solve, :meth:`combine` forms P_0 + P_e u_e and reconstructs
    the one combined response on all nodes (σ, support forces).  Raises SolverError
    when the Foss pencil is defective (the caller falls back to the plain solve).
    ``cache`` (a dict per line of the group,
    :attr:`~stochcable.dynamics.groups.group.GroupSystem.foss_cache`) keeps the
    drag-independent arrays (end-node rows of Φ, of the base response and of the
    static following, ω²·[static correction of âh] at those rows) from the first
    evaluation for the next ones: the same arrays, not recomputed (docs/BENCHMARKS.md
    pass E8).
    """

    def __init__(
        self,
        system: LineSystem,
        inp: LineInputs,
        damping: Damping,
        ends: tuple[int, ...],
        state: FossState | None = None,
        cache: PartCache | None = None,
    ) -> None:
        prep = line_prep(system)
        w = inp.omega
        n_w, n_ch = inp.weights.shape
        d = prep.d
        _, c, foss, rc = foss_state(system, damping) if state is None else state
        if foss is None:
            raise SolverError("Foss eigenproblem is (nearly) defective")
        phi, _, _ = prep.modal(system)
        m, nf = phi.shape[1], phi.shape[0]
        lam = foss.lambdas
        den = 1j * w[None, :] - lam[:, None]  # (2m, n_w)
        bad = np.abs(den) <= 1e-12 * np.maximum(np.abs(lam)[:, None], w[None, :])
        if bad.any():  # the message of solvers._foss_transfer_modal
            foss_transfer_modal(foss, np.zeros((m, n_w), dtype=complex), w, 1)
        w2, iw = w * w, 1j * w
        cache = _foss_cache(system, prep, inp, ends, phi, cache)
        u_p = cache["u_p"]
        up, ah, st_a = cache["follow"]
        adj = cache["adj"]
        # physical channels: the free-row load of solve_free
        rhs = free_load(system, prep, inp, damping)
        flat = np.ascontiguousarray(prep.free_rows(rhs)).reshape(nf, n_w * n_ch)
        p0 = (foss.weights @ real_gemm(phi.T, flat)).reshape(2 * m, n_w, n_ch)
        p0 /= den[:, :, None]
        # unit end motions: the constant static following U_p,j of each attached end DOF
        b = prep.free_rows(block_matvec(c, up))
        n_e = up.shape[2]
        # W âh and W b̂h as the two blocks of one (2m, 2 n_e) product: each column of a
        # product is that of the separate one (the same sums, tested to the bit)
        wab = foss.weights @ np.concatenate([ah, phi.T @ b], axis=1)  # (2m, 2 n_e)
        rden = 1.0 / den
        self.res0 = self.st = None
        if m < nf:
            self.res0 = prep.residual(system, flat).reshape(nf, n_w, n_ch)
            st_b = prep.residual(system, b.astype(complex)).real
            self.st = np.ascontiguousarray(np.hstack([st_a, st_b]))  # (nf, 2 n_e)
        # the truncated modes' response to the kept modes' damping forces, −iω R C Φ z
        # (line_solve.damping_coupling): Φ z read through Φ − iω R C Φ
        self.rc = rc
        y_adj = cache["pa"] @ foss.chi  # (2d, 2m)
        u4 = cache["u4"].copy()
        v = (y_adj @ p0.reshape(2 * m, -1)).reshape(2, d, n_w, n_ch)
        if self.res0 is not None:
            v += self.res0[adj].reshape(2, d, n_w, n_ch)
        if self.rc is not None:
            rc_adj = self.rc[adj] @ foss.chi  # (2d, 2m)
            vr = (rc_adj @ p0.reshape(2 * m, -1)).reshape(2, d, n_w, n_ch)
            v -= iw[:, None] * vr
        u4[1:3] += v
        u4e = cache["up4"].copy()
        # the unit columns' P_e = (ω² W âh − iω W b̂h)/(iω − λ) seen through y_adj, the
        # âh and b̂h rows stacked in one product with 1/(iω − λ) (rows as the separate
        # products', tested to the bit)
        y2 = (y_adj[None, :, None, :] * wab.T.reshape(2, 1, n_e, 2 * m)).reshape(
            2 * 2 * d * n_e, 2 * m
        ) @ rden
        ya, yb = y2[: 2 * d * n_e], y2[2 * d * n_e :]
        ve = (w2 * ya - iw * yb).reshape(2, d, n_e, n_w)
        if self.rc is not None:
            r2 = (rc_adj[None, :, None, :] * wab.T.reshape(2, 1, n_e, 2 * m)).reshape(
                2 * 2 * d * n_e, 2 * m
            ) @ rden
            ra, rb = r2[: 2 * d * n_e], r2[2 * d * n_e :]
            ve -= (iw * (w2 * ra - iw * rb)).reshape(2, d, n_e, n_w)
        if self.st is not None:
            sb = st_b[adj]  # (2d, n_e)
            ve += (cache["w2sa"] - iw[None, None] * sb[:, :, None]).reshape(2, d, n_e, n_w)
        u4e[1:3] += ve.transpose(0, 1, 3, 2)
        f_end = end_loads(system, inp, damping)
        self.sup0 = reactions(system, prep, c, u4, f_end, w)  # (n_w, 2d, n_ch)
        self.supe = reactions(system, prep, c, u4e, cache["zero_e"], w)
        self.inp, self.phi, self.chi, self.rden = inp, phi, foss.chi, rden
        self.p0, self.wab, self.up, self.u_p = p0, wab, up, u_p
        self.w2, self.iw = (w2)[None, :, None], iw[None, :, None]

    def reactions(self, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """R_0 (n_w, |rows|, n_ch) and R_e (n_w, |rows|, n_e) on the attached rows."""
        return self.sup0[:, rows, :], self.supe[:, rows, :]

    def combine(self, ue: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Node displacements (n_nodes, d, n_w, n_ch) and support forces (n_w, 2d,
        n_ch) of the line whose attached ends move by ``ue`` (n_w, n_e, n_ch)."""
        m2, n_w, n_ch = self.p0.shape
        n_e = self.up.shape[2]
        uet = np.ascontiguousarray(np.transpose(ue, (1, 0, 2)))  # (n_e, n_w, n_ch)
        flat_e = uet.reshape(n_e, n_w * n_ch)
        # W âh u_e and W b̂h u_e: the row blocks of one product (tested to the bit)
        gab = self.wab.reshape(m2, 2, n_e).transpose(1, 0, 2).reshape(2 * m2, n_e) @ flat_e
        ga = gab[:m2].reshape(m2, n_w, n_ch)
        gb = gab[m2:].reshape(m2, n_w, n_ch)
        # p0 + (ω² ga − iω gb)/(iω − λ) in place (the sum commutes exactly)
        pc = self.w2 * ga
        pc -= self.iw * gb
        pc *= self.rden[:, :, None]
        pc += self.p0
        z = np.ascontiguousarray(self.chi @ pc.reshape(m2, -1))
        uf = real_gemm(self.phi, z)
        if self.rc is not None:
            uf -= real_gemm(self.rc, z * np.repeat(self.iw.ravel(), n_ch))
        return _assemble_line(self, uf, ue, uet)


class ModalLine:
    """A Foss line of the coarse stage's group
    (:mod:`stochcable.dynamics.groups.group_fixed_point`):
    the modal equations of its kept modes
    (K̂ − ω²M̂ + iωĈ) z = Φᵀf solved per frequency (one batched dense LU for the
    physical channels and the unit end motions), no Foss eigenproblem.

    The same modal system as :class:`FossLine` (Foss diagonalizes it exactly), so
    the same response to round-off, with the interface of :class:`FossLine`
    (:meth:`reactions`, :meth:`combine`): on a few dozen frequencies the batched
    m × m solves cost less than the line's 2m × 2m eigenproblem
    (docs/BENCHMARKS.md, "Bodies", pass E5).  The physical channels' modal response
    z_0 (n_w, m, n_ch), the unit end motions' z_e (n_w, m, n_e) (loads
    ω²âh − iωb̂h, :func:`foss_unit_split`); after the body solve z_0 + z_e u_e is
    reconstructed on the nodes with the static correction of the truncated modes.
    ``cache`` (a dict per line of the coarse group,
    :attr:`~stochcable.dynamics.groups.group.GroupSystem.modal_cache`) keeps
    the drag-independent arrays (static following, unit-motion mass loads, K̂ − ω²M̂,
    end-node rows) from the first coarse evaluation for the next ones: the same
    arrays, not recomputed (docs/BENCHMARKS.md pass E5c).
    """

    def __init__(
        self,
        system: LineSystem,
        inp: LineInputs,
        damping: Damping,
        ends: tuple[int, ...],
        cache: PartCache | None = None,
    ) -> None:
        prep = line_prep(system)
        w = inp.omega
        n_w, n_ch = inp.weights.shape
        d = prep.d
        c = add_blocks(prep.S, drag_blocks(system, damping))
        phi, _, _ = prep.modal(system)
        m, nf = phi.shape[1], phi.shape[0]
        iw = 1j * w
        cache = _modal_cache(system, prep, inp, ends, cache)
        u_p = cache["u_p"]
        up, _, st_a = cache["follow"]
        cphi = prep.free_rows(block_matvec(c, prep.nodes(phi)))
        ch = phi.T @ cphi
        rhs = free_load(system, prep, inp, damping)
        flat = np.ascontiguousarray(prep.free_rows(rhs)).reshape(nf, n_w * n_ch)
        b = prep.free_rows(block_matvec(c, up))
        bh = phi.T @ b
        n_e = up.shape[2]
        f = np.empty((n_w, m, n_ch + n_e), dtype=complex)
        f[:, :, :n_ch] = real_gemm(phi.T, flat).reshape(m, n_w, n_ch).transpose(1, 0, 2)
        f[:, :, n_ch:] = cache["w2ah"] - iw[:, None, None] * bh[None]
        # symmetric matrices passed as their transposes (LAPACK's column-major layout,
        # as analysis._foss_free)
        # (K̂ − ω²M̂) + iωĈ written as its real and imaginary parts (the product iω·Ĉ
        # has the real part ±0): the bits of the complex sum, no complex temporary
        a = np.empty((n_w, m, m), dtype=complex)
        a.real[...] = cache["kmm"]
        np.multiply(w[:, None, None], 0.5 * (ch + ch.T), out=a.imag)
        z = np.linalg.solve(a.transpose(0, 2, 1), f)
        # non-finite entries make the sum non-finite (one reduction, no mask)
        if not np.isfinite(z.sum()):
            raise SolverError("coarse stage: singular modal impedance")
        z0, ze = z[:, :, :n_ch], z[:, :, n_ch:]
        self.res0 = self.st = None
        if m < nf:
            self.res0 = prep.residual(system, flat).reshape(nf, n_w, n_ch)
            st_b = prep.residual(system, b.astype(complex)).real
            self.st = np.ascontiguousarray(np.hstack([st_a, st_b]))  # (nf, 2 n_e)
        adj, pa = cache["adj"], cache["pa"]  # (2d,), (2d, m)
        # Φ z read through Φ − iω R C Φ (line_solve.damping_coupling), as FossLine
        self.rc = damping_coupling(system, prep, c, cphi)
        if self.rc is not None:
            pa = pa - iw[:, None, None] * self.rc[adj][None]  # (n_w, 2d, m)
        u4 = cache["u4"].copy()
        v = np.transpose(pa @ z0, (1, 0, 2)).reshape(2, d, n_w, n_ch)
        if self.res0 is not None:
            v += self.res0[adj].reshape(2, d, n_w, n_ch)
        u4[1:3] += v
        u4e = np.empty((4, d, n_w, n_e), dtype=complex)
        u4e[...] = cache["up4"]
        ve = np.transpose(pa @ ze, (1, 0, 2)).reshape(2, d, n_w, n_e)
        if self.st is not None:
            sb = st_b[adj]  # (2d, n_e)
            ve += (cache["w2sa"] - iw[None, :, None] * sb[:, None, :]).reshape(2, d, n_w, n_e)
        u4e[1:3] += ve
        f_end = end_loads(system, inp, damping)
        self.sup0 = reactions(system, prep, c, u4, f_end, w)
        self.supe = reactions(system, prep, c, u4e, np.zeros((2, d, n_w, n_e), complex), w)
        self.inp, self.phi, self.z0, self.ze, self.up, self.u_p = inp, phi, z0, ze, up, u_p

    def reactions(self, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """R_0 (n_w, |rows|, n_ch) and R_e (n_w, |rows|, n_e) on the attached rows."""
        return self.sup0[:, rows, :], self.supe[:, rows, :]

    def combine(self, ue: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """As :meth:`FossLine.combine`."""
        n_w, m, n_ch = self.z0.shape
        z = self.z0 + self.ze @ ue  # (n_w, m, n_ch)
        zf = np.ascontiguousarray(np.transpose(z, (1, 0, 2))).reshape(m, n_w * n_ch)
        uf = real_gemm(self.phi, zf)
        if self.rc is not None:
            uf -= real_gemm(self.rc, zf * np.repeat(1j * self.inp.omega, n_ch))
        uet = np.ascontiguousarray(np.transpose(ue, (1, 0, 2)))  # (n_e, n_w, n_ch)
        return _assemble_line(self, uf, ue, uet)


def _foss_cache(
    system: LineSystem,
    prep: LinePrep,
    inp: LineInputs,
    ends: tuple[int, ...],
    phi: np.ndarray,
    cache: PartCache | None,
) -> PartCache:
    """The drag-independent arrays of a :class:`FossLine`, filled into ``cache`` (one
    per line of the group) on the first evaluation and kept for the later ones: the
    base response, the static following of the attached ends, the rows of the end
    nodes and their neighbours (nodes 0, 1, n-2, n-1) of Φ, of the base response and
    of the static following, ω²·[static correction of âh] at those rows."""
    if cache:
        return cache
    cache = {} if cache is None else cache
    w = inp.omega
    n_w = inp.weights.shape[0]
    d = prep.d
    nf = phi.shape[0]
    w2 = w * w
    cache["u_p"] = u_p = end_following(system, prep, inp)[0]
    up, _, st_a = cache["follow"] = _unit_follow(system, inp, ends)
    n_e = up.shape[2]
    # end nodes and their neighbours: nodes 0, 1, n-2, n-1
    cache["adj"] = adj = np.r_[np.arange(d), np.arange(nf - d, nf)]
    cache["pa"] = phi[adj]
    cache["u4"] = u_p[[0, 1, -2, -1]]
    up4 = np.empty((4, d, n_w, n_e), dtype=complex)
    up4[...] = up[[0, 1, -2, -1]][:, :, None, :]
    cache["up4"] = up4
    cache["w2sa"] = (
        None if st_a is None else w2[None, None] * st_a[adj][:, :, None]
    )  # (2d, n_e, n_w)
    cache["zero_e"] = np.zeros((2, d, n_w, n_e), complex)  # read only
    return cache


def _modal_cache(
    system: LineSystem,
    prep: LinePrep,
    inp: LineInputs,
    ends: tuple[int, ...],
    cache: PartCache | None,
) -> PartCache:
    """The drag-independent arrays of a :class:`ModalLine`, filled into ``cache`` (one
    per line of the coarse group) on the first coarse evaluation and kept for the
    later ones: the base response, the static following and its mass loads, K̂ − ω²M̂,
    the end-node rows."""
    if cache:
        return cache
    cache = {} if cache is None else cache
    w = inp.omega
    d = prep.d
    phi, mh, kh = prep.modal(system)
    m, nf = phi.shape[1], phi.shape[0]
    w2 = w * w
    cache["u_p"] = end_following(system, prep, inp)[0]
    up, ah, st_a = cache["follow"] = _unit_follow(system, inp, ends)
    cache["w2ah"] = w2[:, None, None] * ah[None]
    cache["adj"] = adj = np.r_[np.arange(d), np.arange(nf - d, nf)]
    cache["pa"] = phi[adj]
    cache["u4"] = cache["u_p"][[0, 1, -2, -1]]
    cache["up4"] = up[[0, 1, -2, -1]][:, :, None, :]
    cache["w2sa"] = None if st_a is None else w2[None, :, None] * st_a[adj][:, None, :]
    key = ("stiff_mass", m, w.tobytes())  # K̂ − ω²M̂, as analysis._foss_free
    if key not in prep.cache:
        prep.cache[key] = kh - (w2[:, None, None]) * mh
    cache["kmm"] = prep.cache[key]
    return cache


def _assemble_line(
    part: FossLine | ModalLine, uf: np.ndarray, ue: np.ndarray, uet: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The tail of :meth:`FossLine.combine` and :meth:`ModalLine.combine`: the free
    rows' modal displacement ``uf`` (nf, n_w·n_ch) plus the truncated modes' static
    correction (physical and unit channels), the static following of the end motions
    ``ue`` (n_w, n_e, n_ch; ``uet`` its (n_e, n_w, n_ch) copy) and the base response:
    node displacements (n_nodes, d, n_w, n_ch) and support forces (n_w, 2d, n_ch)."""
    n, d, n_e = part.up.shape
    n_w, n_ch = ue.shape[0], ue.shape[2]
    if n_e == 0:  # no attached end (a line alone): the line's own response
        if part.res0 is not None:
            uf += part.res0.reshape(uf.shape[0], -1)
        uc = part.u_p.copy()
        uc[1:-1] += uf.reshape(n - 2, d, n_w, n_ch)
        return uc, part.sup0
    flat_e = uet.reshape(n_e, n_w * n_ch)
    if part.res0 is not None:
        w = part.inp.omega
        w2 = (w * w)[None, :, None]
        iw = (1j * w)[None, :, None]
        x = np.concatenate([w2 * uet, -iw * uet], axis=0).reshape(2 * n_e, -1)
        uf += part.res0.reshape(uf.shape[0], -1) + real_gemm(part.st, x)
    uc = part.u_p.copy()
    uc[1:-1] += uf.reshape(n - 2, d, n_w, n_ch)
    uc += real_gemm(part.up.reshape(n * d, n_e), flat_e).reshape(n, d, n_w, n_ch)
    sc = part.sup0 + part.supe @ ue
    return uc, sc
