"""The fast tier's guard (tests/conftest.py): its rule, with the margins that keep it
from failing a test on a loaded or slower machine, and its clocks."""

from __future__ import annotations

import time

import conftest
import pytest


@pytest.mark.parametrize(
    "cpu, own_wall, load, slow",
    [
        (1.9, 1.9, 0.5, False),  # within the 2 s budget
        (3.9, 3.9, 1.0, False),  # a CI core twice slower: still passes
        (4.1, 4.1, 1.0, True),  # over 2 × the budget of CPU
        (0.2, 19.0, 1.0, False),  # waiting on a server: within 10 × the budget
        (0.2, 21.0, 1.0, True),
        (0.2, 21.0, 2.0, False),  # the same wait at a load of 2 per core: within 40 s
        (0.2, 41.0, 2.0, True),
    ],
)
def test_the_rule_and_its_margins(cpu, own_wall, load, slow):
    limit = conftest.fast_tier_wait_limit(load)
    assert conftest.too_slow_for_the_fast_tier(cpu, own_wall, limit) is slow


def test_the_clocks_see_cpu_and_not_sleep():
    cpu0, queued0, wall0 = conftest._cpu_s(), conftest._queued_s(), time.perf_counter()
    time.sleep(0.2)  # waits: wall time, no CPU, no run-queue time
    end = time.process_time() + 0.2
    while time.process_time() < end:  # 0.2 s of CPU
        pass
    cpu = conftest._cpu_s() - cpu0
    wall = time.perf_counter() - wall0
    queued = conftest._queued_s() - queued0
    assert 0.19 < cpu < 0.35  # the spin, with the interpreter's own work (loose: CI)
    assert wall >= 0.4 and 0.0 <= queued <= wall + 0.05  # (schedstat is updated per switch)
