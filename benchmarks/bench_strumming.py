"""What the strumming screening adds to an analysis.

The chain example (`chain_catenary`: 40 elements, 0.5 m/s current, three candidate
modes) analysed with its screening and with every segment's strumming suppressed
(``"suppression": "strakes"``: no screening), in alternating rounds of ``--calls``
calls each (the host's speed drifts; alternating keeps the two paired), after a
warm-up (imports, the compiled lock-in grid); then the screening alone
(``with_strumming`` on the built line system) against the fastest analysis without
it: the load-robust figure.  Prints the median per call of each
round, the medians over rounds and the median of the rounds' ratios; the time series is off.

Run:  python benchmarks/bench_strumming.py [--rounds 7] [--calls 20]
"""

from __future__ import annotations

import argparse
import statistics
import time
import warnings

from host_probe import host_line

from stochcable.analysis import analyze
from stochcable.dynamics.engine import build_engine
from stochcable.dynamics.model.strumming import with_strumming
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
    ap.add_argument("--rounds", type=int, default=9)
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
        print(f"round {r + 1}: with {a * 1e3:.1f} ms, without {b * 1e3:.1f} ms, {a / b - 1:+.1%}")
    a = statistics.median(x for x, _ in rows)
    b = statistics.median(y for _, y in rows)
    ratios = sorted(x / y - 1 for x, y in rows)
    share = statistics.median(ratios)
    # the screening alone, on the built line system (short calls: the minimum is the
    # load-robust statistic), against the fastest analysis without it
    engine = build_engine(screened)
    system = next(iter(engine.systems.values()))
    alone = []
    for _ in range(20 * args.calls):
        t0 = time.perf_counter()
        with_strumming(screened, system)
        alone.append(time.perf_counter() - t0)
    fastest = min(_median_call(quiet, 1) for _ in range(3 * args.calls))
    print(
        f"screening alone: min {min(alone) * 1e3:.2f} ms, median "
        f"{statistics.median(alone) * 1e3:.2f} ms; fastest analysis without it "
        f"{fastest * 1e3:.1f} ms: {min(alone) / fastest:+.1%} (min/min)"
    )
    print("| with the screening | without | added | share: median of rounds (range) |")
    print("|---|---|---|---|")
    print(
        f"| {a * 1e3:.1f} ms | {b * 1e3:.1f} ms | {(a - b) * 1e3:.1f} ms "
        f"| {share:+.1%} ({ratios[0]:+.1%} … {ratios[-1]:+.1%}) |"
    )


if __name__ == "__main__":
    main()
