"""The element check on every way a scene is solved (stochcable.fidelity.mesh_engine):
``analyze``, ``stochcable.build_engine(...).solve(sea)`` and ``run_cases`` give the
same default counts and the same warnings, from the one seam."""

from __future__ import annotations

import copy
import warnings

import pytest

import stochcable
from stochcable import analyze, load_example
from stochcable.cases import run_cases, scatter_from_rows
from stochcable.errors import ResolutionWarning
from stochcable.fidelity.mesh_check import MESH_ERROR_LIMIT, mesh_estimates
from stochcable.fidelity.mesh_engine import MeshCheck

_PHRASE = "error of the end-tension σ"


def _taut(elements: int | None) -> dict:
    doc = load_example("taut_wire").model_dump(mode="json", exclude_none=True)
    doc = copy.deepcopy(doc)
    doc["analysis"].pop("timeseries", None)
    seg = doc["lines"][0]["segments"][0]
    if elements is None:
        seg.pop("elements", None)
    else:
        seg["elements"] = elements
    return doc


def _quiet(fn, *args, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fn(*args, **kw)


def _mesh(msgs) -> list[str]:
    return [w for w in msgs if _PHRASE in w]


def test_public_build_engine_is_checked_and_solve_warns_as_analyze():
    """An explicit coarse count: every solve of the public engine warns exactly as
    ``analyze`` of the same scene does (the warning names the count), and raises a
    ResolutionWarning."""
    doc = _taut(10)
    engine = _quiet(stochcable.build_engine, doc)
    assert isinstance(engine.check, MeshCheck)
    with pytest.warns(ResolutionWarning, match=r"use elements = \d+"):
        got = engine.solve()
    ref = _quiet(analyze, doc)
    assert _mesh(got.warnings) == _mesh(ref.warnings) and len(_mesh(ref.warnings)) == 1
    assert "segments[0].elements = 10" in _mesh(got.warnings)[0]


def test_engine_default_count_is_analyzes_and_other_seas_are_checked():
    """Without ``elements``: the engine's count is the one ``analyze`` chooses (more than
    the default 20) and its own sea is quiet; a shorter-period sea that needs more than
    that count warns, naming the count for it, which is its own estimate's."""
    doc = _taut(None)
    engine = _quiet(stochcable.build_engine, doc)
    ref = _quiet(analyze, doc)
    n = engine.scene.lines[0].segments[0].elements
    assert n == ref.scene.lines[0].segments[0].elements > 20
    own = _quiet(engine.solve)
    assert not _mesh(own.warnings)
    assert own.lines["wire"].end_b.std == pytest.approx(ref.lines["wire"].end_b.std, rel=1e-12)
    sea = dict(doc["sea"])
    # Tp 9 → 8.55 s: a higher sea ω₂ with the wire still wholly in the wave zone (the
    # wave-load rule's (kh)²/12 grows; at 0.9·Tp the zone ends above the wire's foot)
    sea["spectrum"] = {**sea["spectrum"], "tp": 0.95 * sea["spectrum"]["tp"]}
    short = _quiet(engine.solve, sea)
    est = mesh_estimates(short)[0]
    assert est.error > MESH_ERROR_LIMIT and est.needed > n  # (the test's premise)
    (msg,) = _mesh(short.warnings)
    assert f"this sea needs elements = {est.needed}" in msg


def test_case_sets_carry_the_check_in_every_row():
    """A case set on a coarse explicit count: every case's row carries its warning;
    without ``elements`` the set's engine has the count chosen for its shortest-period
    state (the set's damage arrays have that many elements)."""
    rows = [{"hs": 2.0, "tp": tp, "gamma": 3.3, "probability": 0.5} for tp in (9.0, 10.0)]
    sd = scatter_from_rows(rows)
    coarse = _quiet(run_cases, _taut(10), sd)
    for row in coarse.rows:
        assert [w for w in row.warnings if "segments[0].elements = 10" in w], row
    auto = _quiet(run_cases, _taut(None), sd)
    spec = {"type": "jonswap", "hs": 2.0, "tp": 9.0, "gamma": 3.3}
    pilot = dict(_taut(None), sea={"spectrum": spec})
    n = _quiet(analyze, pilot).scene.lines[0].segments[0].elements
    assert n > 20 and auto.s_elements["wire"].size == n
    assert not any(_mesh(r.warnings) for r in auto.rows)
