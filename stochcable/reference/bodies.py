"""Independent checks of the coupled lines–bodies dynamics (Tuah (1982), §3.3).

The engine (:mod:`stochcable.dynamics.groups`) solves the coupled system by its own
paths (modal lines, Foss, the coarse-start drag fixed point); the solvers here take the
assembled system of :func:`stochcable.bodies.coupling.couple` as it is and solve it
directly at every frequency (dense, or line blocks banded with the bodies' Schur
complement), with the bodies' frequency-dependent added mass and radiation damping
exact at every ω — the reference the tests and benchmarks compare the engine with.
:func:`body_drag_damping` is the reference form of a body's linearized drag.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

from typing import Any, Literal

import numpy as np

from stochcable.bodies.coupling import CoupledSystem
from stochcable.bodies.rigid import PLANAR_INDEX, RigidBody, rigid_link_matrix
from stochcable.dynamics.linearization.formulas import drag_linear_current
from stochcable.dynamics.model.solvers import solve_direct
from stochcable.errors import InputError, SolverError
from stochcable.validation import finite_scalar, float_array

__all__ = ["solve_coupled_direct", "body_drag_damping"]

# Dense fallback of the direct solve up to this many coupled DOFs.
_DENSE_MAX = 3000


def body_drag_damping(
    body: RigidBody, rho: float, sigma: Any, mean: Any | None = None
) -> np.ndarray:
    """Linearized quadratic drag of a body as a damping matrix about its reference point.

    Parameters
    ----------
    body : RigidBody
        The body (``drag_area`` Cd·A per global direction at ``drag_point``).
    rho : float
        Water density. [kg/m³]
    sigma : array_like, shape (3,)
        Standard deviation of the relative velocity (fluid minus body) at the drag
        point along x, y, z. [m/s]
    mean : array_like, shape (3,), optional
        Mean relative velocity (current). [m/s]

    Returns
    -------
    ndarray, shape (d, d)
        Tᵀ diag(b) T with T = :func:`rigid_link_matrix` of the drag point. [N·s/m, …]

    Notes
    -----
    Per direction b = ρ CdA E|v| for v ~ N(U, σ²) (DESIGN.md "Drag linearization",
    :func:`stochcable.dynamics.linearization.formulas.drag_linear_current`); for U = 0 this is
    √(8/π)·½ρ CdA σ (Tuah (1982), eq. 5.2.2).  The fluid load that goes with it is
    Tᵀ diag(b) v_fluid (wave velocity at the drag point).
    """
    rho = finite_scalar("rho", rho, "kg/m³")
    s = float_array("sigma", sigma, "m/s", nonnegative=True)
    u = np.zeros(3) if mean is None else float_array("mean", mean, "m/s")
    if s.shape != (3,) or u.shape != (3,):
        raise InputError("sigma", s.shape, "m/s", "sigma and mean must have 3 components")
    b = np.asarray(drag_linear_current(rho, body.drag_area, 1.0, s, u), dtype=float)
    t = rigid_link_matrix(body.drag_point)
    c = t.T @ np.diag(b) @ t
    if body.planar:
        return c[np.ix_(PLANAR_INDEX, PLANAR_INDEX)]
    return c


def _block(a: Any, rows: np.ndarray, cols: np.ndarray) -> Any:
    return a[rows][:, cols]


def solve_coupled_direct(
    system: CoupledSystem,
    F: Any,
    omega: Any,
    method: Literal["auto", "schur", "dense"] = "auto",
) -> np.ndarray:
    """Harmonic response of the coupled lines–bodies system at every frequency.

    Parameters
    ----------
    system : CoupledSystem
    F : array_like, complex, shape (n_w, n) or (n_w, n, k)
        Loads (:func:`stochcable.bodies.coupling.coupled_load`). [N, N·m]
    omega : array_like, shape (n_w,)
        Angular frequencies. [rad/s]
    method : {"auto", "schur", "dense"}
        ``"schur"``: each line's free block solved by
        :func:`stochcable.dynamics.model.solvers.solve_direct` (banded, all frequencies at once),
        the body DOFs from the Schur complement; ``"dense"``: one batched dense solve
        (small systems); ``"auto"``: schur, falling back to dense (up to 3000 DOFs)
        when a line block alone is singular (a fixed-end line resonance).

    Returns
    -------
    ndarray, complex, same shape as F
        x(ω) = Z(ω)⁻¹ F(ω), Z = K − ω²(M + A(ω)) + iω(C + B(ω)). [m, rad]

    Raises
    ------
    SolverError
        When Z(ω) is singular (undamped resonance).

    Notes
    -----
    The direct solve of DESIGN.md "Solution" with the body's frequency-dependent added
    mass and radiation damping (Tuah (1982), eq. 3.2.c.20) exact at every ω.  A body's
    ``fixed_dofs`` are constraints: those DOFs are removed from the system and their
    motion is exactly zero (their loads are reactions, not inputs).  The Foss
    decomposition needs constant matrices
    (:func:`stochcable.bodies.coupling.constant_matrices`) and is exact
    only where A and B are constant.
    """
    w = float_array("omega", omega, "rad/s", nonnegative=True)
    f = np.asarray(F, dtype=complex)
    squeeze = f.ndim == 2
    if squeeze:
        f = f[:, :, None]
    n = system.n_dof
    if f.ndim != 3 or f.shape[:2] != (w.size, n):
        raise InputError("F", f.shape, "N", f"must have shape ({w.size}, {n}[, k])")
    if not np.isfinite(f).all():
        raise InputError("F", "non-finite", "N", "must be finite")
    if method not in ("auto", "schur", "dense"):
        raise InputError("method", method, "-", "must be 'auto', 'schur' or 'dense'")
    if method == "dense":
        x = _solve_dense(system, f, w)
    else:
        try:
            x = _solve_schur(system, f, w)
        except SolverError:
            if method == "schur" or n > _DENSE_MAX:
                raise
            x = _solve_dense(system, f, w)
    return x[:, :, 0] if squeeze else x


def _free_body(system: CoupledSystem) -> tuple[np.ndarray, np.ndarray]:
    """Global indices of the free body DOFs and, among ``body_index``, their positions
    (the bodies' ``fixed_dofs`` removed)."""
    J = system.body_index
    pos = (
        np.concatenate([system.body_dofs[b.name][b.free_index] for b in system.bodies])
        if system.bodies
        else np.zeros(0, dtype=int)
    )
    where = (
        np.searchsorted(J, pos)
        if np.all(np.diff(J) > 0)
        else np.array([int(np.flatnonzero(J == p)[0]) for p in pos], dtype=int)
    )
    return pos.astype(int), where.astype(int)


def _body_z(system: CoupledSystem, w: np.ndarray) -> np.ndarray:
    """Z_JJ(ω) on the body DOFs, (n_w, n_b, n_b)."""
    J = system.body_index
    a, b = system.body_hydrodynamics(w)
    k = _block(system.K, J, J).toarray()
    m = _block(system.M, J, J).toarray()
    c = _block(system.C, J, J).toarray()
    w2 = (w * w)[:, None, None]
    iw = (1j * w)[:, None, None]
    return k[None] - w2 * (m[None] + a) + iw * (c[None] + b)


def _solve_small(z: np.ndarray, g: np.ndarray, w: np.ndarray, what: str) -> np.ndarray:
    """Batched dense solve; SolverError where ||Z||·||x||/||F|| > 1e12 (the estimate of
    :func:`stochcable.dynamics.model.solvers.solve_direct`) or Z is exactly singular."""
    try:
        x = np.linalg.solve(z, g)
    except np.linalg.LinAlgError:
        est = np.linalg.cond(z)
    else:
        nz = np.linalg.norm(z, axis=(1, 2))
        nf = np.linalg.norm(g.reshape(w.size, -1), axis=1)
        nx = np.linalg.norm(x.reshape(w.size, -1), axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            est = np.where(nf > 0, nz * nx / np.where(nf > 0, nf, 1.0), 0.0)
        est = np.where(np.isfinite(x.reshape(w.size, -1)).all(axis=1), est, np.inf)
    bad = ~(est <= 1e12)
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise SolverError(
            f"{what}: dynamic matrix singular to working precision at omega = "
            f"{float(w[k]):.6g} rad/s (condition estimate {float(est[k]):.2e}; "
            "undamped resonance); add damping or move the frequency"
        )
    return x


def _solve_dense(system: CoupledSystem, f: np.ndarray, w: np.ndarray) -> np.ndarray:
    n = system.n_dof
    if n > _DENSE_MAX:
        raise InputError(
            "method",
            "dense",
            "-",
            f"the dense solve is limited to {_DENSE_MAX} DOFs (system has {n})",
        )
    J = system.body_index
    a, b = system.body_hydrodynamics(w)
    k, m, c = system.K.toarray(), system.M.toarray(), system.C.toarray()
    w2 = (w * w)[:, None, None]
    iw = (1j * w)[:, None, None]
    z = k[None] - w2 * m[None] + iw * c[None]
    if J.size:
        z[np.ix_(np.arange(w.size), J, J)] += -w2 * a + iw * b
    free, _ = _free_body(system)
    keep = np.setdiff1d(np.arange(n), np.setdiff1d(J, free))  # fixed body DOFs out
    if keep.size == n:
        return _solve_small(z, f, w, "coupled direct solve")
    x = np.zeros_like(f)
    x[:, keep, :] = _solve_small(z[:, keep][:, :, keep], f[:, keep, :], w, "coupled direct solve")
    return x


def _solve_schur(system: CoupledSystem, f: np.ndarray, w: np.ndarray) -> np.ndarray:
    n_w, n, n_rhs = f.shape
    # the free body DOFs only: fixed ones stay exactly zero (constraints)
    J, where = _free_body(system)
    nb = J.size
    x = np.zeros_like(f)
    w2 = (w * w)[:, None, None]
    iw = (1j * w)[:, None, None]

    def z_of(rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
        return (
            _block(system.K, rows, cols).toarray()[None]
            - w2 * _block(system.M, rows, cols).toarray()[None]
            + iw * _block(system.C, rows, cols).toarray()[None]
        )

    if nb:
        s = _body_z(system, w)[:, where][:, :, where]
        g = f[:, J, :].copy()
    back = []  # (line DOFs, Z_II⁻¹ Z_IJ) for the back-substitution
    for ln in system.lines:
        I = system.line_dofs[ln.name]
        if I.size == 0:
            continue
        kii, mii, cii = (_block(a, I, I) for a in (system.K, system.M, system.C))
        rhs = np.concatenate([f[:, I, :], z_of(I, J)], axis=2) if nb else f[:, I, :]
        y = solve_direct(kii, mii, cii, rhs, w)
        x[:, I, :] = y[:, :, :n_rhs]
        if nb:
            z_ji = z_of(J, I)
            s = s - z_ji @ y[:, :, n_rhs:]
            g = g - z_ji @ y[:, :, :n_rhs]
            back.append((I, y[:, :, n_rhs:]))
    if nb:
        xb = _solve_small(s, g, w, "coupled direct solve (body Schur complement)")
        x[:, J, :] = xb
        for I, yb in back:
            x[:, I, :] -= yb @ xb
    return x
