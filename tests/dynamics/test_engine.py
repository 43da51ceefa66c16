"""Build once, solve per sea state (stochcable.dynamics.engine): an engine solved for
several sea states gives the documents of fresh analyses of the scenes with those
seas, builds the statics and the line models once, and keeps no state that changes
its answer."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from _compare import assert_close_documents

import stochcable
from stochcable.analysis import analyze
from stochcable.dynamics import engine as dengine
from stochcable.dynamics.engine import Engine, build_engine
from stochcable.errors import InputError
from stochcable.examples import load_example
from stochcable.scene.model import Sea, load_scene

SEA_2 = {"spectrum": {"type": "jonswap", "hs": 3.0, "tp": 8.0}, "heading": 0.0}


def _doc(name: str, timeseries: bool = False) -> dict:
    doc = load_example(name).model_dump(mode="json", exclude_none=True)
    if not timeseries:
        doc["analysis"].pop("timeseries", None)
    return doc


def _with_sea(doc: dict, sea: dict) -> dict:
    return {**doc, "sea": sea}


def _plain(result) -> dict:
    doc = result.to_document(timeseries="full")
    doc.pop("timing")
    # analyze() adds the element check's warnings after the engine's solve
    # (stochcable.fidelity.mesh_check): the engine alone does not give them
    doc["warnings"] = [w for w in doc["warnings"] if "error of the end-tension σ" not in w]
    return doc


@pytest.fixture(autouse=True)
def _quiet():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        yield


def _count_builds(monkeypatch) -> dict[str, int]:
    """Count the statics and line-model builds of dynamics.engine."""
    calls = {"statics": 0, "model": 0}
    solve_statics, build_line_system = dengine.solve_statics, dengine.build_line_system

    def statics(*args, **kw):
        calls["statics"] += 1
        return solve_statics(*args, **kw)

    def model(*args, **kw):
        calls["model"] += 1
        return build_line_system(*args, **kw)

    monkeypatch.setattr(dengine, "solve_statics", statics)
    monkeypatch.setattr(dengine, "build_line_system", model)
    return calls


def test_analyze_is_build_then_solve():
    doc = _doc("taut_wire")
    assert_close_documents(_plain(build_engine(doc).solve()), _plain(analyze(doc)), rtol=1e-12)
    # the public one is this engine with the element check (stochcable.fidelity.mesh_engine)
    from stochcable.fidelity.mesh_engine import checked_engine

    assert stochcable.build_engine is checked_engine


def test_two_sea_states_match_fresh_analyses_and_build_once(monkeypatch):
    doc = _doc("chain_catenary", timeseries=True)
    fresh_1 = _plain(analyze(doc))
    fresh_2 = _plain(analyze(_with_sea(doc, SEA_2)))
    calls = _count_builds(monkeypatch)
    engine = build_engine(doc)
    assert isinstance(engine, Engine) and len(engine.systems) == 1
    assert calls == {"statics": 1, "model": 1}
    got_2 = engine.solve(SEA_2)  # a mapping ...
    got_1 = engine.solve()  # ... and the scene's own sea
    assert calls == {"statics": 1, "model": 1}  # nothing rebuilt
    assert_close_documents(_plain(got_1), fresh_1, rtol=1e-12)
    assert_close_documents(_plain(got_2), fresh_2, rtol=1e-12)
    assert got_2.scene.sea == Sea.model_validate(SEA_2)
    assert got_1.timing["statics_s"] == got_2.timing["statics_s"] == engine.timing["statics_s"]


def test_different_hs_on_a_single_line():
    doc = _doc("taut_wire")
    spec = dict(doc["sea"]["spectrum"])
    engine = build_engine(doc)
    small = {**doc["sea"], "spectrum": {**spec, "hs": 0.5 * spec["hs"]}}
    res_small, res = engine.solve(Sea.model_validate(small)), engine.solve()
    assert_close_documents(_plain(res_small), _plain(analyze(_with_sea(doc, small))), rtol=1e-12)
    name = next(iter(res.lines))
    # drag makes the response sublinear in Hs, but it does grow with it
    assert 0.0 < res_small.lines[name].end_b.std < res.lines[name].end_b.std


def test_same_sea_twice_is_identical():
    engine = build_engine(_doc("inclined_guy"))
    a, b = _plain(engine.solve()), _plain(engine.solve())
    assert_close_documents(a, b, rtol=0.0)


def test_scene_with_bodies(monkeypatch):
    doc = _doc("tuah_1982_disc_buoy_single_leg")
    sea = {"spectrum": {"type": "pierson_moskowitz", "m0": 14.0, "omega_p": 0.6}}
    fresh = _plain(analyze(_with_sea(doc, sea)))
    calls = _count_builds(monkeypatch)
    engine = build_engine(doc)
    # the line systems and the groups are built once, with the statics
    assert set(engine.systems) == {"leg"} and engine.model.groups
    first = engine.solve(sea)
    engine.solve()
    assert calls["statics"] == 1 and calls["model"] == 1
    assert_close_documents(_plain(first), fresh, rtol=1e-12)


def test_invalid_sea_is_an_input_error():
    engine = build_engine(_doc("taut_wire"))
    with pytest.raises(InputError, match="sea"):
        engine.solve({"spectrum": {"type": "pierson_moskowitz", "hs": -1.0, "tp": 8.0}})


def test_progress_stages():
    stages: list[str] = []
    engine = build_engine(_doc("taut_wire"), progress=lambda s, i: stages.append(s))
    assert stages == ["statics", "model"]
    stages.clear()
    engine.solve(progress=lambda s, i: stages.append(s))
    assert stages[0] == "linearization" and stages[-2:] == ["outputs", "done"]
    assert np.isfinite(engine.timing["build_s"])


def test_analyze_accepts_a_scene_object():
    scene = load_scene(_doc("taut_wire"))
    assert build_engine(scene).scene is scene
