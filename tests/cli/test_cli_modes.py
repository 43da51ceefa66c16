"""``stochcable modes`` CLI: document shape, agreement with the API, plot, errors."""

from __future__ import annotations

import json
import sys

import numpy as np
import pytest
from _paths import TESTS

from stochcable.cli import main

pytest.importorskip("stochcable.line.statics")

# the taut scene and its reference are tests/line/test_modes.py's
sys.path.insert(0, str(TESTS / "line"))
from test_modes import TAUT_SCENE, taut_scene_reference  # noqa: E402


@pytest.fixture()
def scene_file(tmp_path):
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(TAUT_SCENE))
    return path


def test_modes_json_document(scene_file, tmp_path, capsys):
    out = tmp_path / "modes.json"
    assert main(["modes", str(scene_file), "--count", "4", "-o", str(out)]) == 0
    doc = json.loads(out.read_text())
    line = doc["modes"]["lines"]["taut"]
    assert set(line) == {"omega", "period", "plane"}
    assert doc["modes"]["omega"] == line["omega"]  # the contract's top-level omega
    w = np.array(line["omega"])
    # transverse string modes, each in-plane and out-of-plane; 100-element FE error
    # (nπ/100)²/24 <= 1.7e-4 for n <= 2
    np.testing.assert_allclose(w, np.repeat(taut_scene_reference(2), 2), rtol=2e-4)
    np.testing.assert_allclose(line["period"], 2 * np.pi / w, rtol=1e-14)
    assert sorted(line["plane"]) == ["in-plane"] * 2 + ["out-of-plane"] * 2


def test_modes_stdout_in_air_and_2d(scene_file, capsys):
    assert main(["modes", str(scene_file), "--count", "2", "--dim", "2", "--in-air"]) == 0
    doc = json.loads(capsys.readouterr().out)
    w = np.array(doc["modes"]["omega"])
    # in air: mass 50 instead of 50 + ρπD²/4 → frequencies up by √(m_t/m)
    wet = taut_scene_reference(2)
    ratio = np.sqrt((50.0 + 1025.0 * np.pi * 0.01 / 4) / 50.0)
    np.testing.assert_allclose(w, wet * ratio, rtol=2e-4)
    assert doc["modes"]["lines"]["taut"]["plane"] == ["in-plane", "in-plane"]


def test_modes_plot(scene_file, tmp_path, capsys):
    png = tmp_path / "modes.png"
    assert main(["modes", str(scene_file), "--count", "4", "--plot", str(png)]) == 0
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_modes_errors(scene_file, tmp_path, capsys):
    assert main(["modes", str(scene_file), "--count", "0"]) == 2
    assert "--count = 0: must be an integer >= 1" in capsys.readouterr().err
    assert main(["modes", str(tmp_path / "missing.json")]) == 2
    assert "cannot be read" in capsys.readouterr().err


def test_modes_of_a_scene_with_bodies_say_the_ends_are_held(tmp_path, capsys):
    from stochcable.examples import load_example

    out = tmp_path / "m.json"
    scene = tmp_path / "three_legs.json"
    scene.write_text(load_example("tuah_1982_disc_buoy_three_legs").model_dump_json())
    assert main(["modes", str(scene), "--count", "3", "-o", str(out)]) == 0
    err = capsys.readouterr().err
    assert "ends held at their static positions" in err and "bodies.<name>.modes" in err
    doc = json.loads(out.read_text())
    assert set(doc["modes"]["lines"]) == {"leg1", "leg2", "leg3"}
