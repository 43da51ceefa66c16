"""Adaptive fidelity (issue 7, item 2): the settings chosen by
:func:`stochcable.fidelity.planner.choose_fidelity` against a converged reference.

For each example scene and target (1 %, 5 %): plan (its wall time includes the statics
and the pilot analysis), apply, analyze (median wall time), and compare the σ of the
fairlead (end_b) and anchor (end_a) tension and of the motion at the example mesh's
fairlead-adjacent node (``benchmarks/speed_vs_error.quantities_fd``) with a reference:
direct solve, linearization tolerance 1e-8, every planned segment with 4× the 1 %
plan's elements, linear grid on [ω_min/2, 2·ω_max] of the 1 % plan with a quarter of
its spacing (the "uniform fine model"; its ×2-element twin shows its convergence).

Run:  python benchmarks/adaptive_fidelity.py [scene ...]   (prints a Markdown table)
"""

from __future__ import annotations

import statistics
import sys
import time
import warnings
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from speed_vs_error import base_document, quantities_fd  # noqa: E402

from stochcable.analysis import analyze  # noqa: E402
from stochcable.fidelity import apply_fidelity, choose_fidelity  # noqa: E402
from stochcable.line.mesh import mesh_line  # noqa: E402
from stochcable.scene.model import load_scene  # noqa: E402

SCENES = ("taut_wire", "chain_catenary", "inclined_guy", "tuah_1982_single_leg")
TARGETS = (0.01, 0.05)
QUANT = ("T_fairlead", "T_anchor", "motion")


def timed(scene, repeats=3):
    ts, res = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        res = analyze(scene)
        ts.append(time.perf_counter() - t0)
    return res, statistics.median(ts)


def s_star_of(scene) -> float:
    line = scene.lines[0]
    env = scene.environment
    return float(mesh_line(line, env.rho, env.g).s0[-2])


def reference(scene, plan, factor: int):
    wmin, wmax = plan.omega_min / 2.0, 2.0 * plan.omega_max
    dw = (plan.omega_max - plan.omega_min) / (plan.omega_count - 1) / 4.0
    count = min(8000, int((wmax - wmin) / dw) + 1)
    segs = {k: tuple((i, L, factor * n) for i, L, n in v) for k, v in plan.segments.items()}
    from dataclasses import replace

    p2 = replace(
        plan,
        segments=segs,
        omega_min=wmin,
        omega_max=wmax,
        omega_count=count,
        solver="direct",
        modes="auto",
        tolerance=1e-8,
        choices=(),
    )
    sc = apply_fidelity(scene, p2)
    lin = sc.analysis.linearization.model_copy(update={"max_iterations": 500})
    sc = sc.model_copy(update={"analysis": sc.analysis.model_copy(update={"linearization": lin})})
    res, t = timed(sc, 1)
    return res, t, sum(n for v in segs.values() for _, _, n in v), count


def main(names) -> int:
    rows = []
    for name in names:
        base = load_scene(base_document(name))
        s_star = s_star_of(base)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            plans = {}
            for tgt in TARGETS:
                t0 = time.perf_counter()
                plans[tgt] = choose_fidelity(base, tgt, evaluate=analyze)
                plans[tgt] = (plans[tgt], time.perf_counter() - t0)
            p1 = plans[TARGETS[0]][0]
            ref4, t4, el4, c4 = reference(base, p1, 4)
            ref2, t2, el2, c2 = reference(base, p1, 2)
            q4, q2 = quantities_fd(ref4, s_star), quantities_fd(ref2, s_star)
            conv = max(abs(q2[q] / q4[q] - 1) for q in QUANT)
            dres, dt = timed(base)
            qd = quantities_fd(dres, s_star)
            rows.append(
                (
                    name,
                    "example default",
                    "-",
                    f"{base.lines[0].elements} el, "
                    f"{base.analysis.omega.count} ω to {base.analysis.omega.max:g}",
                    "-",
                    dt,
                    [qd[q] / q4[q] - 1 for q in QUANT],
                    t4,
                    el4,
                    c4,
                    conv,
                )
            )
            for tgt in TARGETS:
                plan, tp = plans[tgt]
                sc = apply_fidelity(base, plan)
                res, ta = timed(sc)
                qa = quantities_fd(res, s_star)
                setting = (
                    f"{int(plan.cost['elements'])} el "
                    f"{[n for _, _, n in next(iter(plan.segments.values()))]}, "
                    f"{plan.omega_count} ω on [{plan.omega_min:.3g}, "
                    f"{plan.omega_max:.3g}], {plan.solver}"
                    + (f" modes {plan.modes}" if plan.solver == "foss" else "")
                    + f", tol {plan.tolerance:.0e}"
                    + ("" if plan.tail_bounded else ", tail unbounded")
                )
                rows.append(
                    (
                        name,
                        f"{tgt:.0%}",
                        f"{plan.error_estimate['total']:.2%}",
                        setting,
                        tp,
                        ta,
                        [qa[q] / q4[q] - 1 for q in QUANT],
                        t4,
                        el4,
                        c4,
                        conv,
                    )
                )
            print(f"done {name}", file=sys.stderr)
    print(
        "| scene | target | estimate | chosen settings | plan time | analysis time | "
        "error fairlead / anchor / motion | uniform fine model (time, elements, ω) | "
        "its ×2→×4 change |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        name, tgt, est, setting = r[:4]
        if tgt == "example default":
            tp, ta, err, t4, el4, c4, conv = "-", r[5], r[6], r[7], r[8], r[9], r[10]
        else:
            tp, ta, err, t4, el4, c4, conv = r[4], r[5], r[6], r[7], r[8], r[9], r[10]
        tps = tp if isinstance(tp, str) else f"{tp * 1e3:.0f} ms"
        print(
            f"| {name} | {tgt} | {est} | {setting} | {tps} | {ta * 1e3:.0f} ms | "
            + " / ".join(f"{e:+.2%}" for e in err)
            + f" | {t4:.2f} s, {el4}, {c4} | {conv:.2%} |"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:] or SCENES))
