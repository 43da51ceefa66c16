"""Tests of the ``stochcable statics`` command."""

from __future__ import annotations

import json

import pytest

from stochcable.cli import main

SCENE = {
    "environment": {"depth": 200.0},
    "lines": [
        {
            "name": "leg1",
            "end_a": {"position": [-800.0, -100.0, -200.0]},
            "end_b": {"position": [0.0, 0.0, -20.0]},
            "segments": [
                {"length": 850.0, "ea": 1.2326e9, "mass": 288.0, "diameter": 0.216, "elements": 20}
            ],
        }
    ],
}


def test_json_output(tmp_path, capsys):
    f = tmp_path / "scene.json"
    f.write_text(json.dumps(SCENE))
    assert main(["statics", str(f), "--format", "json", "--method", "fe"]) == 0
    doc = json.loads(capsys.readouterr().out)
    line = doc["statics"]["lines"]["leg1"]
    assert line["end_a"]["tension"] > 1e5 and line["end_b"]["tension"] > line["end_a"]["tension"]
    assert len(line["nodes"]) == 21 and line["method"] == "fe"
    assert line["touchdown"] > 0


def test_output_file_and_plot(tmp_path):
    pytest.importorskip("matplotlib")
    f = tmp_path / "scene.json"
    f.write_text(json.dumps(SCENE))
    out, png = tmp_path / "out.json", tmp_path / "shape.png"
    assert main(["statics", str(f), "-o", str(out), "--plot", str(png)]) == 0
    assert json.loads(out.read_text())["statics"]["lines"]["leg1"]["method"] == "catenary"
    assert png.stat().st_size > 1000


def test_bad_file_exits_2_one_line(tmp_path, capsys):
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"environment": {"depth": -1.0}, "lines": []}))
    assert main(["statics", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "depth" in err
    assert main(["statics", str(tmp_path / "missing.json")]) == 2
