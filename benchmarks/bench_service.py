"""Load benchmark of the stochcable HTTP service on 127.0.0.1 (bounded, ~30 s).

Starts ``uvicorn service.app:app`` in a subprocess on a free loopback port (so the
load generator does not share the server's GIL), then measures:

1. ``POST /v1/spectra`` (PM, default 200-point grid): p50/p99 latency of sequential
   requests and the throughput of a few concurrent clients.  Goal: p50 <= 5 ms.
2. A 2^20-sample realization (``duration = 2^20·0.25 s``, ``dt = 0.25 s``) answered as
   NumPy .npy (``Accept: application/x-npy``), round trip including decoding, against
   the library's own :func:`stochcable.sea.simulate_sea` time.  Goal: within 2x.
3. ``GET /health`` latency while clients keep asking for that realization.

Usage::

    python benchmarks/bench_service.py [--requests 400] [--quick]
"""

from __future__ import annotations

import argparse
import os
import socket
import subprocess
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor

import httpx
import numpy as np

PM = {"type": "pierson_moskowitz", "hs": 6.0, "tp": 10.0}
N_BIG = 2**20
DT = 0.25


def _free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _start_server(port: int) -> subprocess.Popen:
    env = {**os.environ, "STOCHCABLE_MAX_SAMPLES": str(2**22)}
    proc = subprocess.Popen(
        [sys.executable, "-m", "uvicorn", "service.app:app", "--host", "127.0.0.1",
         "--port", str(port), "--log-level", "warning", "--no-access-log"],
        env=env, stderr=subprocess.DEVNULL,
    )
    deadline = time.monotonic() + 30.0
    while time.monotonic() < deadline:
        try:
            httpx.get(f"http://127.0.0.1:{port}/health", timeout=1.0)
            return proc
        except httpx.TransportError:
            if proc.poll() is not None:
                raise SystemExit("uvicorn exited during start-up")
            time.sleep(0.1)
    proc.kill()
    raise SystemExit("uvicorn did not start within 30 s")


def _pct(samples: list[float], q: float) -> float:
    return float(np.percentile(np.asarray(samples), q))


def _fmt_ms(x: float) -> str:
    return f"{1e3 * x:8.2f} ms"


def bench_spectra(base: str, n: int, workers: int) -> dict:
    body = {"spectrum": PM}
    with httpx.Client(base_url=base, timeout=30.0) as c:
        for _ in range(20):  # warm-up: imports, pydantic caches, connection
            c.post("/v1/spectra", json=body).raise_for_status()
        lat = []
        for _ in range(n):
            t0 = time.perf_counter()
            c.post("/v1/spectra", json=body).raise_for_status()
            lat.append(time.perf_counter() - t0)

    def one(_: int) -> None:
        with httpx.Client(base_url=base, timeout=30.0) as c:
            for _ in range(n // workers):
                c.post("/v1/spectra", json=body).raise_for_status()

    t0 = time.perf_counter()
    with ThreadPoolExecutor(workers) as pool:
        list(pool.map(one, range(workers)))
    wall = time.perf_counter() - t0
    return {"p50": _pct(lat, 50), "p99": _pct(lat, 99),
            "throughput": workers * (n // workers) / wall}


def _big_body() -> dict:
    return {"spectrum": PM, "duration": N_BIG * DT, "dt": DT, "method": "dsa", "seed": 1}


def bench_realization(base: str, repeats: int) -> dict:
    from stochcable.scene import PiersonMoskowitz
    from stochcable.sea import simulate_sea

    spec = PiersonMoskowitz(**{k: v for k, v in PM.items() if k != "type"})
    local = []
    for _ in range(repeats + 1):
        t0 = time.perf_counter()
        sea = simulate_sea(spec.spectral_density, N_BIG * DT, DT, rng=1)
        local.append(time.perf_counter() - t0)
    from stochcable.client import Client

    remote = []
    with Client(base, timeout=120.0) as c:  # the user's path: npy, decoded without copy
        for _ in range(repeats + 1):
            t0 = time.perf_counter()
            res = c.realization(PM, duration=N_BIG * DT, dt=DT, seed=1)
            remote.append(time.perf_counter() - t0)
    if not np.array_equal(res.elevation, sea.elevation):
        raise SystemExit("service and library realizations differ")
    local_t, remote_t = min(local[1:]), min(remote[1:])  # first call plans the FFT
    return {"local": local_t, "remote": remote_t, "ratio": remote_t / local_t,
            "bytes": 16 * N_BIG + 128}


def bench_health_under_load(base: str, n: int, heavy_clients: int) -> dict:
    stop = threading.Event()
    heavy_done = [0]

    def heavy() -> None:
        headers = {"Accept": "application/x-npy", "Accept-Encoding": "identity"}
        with httpx.Client(base_url=base, timeout=120.0) as c:
            while not stop.is_set():
                c.post("/v1/sea/realizations", json=_big_body(), headers=headers)
                heavy_done[0] += 1

    threads = [threading.Thread(target=heavy, daemon=True) for _ in range(heavy_clients)]
    for t in threads:
        t.start()
    time.sleep(0.5)
    lat = []
    with httpx.Client(base_url=base, timeout=30.0) as c:
        for _ in range(n):
            t0 = time.perf_counter()
            c.get("/health").raise_for_status()
            lat.append(time.perf_counter() - t0)
            time.sleep(0.01)
    stop.set()
    for t in threads:
        t.join(120.0)
    return {"p50": _pct(lat, 50), "p99": _pct(lat, 99), "max": max(lat),
            "heavy": heavy_done[0]}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--requests", type=int, default=400,
                        help="sequential /v1/spectra requests (default 400)")
    parser.add_argument("--quick", action="store_true", help="fewer repetitions")
    args = parser.parse_args(argv)
    n = 100 if args.quick else max(20, args.requests)
    repeats = 2 if args.quick else 4

    port = _free_port()
    base = f"http://127.0.0.1:{port}"
    proc = _start_server(port)
    try:
        s = bench_spectra(base, n, workers=4)
        print(f"POST /v1/spectra        p50 {_fmt_ms(s['p50'])}  p99 {_fmt_ms(s['p99'])}  "
              f"throughput {s['throughput']:7.0f} req/s (4 clients)   goal p50 <= 5 ms: "
              f"{'ok' if s['p50'] <= 5e-3 else 'MISSED'}")
        r = bench_realization(base, repeats)
        print(f"2^20-sample realization  library {_fmt_ms(r['local'])}  service npy "
              f"{_fmt_ms(r['remote'])}  ratio {r['ratio']:5.2f}  ({r['bytes'] / 2**20:.1f} MiB)"
              f"   goal <= 2x: {'ok' if r['ratio'] <= 2.0 else 'MISSED'}")
        h = bench_health_under_load(base, 100 if args.quick else 200, heavy_clients=2)
        print(f"GET /health under load   p50 {_fmt_ms(h['p50'])}  p99 {_fmt_ms(h['p99'])}  "
              f"max {_fmt_ms(h['max'])}  ({h['heavy']} heavy realizations meanwhile)")
    finally:
        proc.terminate()
        try:
            proc.wait(10.0)
        except subprocess.TimeoutExpired:
            proc.kill()
    return 0


if __name__ == "__main__":
    sys.exit(main())
