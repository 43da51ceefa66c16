"""Tests of stochcable.bodies.start: the straight-bar start of the body statics.

Checked against the closed form of a weight hanging on a weightless elastic line,
given at a position where the line is slack (MoorDyn's lifting test, tests/Mooring/
lifting.txt of the MoorDyn repository: a 1 t clump 0.5 m above the end of its line).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from stochcable.bodies.from_scene import scene_rigid_bodies
from stochcable.bodies.start import bar_start_poses
from stochcable.line.mesh import mesh_line
from stochcable.scene.model import load_scene
from stochcable.statics import solve_statics

RHO, G = 1000.0, 9.80665
L, EA, M = 100.5, 1.0e9, 1000.0


def _lifting(line_mass: float, position=(0.0, 0.0, -100.0)) -> dict:
    """A 1 t clump (default at z = -100 m) on a 100.5 m line from the origin (0.5 m of
    slack)."""
    return {
        "environment": {"depth": 500.0, "rho": RHO, "g": G},
        "bodies": [
            {"name": "clump", "position": list(position), "mass": M, "fixed_dofs": ["pitch"]}
        ],
        "lines": [
            {
                "name": "line",
                "end_a": {"position": [0.0, 0.0, 0.0]},
                "end_b": {"attach": {"body": "clump", "point": [0.0, 0.0, 0.0]}},
                "segments": [
                    {"length": L, "ea": EA, "mass": line_mass, "diameter": 0.1, "elements": 20}
                ],
            }
        ],
    }


# exactly weightless (the line statics refuse its slack shape) and MoorDyn's 7.85398
# kg/m, 1.6e-6 kg/m lighter than the water it displaces (its slack shape is beyond
# double precision: tension ~1e-4 N against a force resolution of ~4e-5 N)
@pytest.mark.parametrize("line_mass", [RHO * math.pi * 0.1**2 / 4.0, 7.85398])
def test_a_weight_given_above_the_end_of_its_slack_line_hangs_at_the_closed_form(line_mass):
    scene = load_scene(_lifting(line_mass))
    st = solve_statics(scene, "fe")
    tension = M * G
    # the weightless elastic line: z = −L (1 + T/EA); the 1.6e-6 kg/m of buoyancy
    # changes T by 1.6e-3 N (2e-7 relative), z by 1.6e-10 m
    assert st.bodies["clump"].position[2] == pytest.approx(-L * (1.0 + tension / EA), abs=1e-8)
    assert st.lines["line"].tension == pytest.approx(tension, rel=1e-6)
    assert st.bodies["clump"].residual <= 1e-8


def test_bar_start_is_the_taut_bar_equilibrium():
    """The start itself: the clump where the straight bar carries its weight (half
    the line's own weight lumped on it, nil here)."""
    scene = load_scene(_lifting(RHO * math.pi * 0.1**2 / 4.0))
    env = scene.environment
    poses = {"clump": np.array([0.0, 0.0, -100.0, 0.0, 0.0, 0.0])}
    meshes = {"line": mesh_line(scene.resolved_line(scene.lines[0]), env.rho, env.g)}
    start = bar_start_poses(scene, poses, ["clump"], meshes, scene_rigid_bodies(scene))
    np.testing.assert_allclose(start["clump"], [0.0, 0.0, -L * (1.0 + M * G / EA), 0, 0, 0])
    assert poses["clump"][2] == -100.0  # the input is not modified


# started off the vertical, the line slack: 5 m aside, and 60 m aside 20 m deep (a
# slack line of 100.5 m over a 63 m chord); the bar start's stiffness continuation
# swings the pendulum down (a stiff bar alone took 200 trust-region steps to go 19 m
# further off, and a compressive slack law pushed the clump through the anchor)
@pytest.mark.parametrize("position", [(5.0, 0.0, -95.0), (-60.0, 0.0, -20.0)])
def test_a_weight_started_off_the_vertical_hangs_below_the_anchor(position):
    st = solve_statics(load_scene(_lifting(7.85398, position)), "fe")
    np.testing.assert_allclose(
        st.bodies["clump"].position, [0.0, 0.0, -L * (1.0 + M * G / EA)], rtol=0, atol=1e-8
    )
