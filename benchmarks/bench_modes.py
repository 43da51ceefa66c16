"""Benchmark: finite-element assembly and natural modes (issue 3: statics + 30 modes
<= 50 ms, modes part <= 25 ms, for a 3-D 100-element line).

    python benchmarks/bench_modes.py [--quick]

Prints median (or, with --min, minimum) wall times [ms] of
1. statics + assemble + 30 modes of the DESIGN.md example chain (catenary with seabed
   contact, 100 elements, 3-D);
2. assemble and 30 modes versus element count 20…800 for that chain, with each
   eigen-solver ("dense", "banded", "sparse") and the "auto" choice;
3. the same for a line in an oblique vertical plane (no axis-aligned decoupling, one
   3·n_free block) — the worst case for the dense path.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from stochcable.line.fem import assemble, build_fe_model
from stochcable.line.modes import natural_modes
from stochcable.scene.model import load_scene


def chain_scene(elements: int, heading_deg: float = 0.0) -> dict:
    c, s = np.cos(np.radians(heading_deg)), np.sin(np.radians(heading_deg))
    return {
        "environment": {
            "depth": 200.0,
            "rho": 1025.0,
            "seabed": {"stiffness": 3.0e6, "damping": 3.0e5},
        },
        "lines": [
            {
                "name": "leg1",
                "end_a": {"position": [-800.0 * c, -800.0 * s, -200.0]},
                "end_b": {"position": [0.0, 0.0, -20.0]},
                "segments": [
                    {
                        "length": 850.0,
                        "ea": 1.2326e9,
                        "mass": 288.0,
                        "diameter": 0.216,
                        "cd_normal": 1.333,
                        "cd_axial": 0.2034,
                        "ca_normal": 1.0,
                        "elements": elements,
                    }
                ],
            }
        ],
    }


def median_ms(fun, repeat: int) -> float:
    """Median wall time [ms] (or the minimum with --min: robust on a loaded machine)."""
    fun()  # warm-up
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fun()
        times.append(time.perf_counter() - t0)
    return 1e3 * (min(times) if _USE_MIN else statistics.median(times))


_USE_MIN = False


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--quick", action="store_true", help="fewer repeats and sizes")
    parser.add_argument(
        "--min",
        action="store_true",
        help="report the minimum instead of the median (loaded machine)",
    )
    args = parser.parse_args()
    global _USE_MIN
    _USE_MIN = args.min
    repeat = 5 if args.quick else 21
    from stochcable.statics import solve_statics

    scene = load_scene(chain_scene(100))
    env = scene.environment

    def pipeline():
        ls = solve_statics(scene).lines["leg1"]
        return natural_modes(build_fe_model(ls, env, dim=3), count=30)

    ls = solve_statics(scene).lines["leg1"]
    model = build_fe_model(ls, env, dim=3)
    print("DESIGN example chain, 100 elements, 3-D, 30 modes (ms)")
    print(f"  statics                 {median_ms(lambda: solve_statics(scene), repeat):8.2f}")
    t_assemble = median_ms(lambda: build_fe_model(ls, env, dim=3), repeat)
    print(f"  assemble                {t_assemble:8.2f}")
    print(
        f"  30 modes (auto: {natural_modes(model, count=30).method:6s}) "
        f"{median_ms(lambda: natural_modes(model, count=30), repeat):8.2f}"
    )
    print(f"  statics+assemble+modes  {median_ms(pipeline, repeat):8.2f}")

    sizes = (20, 50, 100, 200, 400, 800) if not args.quick else (20, 100, 400)
    for heading, title in (
        (0.0, "chain in the x–z plane"),
        (35.0, "chain in a vertical plane at 35° (one coupled block)"),
    ):
        print(f"\n{title}: assemble and 30 modes vs elements (ms)")
        print(
            f"  {'n_el':>5} {'n_dof':>6} {'assemble':>9} {'dense':>8} {'banded':>8} "
            f"{'sparse':>8} {'auto':>8}"
        )
        for n in sizes:
            ls = solve_statics(load_scene(chain_scene(n, heading))).lines["leg1"]
            model = build_fe_model(ls, env, dim=3)
            t_asm = median_ms(
                lambda: assemble(
                    ls.mesh,
                    ls.positions,
                    ls.tension,
                    env.rho,
                    dim=3,
                    grounded=ls.grounded,
                    seabed=env.seabed,
                ),
                repeat,
            )
            row = []
            for method in ("dense", "banded", "sparse", "auto"):
                if method == "dense" and model.free.size > 1300:
                    row.append(float("nan"))
                    continue
                r = max(3, repeat // 4) if method == "dense" and n >= 400 else repeat
                row.append(median_ms(lambda: natural_modes(model, count=30, method=method), r))
            print(f"  {n:5d} {model.n_dof:6d} {t_asm:9.2f} " + " ".join(f"{t:8.2f}" for t in row))


if __name__ == "__main__":
    main()
