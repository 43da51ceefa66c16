"""Cost of the closed-form residuals of the linear model (issue 31): the linear analysis
against the same analysis with the drag residual, the geometric residual and both
(``analysis.linearization.drag_residual`` / ``geometric_residual``), on four lines:

- chain: the bundled example (its sea, 0.5 m/s current and fairlead surge; its time
  series dropped: they cost the same with and without the residuals);
- taut: the bundled taut wire in its sea;
- deep: the accuracy page's deep-water wire catenary (benchmarks/accuracy_lines.py,
  its default FD scene: fairlead surge, 20 elements);
- two-segment: chain on the bed and synthetic rope to the fairlead, the chain
  example's sea, current and surge.

Each variant is timed as one ``analyze`` of a scene document (statics, engine, fixed
point, outputs, residuals), the four variants interleaved, ``--repeat`` rounds in one
process after one warm-up round; the fastest of the rounds is reported with the ratio
to the linear one, and the residual σ ratios (σ with / σ without) at the fairlead; and
the minor page faults (``ru_minflt``) of the fastest round and their median.

    OPENBLAS_NUM_THREADS=1 python3 benchmarks/residual_cost.py [--repeat 3] [--profile LINE]

Measured (docs/benchmarks/residual_cost.md; the steps in residual_cost_notes.md): both
residuals cost 11–66× the linear analysis before issue 31; with the end, element-tension
and node-motion residuals now chain 1.88–1.91×, taut 1.6–1.7×, deep 1.7×, two-segment
1.5× (load ≈ 1.0): exact steps (adjoint end tensions, pairs f ≥ e in cache-sized blocks,
the lag grid at the alias bound, one end influence, the element and node rows in the
same solve, one dense matrix of pair lines per kind) and approximate ones (Hermite
orders 2 and 3 carrying the higher orders' variance, 32 panels, 64 lines over the
inputs' band with resonant cells integrated, the geometric residual on every second
line, only the panels and elements whose forces reach the ends, the lines above those
the ends need by a bound, the misfit on the residual's lines, the end influence through
the linear solve's modal basis on long lines): corrected σ within +0.02…+0.33 % of
before on the four lines and the inclined guy (tests/dynamics/test_drag_residual.py).
"""

from __future__ import annotations

import argparse
import copy
import cProfile
import json
import math
import os
import pstats
import resource
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from accuracy_lines import fd_document  # noqa: E402 (sibling benchmark script)

from stochcable import analyze, load_example  # noqa: E402

VARIANTS = {
    "linear": {},
    "drag": {"drag_residual": True},
    "geometric": {"geometric_residual": True},
    "both": {"drag_residual": True, "geometric_residual": True},
}


def _example(name: str) -> dict:
    doc = load_example(name).model_dump(mode="json", exclude_none=True)
    doc.get("analysis", {}).pop("timeseries", None)
    return doc


def two_segment() -> dict:
    """Chain on the bed (450 m) and synthetic rope (420 m) to the fairlead, in the
    chain example's depth, sea, current and surge."""
    doc = _example("chain_catenary")
    chain = dict(doc["lines"][0]["segments"][0], length=450.0, elements=20)
    rope = {"length": 420.0, "ea": 1.5e8, "mass": 25.0, "diameter": 0.16,
            "cd_normal": 1.2, "cd_axial": 0.008, "ca_normal": 1.0, "elements": 20}  # fmt: skip
    doc["lines"][0]["segments"] = [chain, rope]
    doc["title"] = "two-segment line: chain on the bed, synthetic rope to the fairlead"
    return doc


def _deep_at_20() -> dict:
    """The deep catenary at the 20 elements the residual record was made with (a segment
    without ``elements`` now gets the count the mesh check asks for: 69 here)."""
    doc = fd_document("deep", "default")
    for seg in doc["lines"][0]["segments"]:
        seg["elements"] = 20
    return doc


def lines(guy: bool = False) -> dict[str, dict]:
    """The four scene documents, linear (switches off); with ``guy`` the inclined guy
    too (the line whose split elements the drag residual needs)."""
    out = {
        "chain": _example("chain_catenary"),
        "taut": _example("taut_wire"),
        "deep": _deep_at_20(),
        "two-segment": two_segment(),
    }
    if guy:
        out["guy"] = _example("inclined_guy")
    return out


def residual_variances() -> dict:
    """The drag and geometric residuals' end-tension variances of every line (and the
    guy), both switches on: line → {"drag"|"geometric": {end: variance [N²]},
    "std_linear": {end: σ [N]}}."""
    out = {}
    for name, doc in lines(guy=True).items():
        lr = next(iter(analyze(with_variant(doc, "both")).lines.values()))
        out[name] = {
            key: {end: float(rec.variance[end]) for end in ("end_a", "end_b")}
            for key, rec in (("drag", lr.drag_residual), ("geometric", lr.geometric_residual))
        }
        out[name]["std_linear"] = {end: float(lr.linear_end(end).std) for end in ("end_a", "end_b")}
    return out


def with_variant(doc: dict, variant: str) -> dict:
    out = copy.deepcopy(doc)
    lin = out.setdefault("analysis", {}).setdefault("linearization", {})
    lin.update({"drag_residual": False, "geometric_residual": False, **VARIANTS[variant]})
    return out


def _fairlead_ratio(res, variant: str) -> float:
    """σ with the variant's residuals over the linear σ at end_b (the records' sum)."""
    lr = next(iter(res.lines.values()))
    recs = [r for r in (lr.drag_residual, lr.geometric_residual) if r is not None and r.computed]
    extra = sum(r.variance["end_b"] for r in recs)
    return math.sqrt(1.0 + extra / lr.linear_end("end_b").std ** 2) if recs else 1.0


def _faults() -> int:
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt


def measure(repeat: int) -> dict[str, dict[str, tuple[float, float, int, float]]]:
    """Fastest wall time [s], fairlead σ ratio, minor page faults in the fastest round
    and their median over the rounds of every line and variant."""
    docs = {name: {v: with_variant(d, v) for v in VARIANTS} for name, d in lines().items()}
    best: dict[str, dict[str, list]] = {n: {v: [math.inf, 1.0, 0] for v in VARIANTS} for n in docs}
    faults: dict[tuple[str, str], list[int]] = {(n, v): [] for n in docs for v in VARIANTS}
    for r in range(repeat + 1):  # round 0: warm-up (imports, numba caches)
        for name, by_v in docs.items():
            for v, doc in by_v.items():
                f0, t0 = _faults(), time.perf_counter()
                res = analyze(doc)
                dt, df = time.perf_counter() - t0, _faults() - f0
                if r > 0:
                    faults[name, v].append(df)
                    if dt < best[name][v][0]:
                        best[name][v][0], best[name][v][2] = dt, df
                best[name][v][1] = _fairlead_ratio(res, v)
    return {
        n: {v: (*x, float(np.median(faults[n, v]))) for v, x in by.items()}
        for n, by in best.items()
    }


def report(best: dict) -> str:
    rows = [
        "| line | linear [ms] | drag [ms] (×) | geometric [ms] (×) | both [ms] (×) "
        "| σ ratio drag | σ ratio geometric | σ ratio both |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for name, by in best.items():
        t0 = by["linear"][0]
        cells = [f"{by['linear'][0] * 1e3:.1f}"]
        for v in ("drag", "geometric", "both"):
            cells.append(f"{by[v][0] * 1e3:.1f} ({by[v][0] / t0:.2f}×)")
        ratios = [f"{by[v][1]:.4f}" for v in ("drag", "geometric", "both")]
        rows.append(f"| {name} | " + " | ".join(cells + ratios) + " |")
    rows += [
        "",
        "| line | minor page faults, linear: fastest round (median) | both |",
        "|---|---|---|",
    ]
    for name, by in best.items():
        cells = [f"{by[v][2]} ({by[v][3]:.0f})" for v in ("linear", "both")]
        rows.append(f"| {name} | " + " | ".join(cells) + " |")
    return "\n".join(rows)


def profile(name: str, variant: str = "both") -> str:
    doc = with_variant(lines()[name], variant)
    analyze(doc)
    prof = cProfile.Profile()
    prof.enable()
    analyze(doc)
    prof.disable()
    out = []

    class _W:
        def write(self, s):
            out.append(s)

    pstats.Stats(prof, stream=_W()).sort_stats(os.environ.get("SORT", "cumulative")).print_stats(45)
    return "".join(out)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--profile", default=None, help="cProfile one line's 'both' analysis")
    ap.add_argument("--only", default=None, help="comma-separated lines")
    ap.add_argument("--record", default=None, help="write the residual variances (JSON)")
    args = ap.parse_args()
    if args.record:
        Path(args.record).write_text(json.dumps(residual_variances(), indent=1) + "\n")
        return
    if args.profile:
        print(profile(args.profile))
        return
    best = measure(args.repeat)
    if args.only:
        best = {k: v for k, v in best.items() if k in args.only.split(",")}
    print(report(best))


if __name__ == "__main__":
    main()
