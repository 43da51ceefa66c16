"""MoorDyn files written by stochcable run in MoorDyn-C, and MoorDyn's converged static
tensions equal stochcable's statics on every MoorDyn line of every test model."""

from __future__ import annotations

import json
import warnings

import pytest

from stochcable.errors import PhysicsWarning
from stochcable.io import read_moordyn
from stochcable.scene.model import load_scene
from stochcable.statics import solve_statics

pytest.importorskip("moordyn")

from _paths import MOORDYN_DATA

from stochcable.reference.moordyn_statics import moordyn_static_tensions  # noqa: E402

DATA = MOORDYN_DATA

# Every test model but tripod_network.txt (its own test below).
MODELS = [
    # the 1 t clump given 0.5 m above the end of its slack, nearly weightless line:
    # stochcable's statics start from the straight-bar model's pose (bodies.start);
    # measured 4e-9
    "clump_weight_lifting.txt",
    "oc3_hywind_v1.txt",
    "oc3_hywind_v2.txt",
    "wd0050_chain.txt",
    "coupled_body.txt",
    "stochcable_clump_buoy.txt",
    "stochcable_buoy_network.txt",
    # OpenFAST's regression-test inputs (tests/data/moordyn/openfast/SOURCE.md); measured
    # worst: 0.021 %, the ITI barge's anchor ends (kBot = 3e4 Pa/m, a soft seabed)
    "openfast/OC3Hywind_MoorDyn.dat",
    "openfast/OC4DeepCwindSemi_MoorDyn.dat",
    "openfast/MRSemi_MoorDyn.dat",
    "openfast/ITIBarge4_MoorDyn.dat",
    "openfast/MIT_NREL_TLP_MoorDyn.dat",
]


@pytest.mark.slow
@pytest.mark.parametrize("name", MODELS)
def test_moordyn_static_end_tensions_equal_stochcable_statics(name):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PhysicsWarning)
        sc = read_moordyn(DATA / name)
        # "fe": the finite-element statics, whose seabed is the same linear springs per
        # contact area as MoorDyn's kBot (the catenary's seabed is rigid)
        st = solve_statics(sc, "fe")
        md = moordyn_static_tensions(sc, ic_threshold=1e-6, ic_tmax=300.0)
    assert len(md) >= len(sc.lines)
    for seg in md:
        tension = st.lines[seg.line].tension
        # both lump the same mesh (MoorDyn's NumSegs = the segment's elements): the
        # first and last segment of each MoorDyn line are elements of the scene line.
        # 0.5 %: the bound; MoorDyn's relaxation stops at threshIC (measured
        # worst: 0.19 %, the buoy network's slack riser at 1.3 kN; the others < 0.1 %)
        assert tension[seg.element_a] == pytest.approx(seg.tension_a, rel=5e-3)
        assert tension[seg.element_b] == pytest.approx(seg.tension_b, rel=5e-3)


@pytest.mark.slow
def test_moordyn_static_tensions_of_the_rm1_tidal_platform():
    """OpenFAST's MHK_RM1_Floating mooring: six heavy chains (645 kg/m, EA 8.5e9 N) in
    50 m, most of their length on the seabed; anchor tensions (14-19 kN) a small
    difference under the fairleads' 222 kN."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PhysicsWarning)
        sc = read_moordyn(DATA / "openfast" / "MHK_RM1_Floating_MoorDyn.dat")
        st = solve_statics(sc, "fe")
        # MoorDyn's dynamic relaxation over 300 s (threshIC 1e-9: it runs the whole
        # TmaxIC; the fairleads' last relative change 2e-6).  Its default stationary
        # solver relaxes the grounded chains slowly, towards stochcable's value: line2's
        # anchor 7.1 % off at 300 s, 5.2 % at 600 s, 2.0 % at 1500 s; the dynamic
        # relaxation 0.30 % at 150 s, 0.14 % at 300 s, 0.04 % at 600 s
        md = moordyn_static_tensions(sc, ic_threshold=1e-9, ic_tmax=300.0, ic_dynamic=True)
    assert len(md) == len(sc.lines) == 6
    for seg in md:
        tension = st.lines[seg.line].tension
        # the 0.5 %: measured worst 0.14 % (anchor ends), fairleads 0.007 %
        assert tension[seg.element_a] == pytest.approx(seg.tension_a, rel=5e-3)
        assert tension[seg.element_b] == pytest.approx(seg.tension_b, rel=5e-3)


def _lowered(scene, drop: float):
    """The scene with every position ``drop`` lower and the water ``drop`` deeper."""
    doc = json.loads(scene.model_dump_json(exclude_none=True))
    doc["environment"]["depth"] += drop
    for line in doc["lines"]:
        for end in ("end_a", "end_b"):
            if "position" in line[end]:
                line[end]["position"][2] -= drop
    for body in doc["bodies"]:
        body["position"][2] -= drop
    return load_scene(doc)


@pytest.mark.slow
def test_moordyn_static_tensions_of_the_tripod_network():
    """MoorDyn's tripod.txt: a four-line junction on three three-segment legs (two of
    them partly on the seabed) and a 0.82 m float (3 segments of 0.21 m) on a tether,
    its free end a massless point.

    As shipped, the float pierces the surface: stochcable's statics converge (the
    float's top element lies across the surface; its wet-fraction stiffness is in the
    body Newton), but MoorDyn has no settled state to compare with: its stationary
    solver's error grows after 30 s (1.7 m/s² at 60 s) and its dynamic relaxation
    leaves the float bobbing (tensions 2 to 50 times off at 30 s).  The two models
    also differ there by design: MoorDyn's wet fraction of a segment counts its
    radius (0.41 m on 0.21 m segments), stochcable's its centreline.  So the tensions
    are compared on the same network 3 m deeper, the float fully submerged."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PhysicsWarning)
        shipped = read_moordyn(DATA / "tripod_network.txt")
        st = solve_statics(shipped, "fe")
        assert max(b.residual for b in st.bodies.values()) <= 1e-8
        sc = _lowered(shipped, 3.0)
        st = solve_statics(sc, "fe")
        # dtM 5e-5 s: the stiff float (EA 2.2e9 N on 0.21 m) at MoorDyn's CFL 0.15;
        # dynamic relaxation over 30 s (threshIC 1e-9: the whole TmaxIC)
        md = moordyn_static_tensions(sc, ic_threshold=1e-9, ic_tmax=30.0, dt=5e-5, ic_dynamic=True)
    assert len(md) == 11
    for seg in md:
        tension = st.lines[seg.line].tension
        # the 0.5 %: measured worst 0.14 % (the slack leg's anchor end, 167 N)
        assert tension[seg.element_a] == pytest.approx(seg.tension_a, rel=5e-3)
        assert tension[seg.element_b] == pytest.approx(seg.tension_b, rel=5e-3)
