"""Tests of the shipped example scenes (stochcable.examples) against their sources."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from references import BLIET_1984_GUY, TUAH_1982_EX2, TUAH_1982_EX5

from stochcable.errors import InputError
from stochcable.examples import DOCUMENTED_WARNINGS, list_examples, load_example
from stochcable.line.catenary import catenary_line
from stochcable.line.mesh import mesh_line
from stochcable.sea.spectra import spectrum_pierson_moskowitz

ROOT = Path(__file__).resolve().parents[1]
PKG = ROOT / "stochcable" / "examples"

EXPECTED = {
    "chain_catenary",
    "tuah_1982_suspended_cable",
    "taut_wire",
    "inclined_guy",
    "tuah_1982_single_leg",
    "tuah_1982_disc_buoy_single_leg",
    "tuah_1982_disc_buoy_three_legs",
    "tuah_1982_strumming_string",
    "cable_laying",
}


def test_list_and_load():
    assert set(list_examples()) == EXPECTED
    assert sorted(p.stem for p in PKG.glob("*.json")) == list_examples()
    for name in list_examples():
        scene = load_example(name)
        assert 0 < len(scene.title) <= 200
        assert load_example(f"{name}.json") == scene
    with pytest.raises(
        InputError,
        match=r"example = 'nope': is not a known example; known: "
        r"cable_laying, chain_catenary, inclined_guy",
    ):
        load_example("nope")


def test_top_level_readme_points_to_package_data():
    text = (ROOT / "examples" / "README.md").read_text(encoding="utf-8")
    assert "stochcable/examples/" in text
    for name in EXPECTED:
        assert f"`{name}`" in text


def test_chain_catenary_is_design_example():
    """The example is DESIGN.md's v1 scene (without the load-free attachment)."""
    doc = json.loads((PKG / "chain_catenary.json").read_text(encoding="utf-8"))
    line = doc["lines"][0]
    assert doc["environment"] == {
        "depth": 200.0,
        "rho": 1025.0,
        "g": 9.80665,
        "current": [{"z": 0.0, "speed": 0.5, "heading": 0.0}],
        "seabed": {"stiffness": 3.0e6, "damping": 3.0e5},
    }
    assert doc["sea"] == {
        "spectrum": {"type": "pierson_moskowitz", "hs": 6.0, "tp": 10.0},
        "heading": 0.0,
    }
    assert line["end_a"]["position"] == [-800.0, 0.0, -200.0]
    # the fairlead surge: DESIGN.md's PM Hs 2 m, Tp 10 s, band-limited by a cos² taper
    # from 0.9 to 1.5 rad/s (a vessel's surge RAO falls off above the wave band)
    surge = line["end_b"]["motion"]["surge"]
    assert surge["type"] == "table"
    w = np.array(surge["omega"])
    taper = np.where(w <= 0.9, 1.0, np.cos(0.5 * np.pi * (w - 0.9) / 0.6) ** 2)
    expected = spectrum_pierson_moskowitz(w, 2.0, 10.0) * taper
    expected[expected < 1e-6] = 0.0  # the table writes negligible densities as 0
    # the table is printed to 4 significant digits
    assert np.allclose(surge["density"], expected, rtol=1e-3, atol=0.0)
    assert line["segments"] == [
        {
            "length": 850.0,
            "ea": 1.2326e9,
            "mass": 288.0,
            "diameter": 0.216,
            "cd_normal": 1.333,
            "cd_axial": 0.2034,
            "ca_normal": 1.0,
            "elements": 40,
        }
    ]


def test_tuah_suspended_cable_matches_seed_data():
    s = load_example("tuah_1982_suspended_cable")
    t = TUAH_1982_EX2
    env, line = s.environment, s.lines[0]
    assert (env.g, env.rho) == (t["g"], t["fluid_density"])
    assert tuple(sg.length for sg in line.segments) == t["segment_lengths"]
    assert sum(sg.elements for sg in line.segments) == t["elements"]
    a, b = line.end_a.position, line.end_b.position
    assert (b[0] - a[0], b[2] - a[2]) == t["span"]
    mesh = mesh_line(line, env.rho, env.g)
    w = (t["cable_density"] - t["fluid_density"]) * t["area"] * t["g"]
    assert mesh.weight == pytest.approx([w] * mesh.n_elements, rel=1e-9)  # D rounded 1e-10
    assert mesh.ea[0] == pytest.approx(t["youngs_modulus"] * t["area"], rel=1e-15)
    assert mesh.node_buoyancy.sum() == t["buoy"]
    assert mesh.s0[mesh.node_buoyancy > 0] == [500.0]


def test_taut_wire_sag_over_span():
    s = load_example("taut_wire")
    res = catenary_line(s.lines[0], s.environment)
    p = res.positions
    chord = p[-1] - p[0]
    # distance of the nodes from the chord, relative to the span
    rel = p - p[0]
    perp = rel - (rel @ chord)[:, None] * chord / (chord @ chord)
    sag = max(float((perp**2).sum(axis=1).max()) ** 0.5, 0.0)
    assert 5e-4 < sag / math.sqrt(chord @ chord) < 2e-3  # "about 1e-3"
    assert res.solution.tension_b == pytest.approx(1.3e6, rel=0.02)


def test_inclined_guy_top_tension():
    """With the thesis's span, the example's guy has the thesis's top tension."""
    s = load_example("inclined_guy")
    res = catenary_line(s.lines[0], s.environment)
    g = BLIET_1984_GUY
    # thesis rho/g unknown: span printed to 0.01 m -> T within ~0.1 %
    assert res.solution.tension_b == pytest.approx(g["top_tension"], rel=2e-3)
    assert math.degrees(res.solution.angle_b) == pytest.approx(g["angle_top_deg"], abs=0.02)


def test_single_leg_wind_balance_and_sea():
    s = load_example("tuah_1982_single_leg")
    res = catenary_line(s.lines[0], s.environment)
    # L = 339 ft chosen so that H balances the seed's 100 lb wind load (0.1 % rounding)
    assert res.solution.H == pytest.approx(TUAH_1982_EX5["wind_load"], rel=2e-3)
    sp = s.sea.spectrum
    assert (sp.m0, sp.omega_p) == (TUAH_1982_EX5["m0"], TUAH_1982_EX5["omega_p"])
    om = s.analysis.omega
    assert om.count == TUAH_1982_EX5["n_frequencies"]
    assert (om.max - om.min) / (om.count - 1) == pytest.approx(TUAH_1982_EX5["d_omega"], rel=1e-12)
    ts = s.analysis.timeseries
    assert (ts.duration, ts.dt) == (TUAH_1982_EX5["record_length"], TUAH_1982_EX5["dt"])


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_example_runs_clean_or_documents_its_warnings(name):
    """Every bundled example analyses without a warning, or each warning it raises is
    one its entry in DOCUMENTED_WARNINGS explains (and each documented one occurs)."""
    from stochcable.analysis import analyze

    result = analyze(load_example(name))
    documented = DOCUMENTED_WARNINGS.get(name, {})
    for message in result.warnings:
        assert any(phrase in message for phrase in documented), message
    for phrase, why in documented.items():
        assert why and any(phrase in m for m in result.warnings), (name, phrase)
