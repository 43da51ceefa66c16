"""Service settings, read from ``STOCHCABLE_*`` environment variables (pydantic-settings).

Every limit the service enforces is a setting here; an answer refusing a request names
the setting (``STOCHCABLE_MAX_SAMPLES``) so an operator knows what to raise.
"""

from __future__ import annotations

import ipaddress
import os
from typing import Literal

import psutil
from pydantic import Field
from pydantic_settings import BaseSettings, SettingsConfigDict

__all__ = ["Settings", "ENV_PREFIX", "is_loopback", "insecure_bind_message"]

ENV_PREFIX = "STOCHCABLE_"


class Settings(BaseSettings):
    """Server address and resource limits of the stochcable service."""

    model_config = SettingsConfigDict(env_prefix=ENV_PREFIX, frozen=True, extra="ignore")

    host: str = Field(default="127.0.0.1", description="Interface uvicorn binds to")
    port: int = Field(default=8000, ge=0, le=65535, description="TCP port")
    workers: int = Field(default=1, ge=1, le=256, description="uvicorn worker processes")
    max_body_bytes: int = Field(
        default=16 * 1024 * 1024,
        ge=1024,
        description="Largest request body accepted; larger answers 413 [bytes]",
    )
    max_samples: int = Field(
        default=2**22,
        ge=16,
        description="Largest time-series length duration/dt, times the number of "
        "kinematics points when points are given [-]",
    )
    max_elements: int = Field(
        default=20_000, ge=1, description="Largest total number of finite elements of a scene [-]"
    )
    max_frequencies: int = Field(
        default=100_000, ge=2, description="Largest frequency-grid size [-]"
    )
    max_points: int = Field(
        default=256, ge=1, description="Largest number of kinematics points of one request [-]"
    )
    max_run_seconds: float = Field(
        default=60.0,
        gt=0,
        description="Wall-clock bound of one computation, queueing included; over it the "
        "request answers 504 [s]",
    )
    max_concurrency: int = Field(
        default=4,
        ge=1,
        le=1024,
        description="Computations running at once per worker process; the rest queue [-]",
    )

    analysis_workers: int = Field(
        default_factory=lambda: os.cpu_count() or 1,
        ge=1,
        le=256,
        description="Worker processes running analyses (POST /v1/analyses), each one "
        "analysis at a time; default the number of cores [-]",
    )
    worker_start_method: Literal["forkserver", "fork"] = Field(
        default="forkserver",
        description="How analysis workers start: forkserver (warm, clean imports) or fork "
        "(a copy of the HTTP process, for tests that patch the library) [-]",
    )
    max_queue: int = Field(
        default=64,
        ge=0,
        le=100_000,
        description="Analyses waiting for a worker process; beyond it the request answers "
        "503 with Retry-After [-]",
    )
    max_memory_bytes: int | None = Field(
        default=None,
        ge=2**20,
        description="Largest estimated peak memory of one analysis (stochcable.estimate_cost); "
        "over it the request answers 422 limit_exceeded.  Default: 80 % of the machine's "
        "memory divided by the analyses that can run at once (analysis_workers × "
        "workers).  Each worker runs under an address-space limit of its imported size "
        "plus twice this budget [bytes]",
    )
    worker_recycle_bytes: int = Field(
        default=1024 * 2**20,
        ge=2**20,
        description="A worker whose resident memory stays above this after an analysis "
        "is replaced by a fresh one, so a heavy analysis's memory returns to the system "
        "[bytes]",
    )

    jobs_database: str = Field(
        default="stochcable-jobs.sqlite",
        description="Where batch jobs and their results are kept: a SQLite file path "
        "(created on first start, WAL mode; relative to the working directory) or any "
        "SQLAlchemy URL such as postgresql+psycopg://user@host/db [-]",
    )
    dask_scheduler: str | None = Field(
        default=None,
        description="Run batch jobs on this Dask scheduler (tcp://HOST:PORT) instead of "
        "the service's own batch worker processes [-]",
    )
    batch_workers: int = Field(
        default_factory=lambda: os.cpu_count() or 1,
        ge=1,
        le=256,
        description="Worker processes running the chunks of batch jobs (below the "
        "analyses' CPU priority); default the number of cores [-]",
    )
    max_batch_cases: int = Field(
        default=100_000, ge=1, description="Largest number of cases of one batch [-]"
    )
    max_queued_batches: int = Field(
        default=64,
        ge=1,
        description="Batches queued or running at once (of all callers); beyond it a "
        "submission answers 422 [-]",
    )
    max_result_bytes: int = Field(
        default=128 * 2**20,
        ge=2**10,
        description="Largest estimated size of one batch's result table [bytes]",
    )
    batch_retention_hours: float = Field(
        default=168.0,
        gt=0,
        description="Finished batches (done, failed, cancelled) and their results are "
        "deleted this long after they finished [h]",
    )
    batch_lease_seconds: float = Field(
        default=30.0,
        ge=1.0,
        description="A running batch whose service process has not reported for this "
        "long (ended, killed) is taken over and resumed by another or a restarted one [s]",
    )
    api_keys: str | None = Field(
        default=None,
        description="Comma-separated API keys; when set, every /v1 request needs "
        "'Authorization: Bearer KEY' and a batch is visible only to the key that "
        "submitted it [-]",
    )
    insecure: bool = Field(
        default=False,
        description="Allow serving on a non-loopback address without API keys [-]",
    )

    @property
    def keys(self) -> tuple[str, ...]:
        """The configured API keys (empty: access control off)."""
        if not self.api_keys:
            return ()
        return tuple(k.strip() for k in self.api_keys.split(",") if k.strip())

    @property
    def memory_budget(self) -> int:
        """``max_memory_bytes``, or its default from the machine's memory. [bytes]"""
        if self.max_memory_bytes is not None:
            return self.max_memory_bytes
        running = self.analysis_workers * self.workers  # each uvicorn process has a pool
        return int(0.8 * psutil.virtual_memory().total / running)

    @staticmethod
    def env_name(field: str) -> str:
        """Environment variable of a setting, e.g. ``STOCHCABLE_MAX_SAMPLES``."""
        return ENV_PREFIX + field.upper()


def is_loopback(host: str) -> bool:
    """Whether ``host`` is a loopback interface (127.0.0.0/8, ::1, localhost)."""
    if host.strip().lower() == "localhost":
        return True
    try:
        return ipaddress.ip_address(host.strip("[]")).is_loopback
    except ValueError:
        return False


def insecure_bind_message(host: str, settings: Settings) -> str | None:
    """Why the service must not start on ``host`` (None when it may): a non-loopback
    address needs API keys (``STOCHCABLE_API_KEYS``) or an explicit ``--insecure``
    (``STOCHCABLE_INSECURE=1``)."""
    if is_loopback(host) or settings.keys or settings.insecure:
        return None
    return (
        f"{host} is not a loopback address and no API keys are set: anyone who reaches it "
        f"could run and read batches; set {Settings.env_name('api_keys')} (comma-separated "
        f"keys, sent as 'Authorization: Bearer KEY') or pass --insecure "
        f"({Settings.env_name('insecure')}=1) to serve without access control"
    )
