"""Complex modes and stability of a line travelling along itself.

The modes of the gyroscopic system are complex: λ² M φ + λ (C + G) φ + K φ = 0 in the
first-order (Foss) form A ż + B z = 0, z = (u, u̇), A = [[D, M], [M, 0]],
B = [[K, 0], [0, −M]], D = C + G.  A is not symmetric when G ≠ 0, so each mode has a
left eigenvector w = (ψ, λψ), ψᵀ(λ² M + λ D + K) = 0, and the modes are normalized by
wᵀ A z = ψᵀ (2 λ M + D) φ = 1, which gives the modal expansion of the receptance

    (−ω² M + iω D + K)⁻¹ = Σ_k φ_k ψ_kᵀ / (iω − λ_k).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from stochcable.errors import InputError, SolverError
from stochcable.line.fem import FEModel
from stochcable.line.modes import PLANE_TOL, _out_of_plane_fraction, plane_normal
from stochcable.line.transport.matrices import _check_model, critical_speed, transport_matrices
from stochcable.line.transport.sparse import lowest_complex_modes
from stochcable.validation import float_array, positive_int

__all__ = [
    "DENSE_MAX_STATES",
    "DENSE_AUTO_STATES",
    "ComplexModes",
    "Stability",
    "complex_modes",
    "receptance_modal",
    "receptance_direct",
    "stability_transport",
    "divergence_speed",
    "modes_document",
]

#: Largest first-order state (2 × free DOFs) solved by the dense QZ with left vectors.
DENSE_MAX_STATES = 4000
#: Above this state size ``method="auto"`` takes the sparse Arnoldi (a dense QZ with
#: left vectors of 1,200 states takes a few seconds on 2 cores).
DENSE_AUTO_STATES = 1200
# A real part below this fraction of |λ| (or of the largest |λ|) is round-off: the
# conservative gyroscopic system has λ on the imaginary axis, and QZ returns it to
# ~1e-12 relative on these well-scaled pencils; 1e-8 leaves four decades of margin.
_REAL_TOL = 1.0e-8


@dataclass(frozen=True, eq=False)
class ComplexModes:
    """Complex modes of a line with transport (and damping).

    Attributes
    ----------
    eigenvalues : ndarray of complex, shape (count,)
        λ_k, u = Re(φ e^{λt}); for a stable conservative system λ = iω. [rad/s]
    right : ndarray of complex, shape (n_dof, count)
        Right shapes φ (zeros at prescribed DOFs).
    left : ndarray of complex, shape (n_dof, count)
        Left shapes ψ, normalized with ``right`` so that ψᵀ(2λM + D)φ = 1.
    speed : float
        Axial speed. [m/s]
    complete : bool
        True when every state eigenvalue is kept (``count`` = 2 × free DOFs): the
        modal receptance is then exact.
    """

    eigenvalues: np.ndarray
    right: np.ndarray
    left: np.ndarray
    speed: float
    complete: bool

    @property
    def omega(self) -> np.ndarray:
        """Damped natural frequencies |Im λ|. [rad/s]"""
        return np.abs(self.eigenvalues.imag)

    @property
    def growth(self) -> np.ndarray:
        """Real parts Re λ: > 0 grows (unstable), < 0 decays. [1/s]"""
        return self.eigenvalues.real


def _free_dense(model: FEModel, a: Any) -> np.ndarray:
    ff, _ = model.partition(a)
    return ff.toarray() if sp.issparse(ff) else np.asarray(ff)


def _pencil(
    model: FEModel, speed: float, added_mass: bool, damping: Any
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Dense free–free (M, D, K) of the gyroscopic system."""
    tr = transport_matrices(model, speed)
    m = _free_dense(model, "MT" if added_mass else "M")
    d = _free_dense(model, tr.G)
    if damping is not None:
        c = damping.toarray() if sp.issparse(damping) else np.asarray(damping, dtype=float)
        if c.shape == (model.n_dof, model.n_dof):
            c = c[np.ix_(model.free, model.free)]
        if c.shape != m.shape:
            raise InputError(
                "damping",
                c.shape,
                "N·s/m",
                f"must be ({model.n_dof}, {model.n_dof}) or free–free {m.shape}",
            )
        d = d + c
    k = _free_dense(model, tr.K)
    return m, d, k


def complex_modes(
    model: FEModel,
    speed: float,
    count: int | None = None,
    added_mass: bool = True,
    damping: Any = None,
    method: Literal["auto", "dense", "sparse"] = "auto",
) -> ComplexModes:
    """Complex modes of a travelling line, with their left eigenvectors.

    Parameters
    ----------
    model : FEModel
        The line's model about its static shape.
    speed : float
        Axial speed c, positive from end_a to end_b. [m/s]
    count : int, optional
        Number of modes with Im λ >= 0 to keep, lowest |λ| first (each stands for its
        conjugate pair when the system is real); default: every state eigenvalue, both
        members of each pair (a complete set, for an exact modal receptance).
    added_mass : bool
        Include the added mass in M (modes in water) or not (in air).
    damping : array_like or sparse, optional
        A symmetric or general damping matrix C, (n_dof, n_dof) or free–free. [N·s/m]
    method : {"auto", "dense", "sparse"}
        "dense": QZ on the first-order pencil (up to ``DENSE_MAX_STATES`` states);
        "sparse": shift-invert Arnoldi for the lowest ``count``
        (:mod:`stochcable.line.transport.sparse`); "auto": dense up to
        ``DENSE_AUTO_STATES`` states or when ``count`` is None, sparse above.

    Returns
    -------
    ComplexModes
        Eigenvalues, right and left shapes, normalized ψᵀ(2λM + D)φ = 1.

    Raises
    ------
    SolverError
        A mode whose normalization wᵀAz vanishes (a defective, i.e. coalescing, pair:
        at a divergence or flutter onset).

    Notes
    -----
    The first-order form of the module docstring generalizes the Foss decomposition
    (Tuah 1982, §3.3; Foss 1958) to a non-symmetric A: with G the right and left
    eigenvectors differ.  For D = G (no damping) and K + K_c positive definite the
    eigenvalues are imaginary (Thomson–Tait–Chetaev), and ψ = φ̄ for λ = iω.
    """
    model = _check_model(model)
    if method not in ("auto", "dense", "sparse"):
        raise InputError("method", method, "-", "must be 'auto', 'dense' or 'sparse'")
    n = model.free.size
    if n == 0:
        raise InputError("model", "no free DOFs", "-", "needs at least one free node")
    if method == "sparse" or (method == "auto" and count is not None and 2 * n > DENSE_AUTO_STATES):
        if count is None:
            raise InputError("count", None, "-", "the sparse complex modes need a count")
        return _sparse(model, speed, positive_int("count", count), added_mass, damping)
    if 2 * n > DENSE_MAX_STATES:
        raise InputError(
            "model",
            f"{n} free DOFs",
            "-",
            f"the dense complex modes take at most {DENSE_MAX_STATES // 2} free DOFs "
            "(fewer elements, or dim=2 for an in-plane line)",
        )
    m, d, k = _pencil(model, speed, added_mass, damping)
    z = np.zeros_like(m)
    a = np.block([[d, m], [m, z]])
    b = np.block([[k, z], [z, -m]])
    lam, vl, vr = sla.eig(-b, a, left=True, right=True)
    if not np.isfinite(lam).all():
        raise SolverError("the first-order pencil has infinite eigenvalues (singular mass)")
    # left eigenvectors of scipy: vlᴴ(−B) = λ vlᴴ A, so w = conj(vl): wᵀ(λA + B) = 0
    w = vl.conj()
    norm = np.einsum("ik,ij,jk->k", w, a, vr)
    scale = np.abs(lam).max()
    # coalescing (defective) pair: wᵀAz vanishes against ‖w‖‖Az‖
    if (np.abs(norm) <= 1e-10 * np.linalg.norm(w, axis=0) * np.linalg.norm(a @ vr, axis=0)).any():
        raise SolverError(
            "a complex mode has wᵀAz ≈ 0 (coalescing eigenvalues): the line is at a "
            "divergence or flutter onset; change the speed slightly"
        )
    root = np.sqrt(norm)
    phi = vr[:n] / root
    psi = w[:n] / root
    if count is None:
        order = np.lexsort((lam.imag, np.abs(lam)))
        complete = True
    else:
        k_req = positive_int("count", count)
        tol = _REAL_TOL * max(scale, 1e-300)
        upper = np.flatnonzero(lam.imag >= -tol)
        # a real pair (divergence: ±σ) keeps both members; an oscillating pair keeps
        # the member with Im λ > 0
        order = upper[np.lexsort((-lam.real[upper], np.abs(lam[upper])))][:k_req]
        complete = False
    right = np.zeros((model.n_dof, order.size), dtype=complex)
    left = np.zeros_like(right)
    right[model.free] = phi[:, order]
    left[model.free] = psi[:, order]
    return ComplexModes(
        eigenvalues=lam[order],
        right=right,
        left=left,
        speed=float(speed),
        complete=complete,
    )


def _sparse(
    model: FEModel, speed: float, count: int, added_mass: bool, damping: Any
) -> ComplexModes:
    """The lowest complex modes by shift-invert Arnoldi on sparse matrices."""
    tr = transport_matrices(model, speed)
    m = model._free_free(model._mass_total if added_mass else model.M)
    d = model._free_free(tr.G)
    if damping is not None:
        c = sp.csr_array(damping) if sp.issparse(damping) else np.asarray(damping, dtype=float)
        if c.shape == (model.n_dof, model.n_dof):
            c = model.partition(c)[0]
        if c.shape != m.shape:
            raise InputError(
                "damping", c.shape, "N·s/m", f"must be ({model.n_dof}, {model.n_dof}) or free–free"
            )
        d = d + sp.csr_array(c)
    k = model._free_free(tr.K)
    lam, phi, psi = lowest_complex_modes(sp.csr_array(m), sp.csr_array(d), sp.csr_array(k), count)
    right = np.zeros((model.n_dof, lam.size), dtype=complex)
    left = np.zeros_like(right)
    right[model.free] = phi
    left[model.free] = psi
    return ComplexModes(eigenvalues=lam, right=right, left=left, speed=float(speed), complete=False)


def receptance_modal(modes: ComplexModes, omega: Any, free: np.ndarray) -> np.ndarray:
    """Receptance on the free DOFs from complete complex modes.

    Parameters
    ----------
    modes : ComplexModes
        A complete set (``count=None``).
    omega : array_like, shape (n_omega,)
        Angular frequencies. [rad/s]
    free : ndarray of int
        The model's free DOFs.

    Returns
    -------
    ndarray of complex, shape (n_omega, n_free, n_free)
        H(ω) = Σ_k φ_k ψ_kᵀ / (iω − λ_k). [m/N]
    """
    if not modes.complete:
        raise InputError(
            "modes", "incomplete", "-", "the modal receptance needs complex_modes(count=None)"
        )
    w = float_array("omega", omega, "rad/s", ndim=1)
    phi = modes.right[free]
    psi = modes.left[free]
    den = 1.0 / (1j * w[:, None] - modes.eigenvalues[None, :])
    return np.einsum("ik,wk,jk->wij", phi, den, psi)


def receptance_direct(
    model: FEModel, speed: float, omega: Any, added_mass: bool = True, damping: Any = None
) -> np.ndarray:
    """Receptance (−ω² M + iω (C + G) + K + K_c)⁻¹ on the free DOFs, by direct solves.

    Parameters
    ----------
    model : FEModel
        The line's model about its static shape.
    speed : float
        Axial speed. [m/s]
    omega : array_like, shape (n_omega,)
        Angular frequencies. [rad/s]
    added_mass, damping
        As :func:`complex_modes`.

    Returns
    -------
    ndarray of complex, shape (n_omega, n_free, n_free)
        The receptance. [m/N]
    """
    w = float_array("omega", omega, "rad/s", ndim=1)
    m, d, k = _pencil(model, speed, added_mass, damping)
    return np.stack([np.linalg.inv(-(x * x) * m + 1j * x * d + k) for x in w])


@dataclass(frozen=True)
class Stability:
    """Stability of a line's static equilibrium at one axial speed.

    Attributes
    ----------
    speed : float
        Axial speed. [m/s]
    kind : str
        "stable", "divergence" (a real eigenvalue λ > 0: an eigenvalue went through
        zero, the effective stiffness lost its positive definiteness) or "flutter" (a
        complex pair with Re λ > 0).
    eigenvalue : complex
        The eigenvalue of largest real part. [rad/s]
    negative_stiffness : int
        Number of negative eigenvalues of K + K_c (the index of the effective
        stiffness).
    """

    speed: float
    kind: str
    eigenvalue: complex
    negative_stiffness: int

    @property
    def stable(self) -> bool:
        """Whether no eigenvalue has Re λ > 0."""
        return self.kind == "stable"


def stability_transport(
    model: FEModel, speed: float, added_mass: bool = True, damping: Any = None
) -> Stability:
    """Divergence or flutter of a travelling line's equilibrium.

    Parameters
    ----------
    model : FEModel
        The line's model about its static shape.
    speed : float
        Axial speed. [m/s]
    added_mass, damping
        As :func:`complex_modes`.

    Returns
    -------
    Stability
        The kind of (in)stability and the leading eigenvalue.

    Notes
    -----
    An eigenvalue with Re λ > ``1e-8``·max|λ| is an instability (the tolerance is four
    decades above the QZ round-off of the imaginary eigenvalues of the conservative
    system); it is a divergence when that eigenvalue is real (|Im λ| below the same
    tolerance), a flutter otherwise.
    """
    model = _check_model(model)
    modes = complex_modes(model, speed, added_mass=added_mass, damping=damping)
    lam = modes.eigenvalues
    scale = float(np.abs(lam).max())
    tol = _REAL_TOL * max(scale, 1e-300)
    i = int(np.argmax(lam.real))
    lead = complex(lam[i])
    k_eff = _free_dense(model, transport_matrices(model, speed).K)
    ev = np.linalg.eigvalsh(0.5 * (k_eff + k_eff.T))
    neg = int((ev < -1e-10 * float(np.abs(ev).max())).sum())
    if lead.real <= tol:
        kind = "stable"
    elif abs(lead.imag) <= tol:
        kind = "divergence"
    else:
        kind = "flutter"
    return Stability(speed=float(speed), kind=kind, eigenvalue=lead, negative_stiffness=neg)


def divergence_speed(model: FEModel) -> float:
    """The lowest axial speed at which the effective stiffness K + K_c turns singular.

    Parameters
    ----------
    model : FEModel
        The line's model about its static shape (K positive definite on its free
        DOFs).

    Returns
    -------
    float
        c_d > 0: K − c² K₁ has a zero eigenvalue at c = c_d, K₁ = −K_c/c²; the
        gyroscopic system has λ = 0 there. [m/s]

    Notes
    -----
    K_c is quadratic in c, so the divergence speeds are the generalized eigenvalues
    K φ = c² K₁ φ (K₁ positive semi-definite); the lowest.  For a taut string c_d =
    √(T/m) exactly (K₁ is then K/c_w² in the transverse directions).  Beyond c_d the
    index of K + K_c is odd and the equilibrium diverges (Thomson–Tait–Chetaev); the
    transverse critical speed of the lowest-tension element, :func:`critical_speed`,
    is a lower bound that the scene checks refuse.
    """
    model = _check_model(model)
    k = _free_dense(model, model.K)
    k1 = -_free_dense(model, transport_matrices(model, 1.0).Kc)
    try:
        mu = sla.eigh(k1, k, eigvals_only=True)  # k1 φ = μ k φ, μ = 1/c²
    except np.linalg.LinAlgError as exc:
        raise SolverError(
            "the stiffness is not positive definite on the free DOFs: no divergence "
            "speed about this equilibrium"
        ) from exc
    top = float(mu.max())
    if top <= 0.0:
        return float("inf")
    return float(1.0 / np.sqrt(top))


def modes_document(
    model: FEModel, speed: float, count: int, added_mass: bool = True
) -> dict[str, Any]:
    """The ``stochcable modes`` document of a travelling line.

    Parameters
    ----------
    model : FEModel
        The line's model about its static shape.
    speed : float
        Axial speed (checked below the critical speed by the caller). [m/s]
    count : int
        Number of modes.
    added_mass : bool
        Modes in water (True) or in air.

    Returns
    -------
    dict
        ``omega`` |Im λ| [rad/s], ``period`` [s] (null at zero), ``growth`` Re λ [1/s],
        ``plane`` as :class:`stochcable.line.modes.Modes`, ``axial_speed`` [m/s],
        ``critical_speed`` √(T/m) [m/s] and ``stability`` ("stable", "divergence" or
        "flutter").
    """
    modes = complex_modes(model, speed, count=count, added_mass=added_mass)
    if 2 * model.free.size <= DENSE_AUTO_STATES:
        kind = stability_transport(model, speed, added_mass=added_mass).kind
    else:  # below the critical speed K + K_c is positive definite: the lowest modes
        tol = _REAL_TOL * float(np.abs(modes.eigenvalues).max())
        lead = modes.eigenvalues[int(np.argmax(modes.eigenvalues.real))]
        grows = lead.real > tol
        kind = "stable" if not grows else "divergence" if abs(lead.imag) <= tol else "flutter"
    mt = model._mass_total if added_mass else model.M
    normal = plane_normal(model.positions)
    shapes = np.hstack([modes.right.real, modes.right.imag])
    k = modes.eigenvalues.size
    en = _out_of_plane_fraction(model, mt, shapes, normal)
    # energy fraction of a complex shape: the real and imaginary parts' energies add
    e_tot = np.einsum("ij,ij->j", shapes, mt @ shapes)
    frac_num = en * e_tot
    num = frac_num[:k] + frac_num[k:]
    den = e_tot[:k] + e_tot[k:]
    frac = np.where(den > 0, num / np.where(den > 0, den, 1.0), 0.0)
    plane = np.where(
        frac <= PLANE_TOL, "in-plane", np.where(frac >= 1.0 - PLANE_TOL, "out-of-plane", "mixed")
    )
    omega = modes.omega
    return {
        "omega": [float(w) for w in omega],
        "period": [float(2.0 * np.pi / w) if w > 0 else None for w in omega],
        "plane": [str(p) for p in plane],
        "growth": [float(g) for g in modes.growth],
        "axial_speed": float(speed),
        "critical_speed": critical_speed(model).speed,
        "stability": kind,
    }
