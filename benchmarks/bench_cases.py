"""Load-case set speed: the chain example over a 200-case Hs × Tp diagram, one heading,
one core.

    python3 benchmarks/bench_cases.py [--quick] [--write] [--north-atlantic]

Reports the time per case of ``run_cases`` against one ``analyze()`` of the same scene,
the share of the fatigue and long-term sums, and the largest difference of a case's
fairlead tension σ from its own ``analyze()`` (the error the reuse buys); then the same
with the residuals of the linear model (``analysis.linearization.drag_residual`` and
``geometric_residual`` set true explicitly): the default set (adaptive anchors), every
case computed and the fixed anchors, fastest of interleaved runs, their accuracy
against every case computed (also on the taut wire and Tuah's single leg), and where
a corrected case's time goes (cProfile of one set).  ``--write`` writes
docs/benchmarks/cases.md; ``--quick`` runs 20 cases and never writes;
``--north-atlantic`` only prints the default set's cases computed and misses on the
bundled North Atlantic diagram (docs/cases.md).
"""

from __future__ import annotations

import argparse
import contextlib
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
from stochcable.cases.residual_anchors import first_anchors
from stochcable.cases.run import _line_totals  # noqa: PLC2701 - the sums timed alone
from stochcable.examples import load_example
from stochcable.scene.model import Sea, load_scene

DOC = Path(__file__).resolve().parents[1] / "docs" / "benchmarks" / "cases.md"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--write", action="store_true")
    ap.add_argument("--north-atlantic", action="store_true")
    args = ap.parse_args()
    if args.north_atlantic:
        runtime.configure()
        warnings.simplefilter("ignore")
        _north_atlantic()
        return
    load0 = os.getloadavg()[0]
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
    others = {} if args.quick else _other_lines()
    lin_share = cor["case_linear"] / cor["analyze"]
    room = (1.0 / 3.0 - lin_share) * cor["analyze"] * 1e3  # [ms a case]
    extra = (cor["case"] - cor["case_linear"]) * len(rows) / cor["computed"] * 1e3
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
        "of 16 cases of the diagram (`stochcable.cases.chunk`): ≈ 2.7 evaluations a case,",
        "all on the full grid, instead of 7.6 from rest (most of them on a coarse",
        "subset); the σ differ from `analyze()`'s (which starts at rest)",
        "within the linearization tolerance (the last row: a run's first case, then warm",
        "cases), and not at all between executors or chunkings.",
        "Timings are of one run on the machine of docs/BENCHMARKS.md; they move with its",
        "fast and slow states.",
        "",
        "## With the residuals of the linear model",
        "",
        "The same set and scene with `analysis.linearization.drag_residual` and",
        "`geometric_residual` true (the default; every case's end statistics and end",
        "damage then those of the corrected spectrum); the fastest of interleaved rounds",
        f"of one `analyze()` (×{cor['n_an']}) and of each set (×{cor['n_set']}: the",
        "fastest engine build plus, for the one-pass sets, the sum of their chunks' (16",
        "cases) fastest rounds, for the default set its fastest whole `run_cases`), so",
        "that the host's load moves a set and an `analyze()` alike.  Host shared with",
        f"other engineers' work: load average {load0:.1f} on 2 cores at the start of the",
        f"run, {os.getloadavg()[0]:.1f} at its end; {host_line()}).",
        "",
        "By default (`stochcable.cases.residual_anchors`) `run_cases` computes the",
        "residuals on the *adaptive anchors*: per heading the periods are bisected from",
        "the shortest, middle and longest — a period between two computed ones is",
        "computed and checked against the corrections interpolated linearly in the",
        "period, and the interval split while they miss by more than",
        "`residual_tolerance` = 2e-3 (σ, Tz, 3-h MPM; 6e-3 on the end damage rates and",
        "on the elements' relative to the line's largest damage rate of the case) or",
        "its ends' corrections spread from its middle's by more than 1.5 tolerances (a",
        "step in the period, where a drag residual's element starts to split, misses by",
        "at most that); in every computed period the Hs are bisected likewise from the",
        "smallest, middle and largest, each period by the curve that meets its first",
        "middle best (`stochcable.cases.anchor_transfer`): the ratios a power of Hs,",
        "the end tensions' residual moments Δm0, Δm2 powers of Hs",
        "(`stochcable.cases.anchor_moments`), or its parents' shape in the bisection of",
        "the periods plus its own departure, linear in Hs; every other case gets its",
        "linear values times the interpolated ratios.  Here",
        f"{cor['computed']} of {len(rows)} cases computed them ({cor['first']} in the first",
        f"pass, {cor['computed'] - cor['first']} in the checks' later passes).  Every case is",
        "solved once (`stochcable.cases.anchor_passes`): the anchors pass after pass with",
        "the residuals, each from the converged σ of the cases computed before it",
        "(interpolated in Hs along its period where two are, else the nearest one's),",
        "then the others linear (from such a start where its period's σ follow the",
        "law, `split_last_pass`; else in warm-start runs across the anchors' positions).",
        "`residual_tolerance=None` computes every case (a plan's default: the service's",
        f"batches); `residual_span=5, residual_tolerance=None` the fixed anchors ({cor['anchors']}",
        "cases, no check).",
        "",
        "| quantity | value |",
        "|---|---|",
        f"| one `analyze()`, residuals on | {cor['analyze'] * 1e3:.1f} ms "
        f"(linear: {cor['analyze_linear'] * 1e3:.1f} ms) |",
        f"| `run_cases` per case, default (adaptive anchors) | "
        f"{cor['case'] * 1e3:.1f} ms (**{cor['case'] / cor['analyze']:.3f} × `analyze()`**) |",
        f"| `run_cases` per case, adaptive in Hs only (every period computed, "
        f"{cor['hs_only']} cases) | {cor['case_hs_only'] * 1e3:.1f} ms "
        f"({cor['case_hs_only'] / cor['analyze']:.3f} × `analyze()`) |",
        f"| `run_cases` per case, every case computed | "
        f"{cor['case_exact'] * 1e3:.1f} ms "
        f"({cor['case_exact'] / cor['analyze']:.3f} × `analyze()`) |",
        f"| `run_cases` per case, fixed anchors (`residual_span=5`) | "
        f"{cor['case_fixed'] * 1e3:.1f} ms "
        f"({cor['case_fixed'] / cor['analyze']:.3f} × `analyze()`) |",
        f"| `run_cases` per case, linear | {cor['case_linear'] * 1e3:.2f} ms "
        f"({cor['case_linear'] / cor['analyze']:.3f} × the corrected `analyze()`) |",
        f"| largest fairlead σ difference from `analyze()` of the same sea (every case) | "
        f"{cor['worst']:.1e} |",
        "",
        "What the interpolation costs in accuracy: each set against every case computed",
        "(largest relative difference over the cases and both ends; an anchor starts its",
        "fixed point from a neighbour's σ, so even computed cases differ within the",
        "linearization tolerance, 1e-4):",
        "",
        "| quantity | adaptive (default) | adaptive in Hs only | fixed anchors |",
        "|---|---|---|---|",
        *[
            f"| {k} | {v:.1e} | {cor['interp']['adaptive in Hs only'][k]:.1e} | "
            f"{cor['interp']['fixed (`residual_span=5`)'][k]:.1e} |"
            for k, v in cor["interp"]["adaptive (default)"].items()
        ],
        "",
        "The default set on two more lines, and on Tuah's leg again with its",
        'segment\'s `elements` left out (", default mesh": the count the planner derives',
        "for ≤ 1 % discretization error on the end-tension σ; Tuah's own 3 elements are",
        "flagged at 160–690 % on these seas), against every case computed (the scenes'",
        "linearization tolerance set to 1e-4; per case CPU time over one corrected",
        "`analyze()` of the same scene and its own sea, fastest of 3 interleaved rounds;",
        "each line on a 4-period diagram and on a realistic one, Tp every 1 s; the",
        "linear set: the residuals off, the floor of any set whose cases all carry",
        "corrections interpolated from computed ones):",
        "",
        "| line, diagram | cases computed | σ | Tz | 3-h MPM | end damage rate "
        "| element damage rate, of the line's largest (of its own) | annual damage "
        "| per case / `analyze()` | every case computed / `analyze()` "
        "| linear set / `analyze()` |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
        *[
            f"| {o['name']}, {o['diagram']} | {o['computed']} of {o['cases']} | "
            f"{o['misses']['σ']:.1e} | {o['misses']['Tz']:.1e} | "
            f"{o['misses']['3-h MPM']:.1e} | {o['misses']['end damage rate']:.1e} | "
            f"{o['misses'][_EL_BIG]:.1e} "
            f"({o['misses']['element damage rate, of its own']:.1e}) | "
            f"{max(o['misses'][f'annual damage, {e}'] for e in ('end_a', 'end_b')):.1e} | "
            f"{o['default']:.2f} | {o['exact']:.2f} | {o['linear']:.2f} |"
            for o in others.values()
        ],
        "",
        "A taut wire's case is solved directly (`stochcable.cases.chunk.set_engine`):",
        "its Foss solve keeps every mode (38 free DOFs: no static correction), so the",
        "banded solve per frequency gives the same σ (to 3e-12) without a 76-state",
        "eigenproblem at every fixed-point evaluation; Tuah's leg (4 free DOFs, a line",
        "alone, every mode kept) by its modal equations per frequency, one batched 4 × 4",
        "LU (`stochcable.dynamics.groups.lineparts.SMALL_MODAL_DOFS`: σ within 2e-14; its",
        "linear set's case 0.90 × the Foss solve's, interleaved).  Where a case's time goes",
        "(cProfile of one set on the 4-period diagrams after a warm-up, ms a case with",
        "the profiler's overhead; the fixed point's evaluations and Foss eigenproblems a",
        "case; outputs: the linear outputs, indicators and the corrected statistics; the",
        "residuals: drag, geometric and along-line, and the elements' corrected",
        "densities):",
        "",
        "| line | set | case | fixed point (evaluations, eigenproblems) | residuals "
        "| outputs | mesh check | damage rates | rest | `analyze()` |",
        "|---|---|---|---|---|---|---|---|---|---|",
        *[
            f"| {o['name']} | {k} | {b['case']:.1f} | {b['fixed point']:.1f} "
            f"({b['evaluations']:.1f}, {b['eigenproblems']:.1f}) | {b['residuals']:.1f} | "
            f"{b['outputs']:.1f} | {b['mesh check']:.1f} | {b['damage rates']:.2f} | "
            f"{b['rest']:.1f} | {o['profile']['analyze']:.1f} |"
            for o in others.values()
            if o["profile"]
            for k, b in o["profile"].items()
            if k != "analyze"
        ],
        "",
        *_why(others),
        "",
        *_meshed(others),
        "",
        "Where a corrected case's time goes when every case computes the residuals",
        "(cProfile of one set, cumulative shares of the set; the rest: the linear",
        "outputs, the corrected end statistics and densities, the fatigue sums):",
        "",
        "| part | share |",
        "|---|---|",
        *[f"| {k} | {v:.0%} |" for k, v in cor["shares"].items()],
        "",
        "Every case is solved by the linear model on the set's engine (statics, models,",
        "factorizations, modes, kinematics per unit wave built once); the residuals are",
        "evaluated on a case's own converged response (covariances, convolutions,",
        "Hermite coefficients, end tensions per unit panel load: they depend on the",
        "case's sea and linearized damping).  A set skips what it never reads: the node",
        "motions' residuals (`line_result.MOTION_RESIDUALS` off in a chunk: 12 ms of a",
        "computed chain case, and their rows in the shared influence; the end and",
        "element tensions bitwise the same), and forms the element tensions' corrected",
        "densities of a computed case in one array operation",
        "(`stochcable.cases.along_spectra`, 7 ms of a computed chain case before).",
        "The default set's cost is the linear set's plus, per computed case, its",
        f"residuals (≈ {extra:.0f} ms a computed case here).  What keeps it under the 1/3",
        f"of `analyze()` asked (issue 31): (1) the linear set alone is {lin_share:.2f} ×",
        f"the corrected `analyze()`, leaving ≈ {room:.1f} ms a case for the residuals,",
        f"i.e. ≈ {room * len(rows) / extra:.0f} computed cases of {len(rows)} at that cost;",
        "(2) the corrections must be smooth in the period for the checks to pass with",
        "few computed periods, and `analyze()`'s discretization of the drag residual",
        "(`stochcable.dynamics.residuals.drag_segments`) is chosen so: whole elements are",
        "grouped in fixed tiles of ⌈n_el/32⌉ consecutive elements (set by the mesh; cut",
        "only where a split element interrupts one or its wave-velocity variance spans",
        "more than 1.5), and a split element's pieces move continuously with the count",
        "its variance asks for (a new piece appears at zero length).  On the chain at",
        "Hs 5 m over Tp 6–16 s the fairlead σ correction runs 1.04137 … 1.04218, steps",
        "≤ 4.3e-4 between periods 0.5 s apart (where an element starts to split or a",
        "tile is cut).  Before, whole elements were grouped by the sea's variance (a",
        "ladder of ratios, the group size bisected into the budget: groups of 2 or 3,",
        "27–32 panels) and the pieces were equal: 1.0384 … 1.0421 with steps up to",
        "2.4e-3, and the checks computed most periods (68 of 200 cases, 0.355 ×",
        "`analyze()`).  The tiles cost the chain's `analyze()` 33 panels instead of 28",
        "(+4.5 %; the two-segment line's +3 %: interleaved `analyze()` runs) and bring",
        "it closer to the finer evaluation before issue 31",
        "(tests/residual_variances_v1.json: fairlead σ +0.03 % instead of −0.11 %).",
        "A set-wide discretization (one pilot sea's pieces",
        "and panels for every case) was dropped before: it moved the set from each",
        "case's own `analyze()` by 4.2e-3 on σ.  Where the corrections bend along a",
        "period (the taut wire near resonance, Tuah's leg) the periods choose the",
        "residual moments or their parents' shape (above), and the checks compute",
        "what these laws still miss.",
    ]
    text = "\n".join(lines) + "\n"
    print(text)
    if args.write and not args.quick:
        DOC.write_text(text, encoding="utf-8")


def _why(others: dict) -> list[str]:
    """What a set's cost is made of on the taut wire and Tuah's leg and what keeps the
    computed cases few (the text, with the figures of the realistic diagrams): the
    residual cost a computed case may have at most for 1/3."""
    rows = []
    for o in others.values():
        if o["profile"]:
            continue
        frac = o["computed"] / o["cases"]
        room = (1.0 / 3.0 - o["linear"]) / frac
        rows.append(
            f"{o['name']}: linear set {o['linear']:.2f}, {o['computed']} of {o['cases']} "
            f"computed, a computed case's residuals {o['exact'] - o['linear']:.2f} × "
            f"`analyze()` where ≤ {room:.2f} would meet 1/3"
        )
    return [
        "The cost of a set is the linear set's plus the computed share times a computed",
        "case's residuals (every case computed: the column before the last) — on the",
        "realistic diagrams " + "; ".join(rows) + ".",
        "The residuals are evaluated on a case's own converged response (covariances,",
        "convolutions, Hermite coefficients, end tensions per unit panel load;",
        "`stochcable.dynamics.residuals`); the checks compute the cases where the",
        "corrections bend, and three laws keep them few there",
        "(`stochcable.cases.anchor_transfer`, each period choosing by its first",
        "middle Hs):",
        "",
        "- *Tuah's leg*: its corrections rise and fall with Hs (end σ +5 % at Hs 1 m,",
        "  +12 % at 4 m, then falling), so a power law between computed Hs one step",
        "  apart misses σ, Tz and damage ratios by 3e-3 … 8e-3, and every computed",
        "  period computed 9 of its 10 Hs (91 of 100 cases); but they change smoothly",
        "  with the period (linear in Tp between periods 1 s apart: within 3.5e-3), so a",
        "  period now borrows the shape of its parents in the bisection of the periods",
        "  (their curves quadratic in Tp through them and their own parent interval's",
        "  other end) plus its own departure from it, linear in Hs: its",
        "  smallest, middle and largest Hs suffice where the parents are computed",
        "  densely (the shortest and longest period, and those whose parents' shape",
        "  does not carry over).",
        "- *The taut wire near resonance* (Tp 10–13 s): its end_b σ correction rises to",
        "  +26 % and falls again with Hs (Tp 12 s), while the residual variance",
        "  Δm0 = σ² − σ_lin² and Δm2 stay powers of Hs (σ_lin is what bends: drag",
        "  damping): interpolated as such (`stochcable.cases.anchor_moments`, the end",
        "  damage over its narrow-band proxy (σ/σ_lin)^m·Tz_lin/Tz with the curve's S-N",
        "  slope) σ and Tz are met to 1e-5 between Hs 0.5 m apart where the ratios'",
        "  law missed σ by 7e-3 between Hs 0.25 m apart.",
        "- *The elements' damage* is checked relative to the line's largest damage rate",
        "  of the case (ends and elements), with the end damage's tolerance: the taut",
        "  wire's element ratios that missed by 2e-2 … 1e-1 (Hs 0.25 m apart, Tp",
        "  10–13 s) are elements 17–19 near end_b whose damage is 0.2–1 % of the line's",
        "  largest: relative to it they miss by ≤ 3e-3.  A designer reads a line's",
        "  fatigue from its largest damage; an element with a hundredth of it has a life",
        "  a hundred times the line's, and its error relative to its own damage (the",
        "  bracketed figures in the table above) moves no design check.  The ends' damage",
        "  keeps its relative tolerance.",
        "",
        "Replayed on the every-case sets (the checks re-run on their numbers): the",
        "moments alone compute no case fewer (the elements bind), the elements'",
        "tolerance alone 3 of 104 fewer on the taut wire, both together 66 → 42;",
        "the parents' shape alone Tuah 91 → 50 (→ 54 with a base linear in Tp between",
        "the parents).  Tried and not adopted: PCHIP, Akima",
        "and makima through all of a column's computed Hs (at most half the miss, no",
        "case fewer); accepting the halves of a failed interval unchecked where the",
        "interval's miss over 4 (a second-order law's error at half the step) meets the",
        "tolerance (with the ratios' law 10–20 % fewer cases, but unchecked misses of",
        "2.9e-3 on σ and 6.4e-3 on end damage on the taut wire); the moments on Tuah's leg",
        "(its residual variance no power of Hs: σ missed by 1e-2 between Hs 1 m apart,",
        "the ratios' law 7e-3), so each period chooses.  Not tried: interpolating each",
        "computed case's residual spectral density line by line (the chunks would return",
        "them); the moments m0 and m2 are two of its integrals.  On Tuah's realistic",
        "diagram every period is computed: its corrections move with the period by",
        "more than the tolerance between periods 2–3 s apart (the middle period missed",
        "by 2.2e-3 … 7.4e-3 linear in Tp, 2.6e-3 … 3.3e-3 quadratic through a third",
        "computed period; replayed on the every-case set), so neither that law nor",
        "leaving out the spread test computes fewer than 44 of 100, and its end periods",
        "taking the middle period's or the other end's shape none fewer.",
        "",
        "What a case's fixed point saves in a set: each anchor starts from the σ of the",
        "computed cases of its column interpolated in Hs",
        "(`stochcable.cases.anchor_passes.column_start`), every other case from those",
        "or its run's neighbours; a warm start iterates on the full grid alone (no",
        "coarse stage: from a start already near, its coarse evaluations cost more",
        "than they save: the chain's linear set 2.7 evaluations a case instead of 4.7,",
        "−7 % a case, the taut wire's and Tuah's −20 … −25 %; σ within 2e-5), and its",
        "first evaluation opens the Anderson memory, so the next step is a secant",
        "step (Tuah's started cases 104 evaluations instead of 121).  Tried and not",
        "kept: the first pass's anchors in warm-start runs instead of at rest (Tuah",
        "−13 % evaluations, within the timing noise, and re-solved leads on chunked",
        "executors).  `analyze()` itself would be faster without the coarse stage on",
        "these two lines (taut wire 25.5 against 30.4 ms: 2 evaluations from rest;",
        "Tuah 16.8 against 18.2 ms), which would raise the ratios above.  Tried on",
        "Tuah's realistic set and not kept: Anderson's memory opened with the case",
        "before's last secant pair (−0.17 evaluations a case), a relaxed or",
        "over-relaxed second point (0.5 … 2: more evaluations), a column start",
        "corrected by a fully computed period's shape (no closer: its σ's shape in Hs",
        "changes with the period).",
    ]


def _meshed(others: dict) -> list[str]:
    """What Tuah's leg at its default mesh shows (the text, with its figures)."""
    meshed = [k for k in others if _MESHED in k]  # (keys "<name>, <n> periods")
    if not meshed:
        return []
    real = others[max(meshed, key=lambda k: int(k.rsplit(", ", 1)[1].split()[0]))]
    return [
        "*Tuah's leg at its default mesh* (the count the planner derives when the",
        "segment's `elements` is left out) is a set's typical line: its `analyze()` is",
        "the model's work, not the pipeline's fixed cost, and its default set costs",
        f"{real['default']:.2f} × `analyze()` a case on the realistic diagram.  With",
        "Tuah's own 3 elements (4 free DOFs) a case is mostly the pipeline's fixed",
        "cost, the same in a set and in `analyze()`, and the ratio stays above 1/3.",
        "Its largest miss on the end damage rate",
        f"({real['misses']['end damage rate']:.1e}) is within the set's target (1e-2 on",
        "damage; the checks' tolerance is 6e-3) but above the checks' tolerance: it lies",
        "inside periods that borrow their parents' shape (Tp 12–13 s, Hs between the",
        "computed middle and largest), where only the first middle Hs is checked.",
    ]


def _switched(scene, on: bool):
    lin = scene.analysis.linearization.model_copy(
        update={"drag_residual": on, "geometric_residual": on}
    )
    return scene.model_copy(
        update={"analysis": scene.analysis.model_copy(update={"linearization": lin})}
    )


#: cProfile function names per part of a corrected case (cumulative times).
_PARTS = {
    "drag residual, end tensions (drag_residual)": "drag_residual",
    "geometric residual, end tensions (geometric_residual)": "geometric_residual",
    "element tensions' residuals (along_line_residual)": "along_line_residual",
    "element tensions' corrected densities (element_densities)": "element_densities",
    "drag fixed point (linearize_coupled)": "linearize_coupled",
}


#: cProfile (file suffix, function) per part of a case (cumulative times); the
#: residuals' parts are subtracted from the outputs' (line_result holds them).
_CASE_PARTS = {
    "fixed point": ("group_fixed_point.py", "linearize_coupled"),
    "Foss eigenproblems": ("modal_solvers.py", "foss_modes"),
    "outputs": ("line_result.py", "line_result"),
    "residuals": ("drag_form_guard.py", "guarded"),
    "geometric": ("geometric_residual.py", "geometric_residual"),
    "along": ("along_line.py", "along_line_residual"),
    "densities": ("chunk.py", "_along_densities"),
    "mesh check": ("mesh_engine.py", "__call__"),
    "damage rates": ("spectral_fatigue.py", "damage_rate"),
    "evaluations": ("group.py", "__call__"),
}


def _breakdown(src, sd, fat, **kw) -> dict:
    """Where a set's case time goes (cProfile of one set after a warm-up): per case,
    the drag fixed point (its evaluations and Foss eigenproblems, counts), the
    residuals, the other outputs, the mesh check and the damage rates [ms]."""
    run_cases(src, sd, fatigue=fat, **kw)
    prof = cProfile.Profile()
    prof.enable()
    run_cases(src, sd, fatigue=fat, **kw)
    prof.disable()
    st = pstats.Stats(prof).stats
    n = len(sd.states)

    def get(part, col=3):
        suffix, fn = _CASE_PARTS[part]
        return sum(v[col] for k, v in st.items() if k[0].endswith(suffix) and k[2] == fn)

    res = sum(get(k) for k in ("residuals", "geometric", "along", "densities"))
    out = {
        "case": max(v[3] for v in st.values()) / n * 1e3,
        "fixed point": get("fixed point") / n * 1e3,
        "eig": get("Foss eigenproblems") / n * 1e3,
        "evaluations": get("evaluations", 1) / n,
        "eigenproblems": get("Foss eigenproblems", 1) / n,
        "residuals": res / n * 1e3,
        "outputs": (get("outputs") - res + get("densities")) / n * 1e3,
        "mesh check": get("mesh check") / n * 1e3,
        "damage rates": get("damage rates") / n * 1e3,
    }
    out["rest"] = out["case"] - sum(
        out[k] for k in ("fixed point", "residuals", "outputs", "mesh check", "damage rates")
    )
    return out


def _corrected(scene, sd, fatigue, n_set: int) -> dict:
    """The corrected set — the default (adaptive anchors), every case computed
    (residual_tolerance=None) and the fixed anchors (residual_span=5,
    residual_tolerance=None) — against the corrected analysis, fastest of
    interleaved rounds."""
    on, off = _switched(scene, True), _switched(scene, False)
    n_an = 5
    analyze(on)
    t: dict[str, list[float]] = {k: [] for k in ("analyze", "analyze_linear")}
    # a set's time as the sum over its chunks of each chunk's fastest round (chunks of
    # 16 cases: whole warm-start runs, so the same solves as in one chunk), plus the
    # fastest engine build: a set is timed as finely as an analysis, so that the
    # host's load moves both alike.  The adaptive set's passes depend on its numbers:
    # it is timed whole (one run_cases on the built engine per round).
    plans = {
        "case_fixed": plan_cases(on, sd, fatigue=fatigue, chunk_size=16, residual_span=5),
        "case_exact": plan_cases(on, sd, fatigue=fatigue, chunk_size=16),
        "case_linear": plan_cases(off, sd, fatigue=fatigue, chunk_size=16),
    }
    chunk_t = {k: [[] for _ in p.chunks] for k, p in plans.items()}
    sets = {}
    build_t = {k: [] for k in plans}
    parts: dict[str, list] = {}
    adaptive_t, hs_only_t, engine = [], [], None
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
                if key == "case_exact":  # (the same engine: on's template)
                    t0 = time.process_time()
                    sets["case"] = run_cases(on, sd, fatigue=fatigue, engine=engine)
                    adaptive_t.append(time.process_time() - t0)
                    with _hs_only():  # (every period's first anchors in the first pass)
                        t0 = time.process_time()
                        sets["hs_only"] = run_cases(on, sd, fatigue=fatigue, engine=engine)
                        hs_only_t.append(time.process_time() - t0)
    for key, plan in plans.items():
        t0 = time.process_time()
        sets[key] = assemble_cases(plan, parts[key])
        total = time.process_time() - t0 + min(build_t[key])
        t[key] = [(total + sum(min(c) for c in chunk_t[key])) / len(sd.states)]
    t["case"] = [(min(adaptive_t) + min(build_t["case_exact"])) / len(sd.states)]
    t["case_hs_only"] = [(min(hs_only_t) + min(build_t["case_exact"])) / len(sd.states)]
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
    interp = {
        "adaptive (default)": _misses(sets["case"], exact, "leg1"),
        "adaptive in Hs only": _misses(sets["hs_only"], exact, "leg1"),
        "fixed (`residual_span=5`)": _misses(sets["case_fixed"], exact, "leg1"),
    }
    prof = cProfile.Profile()
    prof.enable()
    run_cases(on, sd, fatigue=fatigue, residual_tolerance=None)
    prof.disable()
    stats = pstats.Stats(prof).stats
    total = max(v[3] for v in stats.values())
    shares = {}
    for label, fn in _PARTS.items():
        shares[label] = sum(v[3] for k, v in stats.items() if k[2] == fn) / total
    shares["the rest"] = 1.0 - sum(shares.values())
    fixed = int(sum(1 for c in plans["case_fixed"].chunks for x in c if x[2]))
    computed = _computed(on, sd, fatigue)
    with _hs_only():
        hs_only = _computed(on, sd, fatigue)
    out.update(worst=worst, shares=shares, n_an=n_an, n_set=n_set, interp=interp,
               anchors=fixed, computed=computed,
               first=int(first_anchors(sd.states, None).sum()), hs_only=hs_only)  # fmt: skip
    return out


#: The row of the elements' damage misses relative to the line's largest damage rate.
_EL_BIG = "element damage rate, of the line's largest"


def _misses(got, exact, line: str) -> dict:
    """Largest relative difference of ``got`` from ``exact`` over the cases and both
    ends: σ, Tz, 3-h MPM, end damage rate; annual damage and return level per end."""
    out = {}
    for label, col in (("σ", 1), ("Tz", 2), ("3-h MPM", 3)):
        out[label] = max(
            float(np.nanmax(np.abs(got.stats[line][e][:, col] / exact.stats[line][e][:, col] - 1)))
            for e in ("end_a", "end_b")
        )
    d = got.damage_rate_ends[line] / exact.damage_rate_ends[line] - 1
    out["end damage rate"] = float(np.nanmax(np.abs(d)))
    a, b = got.damage_rate_along[line], exact.damage_rate_along[line]
    big = np.nanmax(np.column_stack([exact.damage_rate_ends[line], b]), axis=1)[:, None]
    out[_EL_BIG] = float(np.nanmax(np.abs(a - b) / big))
    out["element damage rate, of its own"] = float(np.nanmax(np.abs(a / b - 1)))
    for e in ("end_a", "end_b"):
        a, b = got.totals[line], exact.totals[line]
        out[f"annual damage, {e}"] = abs(a.annual_damage[e] / b.annual_damage[e] - 1)
        out[f"100-year return level, {e}"] = abs(a.return_level[e] / b.return_level[e] - 1)
    return out


@contextlib.contextmanager
def _hs_only():
    """The adaptive anchors in Hs only, as before the checks across periods: every
    period's first anchors in the first pass (so no period is interpolated)."""
    import stochcable.cases.plan as plan_mod
    import stochcable.cases.run as run_mod
    from stochcable.cases.anchor_layout import layout
    from stochcable.cases.residual_anchors import _open as open_column  # noqa: PLC2701

    real = plan_mod.first_anchors

    def every_period(states, span):
        out = np.zeros(len(states), dtype=bool)
        for cols in layout(states).values():
            for col in cols:
                open_column(col, span, out)
        return out

    plan_mod.first_anchors = run_mod.first_anchors = every_period
    try:
        yield
    finally:
        plan_mod.first_anchors = run_mod.first_anchors = real


def _computed(scene, sd, fatigue) -> int:
    """How many cases the default set computes the residuals on (first pass and the
    checks' later passes)."""
    import stochcable.cases.run as run_mod

    real, seen = run_mod.next_anchors, {}

    def spy(*a, **k):
        more = real(*a, **k)
        seen["exact"] = a[3] | more
        return more

    run_mod.next_anchors = spy
    try:
        run_cases(scene, sd, fatigue=fatigue)
    finally:
        run_mod.next_anchors = real
    return int(seen["exact"].sum()) if seen else len(sd.states)


#: The other lines of the accuracy check: example, Hs range and count, the Tp values
#: of each diagram (a 4-period one and a realistic one, Tp every 1 s), fatigue settings
#: (the linearization tolerance 1e-4 on every line: Tuah's scene has 1e-2, a noise the
#: ratios would carry).  A name ending in :data:`_MESHED` is its example with the
#: segments' ``elements`` left out: the mesh the planner derives for ≤ 1 % on the
#: end-tension σ (Tuah's own 3 elements are flagged at 160–690 % on these seas).
_OTHERS = {
    "taut_wire": (
        0.5,
        3.5,
        13,
        ((6.0, 8.0, 10.0, 12.0), tuple(float(t) for t in range(6, 14))),
        ("dnv-six-strand", {"nominal_area": 1.2e-3}),
    ),
    "tuah_1982_single_leg": (
        1.0,
        10.0,
        10,
        ((6.0, 9.0, 12.0, 15.0), tuple(float(t) for t in range(6, 16))),
        ("api-studless", {"mbs": 2.0e5}),
    ),
}
_MESHED = ", default mesh"
_OTHERS["tuah_1982_single_leg" + _MESHED] = _OTHERS["tuah_1982_single_leg"]


def _other_lines() -> dict:
    """The default set against every case computed on the other lines' diagrams:
    cases, computed cases, largest misses, and the CPU time of the default set, of
    every case computed and of the linear set (the residuals off: the floor of any
    set that corrects every case by interpolation) over one corrected analyze()."""
    out = {}
    for name, (h0, h1, nh, diagrams, (curve, kw)) in _OTHERS.items():
        doc = load_example(name.removesuffix(_MESHED)).model_dump(mode="json", exclude_none=True)
        doc["analysis"].pop("timeseries", None)
        doc["analysis"].setdefault("linearization", {}).update(
            drag_residual=True, geometric_residual=True, tolerance=1e-4
        )
        if name.endswith(_MESHED):
            for line in doc["lines"]:
                for seg in line["segments"]:
                    seg.pop("elements", None)
        off = _switched(load_scene(doc), False)
        scene = load_scene(doc)
        fat = LineFatigue(curve, **kw)
        for tps in diagrams:
            rows = [
                {"hs": float(h), "tp": tp, "hours": 1.0}
                for tp in tps
                for h in np.linspace(h0, h1, nh)
            ]
            sd = scatter_from_rows(rows)
            run_cases(doc, sd, fatigue=fat)  # (warm-up: the line's kernels)
            analyze(scene)
            t = {"analyze": [], "exact": [], "default": [], "linear": []}
            for _ in range(3):  # interleaved rounds, the fastest of each
                for _ in range(3):
                    t0 = time.process_time()
                    analyze(scene)
                    t["analyze"].append(time.process_time() - t0)
                t0 = time.process_time()
                exact = run_cases(doc, sd, fatigue=fat, residual_tolerance=None)
                t1 = time.process_time()
                got = run_cases(doc, sd, fatigue=fat)
                t2 = time.process_time()
                run_cases(off, sd, fatigue=fat)
                t["exact"].append((t1 - t0) / len(rows))
                t["default"].append((t2 - t1) / len(rows))
                t["linear"].append((time.process_time() - t2) / len(rows))
            an = min(t["analyze"])
            line = exact.lines[0]
            prof = {}
            if len(tps) <= 4:  # (where a case's time goes: the linear, every-case sets)
                prof = {"linear": _breakdown(off, sd, fat),
                        "every case computed": _breakdown(doc, sd, fat, residual_tolerance=None),
                        "analyze": an * 1e3}  # fmt: skip
            periods = (
                ", ".join(f"{t:g}" for t in tps)
                if len(tps) <= 4
                else (f"{tps[0]:g}–{tps[-1]:g} every 1")
            )
            out[f"{name}, {len(tps)} periods"] = {
                "name": name, "cases": len(rows), "computed": _computed(scene, sd, fat),
                "misses": _misses(got, exact, line),
                "default": min(t["default"]) / an, "exact": min(t["exact"]) / an,
                "linear": min(t["linear"]) / an,
                "diagram": f"Hs {h0:g}–{h1:g} m ({nh}) × Tp {periods} s", "profile": prof,
            }  # fmt: skip
    return out


def _north_atlantic() -> None:
    """The default set against every case computed on the bundled North Atlantic
    diagram (111 cases, columns of Tz reaching different Hs) for the three lines:
    cases computed and the largest misses (``--north-atlantic``; printed only)."""
    from stochcable.cases import read_scatter
    from stochcable.examples import resources

    path = resources.files("stochcable.examples") / "scatter_north_atlantic.csv"
    sd = read_scatter(str(path))
    lines = {"chain_catenary": ("dnv-studless", {"nominal_diameter": 0.084}),
             **{k: v[4] for k, v in _OTHERS.items() if not k.endswith(_MESHED)}}  # fmt: skip
    print("| line | cases computed | σ | Tz | 3-h MPM | end damage rate | element damage "
          "rate, of the line's largest (of its own) |\n|---|---|---|---|---|---|---|")  # fmt: skip
    for name, (curve, kw) in lines.items():
        doc = load_example(name).model_dump(mode="json", exclude_none=True)
        doc["analysis"].pop("timeseries", None)
        doc["analysis"].setdefault("linearization", {}).update(
            drag_residual=True, geometric_residual=True, tolerance=1e-4
        )
        fat = LineFatigue(curve, **kw)
        ref = run_cases(doc, sd, fatigue=fat, residual_tolerance=None)
        got = run_cases(doc, sd, fatigue=fat)
        m = _misses(got, ref, ref.lines[0])
        print(f"| {name} | {_computed(load_scene(doc), sd, fat)} of {len(sd.states)} | "
              f"{m['σ']:.1e} | {m['Tz']:.1e} | {m['3-h MPM']:.1e} | "
              f"{m['end damage rate']:.1e} | {m[_EL_BIG]:.1e} "
              f"({m['element damage rate, of its own']:.1e}) |")  # fmt: skip


if __name__ == "__main__":
    main()
