"""σ of the relative velocities and the linear drag they give (Tuah 1982, eqs.
5.2.2–5.2.5): the two halves of one step of the drag fixed point.

:func:`drag_coefficients` maps the σ vector to the linearized drag
(:class:`~stochcable.dynamics.model.system.Damping`); :func:`relative_velocity_sigmas` (and
the iteration's faster :func:`sigmas_from_free`) maps a response back to σ.  The σ of
an element is its element mean square,
σ² = Σ_i ∫ S_i ∫₀¹ |row·(v(ξ) − U̇(ξ))|² dξ dω, exact for the wave field and the
structural velocity linear along the element.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from stochcable.compiled import KERNEL_MIN_ENTRIES, optional_kernel
from stochcable.dynamics.linearization.formulas import (
    drag_linear_current,
    drag_linear_harmonic,
    drag_linear_vector,
    mean_abs_gaussian,
)
from stochcable.dynamics.linearization.hu_jin import drag_linear_hu_jin
from stochcable.dynamics.linearization.iteration import FixedPointResult
from stochcable.dynamics.loads.channels import (
    Channel,
)
from stochcable.dynamics.loads.freqblocks import frequency_slices, working_memory_bytes
from stochcable.dynamics.model.blocks import (
    from_freq,
    line_prep,
    real_gemm,
)
from stochcable.dynamics.model.system import (
    Damping,
    LineSystem,
    Response,
)
from stochcable.dynamics.solve.line_loads import (
    LineInputs,
    end_following_at,
    end_nodes,
    line_inputs,
)
from stochcable.errors import InputError
from stochcable.results.documents import LinearizationRecord

# ------------------------------------------------------------------------- damping


def split_sigma(system: LineSystem, x: np.ndarray, method: str) -> dict[str, np.ndarray]:
    """The σ vector (:func:`drag_coefficients` layout) split into "normal" (k, n_el),
    "axial" (n_el,) and "node" (n_drag_nodes,) views, k = 3 for "vector" else 1. [m/s]"""
    n = system.model.n_elements
    k = 3 if method == "vector" else 1
    parts = {
        "normal": x[: k * n].reshape(k, n),
        "axial": x[k * n : (k + 1) * n],
        "node": x[(k + 1) * n :],
    }
    return parts


def _drag_current(
    rho: float,
    cd: np.ndarray | float,
    diameter: np.ndarray | float,
    sigma: np.ndarray,
    mean: np.ndarray,
) -> np.ndarray:
    """:func:`stochcable.dynamics.linearization.formulas.drag_linear_current` without validation
    (finite σ >= 0): the same operations in the same order."""
    return rho * np.asarray(cd, dtype=float) * diameter * mean_abs_gaussian(sigma, mean)


def current_split(system: LineSystem) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The current at the element midpoints split along the element: axial U·e
    (n_el,), the normal vector U − (U·e)e (n_el, 3) and its magnitude (n_el,),
    computed once per line (drag-independent). [m/s]"""
    if "current_split" not in system._cache:
        e = system.frames[0]
        uc = system.current_el
        u_t = np.einsum("ij,ij->i", uc, e)
        u_nvec = uc - u_t[:, None] * e
        system._cache["current_split"] = (u_t, u_nvec, np.linalg.norm(u_nvec, axis=1))
    return system._cache["current_split"]


def drag_coefficients(system: LineSystem, sigma: np.ndarray, method: str) -> Damping:
    """Linear drag of a line from the σ of its relative velocities.

    Parameters
    ----------
    system : LineSystem
        The line.
    sigma : ndarray
        ``[σ_n (n_el), σ_t (n_el), σ_att (n_drag_nodes)]`` for "seed"/"harmonic";
        ``[s1, s2, s3 (3·n_el), σ_t, σ_att]`` for "vector", s1, s2 the σ along n1, n2
        and s3 along (n1 + n2)/√2 (which fixes the covariance). [m/s]
    method : {"seed", "vector", "harmonic"}
        Linearization form (DESIGN.md "Drag linearization").

    Returns
    -------
    Damping

    Notes
    -----
    seed: B_n = ρ Cdn D E|v_n| with v_n ~ N(|U_n|, σ_n²) (:func:`drag_linear_current`;
    = √(8/π)·½ρCdnD·σ_n without current, Tuah (1982), eq. 5.2.2.a); axial the same with
    Cdt and πD (eq. 5.2.2.b) and the mean U·e.  vector: the exact 2×2 normal-plane
    form (:func:`drag_linear_vector`).  harmonic: (8/3π)·½ρCdD·|v̂| with |v̂| = √2 σ
    (the amplitude of a single harmonic of standard deviation σ).  Attachments:
    isotropic, ρ·CdA·E|v| with σ² the total variance of their relative velocity.
    """
    model = system.model
    mesh = model.mesh
    rho = model.rho
    _, n1, n2 = system.frames
    parts = split_sigma(system, np.asarray(sigma, dtype=float), method)
    u_t, u_nvec, u_n = current_split(system)
    d = mesh.diameter
    hu_jin = getattr(mesh, "drag_form", "cross_flow") == "hu_jin"
    if hu_jin and method == "harmonic":
        raise InputError(
            "analysis.linearization.method",
            method,
            "-",
            f"must be 'seed' or 'vector' on line '{system.name}' with drag_form 'hu_jin' "
            "(½ρC_dD|V|V_n has no harmonic linearization here, docs/travelling.md)",
        )
    if method == "vector":
        s1, s2, s3 = parts["normal"]
        c12 = s3**2 - 0.5 * (s1**2 + s2**2)
        c12 = np.clip(c12, -s1 * s2, s1 * s2)
        cov = np.empty((s1.size, 2, 2))
        cov[:, 0, 0], cov[:, 1, 1] = s1**2, s2**2
        cov[:, 0, 1] = cov[:, 1, 0] = c12
        mean = None
        if np.any(u_n > 0):
            mean = np.column_stack(
                [np.einsum("ij,ij->i", u_nvec, n1), np.einsum("ij,ij->i", u_nvec, n2)]
            )
        b_n = drag_linear_vector(rho, mesh.cd_normal, d, cov, mean, u_t if hu_jin else None)
        b_t = drag_linear_current(rho, mesh.cd_axial, math.pi * d, parts["axial"], u_t)
    elif method == "harmonic":
        b_n = drag_linear_harmonic(rho, mesh.cd_normal, d, math.sqrt(2.0) * parts["normal"][0])
        b_t = drag_linear_harmonic(rho, mesh.cd_axial, math.pi * d, math.sqrt(2.0) * parts["axial"])
    else:
        # the iteration's σ are finite and >= 0: skip the public validation (a third
        # of this function's time, called at every iteration); anything else goes
        # through drag_linear_current and its error messages
        sn, st = parts["normal"][0], parts["axial"]
        # finite and >= 0 (NaN fails the comparison; +inf is caught by the sum): the
        # normal and axial σ are the leading part of the σ vector, checked at once
        lead = np.asarray(sigma, dtype=float)[: sn.size + st.size]
        clean = bool((lead >= 0).all() and math.isfinite(float(lead.sum())))
        current = _drag_current if clean else drag_linear_current
        b_n = current(rho, mesh.cd_normal, d, parts["normal"][0], u_n)
        b_t = current(rho, mesh.cd_axial, math.pi * d, parts["axial"], u_t)
        if hu_jin:  # ½ρC_dD|V|V_n with W = U·e − c (linearization.hu_jin)
            b_n = drag_linear_hu_jin(rho, mesh.cd_normal, d, parts["normal"][0], u_n, u_t)
    b_node = np.zeros(model.n_nodes)
    if system.drag_nodes.size:
        idx = system.drag_nodes
        u_node = np.linalg.norm(system.current_node[idx], axis=1)
        sig = parts["node"]
        if method == "harmonic":
            b_node[idx] = drag_linear_harmonic(
                rho, mesh.node_drag_area[idx], 1.0, math.sqrt(2.0) * sig
            )
        else:
            b_node[idx] = drag_linear_current(rho, mesh.node_drag_area[idx], 1.0, sig, u_node)
    b_n = np.atleast_1d(np.asarray(b_n, dtype=float))
    b_t = np.atleast_1d(np.asarray(b_t, dtype=float))
    return Damping(
        method=method,
        sigma=np.asarray(sigma, dtype=float).copy(),
        b_normal=b_n,
        b_axial=b_t,
        b_node=b_node,
        model=model,
    )


def relative_velocity_sigmas(
    system: LineSystem,
    channels: tuple[Channel, ...],
    response: Response | None,
    method: str,
    displacement: np.ndarray | None = None,
) -> np.ndarray:
    """σ of the relative velocity (fluid − structure) of the elements and attachments.

    Parameters
    ----------
    system : LineSystem
    channels : tuple of Channel
        With their spectra on the response grid.
    response : Response or None
        The structural response; None takes ``displacement`` (or the structure at rest).
    method : {"seed", "vector", "harmonic"}
        Layout of the returned vector (see :func:`drag_coefficients`).
    displacement : ndarray, optional
        (n_omega, n_dof, n_ch) displacement used when ``response`` is None. [m/unit]

    Returns
    -------
    ndarray
        The σ vector. [m/s]

    Notes
    -----
    Tuah (1982), eqs. 5.2.3–5.2.5 with an element mean in place of Tuah's nodal value:
    σ² = Σ_i ∫ S_i(ω) ∫₀¹ |r·H_{v,i}(ξ, ω)|² dξ dω (trapezoid on the grid), H_v the
    transfer function of the relative velocity v(ξ) − iωU(ξ) along the element, r
    the element's e (axial) or normals n1, n2; the scalar form uses
    σ_n² = σ_n1² + σ_n2².  The fluid part is integrated exactly
    (:func:`stochcable.dynamics.loads.element_kinematics.element_wave_kinematics`: the wet part
    only), the structural displacement U(ξ) is the element's linear interpolation, so the
    ξ-integral is closed-form (:func:`_element_variance`).  The drag coefficient B is
    then constant over the element (eq. 5.2.2 with this σ).  Attachments: the nodal
    relative velocity.
    """
    inp = line_inputs(system, channels)
    u = None
    if response is not None:
        u = response.displacement
    elif displacement is not None:
        u = displacement
    if u is not None:
        u = from_freq(u, system.model.dim)
    return sigmas_from_nodes(system, inp, u, method)


def _proj_rows(system: LineSystem, method: str) -> np.ndarray:
    """Projection rows of the relative velocity, (n_el, k, d): e, n1 (and n2 in 3-D,
    and (n1 + n2)/√2 for "vector" in 3-D), on the model components."""
    key = ("rows", method)
    if key not in system._cache:
        model = system.model
        comps = list(model.components)
        e, n1, n2 = system.frames
        rows = [e, n1]
        if model.dim == 3:
            rows.append(n2)
            if method == "vector":
                rows.append((n1 + n2) / math.sqrt(2.0))
        system._cache[key] = np.ascontiguousarray(np.stack(rows, axis=1)[:, :, comps])
    return system._cache[key]


def _project_ends(pr: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Projections of node vectors x (n_nodes, d, n_w, n_ch) (complex) at the start and
    the end node of each element: real (n_el, k, 2, 2·n_w·n_ch), the interleaved
    (re, im) view of the complex projections."""
    n, d = x.shape[:2]
    xf = np.ascontiguousarray(x).reshape(n, d, -1).view(float)
    out = np.empty((n - 1, pr.shape[1], 2, xf.shape[-1]))
    np.matmul(pr, xf[:-1], out=out[:, :, 0])
    np.matmul(pr, xf[1:], out=out[:, :, 1])
    return out


def fluid_terms(system: LineSystem, inp: LineInputs, method: str) -> tuple[np.ndarray, bool]:
    """Drag-independent term of the element mean square, cached per inputs and method:
    c0 = Σ weight ∫₀¹ |r·v|² dξ (n_el, k), r the rows of :func:`_proj_rows`, and
    whether there is a fluid velocity (its consistent moments are projected block by
    block: :func:`_projected_moments`)."""
    key = ("fluid", method)
    if key not in inp.cache:
        pr = _proj_rows(system, method)
        if not inp.has_fluid:
            inp.cache[key] = (np.zeros(pr.shape[:2]), False)
        else:
            c0 = np.sum((pr @ inp.square) * pr, axis=2)  # r·S·r (5x the einsum's speed)
            inp.cache[key] = (c0, True)
    return inp.cache[key]


def _projected_moments(pr: np.ndarray, moments: np.ndarray) -> np.ndarray:
    """(r·∫N_a v dξ, r·∫N_b v dξ) of consistent moments (n_el, 2, d, n_w, n_ch) as a real
    (n_el, 2, k, 2·n_w·n_ch) view: one stacked product."""
    n_el, _, d = moments.shape[:3]
    mf = np.ascontiguousarray(moments).reshape(n_el, 2, d, -1).view(float)
    return pr[:, None] @ mf


_GRAM = np.array([[1.0, 0.5], [0.5, 1.0]]) / 3.0  # ∫N_i N_j dξ


def _element_variance(
    system: LineSystem,
    inp: LineInputs,
    method: str,
    u_nodes: np.ndarray | Callable[[slice], np.ndarray] | None = None,
    u_free: np.ndarray | None = None,
) -> np.ndarray:
    """Σ weight ∫₀¹ |r·(v(ξ) + N_a q_a + N_b q_b)|² dξ per element and row, (n_el, k).

    q = −iωU is minus the structural velocity at the element's two nodes, U the node
    displacement ``u_nodes`` (n_nodes, d, n_w, n_ch), or a callable giving it on a
    slice of the frequencies, plus the free-node part ``u_free``
    (n_nodes − 2, d, n_w, n_ch) on the interior nodes (None: nothing; both None: the
    structure at rest).  With m_i = r·∫N_i v and ∫N_a² = ∫N_b² = 1/3, ∫N_a N_b = 1/6
    the integral is ∫|r·v|² + 2Re(m̄_a q_a + m̄_b q_b) + (|q_a|² + |q_b|² +
    Re(q̄_a q_b))/3, summed over blocks of frequencies
    (:func:`~stochcable.dynamics.loads.freqblocks.frequency_slices`): the projections of one
    block only are formed, two stacked real products per block."""
    c0, fluid = fluid_terms(system, inp, method)
    if u_nodes is None and u_free is None:
        return c0
    pr = _proj_rows(system, method)
    n_el, k, d = pr.shape
    n_w, n_ch = inp.weights.shape
    kernel = element_variance_kernel() if n_el * n_w * n_ch >= KERNEL_MIN_ENTRIES else None
    if kernel is not None:  # the same sums in one compiled pass (variance_kernels)
        var = c0.copy()
        # over blocks of frequencies: the block's moments (gathered from the channels)
        # and the kernel's contiguous copies of the block's displacements
        for sl in frequency_slices(n_w, n_ch * 16 * (2 * (n_el + 1) * d + 2 * n_el * d)):
            kernel(
                pr,
                _block(u_nodes, sl),
                None if u_free is None else u_free[:, :, sl],
                inp.omega[sl],
                inp.weights[sl],
                _kernel_moments(inp, sl) if fluid else None,
                var,
            )
        return var
    w2 = _w2(inp)
    var = c0.copy()
    wq = (-1j * inp.omega)[:, None]
    mw_all = _weighted_moments(system, inp, method) if fluid else None
    for sl in frequency_slices(n_w, n_ch * 16 * (3 * (n_el + 1) * d + 5 * n_el * k)):
        cols = slice(2 * n_ch * sl.start, 2 * n_ch * sl.stop)  # the real (re, im) columns
        # U on the block's frequencies (the free part on the interior nodes), times −iω,
        # projected at both ends of every element in one pass
        if u_nodes is not None:
            x = _block(u_nodes, sl) * wq[sl]
            if u_free is not None:
                x[1:-1] += u_free[:, :, sl] * wq[sl]
        else:
            x = np.zeros((n_el + 1, d) + u_free[:, :, sl].shape[2:], dtype=complex)
            np.multiply(u_free[:, :, sl], wq[sl], out=x[1:-1])
        qx = _project_ends(pr, x)
        mw = None
        if mw_all is not None:
            mw = mw_all[..., cols]
        elif fluid:
            mw = np.swapaxes(_projected_moments(pr, inp.moments_at(sl)), 1, 2) * w2[cols]
        var += _structural_variance(qx, w2[cols], mw)
    return var


def _kernel_moments(inp: LineInputs, sl: slice) -> Any:
    """The moments of a block as the variance kernel reads them: the kept whole grid,
    or the channels' element-major storage in place (no gather)."""
    if "moments" in inp.cache:
        return inp.cache["moments"][..., sl, :]
    return inp.fluid_views(sl)


def _block(u: np.ndarray | Callable[[slice], np.ndarray] | None, sl: slice) -> np.ndarray | None:
    """The frequencies ``sl`` of node vectors given as an array or a callable."""
    if u is None:
        return None
    return u(sl) if callable(u) else u[:, :, sl]


def element_variance_kernel() -> Callable[..., None] | None:
    """:func:`stochcable.dynamics.linearization.variance_kernels.element_variance_terms`, or None
    without numba or with ``STOCHCABLE_NUMBA=0`` (the NumPy blocks then)."""
    return optional_kernel(
        "stochcable.dynamics.linearization.variance_kernels", "element_variance_terms"
    )


def _weighted_moments(system: LineSystem, inp: LineInputs, method: str) -> np.ndarray | None:
    """weight·(r·∫N_a v dξ, r·∫N_b v dξ) of all frequencies as a real (n_el, k, 2,
    2·n_w·n_ch) view, cached per inputs and method when it fits in the working-memory
    target (a small model then projects and weighs its moments once, not at every
    evaluation); None when it does not (formed block by block)."""
    key = ("fluid_mw", method)
    if key not in inp.cache:
        pr = _proj_rows(system, method)
        n_el, k = pr.shape[:2]
        n_cols = 2 * inp.weights.size
        if 16 * n_el * k * n_cols > working_memory_bytes():  # (the product and the copy)
            inp.cache[key] = None
        else:
            m = _projected_moments(pr, inp.moments_at())
            inp.cache[key] = np.swapaxes(m, 1, 2) * _w2(inp)
    return inp.cache[key]


def _structural_variance(q: np.ndarray, w2: np.ndarray, mw: np.ndarray | None) -> np.ndarray:
    """The q-terms of :func:`_element_variance` on the real columns of q (n_el, k, 2,
    2N), of the weights w2 (2N,) and of the weighted projected moments mw (n_el, k, 2,
    2N) (a block of columns gives its part of the sums), (n_el, k)."""
    # (|q_a|² + |q_b|² + Re(q̄_a q_b))/3 = ((q_a + q_b)·q_a + q_b·q_b)/3 on the real
    # views: one elementwise pass and one matrix-vector product with the weights
    # (the stacked (2 × 2N)(2N × 2) products of the Gram matrix were 2-3x slower)
    qa, qb = q[:, :, 0], q[:, :, 1]
    t = qa + qb
    t *= qa
    t += qb * qb
    var = (t @ w2) * _GRAM[0, 0]
    if mw is not None:
        var += 2.0 * np.einsum("eksn,eksn->ek", mw, q)  # Σ w (m_a q_a + m_b q_b)
    return var


def _w2(inp: LineInputs) -> np.ndarray:
    """The weights repeated for the interleaved (re, im) views, (2·n_w·n_ch,)."""
    if "w2" not in inp.cache:
        inp.cache["w2"] = np.repeat(inp.weights.ravel(), 2)
    return inp.cache["w2"]


def _sigma_vector(
    system: LineSystem, var: np.ndarray, s_node: np.ndarray, method: str
) -> np.ndarray:
    """The σ vector (layout of :func:`drag_coefficients`) from the element-mean variances
    of the projected relative velocity, var (n_el, k) for the rows of
    :func:`_proj_rows`."""
    var = np.clip(var, 0.0, None)  # round-off of the expanded square
    v_t, v1 = var[:, 0], var[:, 1]
    v2 = var[:, 2] if var.shape[1] > 2 else np.zeros_like(v1)
    if method == "vector":
        v3 = var[:, 3] if var.shape[1] > 3 else 0.5 * v1
        normal = [np.sqrt(v1), np.sqrt(v2), np.sqrt(v3)]
    else:
        normal = [np.sqrt(v1 + v2)]
    return np.concatenate(normal + [np.sqrt(v_t), s_node])


def _weighted_var(x: np.ndarray, inp: LineInputs) -> np.ndarray:
    """Σ_k weight_k |x_k|² over the last axis (n_w·n_ch) of a complex array."""
    xf = x.view(float)
    return (xf * xf) @ _w2(inp)


def _node_sigmas(system: LineSystem, inp: LineInputs, vr_nodes: np.ndarray) -> np.ndarray:
    """σ of the total relative velocity of the attachment nodes, vr_nodes of shape
    (n_drag_nodes, d, n_w, n_ch)."""
    if vr_nodes.shape[0] == 0:
        return np.zeros(0)
    n, d = vr_nodes.shape[:2]
    # the weighted mean square per node and component, summed over the components
    # (flattening the components into the frequency axis mismatched the weights: every
    # scene with an attachment drag area and a sea failed)
    flat = np.ascontiguousarray(vr_nodes).reshape(n * d, -1)
    return np.sqrt(_weighted_var(flat, inp).reshape(n, d).sum(axis=1))


def sigmas_from_nodes(
    system: LineSystem, inp: LineInputs, u: np.ndarray | None, method: str
) -> np.ndarray:
    """σ vector from node displacements u (n_nodes, d, n_w, n_ch) (None: at rest)."""
    model = system.model
    n_w, n_ch = inp.weights.shape
    idx = system.drag_nodes
    if u is None:
        var = _element_variance(system, inp, method)
        vr = (
            np.zeros((idx.size, model.dim, n_w, n_ch), dtype=complex)
            if inp.velocity is None
            else inp.velocity[idx]
        )
    else:
        var = _element_variance(system, inp, method, u)
        q = (-1j * inp.omega)[:, None] * u[idx]
        vr = q if inp.velocity is None else q + inp.velocity[idx]
    return _sigma_vector(system, var, _node_sigmas(system, inp, vr), method)


def end_motion_projections(system: LineSystem, inp: LineInputs, method: str) -> tuple:
    """Drag-independent parts of :func:`sigmas_from_free`, cached per inputs and solver:
    the node displacement U_p of :func:`end_following_at` as a callable on a slice of
    the frequencies (None without end motion: formed block by block), the factors −iω
    per column (n_w·n_ch,) and the attachments' V + Q (n_drag_nodes, d, n_w, n_ch)."""
    key = ("qproj", system.solver)
    prep = line_prep(system)
    if key not in inp.cache:
        wcol = np.repeat(-1j * inp.omega, inp.weights.shape[1])
        idx = system.drag_nodes
        y = np.zeros((idx.size, prep.d) + inp.weights.shape, dtype=complex)
        if inp.velocity is not None:
            y += inp.velocity[idx]
        if inp.ub is not None and idx.size:
            y += (-1j * inp.omega)[:, None] * end_following_at(system, prep, inp, nodes=idx)
        inp.cache[key] = (wcol, y)
    if inp.ub is None:
        return (None, *inp.cache[key])

    def u_p(sl: slice) -> np.ndarray:  # (not kept in the cache: no reference cycle)
        return end_following_at(system, prep, inp, sl)

    return (u_p, *inp.cache[key])


def sigmas_from_free(
    system: LineSystem, inp: LineInputs, u_free: np.ndarray, method: str
) -> np.ndarray:
    """σ vector from the free-node dynamic part of :func:`solve_free`: the structure's
    velocity is that of U_p (:func:`end_following`) plus iω u_f
    (:func:`_element_variance`, over blocks of frequencies)."""
    prep = line_prep(system)
    u_p, wcol, y = end_motion_projections(system, inp, method)
    var = _element_variance(system, inp, method, u_p, u_free)
    idx = system.drag_nodes
    s_node = np.zeros(0)
    if idx.size:
        u_node = np.zeros((idx.size,) + u_free.shape[1:], dtype=complex)
        inner = (idx > 0) & (idx < prep.n - 1)
        u_node[inner] = u_free[idx[inner] - 1]
        vr = y + wcol.reshape(u_free.shape[2:]) * u_node
        s_node = _node_sigmas(system, inp, vr)
    return _sigma_vector(system, var, s_node, method)


def rest_sigmas(system: LineSystem, inp: LineInputs, method: str) -> np.ndarray:
    """The σ of the start (step 5): the fluid velocity relative to the line following
    its ends quasi-statically, :func:`sigmas_from_nodes` of :func:`quasi_static_motion`.  For
    Foss that motion is U_p of :func:`end_following` (the same numbers)."""
    if system.solver == "direct":
        return sigmas_from_nodes(system, inp, quasi_static_motion(system, inp), method)
    u_p, _, y = end_motion_projections(system, inp, method)
    return _sigma_vector(
        system,
        _element_variance(system, inp, method, u_p),
        _node_sigmas(system, inp, y),
        method,
    )


def quasi_static_motion(system: LineSystem, inp: LineInputs) -> np.ndarray | None:
    """Node displacements of the line following its prescribed ends quasi-statically,
    U_f = −K_ff⁻¹K_fb u_b, (n_omega, n_nodes, d, n_ch); None without end motion."""
    if inp.ub is None:
        return None
    prep = line_prep(system)
    u = end_nodes(inp, prep.n, prep.d)
    ub = np.ascontiguousarray(inp.ub.reshape(2 * prep.d, -1))
    u[1:-1] = real_gemm(prep.follower(), ub).reshape(u[1:-1].shape)
    return u


def linearization_record(
    system: LineSystem,
    sigma: np.ndarray,
    damping: Damping,
    fp: FixedPointResult,
    tolerance: float,
    method: str,
) -> LinearizationRecord:
    """The record of a converged (or flagged) drag fixed point of one line: the
    iteration history of ``fp`` (a FixedPointResult), the final σ (the
    :func:`drag_coefficients` layout) split into normal and axial, and the linear
    drag (the vector form reports σ_n = |σ| and b_n = trace/2 of its 2×2 blocks)."""
    parts = split_sigma(system, sigma, method)
    if method == "vector":
        sig_n = np.sqrt(parts["normal"][0] ** 2 + parts["normal"][1] ** 2)
        b_n = 0.5 * np.trace(damping.b_normal, axis1=1, axis2=2)
    else:
        sig_n, b_n = parts["normal"][0], damping.b_normal
    return LinearizationRecord(
        method=method,
        converged=fp.converged,
        iterations=fp.iterations,
        relative_change=fp.relative_change,
        history=fp.history,
        tolerance=tolerance,
        sigma_normal=sig_n,
        sigma_axial=parts["axial"],
        b_normal=b_n,
        b_axial=damping.b_axial,
    )
