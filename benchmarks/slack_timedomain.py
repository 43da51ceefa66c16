"""The residuals of a slack leg against the nonlinear time domain: one leg of the disc
buoy (Tuah 1982) on the free buoy, its anchor span, length and the buoy's wind (the
leg's horizontal tension) varied, at a few element counts and seas
(:func:`stochcable.reference.cable_body_compare.compare_body_line`).  Beside the
default (both residuals) and the linear σ, the drag residual alone and the geometric
residual alone, and the first suspended element's static height above the bed.

    OPENBLAS_NUM_THREADS=1 nice python3 benchmarks/slack_timedomain.py \
        [--cases 20:0.25:250:289:71 21:0.25:250:289:71] [--seeds 3] [--duration 400]
        [--fd-only]

A case is ELEMENTS:M0:SPAN:LENGTH:WIND (elements, the sea's m0 in ft², the anchor's
horizontal distance from the fairlead in ft, the leg's length in ft, the wind on the
buoy in lbf).  Figures: docs/accuracy/bodies.md, "The slack leg's geometric residual".
"""

from __future__ import annotations

import time

from body_timedomain import fd, parser

from stochcable import load_example
from stochcable.errors import ConvergenceError
from stochcable.reference.cable_body_compare import ENDS, compare_body_line


def leg_scene(m0: float, elements: int, span: float, length: float, wind: float) -> dict:
    """The disc-buoy example with its leg's anchor ``span`` [ft] from the fairlead, the
    leg ``length`` [ft], the wind [lbf], the sea's m0 [ft²] and the element count."""
    doc = load_example("tuah_1982_disc_buoy_single_leg").model_dump(mode="json")
    doc["analysis"].pop("timeseries", None)
    doc["sea"]["spectrum"]["m0"] = m0
    seg = doc["lines"][0]["segments"][0]
    seg.update(elements=elements, length=length)
    doc["lines"][0]["end_a"]["position"][0] = doc["lines"][0]["end_b"]["attach"]["point"][0] - span
    doc["bodies"][0]["wind_force"][0] = wind
    return doc


def main() -> None:
    ap = parser(__doc__, ["20:0.25:250:289:71", "21:0.25:250:289:71"], 3, 400.0)
    ap.add_argument("--fd-only", action="store_true")
    a = ap.parse_args()
    print(  # noqa: T201
        "| case | end | FD linear | FD default | drag only | geometric only | TD (95 %) "
        "| default/TD − 1 | linear/TD − 1 | offset δ |\n|---|---|---|---|---|---|---|---|---|---|"
    )
    for case in a.cases:
        nel, m0, span, length, wind = case.split(":")
        doc = leg_scene(float(m0), int(nel), float(span), float(length), float(wind))
        t0 = time.perf_counter()
        lin = fd(doc, False, False)
        default = fd(doc, True, True)[0]
        drag, geo = fd(doc, True, False)[0], fd(doc, False, True)[0]
        td = None
        if not a.fd_only:
            try:
                td = compare_body_line(doc, default, lin, seeds=a.seeds, duration=a.duration)
            except ConvergenceError as exc:
                print(f"| {case} | TD failed: {exc} |", flush=True)  # noqa: T201
        for e in ENDS:
            fl = getattr(lin[0], e).std
            row = [getattr(x, e).std for x in (default, drag, geo)]
            cells = " | ".join(f"{s:.4g} ({100 * (s / fl - 1):+.1f} %)" for s in row)
            tail = "| | | |"
            if td is not None:
                s, half = td.td[e]
                tail = (
                    f"| {s:.4g} ± {half:.2g} | {100 * (row[0] / s - 1):+.1f} % "
                    f"| {100 * (fl / s - 1):+.1f} % | {100 * td.offset[e]:+.1f} % |"
                )
            print(f"| {case} | {e} | {fl:.4g} | {cells} {tail}", flush=True)  # noqa: T201
        print(f"<!-- {case}: {time.perf_counter() - t0:.0f} s -->", flush=True)  # noqa: T201


if __name__ == "__main__":
    main()
