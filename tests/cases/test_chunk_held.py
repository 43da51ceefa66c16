"""The adaptive anchors' later passes compute a case's residuals on its first-pass
drag linearization (stochcable.cases.chunk, LINEARIZATIONS of
stochcable.dynamics.groups.analysis): no second fixed point, the numbers those of a
direct corrected analysis of the same sea."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import stochcable.cases.run as run_mod
import stochcable.dynamics.groups.analysis as analysis_mod
from stochcable import analyze, load_example, load_scene
from stochcable.cases import LineFatigue, run_cases, scatter_from_rows
from stochcable.cases import chunk as chunk_mod
from stochcable.design import damage_rate, fatigue_curve
from stochcable.scene.model import Jonswap, Sea

WIRE = LineFatigue("dnv-six-strand", nominal_area=1.2e-3)
#: The taut wire's hardest column (Tp 10 s): the checks compute cases in later passes.
HS = tuple(float(h) for h in np.round(np.arange(0.5, 3.51, 0.25), 2))


def _wire() -> dict:
    doc = load_example("taut_wire").model_dump(mode="json", exclude_none=True)
    doc["analysis"].pop("timeseries", None)
    doc["analysis"]["linearization"].update(drag_residual=True, geometric_residual=True)
    return doc


def test_a_later_pass_case_is_solved_once_and_equals_its_analysis(monkeypatch):
    # Every case's drag fixed point is solved once (first pass); a case the checks
    # compute later takes its residuals on that linearization.  Its numbers against a
    # direct corrected analyze() of its sea (which starts at rest): both fixed points
    # stop within the linearization tolerance tol of their limit, so σ agrees to a few
    # tol (10·tol allowed) and a damage (∝ σ^m, m = 4, and the corrected spectrum's
    # shape) to 40·tol, as tests/cases/test_cases_run.py's one-at-a-time check.
    doc = _wire()
    rows = [{"hs": h, "tp": 10.0, "gamma": 3.3, "probability": 1 / len(HS)} for h in HS]
    calls = []
    real_fp, real_next = analysis_mod.linearize_coupled, run_mod.next_anchors

    def fixed_point(*a, **k):
        calls.append(1)
        return real_fp(*a, **k)

    later = []

    def spy(*a, **k):
        out = real_next(*a, **k)
        later.extend(int(i) for i in np.flatnonzero(out))
        return out

    monkeypatch.setattr(analysis_mod, "linearize_coupled", fixed_point)
    monkeypatch.setattr(run_mod, "next_anchors", spy)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = run_cases(doc, scatter_from_rows(rows), fatigue=WIRE)
    assert later, "the checks computed no case in a later pass"
    assert len(calls) == len(rows)  # (today's later passes: one more per later case)
    assert not chunk_mod._HELD  # released after the set
    scene = load_scene(doc)
    tol = scene.analysis.linearization.tolerance
    curve = fatigue_curve("dnv-six-strand")
    monkeypatch.setattr(analysis_mod, "linearize_coupled", real_fp)
    for i in (later[0], later[-1]):
        sea = Sea(spectrum=Jonswap(hs=HS[i], tp=10.0, gamma=3.3))
        one = analyze(scene.model_copy(update={"sea": sea})).lines["wire"]
        for j, end in enumerate(("end_a", "end_b")):
            st = getattr(one, end)
            got = res.stats["wire"][end][i]
            np.testing.assert_allclose(got, [st.mean, st.std, st.tz, st.mpm_3h], rtol=10 * tol)
            om, dens = one.end_tension_density(end)
            d = damage_rate(om, dens / 1.2e-3**2, curve)
            assert res.damage_rate_ends["wire"][i, j] == pytest.approx(float(d), rel=40 * tol)
