"""The linearized steady lift of the relative flow in the frequency-domain engine.

A line with a lift coefficient (``segments[j].cl_steady``) in a current carries, per
unit length, the lift of the relative flow V = U − c e (docs/travelling.md;
:func:`stochcable.line.transport.relative_flow.steady_lift_force`)

    f_L = ½ρ C_L D |V|² (ẑ·m̂) m̂,        m̂ = e × V_n / |V_n|.

Its mean is in the statics.  About it, a fluctuation δV = v − u̇ of the relative flow
(the waves' velocity v less the line's u̇) changes it by A δV, with A = ∂f_L/∂V
(:func:`stochcable.line.transport.relative_flow.lift_velocity_jacobian`) at the mean
flow and the static tangent: the lift's part of the linearized fluid load, beside the
drag's B (v − u̇).  It is linearized about the mean flow, not statistically: f_L is
smooth where the mean normal flow is not zero, and |V|² has no |·| to average.  As the
drag's, it is taken about the static tangent (no stiffness of the element's rotation).

A is not symmetric (the lift is across the flow), and the engine's node blocks
(:mod:`stochcable.dynamics.model.blocks`) hold symmetric matrices, so the lift enters
like the gyroscopic matrix of a travelling line (:mod:`stochcable.dynamics.model.
transport`): the line keeps the element blocks l0·A (:attr:`LineSystem.lift`) and is
solved by the direct solve, which adds their free–free band (:func:`lift_band`), the
load of the prescribed end motion (:func:`lift_end_load`), the reaction rows
(:func:`lift_end_rows`); the waves' load A v is the drag's element load with l0·A
(:func:`stochcable.dynamics.model.blocks.element_load`).  The element matrix is
l0·A ⊗ P with P the pattern of the drag (consistent [[1/3, 1/6], [1/6, 1/3]], or
lumped).

A lift whose damping is not dominated by the drag's can make the linear system
unstable (galloping); a stationary response does not exist then, and
:func:`check_lift_stability` refuses it with the converged drag damping.

References
----------
Hu, H. Y. & Jin, D. P. (2001), Non-linear dynamics of a suspended travelling cable
subject to transverse fluid excitation, Journal of Sound and Vibration 239(3),
515–529, eq. 6.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from stochcable.dynamics.model.solvers import band_from_blocks
from stochcable.errors import InputError
from stochcable.line.fem import FEModel, build_fe_model, chain_csr
from stochcable.line.transport.relative_flow import lift_velocity_jacobian

__all__ = [
    "lift_blocks",
    "lift_pattern",
    "lift_band",
    "lift_end_load",
    "lift_end_rows",
    "check_lift_stability",
]


def lift_blocks(
    model: FEModel, tangents: np.ndarray, flow: np.ndarray, cl: np.ndarray | None
) -> np.ndarray | None:
    """Element blocks l0·A (n_el, d, d) of the linearized lift, on the model components.

    Parameters
    ----------
    model : FEModel
        The line's model about its static shape.
    tangents : ndarray, shape (n_el, 3)
        Static element unit tangents, global frame. [-]
    flow : ndarray, shape (n_el, 3)
        Mean relative flow at the elements: the current, less c e on a travelling
        line (zero where dry). [m/s]
    cl : ndarray, shape (n_el,), or None
        Lift coefficients (``mesh.cl_steady``). [-]

    Returns
    -------
    ndarray or None
        l0·∂f_L/∂V per element [N·s/m]; None without lift (no coefficient, no normal
        mean flow, or a planar model: the lift of an in-plane flow is out of the plane
        and its in-plane part zero).
    """
    if cl is None or not np.any(cl):
        return None
    coef = 0.5 * model.rho * np.asarray(cl, dtype=float) * model.mesh.diameter
    a = lift_velocity_jacobian(tangents, flow, 0.0, coef)
    comps = list(model.components)
    el = np.ascontiguousarray(a[:, comps][:, :, comps] * model.l0[:, None, None])
    return el if np.any(el) else None


def lift_pattern(model: FEModel) -> np.ndarray:
    """The 2×2 node pattern of the element matrix (the drag's, by the mass matrix)."""
    if model.mass_matrix == "lumped":
        return np.array([[0.5, 0.0], [0.0, 0.5]])
    return np.array([[1.0 / 3.0, 1.0 / 6.0], [1.0 / 6.0, 1.0 / 3.0]])


def lift_band(el: np.ndarray, pat: np.ndarray) -> np.ndarray:
    """LAPACK band storage (half-bandwidth 2d − 1) of the free–free block of C_L.

    Parameters
    ----------
    el : ndarray, shape (n_el, d, d)
        Element blocks l0·A. [N·s/m]
    pat : ndarray, shape (2, 2)
        Node pattern (:func:`lift_pattern`).

    Returns
    -------
    ndarray, shape (4d − 1, (n_el − 1)·d)
        In the band layout of :func:`~stochcable.dynamics.model.blocks.free_band`.
    """
    # free node k is node k + 1: diagonal from elements k (its node b) and k + 1 (its
    # node a); C[k+1, k] = P[1, 0]·E_k, C[k+1, k+2] = P[0, 1]·E_{k+1}
    diag = pat[0, 0] * el[1:] + pat[1, 1] * el[:-1]
    lower = np.zeros_like(diag)
    upper = np.zeros_like(diag)
    lower[1:] = pat[1, 0] * el[1:-1]
    upper[:-1] = pat[0, 1] * el[1:-1]
    return band_from_blocks((diag, lower, upper))


def lift_end_load(
    el: np.ndarray, pat: np.ndarray, ub: np.ndarray, omega: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The free-node load −iω (C_L U_p)_f of the prescribed end motion.

    Parameters
    ----------
    el, pat
        As :func:`lift_band`.
    ub : ndarray, complex, shape (2, d, n_w, n_ch)
        End motion of end_a and end_b. [m/unit]
    omega : ndarray, shape (n_w,)
        [rad/s]

    Returns
    -------
    (ndarray, ndarray)
        The load on the first and on the last free node, each (d, n_w, n_ch). [N/unit]
    """
    iw = (1j * omega)[:, None]
    a = np.einsum("ij,jwc->iwc", pat[1, 0] * el[0], ub[0])
    b = np.einsum("ij,jwc->iwc", pat[0, 1] * el[-1], ub[1])
    return -iw * a, -iw * b


def lift_end_rows(
    el: np.ndarray, pat: np.ndarray, u_ends: tuple[np.ndarray, ...], omega: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """iω (C_L U) at the end nodes' rows, to add to the reactions' impedance rows.

    Parameters
    ----------
    el, pat
        As :func:`lift_band`.
    u_ends : (ndarray, ndarray, ndarray, ndarray)
        Displacement of nodes 0, 1, n − 2 and n − 1, each (d, n_w, n_ch). [m/unit]
    omega : ndarray, shape (n_w,)
        [rad/s]

    Returns
    -------
    (ndarray, ndarray)
        Rows of end_a and end_b, each (d, n_w, n_ch). [N/unit]
    """
    iw = (1j * omega)[:, None]
    u0, u1, u2, u3 = u_ends
    ra = np.einsum("ij,jwc->iwc", pat[0, 0] * el[0], u0) + np.einsum(
        "ij,jwc->iwc", pat[0, 1] * el[0], u1
    )
    rb = np.einsum("ij,jwc->iwc", pat[1, 1] * el[-1], u3) + np.einsum(
        "ij,jwc->iwc", pat[1, 0] * el[-1], u2
    )
    return iw * ra, iw * rb


def check_lift_stability(system: Any, damping: Any, index: int | None = None) -> None:
    """InputError when the linearized lift makes a line's linear system unstable.

    Parameters
    ----------
    system : LineSystem
        The line (its ``lift``, statics, speed).
    damping : Damping
        Its converged drag damping.
    index : int, optional
        The line's index in the scene, for the message.

    Raises
    ------
    InputError
        ``lines[i].segments[j].cl_steady``: an eigenvalue of the line with its drag,
        seabed and lift damping (and its transport terms) has Re λ > 0 (a flutter or
        divergence: galloping), named with the growth rate and frequency.

    Notes
    -----
    The complex modes (:func:`stochcable.line.transport.modes.complex_modes`) with
    C = C_d + C_seabed + C_L on the line's model at rest (its speed adds G and K_c),
    unstable when an eigenvalue has Re λ > 1e-8 max|λ| (as
    :func:`~stochcable.line.transport.modes.stability_transport`); the Rayleigh
    structural damping is left out (it only adds damping).  Every mode up to 600 free
    DOFs, the lowest 60 above.
    """
    if system.lift is None:
        return
    from stochcable.line.transport.modes import DENSE_AUTO_STATES, complex_modes

    rest = build_fe_model(system.statics, system.environment, dim=system.model.dim)
    d = rest.dim
    pat = lift_pattern(rest)
    el = system.lift
    blocks = np.zeros((el.shape[0], 2 * d, 2 * d))
    for a in range(2):
        for b in range(2):
            blocks[:, a * d : (a + 1) * d, b * d : (b + 1) * d] = pat[a, b] * el
    c = (damping.matrix + rest.Cs + chain_csr(blocks, rest.n_nodes, d)).toarray()
    fr = rest.free
    speed = float(system.line.axial_speed)
    # every mode up to DENSE_AUTO_STATES states (QZ), the lowest 60 above (Arnoldi)
    count = None if 2 * fr.size <= DENSE_AUTO_STATES else min(60, fr.size)
    lam = complex_modes(rest, speed, count=count, damping=c[np.ix_(fr, fr)]).eigenvalues
    tol = 1e-8 * float(np.abs(lam).max())  # stability_transport's: above the QZ round-off
    lead = complex(lam[int(np.argmax(lam.real))])
    if lead.real <= tol:
        return
    kind = "divergence" if abs(lead.imag) <= tol else "flutter"
    seg = next(j for j, sg in enumerate(system.line.segments) if sg.cl_steady != 0.0)
    where = f"lines[{index}]" if index is not None else f"lines['{system.name}']"
    raise InputError(
        f"{where}.segments[{seg}].cl_steady",
        system.line.segments[seg].cl_steady,
        "-",
        f"the linearized lift makes line '{system.name}' unstable with its converged drag "
        f"damping ({kind}: growth Re λ = {lead.real:.3g} 1/s at {abs(lead.imag):.3g} "
        "rad/s; galloping): it has no stationary response; lower the lift coefficient "
        "or simulate it with the time-domain reference (docs/travelling.md)",
    )
