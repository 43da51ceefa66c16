"""Load-case sets (stochcable.cases.run): the set against one-at-a-time analyses, the
exact scalings and symmetries of the damage sums, the one-state long-term limit, and
the rows of cases that fail."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from _scenes import LINEAR_ONLY

from stochcable.analysis import analyze
from stochcable.cases import LineFatigue, run_cases, scatter_from_rows
from stochcable.cases.results import case_dataset, case_document, case_summary_csv
from stochcable.design import SECONDS_PER_YEAR, damage_rate, fatigue_curve
from stochcable.errors import ConvergenceError, InputError
from stochcable.examples import load_example
from stochcable.scene.model import Sea, load_scene
from stochcable.scene.spectra import Jonswap

CHAIN = LineFatigue("dnv-studless", nominal_diameter=0.084)
WIRE = LineFatigue("dnv-six-strand", nominal_area=1.2e-3, design_factor=3.0)


def _doc(name: str) -> dict:
    return json.loads(json.dumps(load_example(name).model_dump(mode="json")))


def _wire(cd: float = 1.2) -> dict:
    """The taut wire example with the sea as its only input (drag ``cd``)."""
    doc = _doc("taut_wire")
    for seg in doc["lines"][0]["segments"]:
        seg["cd_normal"], seg["cd_axial"] = cd, 0.0 if cd == 0 else seg["cd_axial"]
    return doc


def test_set_equals_one_at_a_time_analyses():
    # engine.solve(sea) is analyze() of the scene with that sea (tests/dynamics/test_engine.py,
    # 1e-12) when both use the same model.  Here the set's headings include 30°, so its
    # engine is 3-D while analyze() of the 0° case is 2-D: both drag fixed points stop
    # within the linearization tolerance tol of their own limit, so σ agrees to a few
    # tol (10·tol allowed) and a damage (∝ σ^m, m = 4) to m times that.
    # The linear model: the 3-D engine carries no drag residual (3-D lines are not
    # covered yet, issue 31), the 2-D analyze() would.
    doc = _wire()
    doc["analysis"]["linearization"].update(LINEAR_ONLY)
    scene = load_scene(doc)
    tol = scene.analysis.linearization.tolerance
    rows = [
        {"hs": 2.0, "tp": 8.0, "gamma": 2.0, "heading": 0, "probability": 0.5},
        {"hs": 4.0, "tp": 10.0, "gamma": 3.3, "heading": 30, "probability": 0.5},
    ]
    res = run_cases(scene, scatter_from_rows(rows), fatigue=WIRE)
    curve = fatigue_curve("dnv-six-strand")
    for i, r in enumerate(rows):
        sea = Sea(spectrum=Jonswap(hs=r["hs"], tp=r["tp"], gamma=r["gamma"]), heading=r["heading"])
        one = analyze(scene.model_copy(update={"sea": sea})).lines["wire"]
        for j, end in enumerate(("end_a", "end_b")):
            st = getattr(one, end)
            got = res.stats["wire"][end][i]
            np.testing.assert_allclose(got, [st.mean, st.std, st.tz, st.mpm_3h], rtol=10 * tol)
            d = damage_rate(one.omega, one.end_tension_spectrum(end) / 1.2e-3**2, curve)
            assert res.damage_rate_ends["wire"][i, j] == pytest.approx(float(d), rel=40 * tol)
        d_el = damage_rate(one.omega, one.tension_spectrum / 1.2e-3**2, curve)
        np.testing.assert_allclose(res.damage_rate_along["wire"][i], d_el, rtol=40 * tol)
    assert [r.status for r in res.rows] == ["ok", "ok"]
    assert res.coverage == {"ok": 1.0, "with_response": 1.0, "failed": 0.0}


def test_in_plane_set_equals_analyses_to_round_off():
    # every heading in the plane: the engine is 2-D like analyze(), the same model.  The
    # first case of a warm-start run starts at rest as analyze() does: the same numbers;
    # the next starts from its predecessor's σ (stochcable.cases.chunk): the same fixed
    # point within the linearization tolerance tol (σ to a few tol, 10·tol allowed)
    scene = load_scene(_wire())
    tol = scene.analysis.linearization.tolerance
    rows = [{"hs": h, "tp": 9.0, "heading": 0, "probability": 0.5} for h in (2.0, 3.5)]
    res = run_cases(scene, scatter_from_rows(rows), fatigue=WIRE)
    for i, r in enumerate(res.scatter.states):
        sea = Sea(spectrum=r.spectrum("jonswap"), heading=0.0)
        one = analyze(scene.model_copy(update={"sea": sea})).lines["wire"]
        rel = 1e-12 if i == 0 else 10 * tol
        assert res.stats["wire"]["end_b"][i, 1] == pytest.approx(one.end_b.std, rel=rel)


def test_engine_refuses_an_out_of_plane_sea_when_built_2d():
    from stochcable.dynamics.engine import build_engine

    engine = build_engine(load_scene(_wire()))
    sea = Sea(spectrum=Jonswap(hs=2.0, tp=8.0), heading=30.0)
    with pytest.raises(InputError, match="out of the plane") as exc:
        engine.solve(sea)
    assert exc.value.parameter == "sea.heading"


def test_annual_damage_life_and_one_state_long_term_limit():
    scene = load_scene(_wire())
    res = run_cases(
        scene,
        scatter_from_rows([{"hs": 3.0, "tp": 9.0, "probability": 1.0}]),
        fatigue=WIRE,
        years=10800.0 / SECONDS_PER_YEAR,  # one sea state of three hours
    )
    t = res.totals["wire"]
    for j, end in enumerate(("end_a", "end_b")):
        d = res.damage_rate_ends["wire"][0, j]
        assert t.annual_damage[end] == pytest.approx(d * SECONDS_PER_YEAR, rel=1e-14)
        assert t.fatigue_life[end] == pytest.approx(1.0 / (3.0 * d * SECONDS_PER_YEAR), rel=1e-14)
        # a one-state diagram over its own duration gives the short-term 3-h MPM exactly
        assert t.return_level[end] == pytest.approx(res.stats["wire"][end][0, 3], rel=1e-10)


def test_damage_scales_as_hs_to_the_slope_for_a_linear_response():
    # Without drag the response is linear in the wave amplitude: the tension spectrum
    # goes as Hs² (same Tp and γ), σ as Hs, and the damage of a single-slope curve as
    # Hs^m for every method (each is homogeneous of degree m in σ).  The linear model:
    # the geometric residual is quadratic in the response (σ² ∝ Hs⁴).
    doc = _wire(cd=0.0)
    doc["analysis"]["linearization"].update(LINEAR_ONLY)
    scene = load_scene(doc)
    rows = [{"hs": h, "tp": 9.0, "gamma": 3.3, "probability": 0.5} for h in (1.0, 2.5)]
    for method, m in (("dirlik", 4.0), ("narrow_band", 4.0)):
        f = LineFatigue("dnv-six-strand", nominal_area=1.2e-3, method=method)
        res = run_cases(scene, scatter_from_rows(rows), fatigue=f)
        d = res.damage_rate_ends["wire"]
        np.testing.assert_allclose(d[1] / d[0], 2.5**m, rtol=1e-9)
        along = res.damage_rate_along["wire"]
        np.testing.assert_allclose(along[1] / along[0], 2.5**m, rtol=1e-9)


def test_heading_symmetry_of_a_symmetric_line():
    # The wire lies in the x–z plane: headings +θ and −θ mirror each other (y → −y),
    # so every tension and damage is equal (to round-off of the mirrored solve)
    scene = load_scene(_wire())
    rows = [{"hs": 3.0, "tp": 9.0, "heading": h, "probability": 0.5} for h in (35.0, -35.0)]
    res = run_cases(scene, scatter_from_rows(rows), fatigue=WIRE)
    d = res.damage_rate_ends["wire"]
    np.testing.assert_allclose(d[0], d[1], rtol=1e-9)
    np.testing.assert_allclose(
        res.damage_rate_along["wire"][0], res.damage_rate_along["wire"][1], rtol=1e-9
    )


class _FailsOn:
    """An engine that raises for one case and solves the others (the set must go on)."""

    def __init__(self, engine, bad_hs):
        self.engine, self.bad_hs = engine, bad_hs
        self.strumming, self.scene = engine.strumming, engine.scene

    def solve(self, sea):
        if sea.spectrum.hs == self.bad_hs:
            raise ConvergenceError("drag linearization diverged (test)")
        return self.engine.solve(sea)


def test_a_failing_case_is_a_row_and_the_set_goes_on():
    from stochcable.dynamics.engine import build_engine

    scene = load_scene(_wire())
    rows = [{"hs": h, "tp": 9.0, "probability": p} for h, p in ((2.0, 0.7), (3.0, 0.3))]
    res = run_cases(
        scene, scatter_from_rows(rows), fatigue=WIRE, engine=_FailsOn(build_engine(scene), 3.0)
    )
    assert [r.status for r in res.rows] == ["ok", "failed"]
    assert "ConvergenceError" in res.rows[1].reason
    assert res.coverage == pytest.approx({"ok": 0.7, "with_response": 0.7, "failed": 0.3})
    assert np.isnan(res.stats["wire"]["end_a"][1]).all()
    # the totals are over the cases with a response: the failed probability is missing
    d0 = res.damage_rate_ends["wire"][0, 0]
    assert res.totals["wire"].annual_damage["end_a"] == pytest.approx(0.7 * d0 * SECONDS_PER_YEAR)
    doc = case_document(res)
    assert (
        doc["cases"][1]["status"] == "failed"
        and doc["cases"][1]["lines"]["wire"]["end_a"]["damage_rate"] is None
    )


def test_unconverged_case_is_reported():
    doc = _wire()
    doc["analysis"]["linearization"] = {"max_iterations": 1, "tolerance": 1e-12}
    rows = [{"hs": 3.0, "tp": 9.0, "probability": 1.0}]
    res = run_cases(load_scene(doc), scatter_from_rows(rows), fatigue=WIRE)
    assert res.rows[0].status == "failed" and "ConvergenceError" in res.rows[0].reason
    doc["analysis"]["linearization"]["allow_unconverged"] = True
    res = run_cases(load_scene(doc), scatter_from_rows(rows), fatigue=WIRE)
    assert res.rows[0].status == "not_converged" and "not converged" in res.rows[0].reason
    assert res.coverage["ok"] == 0.0 and res.coverage["with_response"] == 1.0


def test_dataset_csv_and_json_carry_the_same_numbers(tmp_path):
    scene = load_scene(_wire())
    rows = [{"hs": h, "tp": t, "probability": 0.25} for h in (2.0, 3.0) for t in (8.0, 10.0)]
    res = run_cases(scene, scatter_from_rows(rows, source="t"), fatigue=WIRE, years=50.0)
    ds = case_dataset(res)
    np.testing.assert_array_equal(ds["damage_rate"].sel(line="wire", end="end_b").values,
                                  res.damage_rate_ends["wire"][:, 1])  # fmt: skip
    assert ds["hs"].attrs["units"] == "m" and ds.attrs["return_period_years"] == 50.0
    path = tmp_path / "c.nc"
    ds.to_netcdf(path)
    import xarray as xr

    back = xr.load_dataset(path)
    np.testing.assert_array_equal(back["tension_std"].values, ds["tension_std"].values)
    np.testing.assert_array_equal(back["annual_damage_along_wire"].values,
                                  res.totals["wire"].annual_damage["along"])  # fmt: skip
    lines = case_summary_csv(res).splitlines()
    assert len(lines) == 5 and lines[0].startswith("case,hs,tp")
    assert float(lines[1].split(",")[10]) == res.damage_rate_ends["wire"][0, 0]
    doc = json.loads(json.dumps(case_document(res)))
    assert (
        doc["totals"]["wire"]["return_level"]["end_b"] == res.totals["wire"].return_level["end_b"]
    )


def test_fatigue_setting_errors():
    scene = load_scene(_wire())
    sd = scatter_from_rows([{"hs": 3.0, "tp": 9.0, "probability": 1.0}])
    with pytest.raises(InputError, match="nominal_area") as exc:
        run_cases(scene, sd, fatigue=LineFatigue("dnv-six-strand"))
    assert exc.value.parameter.startswith("fatigue[wire].")
    with pytest.raises(InputError, match="names no line"):
        run_cases(scene, sd, fatigue={"nope": WIRE})
    with pytest.raises(InputError, match=">= 1") as exc:
        run_cases(
            scene, sd, fatigue=LineFatigue("dnv-studless", nominal_diameter=0.08, design_factor=0.5)
        )
    assert exc.value.parameter == "fatigue[wire].design_factor"
    with pytest.raises(InputError, match="must be one of"):
        run_cases(scene, sd, fatigue=LineFatigue("dnv-studless", nominal_diameter=0.08, method="x"))
    with pytest.raises(InputError, match="years"):
        run_cases(scene, sd, years=0.0)
    with pytest.raises(InputError, match="curve"):
        run_cases(scene, sd, fatigue=LineFatigue("no-such-curve"))
    # stress curves need pascals: a foot-slug-second scene takes a tension-ratio curve
    fss = load_example("tuah_1982_single_leg")
    with pytest.raises(InputError, match="foot-slug-second"):
        run_cases(fss, sd, fatigue=LineFatigue("dnv-studless", nominal_diameter=0.08))
    res = run_cases(fss, sd, fatigue=LineFatigue("api-studless", mbs=2.0e5))
    assert math.isfinite(res.totals[fss.lines[0].name].annual_damage["end_b"])


def test_a_template_without_a_sea_takes_every_state_long_crested():
    """A scene with no sea of its own (sea: null) still gives its states their seas,
    in and out of the plane (found by schemathesis: the spreading of a missing sea)."""
    doc = load_example("chain_catenary").model_dump(mode="json", exclude_none=True)
    doc["analysis"].pop("timeseries", None)
    doc["sea"] = None
    # the linear model: the set's 3-D engine carries no drag residual (3-D lines are not
    # covered yet, issue 31), the 2-D analyze() of the 0° state would
    doc["analysis"].setdefault("linearization", {}).update(LINEAR_ONLY)
    rows = [{"hs": 2.0, "tp": 8.0, "heading": h, "probability": 0.5} for h in (0.0, 30.0)]
    res = run_cases(load_scene(doc), scatter_from_rows(rows))
    assert [r.status for r in res.rows] == ["ok", "ok"]
    for i, h in enumerate((0.0, 30.0)):
        sea = {"spectrum": res.scatter.states[i].spectrum("jonswap").model_dump(), "heading": h}
        ref = analyze({**doc, "sea": sea}).lines["leg1"].end_b.std
        # 1e-5: fixed points started elsewhere, both within the tolerance 1e-4
        assert res.stats["leg1"]["end_b"][i, 1] == pytest.approx(ref, rel=1e-5)


def test_warm_starts_meet_the_cold_fixed_point_and_a_bad_one_falls_back():
    # stochcable.dynamics.groups.group_fixed_point.warm_starts: a fixed point started from a
    # neighbouring sea state's σ stops within the tolerance of the one started at rest;
    # a start that is not finite is dropped for the rest start (same bits)
    from stochcable.dynamics.engine import build_engine
    from stochcable.dynamics.groups.group_fixed_point import warm_starts

    scene = load_scene(_wire())
    tol = scene.analysis.linearization.tolerance
    engine = build_engine(scene)
    seas = [Sea(spectrum=Jonswap(hs=hs, tp=9.0, gamma=2.0)) for hs in (2.0, 2.5)]
    cold = [engine.solve(s).lines["wire"] for s in seas]
    store: dict = {}
    with warm_starts(store):
        warm = [engine.solve(s).lines["wire"] for s in seas]
    assert warm[0].end_b.std == cold[0].end_b.std  # nothing stored yet: at rest
    # started elsewhere (on this stiff wire the rest start happens to be the better one:
    # 7 evaluations against 5; on the chain example 4.7 against 7.6 a case)
    assert warm[1].linearization.history[0] != cold[1].linearization.history[0]
    assert warm[1].end_b.std == pytest.approx(cold[1].end_b.std, rel=10 * tol)
    (key,) = store
    with warm_starts({key: np.full_like(store[key][:1], np.nan)}):
        fallback = engine.solve(seas[1]).lines["wire"]
    assert fallback.end_b.std == cold[1].end_b.std


def test_a_warm_start_that_does_not_converge_falls_back_to_rest(monkeypatch):
    from stochcable.dynamics.engine import build_engine
    from stochcable.dynamics.groups import group_fixed_point as fixedpoint

    scene = load_scene(_wire())
    engine = build_engine(scene)
    sea = Sea(spectrum=Jonswap(hs=2.5, tp=9.0, gamma=2.0))
    cold = engine.solve(sea).lines["wire"]
    store: dict = {}
    with fixedpoint.warm_starts(store):
        engine.solve(sea)
    iterate, starts = fixedpoint._iterate, []

    def first_diverges(g, x_start, *args, **kwargs):
        starts.append(x_start)
        if len(starts) == 1:  # the warm attempt
            raise ConvergenceError("drag linearization (test)", 3, 1.0, 1e-4)
        return iterate(g, x_start, *args, **kwargs)

    monkeypatch.setattr(fixedpoint, "_iterate", first_diverges)
    with fixedpoint.warm_starts(store):
        fallback = engine.solve(sea).lines["wire"]
    assert len(starts) == 2 and not np.array_equal(starts[0], starts[1])
    assert fallback.end_b.std == cold.end_b.std


@pytest.mark.parametrize("example", ["chain_catenary", "tuah_1982_disc_buoy_single_leg"])
def test_a_fixed_point_started_at_its_own_answer_costs_one_evaluation(example):
    # warm_starts: the adaptive anchors' later passes start a case from its own
    # converged σ; a warm start runs the full grid alone (no coarse stage, whose coarse
    # fixed point is a defect away), which then converges at its first evaluation.
    # The answer moves by one more step of a contracting map from a point already
    # within the tolerance tol:
    # σ within tol (the chain's 7 evaluations from rest, the leg with its buoy too)
    from stochcable.dynamics.engine import build_engine
    from stochcable.dynamics.groups.group_fixed_point import warm_starts

    doc = _doc(example)
    doc["analysis"]["linearization"].update(LINEAR_ONLY)
    scene = load_scene(doc)
    tol = scene.analysis.linearization.tolerance
    engine = build_engine(scene)
    sea = Sea(spectrum=Jonswap(hs=4.0, tp=10.0, gamma=3.3))
    store: dict = {}
    with warm_starts(store):
        cold = engine.solve(sea)
    own = {key: x[:1] for key, x in store.items()}
    with warm_starts(own):
        again = engine.solve(sea)
    for name, line in again.lines.items():
        assert cold.lines[name].linearization.iterations > 2
        assert line.linearization.iterations == 1
        assert line.linearization.converged
        ref = cold.lines[name].end_b.std
        assert line.end_b.std == pytest.approx(ref, rel=tol)


def test_a_set_skips_the_node_motion_residuals_only():
    """A set reports no node motions: its cases skip their residuals
    (``MOTION_RESIDUALS`` off inside a chunk, restored after), and the corrected end
    tensions, their spectra and the elements' σ are those of the engine's full solve
    to round-off (the shared influence's end and element rows are solved alone)."""
    import warnings

    from stochcable.cases.chunk import _set_solves, case_sea, engine_template, set_engine
    from stochcable.dynamics.outputs.line_result import MOTION_RESIDUALS

    scene = load_scene(_wire())
    sd = scatter_from_rows([{"hs": 2.0, "tp": 9.0, "hours": 1.0}])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        engine = set_engine(engine_template(scene, sd.states, "jonswap"))
        sea = case_sea(scene, sd.states[0], "jonswap")
        full = engine.solve(sea).lines["wire"]
        with _set_solves():
            assert not MOTION_RESIDUALS.get()
            part = engine.solve(sea).lines["wire"]
    assert MOTION_RESIDUALS.get()
    assert full.motion_residual is not None and part.motion_residual is None
    assert full.linear is not None  # (the residuals are on)
    # (to round-off, not bitwise: the compiled banded LU substitutes the right-hand sides
    # of a row in runs whose split depends on how many rows are solved — here the end
    # and element rows alone against those and the node rows; measured 2e-16 relative)
    for e in ("end_a", "end_b"):
        a, b = getattr(part, e), getattr(full, e)
        for name in ("std", "m0", "m1", "m2", "m4", "bandwidth"):
            assert getattr(a, name) == pytest.approx(getattr(b, name), rel=1e-12, abs=0)
        got, ref = part.end_tension_density(e)[1], full.end_tension_density(e)[1]
        # (against the density's peak: its tail lines of 1e-20 differ by 3e-12 of themselves)
        np.testing.assert_allclose(got, ref, rtol=1e-12, atol=1e-14 * ref.max())
    np.testing.assert_allclose(part.tension_std, full.tension_std, rtol=1e-12)
