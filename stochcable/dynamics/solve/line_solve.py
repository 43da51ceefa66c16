"""The direct and the Foss modal solve of one line (Tuah 1982, eq. 5.2.6, §5.3), the
support reactions and the end tensions.

End tensions are the change of the magnitude of the force on each support,
δ|F| = (F0/|F0|)·δF, with δF the reaction from the finite-element rows of the end
DOFs, δF = −[(K − ω²M_T + iωC)U − F_fluid]_end: it includes the inertia, drag and
seabed forces of the end node's share of the adjacent element, and tends to the end
element's δT (:func:`stochcable.dynamics.outputs.line_result.element_tension_transfer`) when those
are small (tested).  They live here, not in :mod:`~stochcable.dynamics.outputs.line_result`,
because every :class:`~stochcable.dynamics.model.system.Response` carries them (the coupled
solve and the time series use them too).

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

from stochcable.compiled import kernels_are_paid
from stochcable.dynamics.loads.channels import (
    Channel,
)
from stochcable.dynamics.loads.freqblocks import frequency_slices
from stochcable.dynamics.model.band_lu import band_solve, compiled_band_lu
from stochcable.dynamics.model.blocks import (
    LinePrep,
    NodeBlocks,
    add_blocks,
    block_matvec,
    free_band,
    from_freq,
    line_prep,
    real_gemm,
    to_freq,
)
from stochcable.dynamics.model.lift import lift_band, lift_end_load, lift_end_rows, lift_pattern
from stochcable.dynamics.model.modal_solvers import (
    DefectivePencilWarning,
    foss_modes,
    foss_transfer_modal,
)
from stochcable.dynamics.model.solvers import (
    SINGULAR_CONDITION,
    singular_error,
    solve_band_stacked,
    solve_direct,
)
from stochcable.dynamics.model.system import (
    Damping,
    LineSystem,
    Response,
)
from stochcable.dynamics.model.transport import gyro_band, gyro_end_load, gyro_end_rows
from stochcable.dynamics.solve.line_loads import (
    LineInputs,
    drag_blocks,
    end_following,
    end_loads,
    free_load,
    line_inputs,
)
from stochcable.errors import (
    SolverError,
    warn,
)


def _dynamic(prep: LinePrep, c: NodeBlocks, w: np.ndarray, x: np.ndarray) -> np.ndarray:
    """(−ω²M_T + iωC) x for node vectors x (n_nodes, d, n_w, k)."""
    return -(w * w)[:, None] * block_matvec(prep.MT, x) + (1j * w)[:, None] * block_matvec(c, x)


def solve_free(
    system: LineSystem, inp: LineInputs, damping: Damping, *, modal_direct: bool = False
) -> tuple[np.ndarray, NodeBlocks]:
    """Dynamic part on the free nodes, (n_nodes − 2, d, n_w, n_ch), and C = C_s + C_d.

    The total displacement is U = U_p + [0; u_f; 0] with U_p of :func:`base_motion`.
    ``modal_direct`` (Foss systems): solve the same modal equations per frequency
    instead of by the Foss eigenproblem (:func:`_foss_free`).  The load assembly and
    the solve run over blocks of frequencies
    (:func:`~stochcable.dynamics.loads.freqblocks.frequency_slices`; the Foss
    decomposition once for all blocks)."""
    prep = line_prep(system)
    d = prep.d
    w = inp.omega
    n_w, n_ch = inp.weights.shape
    cd = drag_blocks(system, damping)
    c = add_blocks(prep.S, cd)
    u_f = np.empty((prep.n - 2, d, n_w, n_ch), dtype=complex)
    # a frequency's temporaries: the load on all nodes, its element moments and the
    # solve's copies (≈ 8 node vectors per channel)
    slices = frequency_slices(n_w, 8 * 16 * prep.n * d * max(n_ch, 1))
    if system.solver == "direct":
        bC = prep.bS + free_band(cd)
        if system.gyro is not None:  # a travelling line: + G (dynamics.model.transport)
            bC = bC + gyro_band(system.gyro, d)
        if system.lift is not None:  # the linearized lift: + C_L (dynamics.model.lift)
            pat = lift_pattern(system.model)
            bC = bC + lift_band(system.lift, pat)
        for sl in slices:
            rhs_all = free_load(system, prep, inp, damping, sl)
            if system.gyro is not None and inp.ub is not None:
                ga, gb = gyro_end_load(system.gyro, inp.ub[:, :, sl], w[sl])
                rhs_all[1] += ga
                rhs_all[-2] += gb
            if system.lift is not None and inp.ub is not None:
                la, lb = lift_end_load(system.lift, pat, inp.ub[:, :, sl], w[sl])
                rhs_all[1] += la
                rhs_all[-2] += lb
            rhs_f = to_freq(rhs_all[1:-1])
            # (in a load-case set's chunk: the compiled LU, ≈ 4× LAPACK's stacked gbsv
            # on the taut wire's 38 DOFs; analyze() keeps gbsv, its numbers unchanged)
            paid = kernels_are_paid() and compiled_band_lu(rhs_f.size)
            solve = band_solve if paid else solve_band_stacked
            u = solve(
                prep.bK,
                prep.bM,
                bC,
                rhs_f,
                w[sl],
                2 * d - 1,
                2 * d - 1,
                (system.model.K, system.model.M),
            )
            _check_line_conditioning(system, prep, bC, w[sl], rhs_f, u)
            u_f[:, :, sl] = from_freq(u, d)
        inp.cache.pop("last_fluid", None)
        return u_f, c
    if modal_direct or len(slices) == 1:
        rhs = prep.free_rows(free_load(system, prep, inp, damping))
        u_f = _foss_free(system, prep, c, rhs, w, modal_direct=modal_direct).reshape(u_f.shape)
    else:
        solver = _foss_solver(system, prep, c)
        for sl in slices:
            rhs = prep.free_rows(free_load(system, prep, inp, damping, sl))
            u_f[:, :, sl] = solver(rhs, w[sl]).reshape(u_f[:, :, sl].shape)
    inp.cache.pop("last_fluid", None)  # (the last block's moments: not read again)
    return u_f, c


def total_displacement(system: LineSystem, inp: LineInputs, u_free: np.ndarray) -> np.ndarray:
    """Total displacement (n_nodes, d, n_w, n_ch) from the free-node dynamic part."""
    prep = line_prep(system)
    u = end_following(system, prep, inp)[0].copy()
    u[1:-1] += u_free
    return u


def _solve_nodes(
    system: LineSystem, inp: LineInputs, damping: Damping
) -> tuple[np.ndarray, NodeBlocks]:
    """Total displacement (n_nodes, d, n_w, n_ch) and C = C_s + C_d."""
    u_f, c = solve_free(system, inp, damping)
    return total_displacement(system, inp, u_f), c


def _check_line_conditioning(system, prep, bC, w, f, u) -> None:
    """SolverError where ||Z|| ||U|| / ||F|| exceeds 1e12 (undamped resonance), as
    :func:`stochcable.dynamics.model.solvers.solve_direct`."""

    nc = float(np.sqrt(np.sum(bC**2)))
    nz = prep.norm_K + w**2 * prep.norm_M + w * nc
    nf = np.linalg.norm(f.reshape(w.size, -1), axis=1)
    nu = np.linalg.norm(u.reshape(w.size, -1), axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        est = np.where(
            np.isfinite(nu), nz * np.where(nf > 0, nu / np.where(nf > 0, nf, 1.0), 0.0), np.inf
        )
    bad = np.flatnonzero(est > SINGULAR_CONDITION)
    if bad.size:
        k = int(bad[np.argmax(est[bad])])
        K, M = system.model.partition("K")[0], system.model.partition("MT")[0]
        raise singular_error(K, M, float(w[k]), float(est[k]))


def _foss_free(
    system: LineSystem,
    prep: LinePrep,
    c: NodeBlocks,
    rhs: np.ndarray,
    w: np.ndarray,
    modal_direct: bool = False,
) -> np.ndarray:
    """Foss modal solve on the free DOFs, rhs (n_free_dof, n_w, n_ch), with the static
    correction of the truncated modes (Tuah 1982, §5.3;
    :func:`stochcable.dynamics.model.modal_solvers.foss_decomposition`): :func:`_foss_solver`
    applied to ``rhs``."""
    return _foss_solver(system, prep, c, modal_direct)(rhs, w)


def _foss_solver(
    system: LineSystem, prep: LinePrep, c: NodeBlocks, modal_direct: bool = False
) -> Callable[[np.ndarray, np.ndarray], np.ndarray]:
    """The Foss modal solve with the damping ``c``: the decomposition once, then
    ``solve(rhs, w)`` for loads rhs (n_free_dof, n_w, n_ch) on frequencies w (any block
    of the grid).

    ``modal_direct``: the modal equations (K̂ − ω²M̂ + iωĈ)z = Φᵀf solved per frequency
    (batched dense LU) instead of by the Foss eigenproblem: the same response to
    round-off, cheaper on a few dozen frequencies (the coarse start: 0.23 against
    0.48 ms for 20 modes and 51 frequencies, the 2n-state eigenproblem being
    frequency-independent); also the fallback of a defective Foss pencil.

    Notes
    -----
    The truncated modes are taken by mode acceleration with the damping coupling:
    U = K⁻¹(F + ω²M_T U − iωC U) with U ≈ Φz on the right gives
    U = Φz + R F − iω R C Φz, R = K⁻¹ − Φ K̂⁻¹ Φᵀ the residual flexibility
    (R M_T Φ = 0 for Φ mass-orthonormal eigenvectors, so the inertia adds nothing).
    The term −iω R C Φz is the truncated modes' static response to the damping
    forces of the kept ones; without it (the plain static correction, Tuah 1982,
    §5.3) a heavily drag-damped line loses σ: the two-segment chain + rope line of
    ``benchmarks/residual_cost.py`` read its fairlead σ 4.7 % low with 17 of 78
    modes, 0.01 % with the term.  What is left is second order, R(ω²M_T − iωC)R F."""
    phi, mh, kh = prep.modal(system)
    nf, m = phi.shape
    cphi = prep.free_rows(block_matvec(c, prep.nodes(phi)))
    ch = phi.T @ cphi
    ch = 0.5 * (ch + ch.T)
    # the truncated modes' static response to the kept modes' damping forces, R C Φ
    # (n_free_dof, m): see the notes of :func:`_foss_solver`
    rcphi = damping_coupling(system, prep, c, cphi)
    foss = None
    if not modal_direct:
        try:
            foss = foss_modes(mh, ch, kh)
        except SolverError as exc:
            warn(
                f"{exc}; falling back to the direct solve in modal coordinates",
                DefectivePencilWarning,
                stacklevel=3,
            )

    def solve(rhs: np.ndarray, w: np.ndarray) -> np.ndarray:
        n_w, n_ch = rhs.shape[1:]
        flat = np.ascontiguousarray(rhs).reshape(nf, n_w * n_ch)
        fh = real_gemm(phi.T, flat)  # (m, n_w·n_ch), mode-major
        if foss is not None:
            z = foss_transfer_modal(foss, fh, w, n_ch)
        elif modal_direct:
            # batched LU without the conditioning estimate of solve_direct: a singular
            # frequency raises LinAlgError or gives non-finite σ (the coarse start then
            # falls back on the full grid, which has the checks)
            fh3 = np.moveaxis(fh.reshape(m, n_w, n_ch), 1, 0)
            wz = w[:, None, None]
            key = ("stiff_mass", m, w.tobytes())  # K̂ − ω²M̂: drag-independent, per grid
            if key not in prep.cache:
                prep.cache[key] = kh - wz * wz * mh
            # the matrices are symmetric to the bit (K̂, M̂, Ĉ symmetrized): passed as
            # their transposes, whose memory is the column-major layout LAPACK takes, so
            # numpy's copy into it is contiguous (the same matrices and bits, ≈ 10 %
            # faster)
            z3 = np.linalg.solve((prep.cache[key] + 1j * wz * ch).transpose(0, 2, 1), fh3)
            z = np.ascontiguousarray(np.moveaxis(z3, 0, 1)).reshape(m, n_w * n_ch)
        else:
            fh3 = np.moveaxis(fh.reshape(m, n_w, n_ch), 1, 0)
            z3 = solve_direct(kh, mh, ch, fh3, w, method="dense")
            z = np.ascontiguousarray(np.moveaxis(z3, 0, 1)).reshape(m, n_w * n_ch)
        z = np.ascontiguousarray(z)
        u = real_gemm(phi, z)
        if rcphi is not None:
            u += prep.residual(system, flat, fh)
            u -= real_gemm(rcphi, z * np.repeat(1j * w, n_ch))
        return u.reshape(nf, n_w, n_ch)

    return solve


def damping_coupling(
    system: LineSystem, prep: LinePrep, c: NodeBlocks, cphi: np.ndarray | None = None
) -> np.ndarray | None:
    """R C Φ (n_free_dof, m), real: the truncated modes' static response to unit
    damping forces of the kept modes (R = K⁻¹ − Φ K̂⁻¹ Φᵀ the residual flexibility, C
    the damping blocks ``c``); a modal response z then adds −iω R C Φ z (mode
    acceleration with the damping coupling: the notes of :func:`_foss_solver`).  None
    when the line keeps every mode.  ``cphi``: the free rows of C Φ when the caller
    has them."""
    phi = prep.modal(system)[0]
    if phi.shape[1] >= phi.shape[0]:
        return None
    if cphi is None:
        cphi = prep.free_rows(block_matvec(c, prep.nodes(phi)))
    rc = prep.residual(system, np.ascontiguousarray(cphi, dtype=complex)).real
    return np.ascontiguousarray(rc)


def reactions(
    system: LineSystem,
    prep: LinePrep,
    c: NodeBlocks,
    u: np.ndarray,
    f_all: np.ndarray,
    w: np.ndarray,
) -> np.ndarray:
    """Dynamic force of the line on the supports, (n_w, 2d, n_ch):
    −[(K − ω²M_T + iωC)U − F]_end rows, u and f_all in the node layout."""
    d = u.shape[1]
    shape = u.shape[1:]  # (d, n_w, n_ch)
    ua, ua1 = (np.ascontiguousarray(u[i]).reshape(d, -1).view(float) for i in (0, 1))
    ub, ub1 = (np.ascontiguousarray(u[i]).reshape(d, -1).view(float) for i in (-1, -2))

    def rows(x: NodeBlocks) -> tuple[np.ndarray, np.ndarray]:
        """(X U) at the end nodes' rows for real node blocks X, each (d, n_w, n_ch):
        real d × d products on the interleaved views (the complex (n_w, d, d)
        impedance blocks and their einsums were 0.3 ms of the chain)."""
        ra = x[0][0] @ ua + x[1][0].T @ ua1
        rb = x[0][-1] @ ub + x[1][-1] @ ub1
        return tuple(np.ascontiguousarray(r).view(complex).reshape(shape) for r in (ra, rb))

    ww = (w * w)[:, None]
    iw = (1j * w)[:, None]
    out = []
    rg = None if system.gyro is None else gyro_end_rows(system.gyro, (u[1], u[-2]), w)
    if system.lift is not None:  # the linearized lift's iω(C_L U) rows (dynamics.model.lift)
        rl = lift_end_rows(system.lift, lift_pattern(system.model), (u[0], u[1], u[-2], u[-1]), w)
        rg = rl if rg is None else (rg[0] + rl[0], rg[1] + rl[1])
    for k, (rk, rm, rc) in enumerate(zip(rows(prep.K), rows(prep.MT), rows(c))):
        r = rk - ww * rm + iw * rc - f_all[0 if k == 0 else -1]
        if rg is not None:  # iω(G U) and iω(C_L U) rows (dynamics.model.transport, lift)
            r = r + rg[k]
        out.append(np.moveaxis(r, 1, 0))  # (n_w, d, n_ch)
    return -np.concatenate(out, axis=1)


def line_response(
    system: LineSystem,
    inp: LineInputs,
    damping: Damping,
    solved: tuple[np.ndarray, NodeBlocks] | None = None,
) -> Response:
    """Response with reactions and end tensions; ``solved`` = (u, C) of a solve already
    done with this ``damping`` (:func:`_solve_nodes`) skips the solve."""
    prep = line_prep(system)
    u, c = _solve_nodes(system, inp, damping) if solved is None else solved
    support = reactions(system, prep, c, u, end_loads(system, inp, damping), inp.omega)
    disp = to_freq(u)
    return Response(
        omega=inp.omega,
        displacement=disp,
        support_force=support,
        end_tension=end_tension_from_support(system, support),
    )


# --------------------------------------------------------------------------- solve


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
        At an undamped resonance (from :mod:`stochcable.dynamics.model.solvers`).

    Notes
    -----
    Free rows (Tuah 1982, eq. 5.2.6 with prescribed ends):
    (K_ff − ω²M_T,ff + iωC_ff)U_f = [C_d V + B_I A]_f − (K_fb − ω²M_T,fb + iωC_fb)u_b,
    solved directly or by Foss modal superposition (Tuah 1982, §5.3) with the static
    correction of the truncated modes.  For Foss, a moving end is split into the exact
    quasi-static following U_qs = −K_ff⁻¹K_fb u_b and a dynamic part loaded by the
    inertia and damping forces of u_b and U_qs (the classical support-excitation
    split): the stiffness load K_fb u_b, concentrated next to the end, never meets
    the modal truncation, which cut the end-tension error of a 10-mode solve from
    17 % to 0.3 % on the DESIGN.md example.  With all modes both are the direct solve.

    C = C_d + C_s with C_s the seabed dashpots plus the Rayleigh structural damping
    alpha·M_T + beta·K (``system.structural_damping``).  Implementation: node blocks
    of the block-tridiagonal matrices, the direct solve of all frequencies in one
    stacked banded LAPACK call, the Foss transfer as matrix products over all
    frequencies and channels, K_ff⁻¹ by a cached banded Cholesky.
    """
    t0 = time.perf_counter()
    resp = line_response(system, line_inputs(system, channels), damping)
    if timing is not None:
        timing["solve_s"] = timing.get("solve_s", 0.0) + time.perf_counter() - t0
    return resp


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


def end_tension_from_support(system: LineSystem, support: np.ndarray) -> dict[str, np.ndarray]:
    """δ|F| = (F0/|F0|)·δF at each end, shape (n_ch, n_omega)."""
    model = system.model
    comps = list(model.components)
    d = model.dim
    out = {}
    for k, end in enumerate(("end_a", "end_b")):
        u = _end_direction(system, end)[comps]
        df = support[:, k * d : (k + 1) * d, :]  # fixed DOFs: node 0 then node n-1
        out[end] = np.einsum("c,wcr->rw", u, df)
    return out
