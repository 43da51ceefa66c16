"""A free buoy on three legs in MoorDyn (stochcable.reference.moordyn_body): the setup
against stochcable's statics, a run without a sea, and the file's drag rod."""

from __future__ import annotations

import math

import numpy as np
import pytest

import stochcable

pytest.importorskip("moordyn")

from stochcable.errors import InputError  # noqa: E402
from stochcable.reference.moordyn_body import (  # noqa: E402
    ROD_DIAMETER,
    moordyn_body_input_file,
    simulate_body_moordyn,
    three_leg_buoy_scene,
)
from stochcable.statics import solve_statics  # noqa: E402


@pytest.fixture(scope="module")
def calm():
    """The buoy without a sea (20 elements per leg, as the table): statics and a 60 s
    MoorDyn run, measured over its last 30 s (at 10 elements the touchdown's lumped
    against consistent weight puts the anchors 1.9 % apart)."""
    doc = three_leg_buoy_scene()
    doc.pop("sea")
    st = solve_statics(stochcable.load_scene(doc))
    return st, simulate_body_moordyn(doc, period=30.0, rng=0)


def test_moordyn_statics_agree_with_stochcable(calm):
    st, rec = calm
    # MoorDyn's equilibrium is the mean of the calm run: its initial-condition solve
    # stops at TmaxIC with the buoy 0.05 m below it (see the next test).  MoorDyn
    # lumps the weight on the nodes, ours on consistent elements: measured 0.02 % at
    # the fairleads, 0.37 % at the anchors (the bed contact of the lumped node); 0.5 %
    # is the bar for the statics
    for i, name in enumerate(rec.lines):
        ls = st.lines[name]
        assert rec.fairlead[:, i].mean() == pytest.approx(ls.node_tension[-1], rel=5e-3)
        assert rec.anchor[:, i].mean() == pytest.approx(ls.node_tension[0], rel=5e-3)
    body = st.bodies["buoy"]
    # the pose: 0.12 m higher in MoorDyn, on a heave stiffness of 8.8 kN/m: 1.0 kN,
    # 0.26 % of the lines' vertical pull (407 kN); the same 0.5 % bar on that force
    pull = -sum(f[2] for f in body.line_forces.values())
    z = rec.static_pose[2] + rec.motion[:, 2].mean()
    assert abs(z - body.position[2]) * body.stiffness[2, 2] < 5e-3 * pull
    assert np.abs(rec.static_pose[:2] - body.position[:2]).max() < 1e-6  # symmetry
    assert np.abs(rec.static_pose[3:]).max() < 1e-9


def test_moordyn_buoy_without_a_sea_stays_still(calm):
    _, rec = calm
    # no load but the statics: surge, sway and the rotations stay at rest (the drag
    # rod and the kinematics add nothing at rest; measured 1e-12 m, 1e-13 rad)
    assert np.abs(rec.motion[:, [0, 1]]).max() < 1e-6
    assert np.abs(rec.motion[:, 3:]).max() < 1e-8
    # heave rings about MoorDyn's equilibrium with what the initial-condition solve
    # left (0.049 m, stopped at TmaxIC = 300 s), nearly undamped without a sea (a sea
    # of Hs 3 m damps it through the body drag within ≈ 50 s of the 900 s warm-up)
    assert np.ptp(rec.motion[:, 2]) < 0.1
    # the three legs alike, the tensions steady to the heave ring's share
    assert np.ptp(rec.fairlead.mean(axis=0)) < 1e-6 * rec.fairlead.mean()
    assert rec.fairlead.std(axis=0).max() < 2e-3 * rec.fairlead.mean()


def test_moordyn_drag_rod_carries_the_body_drag_areas():
    doc = three_leg_buoy_scene(elements=4)
    text = moordyn_body_input_file(doc)
    row = next(r for r in text.splitlines() if r.startswith("dragrod "))
    d, _, cd, ca, cd_end, ca_end = (float(x) for x in row.split()[1:])
    rod = next(r for r in text.splitlines() if r.startswith("1 dragrod Body1"))
    length = float(rod.split()[8]) - float(rod.split()[5])
    assert d == ROD_DIAMETER and ca == 0.0 and ca_end == 0.0
    assert cd * d * length == pytest.approx(doc["bodies"][0]["drag_area"][0], rel=1e-9)
    assert 2 * cd_end * math.pi * d**2 / 4 == pytest.approx(doc["bodies"][0]["drag_area"][2])
    body = next(r for r in text.splitlines() if r.startswith("1 Free "))
    assert body.split()[12] == "0"  # MoorDyn's own body drag (vector norm) is off


def test_moordyn_body_refuses_what_it_does_not_model():
    doc = three_leg_buoy_scene(elements=4)
    doc["bodies"][0]["drag_point"] = [0.0, 0.0, -1.0]
    with pytest.raises(InputError, match="drag_point"):
        moordyn_body_input_file(doc)
