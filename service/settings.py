"""Service settings, read from ``STOCHCABLE_*`` environment variables (pydantic-settings).

Every limit the service enforces is a setting here; an answer refusing a request names
the setting (``STOCHCABLE_MAX_SAMPLES``) so an operator knows what to raise.
"""

from __future__ import annotations

import os
from typing import Literal

import psutil
from pydantic import Field
from pydantic_settings import BaseSettings, SettingsConfigDict

__all__ = ["Settings", "ENV_PREFIX"]

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
