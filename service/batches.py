"""Batch jobs: load-case sets run in the background, stored as they go, resumed after a
restart (:mod:`service.store`).

A submission is validated and planned in full before it is stored (the same checks as
``POST /v1/analyses`` on its scene, plus the batch limits); its chunking is fixed then and
stored with it, so a resumed job computes exactly the chunks it had not stored, with the
same numbers.  One runner thread per service process takes jobs from the store under a
renewed lease and runs their chunks on an executor: the service's own batch worker
processes (below the analyses' CPU priority, one BLAS thread each) or, with
``STOCHCABLE_DASK_SCHEDULER``, a Dask cluster.  At most two chunks per worker are in
flight, so a cancellation stops the work within a chunk's time.
"""

from __future__ import annotations

import concurrent.futures as cf
import logging
import multiprocessing
import os
import socket
import threading
import time
import uuid
from datetime import datetime, timezone
from functools import cached_property
from typing import Any

from sqlalchemy.exc import SQLAlchemyError

from stochcable import runtime
from stochcable.cases import read_scatter
from stochcable.cases.chunk import prepare_worker, solve_chunk
from stochcable.cases.fatigue_settings import fatigue_from_document
from stochcable.cases.plan import (
    CasePlan,
    chunk_from_bytes,
    chunk_to_bytes,
    default_chunk_size,
    plan_cases,
)
from stochcable.cases.results import case_dataset, case_document, case_summary_csv
from stochcable.cases.run import assemble_cases
from stochcable.errors import InputError, collect_warnings
from stochcable.scene.model import load_scene

from .batch_schemas import (
    BatchProgress,
    BatchRequest,
    BatchStatus,
    CaseProblem,
    ScatterMatrix,
    ScatterTable,
)
from .encoding import CSV, JSON, NETCDF, dumps
from .errors import Conflict, LimitExceeded, NotFound, StoreUnavailable
from .limits import check_scene
from .settings import Settings
from .store import ACTIVE, JobRecord, JobStore

__all__ = ["BatchService", "plan_request", "BATCH_NICENESS"]

log = logging.getLogger("stochcable.service.batches")

BATCH_NICENESS = 10
"""CPU priority step of the batch workers below the HTTP process (the analysis workers
are 5 below it): synchronous analyses and /health go first while a batch runs."""

_CHUNK_ATTEMPTS = 3
"""Times a chunk is tried when its worker is lost before the job is marked failed."""

#: Bytes per stored number of the result table, with the JSON answer's text. [bytes]
_BYTES_PER_VALUE = 24


def _reason(exc: BaseException) -> str:
    """The first line of an exception's message (SQLAlchemy's carry a long tail)."""
    text = str(getattr(exc, "orig", None) or exc).strip().splitlines()
    return f"{type(exc).__name__}: {text[0] if text else ''}"


def _iso(t: float | None) -> str | None:
    return None if t is None else datetime.fromtimestamp(t, tz=timezone.utc).isoformat()


def _prefixed(exc: InputError, prefix: str) -> InputError:
    return InputError(f"{prefix}.{exc.parameter}", exc.value, exc.unit, exc.constraint)


def plan_request(doc: dict[str, Any], settings: Settings | None = None) -> CasePlan:
    """Validate a batch request document and plan its chunks.

    Parameters
    ----------
    doc : dict
        The request (:class:`~service.batch_schemas.BatchRequest` as JSON) with its
        ``chunk_size``.
    settings : Settings, optional
        Check the service's limits (at submission; a stored job is not checked again).

    Returns
    -------
    CasePlan
    """
    # (a stored job's document also holds its planning warnings: not the request's)
    req = BatchRequest.model_validate({k: v for k, v in doc.items() if k != "warnings"})
    try:
        scene = load_scene(req.scene, allow_files=False)
    except InputError as exc:
        raise _prefixed(exc, "scene") from None
    if settings is not None:
        try:
            check_scene(scene, settings)
        except LimitExceeded as exc:
            exc.parameter = f"scene.{exc.parameter}"
            raise
    scatter_doc: Any = req.model_dump(mode="json", exclude_none=True)["scatter"]
    if settings is not None:  # before the diagram is expanded into its sea states
        _check_case_count(req, settings)
    scatter = read_scatter(scatter_doc, family=req.spectrum)
    if req.headings is not None:
        scatter = scatter.with_headings(req.headings)
    n = len(scatter.states)
    if settings is not None and n > settings.max_batch_cases:
        raise LimitExceeded("scatter", n, settings.max_batch_cases, "max_batch_cases", f"{n} cases")
    names = tuple(ln.name for ln in scene.lines)
    fat = None if req.fatigue is None else req.model_dump(mode="json", exclude_none=True)["fatigue"]
    fatigue = fatigue_from_document(fat, names)
    plan = plan_cases(scene, scatter, fatigue=fatigue, years=req.years, chunk_size=req.chunk_size)
    if settings is not None:
        per_case = sum(10 + sum(s.elements for s in ln.segments) for ln in scene.lines)
        size = n * per_case * _BYTES_PER_VALUE
        if size > settings.max_result_bytes:
            raise LimitExceeded(
                "scatter", n, settings.max_result_bytes, "max_result_bytes",
                f"the result table of {n} cases × {per_case} values ≈ {size} bytes",
                hint="split the scatter diagram into several batches",
            )  # fmt: skip
    return plan


def _check_case_count(req: BatchRequest, settings: Settings) -> None:
    sc = req.scatter
    if isinstance(sc, ScatterMatrix):
        cells = sum(1 for row in sc.occurrence for x in row if x != 0)
        n = cells * max(1, sum(1 for p in (sc.headings or {"0": 1}).values() if p > 0))
    else:
        n = len(sc.rows if isinstance(sc, ScatterTable) else sc)
    n *= len(req.headings) if req.headings else 1
    if n > settings.max_batch_cases:
        raise LimitExceeded("scatter", n, settings.max_batch_cases, "max_batch_cases", f"{n} cases")


def _worker_init(niceness: int) -> None:
    """Batch worker process: low CPU priority, one BLAS thread, the core's settings."""
    import signal
    import warnings

    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the service ends its workers itself
    os.nice(niceness)
    import threadpoolctl

    runtime.configure()
    threadpoolctl.threadpool_limits(1)
    warnings.simplefilter("ignore")  # a case's warnings are in its row


class BatchService:
    """The store, the runner thread and the executor of one service process.

    Parameters
    ----------
    settings : Settings
    """

    def __init__(self, settings: Settings) -> None:
        self.settings = settings
        self.holder = f"{socket.gethostname()}:{os.getpid()}:{uuid.uuid4().hex[:8]}"
        self._stop = threading.Event()
        self._wake = threading.Event()
        self._thread: threading.Thread | None = None
        self._executor: Any = None
        self._last_expiry = 0.0

    # ------------------------------------------------------------ life cycle

    @cached_property
    def store(self) -> JobStore:
        """The job store (opened, and created if new, on first use).

        Raises StoreUnavailable (503) when the database cannot be opened."""
        try:
            return JobStore(self.settings.jobs_database)
        except (OSError, SQLAlchemyError) as exc:
            raise StoreUnavailable(self.settings.jobs_database, _reason(exc)) from None

    def start(self) -> None:
        """Start the runner thread (jobs left running by a former process resume)."""
        if self._thread is None:
            self._thread = threading.Thread(target=self._loop, name="batch-runner", daemon=True)
            self._thread.start()

    def close(self) -> None:
        """Stop the runner (its job's lease is released, so a restart resumes it at once),
        end the workers and close the store."""
        self._stop.set()
        self._wake.set()
        if self._thread is not None:
            self._thread.join(timeout=30)
        self._shutdown_executor()
        if "store" in self.__dict__:
            self.store.close()

    # -------------------------------------------------------------- requests

    def submit(self, request: BatchRequest, owner: str) -> JobRecord:
        """Validate, plan and store a batch; the runner is woken."""
        doc = request.model_dump(mode="json", exclude_none=True)
        doc["scene"] = request.scene.model_dump(mode="json", exclude_unset=True)
        with collect_warnings() as caught:  # (what the set does not apply, ...)
            if doc.get("chunk_size") is None:
                plan = plan_request(doc, self.settings)
                # from the settings alone: a submission never waits for a Dask scheduler
                doc["chunk_size"] = default_chunk_size(
                    len(plan.scatter.states), self.settings.batch_workers
                )
            plan = plan_request(doc, self.settings)
        # stored with the request: the status shows them as long as the job is kept
        doc["warnings"] = list(dict.fromkeys(str(w) for w in caught))
        n = len(plan.scatter.states)
        job = self.store.create(
            owner, doc, n, len(plan.chunks), doc["chunk_size"], self.settings.max_queued_batches
        )
        if job is None:
            limit = self.settings.max_queued_batches
            raise LimitExceeded(
                "body", None, limit, "max_queued_batches", "",
                message=f"{limit} batches are queued or running, the limit "
                f"({Settings.env_name('max_queued_batches')}); retry when one has finished",
            )  # fmt: skip
        self._wake.set()
        return job

    def get(self, job_id: str, owner: str) -> JobRecord:
        """The caller's job (NotFound for unknown ids and other callers' jobs)."""
        job = self.store.get(job_id, owner)
        if job is None:
            raise NotFound(["path", "job_id"], f"no batch {job_id!r}")
        return job

    def status(self, job: JobRecord) -> BatchStatus:
        """The status document of a job."""
        now = time.time()
        since = job.resumed or job.started
        rate = eta = None
        if job.status == "running" and since is not None and now > since:
            rate = (job.cases_done - job.resumed_at_cases) / (now - since)
            if rate > 0:
                eta = (job.n_cases - job.cases_done) / rate
        progress = BatchProgress(
            total=job.n_cases,
            done=job.cases_done,
            not_ok=job.cases_not_ok,
            failed=job.cases_failed,
            fraction=job.cases_done / job.n_cases if job.n_cases else 1.0,
            rate=rate,
            eta_seconds=eta,
        )
        problems = [CaseProblem(**p) for p in self.store.problems(job.id, 100)]
        return BatchStatus(
            id=job.id, status=job.status, created=_iso(job.created), started=_iso(job.started),
            finished=_iso(job.finished), progress=progress, problems=problems,
            problems_total=job.cases_not_ok, error=job.error, chunk_size=job.chunk_size,
            results=f"/v1/batches/{job.id}/results", warnings=job.request.get("warnings", []),
        )  # fmt: skip

    def cancel(self, job: JobRecord, *, delete_finished: bool = True) -> JobRecord | None:
        """Cancel an active job, or delete a finished one and its results (None); with
        ``delete_finished`` False a finished job is left as it is.

        A job seen active that finished before the cancel reached the store (its last
        chunk stored just then) is left as it finished: never deleted by a cancel."""
        if job.status in ACTIVE:
            self.store.finish(job.id, None, "cancelled")
            return self.get(job.id, job.owner)
        if delete_finished:
            self.store.delete(job.id)
            return None
        return job

    def results(self, job: JobRecord, media: str) -> bytes:
        """The result table of a finished job as JSON, CSV or NetCDF."""
        if job.status != "done":
            raise Conflict(
                ["path", "job_id"],
                f"batch {job.id} is {job.status} ({job.cases_done} of {job.n_cases} cases "
                "done): results are available when it is done",
            )  # fmt: skip
        plan = plan_request(job.request)
        result = assemble_cases(plan, (chunk_from_bytes(d) for d in self.store.chunk_data(job.id)))
        if media == CSV:
            return case_summary_csv(result).encode()
        if media == NETCDF:
            from stochcable.results.datasets import netcdf_bytes

            return netcdf_bytes(case_dataset(result))
        return dumps({"id": job.id, **case_document(result)}) if media == JSON else b""

    # ---------------------------------------------------------------- runner

    def _workers(self) -> int:
        if self.settings.dask_scheduler:
            return max(1, len(self._get_executor().scheduler_info().get("workers", {})))
        return self.settings.batch_workers

    def _get_executor(self) -> Any:
        if self._executor is None:
            if self.settings.dask_scheduler:
                import distributed

                client = distributed.Client(self.settings.dask_scheduler, timeout=30)
                client.run(prepare_worker)  # the service's process settings (≈ 30 % faster)
                self._executor = client
            else:
                ctx = multiprocessing.get_context(self.settings.worker_start_method)
                self._executor = cf.ProcessPoolExecutor(
                    self.settings.batch_workers, mp_context=ctx, initializer=_worker_init,
                    initargs=(BATCH_NICENESS,),
                )  # fmt: skip
        return self._executor

    def _shutdown_executor(self) -> None:
        ex, self._executor = self._executor, None
        if ex is None:
            return
        if isinstance(ex, cf.ProcessPoolExecutor):
            for p in list(getattr(ex, "_processes", {}).values()):
                p.terminate()  # a chunk in flight is redone by whoever resumes the job
            ex.shutdown(wait=True, cancel_futures=True)
        else:
            ex.close()

    def _loop(self) -> None:
        lease = self.settings.batch_lease_seconds
        while not self._stop.is_set():
            try:
                self._expire()
                job = self.store.claim(self.holder, lease)
            except Exception as exc:  # the database away for a moment: try again later
                log.warning("batch store unavailable: %s", _reason(exc))
                self._stop.wait(10.0)
                continue
            if job is None:
                self._wake.wait(timeout=min(1.0, lease / 3))
                self._wake.clear()
                continue
            try:
                self._run(job)
            except Exception as exc:  # a defect fails its job, never the service
                log.exception("batch %s failed", job.id)
                self.store.finish(job.id, self.holder, "failed", f"internal error: {exc!r}")

    def _expire(self) -> None:
        now = time.time()
        if now - self._last_expiry > 60:
            self._last_expiry = now
            self.store.expire(now - 3600 * self.settings.batch_retention_hours)

    def _submit(self, plan: CasePlan, k: int, shared: Any) -> Any:
        ex = self._get_executor()
        args = (shared, plan.scatter.family, plan.chunks[k], plan.fatigue, None, plan.leads[k])
        if isinstance(ex, cf.ProcessPoolExecutor):
            return ex.submit(solve_chunk, *args)
        return ex.submit(solve_chunk, *args, pure=False, retries=_CHUNK_ATTEMPTS - 1)

    def _run(self, job: JobRecord) -> None:
        """Run the chunks of ``job`` not yet stored; store each as it finishes."""
        lease = self.settings.batch_lease_seconds
        try:
            plan = plan_request(job.request)
        except (InputError, ValueError) as exc:
            self.store.finish(job.id, self.holder, "failed", f"cannot plan the batch: {exc}")
            return
        todo = [k for k in range(len(plan.chunks)) if k not in self.store.done_chunks(job.id)]
        try:
            ex = self._get_executor()
        except (OSError, TimeoutError) as exc:  # the Dask scheduler away: try again later
            log.warning("batch executor unavailable (%s); job %s waits", exc, job.id)
            self.store.renew(job.id, self.holder, -lease)  # released: claimed again later
            self._stop.wait(min(10.0, lease))
            return
        shared: Any = plan.template
        if not isinstance(ex, cf.ProcessPoolExecutor):
            shared = ex.scatter(plan.template, broadcast=True, hash=False)
        window = 2 * self._workers()
        pending: dict[Any, int] = {}
        attempts: dict[int, int] = {}
        queue = list(reversed(todo))
        while queue or pending:
            while queue and len(pending) < window:
                k = queue.pop()
                pending[self._submit(plan, k, shared)] = k
            done = self._wait_first(list(pending), lease / 3)
            for fut in done:
                k = pending.pop(fut)
                try:
                    res = fut.result()
                except Exception as exc:  # a lost worker: its chunk again, a few times
                    attempts[k] = attempts.get(k, 0) + 1
                    if attempts[k] >= _CHUNK_ATTEMPTS:
                        self._abandon(pending)
                        self.store.finish(
                            job.id, self.holder, "failed",
                            f"chunk {k} failed {attempts[k]} times: {exc!r}",
                        )  # fmt: skip
                        return
                    self._restart_pool_if_broken()
                    queue.append(k)
                    continue
                problems = [
                    {"index": r.index, "status": r.status, "reason": r.reason}
                    for r in res.rows
                    if r.status != "ok"
                ]
                data = chunk_to_bytes(res)
                if not self.store.save_chunk(
                    job.id, self.holder, k, data, problems, len(res.rows), lease
                ):
                    self._abandon(pending)  # cancelled, or taken over
                    return
            if self._stop.is_set():
                self._abandon(pending)
                self.store.renew(job.id, self.holder, -lease)  # release: resume at once
                return
            if not self.store.renew(job.id, self.holder, lease):
                self._abandon(pending)
                return
        self.store.finish(job.id, self.holder, "done")

    def _wait_first(self, futures: list[Any], timeout: float) -> set[Any]:
        """The futures done after at most ``timeout`` seconds (at least one if any
        finishes in time)."""
        if not futures or isinstance(futures[0], cf.Future):
            return cf.wait(futures, timeout=timeout, return_when=cf.FIRST_COMPLETED)[0]
        import distributed

        try:
            return distributed.wait(futures, timeout=timeout, return_when="FIRST_COMPLETED").done
        except TimeoutError:
            return set()

    def _abandon(self, pending: dict[Any, int]) -> None:
        for fut in pending:
            fut.cancel()
        pending.clear()

    def _restart_pool_if_broken(self) -> None:
        ex = self._executor
        if isinstance(ex, cf.ProcessPoolExecutor) and getattr(ex, "_broken", False):
            self._executor = None
            ex.shutdown(wait=False, cancel_futures=True)
