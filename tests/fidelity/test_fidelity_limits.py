"""Adaptive fidelity never fails (issue 16, item 2): the planner respects the limits of
the scene model, says what it cannot bound, and no pydantic ValidationError reaches a
user — the bundled chain example at 5 %, 1 % and 0.3 % through the library, the CLI and
HTTP.

The chain's fairlead surge (DESIGN.md's PM, ω⁻⁵ tail) drives inertia loads whose tension spectrum
decays like ω⁻¹ up to the axial resonances, so the band reaches 90 rad/s at 0.3 %;
there the pilot finds 56 axial/transverse modes whose half-power bandwidth (down to
6e-5 rad/s, seabed damping left out) needs 4.2 million linear frequencies, above the
model's ``analysis.omega.count`` limit: before this change ``analyze()`` died with a raw
ValidationError inside ``apply_fidelity`` and ``POST /v1/analyses`` answered 500.
"""

from __future__ import annotations

import json
import re
from dataclasses import replace

import pytest

from stochcable.analysis import analyze, fidelity_warnings
from stochcable.errors import InputError
from stochcable.examples import load_example
from stochcable.fidelity import apply_fidelity, choose_fidelity
from stochcable.fidelity.limits import (
    elements_limit,
    omega_count_limit,
)
from stochcable.scene.model import OmegaGrid, Segment

# one worker runs the module: its module fixtures run once (--dist loadgroup)
pytestmark = pytest.mark.xdist_group("test_fidelity_limits")


def _chain(target: float | None = None) -> dict:
    """The chain example with DESIGN.md's untapered PM fairlead surge (ω⁻⁵ tail; the
    bundled example band-limits it): the case whose band the limits cut."""
    doc = load_example("chain_catenary").model_dump(mode="json")
    doc["lines"][0]["end_b"]["motion"] = {
        "surge": {"type": "pierson_moskowitz", "hs": 2.0, "tp": 10.0}
    }
    doc["analysis"]["timeseries"] = None
    if target is not None:
        doc["analysis"]["fidelity"] = {"target_error": target}
    return doc


@pytest.fixture(scope="module")
def plan_03():
    """The chain's plan at 0.3 % (the pilots: ≈ 8 s, shared by the tests below)."""
    return choose_fidelity(_chain(), 0.003, evaluate=analyze)


# ---------------------------------------------------------------- the limits


def test_limits_are_read_from_the_scene_model():
    # not copies: the planner follows the model's own constraints
    le = [m.le for m in OmegaGrid.model_fields["count"].metadata if hasattr(m, "le")]
    assert omega_count_limit() == le[0]
    le = [m.le for m in Segment.model_fields["elements"].metadata if hasattr(m, "le")]
    assert elements_limit() == le[0]


@pytest.mark.slow
def test_plan_at_0_3_percent_stays_within_the_limits_and_says_what_it_leaves(plan_03):
    plan = plan_03
    assert plan.omega_count <= omega_count_limit()
    assert all(n <= elements_limit() for v in plan.segments.values() for _, _, n in v)
    # the grid could not resolve every lightly damped mode: said, and estimated
    assert not plan.grid_resolved
    assert plan.error_estimate["grid_unresolved"] > 0
    est = plan.error_estimate
    parts = sum(
        v for k, v in est.items() if k not in ("total", "discretization", "linearization_model")
    )
    assert est["discretization"] == pytest.approx(parts)
    assert est["total"] == pytest.approx(parts + est["linearization_model"])
    (limit,) = plan.limits
    assert "analysis.omega.count" in limit and str(omega_count_limit()) in limit
    grid = next(c for c in plan.choices if c.setting == "analysis.omega.count")
    assert "NOT resolved" in grid.reason
    # what resolving every mode would need (the count follows the modes' damping, e.g.
    # the seabed's): above the limit, said in the reason
    needed = re.search(r"needs (\d+) frequencies", grid.reason)
    assert needed is not None and int(needed.group(1)) > omega_count_limit(), grid.reason
    # the plan is admissible: applying it builds a valid scene
    scene = apply_fidelity(_chain(), plan)
    assert scene.analysis.omega.count == plan.omega_count
    doc = plan.to_document()
    assert doc["grid_resolved"] is False and doc["limits"] == list(plan.limits)
    # the warning names the setting and what is left unresolved (after the one on the
    # linear model's own error, which exceeds 0.3 % on this seabed line)
    model_text, text = fidelity_warnings(plan)
    assert model_text.startswith("adaptive fidelity cannot meet the target error 0.003")
    assert "scene model's limits" in text and "analysis.omega.count" in text
    assert "left unresolved" in text and "analysis.fidelity.target_error" in text


@pytest.mark.slow
def test_an_inadmissible_plan_is_an_input_error_naming_the_request(plan_03):
    bad = replace(plan_03, omega_count=omega_count_limit() + 1)
    with pytest.raises(InputError) as info:
        apply_fidelity(_chain(), bad)
    err = info.value
    assert err.parameter == "analysis.fidelity.target_error" and err.value == 0.003
    assert "analysis.omega.count" in err.constraint and "no admissible plan" in err.constraint


def test_elements_are_clipped_to_the_model_with_a_larger_estimate(monkeypatch):
    import stochcable.fidelity.planner as planner

    scene = load_example("taut_wire")
    free = choose_fidelity(scene, 0.05, evaluate=analyze)
    n_max = max(n for v in free.segments.values() for _, _, n in v)
    monkeypatch.setattr(planner, "elements_limit", lambda: n_max // 2)
    plan = choose_fidelity(scene, 0.05, evaluate=analyze)
    assert max(n for v in plan.segments.values() for _, _, n in v) == n_max // 2
    assert plan.error_estimate["elements"] >= 4 * free.error_estimate["elements"] * 0.99
    (text,) = plan.limits
    assert f"limit of {n_max // 2} elements per segment" in text
    apply_fidelity(scene, plan)  # admissible


@pytest.mark.slow
def test_unbounded_tail_warning_names_the_cause_and_the_fix(plan_03):
    (text, _, _) = fidelity_warnings(replace(plan_03, tail_bounded=False))
    assert "could not bound the response tail" in text
    for part in ("ω⁻⁵", "log ω_max", "band-limit the motion spectrum", "vessel RAO"):
        assert part in text


@pytest.mark.slow
def test_met_targets_have_no_limits_and_unchanged_documents():
    # where the limits are not hit the plan is the one of the rules alone (no new keys)
    plan = choose_fidelity(_chain(), 0.05, evaluate=analyze)
    assert plan.grid_resolved and plan.limits == () and plan.tail_bounded
    assert "grid_unresolved" not in plan.error_estimate
    assert {"limits", "grid_resolved"}.isdisjoint(plan.to_document())
    # nothing to say: with the residuals computed (the default) the model's own error is
    # what they leave (r² + the one-sided bed's 0.45 %, ≈ 0.5 % on this seabed line,
    # stochcable.fidelity.model_error), below 5 %, not the linear model's calibrated 7.7 %
    assert "computed residuals" in plan.model_error_basis
    assert plan.error_estimate["linearization_model"] < 0.05
    assert plan.error_estimate["total"] <= 0.05 and fidelity_warnings(plan) == []


# ------------------------------------------------------------- the entrances
#
# The chain at 5 % and 2 % runs in 5-20 s per entrance (pilots + the planned analysis).
# (Not 1 %: with the residuals on by default the model leaves ≈ 0.5 % of it, the
# discretization's 0.5 % needs the band past the lightly damped axial modes at ≈ 45 rad/s,
# and the grid's limit is hit, the path the tests at 0.3 % and at the limit cover.)
# At 0.3 % the planned analysis (2553 frequencies × 959 elements, direct) takes ≈ 40 s
# on a shared 2-core host: its plan is asserted above (``plan_03``), and the entrances'
# limit paths are exercised at 5 % with the limit lowered (the same code path, cheap)
# and, for the refusal, at 0.3 % with the limit the planner believes raised past the
# model's (what the planner asked before this change: 4.2 million frequencies).

TARGETS = (0.05, 0.02)


def _fidelity_texts(warnings) -> list[str]:
    return [w for w in warnings if w.startswith("adaptive fidelity")]


def _target_met(fidelity: dict, texts: list[str], target: float) -> None:
    """The chain touches the seabed, but with the residuals computed (the default) the
    model's own error is what they leave (r² + the one-sided bed's 0.45 %: ≈ 0.5 %, not
    the linear model's calibrated 7.7 %), below both targets: the estimate meets the
    target with the model error in it, and no fidelity warning is said."""
    est = fidelity["error_estimate"]
    assert 0.0045 <= est["linearization_model"] < target
    assert est["total"] == pytest.approx(est["discretization"] + est["linearization_model"])
    assert est["total"] <= target and texts == []
    assert "computed residuals" in fidelity["model_error_basis"]


@pytest.mark.slow
@pytest.mark.parametrize("target", TARGETS)
def test_library_entrance_meets_the_target(target):
    res = analyze(_chain(target))
    plan = res.fidelity
    assert plan.target_error == target and plan.limits == () and plan.tail_bounded
    _target_met(plan.to_document(), _fidelity_texts(res.warnings), target)


def _cli(tmp_path, doc, capsys) -> tuple[int, str, dict | None]:
    from stochcable.cli import main

    src, out = tmp_path / "scene.json", tmp_path / "out.json"
    src.write_text(json.dumps(doc))
    rc = main(["analyze", str(src), "--timeseries", "none", "-o", str(out)])
    err = capsys.readouterr().err
    assert "Traceback" not in err
    return rc, err, (json.loads(out.read_text()) if rc == 0 else None)


@pytest.mark.slow
@pytest.mark.parametrize("target", TARGETS)
def test_cli_entrance_meets_the_target(target, tmp_path, capsys):
    rc, err, out = _cli(tmp_path, _chain(target), capsys)
    assert rc == 0, err
    assert out["fidelity"]["target_error"] == target
    assert out["fidelity"]["error_estimate"]["discretization"] <= target
    assert "limits" not in out["fidelity"]
    _target_met(out["fidelity"], _fidelity_texts(out["warnings"]), target)


@pytest.fixture(scope="module")
def client():
    from fastapi.testclient import TestClient

    from service.app import create_app
    from service.settings import Settings

    # the run limit is not what this module tests: the 1 % plan's analysis took 60 s of
    # wall time beside the slow tier's other heavy tests on 2 cores (CPU well under it)
    with TestClient(create_app(Settings(max_run_seconds=600.0))) as c:
        yield c


@pytest.mark.slow
@pytest.mark.parametrize("target", TARGETS)
def test_http_entrance_meets_the_target(target, client):
    resp = client.post("/v1/analyses", json=_chain(target))
    assert resp.status_code == 200, resp.text
    doc = resp.json()
    assert doc["fidelity"]["target_error"] == target
    assert doc["fidelity"]["error_estimate"]["discretization"] <= target
    assert "limits" not in doc["fidelity"]
    _target_met(doc["fidelity"], _fidelity_texts(doc["warnings"]), target)


def _patched_client():
    """A service whose analysis workers are forked from this process after the
    planner was patched (forkserver workers would not see the patch), its run limit
    300 s: the refused 0.3 % plan takes its planner 17–21 s of wall time on a quiet
    2-core host (29–33 s CPU), and a CI dry run under other work took it past the
    default 60 s (a 504 where the test asks what the entrance answers, 422)."""
    from fastapi.testclient import TestClient

    from service.app import create_app
    from service.settings import Settings

    settings = Settings(analysis_workers=1, worker_start_method="fork", max_run_seconds=300.0)
    return TestClient(create_app(settings))


@pytest.fixture
def low_limit(monkeypatch):
    """The scene model's frequency limit as the planner reads it, lowered to 200 (the
    5 % plan needs 244 points): the limit path at the cost of a 5 % analysis."""
    import stochcable.fidelity.planner as planner

    monkeypatch.setattr(planner, "omega_count_limit", lambda: 200)


def _check_limit_warning(texts: list[str]) -> None:
    # the CLI prints it on stderr (once per display hook under pytest: at least once)
    text = next(t for t in texts if "scene model's limits" in t)
    assert "analysis.omega.count" in text and "200 frequencies" in text
    assert "estimated σ error" in text and "analysis.fidelity.target_error" in text


@pytest.mark.slow
def test_entrances_at_the_limit_answer_with_the_warning(low_limit, tmp_path, capsys):
    res = analyze(_chain(0.05))
    assert res.fidelity.omega_count == 200 and not res.fidelity.grid_resolved
    _check_limit_warning(_fidelity_texts(res.warnings))
    rc, err, out = _cli(tmp_path, _chain(0.05), capsys)
    assert rc == 0, err
    _check_limit_warning([line.removeprefix("stochcable: warning: ") for line in err.splitlines()])
    assert out["fidelity"]["limits"] and out["fidelity"]["omega"]["count"] == 200
    with _patched_client() as client:
        resp = client.post("/v1/analyses", json=_chain(0.05))
    assert resp.status_code == 200, resp.text
    _check_limit_warning(resp.json()["warnings"])


@pytest.fixture
def no_limit(monkeypatch):
    """The planner reads no frequency limit (as before this change): at 0.3 % it asks
    for 4.2 million frequencies, which the model rejects when the plan is applied."""
    import stochcable.fidelity.planner as planner

    monkeypatch.setattr(planner, "omega_count_limit", lambda: 10**9)


@pytest.mark.slow
def test_entrances_refuse_an_inadmissible_plan(no_limit, tmp_path, capsys):
    with pytest.raises(InputError) as info:
        analyze(_chain(0.003))
    assert info.value.parameter == "analysis.fidelity.target_error"
    rc, err, _ = _cli(tmp_path, _chain(0.003), capsys)
    assert rc == 2
    (line,) = err.strip().splitlines()
    assert line.startswith("stochcable analyze: error: analysis.fidelity.target_error = 0.003")
    assert "analysis.omega.count" in line
    with _patched_client() as client:
        resp = client.post("/v1/analyses", json=_chain(0.003))
    assert resp.status_code == 422, resp.text
    detail = resp.json()["detail"][0]
    assert "analysis.fidelity.target_error" in json.dumps(detail)
    assert "analysis.omega.count" in json.dumps(detail)


@pytest.mark.slow
def test_a_plan_beyond_the_memory_available_is_refused(monkeypatch):
    # a machine with 1 MiB free: the 5 % plan of the chain (≈ 10² MB by the cost
    # model) is refused before any work, naming the target and the estimate
    import stochcable.cost as cost

    monkeypatch.setattr(cost, "available_memory", lambda: 2**20)
    with pytest.raises(InputError, match="memory available now") as info:
        analyze(_chain(0.05))
    assert info.value.parameter == "analysis.fidelity.target_error"
    assert "estimated peak memory" in str(info.value)


def test_base_grid_spacing_gives_its_own_point_count():
    """span/(span/(n − 1)) is n − 1 + round-off for many spans (0.313/(0.313/999) =
    999.0000000000001): the point count of the base grid at the limit is n, not n + 1
    (the planner raised StopIteration at the frequency limit)."""
    from stochcable.fidelity.rules import grid_points

    spans = [0.1 * i + 0.013 for i in range(1, 200)]
    for n in (200, 1000, 4000):
        assert all(grid_points(a, a / (n - 1)) == n for a in spans)
        assert all(grid_points(a, a / (n - 1) * 0.999) > n for a in spans)  # finer: more
