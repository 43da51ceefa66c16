"""Analytic static shapes for the finite-element and modal tests (owned with test_fem.py).

Each builder returns (mesh, positions, tension) ready for :func:`stochcable.line.fem.assemble`.
The meshes are built directly (not from a scene) so that the prestress, the mass per
length and the geometry are exactly those of the closed-form references.
"""

from __future__ import annotations

import numpy as np

from stochcable.line.mesh import LineMesh


def uniform_mesh(
    n_el: int,
    l0: np.ndarray | float,
    ea: float,
    mass: float,
    diameter: float = 0.1,
    ca_normal: float = 0.0,
    weight: float = 0.0,
    name: str = "case",
) -> LineMesh:
    """A one-segment mesh of n_el elements of unstretched lengths l0 (scalar or array)."""
    l0 = np.broadcast_to(np.asarray(l0, dtype=float), (n_el,)).copy()
    s0 = np.concatenate([[0.0], np.cumsum(l0)])
    f = np.ones(n_el)
    z = np.zeros(n_el + 1)
    return LineMesh(
        name=name,
        s0=s0,
        l0=l0,
        ea=ea * f,
        mass=mass * f,
        diameter=diameter * f,
        cd_normal=1.2 * f,
        cd_axial=0.0 * f,
        ca_normal=ca_normal * f,
        weight=weight * f,
        segment=np.zeros(n_el, dtype=int),
        node_mass=z.copy(),
        node_buoyancy=z.copy(),
        node_added_mass=z.copy(),
        node_drag_area=z.copy(),
        end_a=np.zeros(3),
        end_b=np.zeros(3),
    )


def taut_string(
    n_el: int, length: float, tension: float, mass: float, ea: float, direction=(1.0, 0.0, 0.0)
):
    """Straight string along ``direction``; l0 = l so m is per current length."""
    d = np.asarray(direction, float) / np.linalg.norm(direction)
    s = np.linspace(0.0, length, n_el + 1)
    mesh = uniform_mesh(n_el, np.diff(s), ea, mass)
    return mesh, s[:, None] * d[None, :], np.full(n_el, tension)


def hanging_chain(n_el: int, length: float, mass: float, g: float, ea: float):
    """Vertical chain, node 0 at the top (z = 0), free lower end at z = -length.

    Tension at each element's midpoint, T = m g (distance from the free end).
    """
    s = np.linspace(0.0, length, n_el + 1)  # from the top
    mesh = uniform_mesh(n_el, np.diff(s), ea, mass)
    pos = np.column_stack([np.zeros_like(s), np.zeros_like(s), -s])
    mid = 0.5 * (s[1:] + s[:-1])
    return mesh, pos, mass * g * (length - mid)


def shallow_parabola(
    n_el: int, span: float, sag_ratio: float, h: float, mass: float, g: float, ea: float
):
    """Horizontal cable of span ``span``, parabolic sag d = sag_ratio·span, in x–z.

    Nodes uniform in x; horizontal tension component H = h, element tension
    T = H·l/Δx (the parabola is the equilibrium of a load w = m g per horizontal
    length, w = 8 H d / span²; ``mass`` is then chosen by the caller as w/g).
    l0 = l (mass per current length, as in the shallow-sag theory).
    """
    x = np.linspace(0.0, span, n_el + 1)
    d = sag_ratio * span
    z = -4.0 * d * x * (span - x) / span**2
    dx, dz = np.diff(x), np.diff(z)
    l = np.hypot(dx, dz)
    mesh = uniform_mesh(n_el, l, ea, mass)
    pos = np.column_stack([x, np.zeros_like(x), z])
    return mesh, pos, h * l / dx
