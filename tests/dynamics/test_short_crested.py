"""Short-crested seas through the engine (``sea.spreading``): a spreading that narrows
to zero width is the long-crested analysis, mirrored spreadings give mirrored
responses on a line symmetric about the mean heading, sea states of one spreading
reuse their inputs, the time series realize every direction independently, and bad
documents are refused naming the parameter.  Scenes with bodies and vessels:
tests/dynamics/test_short_crested_bodies.py."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _scenes import LINEAR_ONLY

from stochcable.analysis import analyze
from stochcable.dynamics.engine import build_engine
from stochcable.errors import InputError
from stochcable.examples import load_example
from stochcable.scene.model import load_scene


def _chain(heading: float = 0.0, spreading: dict | None = None, timeseries: bool = False) -> dict:
    doc = load_example("chain_catenary").model_dump(mode="json", exclude_none=True)
    if not timeseries:
        doc["analysis"].pop("timeseries", None)
    doc["analysis"]["omega"]["count"] = 120  # (the physics is the test's, not the grid's)
    doc["sea"]["heading"] = heading
    if spreading is not None:
        doc["sea"]["spreading"] = spreading
    return doc


def _stats(result) -> dict:
    line = result.lines["leg1"]
    return {
        "end_a": line.end_a.std,
        "end_b": line.end_b.std,
        "tension": line.tension_std,
        "motion": line.motion_std,
    }


def test_zero_width_spreading_is_the_long_crested_sea():
    """cos-2s with s = 10⁶ in 15 bins: the side bins carry < 1e-30 and are left out,
    so the one direction left is the mean heading: the same channels' numbers (a
    different channel name) and, with one direction, the same realization."""
    ref = analyze(_chain(30.0, timeseries=True))
    got = analyze(_chain(30.0, {"type": "cos2s", "s": 1e6, "directions": 15}, timeseries=True))
    assert got.lines["leg1"].channels[0] == "sea@30"
    a, b = _stats(got), _stats(ref)
    for key in a:
        np.testing.assert_allclose(a[key], b[key], rtol=1e-10, atol=0)
    for end in ("end_a", "end_b"):
        np.testing.assert_allclose(
            got.timeseries.end_tension_linear["leg1"][end],
            ref.timeseries.end_tension_linear["leg1"][end],
            rtol=1e-10,
        )
        # with the residuals' component: its density is the corrected less the linear
        # one, formed by sums in another order on the two paths (round-off of a
        # difference: 1.4e-10 of the total tension measured), so held to 1e-8 of the
        # dynamic tension's σ
        total = got.timeseries.end_tension["leg1"][end]
        np.testing.assert_allclose(
            total, ref.timeseries.end_tension["leg1"][end], rtol=0, atol=1e-8 * np.std(total)
        )
    np.testing.assert_array_equal(got.timeseries.elevation, ref.timeseries.elevation)


def test_mirrored_spreadings_give_mirrored_responses():
    """The chain lies in the x–z plane and the mean heading is 0: the spreading
    mirrored about it (offsets negated) mirrors the response in y, so the tensions and
    the x, y, z motion σ are the same (round-off: the same sums in another order)."""
    table = {"type": "table", "offset": [-35.0, -5.0, 20.0], "weight": [0.2, 0.5, 0.3]}
    mirror = {**table, "offset": [-x for x in table["offset"]]}
    a = _stats(analyze(_chain(0.0, table)))
    b = _stats(analyze(_chain(0.0, mirror)))
    for key in a:
        np.testing.assert_allclose(a[key], b[key], rtol=1e-9, atol=1e-12 * np.max(a[key]))
    # and the spreading matters: out-of-plane motion that a long-crested head sea lacks
    assert np.max(a["motion"][:, 1]) > 1e-3 * np.max(a["motion"][:, 0])


def test_sea_states_of_one_spreading_reuse_their_inputs():
    spread = {"type": "cosn", "n": 4.0, "directions": 9}
    engine = build_engine(_chain(20.0, spread))
    sea = {
        "spectrum": {"type": "jonswap", "hs": 3.0, "tp": 8.0},
        "heading": 20.0,
        "spreading": spread,
    }
    engine.solve()
    got = _stats(engine.solve(sea))
    ref = _stats(analyze({**_chain(20.0, spread), "sea": sea}))
    for key in got:
        np.testing.assert_allclose(got[key], ref[key], rtol=1e-11)
    assert len(engine.systems["leg1"]._cache["heading_inputs"]) == 1  # one spreading kept


def test_time_series_realize_the_directions_independently():
    """Each direction has its own phases: the elevation variance over the record
    scatters about the spectrum's sum Σ S(ω_m)Δω (its expectation: the directions'
    cross terms at one frequency average out), four seeds within 4 standard errors of
    it.  Directions sharing one realization would give (Σ_k √w_k)² times that (≈ 5.6
    here), far outside.  The linear model: the sea's realization, not the residuals."""
    from stochcable.sea.realization import frequency_grid
    from stochcable.sea.spectra import spectrum_pierson_moskowitz

    spread = {"type": "cos2s", "s": 2.0, "directions": 8}
    doc = _chain(45.0, spread, timeseries=True)
    doc["analysis"].setdefault("linearization", {}).update(LINEAR_ONLY)
    ts = doc["analysis"]["timeseries"]
    ts["duration"] = 400.0
    w, dw = frequency_grid(ts["duration"], ts["dt"])
    m0 = float(np.sum(spectrum_pierson_moskowitz(w[1:-1], 6.0, 10.0)) * dw)  # the sea's
    var = []
    for seed in range(4):
        ts["seed"] = seed
        var.append(float(np.var(analyze(doc).timeseries.elevation)))
    var = np.array(var)
    se = var.std(ddof=1) / math.sqrt(var.size)
    assert abs(var.mean() - m0) <= 4 * se, (var, m0)
    ds = load_scene(doc).sea.direction_set()
    coherent = float(np.sum(np.sqrt(ds.weight)) ** 2)
    assert abs(var.mean() - coherent * m0) > 20 * se, (coherent, var, m0)


@pytest.mark.parametrize(
    ("spreading", "parameter"),
    [
        ({"type": "cos2s", "s": 0.0}, "sea.spreading.s"),
        ({"type": "cosn", "n": -1.0}, "sea.spreading.n"),
        ({"type": "cos2s", "s": 2.0, "directions": 0}, "sea.spreading.directions"),
        ({"type": "cos2s", "s": 2.0, "directions": 65}, "sea.spreading.directions"),
        ({"type": "table", "offset": [0.0, 10.0], "weight": [0.0, 0.0]}, "sea.spreading"),
        ({"type": "table", "offset": [0.0, 0.0], "weight": [1.0, 1.0]}, "sea.spreading"),
    ],
)
def test_bad_spreading_names_the_parameter(spreading, parameter):
    with pytest.raises(InputError) as info:
        load_scene(_chain(0.0, spreading))
    assert info.value.parameter == parameter


def test_load_case_sets_keep_the_scene_spreading():
    """A scatter-diagram set of a spread scene spreads every sea state about its
    heading: each case equals analyze() of the scene with that state's sea (and differs
    from the long-crested one)."""
    from stochcable.cases import run_cases, scatter_from_rows

    def still(doc: dict) -> dict:  # no fairlead motion: the sea's share shows
        doc["lines"][0]["end_b"].pop("motion")
        # the linear model: the set's seas, not its residuals (tests/cases)
        doc["analysis"].setdefault("linearization", {}).update(LINEAR_ONLY)
        return doc

    spread = {"type": "cos2s", "s": 2.0, "directions": 8}
    rows = [{"hs": 3.0, "tp": 9.0, "heading": h, "probability": 0.5} for h in (0.0, 30.0)]
    res = run_cases(load_scene(still(_chain(0.0, spread))), scatter_from_rows(rows))
    for i, h in enumerate((0.0, 30.0)):
        spectrum = res.scatter.states[i].spectrum("jonswap")  # the set's γ (DNV)
        sea = {"spectrum": spectrum.model_dump(mode="json"), "heading": h}
        spread_ref = analyze({**still(_chain(h, spread)), "sea": {**sea, "spreading": spread}})
        long_ref = analyze({**still(_chain(h)), "sea": sea})
        got = res.stats["leg1"]["end_b"][i, 1]
        # 1e-5: the engine of a set starts its fixed point elsewhere than analyze(); both
        # stop within the linearization tolerance (1e-4) of the same fixed point
        assert got == pytest.approx(spread_ref.lines["leg1"].end_b.std, rel=1e-5)
        assert abs(got / long_ref.lines["leg1"].end_b.std - 1.0) > 1e-2
