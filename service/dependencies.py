"""Request dependencies (``Annotated`` aliases for route signatures)."""

from __future__ import annotations

from typing import Annotated

from fastapi import Depends, Request

from .encoding import negotiate
from .limits import Runner
from .settings import Settings
from .workers import WorkerPool

__all__ = [
    "SettingsDep",
    "RunnerDep",
    "PoolDep",
    "MediaTypeDep",
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


SettingsDep = Annotated[Settings, Depends(get_settings)]
RunnerDep = Annotated[Runner, Depends(get_runner)]
PoolDep = Annotated[WorkerPool, Depends(get_pool)]
MediaTypeDep = Annotated[str, Depends(negotiate)]
