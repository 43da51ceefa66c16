"""Modal frequency-domain solves of ``M_T U'' + C U' + K U = F`` (Tuah 1982, §5.3;
DESIGN.md "Solution: direct and Foss"), in the layout of
:mod:`stochcable.dynamics.model.solvers` (frequency first, ``Z(omega) = K - omega^2 M +
i omega C``).

- :func:`modal_basis` — lowest modes of ``(K, M)``, mass-normalized.
- :func:`foss_decomposition`, :func:`foss_transfer` — Foss' state-space
  decoupling of the (non-proportionally damped) modal equations
  (:func:`foss_modes`, :func:`foss_transfer_modal`: the same without validation,
  for the engine's inner loop).
- :func:`solve_modal` — truncated modal solve (Foss or direct in modal
  coordinates) with static correction for the truncated modes.
- :func:`auto_mode_count` — how many modes a frequency range needs.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
from scipy.linalg import lapack

from stochcable import validation as _v
from stochcable.dynamics.model.solvers import (
    Matrix,
    as_matrix,
    check_conditioning,
    dense_matrix,
    load_array,
    solve_dense_batched,
    system_matrices,
)
from stochcable.errors import InputError, PhysicsWarning, SolverError, warn

__all__ = [
    "DefectivePencilWarning",
    "FossModes",
    "auto_mode_count",
    "foss_decomposition",
    "foss_modes",
    "foss_transfer",
    "foss_transfer_modal",
    "modal_basis",
    "solve_modal",
]

#: Eigenvector condition number above which the Foss pencil is treated as defective.
DEFECTIVE_CONDITION = 1e7


class DefectivePencilWarning(PhysicsWarning):
    """The Foss eigenproblem is (nearly) defective, e.g. a critically damped mode."""


# ---------------------------------------------------------------------------------
# modes
# ---------------------------------------------------------------------------------


def modal_basis(K: Matrix, M: Matrix, n_modes: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    r"""Lowest natural frequencies and mass-normalized mode shapes of ``(K, M)``.

    Parameters
    ----------
    K : ndarray or scipy.sparse matrix, shape (n_dof, n_dof)
        Symmetric positive definite stiffness. [N/m]
    M : ndarray or scipy.sparse matrix, shape (n_dof, n_dof)
        Symmetric positive definite mass. [kg]
    n_modes : int, optional
        Number of modes (default all). [-]

    Returns
    -------
    omega_n : ndarray, shape (n_modes,)
        Natural frequencies, ascending. [rad/s]
    phi : ndarray, shape (n_dof, n_modes)
        Mode shapes with ``phi^T M phi = I``; sign fixed so that the entry of
        largest magnitude of each mode is positive. [kg^-1/2]

    Raises
    ------
    SolverError
        If ``K`` has a clearly negative eigenvalue (unstable equilibrium) or
        ``M`` is not positive definite.

    Notes
    -----
    ``K phi = omega_n^2 M phi`` (DESIGN.md "Cable model", modes).  Dense input (or
    sparse up to 2000 DOF, or more than half the modes) uses LAPACK ``eigh``
    with an index subset; larger sparse models use ARPACK shift-invert about 0.
    """
    import scipy.sparse.linalg as spla  # (here: ~10 ms of import most analyses skip)

    K_ = as_matrix("K", K)
    n = K_.shape[0]
    M_ = as_matrix("M", M, n)
    m = n if n_modes is None else _v.positive_int("n_modes", n_modes)
    if m > n:
        raise InputError("n_modes", n_modes, "-", f"must be <= n_dof = {n}")
    if sp.issparse(K_) and n > 2000 and 2 * m < n:
        lam, phi = spla.eigsh(sp.csc_matrix(K_), k=m, M=sp.csc_matrix(M_), sigma=0.0, which="LM")
        order = np.argsort(lam)
        lam, phi = lam[order], phi[:, order]
        mm = np.einsum("ij,ij->j", phi, M_ @ phi)
        phi = phi / np.sqrt(mm)
    else:
        try:
            lam, phi = sla.eigh(
                dense_matrix(K_, n), dense_matrix(M_, n), subset_by_index=[0, m - 1]
            )
        except np.linalg.LinAlgError as exc:
            raise SolverError(
                f"modal analysis failed: M is not positive definite ({exc})"
            ) from None
    scale = max(float(np.max(np.abs(lam))), np.finfo(float).tiny)
    if lam[0] < -1e-9 * scale:
        raise SolverError(
            f"K has a negative eigenvalue ({lam[0]:.3e} (rad/s)^2): the equilibrium is "
            "unstable or the model is not restrained; check the end conditions and statics"
        )
    omega_n = np.sqrt(np.clip(lam, 0.0, None))
    idx = np.argmax(np.abs(phi), axis=0)
    sign = np.sign(phi[idx, np.arange(phi.shape[1])])
    return omega_n, phi * np.where(sign == 0, 1.0, sign)


def auto_mode_count(omega_n: np.ndarray, omega_max: float, factor: float = 2.5) -> int:
    """Number of modes with natural frequency up to ``factor * omega_max``.

    Parameters
    ----------
    omega_n : array_like
        Natural frequencies, ascending. [rad/s]
    omega_max : float
        Highest frequency of the excitation (where its spectrum is significant). [rad/s]
    factor : float, optional
        Safety factor (> 1); the modes above contribute quasi-statically and are
        covered by the static correction of :func:`solve_modal`. [-]

    Returns
    -------
    int
        Mode count, at least 1 and at most ``len(omega_n)``. [-]
    """
    wn = _v.float_array("omega_n", omega_n, "rad/s", nonnegative=True)
    wmax = _v.positive("omega_max", omega_max, "rad/s")
    fac = _v.in_range("factor", factor, "-", 1.0)
    return int(min(wn.size, max(1, np.count_nonzero(wn <= fac * wmax))))


# ---------------------------------------------------------------------------------
# Foss
# ---------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class FossModes:
    """Complex modes of the first-order (Foss) form of the modal equations.

    Attributes
    ----------
    lambdas : ndarray, complex, shape (2n,)
        Eigenvalues ``lambda_j`` of ``lambda A theta + B theta = 0``. [rad/s]
    chi : ndarray, complex, shape (n, 2n)
        Lower halves ``chi_j`` of the eigenvectors ``theta_j = [lambda_j chi_j; chi_j]``.
    a : ndarray, complex, shape (2n,)
        ``a_j = theta_j^T A theta_j`` (plain transpose).
    weights : ndarray, complex, shape (2n, n)
        ``G^{-1} chi^T`` with ``G = Theta^T A Theta`` (``= diag(a)`` up to
        round-off; the full ``G`` keeps repeated eigenvalues exact), computed as
        ``Theta^{-1} [Mhat^{-1}; 0]`` (the same matrix, see
        :func:`foss_decomposition`).
    condition : float
        LAPACK ``gecon`` estimate of the 1-norm condition number of the
        column-normalized eigenvector matrix (within a factor ``2n`` of the
        2-norm one). [-]
    """

    lambdas: np.ndarray
    chi: np.ndarray
    a: np.ndarray
    weights: np.ndarray
    condition: float


def foss_decomposition(Mhat: np.ndarray, Chat: np.ndarray, Khat: np.ndarray) -> FossModes:
    r"""Foss state-space decoupling of ``Mhat z'' + Chat z' + Khat z = Fhat``.

    Parameters
    ----------
    Mhat : array_like, shape (n, n)
        Modal mass (``I`` for mass-normalized modes). [kg]
    Chat : array_like, shape (n, n)
        Modal damping, full (non-proportional). [N·s/m]
    Khat : array_like, shape (n, n)
        Modal stiffness. [N/m]

    Returns
    -------
    FossModes

    Raises
    ------
    SolverError
        If the pencil is (nearly) defective — estimated eigenvector matrix condition
        number above ``DEFECTIVE_CONDITION`` (1e7), e.g. a critically damped mode, where
        some ``a_j`` vanish — or ``Mhat`` is not positive definite.

    Notes
    -----
    Tuah (1982), eqs. (5.3.4)-(5.3.20), as fixed in DESIGN.md: ``q = [z'; z]``,
    ``A = [[0, M], [M, C]]``, ``B = [[-M, 0], [0, K]]``, ``A q' + B q = [0; F]``.
    Eigenpairs of ``lambda A theta + B theta = 0``, computed as the standard
    eigenproblem of ``A^{-1}(-B) = [[-M^{-1} C, -M^{-1} K], [I, 0]]`` (``Mhat`` is
    SPD; LAPACK geev), ``theta_j = [lambda_j chi_j; chi_j]``,
    ``a_j = theta_j^T A theta_j``.
    Overdamped (real) eigenvalues and ``C = 0`` (``lambda = +-i omega_n``) need no
    special case.  For repeated eigenvalues (mode crossover) LAPACK returns some basis
    of the eigenspace, not necessarily ``A``-orthogonal; the transfer therefore
    uses ``G^{-1}`` with the full ``G = Theta^T A Theta`` — the exact identity
    ``(i w A + B)^{-1} = Theta (i w - Lambda)^{-1} G^{-1} Theta^T`` valid for any
    non-defective pencil — which reduces to ``1/a_j`` when the eigenvalues are
    distinct.

    Cost: one real ``geev`` of size 2n and one complex LU of ``Theta``.  The LU
    serves twice: ``gecon`` estimates the condition number from it (O(n²), instead
    of an SVD, which cost as much as the eigenproblem), and the weights are
    ``G^{-1} chi^T = Theta^{-1} A^{-1} Theta^{-T} Theta^T [0; I]
    = Theta^{-1} [Mhat^{-1}; 0]``, so ``G`` is never formed;
    ``a_j = 2 lambda_j chi_j^T Mhat chi_j + chi_j^T Chat chi_j`` (seed eq. 5.3.18).
    """
    Mh = _v.float_array("Mhat", Mhat, "kg", ndim=2)
    n = Mh.shape[0]
    Ch = _v.float_array("Chat", Chat, "N*s/m", ndim=2)
    Kh = _v.float_array("Khat", Khat, "N/m", ndim=2)
    for name, arr in (("Mhat", Mh), ("Chat", Ch), ("Khat", Kh)):
        if arr.shape != (n, n):
            raise InputError(name, arr, "-", f"must have shape ({n}, {n})")
    return foss_modes(Mh, Ch, Kh)


def foss_modes(Mh: np.ndarray, Ch: np.ndarray, Kh: np.ndarray) -> FossModes:
    """:func:`foss_decomposition` without validation (float arrays of shape (n, n))."""
    n = Mh.shape[0]
    try:
        mc = sla.cho_factor(Mh, check_finite=False)
    except np.linalg.LinAlgError:
        raise SolverError("Foss eigenproblem: Mhat is not positive definite") from None
    # A^{-1}(-B) = [[-M^-1 C, -M^-1 K], [I, 0]] acting on theta = [lambda chi; chi]:
    # a standard eigenproblem (LAPACK geev), 3-5x faster than QZ on the pencil
    # one triangular solve for M^-1 [C, K, I] (M^-1 also gives the weights below)
    minv = sla.cho_solve(mc, np.hstack([Ch, Kh, np.eye(n)]), check_finite=False)
    S = np.zeros((2 * n, 2 * n))
    S[:n] = -minv[:, : 2 * n]
    S[n:, :n] = np.eye(n)
    # NumPy's geev: the same LAPACK routine as scipy.linalg.eig, but its gufunc
    # releases the GIL (SciPy's f2py wrapper holds it, scipy/scipy#12436), so the
    # lines of a coupled group decompose concurrently (stochcable.runtime)
    lam, theta = np.linalg.eig(S)
    if not np.all(np.isfinite(lam)):  # pragma: no cover - S is finite
        raise SolverError("Foss eigenproblem produced non-finite eigenvalues")
    # SciPy's layout (complex, Fortran order), so the column norms sum in the same
    # order as before the switch: the decomposition is the same to the bit
    theta = np.asfortranarray(theta, dtype=complex)
    lam = lam.astype(complex, copy=False)
    theta /= np.linalg.norm(theta, axis=0)
    # One LU of the column-normalized eigenvector matrix gives both the condition
    # estimate (LAPACK gecon, 1-norm) and the weights Theta^{-1} A^{-1} [0; I].
    lu, piv = sla.lu_factor(theta, check_finite=False)
    if np.any(np.diagonal(lu) == 0.0):
        cond = np.inf
    else:
        rcond, _ = lapack.zgecon(lu, float(np.abs(theta).sum(axis=0).max()), norm="1")
        cond = 1.0 / rcond if rcond > 0 else np.inf
    if not np.isfinite(cond) or cond > DEFECTIVE_CONDITION:
        raise SolverError(
            f"Foss eigenproblem is (nearly) defective: eigenvector condition number "
            f"{cond:.2e} > {DEFECTIVE_CONDITION:.0e} (a critically damped mode, a_j ~ 0); "
            "use the direct modal solve (solve_modal(method='modal_direct'))"
        )
    chi = theta[n:]
    # A^{-1} [0; I] = [M^{-1}; 0] (A = [[0, M], [M, C]])
    rhs = np.zeros((2 * n, n), dtype=complex)
    rhs[:n] = minv[:, 2 * n :]
    weights = sla.lu_solve((lu, piv), rhs, check_finite=False)
    # a_j = theta_j^T A theta_j = 2 lambda_j chi_j^T M chi_j + chi_j^T C chi_j
    a = 2.0 * lam * np.einsum("ij,ij->j", chi, Mh @ chi) + np.einsum("ij,ij->j", chi, Ch @ chi)
    return FossModes(lam, chi, a, weights, float(cond))


def _mode_of_pair(foss: FossModes, j: int) -> int:
    return int(np.argmax(np.abs(foss.chi[:, j]))) + 1


def foss_transfer(foss: FossModes, F_hat: np.ndarray, omega: np.ndarray) -> np.ndarray:
    r"""Modal response ``z(omega)`` from the Foss modes.

    Parameters
    ----------
    foss : FossModes
        From :func:`foss_decomposition`.
    F_hat : array_like, complex, shape (n_omega, n) or (n_omega, n, n_rhs)
        Modal loads ``Phi^T F``. [N·kg^-1/2 for mass-normalized modes]
    omega : array_like, shape (n_omega,)
        Angular frequencies. [rad/s]

    Returns
    -------
    ndarray, complex, same shape as ``F_hat``
        Modal coordinates ``z``. [kg^1/2·m]

    Raises
    ------
    SolverError
        At an undamped resonance: ``|i omega - lambda_j| < 1e-12 max(|lambda_j|,
        omega)``; the message names omega, ``lambda_j`` and the mode.

    Notes
    -----
    ``z(omega) = sum_j chi_j (chi_j^T F_hat) / (a_j (i omega - lambda_j))`` (DESIGN.md;
    Tuah (1982), eqs. 5.3.27-5.3.29), evaluated as ``chi diag(1/(i w - lambda)) G^{-1}
    chi^T F_hat`` (see :func:`foss_decomposition`): ``O(n^2)`` per frequency.
    """
    w = _v.float_array("omega", omega, "rad/s", nonnegative=True)
    n = foss.chi.shape[0]
    f, squeeze = load_array(F_hat, n, w.size)
    n_w, _, r = f.shape
    fm = np.ascontiguousarray(np.moveaxis(f, 0, 1)).reshape(n, n_w * r)
    z = foss_transfer_modal(foss, fm, w, r)
    z = np.moveaxis(z.reshape(n, n_w, r), 1, 0)
    return z[:, :, 0] if squeeze else z


def foss_transfer_modal(foss: FossModes, f: np.ndarray, w: np.ndarray, r: int) -> np.ndarray:
    """:func:`foss_transfer` in the mode-major layout, no validation.

    ``f`` complex (n, n_w·r) with column ``k·r + c`` = frequency k, right-hand side c;
    returns z in the same layout: two matrix products (BLAS gemm) for all
    frequencies and right-hand sides."""
    lam = foss.lambdas
    den = 1j * w[None, :] - lam[:, None]  # (2n, n_w)
    scale = np.maximum(np.abs(lam)[:, None], w[None, :])
    bad = np.abs(den) <= 1e-12 * scale
    if bad.any():
        j, k = (int(x[0]) for x in np.nonzero(bad))
        raise SolverError(
            f"undamped resonance at omega = {w[k]:.6g} rad/s: Foss eigenvalue "
            f"lambda = {lam[j]:.6g} of modal coordinate {_mode_of_pair(foss, j)} has no "
            "damping; add damping or remove this frequency from the grid"
        )
    p = foss.weights @ f  # (2n, n_w·r)
    p = p.reshape(lam.size, w.size, r)
    p /= den[:, :, None]
    return foss.chi @ p.reshape(lam.size, -1)


# ---------------------------------------------------------------------------------
# modal solve
# ---------------------------------------------------------------------------------


def _residual_flexibility_times(
    K: Matrix, phi: np.ndarray, Kh: np.ndarray, f: np.ndarray
) -> np.ndarray:
    """(K^{-1} - phi Kh^{-1} phi^T) f for f of shape (n_omega, n, r)."""
    import scipy.sparse.linalg as spla  # (here: ~10 ms of import most analyses skip)

    n = K.shape[0]
    modal = phi @ np.linalg.solve(Kh, phi.T)
    if sp.issparse(K) and n > 2000:
        lu = spla.splu(sp.csc_matrix(K))
        rhs = np.moveaxis(f, 0, 1).reshape(n, -1)
        full = lu.solve(np.ascontiguousarray(rhs.real)) + 1j * lu.solve(
            np.ascontiguousarray(rhs.imag)
        )
        return np.moveaxis(full.reshape(n, f.shape[0], -1), 1, 0) - modal @ f
    try:
        cf = sla.cho_factor(dense_matrix(K, n))
    except np.linalg.LinAlgError:
        raise SolverError("static correction: K is not positive definite") from None
    flex = sla.cho_solve(cf, np.eye(n)) - modal
    return 0.5 * (flex + flex.T) @ f


def solve_modal(
    K: Matrix,
    M: Matrix,
    C: Matrix | None,
    F: np.ndarray,
    omega: np.ndarray,
    n_modes: int | None = None,
    method: Literal["foss", "modal_direct"] = "foss",
    static_correction: bool = True,
    basis: tuple[np.ndarray, np.ndarray] | None = None,
) -> np.ndarray:
    r"""Truncated modal solution of ``M U'' + C U' + K U = F``, Foss or direct in modal space.

    Parameters
    ----------
    K, M : ndarray or scipy.sparse matrix, shape (n_dof, n_dof)
        Stiffness [N/m] and total mass [kg].
    C : ndarray or scipy.sparse matrix or None
        Damping (need not be proportional). [N·s/m]
    F : array_like, shape (n_omega, n_dof) or (n_omega, n_dof, n_rhs)
        Complex load amplitudes. [N]
    omega : array_like, shape (n_omega,)
        Angular frequencies. [rad/s]
    n_modes : int, optional
        Number of lowest modes kept (default: all, or all of ``basis``). [-]
    method : {"foss", "modal_direct"}, optional
        ``"foss"``: Foss decoupling (:func:`foss_decomposition`), falling back to
        ``"modal_direct"`` with a :class:`DefectivePencilWarning` when the pencil
        is defective (critically damped mode).  ``"modal_direct"``: batched solve
        of ``(Khat - w^2 Mhat + i w Chat) z = Phi^T F`` (n_modes x n_modes).
    static_correction : bool, optional
        Add the response of the truncated modes by mode acceleration with the
        damping coupling, ``R F - i w R C Phi z`` with ``R = K^{-1} - Phi Khat^{-1}
        Phi^T`` (Notes).
    basis : (omega_n, phi), optional
        Precomputed :func:`modal_basis` output (reuse it across the iterations of
        the drag linearization, where only ``C`` changes).

    Returns
    -------
    ndarray, complex, same shape as ``F``
        Response amplitudes ``U = Phi z (+ static correction)``. [m]

    Raises
    ------
    SolverError
        At an undamped resonance (message names omega and the mode).

    Notes
    -----
    Tuah (1982), §5.3: ``U = Phi z`` (eq. 5.3.1), ``Mhat = Phi^T M Phi``, ``Chat =
    Phi^T C Phi`` (full), ``Khat = Phi^T K Phi`` (eq. 5.3.3).  With all modes kept
    this equals :func:`solve_direct` to round-off.  The truncated modes are taken
    by mode acceleration, ``U = K^{-1}(F + w^2 M U - i w C U)`` with ``U ~ Phi z``
    on the right: ``U = Phi z + R F - i w R C Phi z`` (``R M Phi = 0`` for
    mass-orthonormal eigenvectors).  The last term, the truncated modes' static
    response to the kept modes' damping forces, matters on heavily damped lines
    (a drag-damped synthetic rope: 4.7 % of σ); what is left is second order,
    ``R (w^2 M - i w C) R F``.
    """
    K_, M_, C_ = system_matrices(K, M, C)
    n = K_.shape[0]
    w = _v.float_array("omega", omega, "rad/s", nonnegative=True)
    f, squeeze = load_array(F, n, w.size)
    if method not in ("foss", "modal_direct"):
        raise InputError("method", method, "-", "must be 'foss' or 'modal_direct'")
    if basis is None:
        _, phi = modal_basis(K_, M_, n_modes)
    else:
        phi = _v.float_array("basis[1]", basis[1], "kg^-1/2", ndim=2)
        if phi.shape[0] != n:
            raise InputError("basis[1]", phi, "-", f"must have {n} rows")
        if n_modes is not None:
            m = _v.positive_int("n_modes", n_modes)
            if m > phi.shape[1]:
                raise InputError("n_modes", n_modes, "-", f"must be <= {phi.shape[1]}")
            phi = phi[:, :m]
    m = phi.shape[1]
    Mh = phi.T @ (M_ @ phi)
    Kh = phi.T @ (K_ @ phi)
    Ch = np.zeros((m, m)) if C_ is None else phi.T @ (C_ @ phi)
    Mh, Kh, Ch = 0.5 * (Mh + Mh.T), 0.5 * (Kh + Kh.T), 0.5 * (Ch + Ch.T)
    fh = phi.T @ f  # (m, n) @ (n_omega, n, r) -> (n_omega, m, r)
    z = None
    if method == "foss":
        try:
            foss = foss_decomposition(Mh, Ch, Kh)
        except SolverError as exc:
            warn(
                f"{exc}; falling back to the direct solve in modal coordinates",
                DefectivePencilWarning,
                stacklevel=2,
            )
        else:
            z = foss_transfer(foss, fh, w)
    if z is None:
        z = solve_dense_batched(Kh, Mh, Ch, fh, w)
        check_conditioning(Kh, Mh, Ch, w, fh, z)
    u = phi @ z
    if static_correction and m < n:
        u = u + _residual_flexibility_times(K_, phi, Kh, f)
        if C_ is not None:  # the damping coupling: −iω R C Φ z
            rcphi = _residual_flexibility_times(K_, phi, Kh, (C_ @ phi)[None].astype(complex))
            u = u - (1j * w)[:, None, None] * (rcphi[0].real @ z)
    if not np.all(np.isfinite(u)):  # pragma: no cover - guarded above
        raise SolverError("modal solve produced non-finite values")
    return u[:, :, 0] if squeeze else u
