"""Discretization of a line into 2-node straight elements (Tuah (1982), §3.1).

A :class:`LineMesh` holds, per element, the unstretched length and the section and
hydrodynamic properties, and, per node, the lumped attachments.  Nodes sit at segment
boundaries, at the uniform subdivision of each segment into its ``elements`` count, and
at every attachment's arc length (the element containing it is split, so an attachment
is never smeared).  Node 0 is ``end_a``, node ``n_nodes - 1`` is ``end_b``.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stochcable.scene.model import Line

__all__ = ["LineMesh", "mesh_line"]

# An attachment closer than this fraction of its element's length to an existing node
# is placed on that node instead of creating a sliver element.
_SNAP = 1e-6


@dataclass(frozen=True, eq=False)
class LineMesh:
    """Finite-element discretization of one line.

    Attributes
    ----------
    name : str
        Line name.
    s0 : ndarray, shape (n_nodes,)
        Unstretched arc length of each node from end_a. [m]
    l0 : ndarray, shape (n_el,)
        Unstretched element length. [m]
    ea : ndarray, shape (n_el,)
        Axial stiffness. [N]
    mass : ndarray, shape (n_el,)
        Mass per unit length in air. [kg/m]
    diameter : ndarray, shape (n_el,)
        Hydrodynamic diameter. [m]
    cd_normal, cd_axial, ca_normal : ndarray, shape (n_el,)
        Normal drag (on D), axial drag (on πD) and normal added-mass coefficients. [-]
    cl_steady : ndarray, shape (n_el,) or None
        Steady lift coefficient on D and |V_r|² (docs/travelling.md); None: 0. [-]
    weight : ndarray, shape (n_el,)
        Net submerged weight per unit length, positive downward. [N/m]
    segment : ndarray of int, shape (n_el,)
        Index of the scene segment each element belongs to.
    node_mass : ndarray, shape (n_nodes,)
        Lumped attachment mass in air. [kg]
    node_buoyancy : ndarray, shape (n_nodes,)
        Lumped upward buoyancy force of attachments. [N]
    node_added_mass : ndarray, shape (n_nodes,)
        Lumped attachment added mass (isotropic). [kg]
    node_drag_area : ndarray, shape (n_nodes,)
        Lumped attachment Cd·A. [m²]
    end_a, end_b : ndarray, shape (3,)
        End positions. [m]
    axial_speed : float
        Transport speed of the line's material, end_a → end_b (docs/travelling.md). [m/s]
    """

    name: str
    s0: np.ndarray
    l0: np.ndarray
    ea: np.ndarray
    mass: np.ndarray
    diameter: np.ndarray
    cd_normal: np.ndarray
    cd_axial: np.ndarray
    ca_normal: np.ndarray
    weight: np.ndarray
    segment: np.ndarray
    node_mass: np.ndarray
    node_buoyancy: np.ndarray
    node_added_mass: np.ndarray
    node_drag_area: np.ndarray
    end_a: np.ndarray
    end_b: np.ndarray
    axial_speed: float = 0.0
    cl_steady: np.ndarray | None = None

    @property
    def n_nodes(self) -> int:
        """Number of nodes."""
        return int(self.s0.size)

    @property
    def n_elements(self) -> int:
        """Number of elements."""
        return int(self.l0.size)

    @property
    def length(self) -> float:
        """Total unstretched length. [m]"""
        return float(self.s0[-1])


def mesh_line(line: Line, rho: float, g: float) -> LineMesh:
    """Discretize a scene line into elements.

    Parameters
    ----------
    line : Line
        The validated line document.
    rho : float
        Water density. [kg/m³]
    g : float
        Gravitational acceleration. [m/s²]

    Returns
    -------
    LineMesh
        Elements and nodes of the line, attachments on nodes.
    """
    # Node arc lengths per segment: uniform subdivision.
    s_nodes: list[float] = [0.0]
    seg_of_el: list[int] = []
    start = 0.0
    for k, seg in enumerate(line.segments):
        edges = start + seg.length * np.arange(1, seg.elements + 1) / seg.elements
        s_nodes.extend(edges.tolist())
        seg_of_el.extend([k] * seg.elements)
        start += seg.length
    s = np.asarray(s_nodes)
    seg_idx = np.asarray(seg_of_el, dtype=int)
    s[-1] = start  # exact total length

    # Insert attachment nodes (split the element containing them).
    for att in sorted(line.attachments, key=lambda a: a.at):
        at = min(att.at, start)
        j = int(np.searchsorted(s, at))  # s[j-1] < at <= s[j]
        if j == 0:
            continue
        el = j - 1
        le = s[j] - s[j - 1]
        if min(at - s[j - 1], s[j] - at) <= _SNAP * le:
            continue
        s = np.insert(s, j, at)
        seg_idx = np.insert(seg_idx, el, seg_idx[el])

    n = s.size
    node_mass = np.zeros(n)
    node_buoy = np.zeros(n)
    node_am = np.zeros(n)
    node_cda = np.zeros(n)
    for att in line.attachments:
        i = int(np.argmin(np.abs(s - min(att.at, start))))
        node_mass[i] += att.mass
        node_buoy[i] += att.buoyancy
        node_am[i] += att.added_mass
        node_cda[i] += att.drag_area

    segs = line.segments

    def per_el(attr: str) -> np.ndarray:
        vals = np.array([getattr(sg, attr) for sg in segs], dtype=float)
        return vals[seg_idx]

    weight = np.array([sg.submerged_weight(rho, g) for sg in segs])[seg_idx]
    return LineMesh(
        name=line.name,
        s0=s,
        l0=np.diff(s),
        ea=per_el("ea"),
        mass=per_el("mass"),
        diameter=per_el("diameter"),
        cd_normal=per_el("cd_normal"),
        cd_axial=per_el("cd_axial"),
        ca_normal=per_el("ca_normal"),
        weight=weight,
        segment=seg_idx,
        node_mass=node_mass,
        node_buoyancy=node_buoy,
        node_added_mass=node_am,
        node_drag_area=node_cda,
        end_a=np.asarray(line.end_a.position, dtype=float),
        end_b=np.asarray(line.end_b.position, dtype=float),
        axial_speed=float(line.axial_speed),
        cl_steady=per_el("cl_steady") if any(sg.cl_steady for sg in segs) else None,
    )
