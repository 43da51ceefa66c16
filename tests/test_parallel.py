"""Tests of stochcable.runtime (per-line work of a coupled group on a thread pool).

Independent checks: the serial loop (same bits), the calling thread's warning
collector, the environment switch and the BLAS gate.
"""

from __future__ import annotations

import threading

import numpy as np
import pytest

from stochcable import runtime as _parallel
from stochcable.dynamics.line import _single_blas_thread
from stochcable.errors import PhysicsWarning, SolverError, collect_warnings, warn


def _eig_item(seed: int) -> tuple[np.ndarray, str]:
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(60, 60))
    return np.linalg.eigvals(a), threading.current_thread().name


def _count_pool(monkeypatch) -> list[int]:
    """Count the pool hand-offs of line_map (the items then go to whichever thread
    is free first)."""
    used: list[int] = []
    real = _parallel._executor

    def spy(n):
        used.append(n)
        return real(n)

    monkeypatch.setattr(_parallel, "_executor", spy)
    return used


def test_same_bits_and_order_as_the_loop(monkeypatch):
    monkeypatch.setenv("STOCHCABLE_THREADS", "2")
    used = _count_pool(monkeypatch)
    serial = [_eig_item(s)[0] for s in range(5)]
    with _single_blas_thread():
        out = _parallel.line_map(_eig_item, range(5))
    assert used == [1]   # the calling thread and one pool worker
    assert [np.array_equal(a, b) for (a, _), b in zip(out, serial)] == [True] * 5


def test_disabled_by_the_environment_and_outside_single_blas(monkeypatch):
    used = _count_pool(monkeypatch)
    monkeypatch.setenv("STOCHCABLE_THREADS", "1")
    main = threading.current_thread().name
    with _single_blas_thread():
        assert {n for _, n in _parallel.line_map(_eig_item, range(3))} == {main}
    monkeypatch.setenv("STOCHCABLE_THREADS", "2")
    monkeypatch.delenv("OPENBLAS_NUM_THREADS", raising=False)
    monkeypatch.delenv("OMP_NUM_THREADS", raising=False)
    # BLAS not limited to one thread here: no pool (no oversubscription)
    assert {n for _, n in _parallel.line_map(_eig_item, range(3))} == {main}
    # one item: no pool
    with _single_blas_thread():
        assert _parallel.line_map(_eig_item, [0])[0][1] == main
    assert used == []
    monkeypatch.setenv("STOCHCABLE_THREADS", "junk")
    assert _parallel.thread_count() == 1


def test_no_nesting_warnings_forwarded_and_first_exception(monkeypatch):
    monkeypatch.setenv("STOCHCABLE_THREADS", "2")

    def inner(i: int) -> bool:
        return _parallel.pool_active()

    def outer(i: int) -> list[str]:
        warn(f"item {i}", PhysicsWarning)
        # a nested map runs in the thread of the item itself
        names = {threading.current_thread().name}
        _parallel.line_map(lambda j: names.add(threading.current_thread().name), range(3))
        assert len(names) == 1
        return _parallel.line_map(inner, range(2))

    with _single_blas_thread(), collect_warnings() as outer_caught, \
            collect_warnings() as caught, pytest.warns(PhysicsWarning):
        out = _parallel.line_map(outer, range(3))
    assert out == [[True, True]] * 3
    # forwarded to every collector of the calling thread, once each, in item order
    # (whichever thread ran the item)
    assert [str(w) for w in caught] == ["item 0", "item 1", "item 2"]
    assert [str(w) for w in outer_caught] == ["item 0", "item 1", "item 2"]

    def fails(i: int) -> int:
        if i >= 1:
            raise SolverError(f"item {i} failed")
        return i

    with _single_blas_thread(), pytest.raises(SolverError, match="item 1 failed"):
        _parallel.line_map(fails, range(3))


def test_default_is_no_pool(monkeypatch):
    """Opt-in (module docstring: measured gain only on an idle machine)."""
    monkeypatch.delenv("STOCHCABLE_THREADS", raising=False)
    assert _parallel.thread_count() == 1
    monkeypatch.setenv("STOCHCABLE_THREADS", "0")
    assert _parallel.thread_count() == 1
    monkeypatch.setenv("STOCHCABLE_THREADS", "3")
    assert _parallel.thread_count() == 3
