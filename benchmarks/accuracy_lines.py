"""Accuracy per line (issue 22 item 4, issue 31 item 5): the frequency domain (FD) at a
user's settings — the default (corrected: the residual switches true) and the linear
model (switches false) — and with adaptive fidelity, against the time-domain reference
and MoorDyn; spectral fatigue damage against the TD's rainflow damage and the TD
tension's non-Gaussian statistics (benchmarks/accuracy_fatigue.py); the error budget
of the linear FD − TD.

    python benchmarks/accuracy_lines.py [--budget 170] [--only KIND]   # run what is missing
    python benchmarks/accuracy_lines.py --write                         # write the page
    python benchmarks/accuracy_lines.py --quick                         # smoke run, no page

The lines, the fairlead motion and the simulators' settings are those of
benchmarks/moordyn_check.py (chain = the bundled example's line, taut synthetic rope,
deep-water wire catenary, a two-segment chain + rope line, the chain in its 0.5 m/s
current (reference TD only: the MoorDyn harness writes no current); periodic DSA
surge of PM Hs 2 m Tp 10 s on 0.05–2 rad/s, period 200 s, seeds 1–5; 80 elements = 80
MoorDyn segments), and so is the run cache (``--cache``, default the one of
moordyn_check.py: the runs both pages need are run once; the simulations' end-tension
records over the measured period are kept in ``records/`` next to it, for the rainflow
counts).  Every run — one simulation of one seed, one FD analysis, one step of the
error budget — is cached, so the set is run in slices of at most ``--budget`` seconds;
two processes may share the cache (``--only reference|moordyn|fd|budget`` splits the
work).

The FD sees the same motion spectrum, band-limited to the same band: the surge is a
table of the PM density on 0.05–2 rad/s (zero outside), so that adaptive fidelity, which
chooses its own band, cannot widen it.  The error budget re-runs the variants of
benchmarks/fd_budget.py (linear TD → geometric nonlinearity → quadratic drag → one-sided
seabed) for this motion, at 160 elements.
"""

from __future__ import annotations

import argparse
import functools
import hashlib
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

import accuracy_fatigue  # noqa: E402 (sibling benchmark scripts)
import fd_budget  # noqa: E402
import moordyn_check as mc  # noqa: E402

import stochcable  # noqa: E402
from stochcable import analyze  # noqa: E402
from stochcable.fidelity.model_error import CALIBRATION  # noqa: E402
from stochcable.reference.moordyn_compare import student_interval  # noqa: E402
from stochcable.sea.spectra import spectrum_pierson_moskowitz  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "accuracy" / "lines.md"
LINES = ("chain", "taut", "deep", "twoseg", "current")
BUDGET_LINES = ("chain", "taut", "deep")  # with the error budget and the converged FD
MOORDYN_LINES = ("chain", "taut", "deep", "twoseg")  # (the harness writes no current)
FINE = 160  # elements of the converged TD and of the budget
# the TD's mesh study: elements run per line (5 seeds each).  The yardstick of a line
# is its reference TD at the coarsest mesh whose doubling moves σ by less than
# CONVERGED at both ends (paired mean over the seeds); see reference_mesh()
TD_MESHES = {
    "chain": (80, 160), "taut": (80, 160), "deep": (80, 160, 320), "twoseg": (80, 160),
    "current": (80, 160),
}  # fmt: skip
CONVERGED = 0.002
FD_VARIANTS = (
    "default", "linear", "adaptive", "lines80", "lines160", "lines320", "fine320",
    "residuals320",
)  # fmt: skip
NEW_LINE_VARIANTS = ("default", "linear", "adaptive")
FINE_GRID = 2000  # frequencies of the converged continuous-spectrum FD on the band
TARGET = 0.01  # analysis.fidelity.target_error of the adaptive FD


def surge_table() -> dict:
    """The PM surge spectrum as a table on the band (zero outside). [m²·s/rad]"""
    w = np.linspace(mc.BAND[0], mc.BAND[1], 391)
    s = spectrum_pierson_moskowitz(w, mc.HS, mc.TP)
    return {"type": "table", "omega": w.tolist(), "density": s.tolist()}


def fd_document(line: str, variant: str = "default") -> dict:
    """The line's scene as a user runs it in the FD: the line alone with its fairlead
    surging (no sea, no time series; the ``current`` line keeps its current) at the
    settings of ``variant``, the residual switches set explicitly: "default" (true,
    the library's default), "linear" (false), "adaptive" (true, with a target error),
    "lines<n>"/"fine<n>" (false; n elements, the TD's lines or a fine grid) and
    "residuals<n>" (true, as "lines<n>")."""
    corrected = variant in ("default", "adaptive") or variant.startswith("residuals")
    if variant.startswith("residuals"):
        variant = "lines" + variant.removeprefix("residuals")
    doc = mc.line_document(line)
    doc.pop("sea", None)
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
    doc["analysis"].setdefault("linearization", {}).update(
        drag_residual=corrected, geometric_residual=corrected
    )
    return doc


def _density(omega: np.ndarray, density: np.ndarray) -> list[list[float]]:
    return [np.asarray(omega, float).tolist(), np.asarray(density, float).tolist()]


def run_fd(line: str, variant: str) -> dict:
    """One FD analysis: end σ (the answer and the linear model's), the end-tension
    densities, settings, warnings, the fidelity plan."""
    doc = fd_document(line, variant)
    t0 = time.perf_counter()
    res = analyze(doc)
    wall = time.perf_counter() - t0
    lr = res.lines[doc["lines"][0]["name"]]
    sc = res.scene
    an = sc.analysis
    k = list(lr.channels).index(next(c for c in lr.channels if "surge" in c))
    out = {
        # the answer (with the residuals where they were computed) and the linear σ
        "reaction_b": float(lr.end_b.std),
        "reaction_a": float(lr.end_a.std),
        "linear_b": float(lr.linear_end("end_b").std),
        "linear_a": float(lr.linear_end("end_a").std),
        "density": {
            end: {
                "answer": _density(*lr.end_tension_density(end)),
                "linear": _density(lr.omega, lr.end_tension_spectrum(end)),
            }
            for end in ("end_a", "end_b")
        },
        "mean": {end: float(getattr(lr, end).mean) for end in ("end_a", "end_b")},
        "mpm_3h": {end: float(getattr(lr, end).mpm_3h) for end in ("end_a", "end_b")},
        "motion_std": float(math.sqrt(np.trapezoid(lr.input_spectra[k], lr.omega))),
        # on the TD's lines: σ as the DSA sums it (every line with its full weight)
        **dict(zip(("lines_b", "lines_a"), fd_budget.line_sum_std(lr).tolist())),
        "wall": wall,
        "elements": int(sc.lines[0].elements),
        "segment_elements": [int(sg.elements) for sg in sc.lines[0].segments],
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
    return fd_budget.fd(FINE, 1.0, fd_document(line, "linear"))


def run_budget(line: str, variant: str, seed: int) -> dict:
    """One TD variant of the error budget: [[fairlead in, out], [anchor in, out]]
    variances [N²] (fd_budget.td at full motion)."""
    f = _budget_fd(line)
    kw, scale = fd_budget.variant_options(variant, f)
    t0 = time.perf_counter()
    var = fd_budget.td(FINE, seed, scale, fd_document(line, "linear"), **kw)
    return {"var": var.tolist(), "fd": f["std"].tolist(), "wall": time.perf_counter() - t0}


def runs() -> list[dict]:
    """Every run of the page: the simulations first (the long ones), then the FD."""
    out = []
    for line in LINES:
        for s in mc.SEEDS:
            out.append({"line": line, "sim": "reference", "seed": s, **mc.BASE})
            if line in MOORDYN_LINES:
                out.append({"line": line, "sim": "moordyn", "seed": s, **mc.BASE})
    for line in LINES:
        for variant in FD_VARIANTS if line in BUDGET_LINES else NEW_LINE_VARIANTS:
            out.append({"line": line, "sim": "fd", "variant": variant})
    for line, meshes in TD_MESHES.items():
        for n in meshes[1:]:
            for s in mc.SEEDS:
                out.append({"line": line, "sim": "reference", "seed": s, "elements": n})
    for line in BUDGET_LINES:
        for name, _, _ in fd_budget.VARIANTS:
            for s in mc.SEEDS:
                out.append({"line": line, "sim": "budget", "variant": name, "seed": s})
    return out


def record_path(records: Path, run: dict) -> Path:
    """Where the tension records of a simulation run are kept (next to the cache)."""
    return records / (hashlib.sha1(mc.run_key(run).encode()).hexdigest()[:20] + ".npz")


def execute(run: dict, records: Path | None = None) -> dict:
    """One run of :func:`runs` (the simulations through moordyn_check.simulate, their
    end-tension records over the measured period saved under ``records``), with the
    host's load average after it."""
    if run["sim"] == "fd":
        out = run_fd(run["line"], run["variant"])
    elif run["sim"] == "budget":
        out = run_budget(run["line"], run["variant"], run["seed"])
    else:
        h, motion, ba, wall = mc.simulate(run)
        out = mc.summarize(h, motion, ba, wall)
        if records is not None:
            w = h.window(mc.PERIOD, 2 * mc.PERIOD)
            records.mkdir(parents=True, exist_ok=True)
            np.savez_compressed(
                record_path(records, run),
                t=h.t[w],
                reaction_a=h.reaction_a[w],
                reaction_b=h.reaction_b[w],
                tension_a=h.tension_a[w],
                tension_b=h.tension_b[w],
            )
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


def mesh_moves(cache: dict, line: str) -> list[tuple[int, int, list[float]]]:
    """The reference TD's mesh study of ``line``: (n, 2n, [fairlead, anchor] paired mean
    σ(2n)/σ(n) − 1 over the seeds) for each step of :data:`TD_MESHES` that has run."""
    meshes = TD_MESHES.get(line, (mc.BASE["elements"],))
    out = []
    for n, n2 in zip(meshes, meshes[1:]):
        try:
            a, b = _seeds(cache, line, "reference", n), _seeds(cache, line, "reference", n2)
        except KeyError:
            break
        out.append((n, n2, [float(np.mean([y[q] / x[q] - 1.0 for x, y in zip(a, b)]))
                            for q, _ in ENDS]))  # fmt: skip
    return out


def reference_mesh(cache: dict, line: str) -> int:
    """The yardstick's mesh: the coarsest reference TD mesh whose doubling moves σ by
    less than :data:`CONVERGED` at both ends (paired mean); the finest run if none
    does (then the page says so)."""
    steps = mesh_moves(cache, line)
    for n, _, moves in steps:
        if max(abs(m) for m in moves) < CONVERGED:
            return n
    return steps[-1][1] if steps else mc.BASE["elements"]


def _ref(cache: dict, line: str) -> list[dict]:
    """The yardstick: the reference TD at :func:`reference_mesh`."""
    return _seeds(cache, line, "reference", reference_mesh(cache, line))


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
        "([the reference against MoorDyn](../benchmarks/moordyn.md))"
        + (
            " and re-runs the steps of `benchmarks/fd_budget.py` ([the FD error budget]"
            "(../benchmarks/fd_budget.md)) for this page's motion"
            if _budget_complete(cache)
            else ""
        )
        + "; the fatigue and non-Gaussian statistics are `benchmarks/accuracy_fatigue.py`'s.",
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
        "- **Lines** (details and static tensions of the first three on "
        "[the MoorDyn page](../benchmarks/moordyn.md)): `chain`, the bundled "
        "`chain_catenary` example's line (850 m of 288 kg/m chain, 200 m water, "
        "seabed contact) without its current; `taut`, a taut synthetic rope (454 m, 25 "
        "kg/m, EA 1.5e8 N, no seabed contact); `deep`, a wire catenary in 1000 m of water "
        "(2200 m, 70 kg/m, 484 m grounded); `twoseg`, two segments in 200 m of water: "
        "420 m of the chain's chain from the anchor (about 230 m of it on the bed) and "
        "315 m of the taut line's synthetic rope to the fairlead (anchor 700 m from the "
        "fairlead's foot; static tension "
        f"{_seeds(cache, 'twoseg', 'reference')[0]['static_b'] / 1e3:.0f} kN at the "
        "fairlead); `current`, the chain in the example's own current, 0.5 m/s uniform "
        "over depth along +x (from the anchor toward the fairlead).  No sea: only the "
        "fairlead (end_b) moves.",
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
        "- **FD default (no flags)**: `analyze()` at the settings a user runs, with the "
        "residual switches `analysis.linearization.drag_residual` and "
        "`geometric_residual` true (the library's default; set explicitly here so that "
        "the page does not depend on the default of the day): σ is the corrected one, "
        "from the corrected end-tension spectrum (`LineResult.corrected_spectra`).  "
        "Settings (the mesh is the one the scene used: a segment without `elements` "
        "gets the count derived from the line):",
    ]
    for line in LINES:
        out.append(f"  - `{line}`: " + _settings(_fd(cache, line, "default")) + ".")
    out += [
        "- **FD linear**: the same with both switches false: the linear model's σ (what "
        "the `linear` block of a result holds).",
        f"- **FD adaptive**: the default scene with `analysis.fidelity.target_error` = "
        f"{TARGET:g} (switches true); the settings it chose are in the table further down.",
        "- **FD converged** (`chain`, `taut`, `deep`): direct solver, drag linearization "
        f"converged to 1e-8, 320 elements and {FINE_GRID} frequencies on the band; and, "
        "for the budget, on the TD's own lines 2πj/T (80, 160 and 320 elements), its σ "
        "summed as the DSA sums them (every line with its full weight, not the trapezoid).",
        "- **Reference TD**: `simulate_line_timedomain`, 80 elements (two segments: 46 + "
        "34, in proportion to their lengths) and finer meshes for its mesh study ("
        + "; ".join(f"`{ln}`: {', '.join(map(str, ns[1:]))}" for ln, ns in TD_MESHES.items())
        + "; the yardstick is the converged one: 'The yardstick's mesh' below), Newmark "
        "Δt 0.05 s, quadratic drag (on the velocity relative to the current), one-sided "
        "seabed, geometric nonlinearity.",
        "- **MoorDyn**: MoorDyn-C, 80 segments (46 + 34), dtM 1 ms, RK4, coupling every "
        "5 ms, no internal damping; the two-segment line's joint starts at stochcable's "
        "static solution (from the straight line MoorDyn's initial-condition solve stops "
        "unconverged).  **No MoorDyn run for `current`**: the harness "
        "(`stochcable.io.moordyn_write`) writes `Currents 0` and warns that a scene's "
        "current is not written; MoorDyn-C reads a steady current from its own "
        "`current_profile.txt`, not wired here.  The current case has the reference TD "
        "only.",
        "- ± is the 95 % Student-t half-width over the 5 seeds.  FD/TD − 1 is taken per "
        "seed (FD σ over the seed's σ) and then averaged; TD/MoorDyn − 1 is paired "
        "(the same phases in both).",
        "",
    ]
    return out


def _settings(r: dict) -> str:
    w = r["omega"]
    modes = "all" if r["solver"] == "direct" else f"{r['modes']} modes kept"
    segs = r.get("segment_elements", [r["elements"]])
    mesh = f"{r['elements']} elements" + (
        f" ({' + '.join(map(str, segs))})" if len(segs) > 1 else ""
    )
    return (
        f"{mesh}, {w[2]} frequencies on {w[0]:.3g}–{w[1]:.3g} rad/s, "
        f"{r['solver']} ({modes}), linearization tolerance {r['tolerance']:g}"
    )


def _md(cache: dict, line: str) -> list[dict] | None:
    return _seeds(cache, line, "moordyn") if line in MOORDYN_LINES else None


def _sigma_tables(cache: dict) -> list[str]:
    out = [
        "## End tension σ",
        "",
        "| line | end | FD default [kN] | FD linear [kN] | FD adaptive [kN] "
        "| reference TD, 80 elements [kN] | TD, 160 elements [kN] | TD, 320 elements [kN] "
        "| MoorDyn, 80 segments [kN] |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for line in LINES:
        fd0, fdl = _fd(cache, line, "default"), _fd(cache, line, "linear")
        fda = _fd(cache, line, "adaptive")
        md = _md(cache, line)
        tds = {
            n: _seeds(cache, line, "reference", n)
            for n in TD_MESHES.get(line, (80,))
            if all(mc.run_key({"line": line, "sim": "reference", "seed": s, "elements": n})
                   in cache for s in mc.SEEDS)
        }  # fmt: skip
        for q, end in ENDS:
            cells = " | ".join(
                (_kn([r[q] for r in tds[n]]) + (" (yardstick)" if n == reference_mesh(
                    cache, line) else "")) if n in tds else "–"
                for n in (80, 160, 320)
            )  # fmt: skip
            out.append(
                f"| {line} | {end} | {fd0[q] / 1e3:.2f} | {fdl[q] / 1e3:.2f} "
                f"| {fda[q] / 1e3:.2f} | {cells} "
                f"| {_kn([r[q] for r in md]) if md else '–'} |"
            )
    out += [
        "",
        "## The yardstick's mesh",
        "",
        "The reference TD of a line is taken at the coarsest mesh whose doubling moves "
        f"σ by less than {100 * CONVERGED:.1f} % at both ends (paired mean over the "
        "seeds); MoorDyn runs 80 segments on every line (its comparison with the "
        "reference is paired at 80 elements).",
        "",
        "| line | mesh step | fairlead σ moves | anchor σ moves | yardstick |",
        "|---|---|---|---|---|",
    ]
    for line in LINES:
        n_ref = reference_mesh(cache, line)
        for n, n2, moves in mesh_moves(cache, line):
            out.append(
                f"| {line} | {n} → {n2} elements | {100 * moves[0]:+.2f} % "
                f"| {100 * moves[1]:+.2f} % | {n_ref} elements |"
            )
    out += [
        "",
        "## Ratios",
        "",
        "Target (issue 31): the default σ within 1 % of the reference TD at the fairlead "
        "and 2 % at the anchor.  'TD' is the yardstick (the reference TD at its "
        "converged mesh, above); the 80-element ratio is the previous page's.",
        "",
        "| line | end | FD default / TD − 1 | target met | FD default / TD 80 − 1 "
        "| FD linear / TD − 1 "
        "| FD adaptive / TD − 1 | FD default / MoorDyn − 1 | FD linear / MoorDyn − 1 "
        "| TD 80 / MoorDyn − 1 (paired) |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for line in LINES:
        fd0, fdl = _fd(cache, line, "default"), _fd(cache, line, "linear")
        fda = _fd(cache, line, "adaptive")
        td, md = _ref(cache, line), _md(cache, line)
        td80 = _seeds(cache, line, "reference")
        for q, end in ENDS:
            mine = 100.0 * float(np.mean(_over(fd0[q], td, q)))
            # (at the table's precision)
            ok = "yes" if abs(round(mine, 2)) <= (1.0 if q == "reaction_b" else 2.0) else "**no**"
            md_cells = (
                f"{_pct(_over(fd0[q], md, q))} | {_pct(_over(fdl[q], md, q))} "
                f"| {_pct(_over([r[q] for r in td80], md, q))}"
                if md
                else "– | – | –"
            )
            out.append(
                f"| {line} | {end} | {_pct(_over(fd0[q], td, q))} | {ok} "
                f"| {_pct(_over(fd0[q], td80, q))} | {_pct(_over(fdl[q], td, q))} "
                f"| {_pct(_over(fda[q], td, q))} "
                f"| {md_cells} |"
            )
    out += [
        "",
        "Converged (320 elements, direct, drag to 1e-8, on the TD's lines) against the "
        "160-element reference TD, with and without the residuals; and the default "
        "against the 160-element TD (the reference's own mesh error removed):",
        "",
        "| line | end | FD converged, linear / TD − 1 | FD converged, corrected / TD − 1 "
        "| FD default / TD 160 − 1 |",
        "|---|---|---|---|---|",
    ]
    for line in BUDGET_LINES:
        fdc, fdr = _fd(cache, line, "lines320"), _fd(cache, line, "residuals320")
        fd0 = _fd(cache, line, "default")
        td2 = _seeds(cache, line, "reference", FINE)
        for q, end in ENDS:
            lq = q.replace("reaction", "lines")
            rq = q.replace("reaction", "lines_residual")
            out.append(
                f"| {line} | {end} | {_pct(_over(fdc[lq], td2, q))} "
                f"| {_pct(_over(fdr[rq], td2, q))} | {_pct(_over(fd0[q], td2, q))} |"
            )
    out += [
        "",
        "'Corrected': σ with the end-tension variances the linear model drops — the drag "
        "residual and the second-order geometric forces "
        "([their benchmark](../benchmarks/drag_residual.md)); 'linear': without them.",
    ]
    return out + [""]


def _first_clause(text: str) -> str:
    cut = text.find(" (")
    return (text[:cut] + " …") if cut > 0 else text


def _basis(r: dict) -> str:
    """What the plan's model-error estimate rests on (``model_error_basis``)."""
    basis = r["plan"]["model_error_basis"]
    return "residuals" if "computed residuals" in basis else "calibration"


def _adaptive(cache: dict) -> list[str]:
    out = [
        "## Adaptive fidelity (target error 1 %)",
        "",
        "The plan's estimates (`Result.fidelity.error_estimate`) next to what it gives: "
        "'discretization, measured' is |FD adaptive / FD converged − 1| of the linear σ "
        "(320 elements, "
        f"{FINE_GRID} frequencies on the band, direct, tolerance 1e-8), the larger end; "
        "'model' is the plan's estimate of the answer's own error against the nonlinear "
        "time domain (`stochcable.fidelity.model_error`): with the residuals computed "
        "(the switches true), what they leave — the square of their share of σ, plus "
        "the one-sided bed's share on a line with a grounded length ('residuals'); "
        "without them, the linear model's calibrated error "
        "(`CALIBRATION`, 'calibration'); compare the measured FD adaptive / TD in the "
        "ratio table.",
        "",
        "| line | settings chosen | est. discretization | discretization, measured "
        "| est. model | est. total | wall [s] |",
        "|---|---|---|---|---|---|---|",
    ]
    for line in LINES:
        fda = _fd(cache, line, "adaptive")
        est = fda["plan"]["error_estimate"]
        meas = "–"
        if line in BUDGET_LINES:  # the converged FD is linear: compare the linear σ
            conv = _fd(cache, line, "fine320")
            err = max(abs(fda[f"linear_{q[-1]}"] / conv[q] - 1.0) for q, _ in ENDS)
            meas = f"{100 * err:.2f} %"
        out.append(
            f"| {line} | {_settings(fda)} | {100 * est['discretization']:.2f} % "
            f"| {meas} | {100 * est['linearization_model']:.2f} % ({_basis(fda)}) "
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
    fd0 = _fd(cache, line, "linear")  # the linear model's budget
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
        ("FD discretization: default mesh and grid against the converged FD",
         "disc_fd", f"FD linear / FD converged − 1 (320 elements, {FINE_GRID} frequencies, "
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
        ("**total**, measured", "total", "FD linear / TD 80 − 1 (the ratio table)"),
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
        "plans assume for this line with the residual switches false |"
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
        for line in MOORDYN_LINES for q, _ in ENDS
    )  # fmt: skip
    out.append(
        f"- **The two time domains agree**: reference TD and MoorDyn within {tdmd:.2f} % "
        "(mean paired ratio, either end, every line MoorDyn runs), so either is the "
        "yardstick."
    )
    worst = {q: max(abs(_mean_ratio(_fd(cache, line, "default")[q],
                                     _ref(cache, line), q)) for line in LINES)
             for q, _ in ENDS}  # fmt: skip
    out.append(
        f"- **Default (corrected) σ against the TD** (the yardstick: the reference TD at "
        f"its converged mesh, see 'The yardstick's mesh'): worst line {worst['reaction_b']:.2f} % "
        f"at the fairlead (target 1 %), {worst['reaction_a']:.2f} % at the anchor "
        "(target 2 %); per line:"
    )
    for line in LINES:
        td, n_ref = _ref(cache, line), reference_mesh(cache, line)
        fd0, fdl = _fd(cache, line, "default"), _fd(cache, line, "linear")
        f = {q: (_mean_ratio(fd0[q], td, q), _mean_ratio(fdl[q], td, q)) for q, _ in ENDS}
        ci = {q: _pct(_over(fd0[q], td, q)) for q, _ in ENDS}
        text = (
            f"  - **{line}** (TD at {n_ref} elements): default / TD − 1 = "
            f"{ci['reaction_b']} (fairlead), {ci['reaction_a']} (anchor); linear "
            f"{f['reaction_b'][1]:+.2f} % / {f['reaction_a'][1]:+.2f} %."
        )
        if n_ref != mc.BASE["elements"]:
            td80 = _seeds(cache, line, "reference")
            text += (
                "  Against the 80-element TD (the previous yardstick, not mesh-converged): "
                + " / ".join(f"{_mean_ratio(fd0[q], td80, q):+.2f} %" for q, _ in ENDS)
                + "."
            )
        if line in BUDGET_LINES:
            td2, td = _seeds(cache, line, "reference", FINE), _seeds(cache, line, "reference")
            fine = _fd(cache, line, "fine320")
            disc = [100.0 * (fd0[f"linear_{q[-1]}"] / fine[q] - 1.0) for q, _ in ENDS]
            text += (
                "  The default mesh's own discretization error (linear σ against the "
                f"converged FD) is {disc[0]:+.2f} % / {disc[1]:+.2f} %; the reference "
                "itself moves by "
                + " / ".join(
                    f"{100 * np.mean([r2[q] / r[q] - 1.0 for r, r2 in zip(td, td2)]):+.2f} %"
                    for q, _ in ENDS
                )
                + " from 80 to 160 elements; the default against the 160-element TD: "
                + " / ".join(f"{_mean_ratio(fd0[q], td2, q):+.2f} %" for q, _ in ENDS)
                + "."
            )
        out.append(text)
    return out + [""]


def _fatigue_inputs(cache: dict, records: Path) -> list[dict]:
    """Per line and end: the reference TD's support-reaction records (one measured
    period per seed) and the FD default (corrected) and linear densities."""
    out = []
    for line in LINES:
        fd0, fdl = _fd(cache, line, "default"), _fd(cache, line, "linear")
        for q, end in ENDS:
            e = "end_" + q[-1]
            recs, md, td80 = [], [], []
            n_ref = reference_mesh(cache, line)
            for s in mc.SEEDS:
                run = {"line": line, "sim": "reference", "seed": s, "elements": n_ref}
                with np.load(record_path(records, run)) as f:
                    recs.append(np.array(f[q]))
                    dt = float(f["t"][1] - f["t"][0])
                run = {"line": line, "sim": "reference", "seed": s, **mc.BASE}
                with np.load(record_path(records, run)) as f:
                    td80.append(np.array(f[q]))
                if line in MOORDYN_LINES:
                    run["sim"] = "moordyn"
                    with np.load(record_path(records, run)) as f:
                        md.append(np.array(f[q]))
            out.append(
                {
                    "line": line,
                    "end": end,
                    "key": e,
                    "records": recs,
                    "md_records": md,
                    "td80_records": td80,
                    "elements": n_ref,
                    "dt": dt,
                    "default": [np.asarray(x) for x in fd0["density"][e]["answer"]],
                    "linear": [np.asarray(x) for x in fdl["density"][e]["linear"]],
                    "curve": _curve_name(line, e),
                }
            )
    return out


def _curve_name(line: str, end: str) -> str:
    """The DNV curve of a line's end: studless chain where the end is chain, the
    stranded-rope curve on the wire and the synthetic rope (the catalogue has no
    polyester curve; m = 4)."""
    if line in ("chain", "current") or (line == "twoseg" and end == "end_a"):
        return "dnv-studless"
    return "dnv-six-strand"


def _budget_complete(cache: dict) -> bool:
    return all(mc.run_key(r) in cache for r in runs() if r["sim"] == "budget")


def write_page(cache: dict, records: Path | None = None) -> str:
    """The page, from a complete cache and the simulations' ``records`` (the folder
    :func:`execute` saved them in)."""
    lines = _header(cache) + _setup(cache) + _reading(cache) + _sigma_tables(cache)
    if records is not None:
        lines += accuracy_fatigue.sections(_fatigue_inputs(cache, records))
    lines += _adaptive(cache)
    lines += [
        "## Error budget of the linear FD − TD",
        "",
    ]
    if not _budget_complete(cache):
        lines += [
            "Not re-run for this regeneration (CPU); [the FD error budget]"
            "(../benchmarks/fd_budget.md) has the terms of the bundled chain's motion.",
            "",
        ]
        return "\n".join(lines).rstrip() + "\n"
    lines += [
        "The measured total FD/TD − 1 of the **linear** model (switches false) split into "
        "the FD's discretization, the linear model's error (by term) and the reference's "
        "own discretization at 80 elements; the terms multiply, (1 + a)(1 + b)(1 + c) − "
        "1, and add to first order.  The residuals (the default) recover the drag and "
        "geometric terms: compare the ratio table.  Next to them: the model error the "
        "fidelity plan assumes for the line's class when the residuals are not computed "
        "(`stochcable/fidelity/model_error.py`; with them, the default, it estimates "
        "what they leave instead: the adaptive table).",
        "",
    ]
    for line in BUDGET_LINES:
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
        records = args.cache.parent / "records"
        PAGE.write_text(write_page(mc.load_cache(args.cache), records))
        print(f"wrote {PAGE}")
        return 0
    todo = [
        r
        for r in runs()
        if (args.only is None or r["sim"] == args.only) and args.line in (None, r["line"])
    ]
    records = args.cache.parent / "records"
    left = mc.run_missing(
        args.cache, args.budget, todo, functools.partial(execute, records=records)
    )
    print(f"{left} runs left" if left else "all runs done: --write writes the page")
    return 0


if __name__ == "__main__":
    sys.exit(main())
