"""Element matrices of the line's finite-element model (Tuah (1982), §3.1; DESIGN.md
"Cable model"): 2-node straight cable elements about their static shape.

Exact tangent stiffness K_e = [(EA/l0) e eᵀ + (T/l)(I − e eᵀ)] ⊗ [[1, −1], [−1, 1]],
consistent mass m l0 [[1/3, 1/6], [1/6, 1/3]] ⊗ I (eq. 3.1.12) or lumped, and the normal
added mass Ca ρ πD²/4 l0 (I − e eᵀ) ⊗ the same pattern.  Element blocks are
(n_el, 2d, 2d), node-a DOFs first; :mod:`stochcable.line.fem` assembles them.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from stochcable.errors import InputError
from stochcable.validation import float_array, positive

__all__ = [
    "SLACK_EA_RATIO",
    "STIFFNESS_PATTERN",
    "CONSISTENT_PATTERN",
    "LUMPED_PATTERN",
    "element_stiffness",
    "element_mass",
    "element_added_mass",
    "stiffness_blocks",
    "expand_blocks",
    "added_mass_elements",
    "check_dim",
]

#: Slack elements (T <= 0) keep this fraction of their EA and no geometric stiffness,
#: so K stays positive semi-definite and a slack stretch only loses its stiffness
#: ("E -> epsilon", DESIGN.md "Cable model").
SLACK_EA_RATIO = 1.0e-6


def stiffness_blocks(
    e: np.ndarray, l: np.ndarray, l0: np.ndarray, ea: np.ndarray, tension: np.ndarray
) -> np.ndarray:
    """Node-block k (n_el, d, d) of K_e = k ⊗ [[1, -1], [-1, 1]] (no validation)."""
    slack = tension <= 0.0
    t_eff = np.where(slack, 0.0, tension)
    ea_eff = np.where(slack, SLACK_EA_RATIO * ea, ea)
    d = e.shape[1]
    eet = e[:, :, None] * e[:, None, :]
    eye = np.eye(d)
    return (ea_eff / l0)[:, None, None] * eet + (t_eff / l)[:, None, None] * (eye - eet)


def expand_blocks(block: np.ndarray, pattern: np.ndarray) -> np.ndarray:
    """(n_el, d, d) block ⊗ 2×2 pattern -> (n_el, 2d, 2d), node-a DOFs first."""
    n, d, _ = block.shape
    out = np.empty((n, 2 * d, 2 * d))
    for a in range(2):
        for b in range(2):
            out[:, a * d : (a + 1) * d, b * d : (b + 1) * d] = pattern[a, b] * block
    return out


#: The 2×2 node patterns: K_e = k ⊗ STIFFNESS_PATTERN, consistent and lumped mass.
STIFFNESS_PATTERN = np.array([[1.0, -1.0], [-1.0, 1.0]])
CONSISTENT_PATTERN = np.array([[1.0 / 3.0, 1.0 / 6.0], [1.0 / 6.0, 1.0 / 3.0]])
LUMPED_PATTERN = np.array([[0.5, 0.0], [0.0, 0.5]])


def element_stiffness(
    positions_a: np.ndarray,
    positions_b: np.ndarray,
    l0: np.ndarray,
    ea: np.ndarray,
    tension: np.ndarray,
) -> np.ndarray:
    """Exact tangent stiffness of straight 2-node cable elements.

    Parameters
    ----------
    positions_a, positions_b : array_like, shape (n_el, d)
        Positions of the first and second node of each element, d = 2 or 3. [m]
    l0 : array_like, shape (n_el,)
        Unstretched element length. [m]
    ea : array_like, shape (n_el,)
        Axial stiffness. [N]
    tension : array_like, shape (n_el,)
        Effective tension of each element in the static state. [N]

    Returns
    -------
    ndarray, shape (n_el, 2d, 2d)
        Element stiffness, DOFs ordered (node a components, node b components). [N/m]

    Notes
    -----
    With current length l, unit vector e from node a to node b and tension T,

        K_e = [(EA/l0) e eᵀ + (T/l)(I − e eᵀ)] ⊗ [[1, −1], [−1, 1]],

    the derivative of the element end force T(l) e with T = EA (l − l0)/l0 (Tuah
    (1982), eqs. 3.1.8–3.1.11 with the pseudo-Hookean law; DESIGN.md "Cable model").  A slack
    element (T <= 0) gets T -> 0 and EA -> ``SLACK_EA_RATIO``·EA: it carries no
    geometric stiffness and nearly no axial stiffness, and K stays positive
    semi-definite.
    """
    pa = float_array("positions_a", positions_a, "m", ndim=2)
    pb = float_array("positions_b", positions_b, "m", ndim=2)
    if pa.shape != pb.shape or pa.shape[1] not in (2, 3):
        raise InputError(
            "positions_b",
            pb.shape,
            "-",
            f"must have the shape of positions_a {pa.shape}, with 2 or 3 columns",
        )
    n = pa.shape[0]
    l0 = float_array("l0", l0, "m", positive=True)
    ea = float_array("ea", ea, "N", positive=True)
    tension = float_array("tension", tension, "N")
    for name, arr in (("l0", l0), ("ea", ea), ("tension", tension)):
        if arr.shape != (n,):
            raise InputError(name, arr.shape, "-", f"must have one value per element ({n})")
    d = pb - pa
    l = np.linalg.norm(d, axis=1)
    if (l <= 0.0).any():
        i = int(np.flatnonzero(l <= 0.0)[0])
        raise InputError(
            "positions_b", pb[i], "m", f"element {i} has zero length (its nodes coincide)"
        )
    e = d / l[:, None]
    return expand_blocks(stiffness_blocks(e, l, l0, ea, tension), STIFFNESS_PATTERN)


def element_mass(
    l0: np.ndarray, mass: np.ndarray, dim: int = 3, lumped: bool = False
) -> np.ndarray:
    """Structural mass matrices of 2-node cable elements.

    Parameters
    ----------
    l0 : array_like, shape (n_el,)
        Unstretched element length. [m]
    mass : array_like, shape (n_el,)
        Mass per unit (unstretched) length. [kg/m]
    dim : {2, 3}
        Number of displacement components per node.
    lumped : bool
        Lumped (half the element mass on each node) instead of consistent.

    Returns
    -------
    ndarray, shape (n_el, 2·dim, 2·dim)
        Element mass matrices. [kg]

    Notes
    -----
    Consistent mass m l0 [[1/3, 1/6], [1/6, 1/3]] ⊗ I (Tuah (1982), eq. 3.1.12, whose
    C_L·ρA/λ_C is m·l0).  Lumped mass m l0 [[1/2, 0], [0, 1/2]] ⊗ I.
    """
    l0 = float_array("l0", l0, "m", positive=True)
    mass = float_array("mass", mass, "kg/m", nonnegative=True)
    dim = check_dim(dim)
    block = (l0 * mass)[:, None, None] * np.eye(dim)[None]
    return expand_blocks(block, LUMPED_PATTERN if lumped else CONSISTENT_PATTERN)


def element_added_mass(
    tangents: np.ndarray,
    l0: np.ndarray,
    ca_normal: np.ndarray,
    diameter: np.ndarray,
    rho: float,
    lumped: bool = False,
) -> np.ndarray:
    """Normal added-mass matrices of 2-node cable elements.

    Parameters
    ----------
    tangents : array_like, shape (n_el, d)
        Unit vector along each element, d = 2 or 3. [-]
    l0 : array_like, shape (n_el,)
        Unstretched element length. [m]
    ca_normal : array_like, shape (n_el,)
        Normal added-mass coefficient. [-]
    diameter : array_like, shape (n_el,)
        Hydrodynamic diameter. [m]
    rho : float
        Water density. [kg/m³]
    lumped : bool
        Lumped instead of consistent distribution.

    Returns
    -------
    ndarray, shape (n_el, 2d, 2d)
        Element added-mass matrices. [kg]

    Notes
    -----
    Per unit length Can ρ πD²/4 (I − e eᵀ) (Tuah (1982), eq. 3.2.a.2, the −(C_M − 1) ü_N
    term; DESIGN.md "Cable model"), distributed like the structural mass (consistent
    [[1/3, 1/6], [1/6, 1/3]] or lumped) over the unstretched length, as the mass per
    length is.  No tangential added mass.
    """
    e = float_array("tangents", tangents, "-", ndim=2)
    n, d = e.shape
    l0 = float_array("l0", l0, "m", positive=True)
    ca = float_array("ca_normal", ca_normal, "-", nonnegative=True)
    dia = float_array("diameter", diameter, "m", nonnegative=True)
    rho = positive("rho", rho, "kg/m³")
    for name, arr in (("l0", l0), ("ca_normal", ca), ("diameter", dia)):
        if arr.shape != (n,):
            raise InputError(name, arr.shape, "-", f"must have one value per element ({n})")
    return added_mass_elements(e, l0, ca, dia, rho, lumped)


def added_mass_elements(e, l0, ca, dia, rho, lumped):
    d = e.shape[1]
    ma = ca * rho * np.pi * dia**2 / 4.0 * l0
    block = ma[:, None, None] * (np.eye(d)[None] - e[:, :, None] * e[:, None, :])
    return expand_blocks(block, LUMPED_PATTERN if lumped else CONSISTENT_PATTERN)


def check_dim(dim: Any) -> int:
    """The model dimension ``dim`` as an int, 2 (in-plane x–z) or 3 (InputError else)."""
    if isinstance(dim, bool) or dim not in (2, 3):
        raise InputError("dim", dim, "-", "must be 2 (in-plane x–z) or 3")
    return int(dim)
