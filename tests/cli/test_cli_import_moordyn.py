"""``stochcable import`` and MoorDyn files given to ``analyze`` and ``statics``."""

from __future__ import annotations

import json
import warnings

import pytest
from _paths import MOORDYN_DATA

from stochcable.cli import main
from stochcable.errors import PhysicsWarning
from stochcable.io import read_moordyn
from stochcable.scene.model import load_scene

DATA = MOORDYN_DATA
RAO = {
    "omega": [0.0, 0.5, 1.0, 2.0],
    "surge": {"re": [1.0, 0.6, 0.2, 0.0], "im": [0.0, 0.0, 0.0, 0.0]},
    "heave": {"re": [1.0, 0.8, 0.3, 0.0], "im": [0.0, 0.0, 0.0, 0.0]},
}
SEA = {"spectrum": {"type": "jonswap", "hs": 3.0, "tp": 10.0}, "heading": 0.0}


@pytest.fixture
def inputs(tmp_path):
    (tmp_path / "rao.json").write_text(json.dumps(RAO))
    (tmp_path / "sea.json").write_text(json.dumps(SEA))
    return tmp_path


def test_import_writes_the_scene_document(inputs, capsys):
    out = inputs / "scene.json"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PhysicsWarning)
        assert main(["import", str(DATA / "wd0050_chain.txt"), "-o", str(out)]) == 0
        assert load_scene(out) == read_moordyn(DATA / "wd0050_chain.txt")


def test_import_with_sea_and_vessel_rao(inputs):
    out = inputs / "scene.json"
    args = ["import", str(DATA / "oc3_hywind_v2.txt"), "--sea", str(inputs / "sea.json")]
    args += ["--vessel-rao", str(inputs / "rao.json"), "-o", str(out)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PhysicsWarning)
        assert main(args) == 0
    sc = load_scene(out)
    assert sc.sea.spectrum.hs == 3.0
    assert sc.body("vessel").prescribed.surge.re == (1.0, 0.6, 0.2, 0.0)


def test_analyze_takes_the_moordyn_file(inputs, capsys):
    args = ["analyze", str(DATA / "wd0050_chain.txt"), "--format", "json"]
    args += ["--sea", str(inputs / "sea.json"), "--vessel-rao", str(inputs / "rao.json")]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert main(args) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["lines"]["line1"]["end_b"]["tension"]["std"] > 0


def test_bad_file_is_one_line_on_stderr(inputs, capsys):
    bad = inputs / "bad.txt"
    bad.write_text((DATA / "wd0050_chain.txt").read_text().replace("1     chain      1 ", "1 x 1 "))
    assert main(["import", str(bad)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "line 15, column 3 (LINES)" in err and "unknown line type" in err
    assert main(["import", str(inputs / "sea.json")]) == 2
    assert "not a MoorDyn input file" in capsys.readouterr().err


def test_cases_takes_the_moordyn_file(inputs, capsys):
    scatter = inputs / "s.csv"
    scatter.write_text("hs,tp,gamma,probability\n2,8,2,0.5\n3,10,3.3,0.5\n")
    args = ["cases", str(DATA / "wd0050_chain.txt"), "--scatter", str(scatter)]
    args += ["--vessel-rao", str(inputs / "rao.json")]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert main(args) == 0
    doc = json.loads(capsys.readouterr().out)
    assert len(doc["cases"]) == 2
    # the vessel's motion drives the line: the larger sea gives the larger σ
    sig = [c["lines"]["line1"]["end_b"]["tension"]["std"] for c in doc["cases"]]
    assert 0 < sig[0] < sig[1]


def test_fairlead_spectra_replace_the_vessel(inputs, capsys):
    spectra = inputs / "fs.json"
    spectra.write_text(json.dumps({"surge": {"type": "jonswap", "hs": 2.0, "tp": 60.0}}))
    args = ["analyze", str(DATA / "oc3_hywind_v2.txt"), "--format", "json"]
    args += ["--sea", str(inputs / "sea.json"), "--fairlead-spectra", str(spectra)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert main(args) == 0
    doc = json.loads(capsys.readouterr().out)
    sig = {n: doc["lines"][n]["end_b"]["tension"]["std"] for n in ("line1", "line2", "line3")}
    # a surge along x: line1 lies along x, lines 2 and 3 at ±120°; to first order only
    # the motion in a line's own plane changes its tension, cos 120° = −0.5 of it.
    # ±0.01 (2 %): the drag linearization takes the whole (in- and out-of-plane) response
    assert sig["line2"] / sig["line1"] == pytest.approx(0.5, abs=0.01)
    assert sig["line3"] == pytest.approx(sig["line2"], rel=1e-9)
    both = [*args[:2], "--vessel-rao", str(inputs / "rao.json"), "--fairlead-spectra", str(spectra)]
    assert main(both) == 2
    assert "not both" in capsys.readouterr().err
