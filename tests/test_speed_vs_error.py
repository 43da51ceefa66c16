"""Keeps benchmarks/speed_vs_error.py from rotting: its core function, in --quick mode,
on the cheapest example (taut_wire), must produce the documented table structure, finite
errors, and errors that shrink as the setting approaches the converged reference."""

from __future__ import annotations

import copy
import importlib.util
import math
import sys
from pathlib import Path

import numpy as np
import pytest

# an accuracy study against the time domain (seconds of fixtures): the slow tier
pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("test_speed_vs_error")]

SCRIPT = Path(__file__).resolve().parents[1] / "benchmarks" / "speed_vs_error.py"


def _load():
    spec = importlib.util.spec_from_file_location("speed_vs_error", SCRIPT)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod  # dataclasses resolve their module by name
    spec.loader.exec_module(mod)
    return mod


sve = _load()


@pytest.fixture(scope="module")
def study():
    # quick mode, a short 2-seed time-domain reference: about 3 s on the 2-core VM
    return sve.study_scene("taut_wire", quick=True, td=True, td_seeds=2, td_duration=120.0)


def _row(study, label):
    return next(r for r in study.rows if r.setting.label == label)


def test_table_structure(study):
    labels = [r.setting.label for r in study.rows]
    assert labels.count("default") == 1
    assert len(set(labels)) == len(labels)
    groups = {r.setting.group for r in study.rows}
    assert {"default", "elements", "grid", "tolerance", "combined"} <= groups
    for r in study.rows:
        assert r.failure is None, r.failure
        assert r.time_s > 0 and r.repeats >= 1
        assert set(r.values) == set(r.err_ref) == set(r.err_td) == set(sve.QUANTITIES)
        assert all(math.isfinite(v) and v > 0 for v in r.values.values())
        assert all(math.isfinite(e) for e in r.err_ref.values())
        assert all(math.isfinite(e) for e in r.err_td.values())


def test_reference_converged(study):
    ref = study.reference
    # the taut wire converges monotonically at second order (linear elements), so the
    # ladder is Richardson-extrapolated and the estimate is tight (measured 6e-4 at most)
    for q in sve.QUANTITIES:
        assert ref.method[q].startswith("Richardson"), ref.method[q]
        assert 0.0 < ref.uncertainty[q] < 2e-3
    ladder = [st for st in ref.steps if st.used]
    assert [st.elements for st in ladder] == [20, 40, 80]


def test_errors_decrease_towards_reference(study):
    # mesh refinement at fixed grid: monotone for this scene (see test_reference_converged),
    # checked on every other level: an intermediate mesh can land on the reference by
    # chance (the default's motion error is 1e-4 while ×2's is 7e-4: a sign change of
    # an error that shrinks as O(h²) overall)
    for q in ("T_anchor", "motion"):
        errs = [
            abs(_row(study, lab).err_ref[q])
            for lab in ("elements ×0.25", "elements ×0.5", "elements ×2")
        ]
        assert all(a > b for a, b in zip(errs, errs[1:])), (q, errs)
    # a finer grid on the wide band: 50 -> 400 frequencies
    assert abs(_row(study, "50 ω to 2·ω_max").err_ref["T_fairlead"]) > abs(
        _row(study, "400 ω to 2·ω_max").err_ref["T_fairlead"]
    )
    # the combination closest to the reference beats the default on every quantity
    best = _row(study, "×2 el, 400 ω to 2·ω_max")
    default = _row(study, "default")
    for q in sve.QUANTITIES:
        assert abs(best.err_ref[q]) < abs(default.err_ref[q])


def test_time_domain_reference(study):
    td = study.td
    assert td.seeds == 2 and not td.failures
    for q in sve.QUANTITIES:
        assert len(td.per_seed[q]) == 2
        assert td.mean[q] > 0 and math.isfinite(td.halfwidth[q])
        # FD and nonlinear TD agree within a factor 2 for this nearly linear scene
        # (2 short records: the CI is wide, so only a coarse bound is safe)
        assert 0.5 < td.fd_same_mesh[q] / td.mean[q] < 2.0


def test_pareto_front():
    t = [1.0, 2.0, 3.0, 0.5, 4.0, np.nan]
    e = [0.1, 0.2, 0.01, 0.5, 0.001, 1e-9]
    # (0.5, 0.5) -> (1, 0.1) -> (3, 0.01) -> (4, 0.001); (2, 0.2) dominated, NaN ignored
    assert sve.pareto_front(t, e) == [3, 0, 2, 4]


def test_report(study, tmp_path):
    st = sve.Study((study,), True, 1.0, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    paths = sve.write_report(st, tmp_path / "ACCURACY.md")
    text = paths[0].read_text(encoding="utf-8")
    assert "## taut_wire" in text and "### Converged reference" in text
    assert "accuracy/taut_wire.png" in text
    assert text.count("| **default** |") == 1
    png = tmp_path / "accuracy" / "taut_wire.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_scene_document_does_not_mutate():
    base = sve.base_document("taut_wire")
    before = repr(base)
    doc = sve.scene_document(
        base,
        sve.Setting(
            "x",
            "elements",
            elements=0.25,
            modes="all",
            count=50,
            omega_max_factor=2.0,
            tolerance=1e-6,
            solver="direct",
        ),
    )
    assert repr(base) == before
    assert doc["lines"][0]["segments"][0]["elements"] == 5
    assert doc["analysis"]["omega"]["count"] == 50
    assert doc["analysis"]["omega"]["max"] == 2 * base["analysis"]["omega"]["max"]


def test_reference_ladder_puts_a_node_at_the_touchdown():
    # tuah_1982_single_leg lies on the seabed from the anchor to s = 165.7 ft (closed-form
    # catenary): the ladder meshes are split there so that the element ladder converges
    # (uniform meshes oscillate at first order, see stochcable.fidelity.planner)
    from stochcable.fidelity import static_touchdowns
    from stochcable.scene.model import load_scene

    base = sve.base_document("tuah_1982_single_leg")
    before = copy.deepcopy(base)
    s_td = static_touchdowns(load_scene(base))["leg"]
    doc = sve.split_at_touchdown(
        sve.scene_document(base, sve.Setting("x", "reference", elements=4.0)), s_td
    )
    assert base == before  # not mutated
    segs = doc["lines"][0]["segments"]
    assert [s["length"] for s in segs] == pytest.approx([s_td, 339.0 - s_td], rel=1e-12)
    assert sum(s["elements"] for s in segs) == 12 and min(s["elements"] for s in segs) >= 1
    st = load_scene(doc)  # a valid scene
    assert st.lines[0].length == pytest.approx(339.0)
    # no touchdown: unchanged
    assert sve.split_at_touchdown(base, None) is base
