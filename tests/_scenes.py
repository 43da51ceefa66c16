"""Scene pieces shared by several test modules."""

from __future__ import annotations

import math


def three_chain_legs(n_el: int, attach: str | None = None) -> list[dict]:
    """Three 330 m chain legs (EA 5e8 N, 100 kg/m, D 0.1 m) at 0/120/240° from anchors
    at radius 300 m on the seabed at 100 m depth to fairleads at radius 5 m, z = −2 m:
    fixed positions, or points of the body ``attach`` (relative to its reference point
    at the origin). The three-leg buoy of benchmarks/bench_bodies.py."""
    lines = []
    for i in range(3):
        a = math.radians(120.0 * i)
        fair = [5.0 * math.cos(a), 5.0 * math.sin(a), -2.0]
        lines.append(
            {
                "name": f"leg{i + 1}",
                "end_a": {"position": [300.0 * math.cos(a), 300.0 * math.sin(a), -100.0]},
                "end_b": (
                    {"position": fair}
                    if attach is None
                    else {"attach": {"body": attach, "point": fair}}
                ),
                "segments": [
                    {"length": 330.0, "ea": 5e8, "mass": 100.0, "diameter": 0.1, "elements": n_el}
                ],
            }
        )
    return lines
