"""Test-session settings: one BLAS thread, and the service's batch-job store in a
temporary SQLite file (the module-level ``service.app.app`` and every ``create_app()``
read it), never in the working directory."""

from __future__ import annotations

import os
import sys
import tempfile

# One BLAS thread in the test process and in the servers and workers it starts (before
# NumPy is imported: no plugin imports it earlier): the suite runs analyses of small
# models beside servers and worker processes on two cores, where multi-threaded
# OpenBLAS spins against them (a 20-element, 80-frequency analysis took 1.0 s instead
# of 0.035 s); the numbers do not depend on it beyond round-off.  Tests of the BLAS
# settings set their own in their subprocesses.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

_DB_DIR = tempfile.mkdtemp(prefix="stochcable-test-jobs-")
os.environ.setdefault("STOCHCABLE_JOBS_DATABASE", os.path.join(_DB_DIR, "jobs.sqlite"))


# ------------------------------------------------------------------ the fast tier's guard
# The README's test command runs the fast tier (``-m "not slow"``, docs/manual/testing.md)
# on two cores in a few minutes; a test that takes more than FAST_TIER_BUDGET_S belongs to
# the slow tier (``@pytest.mark.slow``, run by .ci/run after it).  The rule measures what
# the test costs, not how busy or fast the machine is, and fails only with a clear margin:
# - CPU: the CPU time of the test's call (this process, all its threads, and the child
#   processes it waited for), less the compilation or loading of numba kernels
#   (stochcable.compiled.compile_cpu_seconds: a machine's first use, not the test's
#   work); fails above FAST_TIER_CPU_S = 2 × the budget (a CI core up to twice slower);
# - waiting: the wall time less the time the test's thread sat in the run queue (load:
#   /proc/self/task/<tid>/schedstat, where the kernel has it), which leaves its own CPU
#   time and its waits (sleeps, servers, processes it did not wait for); fails above
#   FAST_TIER_WAIT_S = 10 × the budget, times the machine's load per core when above 1
#   (the servers and processes it waits on are slowed down by load too: their queueing
#   is not the test's).
# STOCHCABLE_TEST_TIMES=FILE appends every test's figures to FILE (JSON lines: how the
# tiers were measured).
import json  # noqa: E402
import resource  # noqa: E402
import threading  # noqa: E402
import time  # noqa: E402

import pytest  # noqa: E402

FAST_TIER_BUDGET_S = 2.0
FAST_TIER_CPU_S = 2.0 * FAST_TIER_BUDGET_S
FAST_TIER_WAIT_S = 10.0 * FAST_TIER_BUDGET_S
_COST = pytest.StashKey[tuple]()


def _cpu_s() -> float:
    """CPU time of this process and its waited-for children, less kernel compilation."""
    own = resource.getrusage(resource.RUSAGE_SELF)
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    compiled = sys.modules.get("stochcable.compiled")
    compiling = compiled.compile_cpu_seconds() if compiled is not None else 0.0
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime - compiling


def _queued_s() -> float:
    """Time this thread has waited in the run queue (0 where the kernel does not say)."""
    try:
        with open(f"/proc/self/task/{threading.get_native_id()}/schedstat") as f:
            return int(f.read().split()[1]) * 1e-9
    except (OSError, ValueError, IndexError):
        return 0.0


def fast_tier_wait_limit(load_per_core: float) -> float:
    """The waiting limit [s]: FAST_TIER_WAIT_S times the load per core when above 1."""
    return FAST_TIER_WAIT_S * max(1.0, load_per_core)


def too_slow_for_the_fast_tier(cpu: float, own_wall: float, wait_limit: float) -> bool:
    """The guard's rule: CPU [s] over FAST_TIER_CPU_S, or wall time out of the run queue
    [s] over ``wait_limit``."""
    return cpu > FAST_TIER_CPU_S or own_wall > wait_limit


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_call(item):
    cpu0, queued0, wall0 = _cpu_s(), _queued_s(), time.perf_counter()
    yield
    wall = time.perf_counter() - wall0
    item.stash[_COST] = (_cpu_s() - cpu0, wall - (_queued_s() - queued0), wall)


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    report = outcome.get_result()
    if call.when != "call" or _COST not in item.stash:
        return
    cpu, own_wall, wall = item.stash[_COST]
    slow = item.get_closest_marker("slow") is not None
    log = os.environ.get("STOCHCABLE_TEST_TIMES")
    if log:
        with open(log, "a", encoding="utf-8") as f:
            row = {"id": item.nodeid, "cpu": cpu, "own_wall": own_wall, "wall": wall}
            f.write(json.dumps({**row, "slow": slow}) + "\n")
    wait_limit = fast_tier_wait_limit(os.getloadavg()[0] / (os.cpu_count() or 1))
    if report.passed and not slow and too_slow_for_the_fast_tier(cpu, own_wall, wait_limit):
        report.outcome = "failed"
        report.longrepr = (
            f"{item.nodeid}: too slow for the fast tier: {cpu:.1f} s of CPU, "
            f"{own_wall:.1f} s of wall time out of the run queue ({wall:.1f} s in all).  "
            f"The fast tier's budget is {FAST_TIER_BUDGET_S:g} s a test; the guard fails a "
            f"test above {FAST_TIER_CPU_S:g} s of CPU or {wait_limit:.3g} s of wall time "
            f"out of the run queue ({FAST_TIER_WAIT_S:g} s × the load per core above 1; "
            "tests/conftest.py).  Make it faster (share a session "
            "fixture, a smaller model) or mark it @pytest.mark.slow (run by .ci/run after "
            "the fast tier)"
        )
