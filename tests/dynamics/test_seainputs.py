"""Inputs reused across sea states of one heading
(stochcable.dynamics.groups.seainputs): an engine solving sea states of known and new
headings in any order gives the documents of fresh analyses, keeps the inputs of the
headings it has seen (within its memory bound) and none of a large line."""

from __future__ import annotations

import pytest
from _compare import assert_close_documents

from stochcable.analysis import analyze
from stochcable.dynamics.engine import build_engine
from stochcable.dynamics.groups import seainputs
from stochcable.examples import load_example


def _doc(heading: float) -> dict:
    doc = load_example("chain_catenary").model_dump(mode="json", exclude_none=True)
    doc["analysis"].pop("timeseries", None)
    doc["analysis"]["omega"]["count"] = 80  # (a small grid: the test is on the reuse)
    doc["lines"][0]["segments"][0]["elements"] = 20
    # no current: the vector drag form with a current (a quadrature per element and
    # iteration) would be most of the time, and the reuse does not depend on it
    doc["environment"]["current"] = []
    doc["sea"]["heading"] = heading
    return doc


def _sea(kind: str, heading: float) -> dict:
    spec = (
        {"type": "pierson_moskowitz", "hs": 6.0, "tp": 10.0}
        if kind == "pm"
        else {"type": "jonswap", "hs": 3.0, "tp": 8.0, "gamma": 3.3}
    )
    return {"spectrum": spec, "heading": heading}


def _plain(result) -> dict:
    doc = result.to_document()
    doc.pop("timing")
    # analyze() adds the element check's warnings after the engine's solve
    # (stochcable.fidelity.mesh_check): the engine alone does not give them
    doc["warnings"] = [w for w in doc["warnings"] if "error of the end-tension σ" not in w]
    return doc


# 3.3–4.2 s of CPU with the residuals in the element tensions and node motions: over
# the fast tier's budget
@pytest.mark.slow
def test_sea_states_of_known_headings_equal_fresh_analyses() -> None:
    # an out-of-plane heading: the engine's models are 3-D, every heading solvable
    engine = build_engine(_doc(30.0))
    order = [("pm", 30.0), ("js", 30.0), ("pm", 60.0), ("js", 60.0), ("pm", 30.0)]
    for kind, heading in order:
        got = _plain(engine.solve(_sea(kind, heading)))
        ref = _plain(analyze({**_doc(30.0), "sea": _sea(kind, heading)}))
        # the same arrays and caches: round-off only (the contracting fixed point
        # carries 1e-16 regroupings to ~1e-13)
        assert_close_documents(got, ref, rtol=1e-12)
    kept = engine.systems["leg1"]._cache[seainputs._KEY]
    assert sorted(h for h, _ in kept) == [30.0, 60.0]


def test_large_inputs_are_not_kept(monkeypatch) -> None:
    monkeypatch.setattr(seainputs, "INPUT_CACHE_BYTES", 1024)
    engine = build_engine(_doc(0.0))
    got = _plain(engine.solve(_sea("js", 0.0)))
    assert not engine.systems["leg1"]._cache[seainputs._KEY]
    ref = _plain(analyze({**_doc(0.0), "sea": _sea("js", 0.0)}))
    assert_close_documents(got, ref, rtol=1e-12)


def test_oldest_heading_gives_way(monkeypatch) -> None:
    engine = build_engine(_doc(30.0))
    engine.solve(_sea("pm", 30.0))
    size = seainputs._nbytes(*engine.systems["leg1"]._cache[seainputs._KEY][(30.0, None)])
    # room for two headings' inputs (twice their arrays each): the third evicts the first
    monkeypatch.setattr(seainputs, "INPUT_CACHE_BYTES", 4 * size + 1)
    for h in (45.0, 60.0):
        engine.solve(_sea("pm", h))
    assert sorted(h for h, _ in engine.systems["leg1"]._cache[seainputs._KEY]) == [45.0, 60.0]
