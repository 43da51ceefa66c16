"""/v1/batches in one process (FastAPI's TestClient with the app's lifespan: a real SQLite
file, real batch worker processes): submission and validation, status and progress,
results equal to :func:`stochcable.cases.run_cases` bit for bit in JSON, CSV and NetCDF,
cancellation, limits, API keys, and the Python client."""

from __future__ import annotations

import copy
import time
import warnings
from datetime import datetime

import numpy as np
import pytest
import xarray as xr
from _scenes import LINEAR_ONLY
from fastapi.testclient import TestClient

from service.app import create_app
from service.batches import BatchService
from service.settings import Settings
from stochcable.cases import LineFatigue, case_document, case_summary_csv, read_scatter, run_cases
from stochcable.client import Client, ClientError
from stochcable.errors import PhysicsWarning
from stochcable.examples import load_example

# one worker runs the module: its module fixtures run once (--dist loadgroup)
pytestmark = pytest.mark.xdist_group("test_batches")

CHAIN = load_example("chain_catenary").model_dump(mode="json", exclude_unset=True)
# the service's batches, not the residuals (tests/cases): the linear model, ~5× cheaper
# a case, and a set without the residuals' planning warning
CHAIN["analysis"].setdefault("linearization", {}).update(LINEAR_ONLY)
ROWS = [
    {"hs": hs, "tp": tp, "probability": p}
    for hs, tp, p in ((1.0, 7.0, 0.3), (2.0, 9.0, 0.4), (4.0, 11.0, 0.2), (6.0, 13.0, 0.1))
]
FATIGUE = {"curve": "dnv-studless", "nominal_diameter": 0.076}
REQUEST = {"scene": CHAIN, "scatter": ROWS, "headings": [0, 30], "fatigue": FATIGUE}


def _settings(tmp_path, **kw) -> Settings:
    base = {"jobs_database": str(tmp_path / "jobs.sqlite"), "batch_workers": 2,
            "analysis_workers": 1}  # fmt: skip
    return Settings(**{**base, **kw})


def _wait(client, job_id: str, timeout: float = 120.0, headers=None) -> dict:
    deadline = time.monotonic() + timeout
    while True:
        doc = client.get(f"/v1/batches/{job_id}", headers=headers).json()
        if doc["status"] not in ("queued", "running"):
            return doc
        assert time.monotonic() < deadline, f"batch still {doc['status']} after {timeout} s"
        time.sleep(0.1)


@pytest.fixture(scope="module")
def service(tmp_path_factory):
    app = create_app(_settings(tmp_path_factory.mktemp("batches")))
    with TestClient(app) as client:
        yield client


@pytest.fixture(scope="module")
def reference():
    """The same set run by the library in this process, in the service's chunking."""
    scatter = read_scatter(ROWS).with_headings([0, 30])
    return run_cases(
        CHAIN, scatter, fatigue=LineFatigue("dnv-studless", nominal_diameter=0.076), chunk_size=1
    )


@pytest.fixture(scope="module")
def finished(service):
    resp = service.post("/v1/batches", json={**REQUEST, "chunk_size": 1})
    assert resp.status_code == 202, resp.text
    assert resp.headers["location"] == f"/v1/batches/{resp.json()['id']}"
    return _wait(service, resp.json()["id"])


def test_a_batch_runs_to_done_with_progress(finished):
    assert finished["status"] == "done", finished
    p = finished["progress"]
    assert (p["total"], p["done"], p["failed"], p["fraction"]) == (8, 8, 0, 1.0), finished
    # as times, not as ISO texts (a time on the second has no fraction: ':05+00:00' <
    # ':05.1+00:00' as text but not as time)
    times = [datetime.fromisoformat(finished[k]) for k in ("created", "started", "finished")]
    assert times == sorted(times), finished


def test_a_cancel_after_the_last_chunk_keeps_the_batch(service, finished, tmp_path):
    # the page's Cancel of a batch it last saw running asks cancel_only: a batch that
    # has finished since is left as it is (200 with its status), never deleted
    url = f"/v1/batches/{finished['id']}"
    late = service.delete(url + "?cancel_only=true")
    assert late.status_code == 200 and late.json()["status"] == "done"
    assert late.json()["progress"] == finished["progress"]
    assert service.get(url + "/results").status_code == 200
    # a cancel of a job seen running whose last chunk was stored (and the job marked
    # done) before the cancel reached the store: done, kept (it was deleted)
    batches = BatchService(_settings(tmp_path))
    job = batches.store.create("", {"warnings": []}, 1, 1, 1, 10)
    running = batches.store.claim("runner", 30.0)
    assert running is not None and running.id == job.id and running.status == "running"
    assert batches.store.finish(job.id, "runner", "done")
    after = batches.cancel(running)
    assert after is not None and after.status == "done"
    assert batches.store.get(job.id).status == "done"
    # a queued one is cancelled; a finished one deleted when asked (the Delete button)
    queued = batches.store.create("", {"warnings": []}, 1, 1, 1, 10)
    assert batches.cancel(queued).status == "cancelled"
    assert batches.cancel(batches.store.get(queued.id)) is None
    assert batches.store.get(queued.id) is None
    batches.close()


def test_results_equal_the_library_bit_for_bit(service, finished, reference, tmp_path):
    url = f"/v1/batches/{finished['id']}/results"
    doc = service.get(url).json()
    # the JSON floats round-trip exactly: the same numbers as run_cases in this process
    assert {k: v for k, v in doc.items() if k != "id"} == case_document(reference)
    csv = service.get(url, headers={"Accept": "text/csv"})
    assert csv.headers["content-type"].startswith("text/csv")
    assert csv.text == case_summary_csv(reference)
    nc = service.get(url, headers={"Accept": "application/x-netcdf"})
    assert nc.headers["content-type"] == "application/x-netcdf"
    path = tmp_path / "results.nc"
    path.write_bytes(nc.content)
    ds = xr.load_dataset(path)
    np.testing.assert_array_equal(ds["hs"].values, [s.hs for s in reference.scatter.states])
    np.testing.assert_array_equal(
        ds["tension_std"].sel(line="leg1", end="end_a").values,
        reference.stats["leg1"]["end_a"][:, 1],
    )


@pytest.mark.slow
def test_results_before_done_answer_409(tmp_path):
    app = create_app(_settings(tmp_path, batch_workers=1))
    with TestClient(app) as client:
        rows = [{"hs": 1.0 + 0.01 * i, "tp": 9.0, "hours": 1.0} for i in range(400)]
        job = client.post("/v1/batches", json={"scene": CHAIN, "scatter": rows,
                                              "chunk_size": 2}).json()  # fmt: skip
        resp = client.get(f"/v1/batches/{job['id']}/results")
        assert resp.status_code == 409
        assert resp.json()["detail"][0]["type"] == "conflict"
        assert "results are available when it is done" in resp.json()["detail"][0]["msg"]
        # cancel stops the work: after it, at most the chunks in flight (two per
        # worker) finish, and the batch never completes
        deadline = time.monotonic() + 60
        while client.get(f"/v1/batches/{job['id']}").json()["progress"]["done"] < 4:
            assert time.monotonic() < deadline
            time.sleep(0.05)
        cancelled = client.delete(f"/v1/batches/{job['id']}")
        assert cancelled.status_code == 200 and cancelled.json()["status"] == "cancelled"
        at_cancel = cancelled.json()["progress"]["done"]
        time.sleep(1.5)
        later = client.get(f"/v1/batches/{job['id']}").json()
        assert later["status"] == "cancelled"
        assert later["progress"]["done"] <= at_cancel + 2 * 2  # two 2-case chunks in flight
        # a finished batch is deleted with its results
        assert client.delete(f"/v1/batches/{job['id']}").status_code == 204
        assert client.get(f"/v1/batches/{job['id']}").status_code == 404


@pytest.mark.parametrize(
    ("change", "loc", "text"),
    [
        ({"scatter": [{"hs": -1.0, "tp": 9.0, "probability": 1.0}]},
         ["body", "scatter", "rows", 0, "hs"], "greater than 0"),
        ({"scatter": [{"hs": 1.0, "tp": 9.0, "probability": 0.5}]},
         ["body", "scatter", "probability"], "must sum to 1"),
        ({"scatter": {"rows": [{"hs": 1.0, "probability": 1.0}]}},
         ["body", "scatter", 0, "tp"], "give exactly one of tp and tz"),
        ({"fatigue": {"curve": "no-such-curve"}},
         ["body", "fatigue", "leg1", "curve"], "no-such-curve"),
        ({"fatigue": {"leg9": FATIGUE}}, ["body", "fatigue", "leg9"], "names no line"),
        ({"headings": []}, ["body", "headings"], "at least 1"),
        ({"years": 0}, ["body", "years"], "greater than 0"),
    ],
)  # fmt: skip
def test_bad_requests_name_the_field(service, change, loc, text):
    resp = service.post("/v1/batches", json={**REQUEST, **change})
    assert resp.status_code == 422, resp.text
    err = resp.json()["detail"][0]
    assert err["loc"] == loc and text in err["msg"], err


def test_scene_limits_apply_to_the_batch_scene(service):
    scene = copy.deepcopy(CHAIN)
    scene["lines"][0]["segments"][0]["elements"] = 30000
    resp = service.post("/v1/batches", json={**REQUEST, "scene": scene})
    err = resp.json()["detail"][0]
    assert resp.status_code == 422 and err["setting"] == "STOCHCABLE_MAX_ELEMENTS"
    assert err["parameter"] == "scene.lines"


@pytest.mark.parametrize(
    ("setting", "value", "env"),
    [
        ("max_batch_cases", 7, "STOCHCABLE_MAX_BATCH_CASES"),
        ("max_result_bytes", 1024, "STOCHCABLE_MAX_RESULT_BYTES"),
    ],
)
def test_batch_limits_answer_422_naming_the_setting(tmp_path, setting, value, env):
    with TestClient(create_app(_settings(tmp_path, **{setting: value}))) as client:
        resp = client.post("/v1/batches", json=REQUEST)  # 8 cases
        assert resp.status_code == 422
        err = resp.json()["detail"][0]
        assert err["type"] == "limit_exceeded" and err["setting"] == env, err


def test_queued_batches_limit(tmp_path):
    with TestClient(create_app(_settings(tmp_path, max_queued_batches=1, batch_workers=1))) as c:
        rows = [{"hs": 1.0 + 0.01 * i, "tp": 9.0, "hours": 1.0} for i in range(200)]
        first = c.post("/v1/batches", json={"scene": CHAIN, "scatter": rows, "chunk_size": 4})
        second = c.post("/v1/batches", json=REQUEST)
        assert second.status_code == 422
        assert second.json()["detail"][0]["setting"] == "STOCHCABLE_MAX_QUEUED_BATCHES"
        c.delete(f"/v1/batches/{first.json()['id']}")
        assert c.post("/v1/batches", json=REQUEST).status_code == 202


def test_failing_cases_are_rows_not_a_lost_batch(service):
    # one drag-linearization iteration cannot meet a 1e-9 tolerance: every case fails
    # numerically with its reason, and the batch is still done with its result table
    scene = copy.deepcopy(CHAIN)
    scene["analysis"]["linearization"] = {"max_iterations": 1, "tolerance": 1e-9}
    job = service.post("/v1/batches", json={"scene": scene, "scatter": ROWS}).json()
    doc = _wait(service, job["id"])
    assert doc["status"] == "done" and doc["progress"]["done"] == doc["progress"]["failed"] == 4
    assert [p["index"] for p in doc["problems"]] == [0, 1, 2, 3]
    assert all("did not converge" in p["reason"] for p in doc["problems"])
    res = service.get(f"/v1/batches/{job['id']}/results").json()
    assert res["coverage"]["failed"] == pytest.approx(1.0, rel=1e-12)  # a sum of 4 floats
    assert [c["status"] for c in res["cases"]] == ["failed"] * 4


def test_planning_warnings_are_in_the_status(service, finished):
    # the planning warnings are said in the 202 and in every later status (stored with
    # the job); a batch computes every case's residuals, so the set's warning on
    # interpolated corrections (stochcable.cases.run) is not among them
    scene = copy.deepcopy(CHAIN)
    scene["analysis"]["linearization"] = {"drag_residual": True, "geometric_residual": False}
    one = [{**ROWS[0], "probability": 1.0}]
    resp = service.post("/v1/batches", json={"scene": scene, "scatter": one})
    assert resp.status_code == 202, resp.text
    assert resp.json()["warnings"] == []
    assert _wait(service, resp.json()["id"])["warnings"] == []
    assert finished["warnings"] == []
    client = Client("http://testserver")
    client._http = service  # the Python client issues them as the library does
    with warnings.catch_warnings():
        warnings.simplefilter("error", PhysicsWarning)
        job = client.submit_batch(scene, one)
    assert job.warnings == []
    client.wait(job, timeout=120)


def test_api_keys(tmp_path):
    with TestClient(create_app(_settings(tmp_path, api_keys="alpha,beta"))) as client:
        assert client.get("/health").status_code == 200  # liveness never needs a key
        none = client.post("/v1/batches", json=REQUEST)
        assert none.status_code == 401 and none.headers["www-authenticate"] == "Bearer"
        assert none.json()["detail"][0]["type"] == "unauthorized"
        wrong = client.get("/v1/examples", headers={"Authorization": "Bearer gamma"})
        assert wrong.status_code == 401 and "unknown API key" in wrong.json()["detail"][0]["msg"]
        alpha = {"Authorization": "Bearer alpha"}
        beta = {"Authorization": "Bearer beta"}
        job = client.post("/v1/batches", json=REQUEST, headers=alpha).json()
        assert client.get(f"/v1/batches/{job['id']}", headers=alpha).status_code == 200
        # another key does not see it, cannot cancel it or read its results
        assert client.get(f"/v1/batches/{job['id']}", headers=beta).status_code == 404
        assert client.delete(f"/v1/batches/{job['id']}", headers=beta).status_code == 404
        assert client.get("/v1/batches", headers=beta).json()["batches"] == []
        listed = client.get("/v1/batches", headers=alpha).json()["batches"]
        assert [b["id"] for b in listed] == [job["id"]]
        _wait(client, job["id"], headers=alpha)


def test_non_loopback_without_keys_refuses_to_start(tmp_path):
    with pytest.raises(ValueError, match="STOCHCABLE_API_KEYS.*--insecure"):
        create_app(_settings(tmp_path, host="0.0.0.0"))
    create_app(_settings(tmp_path, host="0.0.0.0", insecure=True))
    create_app(_settings(tmp_path, host="0.0.0.0", api_keys="k"))


def test_python_client_submit_wait_results(service, reference):
    client = Client("http://testserver")
    client._http = service  # the TestClient is an httpx.Client on the app
    scatter = read_scatter(ROWS)
    job = client.submit_batch(
        CHAIN, scatter, headings=[0, 30],
        fatigue=LineFatigue("dnv-studless", nominal_diameter=0.076), chunk_size=3,
    )  # fmt: skip
    assert job.status in ("queued", "running", "done")
    done = client.wait(job, timeout=120)
    assert done.status == "done" and done.progress["done"] == 8
    ds = client.results(done)  # chunked by 3 here, by 1 in the reference: the same bits
    np.testing.assert_array_equal(
        ds["tension_std"].sel(line="leg1", end="end_b").values,
        reference.stats["leg1"]["end_b"][:, 1],
    )
    assert client.results(done, "json")["totals"] == case_document(reference)["totals"]
    late = client.cancel(done, keep_finished=True)  # a cancel that came too late
    assert late is not None and late.status == "done" and client.results(done, "json")
    assert client.cancel(done) is None  # a plain DELETE removes a finished batch
    with pytest.raises(ClientError):
        client.batch(done)
    with pytest.raises(ClientError, match="scatter.probability"):
        client.submit_batch(CHAIN, [{"hs": 1.0, "tp": 9.0, "probability": 0.5}])


@pytest.mark.slow
def test_batches_on_a_dask_scheduler(tmp_path, reference):
    distributed = pytest.importorskip("distributed")
    with (
        distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                 dashboard_address=None) as cluster,
        TestClient(create_app(_settings(tmp_path, dask_scheduler=cluster.scheduler_address))) as c,
    ):  # fmt: skip
        docs = []
        # two batches of the same scene, one after the other: the second's copy of the
        # scene on the workers must survive the release of the first's
        for _ in range(2):
            job = c.post("/v1/batches", json={**REQUEST, "chunk_size": 2}).json()
            assert _wait(c, job["id"])["status"] == "done"
            docs.append(c.get(f"/v1/batches/{job['id']}/results").json())
    for doc in docs:
        assert {k: v for k, v in doc.items() if k != "id"} == case_document(reference)


def test_a_huge_matrix_is_refused_before_it_is_expanded(tmp_path):
    # 400 × 400 non-zero cells at 300 headings = 48 million sea states: refused on the
    # count, before any is made (the client's timeout is the bound)
    matrix = {
        "hs": [1.0 + 0.01 * i for i in range(400)],
        "tz": [4.0 + 0.01 * j for j in range(400)],
        "occurrence": [[1.0] * 400] * 400,
        "headings": {str(h): 1.0 for h in range(300)},
    }
    with TestClient(create_app(_settings(tmp_path))) as client:
        resp = client.post("/v1/batches", json={"scene": CHAIN, "scatter": matrix})
    assert resp.status_code == 422
    assert resp.json()["detail"][0]["setting"] == "STOCHCABLE_MAX_BATCH_CASES"
    assert "48000000 cases" in resp.json()["detail"][0]["msg"]


@pytest.mark.slow
def test_a_killed_batch_worker_costs_only_its_chunks(tmp_path):
    import os
    import signal

    with TestClient(create_app(_settings(tmp_path))) as client:
        batches = client.app.state.batches
        rows = [{"hs": 1.0 + 0.01 * i, "tp": 9.0, "hours": 1.0} for i in range(60)]
        job = client.post("/v1/batches", json={"scene": CHAIN, "scatter": rows,
                                              "chunk_size": 2}).json()  # fmt: skip
        deadline = time.monotonic() + 60
        while client.get(f"/v1/batches/{job['id']}").json()["progress"]["done"] < 6:
            assert time.monotonic() < deadline
            time.sleep(0.02)
        victim = next(iter(batches._executor._processes))  # a worker process's pid
        os.kill(victim, signal.SIGKILL)
        doc = _wait(client, job["id"])
        assert doc["status"] == "done" and doc["progress"]["done"] == 60, doc
        got = client.get(f"/v1/batches/{job['id']}/results").json()
    expected = case_document(run_cases(CHAIN, read_scatter(rows), chunk_size=2))
    assert {k: v for k, v in got.items() if k != "id"} == expected


def test_an_unusable_job_store_answers_503_and_analyses_go_on(tmp_path):
    blocker = tmp_path / "a-file"
    blocker.write_text("not a folder")
    settings = _settings(tmp_path, jobs_database=str(blocker / "jobs.sqlite"))
    with TestClient(create_app(settings)) as client:
        resp = client.post("/v1/batches", json=REQUEST)
        assert resp.status_code == 503 and resp.headers["retry-after"] == "5"
        err = resp.json()["detail"][0]
        assert err["type"] == "store_unavailable"
        assert err["setting"] == "STOCHCABLE_JOBS_DATABASE" and "a-file" in err["msg"]
        assert client.get("/health").status_code == 200
        ok = client.post("/v1/analyses?timeseries=none", json=CHAIN)
        assert ok.status_code == 200
