"""The frequency domain of several lines on one free body against the nonlinear time
domain (:func:`stochcable.reference.cable_bodies.simulate_lines_on_body`, compared by
:func:`stochcable.reference.cable_bodies_compare.compare_lines_on_body`): the disc buoy
(Tuah 1982) on two mirrored planar legs and on three
(:func:`~stochcable.reference.cable_bodies_compare.planar_buoy`), at a small and a
moderate sea.

    OPENBLAS_NUM_THREADS=1 nice python3 benchmarks/bodies_timedomain.py \
        [--cases 2:3:0.1 2:3:0.5 3:3:0.1 3:3:0.5] [--seeds 4] [--duration 600]

A case is LEGS:ELEMENTS:M0 (legs, elements per leg, the sea's m0 in ft²).  Figures:
docs/accuracy/bodies.md, "Several legs on one buoy".
"""

from __future__ import annotations

import time

from body_timedomain import parser

from stochcable.errors import ConvergenceError
from stochcable.reference.cable_bodies_compare import compare_lines_on_body, planar_buoy


def main() -> None:
    ap = parser(__doc__, ["2:3:0.1", "2:3:0.5", "3:3:0.1", "3:3:0.5"], 4, 600.0)
    a = ap.parse_args()
    print(  # noqa: T201
        "| legs | elements | m0 [ft²] | record | FD default | FD linear | TD (95 %) "
        "| default/TD − 1 | linear/TD − 1 | offset δ | raw TD |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|"
    )
    for case in a.cases:
        legs, nel, m0 = case.split(":")
        t0 = time.process_time()
        try:
            r = compare_lines_on_body(
                planar_buoy(float(m0), int(nel), int(legs)), seeds=a.seeds, duration=a.duration
            )
        except ConvergenceError as exc:
            print(f"| {legs} | {nel} | {m0} | TD failed: {exc} |", flush=True)  # noqa: T201
            continue
        for k, (td, half) in r.td.items():
            fc, fl = r.fd_default[k], r.fd_linear[k]
            print(  # noqa: T201
                f"| {legs} | {nel} | {m0} | {k} | {fc:.4g} | {fl:.4g} | {td:.4g} ± {half:.2g} | "
                f"{100 * (fc / td - 1):+.1f} % | {100 * (fl / td - 1):+.1f} % | "
                f"{100 * r.offset[k]:+.1f} % | {r.raw[k].mean():.4g} |",
                flush=True,
            )
        print(f"<!-- {case}: {time.process_time() - t0:.0f} s CPU -->", flush=True)  # noqa: T201


if __name__ == "__main__":
    main()
