"""Load-case set speed: the chain example over a 200-case Hs × Tp diagram, one heading,
one core.

    python3 benchmarks/bench_cases.py [--quick] [--write]

Reports the time per case of ``run_cases`` against one ``analyze()`` of the same scene,
the share of the fatigue and long-term sums, and the largest difference of a case's
fairlead tension σ from its own ``analyze()`` (the error the reuse buys); then the same
with the residuals of the linear model (``analysis.linearization.drag_residual`` and
``geometric_residual`` set true explicitly), fastest of interleaved runs, and where a
corrected case's time goes (cProfile of one set).  ``--write`` writes
docs/benchmarks/cases.md; ``--quick`` runs 20 cases and never writes.
"""

from __future__ import annotations

import argparse
import cProfile
import os
import pstats
import time
import warnings
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
from host_probe import host_line

from stochcable import runtime
from stochcable.analysis import analyze
from stochcable.cases import (
    LineFatigue,
    assemble_cases,
    plan_cases,
    run_cases,
    scatter_from_rows,
)
from stochcable.cases.chunk import set_engine
from stochcable.cases.run import _line_totals  # noqa: PLC2701 - the sums timed alone
from stochcable.examples import load_example
from stochcable.scene.model import Sea, load_scene

DOC = Path(__file__).resolve().parents[1] / "docs" / "benchmarks" / "cases.md"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--write", action="store_true")
    args = ap.parse_args()
    runtime.configure()
    warnings.simplefilter("ignore")
    scene = load_example("chain_catenary")
    n_hs, n_tp = (4, 5) if args.quick else (10, 20)
    rows = [
        {"hs": hs, "tp": tp, "heading": 0.0, "probability": 1.0 / (n_hs * n_tp)}
        for hs in np.linspace(1.0, 10.0, n_hs)
        for tp in np.linspace(6.0, 16.0, n_tp)
    ]
    sd = scatter_from_rows(rows)
    fatigue = LineFatigue("dnv-studless", nominal_diameter=0.084)
    analyze(scene)  # warm-up (imports, compiled kernels)
    t_an = []
    for _ in range(5):
        t0 = time.process_time()
        analyze(scene)
        t_an.append(time.process_time() - t0)
    # the same without the strumming screening of its build (the chain is in current)
    doc = scene.model_dump(mode="json", exclude_none=True)
    for seg in doc["lines"][0]["segments"]:
        seg["strumming"] = {"suppression": "strakes"}
    quiet = load_scene(doc)
    analyze(quiet)
    t_q = []
    for _ in range(5):
        t0 = time.process_time()
        analyze(quiet)
        t_q.append(time.process_time() - t0)
    t_sets = []
    for _ in range(1 if args.quick else 3):  # best of 3 (the set's own warm-up: the first)
        t0 = time.process_time()
        res = run_cases(scene, sd, fatigue=fatigue)
        t_sets.append(time.process_time() - t0)
    t_set = min(t_sets)
    p = res.probabilities
    has = np.ones(len(rows), bool)
    t0 = time.process_time()
    for ln in res.lines:
        _line_totals(p, has, res.stats[ln], res.damage_rate_ends[ln],
                     res.damage_rate_along[ln], fatigue, 100.0)  # fmt: skip
    t_sums = time.process_time() - t0
    t0 = time.process_time()
    from stochcable.design import damage_rate, fatigue_curve

    k = 1.0 / (2 * np.pi * 0.084**2 / 4)
    lr = analyze(scene).lines["leg1"]
    dens = np.concatenate(
        [[lr.end_tension_spectrum(e) for e in ("end_a", "end_b")], lr.tension_spectrum]
    )
    stack = np.broadcast_to(dens * k * k, (len(rows), *dens.shape))
    t1 = time.process_time()
    damage_rate(lr.omega, stack, fatigue_curve("dnv-studless"))
    t_damage = time.process_time() - t1
    worst = 0.0
    for i in (0, len(rows) // 2, len(rows) // 2 + 7, len(rows) - 1):  # cold and warm starts
        s = sd.states[i]
        one = analyze(scene.model_copy(update={"sea": Sea(spectrum=s.spectrum("jonswap"))}))
        worst = max(worst, abs(res.stats["leg1"]["end_b"][i, 1] / one.lines["leg1"].end_b.std - 1))
    per_case = t_set / len(rows)
    an = min(t_an)
    cor = _corrected(scene, sd, fatigue, 1 if args.quick else 3)
    lines = [
        "# Load-case sets: speed",
        "",
        f"`python3 benchmarks/bench_cases.py --write` — the chain example over a {len(rows)}-case",
        f"Hs × Tp JONSWAP diagram, one heading, one core (one BLAS thread); {host_line()}.",
        "Times are the process's CPU time (`time.process_time`, the fastest of the",
        "rounds): the host is shared, and its wall-clock times moved ×2 between rounds.",
        "",
        "| quantity | value |",
        "|---|---|",
        f"| one `analyze()` (best of 5) | {an * 1e3:.1f} ms |",
        f"| one `analyze()` without the strumming screening (best of 5) | "
        f"{min(t_q) * 1e3:.1f} ms |",
        f"| `run_cases` per case (best of {len(t_sets)} sets) | {per_case * 1e3:.2f} ms "
        f"({per_case / an:.3f} × `analyze()`, "
        f"{per_case / min(t_q):.3f} × without the screening) |",
        f"| damage rates of all cases (one batched call) | {t_damage * 1e3:.1f} ms "
        f"({t_damage / t_set:.1%} of the set) |",
        f"| annual damage, lives, long-term return levels | {t_sums * 1e3:.1f} ms "
        f"({t_sums / t_set:.1%}) |",
        f"| largest fairlead σ difference from `analyze()` of the same sea | {worst:.1e} |",
        "",
        "The statics, the finite-element model, the modes and the factorizations are built",
        "once per set, and a line's wave kinematics and loads per unit wave once per",
        "heading (kept within 128 MiB a line); a case costs its spectrum's weights, the",
        "drag fixed point and the outputs.  The drag fixed point of a case starts from the",
        "converged σ of the cases before it (extrapolated from the last three) within runs",
        "of 16 cases of the diagram (`stochcable.cases.chunk`): ≈ 4.7 evaluations a case",
        "instead of 7.6 from rest; the σ differ from `analyze()`'s (which starts at rest)",
        "within the linearization tolerance (the last row: a run's first case, then warm",
        "cases), and not at all between executors or chunkings.",
        "Timings are of one run on the machine of docs/BENCHMARKS.md; they move with its",
        "fast and slow states.",
        "",
        "## With the residuals of the linear model",
        "",
        "The same set and scene with `analysis.linearization.drag_residual` and",
        "`geometric_residual` set true (every case's end statistics and end damage then",
        "those of the corrected spectrum); the fastest of interleaved rounds of one",
        f"`analyze()` (×{cor['n_an']}) and of each set's engine build and of each of its",
        f"chunks of 16 cases (×{cor['n_set']}; a set's time is the fastest build plus the",
        "sum of its chunks' fastest rounds, so that the host's load moves a set and an",
        "`analyze()` alike).  By default a",
        "set computes the residuals on every case; with `residual_span=5` (opt-in) on",
        "the anchor cases only — per Tp, γ and heading the smallest and largest Hs and",
        "at most 5 Hs steps apart — interpolating their corrections in Hs on the others",
        f"(`stochcable.cases.residual_anchors`; here {cor['anchors']} of {len(rows)} cases).",
        "",
        "| quantity | value |",
        "|---|---|",
        f"| one `analyze()`, residuals on | {cor['analyze'] * 1e3:.1f} ms "
        f"(linear: {cor['analyze_linear'] * 1e3:.1f} ms) |",
        f"| `run_cases` per case, residuals on (`residual_span=5`: anchors) | "
        f"{cor['case'] * 1e3:.1f} ms "
        f"(**{cor['case'] / cor['analyze']:.3f} × `analyze()`**) |",
        f"| `run_cases` per case, residuals on every case (default) | "
        f"{cor['case_exact'] * 1e3:.1f} ms "
        f"({cor['case_exact'] / cor['analyze']:.3f} × `analyze()`) |",
        f"| `run_cases` per case, linear | {cor['case_linear'] * 1e3:.2f} ms "
        f"({cor['case_linear'] / cor['analyze_linear']:.3f} × the linear `analyze()`) |",
        f"| corrected set / linear set (anchors; every case) | "
        f"{cor['case'] / cor['case_linear']:.2f} ×; "
        f"{cor['case_exact'] / cor['case_linear']:.2f} × |",
        f"| largest fairlead σ difference from `analyze()` of the same sea (every case) | "
        f"{cor['worst']:.1e} |",
        "",
        "What the interpolation costs in accuracy: the anchors' set against every case",
        "computed (largest relative difference over the cases and both ends):",
        "",
        "| quantity | difference |",
        "|---|---|",
        *[f"| {k} | {v:.1e} |" for k, v in cor["interp"].items()],
        "",
        "Where a corrected case's time goes when every case computes the residuals",
        "(cProfile of one set, shares of the set):",
        "",
        "| part | share |",
        "|---|---|",
        *[f"| {k} | {v:.0%} |" for k, v in cor["shares"].items()],
        "",
        "The residuals are evaluated on each case's own converged response: the",
        "velocity and displacement covariances and their k-fold convolutions, the",
        "Hermite coefficients of each panel's U/σ and the end tensions per unit panel",
        "load all depend on the case's sea and its linearized damping, which differs in",
        "every case (the drag's B ∝ σ of the relative velocity), so nothing of them can",
        "be shared between cases: what is shared (statics, models, factorizations,",
        "modes, kinematics per unit wave) is the linear model's, already reused.  What",
        "makes a corrected case cheap is computing them on fewer cases: the corrections'",
        "ratios are smooth along a column of the diagram (one spectral shape, scaled).",
    ]
    text = "\n".join(lines) + "\n"
    print(text)
    if args.write and not args.quick:
        DOC.write_text(text, encoding="utf-8")


def _switched(scene, on: bool):
    lin = scene.analysis.linearization.model_copy(
        update={"drag_residual": on, "geometric_residual": on}
    )
    return scene.model_copy(
        update={"analysis": scene.analysis.model_copy(update={"linearization": lin})}
    )


#: cProfile function names per part of a corrected case (cumulative times).
_PARTS = {
    "drag residual: covariances, convolutions (residual_output_lines)": "residual_output_lines",
    "geometric residual: covariances, convolutions (quadratic_output_lines)": (
        "quadratic_output_lines"
    ),
    "end tensions per unit load (end_influence: drag, geometric, misfit, cells)": ("end_influence"),
    "drag residual: pieces' velocities (segment_velocity)": "segment_velocity",
    "drag fixed point (linearize_coupled)": "linearize_coupled",
}


def _corrected(scene, sd, fatigue, n_set: int) -> dict:
    """The corrected set (residuals on every case, the default; and interpolated
    between anchors, residual_span=5) against the corrected analysis, fastest of
    interleaved rounds."""
    on, off = _switched(scene, True), _switched(scene, False)
    n_an = 5
    analyze(on)
    t: dict[str, list[float]] = {k: [] for k in ("analyze", "analyze_linear")}
    # a set's time as the sum over its chunks of each chunk's fastest round (chunks of
    # 16 cases: whole warm-start runs, so the same solves as in one chunk), plus the
    # fastest engine build: a set is timed as finely as an analysis, so that the
    # host's load moves both alike
    plans = {
        "case": plan_cases(on, sd, fatigue=fatigue, chunk_size=16, residual_span=5),
        "case_exact": plan_cases(on, sd, fatigue=fatigue, chunk_size=16, residual_span=None),
        "case_linear": plan_cases(off, sd, fatigue=fatigue, chunk_size=16),
    }
    chunk_t = {k: [[] for _ in p.chunks] for k, p in plans.items()}
    sets = {}
    build_t = {k: [] for k in plans}
    parts: dict[str, list] = {}
    for r in range(max(n_an, n_set)):
        for key, sc in (("analyze", on), ("analyze_linear", off)):
            if r < n_an:
                t0 = time.process_time()
                analyze(sc)
                t[key].append(time.process_time() - t0)
        for key, plan in plans.items():
            if r < n_set:
                t0 = time.process_time()
                engine = set_engine(plan.template)
                build_t[key].append(time.process_time() - t0)
                parts[key] = []
                for k in range(len(plan.chunks)):
                    t0 = time.process_time()
                    parts[key].append(plan.solve(k, engine))
                    chunk_t[key][k].append(time.process_time() - t0)
    for key, plan in plans.items():
        t0 = time.process_time()
        sets[key] = assemble_cases(plan, parts[key])
        total = time.process_time() - t0 + min(build_t[key])
        t[key] = [(total + sum(min(c) for c in chunk_t[key])) / len(sd.states)]
    out: dict = {k: min(v) for k, v in t.items()}
    worst = 0.0
    n = len(sd.states)
    exact = sets["case_exact"]
    for i in (0, n // 2, n // 2 + 1, n - 1):
        s = sd.states[i]
        one = analyze(on.model_copy(update={"sea": Sea(spectrum=s.spectrum("jonswap"))}))
        worst = max(
            worst, abs(exact.stats["leg1"]["end_b"][i, 1] / one.lines["leg1"].end_b.std - 1)
        )
    interp = {}
    got = sets["case"]
    for label, col in (("σ", 1), ("Tz", 2), ("3-h MPM", 3)):
        interp[label] = max(
            float(
                np.nanmax(np.abs(got.stats["leg1"][e][:, col] / exact.stats["leg1"][e][:, col] - 1))
            )
            for e in ("end_a", "end_b")
        )
    d = got.damage_rate_ends["leg1"] / exact.damage_rate_ends["leg1"] - 1
    interp["end damage rate"] = float(np.nanmax(np.abs(d)))
    for e in ("end_a", "end_b"):
        a, b = got.totals["leg1"], exact.totals["leg1"]
        interp[f"annual damage, {e}"] = abs(a.annual_damage[e] / b.annual_damage[e] - 1)
        interp[f"100-year return level, {e}"] = abs(a.return_level[e] / b.return_level[e] - 1)
    prof = cProfile.Profile()
    prof.enable()
    run_cases(on, sd, fatigue=fatigue, residual_span=None)
    prof.disable()
    stats = pstats.Stats(prof).stats
    total = max(v[3] for v in stats.values())
    shares = {}
    for label, fn in _PARTS.items():
        shares[label] = sum(v[3] for k, v in stats.items() if k[2] == fn) / total
    shares["the rest (linear solve, outputs, fatigue)"] = 1.0 - sum(shares.values())
    anchors = int(sum(1 for c in plan_cases(on, sd, residual_span=5).chunks[0] if c[2]))
    out.update(worst=worst, shares=shares, n_an=n_an, n_set=n_set, interp=interp,
               anchors=anchors)  # fmt: skip
    return out


if __name__ == "__main__":
    main()
