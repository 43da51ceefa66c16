"""The drag residual against the nonlinear time domain, on the chain line of
benchmarks/fd_budget.py (the example's fairlead surge table, sea and current off).

For each motion scale: the FD end-tension σ, the closed-form variance the Borgman
linearization drops (``analysis.linearization.drag_residual``,
:mod:`stochcable.dynamics.drag_residual`), and three TD variants over the same seeds
(fd_budget's periodic DSA surge, whole periods): ``lin_amp`` (the FD's linear drag,
linear bed, full motion), ``quad_st`` (quadratic drag about the static tangent) and
``full`` (the reference TD).  The paired shift quad_st − lin_amp is the quadratic
drag's own effect, which the closed form predicts; full against FD + residual is what
is left (geometric nonlinearity, the one-sided bed).

Run: OPENBLAS_NUM_THREADS=1 nice python3 benchmarks/drag_residual.py [--write]
     [--elements 160] [--seeds 5]
"""

from __future__ import annotations

import argparse
import platform
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from fd_budget import DT, PERIOD, chain_doc, ci, td, td_lines  # noqa: E402

from stochcable import analyze, load_scene  # noqa: E402
from stochcable.reference.cable import simulate_line_timedomain  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "benchmarks" / "drag_residual.md"
ENDS = (("end_b", "fairlead"), ("end_a", "anchor"))


def fd(elements: int, scale: float) -> tuple[dict, object]:
    """FD σ per end and the line's drag residual record (direct solve on the TD's
    lines, drag converged to 1e-8), and the converged drag (B_n, B_t)."""
    _, omega = td_lines()
    doc = chain_doc(
        elements,
        solver="direct",
        omega=omega,
        linearization={"tolerance": 1e-8, "max_iterations": 200, "drag_residual": True},
    )
    surge = doc["lines"][0]["end_b"]["motion"]["surge"]
    surge["density"] = [scale**2 * v for v in surge["density"]]
    t0 = time.perf_counter()
    line = analyze(doc).lines["leg1"]
    wall = time.perf_counter() - t0
    rec = line.linearization
    return {
        "std": {e: getattr(line, e).std for e, _ in ENDS},
        "residual": line.drag_residual,
        "b": (np.asarray(rec.b_normal), np.asarray(rec.b_axial)),
        "wall": wall,
    }


def run(elements: int, seeds: tuple[int, ...], scales: tuple[float, ...]) -> dict:
    out = {}
    for scale in scales:
        f = fd(elements, scale)
        sig = {}
        for name, kw in (
            ("lin_amp", {"seabed": "linear", "drag": "linear", "linear_drag": f["b"]}),
            ("quad_st", {"seabed": "linear", "drag": "static_tangent"}),
            ("full", {}),
        ):
            rows = []
            for seed in seeds:
                t0 = time.time()
                v = td(elements, seed, scale, **kw) * scale**2  # [[in, out] fairlead, anchor]
                rows.append(np.sqrt(v.sum(-1)))
                print(f"scale {scale:g} {name} seed {seed}: {time.time() - t0:.1f} s", flush=True)
            sig[name] = np.array(rows)  # (seed, [fairlead, anchor])
        out[scale] = {"fd": f, "td": sig}
    return out


SEA_CASES = ("taut_wire", "inclined_guy")
SEA_RECORD = 1200.0  # [s] TD record of the sea-driven lines, the first SEA_SKIP dropped
SEA_SKIP = 200.0


def sea_driven(name: str, seeds: tuple[int, ...]) -> dict:
    """A bundled example driven by its sea: FD σ (the example's settings, drag to 1e-8)
    with its residual, and the reference TD (quadratic drag, the example's mesh, its
    analysis band) over ``seeds``."""
    from stochcable import load_example

    doc = load_example(name).model_dump(mode="json")
    doc["analysis"].pop("timeseries", None)
    doc["analysis"]["linearization"].update(tolerance=1e-8, drag_residual=True)
    scene = load_scene(doc)
    line = analyze(scene).lines[scene.lines[0].name]
    band = (float(line.omega[0]), float(line.omega[-1]))
    rows = []
    for seed in seeds:
        t0 = time.time()
        h = simulate_line_timedomain(scene, duration=SEA_RECORD, seed=seed, band=band)
        keep = h.t >= SEA_SKIP
        rows.append([h.tension_b[keep].std(), h.tension_a[keep].std()])
        print(f"{name} seed {seed}: {time.time() - t0:.1f} s", flush=True)
    return {"fd": {e: getattr(line, e).std for e, _ in ENDS}, "residual": line.drag_residual,
            "td": np.array(rows)}  # fmt: skip


def sea_table(res: dict, seeds: tuple[int, ...]) -> str:
    rows = [
        "\n## Sea-driven lines\n",
        f"The `taut_wire` and `inclined_guy` examples in their seas: the reference TD on the "
        f"example's own mesh (so only the linearization differs), its analysis band, records "
        f"of {SEA_RECORD:g} s without the first {SEA_SKIP:g} s, seeds {list(seeds)}.  The "
        "ratios' ± propagate the TD's 95 % half-width.\n",
        "| line | end | FD σ | residual: σ/σ_FD − 1 | TD σ (95 % CI) | FD / TD | "
        "(FD + residual) / TD |",
        "|---|---|---|---|---|---|---|",
    ]
    for name, r in res.items():
        dr = r["residual"]
        for k, (end, label) in enumerate(ENDS):
            m, h = ci(r["td"][:, k])
            fd_, cor = r["fd"][end], dr.std[end]
            rows.append(
                f"| {name} | {label} | {fd_:.4g} | {100 * (dr.ratio(end) - 1):+.1f} % "
                f"| {m:.4g} ± {h:.2g} | {fd_ / m:.3f} ± {fd_ * h / m**2:.3f} "
                f"| {cor / m:.3f} ± {cor * h / m**2:.3f} |"
            )
    return "\n".join(rows) + "\n"


def table(res: dict, elements: int, seeds: tuple[int, ...], wall: float) -> str:
    head = f"""# The drag residual against the time domain

Generated by `OPENBLAS_NUM_THREADS=1 nice python3 benchmarks/drag_residual.py --write`
on {platform.machine()}, Python {platform.python_version()} (whole run {wall:.0f} s).
The chain line of [fd_budget.md](fd_budget.md): {elements} elements in both domains,
the example's fairlead surge (its spectrum table, non-zero on 0.35–1.45 rad/s), sea
and current off; TD
Δt = {DT} s, periodic DSA surge of period {PERIOD:g} s over two periods, the second
measured, seeds {list(seeds)}; FD on the same lines, direct solver, Borgman drag
converged to 1e-8, with `analysis.linearization.drag_residual` on.  ± is the 95 %
half-width over the seeds (Student t), shifts are paired (same phases).

- *residual*: the closed-form variance the linearization drops, as σ/σ_FD − 1, and the
  share of that variance on the analysis band (the rest: superharmonics and
  difference frequencies below it);
- *quadratic drag (TD)*: the paired shift from the TD with the FD's linear drag to the
  TD with quadratic drag (both with the linear bed, full motion) — the effect the
  closed form predicts;
- *TD / (FD + residual) − 1*: the reference TD against the corrected FD: what is left
  (geometric nonlinearity and the one-sided bed, fd_budget.md).

Where it is not yet shown to hold: at a tenth of the motion it predicts less than the
TD's quadratic-drag shift (below; that shift is mostly in band, and why the first-order
closed form misses it is open).
"""
    rows = [head]
    for scale, r in res.items():
        f, sig = r["fd"], r["td"]
        rows.append(f"\n## Motion ×{scale:g}\n")
        rows.append(
            "| end | FD σ [kN] | residual: σ/σ_FD − 1 | its in-band share | quadratic drag "
            "(TD) | TD / FD − 1 | TD / (FD + residual) − 1 |"
        )
        rows.append("|---|---|---|---|---|---|---|")
        dr = f["residual"]
        for k, (end, label) in enumerate(ENDS):
            s_fd = f["std"][end]
            shift_m, shift_h = ci((sig["quad_st"][:, k] - sig["lin_amp"][:, k]) / s_fd)
            td_m, td_h = ci(sig["full"][:, k] / s_fd - 1.0)
            cor_m, cor_h = ci(sig["full"][:, k] / dr.std[end] - 1.0)
            share = dr.in_band[end] / dr.variance[end] if dr.variance[end] > 0 else 0.0
            rows.append(
                f"| {label} | {s_fd / 1e3:.2f} | {100 * (dr.ratio(end) - 1):+.2f} % "
                f"| {100 * share:.0f} % | {100 * shift_m:+.2f} ± {100 * shift_h:.2f} % "
                f"| {100 * td_m:+.2f} ± {100 * td_h:.2f} % "
                f"| {100 * cor_m:+.2f} ± {100 * cor_h:.2f} % |"
            )
        rows.append(
            f"\nFD analysis with the residual: {1e3 * f['wall']:.0f} ms "
            f"({dr.panels} panels, Hermite order {dr.order})."
        )
    return "\n".join(rows) + "\n"


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
