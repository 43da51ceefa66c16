"""Calibration of stochcable.cost: peak memory and time of real analyses against the
estimate (the table and constants in the stochcable.cost docstring).

Each case runs in a fresh subprocess (one BLAS thread, as the service's workers) and
reports the peak resident memory above the warmed-up process (the VmHWM, reset after
two small analyses that load the compiled kernels, minus the RSS then) and the wall
time, next to :func:`stochcable.estimate_cost`.

The linear model's constants are calibrated with the residuals off; ``--residuals``
measures the default analyses (the residuals on) against the whole estimate, whose
residual terms are an upper bound (stochcable.scene.residual_kinds).

Usage::

    python benchmarks/bench_cost.py [--quick] [--residuals]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

_MEASURE = """
import json, resource, sys, time, warnings
import psutil
import stochcable.runtime
stochcable.runtime.configure()
from stochcable.analysis import analyze
from stochcable.examples import load_example
warnings.simplefilter("ignore")
doc = json.loads(sys.argv[1])
# small analyses first: the compiled kernels are loaded once per process (their
# compiler's memory is not the analysis' arrays), as tests/test_cost.py measures
analyze(load_example("taut_wire"))
analyze(load_example("chain_catenary"))
import stochcable.dynamics.loads.kinematics_kernels  # (large grids' compiled kinematics)
try:  # reset the peak RSS (VmHWM) to the current RSS (Linux >= 4.0)
    with open("/proc/self/clear_refs", "w") as f:
        f.write("5")
    def peak():
        for line in open("/proc/self/status"):
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) * 1024
except OSError:
    def peak():
        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
base = psutil.Process().memory_info().rss
t0 = time.perf_counter()
analyze(doc)
t = time.perf_counter() - t0
print(json.dumps({"delta": peak() - base, "seconds": t}))
"""

CASES = [
    ("taut_wire", 200, 1000),
    ("taut_wire", 400, 1000),
    ("chain_catenary", 200, 1000),
    ("chain_catenary", 400, 1000),
    ("chain_catenary", 200, 3000),
    ("tuah_1982_disc_buoy_three_legs", 100, 1000),
    ("tuah_1982_disc_buoy_three_legs", 200, 1000),
]


def _doc(name: str, elements: int, count: int) -> dict:
    from stochcable.examples import load_example

    doc = load_example(name).model_dump(mode="json", exclude_unset=True)
    for line in doc["lines"]:
        for seg in line["segments"]:
            seg["elements"] = elements
    doc["analysis"]["omega"]["count"] = count
    doc["analysis"].pop("timeseries", None)
    return doc


def measure(doc: dict) -> dict:
    env = {**os.environ, "PYTHONPATH": str(ROOT), "OPENBLAS_NUM_THREADS": "1"}
    out = subprocess.run(
        [sys.executable, "-c", _MEASURE, json.dumps(doc)],
        capture_output=True,
        text=True,
        check=True,
        env=env,
        cwd=ROOT,
    )
    return json.loads(out.stdout.splitlines()[-1])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true", help="the first three cases only")
    parser.add_argument(
        "--residuals",
        action="store_true",
        help="the default analyses (the residuals on) against the whole estimate, "
        "instead of the linear model's calibration",
    )
    args = parser.parse_args(argv)
    from stochcable.cost import BASE_BYTES, estimate_cost

    if args.residuals:
        return _residual_table(CASES[:3] if args.quick else CASES)

    print(
        f"{'scene':32s} {'n_el':>5s} {'n_w':>6s} {'ch':>3s} {'ΔRSS MB':>8s} "
        f"{'est. MB':>8s} {'B/(node·ω·ch)':>14s} {'t s':>6s} {'est. s':>6s}"
    )
    for name, elements, count in CASES[:3] if args.quick else CASES:
        doc = _doc(name, elements, count)
        # the linear model's constants: the residuals' terms are bounded apart
        doc["analysis"].setdefault("linearization", {}).update(
            drag_residual=False, geometric_residual=False
        )
        est = estimate_cost(doc)
        got = measure(doc)
        node_w_ch = est.operations - est.samples * (1 + est.channels)  # n_ω Σ n_nodes n_ch
        per = (got["delta"] - BASE_BYTES) / node_w_ch
        print(
            f"{name:32s} {elements:5d} {count:6d} {est.channels:3d} {got['delta'] / 1e6:8.0f} "
            f"{est.memory_bytes / 1e6:8.0f} {per:14.0f} {got['seconds']:6.2f} {est.seconds:6.2f}"
        )
    return 0


def _residual_table(cases: list[tuple[str, int, int]]) -> int:
    """The default analyses' peak against the estimate with the residuals' bound."""
    from stochcable.cost import estimate_cost

    print(
        f"{'scene':32s} {'n_el':>5s} {'n_w':>6s} {'ΔRSS MB':>8s} {'est. MB':>8s} "
        f"{'residual MB':>11s} {'ratio':>6s}"
    )
    for name, elements, count in cases:
        doc = _doc(name, elements, count)
        est = estimate_cost(doc)
        got = measure(doc)
        print(
            f"{name:32s} {elements:5d} {count:6d} {got['delta'] / 1e6:8.0f} "
            f"{est.memory_bytes / 1e6:8.0f} {est.residual_bytes / 1e6:11.0f} "
            f"{got['delta'] / est.memory_bytes:6.2f}"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
