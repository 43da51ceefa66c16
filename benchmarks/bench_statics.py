"""Benchmark of the FE statics: the DESIGN.md chain leg (3-D, end_b off the x axis),
forced FE, median time at 100 elements and the growth with the element count.

Run: python benchmarks/bench_statics.py
"""

from __future__ import annotations

import statistics
import time

from stochcable.mesh import mesh_line
from stochcable.scene import load_scene
from stochcable.statics import _solve_fe, solve_line_statics


def chain(elements: int):
    scene = load_scene({
        "environment": {"depth": 200.0},
        "lines": [{"name": "leg1", "end_a": {"position": [-640.0, -480.0, -200.0]},
                   "end_b": {"position": [0.0, 0.0, -20.0]},
                   "segments": [{"length": 850.0, "ea": 1.2326e9, "mass": 288.0,
                                 "diameter": 0.216, "elements": elements}]}]})
    env = scene.environment
    return mesh_line(scene.lines[0], env.rho, env.g), env


def median_time(fn, repeat: int = 15) -> float:
    fn()
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def main() -> None:
    print(f"{'elements':>8} {'fe 2-D [ms]':>12} {'fe 3-DOF [ms]':>14} {'iter':>5} "
          f"{'catenary [ms]':>14} {'T_b fe/cat - 1':>15}")
    for n in (20, 50, 100, 200, 400, 800):
        mesh, env = chain(n)
        t2 = median_time(lambda: solve_line_statics(mesh, env, method="fe"))
        t3 = median_time(lambda: _solve_fe(mesh, env, None, 1e-10, 500, force_3d=True))
        tc = median_time(lambda: solve_line_statics(mesh, env, method="catenary"))
        r = solve_line_statics(mesh, env, method="fe")
        c = solve_line_statics(mesh, env, method="catenary")
        print(f"{n:8d} {t2 * 1e3:12.2f} {t3 * 1e3:14.2f} {r.iterations:5d} "
              f"{tc * 1e3:14.2f} {r.tension_b / c.tension_b - 1:15.2e}")
    try:
        import moorpy  # noqa: F401
    except ImportError:
        print("moorpy not installed: comparison skipped")


if __name__ == "__main__":
    main()
