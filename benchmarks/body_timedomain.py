"""The frequency domain of a line on a free body against the nonlinear time domain
(:func:`stochcable.reference.cable_body.simulate_line_on_body`, compared by
:func:`stochcable.reference.cable_body_compare.compare_body_line`): the disc buoy on one
leg (Tuah 1982, the bundled example), its leg at 20 elements and the example's 3, at
small seas and at the example's, 5 seeds.

    OPENBLAS_NUM_THREADS=1 nice python3 benchmarks/body_timedomain.py \
        [--cases 20:0.1 20:0.5 3:0.5 3:28] [--seeds 5] [--duration 600]

A case is ELEMENTS:M0 (the leg's element count, the sea's m0 in ft²).  Figures:
docs/accuracy/bodies.md.
"""

from __future__ import annotations

import argparse
import copy
import time
import warnings

from stochcable import analyze, load_example
from stochcable.errors import ConvergenceError
from stochcable.reference.cable_body_compare import ENDS, compare_body_line


def scene(m0: float, elements: int) -> dict:
    """The disc-buoy example with the sea's m0 [ft²] and the leg's element count."""
    doc = load_example("tuah_1982_disc_buoy_single_leg").model_dump(mode="json")
    doc["analysis"].pop("timeseries", None)
    doc["sea"]["spectrum"]["m0"] = m0
    doc["lines"][0]["segments"][0]["elements"] = elements
    return doc


def fd(doc: dict, residuals: bool, geometric: bool | None = None):
    """The leg's and the buoy's results with the residuals on or off (the geometric one
    as ``geometric`` when given)."""
    d = copy.deepcopy(doc)
    geo = residuals if geometric is None else geometric
    d["analysis"]["linearization"].update(drag_residual=residuals, geometric_residual=geo)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = analyze(d)
    return next(iter(res.lines.values())), next(iter(res.bodies.values()))


def parser(doc: str, cases: list[str], seeds: int, duration: float) -> argparse.ArgumentParser:
    """The time-domain benchmarks' arguments: --cases, --seeds, --duration (defaults
    given), the description the module docstring's first paragraph."""
    ap = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    ap.add_argument("--cases", nargs="+", default=cases)
    ap.add_argument("--seeds", type=int, default=seeds)
    ap.add_argument("--duration", type=float, default=duration)
    return ap


def main() -> None:
    ap = parser(__doc__, ["20:0.1", "20:0.5", "3:0.5", "3:28"], 5, 600.0)
    ap.add_argument("--seabed", default="linear")
    ap.add_argument("--internal-damping", type=float, default=0.0)
    a = ap.parse_args()
    print(  # noqa: T201
        "| elements | m0 [ft²] | end | FD default | FD linear | TD (95 %) | default/TD − 1 "
        "| linear/TD − 1 | offset δ | raw TD |\n|---|---|---|---|---|---|---|---|---|---|"
    )
    for case in a.cases:
        nel, m0 = case.split(":")
        doc = scene(float(m0), int(nel))
        t0 = time.perf_counter()
        try:
            r = compare_body_line(
                doc, fd(doc, True)[0], fd(doc, False), seeds=a.seeds, duration=a.duration,
                seabed=a.seabed, internal_damping=a.internal_damping,
            )  # fmt: skip
        except ConvergenceError as exc:
            print(f"| {nel} | {m0} | TD failed: {exc} |", flush=True)  # noqa: T201
            continue
        for e in ENDS:
            td, half = r.td[e]
            print(  # noqa: T201
                f"| {nel} | {m0} | {e} | {r.fd_default[e]:.4g} | {r.fd_linear[e]:.4g} | "
                f"{td:.4g} ± {half:.2g} | {100 * (r.fd_default[e] / td - 1):+.1f} % | "
                f"{100 * (r.fd_linear[e] / td - 1):+.1f} % | {100 * r.offset[e]:+.1f} % | "
                f"{r.raw[e].mean():.4g} |",
                flush=True,
            )
        for k, (f, td, half) in r.motion.items():
            print(  # noqa: T201
                f"| {nel} | {m0} | {k} | {f:.4g} | | {td:.4g} ± {half:.2g} | "
                f"{100 * (f / td - 1):+.1f} % | | {100 * r.offset[k]:+.1f} % | "
                f"{r.raw[k].mean():.4g} |",
                flush=True,
            )
        print(f"<!-- {case}: {time.perf_counter() - t0:.0f} s -->", flush=True)  # noqa: T201


if __name__ == "__main__":
    main()
