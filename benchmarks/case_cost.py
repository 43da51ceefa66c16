"""What one case of a load-case set costs against one ``analyze()`` (issue 31).

    OPENBLAS_NUM_THREADS=1 python3 benchmarks/case_cost.py [--rounds 4] [--lines taut tuah]
    OPENBLAS_NUM_THREADS=1 python3 benchmarks/case_cost.py --solvers

Per line (the chain, the taut wire and Tuah's single leg on the 4-period diagrams of
docs/benchmarks/cases.md, ``--realistic`` Tp every 1 s; the linearization tolerance
1e-4, both residuals on), the fastest of interleaved rounds in one process (CPU time)
of: one ``analyze()`` with the residuals, the same without the node motions' residuals
(``MOTION_RESIDUALS`` off, as a set's cases) and without any residual; per case, the
linear set (residuals off), the set with every case computed
(``residual_tolerance=None``) — both on an engine built once — and the default set
(adaptive anchors, its engine built inside).  A computed
case's residuals are the every-case set's case less the linear set's; what they are
held against is ``analyze()``'s residuals less the node motions' (``--same-seas``:
also of ``analyze()`` of every sea of the set, which split more elements than the
scene's own sea where the set's Hs are larger).

``--solvers``: the linear set per case by the Foss and the direct solve (the rule of
:func:`stochcable.cases.chunk.set_engine`) on the chain, the taut wire, Tuah's leg
and the two-segment line, and their largest σ difference.
"""

from __future__ import annotations

import argparse
import copy
import os
import time
import warnings

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
from host_probe import host_line

from stochcable import runtime
from stochcable.analysis import analyze
from stochcable.cases import LineFatigue, plan_cases, run_cases, scatter_from_rows
from stochcable.cases.chunk import set_engine
from stochcable.dynamics.outputs.line_result import MOTION_RESIDUALS
from stochcable.examples import load_example
from stochcable.fidelity.mesh_engine import checked_engine
from stochcable.scene.model import load_scene

#: example, Hs range and count, periods, fatigue settings (docs/benchmarks/cases.md)
LINES = {
    "chain": ("chain_catenary", 1.0, 10.0, 10, (6.0, 9.0, 12.0, 15.0),
              ("dnv-studless", {"nominal_diameter": 0.084})),
    "taut": ("taut_wire", 0.5, 3.5, 13, (6.0, 8.0, 10.0, 12.0),
             ("dnv-six-strand", {"nominal_area": 1.2e-3})),
    "tuah": ("tuah_1982_single_leg", 1.0, 10.0, 10, (6.0, 9.0, 12.0, 15.0),
             ("api-studless", {"mbs": 2.0e5})),
}  # fmt: skip


def _doc(example: str, on: bool) -> dict:
    if example == "two-segment":
        import residual_cost

        doc = copy.deepcopy(residual_cost.lines()["two-segment"])
    else:
        doc = load_example(example).model_dump(mode="json", exclude_none=True)
    doc["analysis"].pop("timeseries", None)
    doc["analysis"].setdefault("linearization", {}).update(
        drag_residual=on, geometric_residual=on, tolerance=1e-4
    )
    return doc


def _diagram(h0: float, h1: float, nh: int, tps: tuple[float, ...]):
    rows = [{"hs": float(h), "tp": tp, "hours": 1.0} for tp in tps for h in np.linspace(h0, h1, nh)]
    return scatter_from_rows(rows)


def _clock(fn) -> float:
    t0 = time.process_time()
    fn()
    return time.process_time() - t0


#: the realistic diagrams of docs/benchmarks/cases.md (``--realistic``): Tp every 1 s
REALISTIC = {"chain": tuple(range(6, 17)), "taut": tuple(range(6, 14)), "tuah": tuple(range(6, 16))}


def costs(
    name: str, rounds: int, realistic: bool = False, same_seas: bool = False
) -> dict[str, float]:
    """The fastest CPU time [ms] of each part (module notes); per case for the sets;
    ``same_seas``: also ``analyze()`` of every sea of the set (per case: with the
    residuals, without the node motions', linear)."""
    example, h0, h1, nh, tps, (curve, kw) = LINES[name]
    if realistic:
        tps = tuple(float(t) for t in REALISTIC[name])
    on, off = _doc(example, True), _doc(example, False)
    scene, linear = load_scene(on), load_scene(off)
    sd, fat = _diagram(h0, h1, nh, tps), LineFatigue(curve, **kw)
    n = len(sd.states)
    eng_on = set_engine(plan_cases(on, sd, fatigue=fat).template)
    eng_off = set_engine(plan_cases(off, sd, fatigue=fat).template)

    def no_motions() -> None:
        token = MOTION_RESIDUALS.set(False)
        try:
            analyze(scene)
        finally:
            MOTION_RESIDUALS.reset(token)

    parts = {
        "analyze": lambda: analyze(scene),
        "analyze, no node motions": no_motions,
        "analyze, linear": lambda: analyze(linear),
        "linear set": lambda: run_cases(off, sd, fatigue=fat, engine=eng_off),
        "every case computed": lambda: run_cases(
            on, sd, fatigue=fat, engine=eng_on, residual_tolerance=None
        ),
        "default set": lambda: run_cases(on, sd, fatigue=fat),
    }
    per_case = {"linear set", "every case computed", "default set"}
    if same_seas:
        from stochcable.cases.chunk import case_sea

        seas = [case_sea(scene, st, sd.family) for st in sd.states]
        each = [scene.model_copy(update={"sea": sea}) for sea in seas]
        each_lin = [linear.model_copy(update={"sea": sea}) for sea in seas]

        def each_no_motions() -> None:
            token = MOTION_RESIDUALS.set(False)
            try:
                for sc in each:
                    analyze(sc)
            finally:
                MOTION_RESIDUALS.reset(token)

        parts["its seas"] = lambda: [analyze(sc) for sc in each]
        parts["its seas, no node motions"] = each_no_motions
        parts["its seas, linear"] = lambda: [analyze(sc) for sc in each_lin]
        per_case |= {"its seas", "its seas, no node motions", "its seas, linear"}
    for fn in parts.values():  # (warm-up: imports, kernels)
        fn()
    best = {k: np.inf for k in parts}
    for _ in range(rounds):
        for k, fn in parts.items():
            best[k] = min(best[k], _clock(fn) / (n if k in per_case else 1))
    return {k: v * 1e3 for k, v in best.items()}


def solvers(rounds: int, names: list[str]) -> None:
    """The linear set per case by the Foss and the direct solve (module notes) on the
    lines ``names`` (of ``LINES`` and "two-segment")."""
    examples = {"two-segment": "two-segment", **{k: v[0] for k, v in LINES.items()}}
    for name, example in ((k, v) for k, v in examples.items() if k in names):
        _, h0, h1, nh, tps, _ = LINES.get(name, LINES["chain"])
        doc, sd = _doc(example, False), _diagram(h0, h1, nh, tps)
        tmpl = plan_cases(doc, sd).template
        engines = {
            s: checked_engine(
                tmpl.model_copy(update={"analysis": tmpl.analysis.model_copy(update={"solver": s})})
            )
            for s in ("foss", "direct")
        }
        sets = {s: run_cases(doc, sd, engine=e) for s, e in engines.items()}
        best = {s: np.inf for s in engines}
        for _ in range(rounds):
            for s, e in engines.items():
                best[s] = min(best[s], _clock(lambda e=e: run_cases(doc, sd, engine=e)))
        line = sets["foss"].lines[0]
        sig = {
            s: np.stack([r.stats[line][e][:, 1] for e in ("end_a", "end_b")])
            for s, r in sets.items()
        }
        diff = float(np.nanmax(np.abs(sig["direct"] / sig["foss"] - 1)))
        (sys_,) = engines["foss"].systems.values()
        print(
            f"{name}: {sys_.model.free.size} free DOFs, Foss keeps {sys_.n_modes} modes; "
            f"linear set per case Foss {best['foss'] / len(sd.states) * 1e3:.2f} ms, direct "
            f"{best['direct'] / len(sd.states) * 1e3:.2f} ms (direct/Foss "
            f"{best['direct'] / best['foss']:.2f}); largest σ difference {diff:.1e}"
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=4)
    ap.add_argument("--lines", nargs="*", default=[*LINES, "two-segment"])
    ap.add_argument("--solvers", action="store_true")
    ap.add_argument("--realistic", action="store_true", help="Tp every 1 s")
    ap.add_argument("--same-seas", action="store_true", help="analyze() of the set's seas")
    args = ap.parse_args()
    runtime.configure()
    warnings.simplefilter("ignore")
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores; {host_line()}")
    if args.solvers:
        solvers(args.rounds, args.lines)
        return
    for name in (n for n in args.lines if n in LINES):
        c = costs(name, args.rounds, args.realistic, args.same_seas)
        an = c["analyze"]
        resid = c["every case computed"] - c["linear set"]
        target = (
            c["analyze"] - c["analyze, linear"] - (c["analyze"] - c["analyze, no node motions"])
        )
        print(
            f"{name}: analyze() {an:.2f} ms (linear {c['analyze, linear']:.2f}, no node motions "
            f"{c['analyze, no node motions']:.2f}); per case / analyze(): linear set "
            f"{c['linear set'] / an:.3f}, every case computed {c['every case computed'] / an:.3f}, "
            f"default set {c['default set'] / an:.3f}; a computed case's residuals {resid:.2f} ms "
            f"({resid / an:.3f} x), analyze()'s less the node motions' {target:.2f} ms"
        )
        if args.same_seas:
            own = c["its seas, no node motions"] - c["its seas, linear"]
            print(
                f"  analyze() of the set's seas, per case: {c['its seas']:.2f} ms (linear "
                f"{c['its seas, linear']:.2f}); its residuals less the node motions' {own:.2f} "
                f"ms against a computed case's {resid:.2f} ms in the set"
            )
    print(f"load average at the end {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
