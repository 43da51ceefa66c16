"""Benchmark of the FE statics against the closed-form elastic catenary.

Cases: the DESIGN.md chain leg (850 m, 3-D, end_b off the x axis) and the very slack
leg (960 m over an 800 m span, most of the line on the seabed), forced FE, for 20 to
800 elements: median time, Newton iterations, relative error of the end_b tension and
touchdown difference against the catenary (stochcable.line.catenary; the FE-catenary gap is
the O(1/n²) lumping error plus, with seabed contact, the touchdown resolution).

Run: python benchmarks/bench_statics.py
"""

from __future__ import annotations

import statistics
import time

from stochcable.line.mesh import mesh_line
from stochcable.line.statics import solve_fe, solve_line_statics
from stochcable.scene.model import load_scene

CASES = {
    "chain 850 m": (850.0, [-640.0, -480.0, -200.0]),
    "very slack 960 m": (960.0, [-800.0, 0.0, -200.0]),
}


def chain(length: float, end_a: list[float], elements: int):
    scene = load_scene(
        {
            "environment": {"depth": 200.0},
            "lines": [
                {
                    "name": "leg1",
                    "end_a": {"position": end_a},
                    "end_b": {"position": [0.0, 0.0, -20.0]},
                    "segments": [
                        {
                            "length": length,
                            "ea": 1.2326e9,
                            "mass": 288.0,
                            "diameter": 0.216,
                            "elements": elements,
                        }
                    ],
                }
            ],
        }
    )
    env = scene.environment
    return mesh_line(scene.lines[0], env.rho, env.g), env


def median_time(fn, repeat: int = 7) -> float:
    fn()
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def main() -> None:
    for name, (length, end_a) in CASES.items():
        print(f"\n{name}")
        print(
            f"{'elements':>8} {'fe [ms]':>9} {'3-DOF [ms]':>11} {'iter':>5} "
            f"{'cat [ms]':>9} {'T_b fe/cat-1':>13} {'T_a fe/cat-1':>13} {'d_td [m]':>9}"
        )
        for n in (20, 50, 100, 200, 400, 800):
            mesh, env = chain(length, end_a, n)
            t2 = median_time(lambda: solve_line_statics(mesh, env, method="fe"))
            t3 = median_time(lambda: solve_fe(mesh, env, None, 1e-10, 500, force_3d=True))
            tc = median_time(lambda: solve_line_statics(mesh, env, method="catenary"))
            r = solve_line_statics(mesh, env, method="fe")
            c = solve_line_statics(mesh, env, method="catenary")
            dtd = (r.touchdown - c.touchdown) if (r.touchdown and c.touchdown) else float("nan")
            print(
                f"{n:8d} {t2 * 1e3:9.2f} {t3 * 1e3:11.2f} {r.iterations:5d} "
                f"{tc * 1e3:9.2f} {r.tension_b / c.tension_b - 1:13.2e} "
                f"{r.tension_a / c.tension_a - 1:13.2e} {dtd:9.3f}"
            )
    print("\n(MoorPy's catenary on the same line: python benchmarks/bench_moorpy.py)")


if __name__ == "__main__":
    main()
