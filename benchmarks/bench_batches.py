"""Many cases, many processes: a 1,000-case load-case set of the chain example run
serially, on a Dask LocalCluster, and as a batch job of a real ``stochcable serve``.

    python3 benchmarks/bench_batches.py [--quick] [--write]

Reports the throughput of ``run_cases`` serial against a LocalCluster of 2 worker
processes (goal ≥ 1.8×) and against the machine's own ceiling for two workers (the set
split in halves run at once by two independent serial processes: a shared VM gives two
busy processes less than two cores), the executor's overhead per case (LocalCluster of 1
worker against serial, amortized; goal ≤ 1 ms), and, for a batch of the same set submitted to
``POST /v1/batches``, its wall time and the latency of ``GET /health`` polled while it
runs (p50, p99, max).  ``--write`` writes docs/benchmarks/batches.md; ``--quick`` runs
100 cases and never writes.
"""

from __future__ import annotations

import argparse
import os
import platform
import socket
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import httpx
import numpy as np

from stochcable import runtime
from stochcable.cases import LineFatigue, run_cases, scatter_from_rows
from stochcable.cases.chunk import prepare_worker
from stochcable.examples import load_example

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "benchmarks" / "batches.md"
FATIGUE = LineFatigue("dnv-studless", nominal_diameter=0.076)


def _rows(n: int) -> list[dict]:
    n_tp = 50 if n >= 500 else 10
    n_hs = n // n_tp
    return [
        {"hs": hs, "tp": tp, "heading": 0.0, "hours": 1.0}
        for hs in np.linspace(0.5, 10.0, n_hs)
        for tp in np.linspace(5.0, 17.0, n_tp)
    ]


def _timed(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def _time_chunks_here() -> None:
    """In a worker: time every solve_chunk it runs (the tasks resolve the function by
    name in the worker, so they call this wrapper); ``_chunk_seconds`` reads the sum."""
    import stochcable.cases.chunk as chunk

    if getattr(chunk.solve_chunk, "_timed", False):
        return
    inner = chunk.solve_chunk

    def timed(*args, **kw):
        t0 = time.perf_counter()
        try:
            return inner(*args, **kw)
        finally:
            chunk._bench_seconds = getattr(chunk, "_bench_seconds", 0.0) + (
                time.perf_counter() - t0
            )

    timed._timed = True
    chunk.solve_chunk = timed


def _chunk_seconds(reset: bool = False) -> float:
    import stochcable.cases.chunk as chunk

    out = getattr(chunk, "_bench_seconds", 0.0)
    if reset:
        chunk._bench_seconds = 0.0
    return out


def library(scene, rows, repeats: int) -> dict[str, list[float]]:
    """Wall times [s] of run_cases serial, on LocalClusters of 1 and 2 workers and of the
    two-process ceiling (:func:`ceiling`), ``repeats`` rounds interleaved (the machine's
    speed drifts: each round measures all four under the same conditions; one cluster
    at a time, as idle Dask processes poll their memory every 100 ms)."""
    import distributed

    sd = scatter_from_rows(rows)
    run_cases(scene, scatter_from_rows(rows[:4]), fatigue=FATIGUE)  # warm-up
    out: dict[str, list[float]] = {
        "serial": [], "cluster1": [], "cluster2": [], "ceiling": [], "computing1": []
    }  # fmt: skip
    for _ in range(repeats):
        out["serial"].append(_timed(lambda: run_cases(scene, sd, fatigue=FATIGUE)))
        for workers in (1, 2):
            with (
                distributed.LocalCluster(n_workers=workers, threads_per_worker=1,
                                         dashboard_address=None) as cluster,
                distributed.Client(cluster) as client,
            ):  # fmt: skip
                client.run(prepare_worker)  # as the CLI and the service do
                # warm every worker (its engine, as the serial run's warm-up builds one)
                warm = scatter_from_rows(rows[: 4 * workers])
                run_cases(scene, warm, fatigue=FATIGUE, executor=client, chunk_size=1)
                client.run(_time_chunks_here)
                client.run(_chunk_seconds, True)
                out[f"cluster{workers}"].append(
                    _timed(lambda c=client: run_cases(scene, sd, fatigue=FATIGUE, executor=c))
                )
                if workers == 1:  # the time the worker spent inside the chunks
                    out["computing1"].append(sum(client.run(_chunk_seconds).values()))
        out["ceiling"].append(ceiling(rows))
    return out


_HALF = """
import json, sys, time, warnings
from stochcable import runtime
runtime.configure()
warnings.simplefilter("ignore")
from stochcable.cases import LineFatigue, run_cases, scatter_from_rows
from stochcable.examples import load_example
rows = json.loads(sys.argv[1])
fatigue = LineFatigue("dnv-studless", nominal_diameter=0.076)
scene = load_example("chain_catenary")
run_cases(scene, scatter_from_rows(rows[:4]), fatigue=fatigue)  # warm-up, as the serial run
sd = scatter_from_rows(rows)
print("ready", flush=True)
sys.stdin.readline()
t0 = time.perf_counter()
run_cases(scene, sd, fatigue=fatigue)
print(time.perf_counter() - t0, flush=True)
"""


def ceiling(rows) -> float:
    """Wall time of the set split in two halves run at once by two independent serial
    processes (no executor): the machine's own ceiling for two workers [s]."""
    import json

    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    halves = (rows[: len(rows) // 2], rows[len(rows) // 2 :])
    procs = [
        subprocess.Popen([sys.executable, "-c", _HALF, json.dumps(h)], env=env, text=True,
                         stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                         stderr=subprocess.DEVNULL)
        for h in halves
    ]  # fmt: skip
    for p in procs:
        assert p.stdout.readline().strip() == "ready"
    for p in procs:
        p.stdin.write("go\n")
        p.stdin.flush()
    walls = [float(p.stdout.readline()) for p in procs]
    for p in procs:
        p.wait(60)
    return max(walls)


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def service(scene, rows) -> dict[str, float]:
    """A batch of the set on a real server: wall time, /health latency while it runs."""
    port = _free_port()
    url = f"http://127.0.0.1:{port}"
    with tempfile.TemporaryDirectory() as tmp:
        env = {**os.environ, "PYTHONPATH": str(ROOT),
               "STOCHCABLE_JOBS_DATABASE": str(Path(tmp) / "jobs.sqlite")}  # fmt: skip
        proc = subprocess.Popen(
            [sys.executable, "-m", "stochcable", "serve", "--port", str(port),
             "--log-level", "warning"],
            env=env, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        )  # fmt: skip
        try:
            with httpx.Client(base_url=url, timeout=30) as http:
                for _ in range(600):
                    try:
                        if http.get("/health").status_code == 200:
                            break
                    except httpx.HTTPError:
                        time.sleep(0.2)
                body = {"scene": scene.model_dump(mode="json", exclude_unset=True),
                        "scatter": rows, "fatigue": {"curve": "dnv-studless",
                                                     "nominal_diameter": 0.076}}  # fmt: skip
                t0 = time.perf_counter()
                job = http.post("/v1/batches", json=body).json()
                lat = []
                status = job
                polls = 0
                while status["status"] in ("queued", "running"):
                    t1 = time.perf_counter()
                    http.get("/health")
                    lat.append(time.perf_counter() - t1)
                    polls += 1
                    if polls % 20 == 0:
                        status = http.get(f"/v1/batches/{job['id']}").json()
                    time.sleep(0.005)
                wall = time.perf_counter() - t0
                t2 = time.perf_counter()
                http.get(f"/v1/batches/{job['id']}/results")
                fetch = time.perf_counter() - t2
        finally:
            proc.terminate()
            proc.wait(30)
    ms = 1e3 * np.asarray(lat)
    return {"wall": wall, "status": status["status"], "fetch": fetch,
            "p50": float(np.percentile(ms, 50)), "p99": float(np.percentile(ms, 99)),
            "max": float(ms.max()), "polls": len(ms)}  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--write", action="store_true")
    args = ap.parse_args()
    runtime.configure()
    warnings.simplefilter("ignore")
    scene = load_example("chain_catenary")
    rows = _rows(100 if args.quick else 1000)
    n = len(rows)
    runs = library(scene, rows, 1 if args.quick else 3)
    lib = {k: float(np.median(v)) for k, v in runs.items()}
    top = lib["ceiling"]
    svc = service(scene, rows)
    # per round (the same conditions), then the median over the rounds
    rounds = [s_ / c for s_, c in zip(runs["serial"], runs["cluster2"])]
    per_round = [(c - s_) / n * 1e3 for s_, c in zip(runs["serial"], runs["cluster1"])]
    outside = float(
        np.median([(c - k) / n * 1e3 for c, k in zip(runs["cluster1"], runs["computing1"])])
    )
    speedup = float(np.median(rounds))
    overhead = float(np.median(per_round))
    top_speedup = float(np.median([s_ / t for s_, t in zip(runs["serial"], runs["ceiling"])]))
    lines = [
        f"cases {n} (chain example, Hs x Tp, JONSWAP, Dirlik fatigue); medians of "
        f"{len(rounds)} interleaved rounds",
        f"run_cases serial            {lib['serial']:7.2f} s  "
        f"{1e3 * lib['serial'] / n:6.2f} ms/case",
        f"LocalCluster 1 worker       {lib['cluster1']:7.2f} s  executor overhead "
        f"{overhead:+.2f} ms/case   goal <= 1 ms: {'ok' if overhead <= 1 else 'MISSED'}  "
        "(rounds: " + ", ".join(f"{o:+.2f}" for o in per_round) + ")",
        f"  of which outside the chunks  {outside:+.2f} ms/case (the executor's own work: "
        "wall time minus the time the worker spent in solve_chunk; the rest is the worker "
        "process computing at its own speed)",
        f"LocalCluster 2 workers      {lib['cluster2']:7.2f} s  speed-up {speedup:.2f}x   "
        f"goal >= 1.8x: {'ok' if speedup >= 1.8 else 'MISSED'}  (rounds: "
        + ", ".join(f"{r:.2f}x" for r in rounds)
        + ")",
        f"two serial processes at once {top:7.2f} s  speed-up {top_speedup:.2f}x   "
        f"(this machine's ceiling for two workers; LocalCluster at "
        f"{100 * speedup / top_speedup:.0f} % of it)",
        f"service batch (2 workers)   {svc['wall']:7.2f} s  {n / svc['wall']:6.1f} cases/s  "
        f"status {svc['status']}; results fetched in {1e3 * svc['fetch']:.0f} ms",
        f"GET /health during it       p50 {svc['p50']:6.2f} ms  p99 {svc['p99']:6.2f} ms  "
        f"max {svc['max']:6.2f} ms  ({svc['polls']} polls)",
    ]
    text = "\n".join(lines)
    print(text)
    if args.write and not args.quick:
        DOC.write_text(
            "# Batch throughput\n\nFigures of `benchmarks/bench_batches.py`: a "
            f"{n}-case load-case set of the chain example run by `run_cases` serially "
            "and on Dask LocalClusters (worker processes, one thread each), and as a "
            "batch job of a real `stochcable serve` (default settings: one batch worker "
            "process per core) while `GET /health` is polled.  Timings are noisy when "
            "the machine is shared: the rounds show the spread (the machine's own speed drifts "
            "by ±15 % between runs, and two busy processes do not always get two cores: "
            "the two-process ceiling measures what two workers can get at best).\n\n"
            f"Machine: {platform.machine()}, {os.cpu_count()} cores, Python "
            f"{platform.python_version()}.\n\nRegenerate with:\n\n"
            "    python benchmarks/bench_batches.py --write\n\n```\n" + text + "\n```\n",
            encoding="utf-8",
        )


if __name__ == "__main__":
    main()
