"""A moored platform read from a MoorDyn file and driven by vessel RAOs: MoorDyn's time
domain (stochcable.reference.moordyn_vessel) against the frequency domain."""

from __future__ import annotations

import warnings

import pytest

import stochcable
from stochcable.io import read_moordyn

pytest.importorskip("moordyn")

from _paths import MOORDYN_DATA

from stochcable.reference.moordyn_vessel import simulate_vessel_moordyn  # noqa: E402

DATA = MOORDYN_DATA


@pytest.fixture(scope="module")
def platform():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        doc = read_moordyn(DATA / "oc3_hywind_v2.txt").model_dump(mode="json", exclude_none=True)
    doc["sea"] = {"spectrum": {"type": "jonswap", "hs": 6.0, "tp": 11.0}, "heading": 0.0}
    doc["bodies"][0]["prescribed"] = {
        "omega": [0.0, 0.3, 0.6, 1.0, 1.5, 3.0],
        "surge": {"re": [1.0, 0.9, 0.5, 0.15, 0.03, 0.0], "im": [0.0] * 6},
        "heave": {"re": [1.0, 0.95, 0.6, 0.2, 0.05, 0.0], "im": [0.0] * 6},
    }
    doc["analysis"]["omega"] = {"min": 0.2, "max": 2.0, "count": 400}
    return stochcable.load_scene(doc)


@pytest.mark.slow
def test_moordyn_fairlead_sigma_agrees_with_the_frequency_domain(platform):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fd = stochcable.analyze(platform)
    rec = simulate_vessel_moordyn(platform, period=100.0, band=(0.2, 2.0), rng=0)
    assert rec.lines == ("line1", "line2", "line3")
    # lines 2 and 3 mirror each other about y = 0 and the motion has no sway, roll or
    # yaw: MoorDyn gives them the same record (to its round-off)
    assert rec.std[1] == pytest.approx(rec.std[2], rel=1e-6)
    for i, name in enumerate(rec.lines):
        end = fd.lines[name].end_b
        # the static tension of the last segment: MoorDyn's IC solve against the FE
        # statics' last element (0.5 %); the mean fairlead reaction under motion
        # against the FD mean end_b tension (a reaction too), 1 %
        assert rec.static[i] == pytest.approx(fd.statics.lines[name].tension[-1], rel=5e-3)
        assert rec.mean[i] == pytest.approx(end.mean, rel=1e-2)
    # σ: 15 % on the lines the surge loads (measured 5 % at T = 200 s): MoorDyn's lines
    # see no waves and its tension is nonlinear in the motion, the FD is linearized;
    # line1's σ is 14× smaller (surge and heave nearly cancel), 25 % (measured 11 %)
    assert rec.std[1] == pytest.approx(fd.lines["line2"].end_b.std, rel=0.15)
    assert rec.std[0] == pytest.approx(fd.lines["line1"].end_b.std, rel=0.25)
