"""Benchmark: stochcable against MoorPy (an independent implementation) on the DESIGN.md chain.

    python benchmarks/bench_moorpy.py [--quick]

MoorPy (NREL, >= 1.2 for ``Line.dynamicSolve``) is not a dependency of stochcable: without
it the script prints stochcable's side only and says that the comparison was skipped.

Line (DESIGN.md example): chain 850 m, 288 kg/m in air, volume-equivalent diameter
0.216 m, EA 1.2326e9 N, depth 200 m, anchor (−800, 0, −200) on the seabed, fairlead
(0, 0, −20); ρ 1025 kg/m³, g 9.80665 m/s² (MoorPy's System default g = 9.81 is
overridden; its wet weight w = (m − ρπD²/4) g is computed from the same m, D, ρ, g).

1. Statics (issue 3): end tensions and touchdown of MoorPy's elastic catenary
   (``Line.staticSolve``: anchor and fairlead are fixed Points of a System) against
   stochcable's closed-form catenary and its FE Newton solve (40 and 100 elements),
   with wall times.
2. Dynamics (issue 4): MoorPy's frequency-domain lumped-mass model (``Line.dynamicSolve``)
   against ``stochcable.analyze`` on the same input: fairlead surge with a PM motion
   spectrum Hs 2 m, Tp 10 s (σx = 0.5 m), no sea, no current (MoorPy's dynamic model
   has neither), 200 frequencies on [0.05, 2] rad/s, 40 elements, Cdn 1.333,
   Cd_axial 0.2034 on πD (MoorPy ``CdAx`` is referred to D, so CdAx = 0.2034π),
   Can 1, no axial added mass (MoorPy ``CaAx`` = 0), seabed k 3e6 Pa/m and c 3e5 Pa·s/m
   per contact area (MoorPy's kbot, cbot are per node: k·D·Δs with Δs = 850/40 m; the
   literal kbot = 3e6 N/m, cbot = 3e5 N·s/m are run as a sensitivity case).
   Reported: σ of the fairlead and anchor tension from both codes (stochcable: the
   reaction-based end tension and the end elements' EA-strain tension, which is MoorPy's
   definition), linearization iterations and wall times.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import time
import warnings
from pathlib import Path

import numpy as np

from stochcable.analysis import analyze
from stochcable.scene.model import load_scene
from stochcable.statics import solve_statics

EXAMPLE = Path(__file__).resolve().parents[1] / "stochcable" / "examples" / "chain_catenary.json"
DEPTH, RHO, G = 200.0, 1025.0, 9.80665
LENGTH, MASS, DIAMETER, EA = 850.0, 288.0, 0.216, 1.2326e9
CDN, CDT, CAN = 1.333, 0.2034, 1.0
K_BED, C_BED = 3.0e6, 3.0e5
ANCHOR, FAIRLEAD = [-800.0, 0.0, -200.0], [0.0, 0.0, -20.0]


def timed(fun, repeat: int) -> tuple[float, float, object]:
    """(median [s], min [s], last result) of ``repeat`` calls after one warm-up (one
    timed call without warm-up for ``repeat`` = 0)."""
    if repeat == 0:
        t0 = time.perf_counter()
        out = fun()
        t = time.perf_counter() - t0
        return t, t, out
    out = fun()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fun()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), min(times), out


def dynamic_scene(elements: int = 40) -> dict:
    """chain_catenary.json without sea, current and time series (end motion only)."""
    doc = json.loads(EXAMPLE.read_text())
    doc.pop("sea", None)
    doc["environment"].pop("current", None)
    doc["analysis"].pop("timeseries", None)
    doc["lines"][0]["segments"][0]["elements"] = elements
    return doc


def static_scene(elements: int) -> dict:
    doc = dynamic_scene(elements)
    doc["lines"][0]["end_b"].pop("motion", None)
    return doc


# --- MoorPy ---------------------------------------------------------------------------


def moorpy_system(segments: int, g: float = G):
    import moorpy as mp

    ms = mp.System(depth=DEPTH, rho=RHO, g=g)
    ms.addPoint(1, np.array(ANCHOR))
    ms.addPoint(1, np.array(FAIRLEAD))
    line_type = dict(
        name="chain",
        m=MASS,
        d_vol=DIAMETER,
        EA=EA,
        w=(MASS - math.pi / 4 * DIAMETER**2 * RHO) * g,
        Cd=CDN,
        CdAx=CDT * math.pi,
        Ca=CAN,
        CaAx=0.0,
        MBL=0.0,
        cost=0.0,
        material="chain",
    )
    line = ms.addLine(LENGTH, line_type, nSegs=segments, pointA=1, pointB=2)
    ms.initialize()
    return ms, line


def moorpy_statics(repeat: int) -> dict:
    from moorpy.Catenary import catenary

    out = {}
    for g in (G, 9.81):
        ms, line = moorpy_system(40, g)
        t_med, t_min, _ = timed(lambda: line.staticSolve(reset=True), repeat)
        t_prof, _, _ = timed(lambda: line.staticSolve(reset=True, profiles=1), repeat)
        t_init, _, _ = timed(ms.initialize, max(3, repeat // 4))
        out[g] = dict(
            TA=float(line.TA),
            TB=float(line.TB),
            LBot=float(line.LBot),
            HF=float(line.HF),
            VF=float(line.VF),
            t=t_med,
            t_min=t_min,
            t_profiles=t_prof,
            t_initialize=t_init,
            w=float(line.w),
        )
    # seabed friction: Line.staticSolve sets cb = −depth − z_A = 0 for an anchor on the
    # seabed (MoorPy 1.3), so friction is shown through the catenary function directly
    w = out[G]["w"]
    for cb in (0.0, 0.3, 1.0):
        fAH, fAV, fBH, fBV, info = catenary(800.0, 180.0, LENGTH, EA, w, CB=cb, Tol=1e-6)
        out[f"cb={cb}"] = dict(
            TA=math.hypot(fAH, fAV), TB=math.hypot(fBH, fBV), LBot=float(info["LBot"])
        )
    return out


def moorpy_dynamics(
    omega: np.ndarray,
    s_surge: np.ndarray,
    segments: int,
    kbot: float,
    cbot: float,
    tol: float,
    repeat: int,
) -> dict:
    ms, line = moorpy_system(segments)
    n_w = omega.size
    rao_a = np.zeros((n_w, 3))
    rao_b = np.zeros((n_w, 3))
    rao_b[:, 0] = 1.0  # fairlead surge per unit of the "wave" whose spectrum is S_surge

    def run():
        # conv_time=False: MoorPy prints nothing; iterations are counted below
        return line.dynamicSolve(omega, s_surge, rao_a, rao_b, DEPTH, kbot, cbot, tol=tol)

    # iterations: count the getDynamicMatrices calls (one before the loop, one per
    # non-final iteration) in one extra call, or in the single timed one
    calls = [0]
    original = line.getDynamicMatrices

    def counting(*a, **k):
        calls[0] += 1
        return original(*a, **k)

    line.getDynamicMatrices = counting
    t_med, t_min, res = timed(run, repeat) if repeat == 0 else (0.0, 0.0, run())
    line.getDynamicMatrices = original
    if repeat > 0:
        t_med, t_min, res = timed(run, repeat)
    T_amp, T_psd, T_std, s, r_static, r_dyn, r_tot, X = res
    return dict(
        std_a=float(T_std[0]),
        std_b=float(T_std[-1]),
        t=t_med,
        t_min=t_min,
        solves=calls[0],
        T_mean_a=float(line.TA),
        T_mean_b=float(line.TB),
    )


# --- stochcable -----------------------------------------------------------------------


def stochcable_statics(repeat: int) -> dict:
    out = {}
    for n in (40, 100):
        scene = load_scene(static_scene(n))
        for method in ("catenary", "fe"):
            t_med, t_min, res = timed(lambda: solve_statics(scene, method=method), repeat)
            ls = res.lines["leg1"]
            out[(method, n)] = dict(
                TA=float(ls.tension_a),
                TB=float(ls.tension_b),
                touchdown=ls.touchdown,
                t=t_med,
                t_min=t_min,
            )
    return out


def stochcable_dynamics(elements: int, repeat: int) -> dict:
    scene = load_scene(dynamic_scene(elements))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        t_med, t_min, res = timed(lambda: analyze(scene), repeat)
    line = res.lines["leg1"]
    return dict(
        std_a=float(line.end_a.std),
        std_b=float(line.end_b.std),
        el_std_a=float(line.tension_std[0]),
        el_std_b=float(line.tension_std[-1]),
        mean_a=float(line.end_a.mean),
        mean_b=float(line.end_b.mean),
        t=t_med,
        t_min=t_min,
        iterations=line.linearization.iterations,
        omega=np.asarray(line.omega),
        s_in=np.asarray(line.input_spectra[0]),
        warnings=sorted({type(w.message).__name__ for w in caught}),
    )


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--quick", action="store_true", help="fewer repetitions")
    parser.add_argument(
        "--diagnose",
        action="store_true",
        help="also run stochcable with a lumped mass matrix (MoorPy's)",
    )
    args = parser.parse_args()
    rep_fast, rep_slow = (5, 2) if args.quick else (41, 7)
    print(
        f"load average {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f} {os.getloadavg()[2]:.2f}"
    )
    try:
        import moorpy  # noqa: F401

        have_moorpy = True
    except ImportError:
        have_moorpy = False
        print(
            "MoorPy not importable: the MoorPy columns are skipped (pip install moorpy to compare)"
        )

    # 1. statics ---------------------------------------------------------------------
    print("\n1. Statics, end tensions [kN], touchdown [m from the anchor], time [ms] (median/min)")
    sc = stochcable_statics(rep_fast)
    for (method, n), r in sc.items():
        td = float("nan") if r["touchdown"] is None else r["touchdown"]
        print(
            f"  stochcable {method:8s} {n:3d} el"
            f"  T_a {r['TA'] / 1e3:9.3f}  T_b {r['TB'] / 1e3:9.3f}"
            f"  touchdown {td:7.2f}  {1e3 * r['t']:7.3f} / {1e3 * r['t_min']:.3f} ms"
        )
    if have_moorpy:
        mp_st = moorpy_statics(rep_fast)
        cat = sc[("catenary", 40)]
        for g in (G, 9.81):
            r = mp_st[g]
            print(
                f"  MoorPy staticSolve g={g:<7}  T_a {r['TA'] / 1e3:9.3f}  T_b {r['TB'] / 1e3:9.3f}"
                f"  touchdown {r['LBot']:7.2f}  {1e3 * r['t']:7.3f} / {1e3 * r['t_min']:.3f} ms"
                f"  (with profiles {1e3 * r['t_profiles']:.3f} ms, System.initialize"
                f" {1e3 * r['t_initialize']:.3f} ms)"
            )
            print(
                f"      vs stochcable catenary: T_a {r['TA'] / cat['TA'] - 1:+.2e}, "
                f"T_b {r['TB'] / cat['TB'] - 1:+.2e}, touchdown "
                f"{r['LBot'] - cat['touchdown']:+.3f} m"
            )
        for cb in (0.0, 0.3, 1.0):
            r = mp_st[f"cb={cb}"]
            print(
                f"  MoorPy catenary(), seabed friction cb={cb}: T_a {r['TA'] / 1e3:9.3f}  "
                f"T_b {r['TB'] / 1e3:9.3f}  L_bottom {r['LBot']:.2f}"
            )

    # 2. dynamics --------------------------------------------------------------------
    print("\n2. Fairlead surge PM Hs 2 m Tp 10 s, no sea/current: tension σ [kN], time [ms]")
    st = stochcable_dynamics(40, rep_slow)
    omega, s_in = st["omega"], st["s_in"]
    sigma_x = math.sqrt(np.trapezoid(s_in, omega))
    print(
        f"  grid {omega.size} ω on [{omega[0]:.3g}, {omega[-1]:.3g}] rad/s, "
        f"σx on the grid {sigma_x:.4f} m (trapezoid)"
    )
    print(
        f"  stochcable analyze, 40 el: "
        f"end σ_a {st['std_a'] / 1e3:.3f}, σ_b {st['std_b'] / 1e3:.3f}; "
        f"end elements σ_a {st['el_std_a'] / 1e3:.3f}, σ_b {st['el_std_b'] / 1e3:.3f}; "
        f"{st['iterations']} iterations; {1e3 * st['t']:.1f} / {1e3 * st['t_min']:.1f} ms; "
        f"warnings {st['warnings']}"
    )
    st160 = stochcable_dynamics(160, max(2, rep_slow // 2))
    print(
        f"  stochcable analyze, 160 el: end σ_a {st160['std_a'] / 1e3:.3f}, "
        f"σ_b {st160['std_b'] / 1e3:.3f}; end elements σ_a {st160['el_std_a'] / 1e3:.3f}, "
        f"σ_b {st160['el_std_b'] / 1e3:.3f}; {1e3 * st160['t']:.1f} ms"
    )
    if args.diagnose:
        # diagnostic only: analyze() has no mass-matrix option, so its FE builder is
        # wrapped; MoorPy lumps the mass, stochcable's default is consistent
        import functools

        from stochcable.dynamics.model import system as analysis

        original = analysis.build_fe_model
        analysis.build_fe_model = functools.partial(original, mass_matrix="lumped")
        try:
            for n in (40, 160):
                r = stochcable_dynamics(n, 1)
                print(
                    f"  stochcable, lumped mass, {n} el: end σ_a {r['std_a'] / 1e3:.3f}, "
                    f"σ_b {r['std_b'] / 1e3:.3f}; end elements σ_a {r['el_std_a'] / 1e3:.3f}, "
                    f"σ_b {r['el_std_b'] / 1e3:.3f}"
                )
        finally:
            analysis.build_fe_model = original
    if not have_moorpy:
        return
    ds = LENGTH / 40
    cases = [
        (
            "MoorPy 40 seg, kbot = k·D·Δs, tol 0.01 (default)",
            40,
            K_BED * DIAMETER * ds,
            C_BED * DIAMETER * ds,
            0.01,
        ),
        (
            "MoorPy 40 seg, kbot = k·D·Δs, tol 1e-4",
            40,
            K_BED * DIAMETER * ds,
            C_BED * DIAMETER * ds,
            1e-4,
        ),
        ("MoorPy 40 seg, kbot = 3e6 N/m, cbot = 3e5 N·s/m, tol 0.01", 40, K_BED, C_BED, 0.01),
        (
            "MoorPy 160 seg, kbot = k·D·Δs, tol 1e-4",
            160,
            K_BED * DIAMETER * LENGTH / 160,
            C_BED * DIAMETER * LENGTH / 160,
            1e-4,
        ),
    ]
    for name, seg, kb, cb, tol in cases:
        # 160 segments: ≈ 23 s per solve (dense per-frequency solves), timed once
        r = moorpy_dynamics(omega, s_in, seg, kb, cb, tol, rep_slow if seg == 40 else 0)
        ref = st if seg == 40 else st160
        print(
            f"  {name}: σ_a {r['std_a'] / 1e3:.3f}, σ_b {r['std_b'] / 1e3:.3f}; "
            f"{r['solves']} linear solves (= iterations); "
            f"{1e3 * r['t']:.0f} / {1e3 * r['t_min']:.0f} ms"
        )
        print(
            "      MoorPy / stochcable − 1: "
            f"vs end elements σ_a {r['std_a'] / ref['el_std_a'] - 1:+.3f}, "
            f"σ_b {r['std_b'] / ref['el_std_b'] - 1:+.3f}; vs end reactions "
            f"σ_a {r['std_a'] / ref['std_a'] - 1:+.3f}, σ_b {r['std_b'] / ref['std_b'] - 1:+.3f}"
        )


if __name__ == "__main__":
    main()
