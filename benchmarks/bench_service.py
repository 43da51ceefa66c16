"""Load benchmark of the stochcable HTTP service on 127.0.0.1 (bounded, ~30 s).

Starts ``uvicorn service.app:app`` in a subprocess on a free loopback port (so the
load generator does not share the server's GIL), then measures:

1. ``POST /v1/spectra`` (PM, default 200-point grid): p50/p99 latency of sequential
   requests and the throughput of a few concurrent clients.  Goal: p50 <= 5 ms.
2. A 2^20-sample realization (``duration = 2^20·0.25 s``, ``dt = 0.25 s``) answered as
   NumPy .npy (``Accept: application/x-npy``), round trip including decoding, against
   the library's own :func:`stochcable.sea.realization.simulate_sea` time.  Goal: within 2x.
3. ``GET /health`` latency while clients keep asking for that realization.
4. ``POST /v1/analyses`` of the bundled ``chain_catenary`` scene (the start-up
   message's example): p50/p99 latency of sequential requests (JSON decoded) against
   the library's own :func:`stochcable.analysis.analyze` in this process (goal: p50
   within 1.5x), the throughput of 4 concurrent clients (the analyses run in
   ``STOCHCABLE_ANALYSIS_WORKERS`` worker processes, default the number of cores), and
   ``GET /health`` latency while 2 clients keep posting analyses (goal p99 <= 10 ms).
5. ``GET /health`` latency during one heavy analysis (the chain with 300 elements and
   3000 frequencies, ≈ 6 s in one worker; goal max <= 50 ms).
6. The per-request overhead of the process hop: a job that returns a result-sized
   document at once, through :class:`service.workers.WorkerPool` (send the scene,
   receive the bytes), against the same call in this process (goal <= 3 ms).

Usage::

    python benchmarks/bench_service.py [--requests 400] [--quick] [--write]

``--write`` (never with ``--quick``) writes the figures and this command into
``docs/benchmarks/service.md``.
"""

from __future__ import annotations

import argparse
import asyncio
import copy
import os
import platform
import socket
import subprocess
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import httpx
import numpy as np

DOC_PATH = Path(__file__).resolve().parents[1] / "docs" / "benchmarks" / "service.md"

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
        [
            sys.executable,
            "-m",
            "uvicorn",
            "service.app:app",
            "--host",
            "127.0.0.1",
            "--port",
            str(port),
            "--log-level",
            "warning",
            "--no-access-log",
        ],
        env=env,
        stderr=subprocess.DEVNULL,
    )
    deadline = time.monotonic() + 30.0
    while time.monotonic() < deadline:
        try:
            httpx.get(f"http://127.0.0.1:{port}/health", timeout=1.0)
            return proc
        except httpx.TransportError as err:
            if proc.poll() is not None:
                raise SystemExit("uvicorn exited during start-up") from err
            time.sleep(0.1)
    proc.kill()
    raise SystemExit("uvicorn did not start within 30 s")


def _server_s(resp: httpx.Response) -> float:
    """The service's own time from its ``Server-Timing: app;dur=<ms>`` header. [s]"""
    value = resp.headers.get("server-timing", "app;dur=nan")
    return float(value.split("dur=")[1]) / 1e3


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
    return {
        "p50": _pct(lat, 50),
        "p99": _pct(lat, 99),
        "throughput": workers * (n // workers) / wall,
    }


def _big_body() -> dict:
    return {"spectrum": PM, "duration": N_BIG * DT, "dt": DT, "method": "dsa", "seed": 1}


def bench_realization(base: str, repeats: int) -> dict:
    from stochcable.scene.model import PiersonMoskowitz
    from stochcable.sea.realization import simulate_sea

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
    server = []
    headers = {"Accept": "application/x-npy", "Accept-Encoding": "identity"}
    with httpx.Client(base_url=base, timeout=120.0) as c:
        for _ in range(repeats):
            server.append(
                _server_s(c.post("/v1/sea/realizations", json=_big_body(), headers=headers))
            )
    # first call plans the FFT; the minimum is the least disturbed by other load
    local_t, remote_t = min(local[1:]), min(remote[1:])
    local_med, remote_med = float(np.median(local[1:])), float(np.median(remote[1:]))
    return {
        "local": local_t,
        "remote": remote_t,
        "ratio": remote_t / local_t,
        "local_median": local_med,
        "server": min(server),
        "remote_median": remote_med,
        "ratio_median": remote_med / local_med,
        "bytes": 8 * N_BIG + 128,
    }  # the elevation column only (t_n = n·dt)


def _health_while(base: str, n: int, heavy_clients: int, post) -> dict:
    """/health latency while ``heavy_clients`` threads call ``post(client)`` in a loop."""
    stop = threading.Event()
    heavy_done = [0]

    def heavy() -> None:
        with httpx.Client(base_url=base, timeout=120.0) as c:
            while not stop.is_set():
                post(c)
                heavy_done[0] += 1

    threads = [threading.Thread(target=heavy, daemon=True) for _ in range(heavy_clients)]
    for t in threads:
        t.start()
    time.sleep(0.5)
    lat, server = [], []
    with httpx.Client(base_url=base, timeout=30.0) as c:
        for _ in range(n):
            t0 = time.perf_counter()
            resp = c.get("/health")
            resp.raise_for_status()
            lat.append(time.perf_counter() - t0)
            server.append(_server_s(resp))
            time.sleep(0.01)
    stop.set()
    for t in threads:
        t.join(120.0)
    return {
        "p50": _pct(lat, 50),
        "p99": _pct(lat, 99),
        "max": max(lat),
        "server_p99": _pct(server, 99),
        "heavy": heavy_done[0],
    }


def bench_health_under_load(base: str, n: int, heavy_clients: int) -> dict:
    headers = {"Accept": "application/x-npy", "Accept-Encoding": "identity"}
    return _health_while(
        base,
        n,
        heavy_clients,
        lambda c: c.post("/v1/sea/realizations", json=_big_body(), headers=headers),
    )


def _chain_body() -> bytes:
    from stochcable.examples import load_example

    return load_example("chain_catenary").model_dump_json().encode()


def bench_analyses(base: str, n: int, workers: int) -> dict:
    import warnings

    from stochcable.analysis import analyze
    from stochcable.examples import load_example

    scene = load_example("chain_catenary")
    local = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the example's known resolution warnings
        for _ in range(n + 2):
            t0 = time.perf_counter()
            analyze(scene)
            local.append(time.perf_counter() - t0)
    local = local[2:]  # first calls: imports, FFT plans
    body = _chain_body()
    headers = {"Content-Type": "application/json"}
    with httpx.Client(base_url=base, timeout=120.0) as c:
        for _ in range(2):
            c.post("/v1/analyses", content=body, headers=headers).raise_for_status()
        lat, server = [], []
        for _ in range(n):
            t0 = time.perf_counter()
            resp = c.post("/v1/analyses", content=body, headers=headers)
            resp.raise_for_status()
            resp.json()
            lat.append(time.perf_counter() - t0)
            server.append(_server_s(resp))

    per_worker = max(1, n // (2 * workers))

    def one(_: int) -> None:
        with httpx.Client(base_url=base, timeout=120.0) as c:
            for _ in range(per_worker):
                c.post("/v1/analyses", content=body, headers=headers).raise_for_status()

    t0 = time.perf_counter()
    with ThreadPoolExecutor(workers) as pool:
        list(pool.map(one, range(workers)))
    wall = time.perf_counter() - t0
    return {
        "p50": _pct(lat, 50),
        "p99": _pct(lat, 99),
        "local_p50": _pct(local, 50),
        "local_p99": _pct(local, 99),
        "ratio": _pct(lat, 50) / _pct(local, 50),
        "server_p50": _pct(server, 50),
        "throughput": workers * per_worker / wall,
    }


def bench_health_under_analyses(base: str, n: int, heavy_clients: int) -> dict:
    body = _chain_body()
    return _health_while(
        base,
        n,
        heavy_clients,
        lambda c: c.post(
            "/v1/analyses", content=body, headers={"Content-Type": "application/json"}
        ).raise_for_status(),
    )


def _heavy_body() -> bytes:
    import json

    from stochcable.examples import load_example

    doc = load_example("chain_catenary").model_dump(mode="json", exclude_unset=True)
    doc = copy.deepcopy(doc)
    doc["lines"][0]["segments"][0]["elements"] = 300
    doc["analysis"]["omega"]["count"] = 3000
    doc["analysis"].pop("timeseries", None)
    return json.dumps(doc).encode()


def bench_health_during_heavy(base: str, n: int) -> dict:
    """/health latency while one heavy analysis runs (one client, one worker)."""
    body = _heavy_body()
    return _health_while(
        base,
        n,
        1,
        lambda c: c.post(
            "/v1/analyses?timeseries=none",
            content=body,
            headers={"Content-Type": "application/json"},
        ).raise_for_status(),
    )


_RESULT_BYTES = 193_000  # the chain example's result document (JSON)


def echo_job(scene: object) -> tuple[bytes, int]:
    """A worker job that answers at once with a result-sized document."""
    return b"x" * _RESULT_BYTES, 0


def bench_process_hop(n: int) -> dict:
    """Per-request overhead of running a job in a worker process instead of in-process."""
    from service.workers import WorkerPool
    from stochcable.examples import load_example

    scene = load_example("chain_catenary")
    pool = WorkerPool(1, 4, 2**30, 2**31)
    pool.start()

    async def hop() -> list[float]:
        out = []
        for _ in range(n + 5):
            t0 = time.perf_counter()
            await pool.run(echo_job, scene, deadline=time.monotonic() + 30.0, limit=30.0)
            out.append(time.perf_counter() - t0)
        return out[5:]

    try:
        remote = asyncio.run(hop())
    finally:
        pool.close()
    local = []
    for _ in range(n):
        t0 = time.perf_counter()
        echo_job(scene)
        local.append(time.perf_counter() - t0)
    return {"p50": _pct(remote, 50) - _pct(local, 50), "p99": _pct(remote, 99)}


def _write_doc(lines: list[str], command: str) -> None:
    import psutil

    DOC_PATH.parent.mkdir(parents=True, exist_ok=True)
    machine = (
        f"{platform.machine()}, {os.cpu_count()} cores, "
        f"{psutil.virtual_memory().total / 1e9:.0f} GB, Python {platform.python_version()}"
    )
    text = (
        "# Service benchmark\n\n"
        "Figures of `benchmarks/bench_service.py` against a `uvicorn service.app:app` on "
        "127.0.0.1 (analyses in worker processes, default settings).  Timings are noisy "
        "when the machine is shared.\n\n"
        f"Machine: {machine}.\n\n"
        f"Regenerate with:\n\n    {command}\n\n"
        "```\n" + "\n".join(lines) + "\n```\n"
    )
    DOC_PATH.write_text(text, encoding="utf-8")
    print(f"wrote {DOC_PATH}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument(
        "--requests", type=int, default=400, help="sequential /v1/spectra requests (default 400)"
    )
    parser.add_argument("--quick", action="store_true", help="fewer repetitions")
    parser.add_argument(
        "--write", action="store_true", help=f"write the figures into {DOC_PATH.name}"
    )
    args = parser.parse_args(argv)
    lines: list[str] = []

    def report(line: str) -> None:
        print(line)
        lines.append(line)

    n = 100 if args.quick else max(20, args.requests)
    repeats = 2 if args.quick else 15

    port = _free_port()
    base = f"http://127.0.0.1:{port}"
    proc = _start_server(port)
    try:
        s = bench_spectra(base, n, workers=4)
        report(
            f"POST /v1/spectra        p50 {_fmt_ms(s['p50'])}  p99 {_fmt_ms(s['p99'])}  "
            f"throughput {s['throughput']:7.0f} req/s (4 clients)   goal p50 <= 5 ms: "
            f"{'ok' if s['p50'] <= 5e-3 else 'MISSED'}"
        )
        r = bench_realization(base, repeats)
        report(
            f"2^20-sample realization  library {_fmt_ms(r['local'])}  service npy "
            f"{_fmt_ms(r['remote'])}  ratio {r['ratio']:5.2f}  ({r['bytes'] / 2**20:.1f} MiB)"
            f"   goal <= 2x: {'ok' if r['ratio'] <= 2.0 else 'MISSED'}   (medians: "
            f"library {_fmt_ms(r['local_median'])}, service {_fmt_ms(r['remote_median'])}, "
            f"ratio {r['ratio_median']:5.2f}); "
            f"server-side time (Server-Timing) {_fmt_ms(r['server'])}"
        )
        h = bench_health_under_load(base, 100 if args.quick else 200, heavy_clients=2)
        report(
            f"GET /health under load   p50 {_fmt_ms(h['p50'])}  p99 {_fmt_ms(h['p99'])}  "
            f"max {_fmt_ms(h['max'])}  ({h['heavy']} heavy realizations meanwhile)"
        )
        a = bench_analyses(base, 10 if args.quick else 30, workers=4)
        report(
            f"POST /v1/analyses chain  p50 {_fmt_ms(a['p50'])}  p99 {_fmt_ms(a['p99'])}  "
            f"library analyze() p50 {_fmt_ms(a['local_p50'])}  p99 "
            f"{_fmt_ms(a['local_p99'])}  ratio {a['ratio']:5.2f}   goal <= 1.5x: "
            f"{'ok' if a['ratio'] <= 1.5 else 'MISSED'}   throughput "
            f"{a['throughput']:5.2f} analyses/s (4 clients); server-side p50 "
            f"{_fmt_ms(a['server_p50'])}"
        )
        h = bench_health_under_analyses(base, 100 if args.quick else 200, heavy_clients=2)
        report(
            f"GET /health under analyses p50 {_fmt_ms(h['p50'])}  p99 {_fmt_ms(h['p99'])}  "
            f"max {_fmt_ms(h['max'])}  ({h['heavy']} analyses meanwhile)   goal p99 <= 10 ms: "
            f"{'ok' if h['p99'] <= 10e-3 else 'MISSED'}; server-side p99 "
            f"{_fmt_ms(h['server_p99'])}"
        )
        h = bench_health_during_heavy(base, 100 if args.quick else 300)
        report(
            f"GET /health during a heavy analysis p50 {_fmt_ms(h['p50'])}  p99 "
            f"{_fmt_ms(h['p99'])}  max {_fmt_ms(h['max'])}   goal max <= 50 ms: "
            f"{'ok' if h['max'] <= 50e-3 else 'MISSED'}; server-side p99 "
            f"{_fmt_ms(h['server_p99'])}"
        )
    finally:
        proc.terminate()
        try:
            proc.wait(10.0)
        except subprocess.TimeoutExpired:
            proc.kill()
    hop = bench_process_hop(50 if args.quick else 200)
    report(
        f"process hop (scene out, 193 kB document back) overhead p50 {_fmt_ms(hop['p50'])}  "
        f"p99 {_fmt_ms(hop['p99'])}   goal <= 3 ms: {'ok' if hop['p50'] <= 3e-3 else 'MISSED'}"
    )
    if args.write and not args.quick:
        _write_doc(lines, "python benchmarks/bench_service.py --write")
    return 0


if __name__ == "__main__":
    sys.exit(main())
