"""What the strumming screening adds to an analysis.

The chain example (`chain_catenary`: 40 elements, 0.5 m/s current, three candidate
modes) analysed with its screening and with every segment's strumming suppressed
(``"suppression": "strakes"``: no screening), in alternating rounds of ``--calls``
calls each (the host's speed drifts; alternating keeps the two paired), after a
warm-up (imports, the compiled lock-in grid).  Prints the median per call of each
round, the median over rounds and the added share; the time series is off.

Run:  python benchmarks/bench_strumming.py [--rounds 7] [--calls 20]
"""

from __future__ import annotations

import argparse
import statistics
import time
import warnings

from host_probe import host_line

from stochcable.analysis import analyze
from stochcable.examples import load_example
from stochcable.scene.model import load_scene


def _median_call(scene, calls: int) -> float:
    times = []
    for _ in range(calls):
        t0 = time.perf_counter()
        analyze(scene)
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--calls", type=int, default=20)
    args = ap.parse_args()
    warnings.simplefilter("ignore")
    doc = load_example("chain_catenary").model_dump(mode="json", exclude_none=True)
    doc["analysis"].pop("timeseries", None)
    screened = load_scene(doc)
    for seg in doc["lines"][0]["segments"]:
        seg["strumming"] = {"suppression": "strakes"}
    quiet = load_scene(doc)
    for s in (screened, quiet):
        analyze(s)
    print(host_line())
    rows = []
    for r in range(args.rounds):
        a, b = _median_call(screened, args.calls), _median_call(quiet, args.calls)
        rows.append((a, b))
        print(f"round {r + 1}: with {a * 1e3:.1f} ms, without {b * 1e3:.1f} ms, +{a / b - 1:.1%}")
    a = statistics.median(x for x, _ in rows)
    b = statistics.median(y for _, y in rows)
    ratios = sorted(x / y - 1 for x, y in rows)
    print("| with the screening | without | added | share (range over rounds) |")
    print("|---|---|---|---|")
    print(
        f"| {a * 1e3:.1f} ms | {b * 1e3:.1f} ms | {(a - b) * 1e3:.1f} ms "
        f"| +{a / b - 1:.1%} (+{ratios[0]:.1%} … +{ratios[-1]:.1%}) |"
    )

if __name__ == "__main__":
    main()
