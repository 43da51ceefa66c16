"""The batch-job store on a real SQLite file: leases (a job is run by one holder; a lease
that runs out lets another take it over), a chunk counted once, cancellation seen by the
holder, the queue limit and retention."""

from __future__ import annotations

import time

import pytest

from service.store import JobStore


@pytest.fixture
def store(tmp_path):
    s = JobStore(str(tmp_path / "sub" / "jobs.sqlite"))  # the folder is created too
    yield s
    s.close()


def _job(store, max_active=10):
    return store.create("owner", {"x": 1}, n_cases=6, n_chunks=3, chunk_size=2,
                        max_active=max_active)  # fmt: skip


def test_wal_mode_and_round_trip(store):
    job = _job(store)
    with store.engine.connect() as conn:
        assert conn.exec_driver_sql("PRAGMA journal_mode").scalar() == "wal"
    assert store.get(job.id).request == {"x": 1}
    assert store.get(job.id, owner="someone else") is None


def test_lease_takeover_counts_every_chunk_once(store):
    job = _job(store)
    a = store.claim("A", lease=0.2)
    assert a.id == job.id and a.status == "running"
    assert store.claim("B", lease=10) is None  # held by A
    assert store.save_chunk(job.id, "A", 0, b"c0", [], 2, lease=0.2)
    time.sleep(0.3)  # A's lease runs out (A was killed)
    b = store.claim("B", lease=10)
    assert b.id == job.id and b.resumed is not None and b.resumed_at_cases == 2
    assert not store.save_chunk(job.id, "A", 1, b"c1", [], 2, lease=10)  # A lost the job
    assert store.save_chunk(job.id, "B", 0, b"c0", [], 2, lease=10)  # stored before: once
    problems = [{"index": 4, "status": "failed", "reason": "r"}]
    assert store.save_chunk(job.id, "B", 2, b"c2", problems, 2, lease=10)
    rec = store.get(job.id)
    assert (rec.cases_done, rec.cases_failed, rec.cases_not_ok) == (4, 1, 1)
    assert store.done_chunks(job.id) == {0, 2}
    assert list(store.chunk_data(job.id)) == [b"c0", b"c2"]
    assert store.problems(job.id, 10) == problems


def test_cancel_is_seen_by_the_holder(store):
    job = _job(store)
    store.claim("A", lease=10)
    assert store.finish(job.id, None, "cancelled")
    assert not store.renew(job.id, "A", 10)
    assert not store.save_chunk(job.id, "A", 0, b"c", [], 2, lease=10)
    assert not store.finish(job.id, "A", "done")
    assert store.get(job.id).status == "cancelled"


def test_queue_limit_and_retention(store):
    first = _job(store, max_active=2)
    _job(store, max_active=2)
    assert _job(store, max_active=2) is None  # two active
    store.finish(first.id, None, "cancelled")
    assert store.expire(time.time() - 60) == 0  # finished just now: kept
    assert store.expire(time.time() + 1) == 1
    assert store.get(first.id) is None
