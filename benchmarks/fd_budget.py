"""Error budget of the frequency-domain (FD) end tension σ against the nonlinear time
domain (TD), one term at a time, on the bundled chain's line (the example's fairlead surge
table, non-zero on 0.35–1.45 rad/s, on the band 0.05–2 rad/s; sea and current off).

Every TD run is driven by a periodic DSA fairlead surge of period P (lines 2πj/P in the
band, uniform phases per seed) over two periods, measured over the second: the input
variance is the DSA sum exactly, and a linear TD reproduces the FD σ on the same lines
without sampling error.  The TD variants switch one term at a time from the FD's linear
model toward the full nonlinear model (``simulate_line_timedomain(drag=..., seabed=...)``):

    lin        linear drag (the FD's converged B_n, B_t), bilateral linear bed, motion ×1e-3
    lin_full   the same at full motion: + geometric nonlinearity
    quad_st    quadratic drag about the static tangent, linear bed, full motion
    quad       quadratic drag with the instantaneous tangent, linear bed
    full       + the one-sided bed (the reference TD)

Shifts are paired differences between consecutive variants over the same seeds (95 % CI,
Student t); every σ is split into the variance on the input lines (in band) and the
rest (harmonics, out of band).

Run:  OPENBLAS_NUM_THREADS=1 nice -n 19 python3 benchmarks/fd_budget.py [--write]
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np
from scipy import stats

from stochcable import analyze, load_example, load_scene
from stochcable.reference.cable import simulate_line_timedomain

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "benchmarks" / "fd_budget.md"
PERIOD = 200.0  # [s] period of the periodic DSA motion
DT = 0.05  # [s] TD step (the reference's converged step; 0.125 s reads +0.8 %)
BAND = (0.05, 2.0)  # [rad/s]
SMALL = 1e-3  # motion scale of the "linear" TD variant


def chain_doc(elements: int, base: dict | None = None, **analysis) -> dict:
    """The bundled chain's line alone (or the one line of ``base``, a scene document
    with an end_b surge spectrum): fairlead surge only (sea and current off)."""
    if base is None:
        doc = load_example("chain_catenary").model_dump(mode="json")
    else:
        doc = json.loads(json.dumps(base))
    doc["sea"] = None
    doc["environment"]["current"] = []
    doc.setdefault("analysis", {}).pop("timeseries", None)
    doc["analysis"].update(analysis)
    doc["lines"][0]["segments"][0]["elements"] = elements
    return doc


def td_lines(period: float = PERIOD) -> tuple[np.ndarray, dict]:
    """The input lines 2πj/P in the band and the FD grid on them."""
    dw = 2.0 * math.pi / period
    k0, k1 = math.ceil(BAND[0] / dw), math.floor(BAND[1] / dw)
    return dw * np.arange(k0, k1 + 1), {"min": k0 * dw, "max": k1 * dw, "count": k1 - k0 + 1}


def fd(elements: int, scale: float = 1.0, base: dict | None = None, **analysis) -> dict:
    """FD end σ (fairlead, anchor) on the TD's lines and its converged drag; ``scale``
    multiplies the motion amplitude (a table spectrum); ``base`` as :func:`chain_doc`."""
    _, omega = td_lines()
    doc = chain_doc(
        elements,
        base,
        solver="direct",
        omega=omega,
        linearization={"tolerance": 1e-8, "max_iterations": 200},
        **analysis,
    )
    surge = doc["lines"][0]["end_b"]["motion"]["surge"]
    surge["density"] = [scale**2 * v for v in surge["density"]]
    line = analyze(doc).lines[doc["lines"][0]["name"]]
    rec = line.linearization
    return {
        "std": line_sum_std(line),
        "b": (np.asarray(rec.b_normal), np.asarray(rec.b_axial)),
    }


def line_sum_std(line) -> np.ndarray:
    """End σ (fairlead, anchor) [N] of an FD line result on the TD's lines as the DSA
    sums them, Σ_j S(ω_j)Δω: every line with its full weight (the FD's own σ, a
    trapezoid, halves the first and the last line; that matters when the spectrum is
    not zero at the band's ends)."""
    dw = float(line.omega[1] - line.omega[0])
    return np.array(
        [
            math.sqrt(
                float(np.sum(np.abs(line.end_tension_transfer[e]) ** 2 * line.input_spectra)) * dw
            )
            for e in ("end_b", "end_a")
        ]
    )


def periodic_surge(scene, seed: int, n_t: int, period: float = PERIOD) -> np.ndarray:
    """End-motion coefficients (3, n_t/2 + 1) on the 2-period grid: DSA amplitudes
    √(2SΔω) on the lines 2πj/P (the even lines of the grid), uniform phases."""
    lines, _ = td_lines(period)
    dw = 2.0 * math.pi / period
    s = scene.lines[0].end_b.motion.surge.spectral_density(lines, scene.environment.g)
    phase = np.random.default_rng(seed).uniform(-np.pi, np.pi, lines.size)
    c = np.zeros((3, n_t // 2 + 1), dtype=complex)
    j = np.rint(lines / dw).astype(int)
    c[0, 2 * j] = 0.5 * n_t * np.sqrt(2.0 * s * dw) * np.exp(-1j * phase)
    return c


def split_variance(x: np.ndarray, period: float = PERIOD) -> tuple[float, float]:
    """(in-band, out-of-band) variance of one whole period of x: the input lines 2πj/P
    in BAND, and every other line."""
    n = x.size
    p = 2.0 * np.abs(np.fft.rfft(x - x.mean())) ** 2 / n**2
    if n % 2 == 0:
        p[-1] /= 2.0
    w = 2.0 * math.pi / period * np.arange(p.size)
    inb = (w >= BAND[0] - 1e-9) & (w <= BAND[1] + 1e-9)
    return float(p[inb].sum()), float(p[~inb].sum())


def td(
    elements: int, seed: int, scale: float = 1.0, base: dict | None = None, **variant
) -> np.ndarray:
    """TD end σ split: [[fairlead in, out], [anchor in, out]] variances / scale²."""
    scene = load_scene(chain_doc(elements, base))
    n_t = int(round(2 * PERIOD / DT))
    c = periodic_surge(scene, seed, n_t) * scale
    h = simulate_line_timedomain(
        scene, duration=2 * PERIOD, end_realizations={"b": c}, band=BAND, dt=DT, **variant
    )
    keep = (h.t >= PERIOD - 1e-9) & (h.t < 2 * PERIOD - 1e-9)
    return np.array([split_variance(h.tension_b[keep]), split_variance(h.tension_a[keep])]) / (
        scale**2
    )


VARIANTS = (
    ("lin", "linear drag (FD's B), linear bed, motion ×1e-3", {"seabed": "linear"}),
    ("lin_amp", "+ geometric nonlinearity (full motion)", {"seabed": "linear"}),
    ("quad_st", "+ quadratic drag, static tangent", {"drag": "static_tangent", "seabed": "linear"}),
    ("quad", "+ instantaneous tangent", {"seabed": "linear"}),
    ("full", "+ one-sided seabed (the reference TD)", {}),
)
ENDS = ("fairlead", "anchor")


def variant_options(name: str, fd_result: dict) -> tuple[dict, float]:
    """The ``simulate_line_timedomain`` options of a variant and its motion scale
    relative to the FD's (``fd_result`` from :func:`fd`: its drag for the linear ones)."""
    kw = dict(next(v[2] for v in VARIANTS if v[0] == name))
    if name in ("lin", "lin_amp"):
        kw.update(drag="linear", linear_drag=fd_result["b"])
    return kw, (SMALL if name == "lin" else 1.0)


def run(
    elements: int,
    seeds: tuple[int, ...],
    scales: tuple[float, ...],
    base: dict | None = None,
) -> dict:
    """FD and the TD variants for every seed and motion scale: variances (variant,
    seed, end, [in, out]) / scale²."""
    out = {}
    for scale in scales:
        f = fd(elements, scale, base)
        var = np.empty((len(VARIANTS), len(seeds), 2, 2))
        for i, (name, _, _) in enumerate(VARIANTS):
            kw, rel = variant_options(name, f)
            s = rel * scale
            for j, seed in enumerate(seeds):
                t0 = time.time()
                var[i, j] = td(elements, seed, s, base, **kw) * scale**2
                print(f"scale {scale:g} {name} seed {seed}: {time.time() - t0:.1f} s", flush=True)
        out[scale] = {"fd": f["std"], "var": var}
    return out


def ci(x: np.ndarray) -> tuple[float, float]:
    """Mean and 95 % half-width (Student t) over the first axis."""
    n = x.shape[0]
    half = stats.t.ppf(0.975, n - 1) * x.std(axis=0, ddof=1) / math.sqrt(n) if n > 1 else 0.0
    return x.mean(axis=0), half


def table(res: dict, elements: int, seeds: tuple[int, ...]) -> str:
    rows = []
    for scale, r in res.items():
        fdv = r["fd"]
        var = r["var"]  # (variant, seed, end, [in, out])
        sig = np.sqrt(var.sum(-1))  # (variant, seed, end)
        rows.append(f"\n## Motion ×{scale:g} (FD σ {fdv[0] / 1e3:.2f} / {fdv[1] / 1e3:.2f} kN)\n")
        rows.append(
            "| step | fairlead σ/FD − 1 [%] | shift [%] | in-band σ/FD − 1 [%] "
            "| off-band var. [%] | anchor σ/FD − 1 [%] | shift [%] | in-band σ/FD − 1 [%] "
            "| off-band var. [%] |"
        )
        rows.append("|---|---|---|---|---|---|---|---|---|")
        for i, (name, label, _) in enumerate(VARIANTS):
            cells = [f"`{name}`: {label}"]
            for e in range(2):
                m, h = ci(sig[i, :, e] / fdv[e] - 1.0)
                if i:
                    dm, dh = ci((sig[i, :, e] - sig[i - 1, :, e]) / fdv[e])
                    shift = f"{100 * dm:+.2f} ± {100 * dh:.2f}"
                else:
                    shift = "—"
                im, ih = ci(np.sqrt(var[i, :, e, 0]) / fdv[e] - 1.0)
                om, oh = ci(var[i, :, e, 1] / var[i, :, e].sum(-1))
                cells += [
                    f"{100 * m:+.2f} ± {100 * h:.2f}",
                    shift,
                    f"{100 * im:+.2f} ± {100 * ih:.2f}",
                    f"{100 * om:.2f} ± {100 * oh:.2f}",
                ]
            rows.append("| " + " | ".join(cells) + " |")
    head = f"""# FD error budget: the chain's line, one term at a time

Generated by `OPENBLAS_NUM_THREADS=1 nice -n 19 python3 benchmarks/fd_budget.py --write`
({elements} elements in both domains, TD Δt = {DT} s, periodic DSA fairlead surge of
period {PERIOD:g} s over two periods, the second measured, seeds {list(seeds)}; FD on the
same lines, direct solver, Borgman drag converged to 1e-8; about 9 min niced on one
core, `--save f.npz` keeps the raw variances and `--load f.npz --write` re-renders).
σ / FD − 1 and the paired shift of each step from the previous row: mean over seeds
± 95 % CI (Student t).
"off-band var.": the fraction of the TD tension variance off the input lines (below
{BAND[0]} or above {BAND[1]} rad/s: harmonics, zero in a linear model).
"""
    return head + "\n".join(rows) + "\n"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--write", action="store_true", help=f"write {DOC.relative_to(ROOT)}")
    ap.add_argument("--elements", type=int, default=160)
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--save", help="also save the raw variances to this .npz")
    ap.add_argument("--load", help="render the table from a --save file (no runs)")
    args = ap.parse_args(argv)
    seeds = tuple(range(1, args.seeds + 1))
    if args.load:
        raw = np.load(args.load)
        res = {k: {"fd": raw[f"{k:g}_fd"], "var": raw[f"{k:g}_var"]} for k in (1.0, 0.1)}
        seeds = tuple(range(1, res[1.0]["var"].shape[1] + 1))
    else:
        res = run(args.elements, seeds, (1.0, 0.1))
    if args.save:
        np.savez(args.save, **{f"{k:g}_{n}": v[n] for k, v in res.items() for n in ("fd", "var")})
    text = table(res, args.elements, seeds)
    print(text)
    if args.write:
        DOC.write_text(text + NOTES)
    return 0


NOTES = """
## Reading

- **No linear model mismatch.**  Made as linear as the FD (row `lin`: the FD's
  converged drag coefficients, the bed frozen at its static tangent, 1e-3 of the
  motion) the TD reproduces the FD σ to 0.05–0.09 % (the Newmark period error and the
  TD's nodal bed against the FD's split touchdown element).  Added mass, axial drag,
  mass matrix, end nodes and the way the FD applies the fairlead motion are therefore
  not the shortfall.  Only at 160 elements: at 40 and 80 elements the TD's nodal bed is
  itself unconverged (linear TD / FD − 1 = −1.8 / −2.8 % at 40, +1.6 / +2.4 % at 80
  elements, seed 1, period 200 s), so TD comparisons on coarse meshes carry ±2 % of bed
  discretization, not physics.
- **Quadratic drag is the largest term** (+4.0 / +6.4 % at the fairlead / anchor at full
  motion; about +2.5 / +3.2 % in band, the rest superharmonics).  It does not vanish at a
  tenth of the motion (+1.8 / +2.5 %, nearly all in band): the drag is the line's only
  damping and the Borgman coefficient scales with the velocity σ, so the relative error
  of the Gaussian linearization is (nearly) amplitude-free.  This is the in-band gap that
  "persists at a tenth of the motion".
- **Geometric nonlinearity** adds +0.9 / +1.5 % at full motion and +3.0 / +5.8 % at a
  tenth, in both cases off the input band (in band −0.2 to +0.4 %, within the CI):
  second-order tension whose response is limited by the same drag damping, so its share
  does not shrink with the motion either.
- **The instantaneous tangent** (drag split about the moving element instead of the
  static one) changes nothing measurable (≤ 0.01 %).
- **The one-sided bed** (lift-off and landing against the FD's bilateral bed) adds
  +0.3 / +0.45 % at full motion.

Probes (one-off runs, 160 elements, seeds 1–3, not regenerated by this script):

- Scaling the linear drag by 0.85 moves the in-band σ at full motion by less than the
  seed scatter (fairlead −0.7 / −0.2 / +0.1 %, anchor −1.7 / −1.0 / −0.7 % against the
  FD): the end tensions at full motion hardly depend on the damping, so the in-band
  excess of the quadratic drag there (+2.5 / +3.2 %) is not a wrong damping coefficient
  but the drag residual c|v|v − Bv itself (its third-Hermite part, 4/(3π) of σ⁴c², 93 %
  of the residual variance for Gaussian v, spreads over 0–3ω and falls partly in band).
  At a tenth of the motion the same scaling raises the in-band σ by +2.9–3.2 % /
  +3.9–4.4 %, about twice the quadratic drag's +1.6 / +2.1 %: there the response is
  damping-controlled and the Borgman coefficient is ~8 % too high.
- The normal relative velocity of the quadratic-drag TD (seed 1, full motion) is not
  Gaussian: kurtosis 2.3–2.8 over the upper half of the line (so E|v|³ is 3–12 % below
  the Gaussian value there), 3.2–3.6 near the touchdown.

What the FD can still gain: an equivalent linearization of the drag that accounts for
the non-Gaussian relative velocity (in band, ~2.5 / 3 %), and a closed-form
superharmonic term (the variance of the drag residual and of the second-order stretching
through the linear transfer functions; ~2 / 4 % of σ off band).  Neither is implemented.
"""

if __name__ == "__main__":
    sys.exit(main())
