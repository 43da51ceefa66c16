"""Linearized seabed contact of the finite-element model (DESIGN.md "Scene": a linear
bed of stiffness and damping per unit contact area, i.e. times the diameter per unit
length), with the touchdown point where the static catenary puts it, not where the
nodes fall.

Away from the touchdown a grounded node gets a vertical spring and dashpot of its
tributary contact length (half of each adjacent element, :func:`bed_contact`).  The
element that contains the static touchdown point is split there by an internal node
that carries the bed of the grounded part of the element; that node has no mass and is
condensed out, so the mesh, the matrices' band and every output stay those of the
user's elements (:func:`touchdown_element`).

References
----------
Bliet, A. (1984), Dynamic analysis of single span cables, PhD thesis, Massachusetts
Institute of Technology.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from stochcable.line.elements import SLACK_EA_RATIO, added_mass_elements, stiffness_blocks

__all__ = [
    "BedContact",
    "TOUCHDOWN_SNAP",
    "bed_contact",
    "split_touchdown_element",
    "tension_rows",
    "touchdown_element",
]

#: A touchdown closer than this fraction of its element's length to a node is taken
#: at the node: the condensation of a sub-element of relative length ξ loses about
#: ε/ξ of its digits (ε the machine precision), and moving the point of support by
#: 1e-3 of an element changes the suspended span by less than that.
TOUCHDOWN_SNAP = 1.0e-3


@dataclass(frozen=True, eq=False)
class BedContact:
    """The seabed's share of the linear model of one line.

    Attributes
    ----------
    grounded : ndarray of bool, shape (n_nodes,)
        Nodes in contact (each with its tributary spring and dashpot).
    k_diag, c_diag : ndarray, shape (n_dof,)
        Vertical springs [N/m] and dashpots [N·s/m] on the node DOFs.
    element : int or None
        The element that contains the touchdown point strictly inside (None when the
        touchdown is at a node, or there is none).
    fraction : float
        Its grounded fraction ξ = (s_td − s_k)/l0_k (0 without such an element). [-]
    k_block, c_block : ndarray, shape (2·dim, 2·dim) or None
        That element's condensed stiffness [N/m] (replacing its cable stiffness) and
        bed damping [N·s/m] (added), node-a DOFs first.
    transform : ndarray, shape (3·dim, 2·dim) or None
        The map [u_a; u_b] -> [u_a; u_t; u_b] of the condensation (u_t the split
        node's motion), for :meth:`reduce`.
    sub_tangents : ndarray, shape (2, dim) or None
        Unit vectors of the grounded (a–t) and the suspended (t–b) part. [-]
    tension_row : ndarray, shape (2, dim) or None
        The split element's dynamic tension δT = row[0]·u_a + row[1]·u_b: the
        suspended part's (EA/l0_s) e_sᵀ(u_b − u_t) with u_t = R [u_a; u_b]. [N/m]
    """

    grounded: np.ndarray
    k_diag: np.ndarray
    c_diag: np.ndarray
    element: int | None
    fraction: float
    k_block: np.ndarray | None
    c_block: np.ndarray | None
    transform: np.ndarray | None = None
    sub_tangents: np.ndarray | None = None
    tension_row: np.ndarray | None = None

    def reduce(self, pair: np.ndarray) -> np.ndarray:
        """The matrices (2, 2·dim, 2·dim) of the two parts of the split touchdown
        element, on (a, t) and (t, b), reduced to its nodes (a, b): Tᵀ M₃ T with
        T = :attr:`transform`."""
        d = pair.shape[1] // 2
        full = np.zeros((3 * d, 3 * d))
        full[: 2 * d, : 2 * d] += pair[0]
        full[d:, d:] += pair[1]
        t = self.transform
        out = t.T @ full @ t
        return 0.5 * (out + out.T)


def touchdown_element(
    s0: np.ndarray, grounded: np.ndarray, touchdown: float | None
) -> tuple[np.ndarray, int | None, float]:
    """Contact nodes next to the touchdown point and the element that contains it.

    Parameters
    ----------
    s0 : ndarray, shape (n_nodes,)
        Unstretched arc length of the nodes from end_a. [m]
    grounded : ndarray of bool, shape (n_nodes,)
        Nodes in contact in the static solution.
    touchdown : float or None
        Unstretched arc length from end_a where the line leaves the seabed toward
        end_b (:attr:`stochcable.line.statics.LineStatics.touchdown`). [m]

    Returns
    -------
    grounded : ndarray of bool
        The contact nodes: as given, except next to the touchdown, where the node
        before it is in contact and the nodes of its contact run after it are not.
    element : int or None
        The touchdown element k, s_k <= s_td < s_k+1: its node a is the last contact
        node (None without a touchdown).
    fraction : float
        Its grounded fraction ξ = (s_td − s_k)/(s_k+1 − s_k); 0 when the touchdown is
        within :data:`TOUCHDOWN_SNAP` of node k (a touchdown that close to node k+1
        is taken at node k+1, the next element's node a). [-]

    Notes
    -----
    The finite-element statics on a penalty bed marks a node grounded when it sinks
    into the bed, which the node just past the touchdown may do by a fraction of a
    millimetre; its touchdown is interpolated from the vertical tension of the first
    suspended element (:mod:`stochcable.line.statics`), as the catenary's.  The contact
    run that ends next to the touchdown is therefore cut at the touchdown itself.
    """
    gr = np.asarray(grounded, dtype=bool).copy()
    n = gr.size
    if touchdown is None or n < 3 or not gr[1:-1].any():
        return gr, None, 0.0
    s = np.asarray(s0, dtype=float)
    td = float(touchdown)
    k = int(np.clip(np.searchsorted(s, td, side="right") - 1, 0, n - 2))
    xi = (td - s[k]) / (s[k + 1] - s[k])
    if xi >= 1.0 - TOUCHDOWN_SNAP:
        k, xi = k + 1, 0.0
    elif xi <= TOUCHDOWN_SNAP:
        xi = 0.0
    if k >= n - 1 or gr[k + 1 :].all():
        return gr, None, 0.0  # grounded up to end_b: no touchdown toward it
    gr[k] = True
    j = k + 1
    while j < n - 1 and gr[j]:
        gr[j] = False
        j += 1
    return gr, k, float(xi)


def bed_contact(
    s0: np.ndarray,
    l0: np.ndarray,
    diameter: np.ndarray,
    tangents: np.ndarray,
    length: np.ndarray,
    ea: np.ndarray,
    tension: np.ndarray,
    grounded: np.ndarray,
    touchdown: float | None,
    stiffness: float,
    damping: float,
    vertical: int,
) -> BedContact:
    """Linearized seabed springs and dashpots of one line's finite-element model.

    Parameters
    ----------
    s0 : ndarray, shape (n_nodes,)
        Unstretched arc length of the nodes. [m]
    l0, diameter, length, ea, tension : ndarray, shape (n_el,)
        Unstretched length [m], diameter [m], current length [m], axial stiffness [N]
        and static effective tension [N] of the elements.
    tangents : ndarray, shape (n_el, dim)
        Unit vector of each element in the model components. [-]
    grounded : ndarray of bool, shape (n_nodes,)
        Nodes in contact in the static solution.
    touchdown : float or None
        Static touchdown point, unstretched arc length from end_a (None: nodal contact
        only). [m]
    stiffness, damping : float
        Bed stiffness [Pa/m] and damping [Pa·s/m] per unit contact area.
    vertical : int
        Index of the vertical (z) component among the model components.

    Returns
    -------
    BedContact
        The nodal springs and dashpots and the condensed touchdown element.

    Notes
    -----
    Per unit length the bed is a Winkler foundation k' = k·D, c' = c·D (k, c per unit
    area, D the diameter; DESIGN.md "Scene", as MoorDyn's kBot and cBot).  On the
    nodes it is lumped: a grounded node gets k'·(l0,j−1 + l0,j)/2 over its grounded
    neighbours' halves.

    **Touchdown element.**  Linearized about the static catenary, the touchdown point
    is a fixed point of the vertical motion to first order: the line is tangent to the
    bed there (the vertical tension vanishes, V(s_td) = 0), so a material point a
    distance a past it stands κa²/2 above the bed (κ = w/H its curvature) and the
    first-order vertical motion w ≈ a·∂w/∂s lifts it, or presses it into the bed, by
    an amount of second order in the motion: the one-sided contact is a second-order
    effect and the suspended span ends at the static touchdown point (the boundary
    condition of the linear cable dynamics of catenary moorings and risers with a
    grounded length: Triantafyllou, Bliek & Shin 1985, §3; Bliet (1984), ch. 3,
    for a chain tangential to the bottom; Aranha, Martins & Pinto 1997).  A model that
    springs only the nodes grounded in statics moves that point to the last grounded
    node, lengthening the span by up to one element: an O(h) error whose sign depends on
    where the touchdown falls in its element, hence the non-monotone element
    convergence of a grounded chain.

    Here the element k (nodes a, b) that contains s_td, a fraction
    ξ = (s_td − s_k)/l0,k of it grounded, is split at s_td by a node t.  The grounded
    sub-element a–t lies on the bed: horizontal, along the element's horizontal
    direction, of length l_g = ξ·l0(1 + T/EA); the suspended one runs from t to node b
    (the static shape is tangent to the bed at t, so the chord a–b, inclined by about
    κ(1−ξ)²l/2, is not the direction of either part: the axial stiffness EA/l0 along
    the suspended part's steeper direction is what node b's vertical motion feels).
    Each has the element's tension T and EA and its share ξl0, (1−ξ)l0 of the
    unstretched length, so the node block k_e = (EA/l0) e eᵀ + (T/l)(I − e eᵀ) of
    :func:`stochcable.line.elements.element_stiffness` with its own e, l, l0.  The
    grounded part carries the bed: t gets the vertical spring k'·ξl0/2 and dashpot
    c'·ξl0/2, node a the other half (the lumping of the nodes above, on the split
    element).  The massless t is condensed statically (Guyan 1965):

        K_ab = K_oo − K_ot K_tt⁻¹ K_to,   u_t = R u_ab,  R = −K_tt⁻¹ K_to,
        C_ab = c'·ξl0/2 · R_zᵀ R_z,

    with R_z the vertical row of R; the element's mass and added mass are those of its
    two parts (:func:`stochcable.line.elements.element_mass` of ξl0 and (1−ξ)l0, the
    normal added mass along each part's direction) reduced with T = [I 0; R; 0 I]:
    Tᵀ M₃ T.  Its drag stays on its two nodes.  As ξ → 0 the split
    node merges with node a and as ξ → 1 with node b, each then a grounded node as
    above, so the model is continuous in the touchdown's position; the suspended span
    ends at the touchdown whatever the mesh, as on a mesh with a node there (the
    fidelity planner's node at the touchdown), and the tension σ of the grounded chain
    example converges monotonically with the elements (tests/line/test_seabed.py).  Slack
    touchdown elements (T <= 0) keep the nodal contact.

    The statistical linearization of the one-sided contact (k_eq = k·P(contact) for a
    Gaussian vertical motion; Roberts & Spanos 2003, ch. 5) is not used: on a bed
    this stiff (k'·l0 ≫ T/l0) a grounded node hardly moves in the linear model, so
    P(contact) stays near one there and near zero at the suspended nodes above their
    clearance, and the linearization only moves the support between the same nodes; the
    first-order argument above puts it at the touchdown directly.

    References
    ----------
    Triantafyllou, M.S., Bliek, A., Shin, H. (1985).  Dynamic analysis as a tool for
    open-sea mooring system design.  SNAME Transactions 93, 303–324.
    Aranha, J.A.P., Martins, C.A., Pinto, M.O. (1997).  Dynamic tension in risers and
    mooring lines: an algebraic approximation for harmonic excitation.  Applied Ocean
    Research 19, 357–368.
    Guyan, R.J. (1965).  Reduction of stiffness and mass matrices.  AIAA Journal 3(2),
    380.
    Roberts, J.B., Spanos, P.D. (2003).  Random Vibration and Statistical
    Linearization.  Dover.
    """
    n_nodes = s0.size
    dim = tangents.shape[1]
    gr, k, xi = touchdown_element(s0, grounded, touchdown)
    half = diameter * l0 / 2.0
    trib = np.zeros(n_nodes)
    trib[:-1] += half
    trib[1:] += half
    trib = np.where(gr, trib, 0.0)
    if k is not None:
        # the touchdown element's node a carries the half of its grounded part only
        trib[k] -= (1.0 - xi) * half[k]
    split = k is not None and xi > 0.0 and float(tension[k]) > 0.0
    if k is not None and xi > 0.0 and not split:
        trib[k] += (1.0 - xi) * half[k]  # slack: the nodal contact of the statics
    k_diag = np.zeros(n_nodes * dim)
    c_diag = np.zeros(n_nodes * dim)
    k_diag[vertical::dim] = stiffness * trib
    c_diag[vertical::dim] = damping * trib
    if not split:
        return BedContact(gr, k_diag, c_diag, None, 0.0, None, None)
    # the grounded part lies on the bed (horizontal, stretched by T/EA), the
    # suspended part runs from the touchdown to node b
    chord = tangents[k] * length[k]
    horiz = chord.copy()
    horiz[vertical] = 0.0
    l_g = xi * l0[k] * (1.0 + float(tension[k]) / float(ea[k]))
    h_norm = float(np.linalg.norm(horiz))
    sub = np.stack([horiz, horiz])
    if h_norm > 0.0:
        sub[0] = l_g * horiz / h_norm
        sub[1] = chord - sub[0]
    l_sub = np.linalg.norm(sub, axis=1)
    if h_norm <= 1e-6 * length[k] or l_sub[1] <= 1e-6 * length[k]:
        # a (near-)vertical touchdown element: no horizontal bed to split it on
        trib[k] += (1.0 - xi) * half[k]
        k_diag[vertical::dim] = stiffness * trib
        c_diag[vertical::dim] = damping * trib
        return BedContact(gr, k_diag, c_diag, None, 0.0, None, None)
    blocks = stiffness_blocks(
        sub / l_sub[:, None],
        l_sub,
        l0[k] * np.array([xi, 1.0 - xi]),
        np.full(2, ea[k]),
        np.full(2, tension[k]),
    )
    bed_t = xi * half[k]  # contact length lumped on the split node, times D
    k_block, r = _condensed(blocks[0], blocks[1], stiffness * bed_t, vertical)
    rz = r[vertical]
    c_block = damping * bed_t * np.outer(rz, rz)
    transform = np.zeros((3 * dim, 2 * dim))
    transform[:dim, :dim] = np.eye(dim)
    transform[dim : 2 * dim] = r
    transform[2 * dim :, dim:] = np.eye(dim)
    e_s = sub[1] / l_sub[1]
    row = np.zeros((2, dim))
    row[0] = -(r[:, :dim].T @ e_s)
    row[1] = e_s - r[:, dim:].T @ e_s
    row *= float(ea[k]) / ((1.0 - xi) * float(l0[k]))
    return BedContact(
        gr, k_diag, c_diag, k, xi, k_block, c_block, transform, sub / l_sub[:, None], row
    )


def _condensed(
    ka: np.ndarray, kb: np.ndarray, k_t: float, vertical: int
) -> tuple[np.ndarray, np.ndarray]:
    """Stiffness (2d, 2d) of two sub-elements a–t (node block ka) and t–b (kb) joined
    at a massless node t with a vertical spring k_t, t condensed out, and the map
    R (d, 2d), u_t = R [u_a; u_b]."""
    d = ka.shape[0]
    ktt = ka + kb
    ktt[vertical, vertical] += k_t
    kto = np.hstack([-ka, -kb])  # (d, 2d)
    r = -np.linalg.solve(ktt, kto)
    koo = np.zeros((2 * d, 2 * d))
    koo[:d, :d] = ka
    koo[d:, d:] = kb
    kc = koo + kto.T @ r
    return 0.5 * (kc + kc.T), r


def split_touchdown_element(
    bed: BedContact,
    k_el: np.ndarray,
    m_el: np.ndarray,
    ma_el: np.ndarray,
    mesh: Any,
    rho: float,
    lumped: bool,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Element stiffness, mass and added-mass matrices (n_el, 2·dim, 2·dim) with the
    touchdown element's replaced by its split and condensed ones (:func:`bed_contact`):
    the condensed stiffness, and the mass and normal added mass of its two parts
    (lengths ξl0, (1 − ξ)l0, each part's direction) reduced by
    :meth:`BedContact.reduce`.  The inputs unchanged (copies when there is a split)."""
    if bed.element is None:
        return k_el, m_el, ma_el
    k = bed.element
    share = np.array([bed.fraction, 1.0 - bed.fraction])
    k_el, m_el, ma_el = k_el.copy(), m_el.copy(), ma_el.copy()
    k_el[k] = bed.k_block
    m_el[k] = bed.reduce(share[:, None, None] * m_el[k])
    ma_el[k] = bed.reduce(
        added_mass_elements(
            bed.sub_tangents,
            mesh.l0[k] * share,
            np.full(2, mesh.ca_normal[k]),
            np.full(2, mesh.diameter[k]),
            rho,
            lumped,
        )
    )
    return k_el, m_el, ma_el


def tension_rows(
    tangents: np.ndarray, l0: np.ndarray, ea: np.ndarray, tension: np.ndarray, bed: BedContact
) -> np.ndarray:
    """Dynamic effective tension rows (n_el, 2, dim) of the elements,
    δT_j = rows[j, 0]·u_j + rows[j, 1]·u_j+1: (EA/l0)(−e, e) with EA·SLACK_EA_RATIO for
    slack elements (T <= 0), and the split touchdown element's
    :attr:`BedContact.tension_row`. [N/m]"""
    ea_eff = np.where(tension <= 0.0, SLACK_EA_RATIO * ea, ea)
    rows = (ea_eff / l0)[:, None, None] * np.stack([-tangents, tangents], axis=1)
    if bed.element is not None:
        rows[bed.element] = bed.tension_row
    return rows
