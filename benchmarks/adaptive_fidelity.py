"""Adaptive fidelity: the settings chosen by
:func:`stochcable.fidelity.planner.choose_fidelity` against a converged reference.

For each example scene and target (1 %, 5 %): plan (its wall time includes the statics
and the pilot analysis), apply, analyze (median wall time), and compare the σ of the
fairlead (end_b) and anchor (end_a) tension and of the motion at the example mesh's
fairlead-adjacent node (``benchmarks/speed_vs_error.quantities_fd``) with a reference:
direct solve, linearization tolerance 1e-8, every planned segment with 4× the 1 %
plan's elements, linear grid on [ω_min/2, 2·ω_max] of the 1 % plan with a quarter of
its spacing (the "uniform fine model"; its ×2-element twin shows its convergence).

Run:  python benchmarks/adaptive_fidelity.py [scene ...]   (prints the Markdown section;
``python benchmarks/speed_vs_error.py --write`` puts it into docs/ACCURACY.md)
"""

from __future__ import annotations

import statistics
import sys
import time
import warnings
from dataclasses import dataclass
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


@dataclass(frozen=True)
class FidelityRow:
    """One plan (or the example's default) of one scene against its fine model."""

    scene: str
    target: str
    estimate: str
    setting: str
    plan_s: float | None
    analysis_s: float
    errors: tuple[float, ...]
    fine_s: float
    fine_elements: int
    fine_count: int
    fine_change: float


def study_fidelity(names, progress=None) -> list[FidelityRow]:
    """Plan, apply and analyze every scene of ``names`` at every target of
    :data:`TARGETS`, and the example's default, against the uniform fine model."""
    rows: list[FidelityRow] = []
    for name in names:
        base = load_scene(base_document(name))
        s_star = s_star_of(base)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            plans = {}
            for tgt in TARGETS:
                t0 = time.perf_counter()
                plan = choose_fidelity(base, tgt, evaluate=analyze)
                plans[tgt] = (plan, time.perf_counter() - t0)
            p1 = plans[TARGETS[0]][0]
            ref4, t4, el4, c4 = reference(base, p1, 4)
            ref2, _, _, _ = reference(base, p1, 2)
            q4, q2 = quantities_fd(ref4, s_star), quantities_fd(ref2, s_star)
            conv = max(abs(q2[q] / q4[q] - 1) for q in QUANT)
            fine = (t4, el4, c4, conv)
            dres, dt = timed(base)
            qd = quantities_fd(dres, s_star)
            rows.append(
                FidelityRow(
                    name,
                    "example default",
                    "-",
                    f"{base.lines[0].elements} el, "
                    f"{base.analysis.omega.count} ω to {base.analysis.omega.max:g}",
                    None,
                    dt,
                    tuple(qd[q] / q4[q] - 1 for q in QUANT),
                    *fine,
                )
            )
            for tgt in TARGETS:
                plan, tp = plans[tgt]
                res, ta = timed(apply_fidelity(base, plan))
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
                    FidelityRow(
                        name,
                        f"{tgt:.0%}",
                        f"{plan.error_estimate['total']:.2%}",
                        setting,
                        tp,
                        ta,
                        tuple(qa[q] / q4[q] - 1 for q in QUANT),
                        *fine,
                    )
                )
        if progress is not None:
            progress(f"adaptive fidelity: {name} done")
    return rows


def render_table(rows: list[FidelityRow]) -> list[str]:
    """The Markdown table of :func:`study_fidelity`'s rows."""
    out = [
        "| scene | target | estimate | chosen settings | plan time | analysis time | "
        "error fairlead / anchor / motion | uniform fine model (time, elements, ω) | "
        "its ×2→×4 change |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        tps = "-" if r.plan_s is None else f"{r.plan_s * 1e3:.0f} ms"
        out.append(
            f"| {r.scene} | {r.target} | {r.estimate} | {r.setting} | {tps} | "
            f"{r.analysis_s * 1e3:.0f} ms | "
            + " / ".join(f"{e:+.2%}" for e in r.errors)
            + f" | {r.fine_s:.2f} s, {r.fine_elements}, {r.fine_count} | "
            f"{r.fine_change:.2%} |"
        )
    return out


INTRO = """`stochcable.fidelity.choose_fidelity(scene, target_error)` picks the settings from the
scene itself and `apply_fidelity(scene, plan)` returns a new scene with them (rules
and their closed forms in the module docstring of `stochcable.fidelity`). The budget ε is split
band 30 % / grid 15 % / elements 35 % / modes 10 % / linearization 10 %. In short:
ω_min, ω_max from the **response** spectra of a cheap pilot analysis (log grid, mesh with
kh = 1 at its top, the top doubled up to four times until the response tail beyond it is
bounded — power law S ∝ ω^-p fitted to the top fifth, truncated variance S·ω/(p − 1) —
and the pilot covers 2·ω_max); grid spacing from the input spectra's trapezoid error
and 2e^(-πN) ≤ ε on each lightly damped modal peak (N points per half-power
bandwidth, ζ from the pilot's modes and drag); elements from the consistent-mass string
dispersion (kh)²/24 at the response's ω₂ = √(m₂/m₀) (and kh ≤ 1.5 at ω_max), a node at
the static touchdown with h ≤ √ε × suspended length, and the nodal wave-kinematics rule
(kh)²/12 for the elements the sea loads, realized by splitting a segment (at the
touchdown, at the wave-load depth) into sub-segments with the same properties; modes
"auto" or a count up to F·ω_max, F = √(0.06/ε_modes), direct above 40 modes; tolerance
0.1·ε.

Errors are against a reference built from the 1 % plan: direct, tolerance 1e-8, 4× the
planned elements in every (split) segment, linear grid on [ω_min/2, 2·ω_max] at a quarter
of the plan's spacing — the "uniform fine model", whose ×2 → ×4 change is shown.
Quantities as above (end_b, end_a tension σ, motion σ at the example mesh's
fairlead-adjacent node). "estimate" is the plan's own error estimate. Times are medians
of 3; the plan time includes the statics and the pilot."""


def render_section(rows: list[FidelityRow]) -> list[str]:
    """The "Adaptive fidelity" section of docs/ACCURACY.md (Markdown lines)."""
    out = ["## Adaptive fidelity", "", INTRO, ""]
    out += render_table(rows)
    out += ["", "Reading:", ""]
    for tgt in TARGETS:
        label = f"{tgt:.0%}"
        sel = [r for r in rows if r.target == label]
        if not sel:
            continue
        worst = max(sel, key=lambda r: max(abs(e) for e in r.errors))
        w = max(abs(e) for e in worst.errors)
        missed = [r.scene for r in sel if max(abs(e) for e in r.errors) > tgt]
        speed = ", ".join(
            f"{r.scene} {(r.plan_s or 0.0) + r.analysis_s:.2f} s against {r.fine_s:.2f} s"
            for r in sel
        )
        out.append(
            f"- **{label}**: "
            + (
                "every quantity of every scene within the target"
                if not missed
                else "target missed on " + ", ".join(missed)
            )
            + f" (worst {w:.2%}, {worst.scene}); plan + analysis against the uniform "
            f"fine model: {speed}."
        )
    return out


def main(names) -> int:
    def progress(msg: str) -> None:
        print(msg, file=sys.stderr)

    print("\n".join(render_section(study_fidelity(names, progress))))
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:] or SCENES))
