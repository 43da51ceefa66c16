"""Tests of stochcable.bodies.mooring: the condensed end stiffness of a line.

Checked against central finite differences of the re-solved line statics, for a float
whose elements cross the water surface (their wet fraction moves with the ends).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from stochcable.bodies.mooring import end_condensation
from stochcable.line.mesh import mesh_line
from stochcable.line.statics import solve_line_statics
from stochcable.scene.model import load_scene


def _float_on_tether(top_z: float) -> dict:
    """A 0.63 m float (0.82 m diameter, net buoyancy 4 kN/m) on a 1.1 m tether from a
    point body 1.6 m below the surface, its top end on a second point body at top_z."""
    body = {"mass": 0.001, "fixed_dofs": ["roll", "pitch", "yaw"]}
    return {
        "environment": {"depth": 16.0, "rho": 1025.0, "g": 9.80665},
        "bodies": [
            {"name": "junction", "position": [0.0, 0.0, -1.6], **body},
            {"name": "top", "position": [0.35, 0.2, top_z], **body},
        ],
        "lines": [
            {
                "name": "float",
                "end_a": {"attach": {"body": "junction", "point": [0.0, 0.0, 0.0]}},
                "end_b": {"attach": {"body": "top", "point": [0.0, 0.0, 0.0]}},
                "segments": [
                    {"length": 1.11, "ea": 2.6e7, "mass": 3.8, "diameter": 0.025, "elements": 5},
                    {"length": 0.63, "ea": 2.2e9, "mass": 133.3, "diameter": 0.82, "elements": 3},
                ],
            }
        ],
    }


@pytest.mark.parametrize("top_z", [0.05, -0.3])
def test_condensed_stiffness_of_a_float_piercing_the_surface(top_z):
    """K_e = −dF/dx of both ends equals the central differences of the end forces of
    the re-solved statics: with the top element across the surface (the derivative of
    its wet fraction: z–z terms ten times the elastic ones) and fully submerged."""
    scene = load_scene(_float_on_tether(top_z))
    env = scene.environment
    ln = scene.lines[0]
    mesh = mesh_line(scene.resolved_line(ln), env.rho, env.g)
    ls = solve_line_statics(mesh, env, method="fe", tolerance=1e-13)
    crossing = bool(np.any(ls.positions[:, 2] > 0.0))
    assert crossing == (top_z > 0.0)
    ends = ["end_a", "end_b"]
    ke, _ = end_condensation(scene, ln, ls, ends, False, "fe", 1e-13)
    h = 1e-6
    fd = np.zeros((6, 6))
    for q, end in enumerate(ends):
        for k in range(3):
            forces = []
            for sign in (1.0, -1.0):
                moved = getattr(mesh, end).copy()
                moved[k] += sign * h
                m2 = dataclasses.replace(mesh, **{end: moved})
                l2 = solve_line_statics(m2, env, method="fe", initial=ls.positions, tolerance=1e-13)
                forces.append(np.concatenate([l2.force_a, l2.force_b]))
            fd[:, 3 * q + k] = -(forces[0] - forces[1]) / (2.0 * h)
    # central differences of 1e-6 m on end forces resolved to ~1e-9 N: 1e-4 of the
    # largest entry (the float's vertical stiffness, ~6 kN/m across the surface)
    np.testing.assert_allclose(ke, fd, rtol=0, atol=1e-4 * np.abs(fd).max())
    if crossing:
        # the wet-fraction term dominates the vertical stiffness of the top end
        assert ke[5, 5] > 5.0 * ke[3, 3]
