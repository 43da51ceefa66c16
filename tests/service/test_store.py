"""The batch-job store on a real SQLite file and, where a PostgreSQL server can be
started here (Debian's postgresql binaries and psycopg), on a throw-away PostgreSQL
cluster: leases (a job is run by one holder; a lease that runs out lets another take it
over), a chunk counted once, cancellation seen by the holder, the queue limit and
retention."""

from __future__ import annotations

import os
import shutil
import socket
import subprocess
import tempfile
import time

import pytest

from service.store import JobStore

# one worker runs the module: its module fixtures run once (--dist loadgroup)
pytestmark = pytest.mark.xdist_group("test_store")


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="module")
def postgres_url():
    """A PostgreSQL cluster in a temporary folder on 127.0.0.1 (skipped with the reason
    where none can be started)."""
    initdb, pg_ctl = shutil.which("initdb"), shutil.which("pg_ctl")
    if initdb is None or pg_ctl is None:
        pytest.skip("no PostgreSQL server binaries (initdb, pg_ctl) on PATH")
    pytest.importorskip("psycopg", reason="the psycopg driver is not installed")
    folder = tempfile.mkdtemp(prefix="stochcable-pg-")
    as_user: list[str] = []
    if os.geteuid() == 0:  # the server refuses to run as root
        if shutil.which("runuser") is None:
            pytest.skip("running as root without runuser to start PostgreSQL as another user")
        shutil.chown(folder, "postgres")
        as_user = ["runuser", "-u", "postgres", "--"]
    data, port = os.path.join(folder, "data"), _free_port()
    quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL}
    try:
        subprocess.run([*as_user, initdb, "-D", data, "-A", "trust", "-U", "stochcable"],
                       check=True, timeout=120, **quiet)  # fmt: skip
        opts = f"-p {port} -k {folder} -c listen_addresses=127.0.0.1"
        subprocess.run([*as_user, pg_ctl, "-D", data, "-o", opts, "-w", "-t", "60", "start"],
                       check=True, timeout=90, **quiet)  # fmt: skip
    except (subprocess.CalledProcessError, subprocess.TimeoutExpired) as exc:
        shutil.rmtree(folder, ignore_errors=True)
        pytest.skip(f"PostgreSQL could not be started here ({exc})")
    yield f"postgresql+psycopg://stochcable@127.0.0.1:{port}/postgres"
    subprocess.run([*as_user, pg_ctl, "-D", data, "-m", "immediate", "stop"], timeout=60, **quiet)
    shutil.rmtree(folder, ignore_errors=True)


@pytest.fixture(params=["sqlite", "postgresql"])
def store(request, tmp_path):
    if request.param == "sqlite":
        s = JobStore(str(tmp_path / "sub" / "jobs.sqlite"))  # the folder is created too
    else:
        s = JobStore(request.getfixturevalue("postgres_url"))
    yield s
    with s.engine.begin() as conn:  # a clean database for the next test
        conn.exec_driver_sql("DELETE FROM stochcable_batch_chunks")
        conn.exec_driver_sql("DELETE FROM stochcable_batches")
    s.close()


def _job(store, max_active=10):
    return store.create("owner", {"x": 1}, n_cases=6, n_chunks=3, chunk_size=2,
                        max_active=max_active)  # fmt: skip


def test_wal_mode_and_round_trip(store):
    job = _job(store)
    if store.url.startswith("sqlite"):
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


def test_a_job_created_as_the_runner_claims_starts_after_it(tmp_path, monkeypatch):
    """The runner takes its time before it selects the queued jobs; a job created and
    committed in between (the runner descheduled under load: test_batches saw
    started < created once in 3 loaded runs) is claimed with the time after the
    select, never before its creation."""
    import types

    import service.store as store_module

    store = JobStore(str(tmp_path / "jobs.sqlite"))
    job = store.create("", {"warnings": []}, 1, 1, 1, 10)
    early = [job.created - 1.0]  # the claim's first reading: before the job existed
    clock = types.SimpleNamespace(time=lambda: early.pop() if early else time.time())
    monkeypatch.setattr(store_module, "time", clock)
    claimed = store.claim("runner", 30.0)
    assert claimed is not None and claimed.id == job.id and not early
    assert claimed.started >= claimed.created
    store.close()
