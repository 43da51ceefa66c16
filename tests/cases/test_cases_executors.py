"""The execution seam of load-case sets: the same bits whichever executor runs the
chunks — this process, a process pool, a real Dask LocalCluster of two worker
processes — and however the set is chunked."""

from __future__ import annotations

import multiprocessing
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest

from stochcable.cases import LineFatigue, run_cases, scatter_from_rows
from stochcable.errors import InputError
from stochcable.examples import load_example

# one worker runs the module: its module fixtures run once (--dist loadgroup)
pytestmark = pytest.mark.xdist_group("test_cases_executors")

FATIGUE = LineFatigue("dnv-studless", nominal_diameter=0.084)


@pytest.fixture(scope="module")
def scene():
    return load_example("chain_catenary")


@pytest.fixture(scope="module")
def scatter():
    # six cases per heading in a row: all but the first of each warm-start from the
    # cases before them (stochcable.cases.chunk), so chunks that start inside a run
    # replay its earlier cases to give the same bits
    rows = [
        {"hs": hs, "tp": tp, "heading": hd, "probability": 1 / 12}
        for hd in (0.0, 180.0)
        for hs in (1.5, 4.0)
        for tp in (7.0, 10.0, 13.0)
    ]
    return scatter_from_rows(rows)


@pytest.fixture(scope="module")
def serial(scene, scatter):
    return run_cases(scene, scatter, fatigue=FATIGUE)


def _assert_same_bits(a, b):
    assert [r.status for r in a.rows] == [r.status for r in b.rows]
    for ln in a.lines:
        for e in ("end_a", "end_b"):
            np.testing.assert_array_equal(a.stats[ln][e], b.stats[ln][e])
        np.testing.assert_array_equal(a.damage_rate_ends[ln], b.damage_rate_ends[ln])
        np.testing.assert_array_equal(a.damage_rate_along[ln], b.damage_rate_along[ln])
        assert a.totals[ln].return_level == b.totals[ln].return_level
        assert a.totals[ln].annual_damage["end_b"] == b.totals[ln].annual_damage["end_b"]


def test_chunking_does_not_change_a_bit(scene, scatter, serial):
    done = []
    again = run_cases(
        scene, scatter, fatigue=FATIGUE, chunk_size=5, progress=lambda d, n: done.append((d, n))
    )
    _assert_same_bits(serial, again)
    assert done == [(5, 12), (10, 12), (12, 12)]


@pytest.mark.slow
def test_process_pool_gives_the_same_bits(scene, scatter, serial):
    ctx = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max_workers=2, mp_context=ctx) as pool:
        pooled = run_cases(scene, scatter, fatigue=FATIGUE, executor=pool)
    _assert_same_bits(serial, pooled)


@pytest.mark.slow
def test_dask_local_cluster_gives_the_same_bits(scene, scatter, serial):
    distributed = pytest.importorskip("distributed")
    with (
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        on_dask = run_cases(scene, scatter, fatigue=FATIGUE, client=client, chunk_size=3)
        # the same scene again on the same client, at once (a design loop; the service's
        # next batch): the first set's copy of the scene, released as it ends, must not
        # take the second set's copy with it ("lost dependencies" when the copies share
        # a key)
        again = [
            run_cases(scene, scatter, fatigue=FATIGUE, client=client, chunk_size=cs)
            for cs in (3, 4, 3)
        ]
    _assert_same_bits(serial, on_dask)
    for res in again:
        _assert_same_bits(serial, res)


def test_chunk_size_is_validated(scene, scatter):
    with pytest.raises(InputError, match="chunk_size"):
        run_cases(scene, scatter, chunk_size=0)


@pytest.mark.slow
def test_a_killed_dask_worker_costs_nothing(scene, scatter, serial):
    # One worker process is killed (SIGKILL) after the first chunks finish: its nanny
    # restarts it, the scheduler reruns the chunks it held, and the set completes with
    # every case, bit for bit the serial answer.
    distributed = pytest.importorskip("distributed")
    import os
    import signal

    with (
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        killed = []

        def kill_one(done: int, total: int) -> None:
            if done >= 2 and not killed:
                victim = sorted(client.scheduler_info()["workers"])[0]
                pid = client.run(os.getpid, workers=[victim])[victim]
                os.kill(pid, signal.SIGKILL)
                killed.append(victim)

        result = run_cases(
            scene, scatter, fatigue=FATIGUE, executor=client, chunk_size=1, progress=kill_one
        )
    assert killed
    _assert_same_bits(serial, result)
