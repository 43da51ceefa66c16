"""The analysis worker pool (service.workers) on its own: a job's answer comes back, a
failure comes back as its error answer, the run limit kills and replaces the worker, a
killed worker costs only its request, a full queue answers at once, and a MemoryError
under the worker's address-space limit is a 422 naming STOCHCABLE_MAX_MEMORY_BYTES.

The jobs are functions of this module: the workers import it by name (pickled by
reference), as they import service.jobs in the server.
"""

from __future__ import annotations

import asyncio
import os
import signal
import time

import numpy as np
import pytest

from service.errors import JobFailed, QueueFull, RunTimeExceeded, WorkerLost
from service.workers import WorkerPool
from stochcable.errors import InputError

MB = 2**20


def _add(a: int, b: int) -> int:
    return a + b


def _pid() -> int:
    return os.getpid()


def _sleep(seconds: float) -> float:
    time.sleep(seconds)
    return seconds


def _die() -> None:
    os.kill(os.getpid(), signal.SIGKILL)


def _bad_input() -> None:
    raise InputError("sea.spectrum.hs", -1.0, "m", "must be > 0")


def _allocate(n_bytes: int) -> int:
    return int(np.ones(n_bytes // 8).sum())


def _pool(size: int = 1, max_queue: int = 4, budget: int = 4096 * MB) -> WorkerPool:
    return WorkerPool(size, max_queue, budget, recycle_bytes=4096 * MB)


def _run(pool: WorkerPool, func, *args, seconds: float = 30.0):
    async def go():
        return await pool.run(func, *args, deadline=time.monotonic() + seconds, limit=seconds)

    return asyncio.run(go())


@pytest.fixture
def pool():
    p = _pool()
    yield p
    p.close()


def test_answer_and_error_answer_come_back(pool):
    assert _run(pool, _add, 2, 3) == 5
    with pytest.raises(JobFailed) as info:
        _run(pool, _bad_input)
    assert info.value.status == 422
    assert info.value.item["type"] == "input_error"
    assert info.value.item["parameter"] == "sea.spectrum.hs"
    assert info.value.item["loc"] == ["body", "sea", "spectrum", "hs"]
    assert _run(pool, _add, 1, 1) == 2  # the worker stays


def test_run_limit_kills_and_replaces_the_worker(pool):
    before = _run(pool, _pid)
    t0 = time.monotonic()
    with pytest.raises(RunTimeExceeded):
        _run(pool, _sleep, 60.0, seconds=0.5)
    assert time.monotonic() - t0 < 30.0  # ended by the kill, not by the 60 s sleep
    with pytest.raises(ProcessLookupError):
        os.kill(before, 0)  # the old worker is gone
    after = _run(pool, _pid)
    assert after != before and pool.replaced == 1


def test_a_killed_worker_costs_only_its_request():
    pool = _pool(size=2)
    try:

        async def go():
            deadline = time.monotonic() + 30.0
            return await asyncio.gather(
                pool.run(_die, deadline=deadline, limit=30.0),
                pool.run(_sleep, 0.3, deadline=deadline, limit=30.0),
                return_exceptions=True,
            )

        died, slept = asyncio.run(go())
        assert isinstance(died, WorkerLost) and died.exitcode == -signal.SIGKILL
        assert "SIGKILL" in str(died) and "replaced" in str(died)
        assert slept == 0.3
        assert [_run(pool, _add, i, 1) for i in range(3)] == [1, 2, 3]
        assert len(pool.pids()) == 2
    finally:
        pool.close()


def test_full_queue_answers_at_once():
    pool = _pool(size=1, max_queue=1)
    try:

        async def go():
            deadline = time.monotonic() + 30.0
            running = asyncio.ensure_future(pool.run(_sleep, 1.0, deadline=deadline, limit=30.0))
            # waited for, not slept on: the worker starts on first demand, slower on a
            # loaded machine
            while (pool.busy < 1 or pool.waiting) and time.monotonic() < deadline:
                await asyncio.sleep(0.01)
            waiting = asyncio.ensure_future(pool.run(_add, 1, 2, deadline=deadline, limit=30.0))
            while pool.waiting < 1 and time.monotonic() < deadline:
                await asyncio.sleep(0.01)
            with pytest.raises(QueueFull) as info:
                await pool.run(_add, 2, 2, deadline=deadline, limit=30.0)
            return info.value, await running, await waiting

        full, first, second = asyncio.run(go())
        assert full.retry_after >= 1 and "STOCHCABLE_MAX_QUEUE" in str(full)
        assert (first, second) == (1.0, 3)
    finally:
        pool.close()


def test_memory_error_under_the_address_space_limit_is_a_422():
    # a 64 MB budget: the worker's address space is its imported size + 128 MB, so a
    # 1 GB array cannot be mapped (MemoryError in the worker, not the OOM killer)
    pool = _pool(budget=64 * MB)
    try:
        assert _run(pool, _allocate, 8 * MB) == MB
        with pytest.raises(JobFailed) as info:
            _run(pool, _allocate, 1024 * MB)
        item = info.value.item
        assert info.value.status == 422 and item["type"] == "limit_exceeded"
        assert item["setting"] == "STOCHCABLE_MAX_MEMORY_BYTES"
        assert "ran out of memory" in item["msg"]
        assert _run(pool, _add, 1, 2) == 3  # a fresh worker (the old one is replaced)
        assert pool.replaced == 1
    finally:
        pool.close()


def test_full_queue_is_503_with_retry_after_over_http():
    import copy
    import threading

    from fastapi.testclient import TestClient

    from service.app import create_app
    from service.settings import Settings
    from stochcable.examples import load_example

    chain = load_example("chain_catenary").model_dump(mode="json", exclude_unset=True)
    long = copy.deepcopy(chain)
    long["lines"][0]["segments"][0]["elements"] = 100
    long["analysis"]["omega"]["count"] = 2000  # ≈ 1.5 s in the one worker
    app = create_app(Settings(analysis_workers=1, max_queue=0))
    with TestClient(app) as c:
        out = {}
        t = threading.Thread(target=lambda: out.setdefault("r", c.post("/v1/analyses", json=long)))
        t.start()
        # the long analysis holds the one worker (the lifespan started it idle): waited
        # for, not slept on (a loaded machine takes longer to hand the request over)
        end = time.monotonic() + 30.0
        while (app.state.pool.busy < 1 or app.state.pool.waiting) and time.monotonic() < end:
            time.sleep(0.01)
        resp = c.post("/v1/analyses", json=chain)
        # the light endpoints do not queue behind the analysis
        light = c.post("/v1/spectra", json={"spectrum": {"type": "jonswap", "hs": 2, "tp": 8}})
        t.join(60.0)
    assert out["r"].status_code == 200
    assert light.status_code == 200
    assert resp.status_code == 503 and int(resp.headers["retry-after"]) >= 1
    err = resp.json()["detail"][0]
    assert err["type"] == "queue_full" and err["setting"] == "STOCHCABLE_MAX_QUEUE"


def test_non_finite_results_name_the_line():
    from service.errors import error_answer
    from service.jobs import non_finite_error
    from stochcable.analysis import analyze
    from stochcable.examples import load_example

    scene = load_example("tuah_1982_disc_buoy_three_legs")
    doc = analyze(scene).to_document()
    doc["lines"]["leg2"]["end_a"]["tension"]["std"] = float("nan")  # as a core overflow would
    status, item, _ = error_answer(non_finite_error(scene, doc))
    assert status == 422 and item["type"] == "numerical_error"
    assert item["parameter"] == "lines[1]" and item["loc"] == ["body", "lines", 1]
    assert "line 'leg2'" in item["msg"]
