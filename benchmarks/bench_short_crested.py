"""Cost of a short-crested sea: the chain example at a 30° mean heading (3-D models),
long-crested against cos-2s spreading (s = 4) in 4, 8 and 16 directions; and the
three-leg disc buoy example (a free body on three legs, Tuah 1982, §6.7) at 30°, its
excitation table extended over the whole circle (the disc is axisymmetric: the
heading-0 force and moment turned by the heading), long-crested against 4 and 16
directions.

    python3 benchmarks/bench_short_crested.py [--write]

Best of 9 of ``analyze()`` (no time series, the strumming screening off: it is not
what is measured) and of ``Engine.solve()`` of a built engine (the inputs of the
directions reused), one BLAS thread.  Goal (issue "Cables that strum and seas that
spread", issue 20): 16 directions ≤ 3× the long-crested analysis.  ``--write``
writes docs/benchmarks/short_crested.md.
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import time
import warnings
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from stochcable import runtime
from stochcable.analysis import analyze
from stochcable.dynamics.engine import build_engine
from stochcable.examples import load_example

DOC = Path(__file__).resolve().parents[1] / "docs" / "benchmarks" / "short_crested.md"


def _scene(directions: int | None) -> dict:
    d = load_example("chain_catenary").model_dump(mode="json", exclude_none=True)
    d["analysis"].pop("timeseries", None)
    d["sea"]["heading"] = 30.0
    for seg in d["lines"][0]["segments"]:
        seg["strumming"] = {"suppression": "strakes"}
    if directions:
        d["sea"]["spreading"] = {"type": "cos2s", "s": 4.0, "directions": directions}
    return d


def _buoy(directions: int | None) -> dict:
    """The three-leg disc buoy at a 30° mean heading, its excitation over the whole
    circle in 15° steps (axisymmetric disc: the heading-0 vectors turned about z)."""
    d = load_example("tuah_1982_disc_buoy_three_legs").model_dump(mode="json", exclude_none=True)
    d["analysis"].pop("timeseries", None)
    exc = d["bodies"][0]["hydrodynamics"]["excitation"]
    f0 = np.asarray(exc["re"], float)[0] + 1j * np.asarray(exc["im"], float)[0]
    heads = np.arange(0.0, 360.0, 15.0)
    rows = []
    for b in np.radians(heads):
        c, s = math.cos(b), math.sin(b)
        rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        rows.append(np.concatenate([rot @ f0[:3], rot @ f0[3:]]))
    rows = np.array(rows)
    exc.update(heading=heads.tolist(), re=rows.real.tolist(), im=rows.imag.tolist())
    d["sea"]["heading"] = 30.0
    if directions:
        d["sea"]["spreading"] = {"type": "cos2s", "s": 4.0, "directions": directions}
    return d


def _rows(make, counts) -> list[tuple[int | None, float, float]]:
    rows = []
    for k in counts:
        doc = make(k)
        engine = build_engine(doc)
        rows.append((k, _best(lambda doc=doc: analyze(doc)), _best(engine.solve)))
    return rows


def _table(rows) -> list[str]:
    base_a, base_s = rows[0][1], rows[0][2]
    out = [
        "| directions | `analyze()` [ms] | × long-crested | `Engine.solve()` [ms] "
        "| × long-crested |",
        "|---|---|---|---|---|",
    ]
    for k, a, s in rows:
        out.append(
            f"| {k or 'long-crested'} | {a * 1e3:.1f} | {a / base_a:.2f} | {s * 1e3:.1f} | "
            f"{s / base_s:.2f} |"
        )
    return out


def _best(fn, n: int = 9) -> float:
    fn()
    times = []
    for _ in range(n):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--write", action="store_true")
    args = ap.parse_args()
    runtime.configure()
    warnings.simplefilter("ignore")
    chain = _rows(_scene, (None, 4, 8, 16))
    buoy = _rows(_buoy, (None, 4, 16))
    lines = [
        "# Short-crested seas: cost",
        "",
        "`python3 benchmarks/bench_short_crested.py --write` — one BLAS thread, best of 9.",
        f"Machine: {platform.machine()}, {os.cpu_count()} cores.",
        "",
        "## Lines: the chain example",
        "",
        "At a 30° mean heading (3-D models), cos-2s spreading s = 4, the strumming",
        "screening off.",
        "",
        *_table(chain),
        "",
        "Each direction is an input channel of every line: the loads, the drag",
        "linearization's variance sums and the solves see one more column per direction;",
        "the model, the modes and the factorizations are shared, and an engine keeps the",
        "directions' kinematics for the next sea state of the same spreading.",
        "",
        "## A body: the three-leg disc buoy example",
        "",
        "The seed's §6.7 disc on three legs at a 30° mean heading, cos-2s spreading",
        "s = 4, the disc's excitation table over the whole circle (15° steps).",
        "",
        *_table(buoy),
        "",
        "Each direction excites the disc at its heading and loads the legs; the coupled",
        "drag fixed point is one over all directions (its substructured solves see one",
        "more column per direction), and an engine keeps the legs' kinematics per",
        "direction for the next sea state of the same spreading.",
        "",
    ]
    text = "\n".join(lines)
    print(text)
    if args.write:
        DOC.write_text(text)


if __name__ == "__main__":
    main()
