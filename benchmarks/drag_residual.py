"""The closed-form residuals of the linear model against the nonlinear time domain: the
drag the linearization drops (``analysis.linearization.drag_residual``) and the
second-order geometric forces (``analysis.linearization.geometric_residual``).

The chain line of benchmarks/fd_budget.py (the example's fairlead surge table, sea and
current off), at the example's motion and a tenth of it: the FD end-tension σ with both
residuals, and four TD variants over the same seeds (fd_budget's periodic DSA surge,
whole periods): ``lin`` (the FD's linear drag, linear bed, 1e-3 of the motion: the
linear model), ``lin_amp`` (the same at the motion: + geometric nonlinearity),
``quad_st`` (+ quadratic drag about the static tangent) and ``full`` (the reference TD).
The paired shifts lin_amp − lin and quad_st − lin_amp are what the geometric and the
drag residual predict; full against FD + both residuals is what is left (the one-sided
bed).  Then the sea-driven ``taut_wire`` and ``inclined_guy`` examples against the
reference TD on their own meshes, and the paired quadratic-drag shift there (the TD
against the TD with the FD's linear drag, same seeds).

Run: OPENBLAS_NUM_THREADS=1 nice python3 benchmarks/drag_residual.py [--write]
     [--elements 160] [--seeds 5]
"""

from __future__ import annotations

import argparse
import math
import platform
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from fd_budget import DT, PERIOD, SMALL, chain_doc, ci, td, td_lines  # noqa: E402

from stochcable import analyze, load_example, load_scene  # noqa: E402
from stochcable.reference.cable import simulate_line_timedomain  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "benchmarks" / "drag_residual.md"
ENDS = (("end_b", "fairlead"), ("end_a", "anchor"))
RESIDUALS = {"drag_residual": True, "geometric_residual": True}
SEA_CASES = ("taut_wire", "inclined_guy")
SEA_RECORD = 1200.0  # [s] TD record of the sea-driven lines, the first SEA_SKIP dropped
SEA_SKIP = 200.0


def corrected(line, end: str) -> float:
    """σ with both residuals: their variances add (zero-mean flow: uncorrelated). [N]"""
    extra = sum(getattr(line, k).variance[end] for k in RESIDUALS)
    return math.sqrt(line.linear_end(end).std ** 2 + extra)


def fd(elements: int, scale: float) -> dict:
    """The FD line with both residuals (direct solve on the TD's lines, drag to 1e-8)."""
    _, omega = td_lines()
    doc = chain_doc(
        elements,
        solver="direct",
        omega=omega,
        linearization={"tolerance": 1e-8, "max_iterations": 200, **RESIDUALS},
    )
    surge = doc["lines"][0]["end_b"]["motion"]["surge"]
    surge["density"] = [scale**2 * v for v in surge["density"]]
    t0 = time.perf_counter()
    line = analyze(doc).lines["leg1"]
    return {"line": line, "wall": time.perf_counter() - t0}


def run(elements: int, seeds: tuple[int, ...], scales: tuple[float, ...]) -> dict:
    out = {}
    for scale in scales:
        f = fd(elements, scale)
        rec = f["line"].linearization
        lin = {"seabed": "linear", "drag": "linear",
               "linear_drag": (np.asarray(rec.b_normal), np.asarray(rec.b_axial))}  # fmt: skip
        sig = {}
        for name, s, kw in (
            ("lin", SMALL, lin),
            ("lin_amp", scale, lin),
            ("quad_st", scale, {"seabed": "linear", "drag": "static_tangent"}),
            ("full", scale, {}),
        ):
            rows = []
            for seed in seeds:
                t0 = time.time()
                v = td(elements, seed, s, **kw) * scale**2  # variance at the scale's motion
                rows.append(np.sqrt(v.sum(-1)))
                print(f"scale {scale:g} {name} seed {seed}: {time.time() - t0:.1f} s", flush=True)
            sig[name] = np.array(rows)  # (seed, [fairlead, anchor])
        out[scale] = {"fd": f, "td": sig}
    return out


def sea_driven(name: str, seeds: tuple[int, ...]) -> dict:
    """A bundled example driven by its sea: FD with both residuals (the example's
    settings, drag to 1e-8), and the reference TD (quadratic drag, the example's mesh,
    its analysis band) over ``seeds``."""
    doc = load_example(name).model_dump(mode="json")
    doc["analysis"].pop("timeseries", None)
    doc["analysis"]["linearization"].update(tolerance=1e-8, **RESIDUALS)
    scene = load_scene(doc)
    line = analyze(scene).lines[scene.lines[0].name]
    band = (float(line.omega[0]), float(line.omega[-1]))
    rec = line.linearization
    lin = {"drag": "linear", "linear_drag": (np.asarray(rec.b_normal), np.asarray(rec.b_axial))}
    rows, rows_lin = [], []
    for seed in seeds:
        t0 = time.time()
        for out, kw in ((rows, {}), (rows_lin, lin)):
            h = simulate_line_timedomain(scene, duration=SEA_RECORD, seed=seed, band=band, **kw)
            keep = h.t >= SEA_SKIP
            out.append([h.tension_b[keep].std(), h.tension_a[keep].std()])
        print(f"{name} seed {seed}: {time.time() - t0:.1f} s", flush=True)
    return {"line": line, "td": np.array(rows), "td_lin": np.array(rows_lin)}


def _pct(m: float, h: float | None = None) -> str:
    return f"{100 * m:+.2f} %" if h is None else f"{100 * m:+.2f} ± {100 * h:.2f} %"


def table(res: dict, elements: int, seeds: tuple[int, ...], wall: float) -> str:
    head = f"""# Closed-form residuals of the linear model against the time domain

Generated by `OPENBLAS_NUM_THREADS=1 nice python3 benchmarks/drag_residual.py --write`
on {platform.machine()}, Python {platform.python_version()} (whole run {wall:.0f} s).
The chain line of [fd_budget.md](fd_budget.md): {elements} elements in both domains,
the example's fairlead surge (its spectrum table, non-zero on 0.35–1.45 rad/s), sea
and current off; TD Δt = {DT} s, periodic DSA surge of period {PERIOD:g} s over two
periods, the second measured, seeds {list(seeds)}; FD on the same lines, direct solver,
Borgman drag converged to 1e-8, with `analysis.linearization.drag_residual` and
`.geometric_residual` on.  ± is the 95 % half-width over the seeds (Student t); shifts
are paired (same phases), relative to the FD σ.

- *drag residual* / *geometric residual*: the closed-form variance each adds, as
  σ/σ_FD − 1;
- *TD shifts*: quadratic drag = `quad_st` − `lin_amp` (the TD with quadratic drag
  against the TD with the FD's linear drag), geometric = `lin_amp` − `lin` (the TD at
  the motion against the TD at 1e-3 of it, both with the FD's linear drag and a linear
  bed) — the effects the residuals predict;
- *TD / (FD + residuals) − 1*: the reference TD against the FD with both residuals
  (their variances add): what is left is the one-sided bed (+0.3 / +0.45 %,
  fd_budget.md).

Where they are first-order terms and show it: at a tenth of the motion the drag
residual predicts less than the TD's quadratic-drag shift and the geometric residual
more than the TD's geometric shift (their sum still lands within the CI).  The
corrections checked here go up to +18 % (the sea-driven lines below); a PhysicsWarning
says so beyond ×1.25.
"""
    rows = [head]
    for scale, r in res.items():
        line, sig = r["fd"]["line"], r["td"]
        rows += [
            f"\n## Motion ×{scale:g}\n",
            "| end | FD σ [kN] | drag residual | TD shift: quadratic drag | geometric "
            "residual | TD shift: geometric | TD / FD − 1 | TD / (FD + residuals) − 1 |",
            "|---|---|---|---|---|---|---|---|",
        ]
        for k, (end, label) in enumerate(ENDS):
            s_fd = line.linear_end(end).std
            quad = ci((sig["quad_st"][:, k] - sig["lin_amp"][:, k]) / s_fd)
            geo = ci((sig["lin_amp"][:, k] - sig["lin"][:, k]) / s_fd)
            rows.append(
                f"| {label} | {s_fd / 1e3:.2f} | {_pct(line.drag_residual.ratio(end) - 1)} "
                f"| {_pct(*quad)} | {_pct(line.geometric_residual.ratio(end) - 1)} "
                f"| {_pct(*geo)} | {_pct(*ci(sig['full'][:, k] / s_fd - 1.0))} "
                f"| {_pct(*ci(sig['full'][:, k] / corrected(line, end) - 1.0))} |"
            )
        rows.append(f"\nFD analysis with both residuals: {1e3 * r['fd']['wall']:.0f} ms.")
    return "\n".join(rows) + "\n"


def sea_table(res: dict, seeds: tuple[int, ...]) -> str:
    rows = [
        "\n## Sea-driven lines\n",
        f"The `taut_wire` and `inclined_guy` examples in their seas: the reference TD on the "
        f"example's own mesh (so only the linear model differs), its analysis band, records "
        f"of {SEA_RECORD:g} s without the first {SEA_SKIP:g} s, seeds {list(seeds)}.  The "
        "ratios' ± propagate the TD's 95 % half-width; *TD shift: quadratic drag* is the "
        "paired TD − TD with the FD's linear drag (same seeds), relative to the FD σ, "
        "beside the drag residual it is the prediction of; *panels*: those the drag "
        "residual was evaluated on (the elements near the surface split).\n",
        "| line | end | FD σ [N] | drag residual | TD shift: quadratic drag | geometric "
        "residual | panels | TD σ (95 % CI) [N] | FD / TD | (FD + residuals) / TD |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for name, r in res.items():
        line = r["line"]
        for k, (end, label) in enumerate(ENDS):
            m, h = ci(r["td"][:, k])
            fd_, cor = line.linear_end(end).std, corrected(line, end)
            quad = ci((r["td"][:, k] - r["td_lin"][:, k]) / fd_)
            rows.append(
                f"| {name} | {label} | {fd_:.4g} | {_pct(line.drag_residual.ratio(end) - 1)} "
                f"| {_pct(*quad)} | {_pct(line.geometric_residual.ratio(end) - 1)} "
                f"| {line.drag_residual.panels} | {m:.4g} ± {h:.2g} "
                f"| {fd_ / m:.3f} ± {fd_ * h / m**2:.3f} | {cor / m:.3f} ± {cor * h / m**2:.3f} |"
            )
    return "\n".join(rows) + "\n" + SEA_NOTES


#: The diagnosis of the inclined guy's former overshoot (a one-off experiment: the
#: reference TD's linear drag plus a patched-in dropped drag, not rerun here).
SEA_NOTES = """
The inclined guy's drag residual used to read +38.5 % / +33.6 % (fairlead / anchor;
(FD + residuals) / TD 1.162 ± 0.043 / 1.149 ± 0.040) against a paired quadratic-drag
shift of +14 % / +12 % in the TD.  Not a limit of the first-order theory but its
discretization: the example's 26 m top element at z = 0 spans 14 m of depth, over
which the wave-velocity σ falls by a factor 2.2, and the residual took it as one
element-mean velocity spread evenly over the element's two nodes, where the pointwise
drag concentrates toward the fixed fairlead node.  The overshoot was all on the line's
0.7 %-damped mode at 1.19 rad/s, driven through the first free node (1.15–1.3 rad/s:
+51 000 N² predicted, ≈ 0 in the TD; the sum-frequency band 1.3–2.0 rad/s agreed,
47 500 against 44 500 N²).  A TD with the FD's linear drag plus the dropped drag of
the fluid velocity, c|w|w − B_e·w (a one-off experiment: the reference model's linear
drag with that load patched in, seeds 1–5), reproduces both: +16 ± 7 % taken pointwise
(as the TD's quadratic drag, +14 ± 4 %), +32 ± 9 % taken as element means spread
evenly (as the old closed form).  The linear model has the same defect (one B per
element): its misfit (B(ξ) − B_e)·v is linear, correlated with the linear response, and
lowers the fairlead σ² by 22 % here.  Now the elements whose wave-velocity variance
varies by more than ×1.5 along them are split into pieces (up to half the panel
budget, `stochcable.dynamics.residuals.drag_segments`), whole elements are grouped into panels
only where the variance is uniform enough, the misfit enters with its cross term, and
the guy's corrected σ lands within the TD's interval.  Splitting finer (×1.05, 186
panels) moves it by 0.2 %; on 160 elements (linear σ −7.5 %) the corrected σ is 3 %
higher, the TD ≈ 1 % (3 seeds).

When the correction is trustworthy: the residual is a first-order term about the
equivalent linear system; it is checked against the nonlinear TD up to +18 % in σ
(the taut wire, the guy) and at +4 / +7 % (the chain), where (FD + residuals) / TD is
within the TD's 95 % interval.  Beyond ×1.25 either way a PhysicsWarning says the
correction is larger than any checked: run the reference TD
(`stochcable.reference.cable.simulate_line_timedomain`) for the σ.  Lines on free
bodies, 3-D lines and the vector linearization are not covered (the record says why).
"""


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--write", action="store_true", help=f"write {DOC.relative_to(ROOT)}")
    ap.add_argument("--elements", type=int, default=160)
    ap.add_argument("--seeds", type=int, default=5)
    args = ap.parse_args()
    seeds = tuple(range(1, args.seeds + 1))
    t0 = time.time()
    res = run(args.elements, seeds, (1.0, 0.1))
    sea = {name: sea_driven(name, seeds) for name in SEA_CASES}
    text = table(res, args.elements, seeds, time.time() - t0) + sea_table(sea, seeds)
    print(text)
    if args.write:
        DOC.write_text(text)


if __name__ == "__main__":
    main()
