"""The batch-job store: jobs, their chunks' results and their state in a database
(SQLAlchemy Core; a SQLite file by default, in WAL mode, or any SQLAlchemy URL).

Everything a caller submitted is written before the submission is answered, and every
finished chunk is written in one transaction with the job's progress, so a job survives a
restart of the service: finished jobs with their results, unfinished ones resumed from
their last finished chunk.  Several service processes may share one database: a running
job is held by one of them under a lease that it renews; a lease that runs out (its
process ended or was killed) lets another process, or the restarted one, take the job
over.  A chunk is stored once (its key is the job and the chunk index), so no case is
lost or counted twice.
"""

from __future__ import annotations

import json
import time
import uuid
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import sqlalchemy as sa
from sqlalchemy.engine import Engine

__all__ = ["JobStore", "JobRecord", "ACTIVE", "FINISHED", "STATUSES"]

ACTIVE = ("queued", "running")
FINISHED = ("done", "failed", "cancelled")
STATUSES = ACTIVE + FINISHED
#: Problem rows (cases not ok) kept per job for the status answer. [-]
_PROBLEMS_KEPT = 1000

_meta = sa.MetaData()
_jobs = sa.Table(
    "stochcable_batches",
    _meta,
    sa.Column("id", sa.String(32), primary_key=True),
    sa.Column("owner", sa.String(64), nullable=False, default=""),
    sa.Column("status", sa.String(16), nullable=False),
    sa.Column("created", sa.Float, nullable=False),
    sa.Column("started", sa.Float),
    sa.Column("finished", sa.Float),
    sa.Column("request", sa.Text, nullable=False),
    sa.Column("n_cases", sa.Integer, nullable=False),
    sa.Column("n_chunks", sa.Integer, nullable=False),
    sa.Column("chunk_size", sa.Integer, nullable=False),
    sa.Column("cases_done", sa.Integer, nullable=False, default=0),
    sa.Column("cases_not_ok", sa.Integer, nullable=False, default=0),
    sa.Column("cases_failed", sa.Integer, nullable=False, default=0),
    sa.Column("resumed_at_cases", sa.Integer, nullable=False, default=0),
    sa.Column("resumed", sa.Float),
    sa.Column("error", sa.Text),
    sa.Column("holder", sa.String(64)),
    sa.Column("lease_until", sa.Float),
    sa.Index("ix_stochcable_batches_status_created", "status", "created"),
)
_chunks = sa.Table(
    "stochcable_batch_chunks",
    _meta,
    sa.Column(
        "job_id", sa.String(32), sa.ForeignKey(_jobs.c.id, ondelete="CASCADE"), primary_key=True
    ),  # fmt: skip
    sa.Column("chunk", sa.Integer, primary_key=True),
    sa.Column("n_cases", sa.Integer, nullable=False),
    sa.Column("problems", sa.Text, nullable=False),
    sa.Column("data", sa.LargeBinary, nullable=False),
)


@dataclass(frozen=True)
class JobRecord:
    """A batch job as stored (without its chunks' data).

    Attributes
    ----------
    id, owner, status : str
    created, started, finished, resumed : float or None
        Unix times. [s]
    request : dict
        The submitted request document (validated).
    n_cases, n_chunks, chunk_size, cases_done, cases_not_ok, cases_failed : int
    resumed_at_cases : int
        Cases already done when the job was last (re)started by a service process.
    error : str or None
        Why the job failed.
    """

    id: str
    owner: str
    status: str
    created: float
    started: float | None
    finished: float | None
    resumed: float | None
    request: dict[str, Any]
    n_cases: int
    n_chunks: int
    chunk_size: int
    cases_done: int
    cases_not_ok: int
    cases_failed: int
    resumed_at_cases: int
    error: str | None


def _record(row: Any) -> JobRecord:
    m = row._mapping
    return JobRecord(
        m["id"], m["owner"], m["status"], m["created"], m["started"], m["finished"],
        m["resumed"], json.loads(m["request"]), m["n_cases"], m["n_chunks"],
        m["chunk_size"], m["cases_done"], m["cases_not_ok"], m["cases_failed"],
        m["resumed_at_cases"], m["error"],
    )  # fmt: skip


def database_url(setting: str) -> str:
    """The SQLAlchemy URL of the ``jobs_database`` setting (a file path: SQLite)."""
    if "://" in setting:
        return setting
    return "sqlite:///" + str(Path(setting).expanduser().resolve())


def _sqlite_pragmas(dbapi_conn: Any, _record: Any) -> None:
    cur = dbapi_conn.cursor()
    cur.execute("PRAGMA journal_mode=WAL")  # readers never wait for the writer
    cur.execute("PRAGMA synchronous=NORMAL")  # durable at each checkpoint, safe in WAL
    cur.execute("PRAGMA foreign_keys=ON")
    cur.execute("PRAGMA busy_timeout=10000")
    cur.close()


class JobStore:
    """Batch jobs in a database.

    Parameters
    ----------
    url : str
        The ``jobs_database`` setting: a SQLite file path or a SQLAlchemy URL.
    """

    def __init__(self, url: str) -> None:
        self.url = database_url(url)
        sqlite = self.url.startswith("sqlite")
        if sqlite:
            Path(self.url.removeprefix("sqlite:///")).parent.mkdir(parents=True, exist_ok=True)
        args = {"timeout": 30, "check_same_thread": False} if sqlite else {}
        self.engine: Engine = sa.create_engine(self.url, connect_args=args, pool_pre_ping=True)
        if sqlite:
            sa.event.listen(self.engine, "connect", _sqlite_pragmas)
        _meta.create_all(self.engine)

    def close(self) -> None:
        """Close the database connections."""
        self.engine.dispose()

    # ---------------------------------------------------------------- submission

    def create(
        self,
        owner: str,
        request: Mapping[str, Any],
        n_cases: int,
        n_chunks: int,
        chunk_size: int,
        max_active: int,
    ) -> JobRecord | None:
        """Store a new queued job; None when ``max_active`` jobs are queued or running."""
        job_id = uuid.uuid4().hex
        now = time.time()
        with self.engine.begin() as conn:
            active = conn.execute(
                sa.select(sa.func.count()).select_from(_jobs).where(_jobs.c.status.in_(ACTIVE))
            ).scalar_one()
            if active >= max_active:
                return None
            conn.execute(
                _jobs.insert().values(
                    id=job_id, owner=owner, status="queued", created=now,
                    request=json.dumps(request), n_cases=n_cases, n_chunks=n_chunks,
                    chunk_size=chunk_size, cases_done=0, cases_not_ok=0, cases_failed=0,
                    resumed_at_cases=0,
                )
            )  # fmt: skip
        return self.get(job_id)

    def get(self, job_id: str, owner: str | None = None) -> JobRecord | None:
        """The job, or None (also when ``owner`` is given and is not the job's)."""
        q = sa.select(_jobs).where(_jobs.c.id == job_id)
        if owner is not None:
            q = q.where(_jobs.c.owner == owner)
        with self.engine.connect() as conn:
            row = conn.execute(q).first()
        return None if row is None else _record(row)

    def list(self, owner: str | None, limit: int = 100) -> list[JobRecord]:
        """The most recent jobs of ``owner`` (all when None), newest first."""
        q = sa.select(_jobs).order_by(_jobs.c.created.desc()).limit(limit)
        if owner is not None:
            q = q.where(_jobs.c.owner == owner)
        with self.engine.connect() as conn:
            return [_record(r) for r in conn.execute(q)]

    def problems(self, job_id: str, limit: int) -> list[dict[str, Any]]:
        """The cases of the job that are not ok, in case order (at most ``limit``)."""
        q = (
            sa.select(_chunks.c.problems)
            .where(_chunks.c.job_id == job_id)
            .order_by(_chunks.c.chunk)
        )
        out: list[dict[str, Any]] = []
        with self.engine.connect() as conn:
            for (text,) in conn.execute(q):
                out.extend(json.loads(text))
                if len(out) >= limit:
                    break
        return sorted(out, key=lambda p: p["index"])[:limit]

    # ------------------------------------------------------------------ running

    def claim(self, holder: str, lease: float) -> JobRecord | None:
        """Take the oldest queued job, or a running one whose lease ran out, under a
        lease held by ``holder``; None when there is none."""
        now = time.time()
        free = sa.or_(
            _jobs.c.status == "queued",
            sa.and_(_jobs.c.status == "running", _jobs.c.lease_until < now),
        )
        with self.engine.begin() as conn:
            candidates = conn.execute(
                sa.select(_jobs.c.id, _jobs.c.status).where(free).order_by(_jobs.c.created).limit(8)
            ).all()
            for job_id, status in candidates:
                # the time after the select: a job created (committed) since ``now`` was
                # taken would start before it was created (seen under load)
                at = max(now, time.time())
                done = sa.select(sa.func.coalesce(sa.func.sum(_chunks.c.n_cases), 0)).where(
                    _chunks.c.job_id == job_id
                )
                res = conn.execute(
                    _jobs.update()
                    .where(_jobs.c.id == job_id, free)
                    .values(
                        status="running", holder=holder, lease_until=at + lease,
                        started=sa.func.coalesce(_jobs.c.started, at),
                        resumed=at if status == "running" else None,
                        resumed_at_cases=done.scalar_subquery(),
                    )
                )  # fmt: skip
                if res.rowcount == 1:
                    break
            else:
                return None
        return self.get(job_id)

    def renew(self, job_id: str, holder: str, lease: float) -> bool:
        """Extend the lease; False when the job is no longer this holder's to run
        (cancelled, or taken over)."""
        with self.engine.begin() as conn:
            res = conn.execute(
                _jobs.update()
                .where(_jobs.c.id == job_id, _jobs.c.holder == holder, _jobs.c.status == "running")
                .values(lease_until=time.time() + lease)
            )
        return res.rowcount == 1

    def done_chunks(self, job_id: str) -> set[int]:
        """Indices of the chunks already stored."""
        with self.engine.connect() as conn:
            rows = conn.execute(sa.select(_chunks.c.chunk).where(_chunks.c.job_id == job_id))
            return {r[0] for r in rows}

    def save_chunk(
        self,
        job_id: str,
        holder: str,
        chunk: int,
        data: bytes,
        problems: list[dict[str, Any]],
        n_cases: int,
        lease: float,
    ) -> bool:
        """Store a finished chunk and the job's progress in one transaction; False (and
        nothing stored) when the job is no longer this holder's (cancelled, taken over)."""
        n_failed = sum(p["status"] == "failed" for p in problems)
        kept = json.dumps(problems[:_PROBLEMS_KEPT])
        try:
            with self.engine.begin() as conn:
                exists = conn.execute(
                    sa.select(_chunks.c.chunk).where(
                        _chunks.c.job_id == job_id, _chunks.c.chunk == chunk
                    )
                ).first()
                if exists is not None:  # stored by a holder before: do not count it twice
                    return True
                held = sa.and_(
                    _jobs.c.id == job_id, _jobs.c.holder == holder, _jobs.c.status == "running"
                )
                res = conn.execute(
                    _jobs.update()
                    .where(held)
                    .values(
                        cases_done=_jobs.c.cases_done + n_cases,
                        cases_not_ok=_jobs.c.cases_not_ok + len(problems),
                        cases_failed=_jobs.c.cases_failed + n_failed,
                        lease_until=time.time() + lease,
                    )
                )
                if res.rowcount != 1:
                    return False
                conn.execute(
                    _chunks.insert().values(
                        job_id=job_id, chunk=chunk, n_cases=n_cases, problems=kept, data=data
                    )
                )
        except sa.exc.IntegrityError:  # the same chunk stored at once by a former holder
            return True
        return True

    def chunk_data(self, job_id: str) -> Iterator[bytes]:
        """The stored chunks' data, in chunk order."""
        q = sa.select(_chunks.c.data).where(_chunks.c.job_id == job_id).order_by(_chunks.c.chunk)
        with self.engine.connect() as conn:
            for (data,) in conn.execute(q):
                yield data

    def finish(
        self, job_id: str, holder: str | None, status: str, error: str | None = None
    ) -> bool:
        """Mark an active job done, failed or cancelled (by its holder, or by anyone
        when ``holder`` is None); False when it was no longer active (or not held)."""
        cond = [_jobs.c.id == job_id, _jobs.c.status.in_(ACTIVE)]
        if holder is not None:
            cond.append(_jobs.c.holder == holder)
        with self.engine.begin() as conn:
            res = conn.execute(
                _jobs.update()
                .where(*cond)
                .values(status=status, finished=time.time(), error=error, holder=None,
                        lease_until=None)
            )  # fmt: skip
        return res.rowcount == 1

    def delete(self, job_id: str) -> None:
        """Remove a job and its chunks."""
        with self.engine.begin() as conn:
            conn.execute(_chunks.delete().where(_chunks.c.job_id == job_id))
            conn.execute(_jobs.delete().where(_jobs.c.id == job_id))

    def expire(self, older_than: float) -> int:
        """Delete finished jobs that finished before ``older_than`` (Unix time); their
        number."""
        with self.engine.begin() as conn:
            old = sa.select(_jobs.c.id).where(
                _jobs.c.status.in_(FINISHED), _jobs.c.finished < older_than
            )
            ids = [r[0] for r in conn.execute(old)]
            if ids:
                conn.execute(_chunks.delete().where(_chunks.c.job_id.in_(ids)))
                conn.execute(_jobs.delete().where(_jobs.c.id.in_(ids)))
        return len(ids)
