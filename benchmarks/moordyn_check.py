"""Benchmark: the time-domain reference against MoorDyn-C (issue 22 item 1).

    python benchmarks/moordyn_check.py [--budget 170] [--cache DIR]   # run what is missing
    python benchmarks/moordyn_check.py --write                         # write the page

Every simulation (one line, one simulator, one seed, one set of options) is cached in
``--cache`` (default: <tmp>/stochcable_moordyn_check/runs.json), so the full set is run
in slices of at most ``--budget`` seconds (a single simulation takes 5–45 s on one core)
and the page docs/benchmarks/moordyn.md is written from the cache once all are there.

Lines (one homogeneous segment each, 80 elements = 80 MoorDyn segments):

- ``chain``: the bundled example's line (stochcable/examples/chain_catenary.json: 850 m
  of 288 kg/m chain, EA 1.2326e9 N, D 0.216 m, Cdn 1.333, CdAx 0.2034, Can 1, depth
  200 m, seabed 3e6 Pa/m and 3e5 Pa·s/m).
- ``taut``: a taut synthetic rope (polyester-like: D 0.16 m, 25 kg/m, EA 1.5e8 N, Cdn
  1.2, CdAx 0.008, Can 1; 454 m from (−420, 0, −200) to (0, 0, −20): about 0.7 %
  strain, 0.97 MN, no seabed contact).
- ``deep``: a deep-water wire catenary (D 0.12 m, 70 kg/m, EA 1.2e9 N, Cdn 1.2, CdAx
  0.008, Can 1; 2200 m from (−1800, 0, −1000) to (0, 0, −20), depth 1000 m, touchdown
  484 m from the anchor; seabed as the chain's).

The accuracy page (benchmarks/accuracy_lines.py) adds ``twoseg`` (420 m of the chain's
chain from the anchor, 315 m of the taut line's rope to the fairlead, anchor at
(−700, 0, −200)) and ``current`` (the chain in the example's 0.5 m/s current; the
reference only: :func:`run_scene` keeps the current, MoorDyn's input file has none).

Motion: fairlead surge, periodic DSA of a Pierson–Moskowitz spectrum Hs 2 m, Tp 10 s on
0.05–2 rad/s, period T = 200 s; record = one warm-up period (30 s half-cosine ramp)
and one measured period; seeds 1–5; no sea, no current.  Reference: Newmark Δt
0.05 s.  MoorDyn: dtM 1 ms, RK4 (see stochcable.reference.moordyn on why not RK2),
coupling calls every 5 ms, BA = 0 unless stated.
"""

from __future__ import annotations

import argparse
import fcntl
import json
import math
import os
import tempfile
import time
from collections.abc import Callable
from importlib import metadata
from pathlib import Path

import numpy as np

from stochcable.examples import load_example
from stochcable.reference.moordyn import (
    comparison_scene,
    internal_damping_coefficient,
    periodic_dsa_surge,
    simulate_line_moordyn,
)
from stochcable.reference.moordyn_compare import (
    simulate_line_reference,
    student_interval,
    window_std,
)
from stochcable.scene.model import load_scene
from stochcable.sea.spectra import spectrum_pierson_moskowitz

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "benchmarks" / "moordyn.md"
PERIOD, RAMP, BAND, HS, TP = 200.0, 30.0, (0.05, 2.0), 2.0, 10.0
SEEDS = (1, 2, 3, 4, 5)
SEABED = {"stiffness": 3.0e6, "damping": 3.0e5}
CACHE = Path(tempfile.gettempdir()) / "stochcable_moordyn_check" / "runs.json"

TAUT = {
    "environment": {"depth": 200.0, "rho": 1025.0, "g": 9.80665, "seabed": SEABED},
    "lines": [
        {
            "name": "taut_rope",
            "end_a": {"position": [-420.0, 0.0, -200.0]},
            "end_b": {"position": [0.0, 0.0, -20.0]},
            "segments": [
                {"length": 454.0, "ea": 1.5e8, "mass": 25.0, "diameter": 0.16,
                 "cd_normal": 1.2, "cd_axial": 0.008, "ca_normal": 1.0}
            ],
        }
    ],
}  # fmt: skip
DEEP = {
    "environment": {"depth": 1000.0, "rho": 1025.0, "g": 9.80665, "seabed": SEABED},
    "lines": [
        {
            "name": "deep_wire",
            "end_a": {"position": [-1800.0, 0.0, -1000.0]},
            "end_b": {"position": [0.0, 0.0, -20.0]},
            "segments": [
                {"length": 2200.0, "ea": 1.2e9, "mass": 70.0, "diameter": 0.12,
                 "cd_normal": 1.2, "cd_axial": 0.008, "ca_normal": 1.0}
            ],
        }
    ],
}  # fmt: skip
TWO_SEGMENT = {
    "environment": {"depth": 200.0, "rho": 1025.0, "g": 9.80665, "seabed": SEABED},
    "lines": [
        {
            "name": "chain_rope",
            "end_a": {"position": [-700.0, 0.0, -200.0]},
            "end_b": {"position": [0.0, 0.0, -20.0]},
            "segments": [
                {"length": 420.0, "ea": 1.2326e9, "mass": 288.0, "diameter": 0.216,
                 "cd_normal": 1.333, "cd_axial": 0.2034, "ca_normal": 1.0},
                {"length": 315.0, "ea": 1.5e8, "mass": 25.0, "diameter": 0.16,
                 "cd_normal": 1.2, "cd_axial": 0.008, "ca_normal": 1.0},
            ],
        }
    ],
}  # fmt: skip


def line_document(name: str, seabed_damping: float | None = None) -> dict:
    """The scene document of a benchmark line (seabed damping overridden if given):
    ``chain``, ``taut``, ``deep``, ``twoseg`` (chain on the bed, synthetic rope to the
    fairlead) or ``current`` (the chain in the example's 0.5 m/s current)."""
    if name in ("chain", "current"):  # "current": the example keeps its 0.5 m/s current
        doc = load_example("chain_catenary").model_dump(mode="json", exclude_none=True)
        if name == "chain":
            doc["environment"]["current"] = []
    else:
        doc = json.loads(json.dumps({"taut": TAUT, "deep": DEEP, "twoseg": TWO_SEGMENT}[name]))
    if seabed_damping is not None:
        doc["environment"]["seabed"] = dict(doc["environment"]["seabed"], damping=seabed_damping)
    return doc


# ---------------------------------------------------------------- the runs

# A run: (line, simulator, seed, options); options of the reference: dt, ba (N·s or
# MoorDyn's −ζ, converted per element count); of MoorDyn: ba, scheme, coupling; both:
# elements, cbot (seabed damping override).
BASE = {"elements": 80}


def _runs() -> list[dict]:
    runs = []

    def both(line, seeds, **opt):
        for s in seeds:
            runs.append({"line": line, "sim": "reference", "seed": s, **BASE, **opt})
            runs.append({"line": line, "sim": "moordyn", "seed": s, **BASE, **opt})

    for line in ("chain", "taut", "deep"):
        both(line, SEEDS)
    two = (1, 2)
    both("chain", two, elements=20)
    both("chain", two, elements=40)
    both("chain", two, cbot=0.0)
    for s in two:
        runs.append(
            {"line": "chain", "sim": "reference", "seed": s, **BASE, "cbot": 0.0, "dt": 0.0125}
        )
    for s in two:
        for dt in (0.025, 0.1, 0.125, 0.2):
            runs.append({"line": "chain", "sim": "reference", "seed": s, **BASE, "dt": dt})
        runs.append({"line": "chain", "sim": "moordyn", "seed": s, **BASE, "coupling": 1e-3})
        runs.append({"line": "chain", "sim": "moordyn", "seed": s, **BASE, "ba": -1.0})
        runs.append(
            {"line": "chain", "sim": "reference", "seed": s, **BASE, "ba": -1.0, "dt": 0.025}
        )
    for n in (20, 40, 80):
        for s in two:
            runs.append(
                {"line": "chain", "sim": "reference", "seed": s, **BASE, "elements": n,
                 "mass": "lumped"}
            )  # fmt: skip
    for s in two:
        runs.append({"line": "deep", "sim": "reference", "seed": s, **BASE, "dt": 0.025})
        runs.append({"line": "deep", "sim": "reference", "seed": s, **BASE, "mass": "lumped"})
    for line in ("chain", "taut", "deep"):
        for s in (1, 2, 3):
            runs.append(
                {"line": line, "sim": "moordyn", "seed": s, **BASE, "ba": -1.0, "scheme": "RK2"}
            )
            runs.append({"line": line, "sim": "reference", "seed": s, **BASE, "ba": -1.0})
    return runs


def run_key(run: dict) -> str:
    return json.dumps(run, sort_keys=True)


def run_scene(run: dict):
    """The scene a run simulates: :func:`comparison_scene` of the line at the run's
    element count (a line of several segments: the count shared in proportion to their
    lengths; a line with a current: the current kept, which comparison_scene drops)."""
    doc = line_document(run["line"], run.get("cbot"))
    segs = doc["lines"][0]["segments"]
    if len(segs) == 1 and not (doc["environment"].get("current") and run["sim"] == "reference"):
        return comparison_scene(doc, elements=run["elements"])
    total = sum(sg["length"] for sg in segs)
    for sg in segs:
        sg["elements"] = max(1, round(run["elements"] * sg["length"] / total))
    ln = doc["lines"][0]
    for end in ("end_a", "end_b"):
        ln[end].pop("motion", None)
    doc.pop("sea", None)
    doc.setdefault("analysis", {}).pop("timeseries", None)
    doc["analysis"].pop("fidelity", None)
    if run["sim"] == "moordyn":
        doc["environment"]["current"] = []  # (not reached: no MoorDyn run with a current)
    return load_scene(doc)


def simulate(run: dict):
    """One simulation: the end-tension history, the motion and the wall time [s]."""
    sc = run_scene(run)
    motion = periodic_dsa_surge(
        lambda w: spectrum_pierson_moskowitz(w, HS, TP), PERIOD, BAND, run["seed"]
    )
    ba = internal_damping_coefficient(sc, run.get("ba", 0.0))
    t0 = time.perf_counter()
    if run["sim"] == "reference":
        h = simulate_line_reference(
            sc,
            motion,
            duration=2 * PERIOD,
            ramp=RAMP,
            dt=run.get("dt", 0.05),
            internal_damping=ba,
            mass_matrix=run.get("mass", "consistent"),
        )
    else:
        h = simulate_line_moordyn(
            sc,
            motion,
            duration=2 * PERIOD,
            ramp=RAMP,
            coupling_dt=run.get("coupling", 5e-3),
            internal_damping=run.get("ba", 0.0),
            scheme=run.get("scheme", "RK4"),
        )
    return h, motion, ba, time.perf_counter() - t0


def summarize(h, motion, ba: float, wall: float) -> dict:
    """σ over the measured period, static tensions, wall time of one simulation."""
    sig, xs = window_std(h, PERIOD, 2 * PERIOD)
    return {
        **sig,
        "motion_std": xs,
        "motion_exact": motion.std,
        "static_a": h.static_a,
        "static_b": h.static_b,
        "ba_ns": ba,
        "wall": wall,
    }


def execute(run: dict) -> dict:
    """One simulation: σ over the measured period, static tensions, wall time."""
    return summarize(*simulate(run))


def load_cache(path: Path) -> dict:
    return json.loads(path.read_text()) if path.exists() else {}


def run_missing(
    cache_path: Path,
    budget: float,
    runs: list[dict] | None = None,
    execute_run: Callable[[dict], dict] | None = None,
) -> int:
    """Run missing simulations until ``budget`` seconds are spent; the number left.

    ``runs`` (default this page's) are executed by ``execute_run`` (default
    :func:`execute`); benchmarks/accuracy_lines.py shares the cache and its runs."""
    cache = load_cache(cache_path)
    t_start = time.perf_counter()
    todo = [r for r in (_runs() if runs is None else runs) if run_key(r) not in cache]
    for i, run in enumerate(todo):
        if time.perf_counter() - t_start > budget:
            return len(todo) - i
        if run_key(run) in load_cache(cache_path):  # done by another process
            continue
        print(f"run {run_key(run)}", flush=True)
        result = (execute_run or execute)(run)
        cache_path.parent.mkdir(parents=True, exist_ok=True)
        # read-add-write under a lock: without it two processes finishing together each
        # wrote the cache they had read, and one run was lost
        with open(cache_path.with_name(cache_path.name + ".lock"), "w") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)
            cache = load_cache(cache_path)  # another process may have added runs
            cache[run_key(run)] = result
            tmp = cache_path.with_name(f"{cache_path.name}.{os.getpid()}")
            tmp.write_text(json.dumps(cache, indent=1))
            os.replace(tmp, cache_path)  # atomic: a reader never sees half a file
        print(f"  {cache[run_key(run)]['wall']:.1f} s", flush=True)
    return 0


# ---------------------------------------------------------------- the page


def _get(cache: dict, line: str, sim: str, seeds, **opt) -> list[dict]:
    out = []
    for s in seeds:
        key = run_key({"line": line, "sim": sim, "seed": s, **BASE, **opt})
        if key not in cache:
            raise KeyError(f"missing run {key}: run the script without --write first")
        out.append(cache[key])
    return out


def _ci(x) -> str:
    m, h = student_interval(np.asarray(x, float))
    return f"{m / 1e3:.2f} ± {h / 1e3:.2f}"


def _pct(x) -> str:
    m, h = student_interval(100.0 * np.asarray(x, float))
    return f"{m:+.3f} ± {h:.3f} %" if math.isfinite(h) else f"{m:+.3f} %"


def _ratio(ref: list[dict], md: list[dict], q: str) -> list[float]:
    return [r[q] / m[q] - 1.0 for r, m in zip(ref, md)]


def _shift(new: list[dict], base: list[dict], q: str) -> list[float]:
    return [n[q] / b[q] - 1.0 for n, b in zip(new, base)]


def write_page(cache: dict) -> str:
    lines = [
        "# The time-domain reference against MoorDyn",
        "",
        "`python3 benchmarks/moordyn_check.py` (repeat until it reports nothing left; "
        "each call runs at most `--budget` s), then `python3 benchmarks/moordyn_check.py "
        "--write`.  Harness: `stochcable.reference.moordyn` (conventions, MoorDyn input "
        "file, coupled stepping) and `stochcable.reference.moordyn_compare`.",
        "",
        f"MoorDyn-C {metadata.version('moordyn')} (the `moordyn` package) against "
        "`simulate_line_timedomain`, the same line, coefficients and fairlead surge: "
        f"periodic DSA of PM Hs {HS:g} m, Tp {TP:g} s on {BAND[0]:g}–{BAND[1]:g} rad/s, "
        f"period {PERIOD:g} s (Δω = {2 * math.pi / PERIOD:.4f} rad/s), one warm-up "
        f"period with a {RAMP:g} s half-cosine ramp, one measured period; no sea, no "
        "current; 80 elements = 80 MoorDyn segments; reference Newmark Δt 0.05 s; "
        "MoorDyn dtM 1 ms, RK4, coupling calls every 5 ms, BA = 0.  σ is over the "
        "measured period sampled every 0.05 s, in kN; ± is the 95 % Student-t half-width "
        "over the seeds.  Tension = the end **segment's** tension in both (MoorDyn "
        "`GetLineFairTen`, `GetLineNodeTen(0)`; ours `element_tension`), 'reaction' = "
        "the fairlead support reaction (the end segment plus the loads lumped on the end "
        "node, its inertia included).  The ratio is paired (same phases per seed): "
        "σ_reference/σ_MoorDyn − 1.  Wall times: one simulation on one core of the "
        "shared 2-core machine (other work running).",
        "",
    ]
    md0 = _get(cache, "chain", "moordyn", SEEDS)
    x_exact = md0[0]["motion_exact"]
    x_real = max(abs(r["motion_std"] / r["motion_exact"] - 1.0) for r in md0)
    lines += [
        f"Motion σ: {x_exact:.5f} m (Σ S(ω_j)Δω), realized over the measured period to "
        f"{x_real:.1e} relative in every seed.",
        "",
        "## Agreement, 5 seeds",
        "",
        "| line | static T_a ref / MD [kN] | σ_a ref [kN] | σ_a MD [kN] | ratio a "
        "| static T_b ref / MD [kN] | σ_b ref [kN] | σ_b MD [kN] | ratio b | ratio reaction b "
        "| σ_a/σ_x ref / MD [kN/m] | σ_b/σ_x ref / MD [kN/m] | wall ref / MD [s] |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for line in ("chain", "taut", "deep"):
        ref = _get(cache, line, "reference", SEEDS)
        md = _get(cache, line, "moordyn", SEEDS)
        nb_r = np.mean([r["b"] / r["motion_std"] for r in ref]) / 1e3
        nb_m = np.mean([r["b"] / r["motion_std"] for r in md]) / 1e3
        na_r = np.mean([r["a"] / r["motion_std"] for r in ref]) / 1e3
        na_m = np.mean([r["a"] / r["motion_std"] for r in md]) / 1e3
        lines.append(
            f"| {line} | {ref[0]['static_a'] / 1e3:.1f} / {md[0]['static_a'] / 1e3:.1f} "
            f"| {_ci([r['a'] for r in ref])} | {_ci([r['a'] for r in md])} "
            f"| {_pct(_ratio(ref, md, 'a'))} "
            f"| {ref[0]['static_b'] / 1e3:.1f} / {md[0]['static_b'] / 1e3:.1f} "
            f"| {_ci([r['b'] for r in ref])} | {_ci([r['b'] for r in md])} "
            f"| {_pct(_ratio(ref, md, 'b'))} | {_pct(_ratio(ref, md, 'reaction_b'))} "
            f"| {na_r:.2f} / {na_m:.2f} | {nb_r:.2f} / {nb_m:.2f} "
            f"| {np.mean([r['wall'] for r in ref]):.0f} / "
            f"{np.mean([r['wall'] for r in md]):.0f} |"
        )
    lines += _experiments(cache)
    lines += _partial_window()
    lines += _findings(cache)
    return "\n".join(lines) + "\n"


def _partial_window() -> list[str]:
    """The realized motion σ when a DSA record of length T_L is measured after a ramp
    (over part of its period), as a 600 s record at 0.05 s after a 30 s ramp."""
    out = [
        "",
        "## Why whole periods: the motion σ over part of a DSA period",
        "",
        "A DSA record has the spectrum's variance exactly over its whole period only.  "
        "Measured after a 30 s ramp on a 600 s record (the example scene's time-series "
        "length), the realized fairlead σ of five seeds is:",
        "",
        "| seed | σ_x over [30, 600) s [m] | relative to Σ S Δω |",
        "|---|---|---|",
    ]
    for seed in SEEDS:
        m = periodic_dsa_surge(lambda w: spectrum_pierson_moskowitz(w, HS, TP), 600.0, BAND, seed)
        x = m.displacement(np.arange(30.0, 600.0, 0.05))
        out.append(f"| {seed} | {x.std():.4f} | {x.std() / m.std - 1.0:+.2%} |")
    out.append("")
    out.append(
        "Each seed's tension σ then carries that input error (the normalized σ/σ_x "
        "removes most of it); over whole periods the error is zero (table above)."
    )
    return out


def _mean_pct(new: list[dict], base: list[dict], q: str) -> float:
    return 100.0 * float(np.mean(_shift(new, base, q)))


def _findings(cache: dict) -> list[str]:
    """The conclusions, with their numbers read from the runs above."""
    two, three = (1, 2), (1, 2, 3)
    g = lambda line, sim, seeds=two, **o: _get(cache, line, sim, seeds, **o)  # noqa: E731
    worst = max(
        abs(x) * 100.0
        for line in ("chain", "taut", "deep")
        for q in ("a", "b")
        for x in _ratio(g(line, "reference", SEEDS), g(line, "moordyn", SEEDS), q)
    )
    ref0 = g("chain", "reference")
    dts = {dt: _mean_pct(g("chain", "reference", dt=dt), ref0, "b") for dt in (0.025, 0.125, 0.2)}
    n20 = 100 * np.mean(
        _ratio(g("chain", "reference", elements=20), g("chain", "moordyn", elements=20), "b")
    )
    n20l = 100 * np.mean(
        _ratio(
            g("chain", "reference", elements=20, mass="lumped"),
            g("chain", "moordyn", elements=20),
            "b",
        )
    )
    ba = {
        line: (
            100
            * np.mean(
                _ratio(
                    g(line, "reference", three),
                    g(line, "moordyn", three, ba=-1.0, scheme="RK2"),
                    "b",
                )
            ),
            100
            * np.mean(
                _ratio(
                    g(line, "reference", three, ba=-1.0),
                    g(line, "moordyn", three, ba=-1.0, scheme="RK2"),
                    "b",
                )
            ),
        )
        for line in ("chain", "taut", "deep")
    }
    deep_l = 100 * np.mean(_ratio(g("deep", "reference", mass="lumped"), g("deep", "moordyn"), "b"))
    deep_c = 100 * np.mean(_ratio(g("deep", "reference"), g("deep", "moordyn"), "b"))
    cb = 100 * np.mean(
        _ratio(g("chain", "reference", cbot=0.0), g("chain", "moordyn", cbot=0.0), "b")
    )
    cb_fine = 100 * np.mean(
        _ratio(g("chain", "reference", cbot=0.0, dt=0.0125), g("chain", "moordyn", cbot=0.0), "b")
    )
    rk = _mean_pct(
        g("chain", "moordyn", ba=-1.0, scheme="RK2"), g("chain", "moordyn", ba=-1.0), "b"
    )
    cpl = _mean_pct(g("chain", "moordyn", coupling=1e-3), g("chain", "moordyn"), "b")
    react = 100 * np.mean([r["reaction_b"] / r["b"] - 1.0 for r in ref0])
    return [
        "",
        "## Findings",
        "",
        f"1. **Agreement.**  With the same physics (no internal damping) and 80 elements the "
        f"reference and MoorDyn agree on the end tension σ within {worst:.2f} % on every "
        "seed of the three lines, at both ends, and on the static end tensions within "
        "0.01 %.  The goal (0.5 %) is met without changing the reference's physics; the "
        "differences below are the modelling and numerical choices that move it.",
        f"2. **Reference time step** (Newmark period error, numerical): the fairlead σ "
        f"moves by {dts[0.025]:+.2f} % at Δt 0.025 s, {dts[0.125]:+.2f} % at 0.125 s and "
        f"{dts[0.2]:+.2f} % at 0.2 s against Δt 0.05 s.  0.125 s is the step the reference "
        "picks by itself for this motion on the example's 0.25 s grid ((ωΔt)²/12 ≤ 0.5 % "
        "at the 99 % frequency, 1.72 rad/s): its default records read high by that row.  "
        "Pass `dt` ≤ 0.05 s (what this page does) for a 0.2 %-level yardstick.",
        "3. **Internal damping** (physical: MoorDyn's `BA`).  MoorDyn as commonly run "
        "(BA = −1, i.e. ζ = 1 of each segment's axial mode, RK2; RK2 needs it: without "
        "damping its axial modes grow) against the undamped reference: ratio b "
        + ", ".join(f"{k} {v[0]:+.2f} %" for k, v in ba.items())
        + "; with the same BA in the reference (`simulate_line_timedomain(..., "
        "internal_damping=BA)`, N·s, from `internal_damping_coefficient`): "
        + ", ".join(f"{k} {v[1]:+.2f} %" for k, v in ba.items())
        + ".  ζ-per-segment damping depends on the segment count; it is a model choice of "
        "MoorDyn's, not a property of the line.",
        f"4. **Lumped vs consistent mass** (discretization).  At 20 elements the reference "
        f"reads {n20:+.2f} % against MoorDyn at the fairlead; with MoorDyn's lumped mass "
        f"(`mass_matrix='lumped'`) {n20l:+.2f} % — the mass matrix is most of the "
        "difference, the rest is MoorDyn's nodal drag and node-tangent added mass.  Both "
        "converge to the same σ as the elements grow (the 40- and 80-element rows).  The "
        f"deep line's {deep_c:+.2f} % at 80 elements (27.5 m elements) is the same term: "
        f"{deep_l:+.2f} % with the lumped mass.",
        f"5. **Seabed damping.**  With cBot = 0 the reference reads {cb:+.0f} % against "
        "MoorDyn (which moves by < 0.3 %): the grounded nodes ring on the contact spring "
        "(k·D·l ≈ 6.9e6 N/m per node against ≈ 3.4 t of node mass, ≈ 45 rad/s; ωΔt ≈ 2.3 "
        "at Δt 0.05 s) and the one-sided contact pumps that unresolved oscillation; no "
        "ResolutionWarning says so.  At Δt 0.0125 s the reference reads "
        f"{cb_fine:+.2f} %.  With the example's cBot = 3e5 Pa·s/m the contact mode is "
        "overdamped and Δt 0.05 s is fine.",
        "6. **Conventions that do not matter here**: MoorDyn's `CdAx` is on π·d like ours "
        "(passed unchanged; a factor π in the axial drag moves the chain's fairlead σ by "
        "≈ 1.7 % at 40 elements, which the test would see); MoorDyn coupling calls "
        f"every 1 ms instead of 5 ms move the fairlead σ by {cpl:+.3f} %; RK2 instead of "
        f"RK4 (with BA = −1) by {rk:+.3f} %.",
        f"7. **Which tension.**  MoorDyn's `FairTen`/`AnchTen` are end-*segment* tensions; "
        f"the support reaction (the frequency-domain end tension's definition) has a σ "
        f"{react:+.2f} % above it at the chain's fairlead with 80 elements (O(1/N): the "
        "inertia of the half element on the end node), identical in both simulators.  "
        "A comparison of the frequency domain with MoorDyn must use the same one.",
    ]


def _experiments(cache: dict) -> list[str]:
    two = (1, 2)
    ref0 = _get(cache, "chain", "reference", two)
    md0 = _get(cache, "chain", "moordyn", two)
    out = [
        "",
        "## Controlled experiments (chain, seeds 1–2, one term switched at a time)",
        "",
        "Shift = σ(changed)/σ(baseline) − 1 of the simulator changed; ratio = the paired "
        "reference/MoorDyn ratio with the change.",
        "",
        "| change | shift ref a / b | shift MD a / b | ratio a | ratio b |",
        "|---|---|---|---|---|",
        f"| baseline (80 el., Δt 0.05 s, RK4, BA 0) | – | – | {_pct(_ratio(ref0, md0, 'a'))} "
        f"| {_pct(_ratio(ref0, md0, 'b'))} |",
    ]

    def row(label, ref, md):
        sr = f"{_pct(_shift(ref, ref0, 'a'))} / {_pct(_shift(ref, ref0, 'b'))}"
        sm = f"{_pct(_shift(md, md0, 'a'))} / {_pct(_shift(md, md0, 'b'))}"
        if ref is ref0:
            sr = "–"
        if md is md0:
            sm = "–"
        out.append(
            f"| {label} | {sr} | {sm} | {_pct(_ratio(ref, md, 'a'))} "
            f"| {_pct(_ratio(ref, md, 'b'))} |"
        )

    for n in (20, 40, 80):
        md_n = md0 if n == 80 else _get(cache, "chain", "moordyn", two, elements=n)
        if n != 80:
            row(
                f"{n} elements (both)",
                _get(cache, "chain", "reference", two, elements=n),
                md_n,
            )
        row(
            f"{n} elements, reference with lumped mass (`mass_matrix='lumped'`)",
            _get(cache, "chain", "reference", two, elements=n, mass="lumped"),
            md_n,
        )
    for dt in (0.025, 0.1, 0.125, 0.2):
        row(
            f"reference Δt {dt:g} s (Newmark period error (ωΔt)²/12 = "
            f"{(2.0 * dt) ** 2 / 12:.2%} at 2 rad/s, {(0.63 * dt) ** 2 / 12:.3%} at the peak)",
            _get(cache, "chain", "reference", two, dt=dt),
            md0,
        )
    row(
        "MoorDyn coupling calls every 1 ms",
        ref0,
        _get(cache, "chain", "moordyn", two, coupling=1e-3),
    )
    row(
        "seabed damping cBot = 0 (both)",
        _get(cache, "chain", "reference", two, cbot=0.0),
        _get(cache, "chain", "moordyn", two, cbot=0.0),
    )
    row(
        "… and the reference at Δt 0.0125 s",
        _get(cache, "chain", "reference", two, cbot=0.0, dt=0.0125),
        _get(cache, "chain", "moordyn", two, cbot=0.0),
    )
    md_ba4 = _get(cache, "chain", "moordyn", two, ba=-1.0)
    row("MoorDyn BA = −1 (ζ 1 per segment), RK4; reference undamped", ref0, md_ba4)
    row(
        "… and the reference with the same BA (`internal_damping`), Δt 0.025 s",
        _get(cache, "chain", "reference", two, ba=-1.0, dt=0.025),
        md_ba4,
    )
    ref_d = _get(cache, "deep", "reference", two)
    md_d = _get(cache, "deep", "moordyn", two)
    out += [
        "",
        "Deep-water catenary, seeds 1–2:",
        "",
        "| change | ratio a | ratio b |",
        "|---|---|---|",
        f"| baseline | {_pct(_ratio(ref_d, md_d, 'a'))} | {_pct(_ratio(ref_d, md_d, 'b'))} |",
    ]
    for label, opt in (
        ("reference Δt 0.025 s", {"dt": 0.025}),
        ("reference lumped mass", {"mass": "lumped"}),
    ):
        r = _get(cache, "deep", "reference", two, **opt)
        out.append(f"| {label} | {_pct(_ratio(r, md_d, 'a'))} | {_pct(_ratio(r, md_d, 'b'))} |")
    out += [
        "",
        "## Internal damping: MoorDyn as commonly run (BA = −1, RK2) — seeds 1–3",
        "",
        "| line | BA [N·s] | ratio a, reference undamped | ratio b, reference undamped "
        "| ratio a, reference with BA | ratio b, reference with BA |",
        "|---|---|---|---|---|---|",
    ]
    three = (1, 2, 3)
    for line in ("chain", "taut", "deep"):
        md = _get(cache, line, "moordyn", three, ba=-1.0, scheme="RK2")
        ref_u = _get(cache, line, "reference", three)
        ref_d = _get(cache, line, "reference", three, ba=-1.0)
        out.append(
            f"| {line} | {ref_d[0]['ba_ns']:.3g} | {_pct(_ratio(ref_u, md, 'a'))} "
            f"| {_pct(_ratio(ref_u, md, 'b'))} | {_pct(_ratio(ref_d, md, 'a'))} "
            f"| {_pct(_ratio(ref_d, md, 'b'))} |"
        )
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--budget", type=float, default=170.0, help="seconds per call")
    ap.add_argument("--cache", type=Path, default=CACHE)
    ap.add_argument("--write", action="store_true", help=f"write {PAGE.relative_to(ROOT)}")
    args = ap.parse_args()
    if args.write:
        PAGE.write_text(write_page(load_cache(args.cache)))
        print(f"wrote {PAGE}")
        return
    left = run_missing(args.cache, args.budget)
    print(f"{left} runs left" if left else "all runs done: --write writes the page")


if __name__ == "__main__":
    main()
