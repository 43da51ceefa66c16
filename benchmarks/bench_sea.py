"""Benchmark: 2^20-sample DSA sea realization and the dispersion relation.

Run: ``python benchmarks/bench_sea.py [--tune]``.  ``--tune`` first measures the
2^20-point FFTW plans and saves them as wisdom (``stochcable.sea.fft.tune``, 15–35 s; the
file is ``stochcable.sea.fft.wisdom_path()``, set ``STOCHCABLE_FFTW_WISDOM`` to choose it or
to an empty value to run without wisdom).  Prints the median and the minimum over repeated
runs (timeit style: each sample is one call, wall clock), with pyfftw and with the
numpy.fft fallback, the load average before and after, and the minor page faults of one
realization in the steady state (result dropped, as in the timing loop) and when the
caller keeps its realizations.
Goals (docs/BENCHMARKS.md): realization <= 8 ms, dispersion of 10,000 ω <= 0.5 ms.
The coefficient kernel is compiled with numba when it is installed (the first
realization of >= 2^16 lines imports numba and loads the kernel: time printed); the rows
marked [numpy kernel] run the same realizations with STOCHCABLE_NUMBA=0.
stochcable.sea.fft sets OMP_WAIT_POLICY=PASSIVE unless the environment sets a policy: the
numbers depend on it (see docs/BENCHMARKS.md).
"""

from __future__ import annotations

import os
import platform
import resource
import statistics
import sys
import time

import numpy as np
from host_probe import host_line

from stochcable.sea import fft as _fft
from stochcable.sea import realization as sea
from stochcable.sea.kinematics import wavenumber
from stochcable.sea.spectra import spectrum_jonswap, spectrum_pierson_moskowitz


def median_ms(fn, repeat: int, warmup: int = 2) -> tuple[float, float]:
    """(median, min) wall time [ms] of ``repeat`` calls after ``warmup`` calls."""
    for _ in range(warmup):
        fn()
    samples = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        samples.append(time.perf_counter() - t0)
    return 1e3 * statistics.median(samples), 1e3 * min(samples)


def minor_faults(fn, repeat: int, keep: bool) -> float:
    """Median minor page faults of one call (results dropped or kept)."""
    kept, counts = [], []
    for _ in range(repeat):
        f0 = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
        out = fn()
        counts.append(resource.getrusage(resource.RUSAGE_SELF).ru_minflt - f0)
        if keep:
            kept.append(out)
        del out
    return statistics.median(counts)


def main() -> None:
    n_t, dt = 2**20, 0.25
    duration = n_t * dt
    omega, _ = sea.frequency_grid(duration, dt)
    print(
        f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
        f"python {platform.python_version()}, numpy {np.__version__}"
    )
    print("load average before: {:.2f} {:.2f} {:.2f}".format(*os.getloadavg()))
    print(host_line())
    print(f"OMP_WAIT_POLICY={os.environ.get('OMP_WAIT_POLICY')}")
    if "--tune" in sys.argv[1:]:
        t0 = time.perf_counter()
        _fft.tune(n_t)
        print(f"FFTW plans of 2^20 points measured in {time.perf_counter() - t0:.1f} s")
    t0 = time.perf_counter()
    compiled = sea._compiled_kernel()
    t_load = time.perf_counter() - t0
    if compiled is None:
        print("coefficient kernel: numpy (numba not installed or STOCHCABLE_NUMBA=0)")
    else:
        import numba

        from stochcable.sea import kernels as _kernels

        print(
            f"coefficient kernel: numba {numba.__version__} (import + kernel "
            f"{'load from cache' if _kernels.CACHED else 'compile, no cache'}: "
            f"{1e3 * t_load:.0f} ms)"
        )
    wis = _fft.wisdom_path()
    print(
        "FFTW wisdom: "
        + ("off" if wis is None else f"{wis} ({'present' if os.path.exists(wis) else 'none'})")
    )

    def pm(w):
        return spectrum_pierson_moskowitz(w, 6.0, 10.0)

    def js(w):
        return spectrum_jonswap(w, 6.0, 10.0, 3.3)

    seeds = iter(range(10**6))
    rows = []

    def numpy_kernel(fn):  # the same call with STOCHCABLE_NUMBA=0 (NumPy kernel)
        def run():
            os.environ["STOCHCABLE_NUMBA"] = "0"
            try:
                return fn()
            finally:
                os.environ.pop("STOCHCABLE_NUMBA")

        return run

    if compiled is not None and "STOCHCABLE_NUMBA" not in os.environ:
        rows.append(
            (
                "simulate_sea PM, DSA, 2^20 samples [pyfftw, numpy kernel]",
                median_ms(
                    numpy_kernel(lambda: sea.simulate_sea(pm, duration, dt, "dsa", next(seeds))), 30
                ),
            )
        )
    for backend in ("pyfftw", "numpy"):
        saved = _fft._pyfftw
        if backend == "numpy":
            _fft._pyfftw = None
        try:
            rows.append(
                (
                    f"simulate_sea PM, DSA, 2^20 samples [{backend}]",
                    median_ms(lambda: sea.simulate_sea(pm, duration, dt, "dsa", next(seeds)), 30),
                )
            )
            rows.append(
                (
                    f"simulate_sea JONSWAP, DSA, 2^20 samples [{backend}]",
                    median_ms(lambda: sea.simulate_sea(js, duration, dt, "dsa", next(seeds)), 30),
                )
            )
            rows.append(
                (
                    f"simulate_sea PM, NSA, 2^20 samples [{backend}]",
                    median_ms(lambda: sea.simulate_sea(pm, duration, dt, "nsa", next(seeds)), 30),
                )
            )
            x = np.zeros(n_t // 2 + 1, complex)
            x[1:-1] = 1.0
            rows.append(
                (f"  irfft alone, 2^20 [{backend}]", median_ms(lambda: _fft.irfft(x, n_t), 30))
            )
        finally:
            _fft._pyfftw = saved
    rows.append(("  PM spectrum on 2^19+1 frequencies", median_ms(lambda: pm(omega), 30)))
    u = np.random.default_rng(0).random(n_t // 2 - 1)
    s_lines = pm(omega)[1:-1]
    out = np.empty(u.size, complex)
    fft_in = _fft.irfft_input(n_t)[1:-1]

    def kernel() -> None:  # amplitudes x phasors + FFT input, chunk by chunk, 1 thread
        for a in range(0, u.size, sea._CHUNK):
            b = min(a + sea._CHUNK, u.size)
            sea._phasor_chunk(u[a:b], s_lines[a:b], 1.0, out[a:b], None, fft_in[a:b], 1.0)

    rows.append(
        ("  coefficient kernel (table + series), 2^19, 1 thread [numpy]", median_ms(kernel, 30))
    )
    if compiled is not None:
        jbuf, empty = np.empty(sea._CHUNK), np.empty(0)

        def kernel_numba() -> None:  # the same, compiled
            for a in range(0, u.size, sea._CHUNK):
                b = min(a + sea._CHUNK, u.size)
                compiled(
                    u[a:b],
                    s_lines[a:b],
                    1.0,
                    empty,
                    empty,
                    sea._TABLE,
                    out[a:b],
                    fft_in[a:b],
                    1.0,
                    jbuf,
                )

        rows.append(
            (
                "  coefficient kernel (table + series), 2^19, 1 thread [numba]",
                median_ms(kernel_numba, 30),
            )
        )
    rows.append(
        ("  np.exp(-1j*theta), 2^19 (reference, not used)", median_ms(lambda: np.exp(-1j * u), 10))
    )
    rng = np.random.default_rng(0)
    rows.append(("  rng.random(2^19)", median_ms(lambda: rng.random(n_t // 2), 30)))

    w = np.linspace(0.01, 3.0, 10_000)
    rows.append(("wavenumber, 10,000 omega, h = 50 m", median_ms(lambda: wavenumber(w, 50.0), 300)))
    rows.append(("wavenumber, 10,000 omega, h = 5 m", median_ms(lambda: wavenumber(w, 5.0), 300)))
    rows.append(("wavenumber, 10,000 omega, deep", median_ms(lambda: wavenumber(w), 300)))
    k = wavenumber(w, 50.0)
    res = np.abs(9.80665 * k * np.tanh(50.0 * k) / w**2 - 1).max()

    width = max(len(r[0]) for r in rows)
    print(f"{'':<{width}}  {'median':>8}    {'min':>8}")
    for name, (med, low) in rows:
        print(f"{name:<{width}}  {med:8.3f} ms {low:8.3f} ms")
    print(f"dispersion max relative residual |g k tanh(kh)/w^2 - 1| = {res:.1e}")
    one = lambda: sea.simulate_sea(pm, duration, dt, "dsa", next(seeds))  # noqa: E731
    print(
        f"minor page faults per 2^20 realization: {minor_faults(one, 10, False):.0f} "
        f"(result dropped), {minor_faults(one, 10, True):.0f} (results kept; "
        f"4 KiB pages, fewer where transparent huge pages apply)"
    )
    print("load average after: {:.2f} {:.2f} {:.2f}".format(*os.getloadavg()))


if __name__ == "__main__":
    main()
