"""The lowest complex modes of a long travelling line: shift-invert Arnoldi.

The first-order system ż = S z, z = (φ, λφ), S = [[0, I], [−M⁻¹K, −M⁻¹D]], has the
inverse S⁻¹ z = (−K⁻¹(D z₁ + M z₂), z₁): one sparse LU of the effective stiffness K
(positive definite below the critical speed) serves every product, and ARPACK's
largest 1/λ are the smallest |λ|.  The left eigenvectors are the right ones of the
transposed problem (D → Dᵀ, M and K symmetric), matched to the right ones by
eigenvalue and bi-normalized ψᵀ(2λM + D)φ = I within each cluster of equal λ
(degenerate in- and out-of-plane pairs).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from stochcable.errors import SolverError

__all__ = ["lowest_complex_modes"]

# Eigenvalues closer than this (relative to |λ|) form one cluster: ARPACK returns
# them to ~1e-12 on these pencils, distinct modes of a line differ by far more.
_CLUSTER_TOL = 1.0e-7


def _operator(m: Any, d: Any, k: Any) -> spla.LinearOperator:
    n = m.shape[0]
    try:
        lu = spla.splu(sp.csc_matrix(k))
    except RuntimeError as exc:  # singular K: at a divergence
        raise SolverError(
            "the effective stiffness K + K_c is singular: the line is at a divergence"
        ) from exc

    def solve(b: np.ndarray) -> np.ndarray:
        return lu.solve(np.ascontiguousarray(b.real)) + 1j * lu.solve(np.ascontiguousarray(b.imag))

    def matvec(z: np.ndarray) -> np.ndarray:
        z = np.asarray(z).reshape(-1)
        z1, z2 = z[:n], z[n:]
        return np.concatenate([-solve(d @ z1 + m @ z2), z1])

    return spla.LinearOperator((2 * n, 2 * n), matvec=matvec, dtype=complex)


def _eigs(m: Any, d: Any, k: Any, nev: int) -> tuple[np.ndarray, np.ndarray]:
    n = m.shape[0]
    op = _operator(m, d, k)
    rng = np.random.default_rng(0)  # a fixed ARPACK start: reproducible modes
    v0 = rng.standard_normal(2 * n) + 0j
    try:
        mu, vec = spla.eigs(op, k=nev, which="LM", v0=v0, tol=1e-12, maxiter=20 * n)
    except spla.ArpackNoConvergence as exc:
        raise SolverError(
            f"the complex modes did not converge (ARPACK: {exc.eigenvalues.size} of {nev})"
        ) from exc
    lam = 1.0 / mu
    return lam, vec[:n]


def lowest_complex_modes(
    m: Any, d: Any, k: Any, count: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Lowest ``count`` eigenvalues with Im λ >= 0, right and left shapes.

    Parameters
    ----------
    m, d, k : sparse, shape (n, n)
        Free–free mass (symmetric), damping plus gyroscopic, and effective stiffness
        (symmetric, nonsingular).
    count : int
        Modes to return.

    Returns
    -------
    lam : ndarray of complex, shape (count,)
    phi, psi : ndarray of complex, shape (n, count)
        Right and left shapes, ψᵀ(2λM + D)φ = 1 (identity within a cluster).
    """
    n = m.shape[0]
    nev = min(2 * count + 6, 2 * n - 2)
    lam_r, phi_all = _eigs(m, d, k, nev)
    lam_l, psi_all = _eigs(m, d.T.tocsr(), k, nev)
    scale = float(np.abs(lam_r).max())
    keep = np.flatnonzero(lam_r.imag >= -_CLUSTER_TOL * scale)
    keep = keep[np.lexsort((-lam_r.real[keep], np.abs(lam_r[keep])))][:count]
    lam = lam_r[keep]
    phi = phi_all[:, keep]
    psi = np.zeros_like(phi)
    done = np.zeros(keep.size, dtype=bool)
    for i in range(keep.size):
        if done[i]:
            continue
        tol = _CLUSTER_TOL * max(abs(lam[i]), 1e-300)
        cl_r = np.flatnonzero(np.abs(lam - lam[i]) <= tol)
        cl_l = np.flatnonzero(np.abs(lam_l - lam[i]) <= tol)
        if cl_l.size != cl_r.size:
            raise SolverError(
                f"the left and right complex modes do not match at λ = {lam[i]:.6g} "
                f"({cl_r.size} right, {cl_l.size} left): ask for more modes"
            )
        pr, pl = phi[:, cl_r], psi_all[:, cl_l]
        nrm = pl.T @ ((2.0 * lam[i]) * (m @ pr) + d @ pr)
        try:
            psi[:, cl_r] = pl @ np.linalg.inv(nrm).T
        except np.linalg.LinAlgError as exc:
            raise SolverError(
                f"coalescing complex modes at λ = {lam[i]:.6g} (a divergence or flutter "
                "onset): change the speed slightly"
            ) from exc
        done[cl_r] = True
    return lam, phi, psi
