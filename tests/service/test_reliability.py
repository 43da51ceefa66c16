"""Reliability of a real ``stochcable serve`` (a subprocess on 127.0.0.1, a free port):
a document too large for the memory budget is refused before any work; a heavy analysis
does not hold up the others; a worker killed with SIGKILL costs only its request; the
run limit ends a long analysis and its memory returns.

Loopback only; every loop is bounded; the server processes are ended by the fixtures.
The bounds on seconds are the service's promises (issue "a service that cannot be
knocked over"), enforced as client timeouts, with room for a shared CI machine.
"""

from __future__ import annotations

import copy
import os
import signal
import threading
import time
from pathlib import Path

import httpx
import psutil
import pytest
from _server import Server

from stochcable.examples import load_example

# reliability: servers killed and restarted, run limits (the slow tier; one worker: its
# module servers start once)
pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("test_reliability")]

ROOT = Path(__file__).resolve().parents[2]
CHAIN = load_example("chain_catenary").model_dump(mode="json", exclude_unset=True)
GB = 1e9


def _chain(elements: int, count: int, timeseries: bool = True) -> dict:
    doc = copy.deepcopy(CHAIN)
    doc["lines"][0]["segments"][0]["elements"] = elements
    doc["analysis"]["omega"]["count"] = count
    if not timeseries:
        doc["analysis"].pop("timeseries", None)
    return doc


HEAVY_INADMISSIBLE = _chain(20000, 100000)  # at STOCHCABLE_MAX_ELEMENTS/_FREQUENCIES
LONG = _chain(600, 6000, timeseries=False)  # ≈ 6 s and ≈ 0.7 GB on the 2-core machine


@pytest.fixture(scope="module")
def two_workers():
    # the heavy analysis (≈ 6 s alone) beside the slow tier's other heavy tests on a
    # shared machine took over the default 60 s run limit (measured: 60.5 s, a 504);
    # what is tested here is that it holds up no other request, not the limit
    server = Server(analysis_workers=2, max_run_seconds=240)
    yield server
    server.stop()


@pytest.fixture(scope="module")
def one_worker():
    server = Server(analysis_workers=1, max_run_seconds=2)
    yield server
    server.stop()


def _detail(resp: httpx.Response) -> dict:
    assert resp.headers["content-type"].startswith("application/json"), resp.text
    return resp.json()["detail"][0]


def test_heavy_document_is_refused_before_any_work(two_workers):
    # 20000 elements × 100000 frequencies: inside the element and frequency limits,
    # terabytes of arrays; refused on the estimate (the client's 2 s timeout is the bound)
    resp = two_workers.post(HEAVY_INADMISSIBLE, timeout=2.0)
    assert resp.status_code == 422
    err = _detail(resp)
    assert err["type"] == "limit_exceeded" and err["setting"] == "STOCHCABLE_MAX_MEMORY_BYTES"
    assert err["parameter"] == "analysis.omega.count"
    assert "estimated peak memory" in err["msg"] and "reduce analysis.omega.count" in err["msg"]
    assert two_workers.process.memory_info().rss < 1 * GB
    assert all(w.memory_info().rss < 1 * GB for w in two_workers.workers())


@pytest.mark.slow
def test_heavy_analysis_does_not_hold_up_the_others(two_workers):
    heavy: dict[str, httpx.Response] = {}
    thread = threading.Thread(
        target=lambda: heavy.setdefault("r", two_workers.post(LONG, timeout=240.0))
    )
    thread.start()
    time.sleep(0.5)  # the heavy analysis has its worker
    results: list[int] = []
    errors: list[BaseException] = []

    def client() -> None:
        try:
            with httpx.Client(base_url=two_workers.url, timeout=5.0) as c:
                for _ in range(5):
                    resp = c.post("/v1/analyses?timeseries=none", json=CHAIN)
                    results.append(resp.status_code)
                    assert c.get("/health").status_code == 200
        except BaseException as exc:  # noqa: BLE001 - reported below
            errors.append(exc)

    clients = [threading.Thread(target=client) for _ in range(4)]
    for t in clients:
        t.start()
    for t in clients:
        t.join(60.0)
    assert not errors, errors
    assert results == [200] * 20
    thread.join(240.0)
    assert heavy["r"].status_code == 200, heavy["r"].text


def test_killed_worker_costs_only_its_request(one_worker):
    (worker,) = one_worker.workers()
    out: dict[str, httpx.Response] = {}
    thread = threading.Thread(target=lambda: out.setdefault("r", one_worker.post(LONG, 30.0)))
    thread.start()
    deadline = time.monotonic() + 1.0  # well inside the 2 s run limit
    while worker.cpu_percent(0.1) < 50.0 and time.monotonic() < deadline:
        pass  # until the worker computes
    os.kill(worker.pid, signal.SIGKILL)
    thread.join(30.0)
    resp = out["r"]
    assert resp.status_code == 503
    err = _detail(resp)
    assert err["type"] == "worker_lost" and "SIGKILL" in err["msg"]
    assert resp.headers["retry-after"]
    for _ in range(3):
        assert one_worker.post(CHAIN, 10.0).status_code == 200
    assert [w.pid for w in one_worker.workers()] != [worker.pid]


def test_run_limit_ends_a_long_analysis_and_its_memory_returns(one_worker):
    assert one_worker.post(CHAIN, 10.0).status_code == 200
    (worker,) = one_worker.workers()
    baseline = worker.memory_info().rss
    resp = one_worker.post(LONG, 30.0)
    assert resp.status_code == 504
    err = _detail(resp)
    assert err["type"] == "run_time_exceeded" and err["setting"] == "STOCHCABLE_MAX_RUN_SECONDS"
    assert not worker.is_running() or worker.status() == psutil.STATUS_ZOMBIE
    assert one_worker.post(CHAIN, 10.0).status_code == 200
    (fresh,) = one_worker.workers()
    # a fresh worker after one chain analysis, as the baseline was measured: the same
    # imports and caches (150 MB margin for allocator and page-cache noise)
    assert fresh.memory_info().rss < baseline + 150e6
