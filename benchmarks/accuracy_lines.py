"""Accuracy per line (issue 22 item 4): the frequency domain (FD) at a user's settings and
with adaptive fidelity against the time-domain reference and MoorDyn, with the error
budget of FD − TD.

    python benchmarks/accuracy_lines.py [--budget 170] [--only KIND]   # run what is missing
    python benchmarks/accuracy_lines.py --write                         # write the page
    python benchmarks/accuracy_lines.py --quick                         # smoke run, no page

The lines, the fairlead motion and the simulators' settings are those of
benchmarks/moordyn_check.py (chain = the bundled example's line, taut synthetic rope,
deep-water wire catenary; periodic DSA surge of PM Hs 2 m Tp 10 s on 0.05–2 rad/s,
period 200 s, seeds 1–5; 80 elements = 80 MoorDyn segments), and so is the run cache
(``--cache``, default the one of moordyn_check.py: the runs both pages need are run
once).  Every run — one simulation of one seed, one FD analysis, one step of the error
budget — is cached, so the set is run in slices of at most ``--budget`` seconds; two
processes may share the cache (``--only reference|moordyn|fd|budget`` splits the work).

The FD sees the same motion spectrum, band-limited to the same band: the surge is a
table of the PM density on 0.05–2 rad/s (zero outside), so that adaptive fidelity, which
chooses its own band, cannot widen it.  The error budget re-runs the variants of
benchmarks/fd_budget.py (linear TD → geometric nonlinearity → quadratic drag → one-sided
seabed) for this motion, at 160 elements.
"""

from __future__ import annotations

import argparse
import functools
import math
import os
import platform
import sys
import time
from importlib import metadata
from pathlib import Path

import numpy as np
import scipy

sys.path.insert(0, str(Path(__file__).resolve().parent))

import fd_budget  # noqa: E402 (sibling benchmark scripts)
import moordyn_check as mc  # noqa: E402

import stochcable  # noqa: E402
from stochcable import analyze  # noqa: E402
from stochcable.fidelity.model_error import CALIBRATION  # noqa: E402
from stochcable.reference.moordyn_compare import student_interval  # noqa: E402
from stochcable.sea.spectra import spectrum_pierson_moskowitz  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "accuracy" / "lines.md"
LINES = ("chain", "taut", "deep")
FINE = 160  # elements of the converged TD and of the budget
FD_VARIANTS = (
    "default", "adaptive", "residuals", "lines80", "lines160", "lines320", "fine320",
    "residuals320",
)  # fmt: skip
FINE_GRID = 2000  # frequencies of the converged continuous-spectrum FD on the band
TARGET = 0.01  # analysis.fidelity.target_error of the adaptive FD


def surge_table() -> dict:
    """The PM surge spectrum as a table on the band (zero outside). [m²·s/rad]"""
    w = np.linspace(mc.BAND[0], mc.BAND[1], 391)
    s = spectrum_pierson_moskowitz(w, mc.HS, mc.TP)
    return {"type": "table", "omega": w.tolist(), "density": s.tolist()}


def fd_document(line: str, variant: str = "default") -> dict:
    """The line's scene as a user runs it in the FD: the line alone with its fairlead
    surging (no sea, no current, no time series) at the settings of ``variant``
    ("residuals…": those of the rest of the name, "default" for none, with the
    closed-form residuals of the linear model asked for)."""
    residuals = variant.startswith("residuals")
    if residuals:
        rest = variant.removeprefix("residuals")
        variant = "lines" + rest if rest else "default"
    doc = mc.line_document(line)
    doc.pop("sea", None)
    doc["environment"]["current"] = []
    doc.setdefault("analysis", {}).pop("timeseries", None)
    doc["lines"][0]["end_b"]["motion"] = {"surge": surge_table()}
    if variant == "adaptive":
        doc["analysis"]["fidelity"] = {"target_error": TARGET}
    elif variant.startswith(("lines", "fine")):
        _, omega = fd_budget.td_lines(mc.PERIOD)
        if variant.startswith("fine"):
            omega = {"min": mc.BAND[0], "max": mc.BAND[1], "count": FINE_GRID}
        doc["analysis"].update(
            solver="direct",
            omega=omega,
            linearization={"tolerance": 1e-8, "max_iterations": 200},
        )
        n = variant.removeprefix("lines").removeprefix("fine")
        doc["lines"][0]["segments"][0]["elements"] = int(n)
    if residuals:
        doc["analysis"].setdefault("linearization", {}).update(
            drag_residual=True, geometric_residual=True
        )
    return doc


def run_fd(line: str, variant: str) -> dict:
    """One FD analysis: end σ, settings, warnings, the fidelity plan."""
    doc = fd_document(line, variant)
    t0 = time.perf_counter()
    res = analyze(doc)
    wall = time.perf_counter() - t0
    lr = res.lines[doc["lines"][0]["name"]]
    sc = res.scene
    an = sc.analysis
    k = list(lr.channels).index(next(c for c in lr.channels if "surge" in c))
    out = {
        "reaction_b": float(lr.linear_end("end_b").std),
        "reaction_a": float(lr.linear_end("end_a").std),
        "motion_std": float(math.sqrt(np.trapezoid(lr.input_spectra[k], lr.omega))),
        # on the TD's lines: σ as the DSA sums it (every line with its full weight)
        **dict(zip(("lines_b", "lines_a"), fd_budget.line_sum_std(lr).tolist())),
        "wall": wall,
        "elements": int(sc.lines[0].elements),
        "omega": [float(lr.omega[0]), float(lr.omega[-1]), int(lr.omega.size)],
        "solver": an.solver,
        "modes": lr.n_modes,
        "tolerance": an.linearization.tolerance,
        "warnings": list(res.warnings),
    }
    parts = [r for r in (lr.drag_residual, lr.geometric_residual) if r is not None]
    if parts and all(r.computed for r in parts):  # (uncorrelated: the variances add)
        for k, end in enumerate(("end_b", "end_a")):
            extra = sum(r.variance[end] for r in parts)
            out["residual_" + end[-1]] = math.sqrt(lr.linear_end(end).std ** 2 + extra)
            out["lines_residual_" + end[-1]] = math.sqrt(
                out[("lines_b", "lines_a")[k]] ** 2 + extra
            )
    if res.fidelity is not None:
        plan = res.fidelity.to_document()
        out["plan"] = {
            "error_estimate": plan["error_estimate"],
            "model_error_basis": plan["model_error_basis"],
            "limits": plan.get("limits", []),
            "tail_bounded": plan["tail_bounded"],
        }
    return out


@functools.cache
def _budget_fd(line: str) -> dict:
    return fd_budget.fd(FINE, 1.0, fd_document(line))


def run_budget(line: str, variant: str, seed: int) -> dict:
    """One TD variant of the error budget: [[fairlead in, out], [anchor in, out]]
    variances [N²] (fd_budget.td at full motion)."""
    f = _budget_fd(line)
    kw, scale = fd_budget.variant_options(variant, f)
    t0 = time.perf_counter()
    var = fd_budget.td(FINE, seed, scale, fd_document(line), **kw)
    return {"var": var.tolist(), "fd": f["std"].tolist(), "wall": time.perf_counter() - t0}


def runs() -> list[dict]:
    """Every run of the page."""
    out = []
    for line in LINES:
        for variant in FD_VARIANTS:
            out.append({"line": line, "sim": "fd", "variant": variant})
        for s in mc.SEEDS:
            out.append({"line": line, "sim": "reference", "seed": s, **mc.BASE})
            out.append({"line": line, "sim": "moordyn", "seed": s, **mc.BASE})
        for s in mc.SEEDS:
            out.append({"line": line, "sim": "reference", "seed": s, "elements": FINE})
    for line in LINES:
        for name, _, _ in fd_budget.VARIANTS:
            for s in mc.SEEDS:
                out.append({"line": line, "sim": "budget", "variant": name, "seed": s})
    return out


def execute(run: dict) -> dict:
    """One run of :func:`runs` (the simulations through moordyn_check.execute), with
    the host's load average after it."""
    if run["sim"] == "fd":
        out = run_fd(run["line"], run["variant"])
    elif run["sim"] == "budget":
        out = run_budget(run["line"], run["variant"], run["seed"])
    else:
        out = mc.execute(run)
    return {**out, "load": list(os.getloadavg())}


# ---------------------------------------------------------------- the page

ENDS = (("reaction_b", "fairlead"), ("reaction_a", "anchor"))


def _get(cache: dict, run: dict) -> dict:
    key = mc.run_key(run)
    if key not in cache:
        raise KeyError(f"missing run {key}: run the script without --write first")
    return cache[key]


def _seeds(cache: dict, line: str, sim: str, elements: int = 80) -> list[dict]:
    return [
        _get(cache, {"line": line, "sim": sim, "seed": s, "elements": elements}) for s in mc.SEEDS
    ]


def _fd(cache: dict, line: str, variant: str) -> dict:
    return _get(cache, {"line": line, "sim": "fd", "variant": variant})


def _kn(x: list[float]) -> str:
    m, h = student_interval(np.asarray(x, float))
    return f"{m / 1e3:.2f} ± {h / 1e3:.2f}"


def _pct(x: list[float] | float) -> str:
    x = np.atleast_1d(np.asarray(x, float)) * 100.0
    if x.size == 1:
        return f"{x[0]:+.2f} %"
    m, h = student_interval(x)
    return f"{m:+.2f} ± {h:.2f} %"


def _over(num: float | list[float], den: list[dict], q: str) -> list[float]:
    """Per seed num/σ_seed − 1 (num a number, or one value per seed: paired)."""
    nums = num if isinstance(num, list) else [num] * len(den)
    return [n / d[q] - 1.0 for n, d in zip(nums, den)]


def _budget(cache: dict, line: str) -> dict[str, np.ndarray]:
    """σ per budget variant: (seed, end) [N], and the FD σ (end) it is measured against."""
    out = {}
    fdv = None
    for name, _, _ in fd_budget.VARIANTS:
        recs = [
            _get(cache, {"line": line, "sim": "budget", "variant": name, "seed": s})
            for s in mc.SEEDS
        ]
        out[name] = np.array([np.sqrt(np.asarray(r["var"]).sum(-1)) for r in recs])
        fdv = np.asarray(recs[0]["fd"])
    out["fd"] = fdv
    return out


def _header(cache: dict) -> list[str]:
    mine = [cache[k] for k in {mc.run_key(r) for r in runs()} if k in cache]
    loads = np.array([r["load"][0] for r in mine if "load" in r] or [math.nan])
    wall = sum(r["wall"] for r in mine)
    return [
        "# Accuracy per line: frequency domain, time-domain reference and MoorDyn",
        "",
        "Generated by `python3 benchmarks/accuracy_lines.py` (repeat until it reports "
        "nothing left; each call runs at most `--budget` s; `--only reference|moordyn|fd|"
        "budget` lets two processes share the work) and then `python3 "
        "benchmarks/accuracy_lines.py --write`.  Do not edit by hand: re-run the script.  "
        "It shares its run cache with `benchmarks/moordyn_check.py` "
        "([the reference against MoorDyn](../benchmarks/moordyn.md)) and re-runs the "
        "steps of `benchmarks/fd_budget.py` ([the FD error budget]"
        "(../benchmarks/fd_budget.md)) for this page's motion.",
        "",
        f"Machine: {platform.machine()}, {os.cpu_count()} cores, Python "
        f"{platform.python_version()}, numpy {np.__version__}, scipy {scipy.__version__}, "
        f"stochcable {stochcable.__version__}, MoorDyn-C {metadata.version('moordyn')}.  "
        f"1-min load average after each run {np.nanmin(loads):.2f}–{np.nanmax(loads):.2f} "
        "(a shared 2-core VM; every run on one core, niced).  Sum of the wall times of "
        f"the {len(mine)} runs: {wall / 60:.0f} min.",
        "",
    ]


def _setup(cache: dict) -> list[str]:
    md0 = _seeds(cache, "chain", "moordyn")
    x_exact = md0[0]["motion_exact"]
    out = [
        "## What is compared",
        "",
        "- **Lines** (one homogeneous segment each; details and static tensions on "
        "[the MoorDyn page](../benchmarks/moordyn.md)): `chain`, the bundled "
        "`chain_catenary` example's line (850 m of 288 kg/m chain, 200 m water, "
        "seabed contact); `taut`, a taut synthetic rope (454 m, 25 kg/m, EA 1.5e8 N, "
        "no seabed contact); `deep`, a wire catenary in 1000 m of water (2200 m, 70 "
        "kg/m, 484 m grounded).  No sea, no current: only the fairlead (end_b) moves.",
        f"- **Motion**: fairlead surge, PM Hs {mc.HS:g} m, Tp {mc.TP:g} s on "
        f"{mc.BAND[0]:g}–{mc.BAND[1]:g} rad/s.  The time domain uses its periodic DSA "
        f"realization (period {mc.PERIOD:g} s, one warm-up period with a {mc.RAMP:g} s "
        "ramp and one measured period, seeds "
        f"{', '.join(map(str, mc.SEEDS))}): the motion σ over the measured window is "
        f"{x_exact:.5f} m for every seed.  The FD gets the same density as a table on the "
        "band (zero outside); its motion σ is "
        + ", ".join(f"{_fd(cache, line, 'default')['motion_std']:.5f} m ({line})" for line in LINES)
        + " on its default grid.",
        "- **Tension**: σ of the support reaction at the fairlead and at the anchor — the "
        "FD's `end_b`/`end_a` tension.  In both simulators the reaction is the end "
        "segment's force plus the loads lumped on the end node (MoorDyn: the end node's "
        "net force and inertia); see the MoorDyn page for the end-segment tension.",
        "- **FD default**: `analyze()` at the settings a user runs — `chain`: the "
        "example's own (" + _settings(_fd(cache, "chain", "default")) + "); `taut`, "
        "`deep`: the scene model's defaults (" + _settings(_fd(cache, "taut", "default")) + ").",
        f"- **FD adaptive**: the same scene with `analysis.fidelity.target_error` = "
        f"{TARGET:g}; the settings it chose are in the table further down.",
        "- **FD converged**: direct solver, drag linearization converged to 1e-8, 320 "
        f"elements and {FINE_GRID} frequencies on the band; and, for the budget, on the "
        "TD's own lines 2πj/T (80, 160 and 320 elements), its σ summed as the DSA sums "
        "them (every line with its full weight, not the trapezoid).",
        "- **Reference TD**: `simulate_line_timedomain`, 80 elements (and 160), Newmark "
        "Δt 0.05 s, quadratic drag, one-sided seabed, geometric nonlinearity.",
        "- **MoorDyn**: MoorDyn-C, 80 segments, dtM 1 ms, RK4, coupling every 5 ms, "
        "no internal damping.",
        "- ± is the 95 % Student-t half-width over the 5 seeds.  FD/TD − 1 is taken per "
        "seed (FD σ over the seed's σ) and then averaged; TD/MoorDyn − 1 is paired "
        "(the same phases in both).",
        "",
    ]
    return out


def _settings(r: dict) -> str:
    w = r["omega"]
    modes = "all" if r["solver"] == "direct" else f"{r['modes']} modes kept"
    return (
        f"{r['elements']} elements, {w[2]} frequencies on {w[0]:.3g}–{w[1]:.3g} rad/s, "
        f"{r['solver']} ({modes}), linearization tolerance {r['tolerance']:g}"
    )


def _sigma_tables(cache: dict) -> list[str]:
    out = [
        "## End tension σ",
        "",
        "| line | end | FD default [kN] | FD adaptive [kN] | reference TD [kN] "
        "| MoorDyn [kN] | TD, 160 elements [kN] |",
        "|---|---|---|---|---|---|---|",
    ]
    for line in LINES:
        fd0, fda = _fd(cache, line, "default"), _fd(cache, line, "adaptive")
        td, md = _seeds(cache, line, "reference"), _seeds(cache, line, "moordyn")
        td2 = _seeds(cache, line, "reference", FINE)
        for q, end in ENDS:
            out.append(
                f"| {line} | {end} | {fd0[q] / 1e3:.2f} | {fda[q] / 1e3:.2f} "
                f"| {_kn([r[q] for r in td])} | {_kn([r[q] for r in md])} "
                f"| {_kn([r[q] for r in td2])} |"
            )
    out += [
        "",
        "## Ratios",
        "",
        "| line | end | FD default / TD − 1 | FD adaptive / TD − 1 | FD default + "
        "residuals / TD − 1 | FD default / MoorDyn − 1 | FD adaptive / MoorDyn − 1 "
        "| TD / MoorDyn − 1 (paired) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for line in LINES:
        fd0, fda = _fd(cache, line, "default"), _fd(cache, line, "adaptive")
        fdr = _fd(cache, line, "residuals")
        td, md = _seeds(cache, line, "reference"), _seeds(cache, line, "moordyn")
        for q, end in ENDS:
            rq = q.replace("reaction", "residual")
            out.append(
                f"| {line} | {end} | {_pct(_over(fd0[q], td, q))} "
                f"| {_pct(_over(fda[q], td, q))} | {_pct(_over(fdr[rq], td, q))} "
                f"| {_pct(_over(fd0[q], md, q))} | {_pct(_over(fda[q], md, q))} "
                f"| {_pct(_over([r[q] for r in td], md, q))} |"
            )
    out += [
        "",
        "Converged (320 elements, direct, drag to 1e-8, on the TD's lines) against the "
        "160-element reference TD, with and without the residuals:",
        "",
        "| line | end | FD converged / TD − 1 | FD converged + residuals / TD − 1 |",
        "|---|---|---|---|",
    ]
    for line in LINES:
        fdc, fdr = _fd(cache, line, "lines320"), _fd(cache, line, "residuals320")
        td2 = _seeds(cache, line, "reference", FINE)
        for q, end in ENDS:
            lq = q.replace("reaction", "lines")
            rq = q.replace("reaction", "lines_residual")
            out.append(
                f"| {line} | {end} | {_pct(_over(fdc[lq], td2, q))} "
                f"| {_pct(_over(fdr[rq], td2, q))} |"
            )
    out += [
        "",
        "'FD default + residuals': σ with the end-tension variances the linear model "
        "drops — the drag residual and the second-order geometric forces "
        "(`analysis.linearization.drag_residual`, `.geometric_residual`, "
        "[their benchmark](../benchmarks/drag_residual.md)); the linear σ is unchanged.",
    ]
    return out + [""]


def _first_clause(text: str) -> str:
    cut = text.find(" (")
    return (text[:cut] + " …") if cut > 0 else text


def _adaptive(cache: dict) -> list[str]:
    out = [
        "## Adaptive fidelity (target error 1 %)",
        "",
        "The plan's estimates (`Result.fidelity.error_estimate`) next to what it gives: "
        "'discretization, measured' is |FD adaptive / FD converged − 1| (320 elements, "
        f"{FINE_GRID} frequencies on the band, direct, tolerance 1e-8), the larger end; "
        "'model' is the calibrated error of the linear model against the nonlinear time domain "
        "(`stochcable.fidelity.model_error.CALIBRATION`), compared with the measured "
        "FD/TD below.",
        "",
        "| line | settings chosen | est. discretization | discretization, measured "
        "| est. model | est. total | wall [s] |",
        "|---|---|---|---|---|---|---|",
    ]
    for line in LINES:
        fda, conv = _fd(cache, line, "adaptive"), _fd(cache, line, "fine320")
        est = fda["plan"]["error_estimate"]
        meas = max(abs(fda[q] / conv[q] - 1.0) for q, _ in ENDS)
        out.append(
            f"| {line} | {_settings(fda)} | {100 * est['discretization']:.2f} % "
            f"| {100 * meas:.2f} % | {100 * est['linearization_model']:.2f} % "
            f"| {100 * est['total']:.2f} % | {fda['wall']:.2f} |"
        )
    out += [
        "",
        "Warnings of the FD analyses (first clause of each; `Result.warnings`):",
        "",
    ]
    for line in LINES:
        for variant in ("default", "adaptive"):
            for w in _fd(cache, line, variant)["warnings"]:
                out.append(f"- `{line}`, {variant}: {_first_clause(w)}")
    out += [
        "",
        "The tension spectrum 'at the top of the grid' is expected here: the motion "
        "stops at 2 rad/s by construction, in both domains, so nothing is cut that the "
        "time domain has.",
        "",
    ]
    return out


def _budget_section(cache: dict, line: str) -> list[str]:
    b = _budget(cache, line)
    fd0 = _fd(cache, line, "default")
    fd2, fd3 = _fd(cache, line, "lines160"), _fd(cache, line, "lines320")
    td, td2 = _seeds(cache, line, "reference"), _seeds(cache, line, "reference", FINE)
    klass = "suspended" if line == "taut" else "touchdown"
    cal = CALIBRATION[klass]
    cells = {}
    fine = _fd(cache, line, "fine320")
    # the FD on the TD's lines as the DSA sums them (see fd_budget.line_sum_std)
    fd2 = {q: fd2[f"lines_{q[-1]}"] for q, _ in ENDS}
    fd3 = {q: fd3[f"lines_{q[-1]}"] for q, _ in ENDS}
    for e, (q, _) in enumerate(ENDS):
        fdv = b["fd"][e]
        inv = {k: fdv / v[:, e] for k, v in b.items() if k != "fd"}  # FD/σ per seed
        disc_td = np.array([r2[q] / r[q] for r, r2 in zip(td, td2)])
        product = (fd0[q] / fine[q]) * (fine[q] / fd2[q]) * inv["full"] * disc_td - 1.0
        cells[q] = {
            "disc_fd": _pct(fd0[q] / fine[q] - 1.0),
            "lines": _pct(fine[q] / fd2[q] - 1.0),
            "lin": _pct(list(inv["lin"] - 1.0)),
            "geo": _pct(list(inv["lin_amp"] - inv["lin"])),
            "drag": _pct(list(inv["quad"] - inv["lin_amp"])),
            "bed": _pct(list(inv["full"] - inv["quad"])),
            "model": _pct(list(inv["full"] - 1.0)),
            "model160": _pct(_over(fd2[q], td2, q)),
            "disc_td": _pct(list(disc_td - 1.0)),
            "product": _pct(list(product)),
            "total": _pct(_over(fd0[q], td, q)),
            "check": _pct(fd3[q] / fd2[q] - 1.0),
            "fd_b": f"{fdv / 1e3:.2f}",
        }
    c_b, c_a = cells["reaction_b"], cells["reaction_a"]
    c_b_check, c_a_check = c_b["check"], c_a["check"]
    rows = [
        ("FD discretization: default settings against the converged FD",
         "disc_fd", f"FD default / FD converged − 1 (320 elements, {FINE_GRID} frequencies, "
         "direct, tolerance 1e-8)"),
        ("spectrum sampling: the continuous spectrum against the TD's lines", "lines",
         "FD converged / FD on the TD's lines 2πj/T with 160 elements − 1 (160 → 320 "
         f"elements on the lines: {c_b_check} / {c_a_check})"),
        ("linear model mismatch", "lin",
         "FD 160 / TD made linear − 1 (the FD's drag coefficients, a bilateral linear bed, "
         "1e-3 of the motion)"),
        ("geometric nonlinearity", "geo", "TD step: + full motion"),
        ("drag linearization", "drag",
         "TD step: + quadratic drag (the static and the instantaneous tangent)"),
        ("seabed (one-sided)", "bed", "TD step: + lift-off and landing"),
        ("**model error** (sum of the four above)", "model",
         "FD 160 / nonlinear TD 160 − 1, the budget's runs"),
        ("… the same from the page's TD 160 runs", "model160",
         "FD 160 / TD 160 − 1: a check of the budget's last step"),
        ("TD discretization: 80 → 160 elements", "disc_td",
         "TD 160 / TD 80 − 1, paired"),
        ("product of the terms (check)", "product",
         "∏(1 + term) − 1 over the FD, sampling, model (budget) and TD terms, per seed"),
        ("**total**, measured", "total", "FD default / TD 80 − 1 (the ratio table)"),
    ]  # fmt: skip
    out = [
        f"### {line}",
        "",
        f"FD 160 σ: {c_b['fd_b']} kN (fairlead) / {c_a['fd_b']} kN (anchor).  Each term "
        "is a contribution to FD/TD − 1 (negative: the FD reads low); the model terms "
        "are the steps of `benchmarks/fd_budget.py` from the TD made linear to the full "
        "reference, at 160 elements, each step's FD/σ_TD difference per seed.",
        "",
        "| term | fairlead | anchor | how |",
        "|---|---|---|---|",
    ]
    for label, key, how in rows:
        out.append(f"| {label} | {c_b[key]} | {c_a[key]} | {how} |")
    out.append(
        f"| fidelity plan's model-error calibration (`{klass}`) | ±{100 * cal.fairlead:.2f} % "
        f"| ±{100 * cal.anchor:.2f} % | `CALIBRATION['{klass}']`, what `target_error` "
        "plans assume for this line |"
    )
    return out + [""]


def _mean_ratio(num: float | list[float], den: list[dict], q: str) -> float:
    return 100.0 * float(np.mean(_over(num, den, q)))


def _reading(cache: dict) -> list[str]:
    """The summary, its numbers read from the runs."""
    out = ["## Reading", ""]
    tdmd = max(
        abs(_mean_ratio([r[q] for r in _seeds(cache, line, "reference")],
                        _seeds(cache, line, "moordyn"), q))
        for line in LINES for q, _ in ENDS
    )  # fmt: skip
    out.append(
        f"- **The two time domains agree**: reference TD and MoorDyn within {tdmd:.2f} % "
        "(mean paired ratio, either end, every line), so either is the yardstick."
    )
    for line in LINES:
        td, td2 = _seeds(cache, line, "reference"), _seeds(cache, line, "reference", FINE)
        fd0, fda = _fd(cache, line, "default"), _fd(cache, line, "adaptive")
        fine = _fd(cache, line, "fine320")
        est = fda["plan"]["error_estimate"]
        cal = CALIBRATION["suspended" if line == "taut" else "touchdown"]
        f = {q: (_mean_ratio(fd0[q], td, q), _mean_ratio(fda[q], td, q)) for q, _ in ENDS}
        on_lines = _fd(cache, line, "lines160")
        model = [
            student_interval(100.0 * np.array(_over(on_lines[f"lines_{q[-1]}"], td2, q)))
            for q, _ in ENDS
        ]
        disc = [100.0 * (fd0[q] / fine[q] - 1.0) for q, _ in ENDS]
        adisc = 100.0 * max(abs(fda[q] / fine[q] - 1.0) for q, _ in ENDS)
        verdict = []
        for (m, h), c in zip(model, (cal.fairlead, cal.anchor)):
            if abs(m) <= 100.0 * c:
                verdict.append("covered")
            elif abs(m) - h <= 100.0 * c:
                verdict.append("covered within the CI")
            else:
                verdict.append("**not covered**")
        out.append(
            f"- **{line}**: FD default / TD − 1 = {f['reaction_b'][0]:+.2f} % (fairlead), "
            f"{f['reaction_a'][0]:+.2f} % (anchor); adaptive {f['reaction_b'][1]:+.2f} % / "
            f"{f['reaction_a'][1]:+.2f} %.  The default settings' own discretization "
            f"error is {disc[0]:+.2f} % / {disc[1]:+.2f} %; the adaptive plan's "
            f"{adisc:.2f} % against its estimate {100 * est['discretization']:.2f} %.  "
            "The linear model's error (FD and TD on the same lines, 160 elements) is "
            f"{model[0][0]:+.2f} ± {model[0][1]:.2f} % / {model[1][0]:+.2f} ± "
            f"{model[1][1]:.2f} %; the fidelity plan assumes ±{100 * cal.fairlead:.2f} % / "
            f"±{100 * cal.anchor:.2f} % for this class of line: "
            + " / ".join(verdict)
            + ".  The reference itself moves by "
            + " / ".join(
                f"{100 * np.mean([r2[q] / r[q] - 1.0 for r, r2 in zip(td, td2)]):+.2f} %"
                for q, _ in ENDS
            )
            + " from 80 to 160 elements."
        )
    return out + [""]


def write_page(cache: dict) -> str:
    """The page, from a complete cache."""
    lines = _header(cache) + _setup(cache) + _reading(cache) + _sigma_tables(cache)
    lines += _adaptive(cache)
    lines += [
        "## Error budget of FD − TD",
        "",
        "The measured total FD/TD − 1 split into the FD's discretization, the linear "
        "model's error (by term) and the reference's own discretization at 80 elements; "
        "the terms multiply, (1 + a)(1 + b)(1 + c) − 1, and add to first order.  Next to "
        "them: the model error the fidelity plan assumes for the line's class "
        "(`stochcable/fidelity/model_error.py`), to be compared with the measured model "
        "error.",
        "",
    ]
    for line in LINES:
        lines += _budget_section(cache, line)
    return "\n".join(lines).rstrip() + "\n"


def quick() -> int:
    """Smoke run: one FD analysis of each kind, one short budget step; no cache."""
    for line in LINES:
        for variant in ("default", "adaptive", "lines80"):
            r = run_fd(line, variant)
            print(f"{line} FD {variant}: fairlead {r['reaction_b'] / 1e3:.2f} kN, "
                  f"anchor {r['reaction_a'] / 1e3:.2f} kN, {r['wall']:.2f} s")  # fmt: skip
    r = run_budget("taut", "lin", 1)
    print(f"taut budget 'lin' seed 1: σ_b {math.sqrt(sum(r['var'][0])) / 1e3:.2f} kN")
    return 0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--budget", type=float, default=170.0, help="seconds per call")
    ap.add_argument("--cache", type=Path, default=mc.CACHE)
    ap.add_argument("--only", choices=("reference", "moordyn", "fd", "budget"))
    ap.add_argument("--line", choices=LINES, help="only the runs of this line")
    ap.add_argument("--write", action="store_true", help=f"write {PAGE.relative_to(ROOT)}")
    ap.add_argument("--quick", action="store_true", help="smoke run of every kind of run")
    args = ap.parse_args(argv)
    if args.quick:
        return quick()
    if args.write:
        PAGE.write_text(write_page(mc.load_cache(args.cache)))
        print(f"wrote {PAGE}")
        return 0
    todo = [
        r
        for r in runs()
        if (args.only is None or r["sim"] == args.only) and args.line in (None, r["line"])
    ]
    left = mc.run_missing(args.cache, args.budget, todo, execute)
    print(f"{left} runs left" if left else "all runs done: --write writes the page")
    return 0


if __name__ == "__main__":
    sys.exit(main())
