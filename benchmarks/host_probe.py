"""Host-speed probe printed by the benchmarks, so runs on different days compare.

The 2-core cloud machine's speed drifts from day to day (the same commit measured
21 ms and 34 ms for the chain analysis on two days, docs/BENCHMARKS.md "Host speed").
Each benchmark prints this probe next to its numbers; a reader scales a result by
the ratio of probes before comparing it with a goal measured on another day.

The probe is two fixed workloads, each the minimum of 7 runs (the minimum is the
least load-sensitive statistic): a pure-Python loop (what Python-heavy stages such as
the model assembly and small-array kernels pay) and a NumPy/LAPACK kernel of the
size of the analyses' per-line work (78×78 real geev, as in a Foss decomposition).

Importing it also applies :func:`stochcable.runtime.configure` (one BLAS thread for
small models, the allocator pad, passive OpenMP waiting): the benchmarks measure with
the settings of the command line and the service.
"""

from __future__ import annotations

import time

import numpy as np

from stochcable import runtime

runtime.configure()

__all__ = ["host_probe", "host_line"]


def _best(fn, repeat: int = 7) -> float:
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def host_probe() -> dict[str, float]:
    """Minimum wall times of the probe workloads. [ms]

    Returns
    -------
    dict
        ``python_ms``: ``sum(range(10**6))``; ``geev_ms``: ``np.linalg.eig`` of a fixed
        78×78 real matrix (seeded); both minima of 7 runs.
    """
    a = np.random.default_rng(0).standard_normal((78, 78))
    return {
        "python_ms": 1e3 * _best(lambda: sum(range(10**6))),
        "geev_ms": 1e3 * _best(lambda: np.linalg.eig(a)),
    }


def host_line() -> str:
    """One printable line with the probe."""
    p = host_probe()
    return (
        f"host probe: python sum(range(1e6)) {p['python_ms']:.1f} ms, "
        f"78x78 geev {p['geev_ms']:.2f} ms (min of 7; compare runs by these)"
    )
