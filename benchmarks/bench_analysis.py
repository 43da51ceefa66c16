"""Benchmark of analyze() (issue 4, "Accuracy and speed").

The DESIGN.md reference chain (stochcable/examples/chain_catenary.json: 40 elements,
2-D, 200 frequencies to 2 rad/s, sea + fairlead surge channels, Foss with "auto"
modes), without the time series:

1. median (and min) wall time of analyze() and each stage's share, for Foss "auto",
   Foss with all modes and the direct solver;
2. fairlead (end_b) and anchor (end_a) tension σ versus elements (10–160), kept modes
   (all, auto, 10, 20) and frequency count (50–400), each with its time and its error
   relative to a converged reference: 320 elements, direct solve (= Foss with all
   modes), 800 frequencies on [0.05, 4] rad/s (the fairlead-surge inertia tension
   decays like ω⁻¹ beyond 2 rad/s, so the 2 rad/s grids also carry a cut-off error).

Run:  python benchmarks/bench_analysis.py [--quick]
"""

from __future__ import annotations

import argparse
import copy
import json
import statistics
import time
import warnings
from pathlib import Path

from host_probe import host_line

from stochcable.analysis import analyze
from stochcable.scene.model import load_scene

EXAMPLE = Path(__file__).resolve().parents[1] / "stochcable" / "examples" / "chain_catenary.json"


def base_doc() -> dict:
    doc = json.loads(EXAMPLE.read_text())
    doc["analysis"].pop("timeseries", None)
    return doc


def variant(
    doc: dict, *, elements=None, modes=None, count=None, solver=None, omega_max=None
) -> dict:
    d = copy.deepcopy(doc)
    if elements is not None:
        d["lines"][0]["segments"][0]["elements"] = elements
    if modes is not None:
        d["analysis"]["modes"] = modes
    if solver is not None:
        d["analysis"]["solver"] = solver
    if count is not None:
        d["analysis"]["omega"]["count"] = count
    if omega_max is not None:
        d["analysis"]["omega"]["max"] = omega_max
    return d


def timed(doc: dict, repeat: int):
    scene = load_scene(doc)
    times, cpu, stages = [], [], []
    res = None
    for _ in range(repeat + 1):
        t0, c0 = time.perf_counter(), time.process_time()
        res = analyze(scene)
        times.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
        stages.append(res.timing)
    times, cpu, stages = times[1:], cpu[1:], stages[1:]  # first call warms caches
    # process time is less sensitive than wall time to other processes on the cores
    return res, statistics.median(times), min(times), stages, statistics.median(cpu)


def sigmas(res) -> tuple[float, float]:
    line = next(iter(res.lines.values()))
    return line.end_a.std, line.end_b.std


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer repeats, smaller sweeps")
    args = ap.parse_args()
    repeat = 3 if args.quick else 15
    warnings.simplefilter("ignore")
    doc = base_doc()

    import os

    load = os.getloadavg()[0]
    print(host_line())
    print(
        f"load average (1 min) {load:.2f}"
        + ("" if load < 1.5 else "  -- machine busy: timings inflated")
    )
    print("== analyze() on the reference chain (no time series) ==")
    print(f"{'case':<22}{'median ms':>10}{'min ms':>9}{'cpu ms':>9}  stage shares (median)")
    for name, d in (
        ("foss, modes auto", doc),
        ("foss, all modes", variant(doc, modes=78)),
        ("direct", variant(doc, solver="direct")),
    ):
        res, med, mn, stages, cpu = timed(d, repeat)
        keys = ("statics_s", "model_s", "linearization_s", "outputs_s")
        share = {k: statistics.median(s[k] for s in stages) for k in keys}
        tot = statistics.median(s["total_s"] for s in stages)
        text = ", ".join(
            f"{k[:-2]} {1e3 * v:.1f} ms ({100 * v / tot:.0f} %)" for k, v in share.items()
        )
        it = res.lines["leg1"].linearization.iterations
        print(
            f"{name:<22}{1e3 * med:>10.1f}{1e3 * mn:>9.1f}{1e3 * cpu:>9.1f}  {text}; "
            f"{it} drag evaluations (coarse start and full grid)"
        )

    print("\n== error versus setting ==")
    print(
        "ref A: 320 el, direct, the example's grid (200 ω on [0.05, 2]) — isolates "
        "elements and modes"
    )
    print("ref B: 320 el, direct, 800 ω on [0.05, 4] — converged, includes the cut-off")
    ref_a, *_ = timed(variant(doc, elements=320, solver="direct"), 1)
    ref_b, *_ = timed(variant(doc, elements=320, solver="direct", count=800, omega_max=4.0), 1)
    refs = {"A": sigmas(ref_a), "B": sigmas(ref_b)}
    for k, (a, b) in refs.items():
        print(f"ref {k} σ_T: anchor {a:.1f} N, fairlead {b:.1f} N")
    print(
        f"{'setting':<36}{'ref':>4}{'median ms':>10}{'min ms':>9}{'err anchor':>12}"
        f"{'err fairlead':>14}"
    )

    def row(label: str, d: dict, ref: str) -> None:
        res, med, mn, *_ = timed(d, max(1, repeat // 3))
        a, b = sigmas(res)
        ra, rb = refs[ref]
        print(
            f"{label:<36}{ref:>4}{1e3 * med:>10.1f}{1e3 * mn:>9.1f}{a / ra - 1:>+12.2e}"
            f"{b / rb - 1:>+14.2e}"
        )

    for n in (10, 20, 40, 80) if args.quick else (10, 20, 40, 80, 160):
        row(f"elements {n} (foss auto)", variant(doc, elements=n), "A")
    for n in (10, 20, 40, 80) if args.quick else (10, 20, 40, 80, 160):
        row(f"elements {n} (direct)", variant(doc, elements=n, solver="direct"), "A")
    for m in ("all", "auto", 10, 20):
        row(f"modes {m} (40 el)", variant(doc, modes=78 if m == "all" else m), "A")
    for c in (50, 100, 200, 400):
        row(f"omega count {c} on [0.05, 2] (40 el)", variant(doc, count=c), "B")
    for c in (200, 400, 800):
        row(f"omega count {c} on [0.05, 4] (40 el)", variant(doc, count=c, omega_max=4.0), "B")


if __name__ == "__main__":
    main()
