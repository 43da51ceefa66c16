"""Service limits: body size (413), work size (422 limit_exceeded naming the
STOCHCABLE_* setting), run time (504, never hangs), settings from the environment."""

from __future__ import annotations

import threading
import time

import pytest
from fastapi.testclient import TestClient

from service.app import create_app
from service.dependencies import RunnerDep
from service.errors import LimitExceeded
from service.limits import check_elements
from service.settings import Settings

# one worker runs the module: its module fixtures run once (--dist loadgroup)
pytestmark = pytest.mark.xdist_group("test_service_limits")

PM = {"type": "pierson_moskowitz", "hs": 6.0, "tp": 10.0}


def _err(resp, status):
    assert resp.status_code == status, resp.text
    return resp.json()["detail"][0]


@pytest.fixture(scope="module")
def small() -> TestClient:
    settings = Settings(max_samples=4096, max_frequencies=1000, max_points=4, max_body_bytes=4096)
    with TestClient(create_app(settings)) as c:
        yield c


def test_sample_limit_names_the_bound(small):
    body = {"spectrum": PM, "duration": 8192.0, "dt": 1.0}
    err = _err(small.post("/v1/sea/realizations", json=body), 422)
    assert err["type"] == "limit_exceeded"
    assert err["msg"] == (
        "duration/dt = 8192 samples exceeds the limit of 4096 (STOCHCABLE_MAX_SAMPLES)"
    )
    assert err["setting"] == "STOCHCABLE_MAX_SAMPLES" and err["limit"] == 4096
    assert err["parameter"] == "duration"
    # at the bound it is accepted
    ok = small.post("/v1/sea/realizations", json={**body, "duration": 4096.0})
    assert ok.status_code == 200


def test_sample_limit_counts_kinematics_points(small):
    body = {
        "spectrum": PM,
        "duration": 2048.0,
        "dt": 1.0,
        "points": [[0.0, 0.0, -1.0], [0.0, 0.0, -2.0], [0.0, 0.0, -3.0]],
    }
    err = _err(small.post("/v1/sea/realizations", json=body), 422)
    assert "2048 × 3 = 6144 kinematics samples exceeds the limit of 4096" in err["msg"]
    assert err["parameter"] == "points"


def test_point_limit(small):
    body = {"spectrum": PM, "duration": 16.0, "dt": 1.0, "points": [[0.0, 0.0, -1.0]] * 5}
    err = _err(small.post("/v1/sea/realizations", json=body), 422)
    assert err["msg"] == "5 points exceeds the limit of 4 (STOCHCABLE_MAX_POINTS)"


def test_frequency_limit(small):
    body = {"spectrum": PM, "omega": {"min": 0.1, "max": 2.0, "count": 1001}}
    err = _err(small.post("/v1/spectra", json=body), 422)
    assert err["msg"] == (
        "omega.count = 1001 frequencies exceeds the limit of 1000 (STOCHCABLE_MAX_FREQUENCIES)"
    )
    assert err["loc"] == ["body", "omega", "count"]


def test_element_limit_helper():
    check_elements(10, Settings(max_elements=10))
    with pytest.raises(
        LimitExceeded,
        match=r"11 finite elements exceeds the limit of 10 "
        r"\(STOCHCABLE_MAX_ELEMENTS\)",
    ):
        check_elements(11, Settings(max_elements=10))


def test_body_over_content_length_is_413(small):
    table = {"type": "table", "omega": [0.1 * i for i in range(1, 400)], "density": [1.0] * 399}
    err = _err(small.post("/v1/spectra", json={"spectrum": table}), 413)
    assert err["type"] == "body_too_large"
    assert "exceeds the limit of 4096 bytes (STOCHCABLE_MAX_BODY_BYTES)" in err["msg"]


def test_streamed_body_over_the_limit_is_413(small):
    # no Content-Length (chunked upload): the streamed size is counted
    def chunks():
        yield b'{"spectrum": {"type": "pierson_moskowitz", "hs": 6, "tp": 10}, "g": 9.8'
        for _ in range(100):
            yield b" " * 100
        yield b"}"

    resp = small.post("/v1/spectra", content=chunks(), headers={"Content-Type": "application/json"})
    err = _err(resp, 413)
    assert err["msg"] == (
        "the request body exceeds the limit of 4096 bytes (STOCHCABLE_MAX_BODY_BYTES)"
    )


def _slow_app(**kw):
    app = create_app(Settings(**kw))
    release = threading.Event()

    @app.post("/slow")
    async def slow(runner: RunnerDep) -> dict:
        await runner.run(release.wait, 10.0)
        return {"done": True}

    return app, release


def test_run_time_limit_answers_504_and_never_hangs():
    app, release = _slow_app(max_run_seconds=0.3, max_concurrency=1)
    with TestClient(app) as c:
        t0 = time.perf_counter()
        err = _err(c.post("/slow"), 504)
        elapsed = time.perf_counter() - t0
        assert err["type"] == "run_time_exceeded" and err["setting"] == "STOCHCABLE_MAX_RUN_SECONDS"
        assert "within the limit of 0.3 s" in err["msg"]
        assert elapsed < 3.0  # 0.3 s bound + TestClient overhead, generous for CI
        # the abandoned computation still holds the only slot: the next one times out
        # in the queue, while /health (no computation) answers at once
        assert c.get("/health").status_code == 200
        assert c.post("/v1/spectra", json={"spectrum": PM}).status_code == 504
        release.set()  # the abandoned computation ends and frees its slot
        deadline = time.monotonic() + 5.0
        while time.monotonic() < deadline:
            resp = c.post("/v1/spectra", json={"spectrum": PM})
            if resp.status_code == 200:
                break
            time.sleep(0.05)
        assert resp.status_code == 200


def test_concurrency_limit_queues_instead_of_failing():
    app, release = _slow_app(max_run_seconds=5.0, max_concurrency=1)
    with TestClient(app) as c:
        out = {}
        th = threading.Thread(target=lambda: out.setdefault("r", c.post("/slow")))
        th.start()
        time.sleep(0.2)
        release.set()
        th.join(5.0)
        assert out["r"].json() == {"done": True}
        assert c.post("/v1/spectra", json={"spectrum": PM}).status_code == 200


def test_settings_from_the_environment(monkeypatch):
    monkeypatch.setenv("STOCHCABLE_MAX_SAMPLES", "1024")
    monkeypatch.setenv("STOCHCABLE_MAX_RUN_SECONDS", "2.5")
    s = Settings()
    assert s.max_samples == 1024 and s.max_run_seconds == 2.5
    assert Settings.env_name("max_samples") == "STOCHCABLE_MAX_SAMPLES"
    with TestClient(create_app()) as c:
        err = _err(
            c.post("/v1/sea/realizations", json={"spectrum": PM, "duration": 2048.0, "dt": 1.0}),
            422,
        )
        assert "limit of 1024 (STOCHCABLE_MAX_SAMPLES)" in err["msg"]


def test_default_sample_limit_is_2_to_the_22():
    assert Settings().max_samples == 2**22


def _chain(elements: int, count: int) -> dict:
    from stochcable.examples import load_example

    doc = load_example("chain_catenary").model_dump(mode="json", exclude_unset=True)
    doc["lines"][0]["segments"][0]["elements"] = elements
    doc["analysis"]["omega"]["count"] = count
    return doc


def test_memory_budget_refuses_before_any_work():
    from stochcable import estimate_cost

    doc = _chain(400, 4000)  # ≈ 2.9 GB estimated
    need = estimate_cost(doc).memory_bytes
    with TestClient(create_app(Settings(max_memory_bytes=need - 1))) as c:
        err = _err(c.post("/v1/analyses", json=doc), 422)
    assert err["type"] == "limit_exceeded" and err["setting"] == "STOCHCABLE_MAX_MEMORY_BYTES"
    assert err["limit"] == need - 1 and f"= {need} bytes exceeds the limit" in err["msg"]
    assert err["parameter"] == "analysis.omega.count"
    assert "reduce analysis.omega.count (4000) or the elements of the lines" in err["msg"]


def test_hopeless_run_time_refuses_before_any_work():
    from service.limits import RUN_TIME_MARGIN
    from stochcable import estimate_cost

    doc = _chain(400, 4000)
    seconds = estimate_cost(doc).seconds
    limit = 0.9 * seconds / RUN_TIME_MARGIN
    with TestClient(create_app(Settings(max_run_seconds=limit))) as c:
        err = _err(c.post("/v1/analyses", json=doc), 422)
    assert err["type"] == "limit_exceeded" and err["setting"] == "STOCHCABLE_MAX_RUN_SECONDS"
    assert "estimated run time" in err["msg"] and "reduce analysis.omega.count" in err["msg"]
