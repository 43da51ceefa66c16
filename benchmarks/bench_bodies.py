"""Benchmark of the coupled lines–bodies analysis (issue 6, "Bodies and moving ends").

A buoy (6 DOF, constant added mass and radiation damping, drag) on three chain legs
at 0/120/240 deg, 40 elements per leg (3-D), 200 frequencies on [0.1, 2] rad/s,
JONSWAP Hs 3 m Tp 9 s.  Timed: the whole dynamic analysis of the group
with the statics (lines and the buoy pose, stochcable.line.statics) and without them
(:func:`stochcable.dynamics.groups.analyze_coupled`: models, channels, coupled drag
linearization, coupled modes, line and body outputs), with one BLAS thread as
``analyze()`` runs small models, for the direct and the Foss ("auto") solvers, and
the whole ``analyze()`` call (scene to result: statics, dynamics, warnings,
indicators).  For scale: the same three legs analysed independently, fairleads fixed at their static
positions.  The dynamics are also timed without the coarse start of the drag
linearization (``COARSE_MIN_FREQUENCIES`` raised), with the largest relative change
of the buoy motion σ and the fairlead/anchor tension σ it makes.  Then a cProfile
breakdown of one full coupled analysis (direct).  ``--ab``: only an interleaved A/B
of the reference paths (node-level Foss lines, full coupled-mode eigenproblem) against
the fast ones (pass E3, docs/BENCHMARKS.md), wall and process time.  ``--threads-ab``:
only an interleaved A/B of the per-line thread pool off and on (pass E4).
``--coarse-ab``: only an interleaved A/B of the coarse start off and on (pass E5:
defect-corrected coarse stage), with the evaluation counts.


Run:  python benchmarks/bench_bodies.py [--repeat N] [--profile] [--ab] [--threads-ab]
      [--coarse-ab]
"""

from __future__ import annotations

import argparse
import cProfile
import io
import math
import pstats
import statistics
import time
import warnings
from typing import Any

import numpy as np
from host_probe import host_line

import stochcable.dynamics.groups.coarse as coupled_coarse
import stochcable.dynamics.groups.lineparts as coupled_lineparts
import stochcable.dynamics.groups.modes as coupled_modes
from stochcable.analysis import analyze
from stochcable.dynamics.groups import analyze_coupled
from stochcable.dynamics.groups.line_fixed_point import linearize
from stochcable.dynamics.loads.channels import line_channels
from stochcable.dynamics.model.system import build_line_system
from stochcable.dynamics.outputs.line_result import line_result
from stochcable.runtime import single_blas_thread
from stochcable.scene.model import load_scene
from stochcable.statics import solve_statics


def scene_doc(solver: str = "direct", n_el: int = 40, count: int = 200) -> dict:
    lines = []
    for i in range(3):
        a = math.radians(120.0 * i)
        lines.append(
            {
                "name": f"leg{i + 1}",
                "end_a": {"position": [300.0 * math.cos(a), 300.0 * math.sin(a), -100.0]},
                "end_b": {
                    "attach": {
                        "body": "buoy",
                        "point": [5.0 * math.cos(a), 5.0 * math.sin(a), -2.0],
                    }
                },
                "segments": [
                    {"length": 330.0, "ea": 5e8, "mass": 100.0, "diameter": 0.1, "elements": n_el}
                ],
            }
        )
    diag = lambda v: [[v[i] if i == j else 0.0 for j in range(6)] for i in range(6)]  # noqa: E731
    body = {
        "name": "buoy",
        "position": [0.0, 0.0, 0.0],
        "mass": 2.0e4,
        "inertia": [[5e4, 0, 0], [0, 5e4, 0], [0, 0, 8e4]],
        "added_mass": diag([1e4, 1e4, 2e4, 2e4, 2e4, 1e3]),
        "radiation_damping": diag([1e3, 1e3, 5e3, 1e3, 1e3, 1e2]),
        "hydrostatic_stiffness": diag([0.0, 0.0, 1.26e5, 1e5, 1e5, 0.0]),
        "drag_area": [4.0, 4.0, 8.0],
        "drag_point": [0.0, 0.0, -1.0],
    }
    return {
        "environment": {"depth": 100.0},
        "sea": {"spectrum": {"type": "jonswap", "hs": 3.0, "tp": 9.0}, "heading": 0.0},
        "bodies": [body],
        "lines": lines,
        "analysis": {"omega": {"min": 0.1, "max": 2.0, "count": count}, "solver": solver},
    }


def run_coupled(scene, statics=None):
    """Statics (when not given) and the coupled dynamics, one BLAS thread and glibc's
    heap top pad as ``analyze()`` runs them (pass E4: the earlier passes timed without
    the pad, ≈ 6 % slower from page faults)."""
    timing: dict[str, float] = {}
    with single_blas_thread():
        if statics is None:
            statics = solve_statics(scene, method="fe")
        out = analyze_coupled(scene, statics, scene.analysis, timing=timing)
    return out, timing


def independent_scene(scene, statics):
    """The three legs alone with their fairleads fixed at the static attachments."""
    doc = scene_doc(scene.analysis.solver)
    doc.pop("bodies")
    for ln in doc["lines"]:
        ln["end_b"] = {"position": statics.lines[ln["name"]].positions[-1].tolist()}
    return load_scene(doc)


def run_independent(scene, statics):
    w = scene.analysis.omega.values()
    with single_blas_thread():
        for line in scene.lines:
            s = build_line_system(scene, line, statics.lines[line.name])
            ch = line_channels(scene, line, s.positions, w)
            line_result(s, ch, linearize(s, ch, scene.analysis), scene.analysis)


def key_results(lines, bodies):
    """Buoy surge/heave/pitch σ and every leg's fairlead and anchor tension σ."""
    return np.r_[
        bodies["buoy"].motion_std[[0, 2, 4]],
        [lines[n].end_b.std for n in lines],
        [lines[n].end_a.std for n in lines],
    ]


def without_coarse_start(scene, statics, repeat):
    """Dynamics median time and results with the coarse start switched off."""
    saved = coupled_coarse.COARSE_MIN_FREQUENCIES
    coupled_coarse.COARSE_MIN_FREQUENCIES = 10**9
    try:
        (lines, bodies, _, _), _ = run_coupled(scene, statics)
        med, _ = median_time(lambda: run_coupled(scene, statics), repeat)
    finally:
        coupled_coarse.COARSE_MIN_FREQUENCIES = saved
    return med, lines, bodies


def reference_paths(on: bool) -> None:
    """Switch the issue-6 pass E3 fast paths off (the reference: node-level Foss lines,
    the full coupled-mode eigenproblem) or on."""
    coupled_lineparts._MODAL_FOSS = not on
    coupled_modes._CB_MIN_RATIO = 1e9 if on else 1.5


def interleaved_ab(
    repeat: int, variants: dict[str, Any], reference: str, history: bool = False
) -> None:
    """Interleaved A/B in one process, per solver: each variant (a label and a
    function that switches it on) in turn, full analysis (statics + dynamics) and
    dynamics alone, medians of wall and process time (with threads the process time
    can exceed the wall time), and the largest relative change of the buoy σ and
    tension σ of each variant against ``reference`` (0: same bits).  ``history``:
    print each variant's evaluation count and history."""
    for solver in ("foss", "direct"):
        scene = load_scene(scene_doc(solver))
        statics = solve_statics(scene, method="fe")
        keys = {}
        for label, use in variants.items():
            use()
            (lines, bodies, _, _), _ = run_coupled(scene, statics)
            keys[label] = key_results(lines, bodies)
            if history:
                rec = lines["leg1"].linearization
                print(
                    f"{solver:6s} {label}: {rec.iterations} evaluations, history "
                    f"{', '.join(f'{h:.1e}' for h in rec.history)}"
                )
            run_coupled(scene)  # warm-up
        t = {(v, k): [] for v in variants for k in ("fw", "fp", "dw", "dp")}
        for _ in range(repeat):
            for label, use in variants.items():
                use()
                _time_full_and_dynamics(scene, statics, t, label)
        for label in variants:
            med = {k: 1e3 * statistics.median(t[label, k]) for k in ("fw", "fp", "dw", "dp")}
            diff = np.max(np.abs(keys[label] / keys[reference] - 1.0))
            print(
                f"{solver:6s} {label}: full {med['fw']:.1f} ms (process {med['fp']:.1f}), "
                f"dynamics {med['dw']:.1f} ms (process {med['dp']:.1f}), medians of "
                f"{repeat}; max relative change of the key σ vs {reference}: {diff:.1e}"
            )


def _time_full_and_dynamics(scene, statics, t: dict, key) -> None:  # noqa: ANN001
    """One timed full analysis (with statics) and one dynamics-only run, appended to
    ``t[key, "fw"/"fp"/"dw"/"dp"]`` (wall and process time). [s]"""
    for kind, st in (("f", None), ("d", statics)):
        w0, p0 = time.perf_counter(), time.process_time()
        run_coupled(scene, st)
        t[key, kind + "w"].append(time.perf_counter() - w0)
        t[key, kind + "p"].append(time.process_time() - p0)


def fast_paths_ab(repeat: int) -> None:
    """The reference paths (node-level Foss lines, full coupled-mode eigenproblem)
    against the fast ones (pass E3)."""
    try:
        interleaved_ab(
            repeat,
            {
                "reference": lambda: reference_paths(True),
                "fast     ": lambda: reference_paths(False),
            },
            "reference",
        )
    finally:
        reference_paths(False)


def threads_ab(repeat: int) -> None:
    """The per-line thread pool (stochcable.runtime, pass E4) off
    (``STOCHCABLE_THREADS=1``) and on (2 threads)."""
    import os

    saved = os.environ.get("STOCHCABLE_THREADS")

    def threads(n: str) -> Any:
        return lambda: os.environ.__setitem__("STOCHCABLE_THREADS", n)

    try:
        interleaved_ab(repeat, {"1 thread ": threads("1"), "2 threads": threads("2")}, "1 thread ")
    finally:
        if saved is None:
            os.environ.pop("STOCHCABLE_THREADS", None)
        else:
            os.environ["STOCHCABLE_THREADS"] = saved


def coarse_ab(repeat: int) -> None:
    """The coarse start of the drag linearization off (``COARSE_MIN_FREQUENCIES``
    raised) and on, with the evaluations of each."""
    saved = coupled_coarse.COARSE_MIN_FREQUENCIES

    def coarse(on: bool) -> Any:
        return lambda: setattr(coupled_coarse, "COARSE_MIN_FREQUENCIES", saved if on else 10**9)

    try:
        interleaved_ab(
            repeat,
            {"coarse off": coarse(False), "coarse on ": coarse(True)},
            "coarse off",
            history=True,
        )
    finally:
        coupled_coarse.COARSE_MIN_FREQUENCIES = saved


def median_time(fn, repeat: int) -> tuple[float, float]:
    fn()  # warm-up
    t = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        t.append(time.perf_counter() - t0)
    return statistics.median(t), min(t)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--profile", action="store_true")
    ap.add_argument(
        "--ab",
        action="store_true",
        help="only the interleaved A/B of the reference and the fast paths",
    )
    ap.add_argument(
        "--threads-ab",
        action="store_true",
        help="only the interleaved A/B of the per-line thread pool off/on",
    )
    ap.add_argument(
        "--coarse-ab",
        action="store_true",
        help="only the interleaved A/B of the coarse start off/on",
    )
    args = ap.parse_args()
    warnings.simplefilter("ignore")
    print(host_line())
    if args.coarse_ab:
        with single_blas_thread():
            coarse_ab(max(args.repeat, 9))
        print(host_line())
        return
    if args.ab:
        with single_blas_thread():
            fast_paths_ab(max(args.repeat, 9))
        return
    if args.threads_ab:
        with single_blas_thread():
            threads_ab(max(args.repeat, 11))
        return
    for solver in ("direct", "foss"):
        scene = load_scene(scene_doc(solver))
        med_s, _ = median_time(lambda: solve_statics(scene, method="fe"), args.repeat)
        statics = solve_statics(scene, method="fe")
        (lines, bodies, _, _), timing = run_coupled(scene, statics)
        med_f, best_f = median_time(lambda: run_coupled(scene), args.repeat)
        med_a, best_a = median_time(lambda: analyze(scene), args.repeat)
        med, best = median_time(lambda: run_coupled(scene, statics), args.repeat)
        ind = independent_scene(scene, statics)
        ind_st = solve_statics(ind, method="fe")
        med_i, _ = median_time(lambda: run_independent(ind, ind_st), args.repeat)
        rec = lines["leg1"].linearization
        print(
            f"{solver:6s}: full (statics + dynamics) {1e3 * med_f:7.1f} ms median "
            f"({1e3 * best_f:.1f} min); dynamics {1e3 * med:.1f} ms ({1e3 * best:.1f} min), "
            f"{rec.iterations} iterations; statics {1e3 * med_s:.1f} ms; "
            f"the legs alone (fairleads fixed) {1e3 * med_i:.1f} ms"
        )
        print(
            f"        through analyze() (scene to result, warnings and indicators): "
            f"{1e3 * med_a:.1f} ms median ({1e3 * best_a:.1f} min)"
        )
        med_nc, l_nc, b_nc = without_coarse_start(scene, statics, args.repeat)
        ref = key_results(l_nc, b_nc)
        diff = np.max(np.abs(key_results(lines, bodies) / ref - 1.0))
        print(
            f"        without the coarse start: dynamics {1e3 * med_nc:.1f} ms, "
            f"{l_nc['leg1'].linearization.iterations} iterations; max relative change "
            f"of the buoy σ and tension σ with it {diff:.1e}"
        )
        print("        stages: " + ", ".join(f"{k} {1e3 * v:.1f} ms" for k, v in timing.items()))
        print(
            f"        buoy surge/heave/pitch σ = {bodies['buoy'].motion_std[[0, 2, 4]]}, "
            f"leg1/leg2 fairlead tension σ = {lines['leg1'].end_b.std:.1f} / "
            f"{lines['leg2'].end_b.std:.1f} N"
        )
    if args.profile:
        scene = load_scene(scene_doc("direct"))
        run_coupled(scene)
        pr = cProfile.Profile()
        pr.enable()
        run_coupled(scene)
        pr.disable()
        s = io.StringIO()
        pstats.Stats(pr, stream=s).sort_stats("tottime").print_stats(14)
        print(s.getvalue())


if __name__ == "__main__":
    main()
