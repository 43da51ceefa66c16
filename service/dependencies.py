"""Request dependencies (``Annotated`` aliases for route signatures)."""

from __future__ import annotations

import hashlib
import hmac
from typing import Annotated

from fastapi import Depends, Request

from .batches import BatchService
from .encoding import negotiate
from .errors import Unauthorized
from .limits import Runner
from .settings import Settings
from .workers import WorkerPool

__all__ = [
    "SettingsDep",
    "RunnerDep",
    "PoolDep",
    "MediaTypeDep",
    "BatchesDep",
    "CallerDep",
    "get_batches",
    "get_caller",
    "get_settings",
    "get_runner",
    "get_pool",
]


def get_settings(request: Request) -> Settings:
    """The settings the application was created with."""
    return request.app.state.settings


def get_runner(request: Request) -> Runner:
    """The application's bounded thread runner."""
    return request.app.state.runner


def get_pool(request: Request) -> WorkerPool:
    """The application's analysis worker processes."""
    return request.app.state.pool


def get_batches(request: Request) -> BatchService:
    """The application's batch jobs (store and runner)."""
    return request.app.state.batches


def get_caller(request: Request) -> str:
    """Who asks: the SHA-256 digest of the request's API key, or "" when access control
    is off (no ``STOCHCABLE_API_KEYS``).

    Raises 401 (``WWW-Authenticate: Bearer``) for a missing or unknown key.
    """
    keys = request.app.state.settings.keys
    if not keys:
        return ""
    scheme, _, token = request.headers.get("authorization", "").partition(" ")
    token = token.strip()
    if scheme.lower() != "bearer" or not token:
        raise Unauthorized("this service needs an API key: send 'Authorization: Bearer KEY'")
    if not any(hmac.compare_digest(token.encode(), k.encode()) for k in keys):
        raise Unauthorized("unknown API key (the Authorization: Bearer header)")
    return hashlib.sha256(token.encode()).hexdigest()


SettingsDep = Annotated[Settings, Depends(get_settings)]
RunnerDep = Annotated[Runner, Depends(get_runner)]
PoolDep = Annotated[WorkerPool, Depends(get_pool)]
MediaTypeDep = Annotated[str, Depends(negotiate)]
BatchesDep = Annotated[BatchService, Depends(get_batches)]
CallerDep = Annotated[str, Depends(get_caller)]
