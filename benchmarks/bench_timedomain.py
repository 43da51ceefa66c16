"""Benchmark: nonlinear time-domain reference vs the frequency-domain analysis.

Chain catenary of DESIGN.md (850 m, 200 m depth, 40 elements) in a Pierson–Moskowitz
sea (Hs 6 m, Tp 10 s) with a random fairlead surge (Hs 2 m): the cost of the
time-domain simulation per simulated second, and the linearization error of σ of the
fairlead tension and of the motion of the node next to the fairlead (FD analysis with
statistically linearized drag vs the nonlinear TD driven by the same realizations).

Run: ``python benchmarks/bench_timedomain.py [--seeds 4] [--duration 600]``.
The sampling error of one record's σ̂ is estimated as var(σ̂)/σ² ≈ 1/(2 N_eff),
N_eff = T/∫ρ²dτ with ∫ρ²dτ = π∫S²dω/m0² from the FD spectrum.
"""

from __future__ import annotations

import argparse
import math
import sys
import time

import numpy as np


def _scene(elements: int):
    from stochcable.scene.model import load_scene

    return load_scene(
        {
            "environment": {"depth": 200.0, "seabed": {"stiffness": 3e6, "damping": 3e5}},
            "sea": {"spectrum": {"type": "pierson_moskowitz", "hs": 6.0, "tp": 10.0}},
            "lines": [
                {
                    "name": "leg1",
                    "end_a": {"position": [-800.0, 0.0, -200.0]},
                    "end_b": {
                        "position": [0.0, 0.0, -20.0],
                        "motion": {"surge": {"type": "pierson_moskowitz", "hs": 2.0, "tp": 10.0}},
                    },
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
            "analysis": {"solver": "direct", "omega": {"min": 0.05, "max": 3.0, "count": 300}},
        }
    )


def _rel_sampling_error(omega, s, record):
    m0 = np.trapezoid(s, omega)
    return math.sqrt(math.pi * np.trapezoid(s**2, omega) / m0**2 / (2.0 * record))


def main(argv: list[str] | None = None) -> int:
    from stochcable.analysis import analyze
    from stochcable.reference.cable import simulate_line_timedomain

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--elements", type=int, default=40)
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--duration", type=float, default=600.0)
    args = ap.parse_args(argv)

    scene = _scene(args.elements)
    t0 = time.perf_counter()
    res = analyze(scene)
    t_fd = time.perf_counter() - t0
    lr = res.lines["leg1"]
    node = -2
    fd = {
        "T_b": lr.end_b.std,
        "T_a": lr.end_a.std,
        "x_fl": lr.motion_std[node, 0],
        "z_fl": lr.motion_std[node, 2],
    }
    spectra = {
        "T_b": lr.end_tension_spectrum("end_b"),
        "T_a": lr.end_tension_spectrum("end_a"),
        "x_fl": lr.motion_spectrum[node, 0],
        "z_fl": lr.motion_spectrum[node, 2],
    }

    rows = []
    for seed in range(1, args.seeds + 1):
        t0 = time.perf_counter()
        h = simulate_line_timedomain(scene, duration=args.duration, seed=seed, band=(0.05, 3.0))
        wall = time.perf_counter() - t0
        ms = h.motion_std()
        rows.append(
            {
                "seed": seed,
                "wall": wall,
                "dt": h.dt,
                "ramp": h.ramp,
                "it": float(h.iterations[1:].mean()),
                "it_max": int(h.iterations.max()),
                "T_b": h.tension_statistics("b")["std"],
                "T_a": h.tension_statistics("a")["std"],
                "x_fl": ms[node, 0],
                "z_fl": ms[node, 2],
            }
        )
    record = args.duration - rows[0]["ramp"]
    print(f"chain catenary, {args.elements} elements, 2-D; FD analyze {t_fd:.2f} s")
    print(
        f"TD: dt = {rows[0]['dt']:.4f} s, ramp {rows[0]['ramp']:.0f} s, "
        f"record {record:.0f} s per seed"
    )
    print()
    print(
        f"{'seed':>4} {'wall s':>8} {'ms/sim s':>9} {'Newton it':>9} "
        f"{'σT_b kN':>9} {'σT_a kN':>9} {'σx_fl m':>8} {'σz_fl m':>8}"
    )
    for r in rows:
        print(
            f"{r['seed']:>4} {r['wall']:>8.2f} {1e3 * r['wall'] / args.duration:>9.1f} "
            f"{r['it']:>5.2f}/{r['it_max']:<3d} {r['T_b'] / 1e3:>9.2f} "
            f"{r['T_a'] / 1e3:>9.2f} {r['x_fl']:>8.4f} {r['z_fl']:>8.4f}"
        )
    print()
    print(f"{'quantity':>8} {'σ FD':>12} {'σ TD mean':>12} {'FD/TD-1':>9} {'±2 s.e.':>8}")
    n = len(rows)
    for key in ("T_b", "T_a", "x_fl", "z_fl"):
        td = float(np.mean([r[key] for r in rows]))
        se = _rel_sampling_error(lr.omega, spectra[key], record) / math.sqrt(n)
        print(f"{key:>8} {fd[key]:>12.5g} {td:>12.5g} {fd[key] / td - 1:>+9.2%} {2 * se:>8.2%}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
