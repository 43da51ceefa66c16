"""A batch survives its service: a real ``stochcable serve`` killed with SIGKILL in the
middle of a batch, and one stopped gracefully, are started again on the same SQLite file;
the batch resumes from its last stored chunk and completes with every case once — its
results equal the library's, bit for bit."""

from __future__ import annotations

import sqlite3
import time

import httpx
import pytest
from _server import Server

from stochcable.cases import case_document, read_scatter, run_cases
from stochcable.examples import load_example

CHAIN = load_example("chain_catenary").model_dump(mode="json", exclude_unset=True)
N, CHUNK = 96, 4  # enough that the kill (>= 32 done) and the stop (+16) fall mid-batch
ROWS = [{"hs": 1.0 + 0.02 * i, "tp": 8.0 + 0.01 * i, "hours": 1.0} for i in range(N)]
LEASE = 2.0  # s: a killed server's batch is taken over this long after its last report


def _status(server: Server, job_id: str) -> dict:
    return httpx.get(f"{server.url}/v1/batches/{job_id}", timeout=10).json()


def _until(server: Server, job_id: str, done, timeout: float = 180.0) -> dict:
    deadline = time.monotonic() + timeout
    while True:
        doc = _status(server, job_id)
        if done(doc):
            return doc
        assert time.monotonic() < deadline, f"batch at {doc['progress']} after {timeout} s"
        time.sleep(0.1)


@pytest.mark.slow
def test_killed_and_stopped_service_resume_the_batch(tmp_path):
    db = tmp_path / "jobs.sqlite"
    settings = {"jobs_database": db, "batch_workers": 1, "analysis_workers": 1,
                "batch_lease_seconds": LEASE}  # fmt: skip
    first = Server(**settings)
    try:
        resp = httpx.post(f"{first.url}/v1/batches", timeout=30,
                          json={"scene": CHAIN, "scatter": ROWS, "chunk_size": CHUNK})  # fmt: skip
        assert resp.status_code == 202, resp.text
        job_id = resp.json()["id"]
        # the synchronous API keeps answering while the batch runs (the batch workers
        # run below the analyses' CPU priority)
        _until(first, job_id, lambda d: d["status"] == "running")
        analysis = httpx.post(f"{first.url}/v1/analyses?timeseries=none", json=CHAIN, timeout=60)
        assert analysis.status_code == 200 and "leg1" in analysis.json()["lines"]
        at_kill = _until(first, job_id, lambda d: d["progress"]["done"] >= 8 * CHUNK)
    finally:
        first.kill()  # SIGKILL: no lease released, chunks in flight lost
    assert at_kill["status"] == "running" and at_kill["progress"]["done"] < N

    second = Server(**settings)
    try:
        # taken over when the killed server's lease runs out, then stopped gracefully
        resumed = _until(
            second,
            job_id,
            lambda d: d["progress"]["done"] >= at_kill["progress"]["done"] + 4 * CHUNK,
        )
    finally:
        second.stop()  # SIGINT: the lease is released, the restart resumes at once
    assert resumed["progress"]["done"] < N, "the batch must still be unfinished here"

    third = Server(**settings)
    try:
        final = _until(third, job_id, lambda d: d["status"] != "running")
        results = httpx.get(f"{third.url}/v1/batches/{job_id}/results", timeout=60).json()
    finally:
        third.stop()
    assert final["status"] == "done" and final["progress"]["done"] == N
    with sqlite3.connect(db) as conn:  # every chunk stored once
        rows = conn.execute(
            "SELECT COUNT(*), SUM(n_cases) FROM stochcable_batch_chunks WHERE job_id = ?",
            (job_id,),
        ).fetchone()
    assert rows == (N // CHUNK, N)
    # the service's batches compute every case's residuals (a plan's default): so does
    # the library's set here (its default interpolates between the 96 periods' anchors)
    expected = case_document(
        run_cases(CHAIN, read_scatter(ROWS), chunk_size=CHUNK, residual_tolerance=None)
    )
    assert {k: v for k, v in results.items() if k != "id"} == expected
