"""Planning a load-case set: chunks fixed before work, a chunk's result as bytes and back
exactly, and the set assembled from its chunks in any order equal to run_cases."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from _scenes import LINEAR_ONLY

from stochcable.cases import LineFatigue, run_cases, scatter_from_rows
from stochcable.cases.chunk import CaseRow, ChunkResult
from stochcable.cases.plan import chunk_from_bytes, chunk_to_bytes, default_chunk_size, plan_cases
from stochcable.cases.run import assemble_cases
from stochcable.errors import InputError
from stochcable.examples import load_example

SCENE = load_example("chain_catenary")
SCATTER = scatter_from_rows(
    [{"hs": h, "tp": t, "probability": 0.2} for h, t in ((1, 7), (2, 8), (3, 9), (4, 10), (5, 11))]
)


def test_chunk_bytes_round_trip_exactly():
    rows = (
        CaseRow(3, "ok", "", (), ("a warning",)),
        CaseRow(7, "failed", "ConvergenceError: ✗ did not converge", ("l:x",), ()),
    )
    rng = np.random.default_rng(1)
    stats = {"l ine/1": {"end_a": rng.normal(size=(2, 4)), "end_b": np.full((2, 4), np.nan)}}
    res = ChunkResult(np.array([3, 7]), rows, stats, {"l ine/1": rng.normal(size=(2, 12))},
                      {"l ine/1": np.linspace(0, 1, 10)})  # fmt: skip
    back = chunk_from_bytes(chunk_to_bytes(res))
    assert back.rows == rows
    np.testing.assert_array_equal(back.indices, res.indices)
    for e in ("end_a", "end_b"):
        np.testing.assert_array_equal(back.stats["l ine/1"][e], stats["l ine/1"][e])
    np.testing.assert_array_equal(back.damage["l ine/1"], res.damage["l ine/1"])
    np.testing.assert_array_equal(back.s_elements["l ine/1"], res.s_elements["l ine/1"])


def test_assembled_from_stored_chunks_in_any_order_equals_run_cases():
    fatigue = LineFatigue("dnv-studless", nominal_diameter=0.076)
    plan = plan_cases(SCENE, SCATTER, fatigue=fatigue, chunk_size=2)
    assert [len(c) for c in plan.chunks] == [2, 2, 1]
    stored = [chunk_to_bytes(plan.solve(k)) for k in range(len(plan.chunks))]
    got = assemble_cases(plan, [chunk_from_bytes(b) for b in reversed(stored)])
    # (a plan computes every case's residuals: run_cases so, not on its adaptive anchors)
    ref = run_cases(SCENE, SCATTER, fatigue=fatigue, residual_tolerance=None)
    np.testing.assert_array_equal(got.stats["leg1"]["end_a"], ref.stats["leg1"]["end_a"])
    np.testing.assert_array_equal(got.damage_rate_along["leg1"], ref.damage_rate_along["leg1"])
    assert got.totals["leg1"].return_level == ref.totals["leg1"].return_level


@pytest.mark.parametrize(
    ("kw", "parameter"),
    [({"years": 0.0}, "years"), ({"years": True}, "years"), ({"chunk_size": 0}, "chunk_size"),
     ({"fatigue": {"nope": LineFatigue()}}, "fatigue")],
)  # fmt: skip
def test_plan_refuses_bad_settings(kw, parameter):
    with pytest.raises(InputError) as err:
        plan_cases(SCENE, SCATTER, **kw)
    assert err.value.parameter == parameter


def test_default_chunk_size():
    assert default_chunk_size(1000, 2) == 64  # capped: progress and small losses
    assert default_chunk_size(200, 2) == 32  # about four chunks per worker (25) ...
    assert default_chunk_size(40, 2) == 16  # ... whole warm-start runs (16 cases)
    assert default_chunk_size(1, 8) == 1


def test_a_set_applies_the_scenes_residuals():
    """With the scene's residuals on, every case's end statistics are analyze()'s
    corrected ones for its sea state and its end damage is that of analyze()'s
    corrected density (σ and Tz within the linearization tolerance 1e-4: the second
    case's fixed point starts from the first's σ, analyze()'s at rest, both within
    it; measured 1.3e-5 on Tz; 3e-4 on the damage, ∝ σ³); the along-line damage stays the linear
    spectrum's, and the corrected σ exceed the linear set's (the chain: 4–7 %)."""
    from stochcable.analysis import analyze
    from stochcable.cases.chunk import case_sea
    from stochcable.cases.fatigue_settings import curve_factor
    from stochcable.design import damage_rate

    doc = SCENE.model_dump(mode="json", exclude_unset=True)
    doc["analysis"].pop("timeseries", None)
    doc["analysis"].setdefault("linearization", {}).update(
        drag_residual=True, geometric_residual=True
    )
    rows = [{"hs": 2, "tp": 8, "probability": 0.5}, {"hs": 3, "tp": 9, "probability": 0.5}]
    small = scatter_from_rows(rows)
    fatigue = LineFatigue("dnv-studless", nominal_diameter=0.076)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        plan = plan_cases(doc, small, fatigue=fatigue)
        asked = run_cases(doc, small, fatigue=fatigue)
    # (two periods of one Hs each: every case computes its residuals, and the set's
    # warning on interpolated corrections stays silent)
    assert not [w for w in caught if "load-case set:" in str(w.message)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        linear = SCENE.model_dump(mode="json", exclude_unset=True)
        linear["analysis"].setdefault("linearization", {}).update(LINEAR_ONLY)
        plain = run_cases(linear, small, fatigue=fatigue)
    lin = plan.template.analysis.linearization
    assert lin.drag_residual and lin.geometric_residual
    curve, factor = curve_factor(fatigue, SCENE.environment.g, "leg1")
    for i, state in enumerate(small.states):
        sea = case_sea(plan.template, state, small.family).model_dump(mode="json")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            one = analyze({**doc, "sea": sea}).lines["leg1"]
        assert one.corrected_spectra is not None
        for k, e in enumerate(("end_a", "end_b")):
            st = getattr(one, e)
            got = asked.stats["leg1"][e][i]
            assert got[1] == pytest.approx(st.std, rel=lin.tolerance)
            assert got[2] == pytest.approx(st.tz, rel=lin.tolerance)
            assert got[1] > 1.02 * plain.stats["leg1"][e][i, 1]
            om, dens = one.end_tension_density(e)
            d = float(damage_rate(om, dens * factor**2, curve, "dirlik"))
            assert asked.damage_rate_ends["leg1"][i, k] == pytest.approx(d, rel=3 * lin.tolerance)
            assert asked.damage_rate_ends["leg1"][i, k] > plain.damage_rate_ends["leg1"][i, k]
