"""Speed versus error of every fidelity setting of analyze().

For reference scenes of :mod:`stochcable.examples` — ``taut_wire``, ``chain_catenary``
(seabed, moving fairlead), ``inclined_guy`` and a buoy mooring (``tuah_1982_single_leg``:
until bodies exist the buoy is *not* modelled as a body, it is the line's end_b heaving
with the sea surface, RAO 1) — sweep the settings of ``analysis`` and of
``segments[].elements``:

- elements per segment ×0.25 … ×4 of the example's,
- kept modes (Foss): auto, 5, 10, 20, all,
- frequency count 50 … 800 at the example's ``omega.max`` and at twice it,
- grid spacing linear / log,
- drag-linearization tolerance 1e-2 … 1e-6,
- solver direct versus foss,

plus a few combinations (finer mesh and wider grid together) for the Pareto front.
Each setting's wall time is the median of repeated ``analyze()`` calls, and its error is
measured on three quantities — fairlead (end_b) and anchor (end_a) effective-tension σ
and σ of the motion (|σ_x, σ_y, σ_z|) at the arc length of the example mesh's
fairlead-adjacent node (linearly interpolated for other meshes) — against

(a) a converged frequency-domain reference: direct solve, linearization tolerance 1e-8,
    the grid [ω_min, 2·ω_max] with 8× the example's count (Δω/4), and an
    element ladder ×1, ×2, ×4, ×8 with Richardson extrapolation when the last three
    steps converge monotonically (else the finest level); on a grounded line every
    ladder mesh has a node at the static touchdown
    (:func:`stochcable.fidelity.planner.static_touchdowns`), a discretization
    independent of the split touchdown element of the swept settings
    (:func:`stochcable.line.seabed.bed_contact`); its convergence is shown (element
    steps, a half-count grid on the finest mesh and a 4·ω_max grid);
(b) the nonlinear time-domain reference (:func:`stochcable.reference.cable.
    simulate_line_timedomain`, Newmark average acceleration, same mesh family) over
    several seeds of 600 s, excitation band [ω_min, 2·ω_max]: mean σ_TD with its 95 %
    Student-t confidence interval, and the FD/TD ratio with its interval.

Writes a Markdown report (``docs/ACCURACY.md`` with ``--write``) and PNG plots of error versus
time (log–log, each setting a point, Pareto front drawn, default marked) under
``docs/accuracy/``; the report ends with the adaptive-fidelity section of
``benchmarks/adaptive_fidelity.py`` (left out with ``--no-fidelity`` and ``--quick``).

Run:  python benchmarks/speed_vs_error.py [--quick] [--write | --out FILE.md]
(without --write or --out the report goes to stdout; --quick never writes the docs)
"""

from __future__ import annotations

import argparse
import copy
import math
import os
import platform
import statistics
import sys
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

SCENES: tuple[str, ...] = ("taut_wire", "chain_catenary", "inclined_guy", "tuah_1982_single_leg")
QUANTITIES: tuple[str, ...] = ("T_fairlead", "T_anchor", "motion")
LINES_LINK = (
    "Per line against the nonlinear time-domain reference and MoorDyn — the FD at a "
    "user's settings and with adaptive fidelity, confidence intervals over seeds, and "
    "the error budget of FD − TD by term: [Accuracy per line](accuracy/lines.md) "
    "(`benchmarks/accuracy_lines.py`)."
)
QUANTITY_TEXT = {
    "T_fairlead": "fairlead (end_b) tension σ",
    "T_anchor": "anchor (end_a) tension σ",
    "motion": "fairlead-adjacent node motion σ",
}
# Element factor of the time-domain model per scene: the coarsest level of the FD
# element ladder whose next refinement changes the tension σ by < ~2 % (full run;
# measured with this script) — the TD costs grow with the element count.
TD_MESH = {
    "taut_wire": 2.0,
    "chain_catenary": 2.0,
    "inclined_guy": 4.0,
    "tuah_1982_single_leg": 1.0,
}
TD_DEFAULT_SCENES: tuple[str, ...] = (
    "taut_wire",
    "chain_catenary",
    "inclined_guy",
    "tuah_1982_single_leg",
)
REF_TOLERANCE = 1e-8  # linearization tolerance of the references [-]
CI_LEVEL = 0.95

Progress = Callable[[str], None]


def _silent(msg: str) -> None:
    return None


# ----------------------------------------------------------------------- settings


@dataclass(frozen=True)
class Setting:
    """One fidelity setting, relative to the example scene.

    Attributes
    ----------
    label : str
        Short name in tables and plots.
    group : str
        Which knob it varies ("default", "elements", "modes", "grid", "spacing",
        "tolerance", "solver", "combined").
    elements : float
        Factor on every segment's element count (rounded, at least 1 per segment). [-]
    modes : str or int
        "auto", "all" or a count (Foss only). [-]
    count : int or None
        Frequency count (None: the example's). [-]
    omega_max_factor : float
        Factor on the example's omega.max. [-]
    spacing : str or None
        "linear" or "log" (None: the example's). [-]
    tolerance : float or None
        Linearization tolerance (None: the example's). [-]
    solver : str or None
        "foss" or "direct" (None: the example's). [-]
    """

    label: str
    group: str
    elements: float = 1.0
    modes: str | int = "auto"
    count: int | None = None
    omega_max_factor: float = 1.0
    spacing: str | None = None
    tolerance: float | None = None
    solver: str | None = None


def base_document(name: str) -> dict[str, Any]:
    """The example scene as a plain document, without its time series."""
    from stochcable.examples import load_example

    doc = load_example(name).model_dump(mode="json")
    doc["analysis"]["timeseries"] = None
    return doc


def scene_document(
    base: dict[str, Any], s: Setting, *, max_iterations: int = 500
) -> dict[str, Any]:
    """The example document with setting ``s`` applied (the input is not mutated)."""
    d = copy.deepcopy(base)
    for seg in d["lines"][0]["segments"]:
        seg["elements"] = max(1, int(round(seg["elements"] * s.elements)))
    if sum(seg["elements"] for seg in d["lines"][0]["segments"]) < 2:
        d["lines"][0]["segments"][0]["elements"] = 2
    a = d["analysis"]
    # the study's FD is the linear model (its settings' errors; the residuals are the
    # separate "FD + residuals" column, fd_with_residuals): both switches false, the
    # defaults since issue 31 being true
    a.setdefault("linearization", {}).update(drag_residual=False, geometric_residual=False)
    a["modes"] = 100_000 if s.modes == "all" else s.modes  # clamped to the free DOFs
    om = a["omega"]
    om["max"] = om["max"] * s.omega_max_factor
    if s.count is not None:
        om["count"] = int(s.count)
    if s.spacing is not None:
        om["spacing"] = s.spacing
    if s.tolerance is not None:
        a["linearization"]["tolerance"] = s.tolerance
        a["linearization"]["max_iterations"] = max_iterations
    if s.solver is not None:
        a["solver"] = s.solver
    return d


def split_at_touchdown(doc: dict[str, Any], touchdown: float | None) -> dict[str, Any]:
    """``doc`` with the first line's segment that contains ``touchdown`` (arc length from
    end_a [m]) split there, its elements shared in proportion (at least one each)."""
    if touchdown is None:
        return doc
    d = copy.deepcopy(doc)
    segs, out, s0 = d["lines"][0]["segments"], [], 0.0
    for seg in segs:
        length, n = float(seg["length"]), int(seg["elements"])
        if s0 + 1e-6 * length < touchdown < s0 + length * (1.0 - 1e-6):
            a = touchdown - s0
            n_a = min(max(1, round(n * a / length)), max(1, n - 1))
            out += [
                dict(seg, length=a, elements=n_a),
                dict(seg, length=length - a, elements=max(1, n - n_a)),
            ]
        else:
            out.append(seg)
        s0 += length
    d["lines"][0]["segments"] = out
    return d


def sweep_settings(base: dict[str, Any], quick: bool = False) -> list[Setting]:
    """The settings swept for one example (one knob at a time, plus combinations)."""
    a = base["analysis"]
    c0 = int(a["omega"]["count"])
    tol0 = float(a["linearization"]["tolerance"])
    out = [Setting("default", "default")]
    factors = (0.25, 0.5, 2.0, 4.0) if not quick else (0.25, 0.5, 2.0)
    out += [Setting(f"elements ×{f:g}", "elements", elements=f) for f in factors]
    if not quick:
        out += [Setting(f"modes {m}", "modes", modes=m) for m in (5, 10, 20, "all")]
        out.append(Setting("direct", "solver", solver="direct"))
    counts = (50, 100, 200, 400, 800) if not quick else (50, 400)
    for wf in (1.0, 2.0):
        for c in counts:
            if wf == 1.0 and c == c0:
                continue
            out.append(
                Setting(
                    (f"{c} ω to ω_max" if wf == 1.0 else f"{c} ω to {wf:g}·ω_max"),
                    "grid",
                    count=c,
                    omega_max_factor=wf,
                )
            )
    if not quick:
        out.append(Setting("log spacing", "spacing", spacing="log"))
        out.append(
            Setting(
                f"log, {2 * c0} ω to 2·ω_max",
                "spacing",
                spacing="log",
                count=2 * c0,
                omega_max_factor=2.0,
            )
        )
    tols = (1e-2, 1e-3, 1e-4, 1e-5, 1e-6) if not quick else (1e-2, 1e-6)
    out += [
        Setting(f"tolerance {t:.0e}", "tolerance", tolerance=t)
        for t in tols
        if not math.isclose(t, tol0)
    ]
    combos = ((0.5, 400), (2.0, 400), (2.0, 800), (4.0, 800)) if not quick else ((2.0, 400),)
    for f, c in combos:
        out.append(
            Setting(
                f"×{f:g} el, {c} ω to 2·ω_max",
                "combined",
                elements=f,
                count=c,
                omega_max_factor=2.0,
            )
        )
    if not quick:
        out.append(
            Setting(
                "×4 el, direct, 800 ω to 2·ω_max, tol 1e-6",
                "combined",
                elements=4.0,
                count=800,
                omega_max_factor=2.0,
                solver="direct",
                tolerance=1e-6,
            )
        )
    return out


# --------------------------------------------------------------------- measuring


def quantities_fd(result: Any, s_star: float) -> dict[str, float]:
    """Fairlead/anchor tension σ [N] and motion σ at arc length ``s_star`` [m]."""
    line = next(iter(result.lines.values()))
    comp = [np.interp(s_star, line.s_nodes, line.motion_std[:, k]) for k in range(3)]
    return {
        "T_fairlead": float(line.end_b.std),
        "T_anchor": float(line.end_a.std),
        "motion": float(np.sqrt(np.sum(np.square(comp)))),
    }


def fd_with_residuals(doc: dict[str, Any]) -> dict[str, float]:
    """End-tension σ of ``doc``'s analysis with the closed-form drag and geometric
    residuals (σ² + both variances; NaN at an end where a residual is not computed). [N]"""
    import stochcable

    d = copy.deepcopy(doc)
    d["analysis"].setdefault("linearization", {}).update(
        drag_residual=True, geometric_residual=True
    )
    line = next(iter(stochcable.analyze(d).lines.values()))
    out = {}
    for q, e in (("T_fairlead", "end_b"), ("T_anchor", "end_a")):
        var = line.linear_end(e).std ** 2
        for rec in (line.drag_residual, line.geometric_residual):
            var = var + (rec.variance[e] if rec is not None and rec.computed else math.nan)
        out[q] = math.sqrt(var) if var >= 0 else math.nan
    return out


def quantities_td(history: Any, s_star: float) -> dict[str, float]:
    """The same three quantities from a time-domain history (after its ramp)."""
    ms = history.motion_std()
    comp = [np.interp(s_star, history.s0, ms[:, k]) for k in range(3)]
    return {
        "T_fairlead": history.tension_statistics("b")["std"],
        "T_anchor": history.tension_statistics("a")["std"],
        "motion": float(np.sqrt(np.sum(np.square(comp)))),
    }


def timed_analysis(doc: dict[str, Any], repeats: int, budget_s: float) -> tuple[Any, float, int]:
    """analyze() of ``doc``: (last result, median wall time [s], repeats done).

    Runs at least once and at most ``repeats`` times, stopping early once the calls
    have taken ``budget_s`` seconds in total.
    """
    from stochcable.analysis import analyze
    from stochcable.scene.model import load_scene

    scene = load_scene(doc)
    times: list[float] = []
    res = None
    while len(times) < repeats and (not times or sum(times) < budget_s):
        t0 = time.perf_counter()
        res = analyze(scene)
        times.append(time.perf_counter() - t0)
    return res, statistics.median(times), len(times)


@dataclass(frozen=True)
class Row:
    """One measured setting."""

    setting: Setting
    elements: int
    n_omega: int
    omega_max: float
    modes_kept: int | None
    iterations: int
    time_s: float
    repeats: int
    values: dict[str, float]
    err_ref: dict[str, float]
    err_td: dict[str, float] = field(default_factory=dict)
    failure: str | None = None


@dataclass(frozen=True)
class LadderStep:
    """One run of the reference's convergence study."""

    label: str
    elements: int
    n_omega: int
    omega_max: float
    values: dict[str, float]
    time_s: float
    used: bool  # part of the element ladder


@dataclass(frozen=True)
class Reference:
    """The converged frequency-domain reference of one scene."""

    values: dict[str, float]
    uncertainty: dict[str, float]  # relative [-]
    method: dict[str, str]  # per quantity: "Richardson (p = …)" or "finest level"
    steps: tuple[LadderStep, ...]
    omega_max: float
    count: int
    wmax_change: dict[str, float]  # relative change 2·ω_max -> 4·ω_max [-]
    count_change: dict[str, float]  # relative change half count -> count [-]


@dataclass(frozen=True)
class TDReference:
    """Nonlinear time-domain reference over several seeds."""

    elements: int
    seeds: int
    duration: float
    record: float  # per seed, after the ramp [s]
    dt: float
    band: tuple[float, float]
    per_seed: dict[str, tuple[float, ...]]
    mean: dict[str, float]
    halfwidth: dict[str, float]  # CI half-width of the mean [same unit]
    fd_same_mesh: dict[str, float]  # FD (direct, reference grid) on the TD mesh
    wall_s: float  # per seed, median
    failures: tuple[str, ...] = ()
    refined: tuple[str, ...] = ()  # seeds rerun at Δt/4 after a non-stationary record
    # the same FD's end-tension σ with the closed-form drag and geometric residuals
    # (analysis.linearization.drag_residual / geometric_residual; NaN where not computed)
    fd_residuals: dict[str, float] = field(default_factory=dict)


@dataclass(frozen=True)
class SceneStudy:
    name: str
    title: str
    default: dict[str, Any]  # the example's settings (elements, grid, …)
    s_star: float
    rows: tuple[Row, ...]
    reference: Reference
    td: TDReference | None
    td_note: str = ""


def _rel(x: float, ref: float) -> float:
    return x / ref - 1.0 if ref != 0.0 else float("nan")


def converged_reference(
    name: str,
    base: dict[str, Any],
    s_star: float,
    *,
    quick: bool = False,
    progress: Progress = _silent,
) -> Reference:
    """The converged FD reference of an example (see the module docstring)."""
    from stochcable.fidelity import static_touchdowns
    from stochcable.scene.model import load_scene

    c0 = int(base["analysis"]["omega"]["count"])
    count = (8 if not quick else 2) * c0
    factors = (1.0, 2.0, 4.0, 8.0) if not quick else (1.0, 2.0, 4.0)
    steps: list[LadderStep] = []
    s_td = static_touchdowns(load_scene(base)).get(base["lines"][0]["name"])

    def run(label: str, f: float, wf: float, c: int, used: bool) -> LadderStep:
        s = Setting(
            label,
            "reference",
            elements=f,
            omega_max_factor=wf,
            count=c,
            solver="direct",
            tolerance=REF_TOLERANCE,
        )
        doc = split_at_touchdown(scene_document(base, s), s_td)
        res, t, _ = timed_analysis(doc, 1, 0.0)
        line = next(iter(res.lines.values()))
        if not line.linearization.converged:  # pragma: no cover - reported, not hidden
            raise RuntimeError(f"{name}: reference '{label}' did not converge")
        step = LadderStep(
            label,
            int(line.s_nodes.size - 1),
            c,
            doc["analysis"]["omega"]["max"],
            quantities_fd(res, s_star),
            t,
            used,
        )
        steps.append(step)
        progress(f"  ref {label}: {t:.2f} s")
        return step

    ladder = [run(f"elements ×{f:g}", f, 2.0, count, True) for f in factors]
    half = run(f"elements ×{factors[-1]:g}, {count // 2} ω", factors[-1], 2.0, count // 2, False)
    wide = run(f"elements ×2, {2 * count} ω to 4·ω_max", 2.0, 4.0, 2 * count, False)
    values, unc, method = {}, {}, {}
    for q in QUANTITIES:
        v = [st.values[q] for st in ladder]
        d1, d2 = v[-2] - v[-3], v[-1] - v[-2]
        fine = v[-1]
        p = None
        if d1 * d2 > 0 and abs(d2) < abs(d1):
            p = math.log2(d1 / d2)
        if p is not None and 0.5 <= p <= 6.0:
            corr = d2 / (2.0**p - 1.0)
            values[q] = fine + corr
            method[q] = f"Richardson, p = {p:.2f}"
            e_el = abs(corr / values[q])
        else:
            values[q] = fine
            method[q] = (
                "finest level (last steps not monotone)"
                if p is None
                else f"finest level (observed order {p:.1f} out of range)"
            )
            e_el = abs(d2 / fine) if fine else float("nan")
        e_grid = abs(_rel(fine, half.values[q]))
        unc[q] = e_el + e_grid
    ref2 = ladder[1]  # ×2 elements at 2·ω_max, same Δω as `wide`
    return Reference(
        values=values,
        uncertainty=unc,
        method=method,
        steps=tuple(steps),
        omega_max=ladder[-1].omega_max,
        count=count,
        wmax_change={q: _rel(wide.values[q], ref2.values[q]) for q in QUANTITIES},
        count_change={q: _rel(ladder[-1].values[q], half.values[q]) for q in QUANTITIES},
    )


def td_reference(
    name: str,
    base: dict[str, Any],
    s_star: float,
    *,
    seeds: int,
    duration: float,
    mesh_factor: float,
    count: int,
    progress: Progress = _silent,
) -> TDReference:
    """Nonlinear TD statistics over ``seeds`` seeds and the FD answer on the same mesh."""
    from scipy import stats

    from stochcable.errors import ConvergenceError
    from stochcable.reference.cable import NONSTATIONARY_RATIO, simulate_line_timedomain
    from stochcable.scene.model import load_scene

    s = Setting(
        "td",
        "reference",
        elements=mesh_factor,
        omega_max_factor=2.0,
        count=count,
        solver="direct",
        tolerance=REF_TOLERANCE,
    )
    doc = scene_document(base, s)
    scene = load_scene(doc)
    om = doc["analysis"]["omega"]
    band = (float(om["min"]), float(om["max"]))
    fd, _, _ = timed_analysis(doc, 1, 0.0)
    fd_q = quantities_fd(fd, s_star)
    fd_r = fd_with_residuals(doc)
    per: dict[str, list[float]] = {q: [] for q in QUANTITIES}
    walls: list[float] = []
    failures: list[str] = []
    dt = ramp = float("nan")
    refined: list[str] = []
    for seed in range(1, seeds + 1):
        t0 = time.perf_counter()
        try:
            h = simulate_line_timedomain(scene, duration=duration, seed=seed, band=band)
            dt = h.dt  # the step of the seeds that did not diverge
            # a diverged seed (a non-stationary record: the integrator pumped an
            # under-resolved snap oscillation) is rerun with a quarter of the step
            # instead of being averaged in (tuah_1982_single_leg, 3 elements, Δt =
            # 0.125 s: seeds 3 and 6 jumped to σ ≈ 1e4 lbf against ≈ 360 lbf)
            ratio, t_jump, w_dom = h.stationarity_ratio()
            if ratio > NONSTATIONARY_RATIO:
                dt0 = h.dt
                h = simulate_line_timedomain(
                    scene, duration=duration, seed=seed, band=band, dt=dt0 / 4.0
                )
                ratio2 = h.stationarity_ratio()[0]
                note = (
                    f"seed {seed}: not stationary at Δt = {dt0:g} s (window σ ratio "
                    f"{ratio:.3g} from t = {t_jump:.0f} s, oscillation at "
                    f"{w_dom:.3g} rad/s, ωΔt = {w_dom * dt0:.2f})"
                )
                if ratio2 > NONSTATIONARY_RATIO:
                    failures.append(note + f", still at Δt = {h.dt:g} s (ratio {ratio2:.3g})")
                    progress(f"  TD seed {seed}: diverged, excluded")
                    continue
                refined.append(note + f"; rerun at Δt = {h.dt:g} s (ratio {ratio2:.3g})")
                progress(f"  TD seed {seed}: diverged, rerun at dt/4")
        except ConvergenceError as exc:
            failures.append(f"seed {seed}: {str(exc).split(';')[0]}")
            progress(f"  TD seed {seed}: failed ({exc})")
            if len(failures) >= 2 and not walls:
                break  # the model does not run: stop spending time on it
            continue
        walls.append(time.perf_counter() - t0)
        ramp = h.ramp
        for q, v in quantities_td(h, s_star).items():
            per[q].append(v)
        progress(f"  TD seed {seed}: {walls[-1]:.1f} s")
    n = len(walls)
    mean, hw = {}, {}
    for q in QUANTITIES:
        x = np.asarray(per[q])
        mean[q] = float(x.mean()) if n else float("nan")
        if n >= 2:
            hw[q] = float(stats.t.ppf(0.5 + CI_LEVEL / 2, n - 1) * x.std(ddof=1) / math.sqrt(n))
        else:
            hw[q] = float("nan")
    elements = sum(seg["elements"] for seg in doc["lines"][0]["segments"])
    return TDReference(
        elements=elements,
        seeds=n,
        duration=duration,
        record=duration - ramp,
        dt=dt,
        band=band,
        per_seed={q: tuple(v) for q, v in per.items()},
        mean=mean,
        halfwidth=hw,
        fd_same_mesh=fd_q,
        fd_residuals=fd_r,
        wall_s=statistics.median(walls) if walls else float("nan"),
        failures=tuple(failures),
        refined=tuple(refined),
    )


def study_scene(
    name: str,
    *,
    quick: bool = False,
    td: bool = True,
    td_seeds: int = 8,
    td_duration: float = 600.0,
    repeats: int | None = None,
    budget_s: float | None = None,
    settings: Sequence[Setting] | None = None,
    progress: Progress = _silent,
) -> SceneStudy:
    """Sweep the settings of one example and measure time and errors.

    Parameters
    ----------
    name : str
        Example name (:func:`stochcable.examples.list_examples`). [-]
    quick : bool
        Smaller sweep, cheaper reference (×1…×4 elements, 2× count), one repeat. [-]
    td : bool
        Also run the nonlinear time-domain reference. [-]
    td_seeds, td_duration : int, float
        Seeds and simulated length per seed of the TD reference. [-], [s]
    repeats, budget_s : int, float, optional
        Timing: at most ``repeats`` calls per setting, fewer once ``budget_s`` is
        spent (defaults 7 and 2.0 s; quick 1). [-], [s]
    settings : sequence of Setting, optional
        Overrides :func:`sweep_settings`. [-]
    progress : callable
        Receives one line of text per step. [-]

    Returns
    -------
    SceneStudy
    """
    from stochcable.examples import load_example

    warnings.simplefilter("ignore")
    repeats = repeats if repeats is not None else (1 if quick else 7)
    budget_s = budget_s if budget_s is not None else (0.0 if quick else 2.0)
    base = base_document(name)
    title = load_example(name).title
    progress(f"{name}: warm-up")
    res0, _, _ = timed_analysis(base, 1, 0.0)
    s_star = float(next(iter(res0.lines.values())).s_nodes[-2])
    ref = converged_reference(name, base, s_star, quick=quick, progress=progress)
    a = base["analysis"]
    default = {
        "elements": [seg["elements"] for seg in base["lines"][0]["segments"]],
        "omega": a["omega"],
        "solver": a["solver"],
        "modes": a["modes"],
        "tolerance": a["linearization"]["tolerance"],
    }
    rows: list[Row] = []
    for s in settings if settings is not None else sweep_settings(base, quick):
        doc = scene_document(base, s)
        n_el = sum(seg["elements"] for seg in doc["lines"][0]["segments"])
        n_om = int(doc["analysis"]["omega"]["count"])
        w_max = float(doc["analysis"]["omega"]["max"])
        try:
            res, t, n = timed_analysis(doc, repeats, budget_s)
        except Exception as exc:  # a failing setting is a result, not a crash
            rows.append(
                Row(
                    s,
                    n_el,
                    n_om,
                    w_max,
                    None,
                    0,
                    float("nan"),
                    0,
                    {q: float("nan") for q in QUANTITIES},
                    {q: float("nan") for q in QUANTITIES},
                    failure=f"{type(exc).__name__}: {str(exc)[:160]}",
                )
            )
            progress(f"  {s.label}: FAILED {exc}")
            continue
        line = next(iter(res.lines.values()))
        vals = quantities_fd(res, s_star)
        rows.append(
            Row(
                s,
                n_el,
                n_om,
                w_max,
                line.n_modes,
                int(line.linearization.iterations),
                t,
                n,
                vals,
                {q: _rel(vals[q], ref.values[q]) for q in QUANTITIES},
            )
        )
        progress(f"  {s.label}: {1e3 * t:.1f} ms, err T_b {rows[-1].err_ref['T_fairlead']:+.2e}")
    tdr = None
    note = ""
    if td:
        progress(f"{name}: time-domain reference")
        tdr = td_reference(
            name,
            base,
            s_star,
            seeds=td_seeds,
            duration=td_duration,
            mesh_factor=TD_MESH.get(name, 1.0),
            count=ref.count,
            progress=progress,
        )
        if tdr.seeds:
            rows = [
                replace(r, err_td={q: _rel(r.values[q], tdr.mean[q]) for q in QUANTITIES})
                for r in rows
            ]
    else:
        note = "time-domain reference not run for this scene"
    return SceneStudy(name, title, default, s_star, tuple(rows), ref, tdr, note)


@dataclass(frozen=True)
class Study:
    scenes: tuple[SceneStudy, ...]
    quick: bool
    wall_s: float
    load_before: tuple[float, float, float]
    load_after: tuple[float, float, float]
    fidelity: tuple[Any, ...] = ()  # adaptive_fidelity.FidelityRow per plan


def run_study(
    scenes: Sequence[str] = SCENES,
    *,
    quick: bool = False,
    td_scenes: Sequence[str] | None = None,
    td_seeds: int | None = None,
    td_duration: float | None = None,
    fidelity: bool = False,
    progress: Progress = _silent,
) -> Study:
    """Run :func:`study_scene` for every scene (the TD reference for ``td_scenes``) and,
    with ``fidelity``, the adaptive-fidelity plans of ``benchmarks/adaptive_fidelity.py``
    (its section of the report)."""
    if td_scenes is None:
        td_scenes = ("taut_wire", "chain_catenary") if quick else TD_DEFAULT_SCENES
    td_seeds = td_seeds if td_seeds is not None else (2 if quick else 8)
    td_duration = td_duration if td_duration is not None else (300.0 if quick else 600.0)
    load0 = os.getloadavg()
    t0 = time.perf_counter()
    out = [
        study_scene(
            n,
            quick=quick,
            td=n in td_scenes,
            td_seeds=td_seeds,
            td_duration=td_duration,
            progress=progress,
        )
        for n in scenes
    ]
    rows: tuple[Any, ...] = ()
    if fidelity:
        sys.path.insert(0, str(Path(__file__).resolve().parent))
        from adaptive_fidelity import study_fidelity

        rows = tuple(study_fidelity(scenes, progress))
    return Study(tuple(out), quick, time.perf_counter() - t0, load0, os.getloadavg(), rows)


# ----------------------------------------------------------------------- report


def pareto_front(times: Sequence[float], errors: Sequence[float]) -> list[int]:
    """Indices of the non-dominated points (less time and less error), by time."""
    pts = [
        (t, e, i)
        for i, (t, e) in enumerate(zip(times, errors))
        if np.isfinite(t) and np.isfinite(e)
    ]
    pts.sort(key=lambda p: (p[0], p[1]))
    front, best = [], math.inf
    for _t, e, i in pts:
        if e < best:
            front.append(i)
            best = e
    return front


_FLOOR = 1e-7  # |error| shown at this value on log axes when it is smaller


def _plot_scene(sc: SceneStudy, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    rows = [r for r in sc.rows if r.failure is None]
    groups = sorted({r.setting.group for r in rows}, key=lambda g: (g != "default", g))
    colors = dict(zip(groups, plt.rcParams["axes.prop_cycle"].by_key()["color"] * 2))
    n_rows = 2 if sc.td is not None and sc.td.seeds else 1
    fig, axes = plt.subplots(n_rows, 3, figsize=(15, 4.6 * n_rows), squeeze=False)
    for j, kind in enumerate(("ref", "td")[:n_rows]):
        for k, q in enumerate(QUANTITIES):
            ax = axes[j, k]
            t = [1e3 * r.time_s for r in rows]
            e = [max(abs((r.err_ref if kind == "ref" else r.err_td)[q]), _FLOOR) for r in rows]
            for g in groups:
                if g == "default":
                    continue
                idx = [i for i, r in enumerate(rows) if r.setting.group == g]
                ax.scatter(
                    [t[i] for i in idx],
                    [e[i] for i in idx],
                    s=22,
                    color=colors[g],
                    label=g,
                    zorder=3,
                )
            front = pareto_front(t, e)
            ft = [t[i] for i in front] + [max(t)]
            fe = [e[i] for i in front] + [e[front[-1]]]
            ax.step(
                ft, fe, where="post", color="k", lw=1, alpha=0.7, label="Pareto front", zorder=2
            )
            d = next(i for i, r in enumerate(rows) if r.setting.group == "default")
            ax.scatter(
                [t[d]],
                [e[d]],
                s=180,
                marker="*",
                color="red",
                edgecolor="k",
                label="default (example)",
                zorder=4,
            )
            if kind == "ref":
                u = sc.reference.uncertainty[q]
                ax.axhline(
                    max(u, _FLOOR), color="grey", ls="--", lw=1, label="reference uncertainty"
                )
                ax.set_title(f"{QUANTITY_TEXT[q]}\nvs converged FD reference", fontsize=9)
            else:
                hw = sc.td.halfwidth[q] / sc.td.mean[q]
                ax.axhline(
                    hw,
                    color="grey",
                    ls=":",
                    lw=1.5,
                    label=f"TD {int(CI_LEVEL * 100)} % CI half-width",
                )
                ax.set_title(
                    f"{QUANTITY_TEXT[q]}\nvs nonlinear TD ({sc.td.seeds} seeds)", fontsize=9
                )
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
            ax.yaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
            ax.set_xlabel("analyze() wall time, median [ms]")
            ax.set_ylabel("|relative error of σ|")
            ax.grid(True, which="both", alpha=0.3)
            if k == 0:
                ax.legend(fontsize=7, loc="best")
    fig.suptitle(f"{sc.name}: error versus time", fontsize=11)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=90)
    plt.close(fig)


def _g(x: float, digits: int = 4) -> str:
    if x is None or not np.isfinite(x):
        return "—"
    return f"{x:.{digits}g}"


def _pct(x: float) -> str:
    if x is None or not np.isfinite(x):
        return "—"
    a = abs(x)
    if a >= 0.01:
        return f"{100 * x:+.1f} %"
    if a >= 1e-4:
        return f"{100 * x:+.3f} %"
    return f"{x:+.1e}"


def cheapest(
    rows: Sequence[Row], quantities: Sequence[str], target: float, kind: str = "ref"
) -> Row | None:
    """The fastest row whose |error| on every one of ``quantities`` is <= ``target``."""

    def ok_(r: Row) -> bool:
        err = r.err_ref if kind == "ref" else r.err_td
        return all(abs(err.get(q, math.nan)) <= target for q in quantities)

    ok = [r for r in rows if r.failure is None and ok_(r)]
    return min(ok, key=lambda r: r.time_s) if ok else None


SCENE_NOTES = {
    "taut_wire": (
        "The fairlead tension σ is a fraction of a newton on a 1.3 MN mean, the small "
        "difference of the tension the normal wave loads and the axial drag give: the drag "
        "the linearization drops accounts for FD/TD < 1 on the tension — with the "
        "closed-form drag residual (analysis.linearization.drag_residual) the ratio is "
        "1.016 ± 0.029 (docs/benchmarks/drag_residual.md); the second-order stretch "
        "(indicators.second_order) is 1e-7 of it."
    ),
    "chain_catenary": (
        "The fairlead surge is a Pierson–Moskowitz spectrum (Hs 2 m, Tp 10 s) tapered to "
        "0.35–1.5 rad/s, as a vessel's RAO would cut it (an untapered ω⁻⁵ tail drives "
        "inertia tension whose spectrum decays like ω⁻¹ only). The element that contains "
        "the static touchdown is split there and condensed "
        "(stochcable.line.seabed.bed_contact), so the suspended span ends at the touchdown "
        "whatever the mesh and the element ladder converges monotonically; the reference "
        "ladder also puts a node at the touchdown (a second discretization)."
    ),
    "inclined_guy": (
        "end_b is at the still-water level (z = 0). Wave kinematics are evaluated at the "
        "nodes and distributed over the elements, so the top element (14 m tall at 40 "
        "elements) spreads the surface kinematics over a depth far larger than their decay "
        "length 1/k (2.5 m at 2 rad/s). Checked while writing this script: the end_b "
        "tension variance above 2 rad/s falls from 2.2e4 to 2.5e3 to 77 N² at 40/80/160 "
        "elements and the 1–2 rad/s band changes by ×5. Elements in the splash zone should "
        "be shorter than about g/ω_max²; the example's 40 elements are far too coarse."
        " With the closed-form drag residual (analysis.linearization.drag_residual, which "
        "splits the top elements) (FD + residuals) / TD is 0.994 ± 0.037 at the fairlead "
        "on the example's mesh (docs/benchmarks/drag_residual.md)."
    ),
    "tuah_1982_single_leg": (
        "The buoy is not modelled (no bodies yet): end_b heaves with the sea surface (RAO "
        "1). The line goes nearly slack in the TD (minimum tension ≈ 0), which the linear "
        "FD cannot represent. The TD Newton iteration fails on refined meshes (6 and 12 "
        "elements, even with Δt/4) at the first slack–taut snaps, so the TD runs on the "
        "example's 3-element mesh: 'FD same mesh / TD' is the linearization error there, "
        "while 'FD reference / TD' mixes it with the 3-element mesh error of the TD. On "
        "that mesh the automatic step (Δt = 0.125 s) lets the average-acceleration scheme "
        "pump an axial rattle of the two inner nodes at the slack–taut switches (18.9 "
        "rad/s, ωΔt = 2.4) in some seeds: the record jumps to a persistent tension σ ≈ "
        "1e4 lbf; such records are detected (window σ ratio above "
        "stochcable.reference.cable.NONSTATIONARY_RATIO) and rerun at Δt/4 (listed "
        "below). The closed-form residuals assume a line that stays taut (a Gaussian "
        "response about the static state); here they add to the overestimate "
        "((FD + residuals)/TD 1.68 in the summary): a line that goes slack needs the time "
        "domain, and the analysis's snap indicator says so."
    ),
}


def _reading(sc: SceneStudy) -> list[str]:
    rows = [r for r in sc.rows if r.failure is None]
    d = next(r for r in rows if r.setting.group == "default")
    out = [
        f"- Default (the example's settings): {1e3 * d.time_s:.0f} ms; error vs the "
        f"converged FD reference: fairlead {_pct(d.err_ref['T_fairlead'])}, anchor "
        f"{_pct(d.err_ref['T_anchor'])}, motion {_pct(d.err_ref['motion'])}."
    ]
    for qs, what in ((("T_fairlead",), "fairlead tension σ"), (QUANTITIES, "all three quantities")):
        found: dict[float, Row | None] = {t: cheapest(rows, qs, t) for t in (0.01, 0.05)}
        for target in (0.01, 0.05):
            r = found[target]
            if target == 0.05 and r is found[0.01]:
                continue  # the 1 % answer already holds for 5 %
            if r is None:
                out.append(
                    f"- {100 * target:g} % on {what}: no swept setting reaches it "
                    "(only the reference ladder does, see below)."
                )
                continue
            worst = max(abs(r.err_ref[q]) for q in QUANTITIES)
            out.append(
                f"- To get {100 * target:g} % on {what} you need "
                f"**{r.setting.label}** ({r.elements} elements, {r.n_omega} ω to "
                f"{_g(r.omega_max)} rad/s); it costs {1e3 * r.time_s:.0f} ms "
                f"({r.time_s / d.time_s:.1f}× the default)"
                + (
                    f"; worst error of the three quantities there {_pct(worst)}."
                    if len(qs) == 1
                    else "."
                )
            )
    u = sc.reference.uncertainty["T_fairlead"]
    if u > 0.005:
        out.append(
            f"- The reference itself is known to ±{_pct(u).lstrip('+')} on the fairlead "
            "tension σ only: smaller errors in the table are not resolved."
        )
    el = [st for st in sc.reference.steps if st.used]
    for q in ("T_fairlead",):
        v = np.array([st.values[q] for st in el])
        dv = np.diff(v)
        if dv.size >= 2 and np.any(dv[:-1] * dv[1:] < 0):
            out.append(
                f"- Element convergence of the {QUANTITY_TEXT[q]} is **not monotone** "
                "(successive refinements change sign: "
                + ", ".join(f"{st.elements} el {_g(st.values[q], 6)}" for st in el)
                + "); an error estimate from two meshes can be misleading here."
            )
    wm = sc.reference.wmax_change["T_fairlead"]
    if abs(wm) > 0.01:
        out.append(
            f"- Raising ω_max from 2× to 4× the example's still changes the "
            f"fairlead tension σ by {_pct(wm)}: the σ of this band-limited quantity "
            "depends on the band; the reference is defined for "
            f"[ω_min, {_g(sc.reference.omega_max)}] rad/s."
        )
    if sc.td is not None and sc.td.seeds:
        r_ = sc.td.fd_same_mesh["T_fairlead"] / sc.td.mean["T_fairlead"]
        out.append(
            f"- Linearization: FD/TD for the fairlead tension σ = {r_:.3f} "
            f"({_ratio_ci(sc.td, 'T_fairlead')}); errors of a setting smaller than "
            "this are below what the linear method can promise against the "
            "nonlinear model."
        )
    return out


def _ratio_ci(td: TDReference, q: str) -> str:
    m, hw, fd = td.mean[q], td.halfwidth[q], td.fd_same_mesh[q]
    if not np.isfinite(hw) or hw >= m:
        return "CI —"
    return f"{int(CI_LEVEL * 100)} % CI {fd / (m + hw):.3f}–{fd / (m - hw):.3f}"


def _residual_ratio(td: TDReference, q: str) -> str:
    """(FD + residuals)/TD with its interval, or why there is none."""
    fd, m, hw = td.fd_residuals.get(q, math.nan), td.mean[q], td.halfwidth[q]
    if not math.isfinite(fd):
        return "not computed"
    if not np.isfinite(hw) or hw >= m:
        return f"{fd / m:.3f} (CI —)"
    return f"{fd / m:.3f} ({int(CI_LEVEL * 100)} % CI {fd / (m + hw):.3f}–{fd / (m - hw):.3f})"


def render_markdown(study: Study, plot_dir_rel: str = "accuracy") -> str:
    """The report text (Markdown)."""
    import numpy as _np
    import scipy as _sp

    import stochcable

    L: list[str] = []
    L.append("# Speed versus accuracy of the frequency-domain analysis")
    L.append("")
    L.append(
        "Generated by `python benchmarks/speed_vs_error.py"
        + (" --quick" if study.quick else " --write")
        + "`. Do not edit by "
        "hand: re-run the script."
    )
    L.append("")
    L.append(LINES_LINK)
    L.append("")
    L.append(
        f"Machine: {platform.machine()}, {os.cpu_count()} cores, Python "
        f"{platform.python_version()}, numpy {_np.__version__}, scipy {_sp.__version__}, "
        f"stochcable {getattr(stochcable, '__version__', '?')}. "
        f"Load average (1, 5, 15 min) before the run "
        f"{', '.join(f'{x:.2f}' for x in study.load_before)}, after "
        f"{', '.join(f'{x:.2f}' for x in study.load_after)} (a shared 2-core "
        f"VM whose speed varies; times are medians and vary by ±30 % between runs). "
        f"Whole run {study.wall_s:.0f} s."
    )
    L.append("")
    L.append("## What is measured and how")
    L.append("")
    L.append("""- **Scenes** (`stochcable/examples`): `taut_wire`, `chain_catenary` (seabed contact,
  fairlead surge + sea), `inclined_guy` (Bliet 1984), and the buoy mooring
  `tuah_1982_single_leg` — the buoy is **not** a body here: it is the line's end_b,
  heaving with the sea surface (RAO 1), a prescribed moving end.
- **Settings** (one knob at a time from the example's settings, plus combinations):
  elements per segment ×0.25 … ×4; kept Foss modes auto / 5 / 10 / 20 / all; frequency
  count 50 … 800 at the example's ω_max and at 2·ω_max; linear/log spacing;
  linearization tolerance 1e-2 … 1e-6; direct versus Foss.
- **Time**: wall time of `analyze(scene)` (statics, model, modes, linearization, outputs;
  no time series), median of up to 7 calls (fewer once 2 s is spent), after a warm-up
  call of the scene.
- **Quantities**: σ of the fairlead (end_b) and anchor (end_a) effective tension, and σ of
  the total motion |(σ_x, σ_y, σ_z)| at the arc length of the example mesh's node next to
  the fairlead (linearly interpolated between nodes for other meshes, so every mesh is
  compared at the same material point).
- **(a) Converged FD reference**: direct solve, linearization tolerance 1e-8, frequency
  grid [ω_min, 2·ω_max] with 8× the example's count (a quarter of its Δω; 2× in --quick), element
  ladder ×1, ×2, ×4, ×8 (×4 in --quick). When the last three levels converge
  monotonically with an observed order p in [0.5, 6], the value is Richardson-extrapolated
  (σ* = σ_8 + (σ_8 − σ_4)/(2^p − 1)); otherwise the finest level is taken. Its stated
  uncertainty = the Richardson correction (or the last element step when not monotone) +
  the change from half the count to the full count on the finest mesh. The change from
  2·ω_max to 4·ω_max (same Δω, ×2 mesh) is shown separately: the reference is defined for
  the band [ω_min, 2·ω_max].
- **(b) Nonlinear time-domain reference**: `simulate_line_timedomain` (Newmark average
  acceleration with Newton, geometrically exact elements, quadratic Morison drag,
  one-sided seabed) on a refined mesh (column "TD mesh"), excitation band
  [ω_min, 2·ω_max] (the reference band), DSA realizations with seeds 1…n, each record
  after its half-cosine ramp. σ_TD is the mean over seeds with a 95 % Student-t
  confidence interval from the seed-to-seed scatter; "FD/TD" uses the FD answer
  (direct, reference grid) on the **same mesh** as the TD, so it isolates the
  linearization (drag and geometry) error; its interval is FD/(σ̄_TD ± half-width).
  "(FD + residuals)/TD" is the same FD with the closed-form drag and geometric
  residuals of the linear model added to its variance
  (`analysis.linearization.drag_residual`, `geometric_residual`;
  docs/benchmarks/drag_residual.md).
- Errors are signed relative errors σ/σ_ref − 1; the plots show their magnitude
  (values below 1e-7 are drawn at 1e-7).""")
    L.append("")
    L.append("## Summary")
    L.append("")
    L.append(
        "| scene | default time | same with solver direct "
        "| default error (fairlead / anchor / motion) | cheapest ≤ 1 % fairlead | its time "
        "| FD/TD fairlead (95 % CI) | (FD + residuals)/TD fairlead (95 % CI) |"
    )
    L.append("|---|---|---|---|---|---|---|---|")
    for sc in study.scenes:
        rows = [r for r in sc.rows if r.failure is None]
        d = next(r for r in rows if r.setting.group == "default")
        c = cheapest(rows, ("T_fairlead",), 0.01)
        td = td_res = "not run"
        if sc.td is not None and sc.td.seeds:
            td = (
                f"{sc.td.fd_same_mesh['T_fairlead'] / sc.td.mean['T_fairlead']:.3f} "
                f"({_ratio_ci(sc.td, 'T_fairlead')})"
            )
            td_res = _residual_ratio(sc.td, "T_fairlead")
        elif sc.td is not None:
            td = td_res = "TD failed"
        dr = next((r for r in rows if r.setting.label == "direct"), None)
        L.append(
            f"| {sc.name} | {1e3 * d.time_s:.0f} ms | "
            f"{f'{1e3 * dr.time_s:.0f} ms' if dr else '—'} | {_pct(d.err_ref['T_fairlead'])} / "
            f"{_pct(d.err_ref['T_anchor'])} / {_pct(d.err_ref['motion'])} | "
            f"{c.setting.label if c else 'none swept'} | "
            f"{f'{1e3 * c.time_s:.0f} ms' if c else '—'} | {td} | {td_res} |"
        )
    L.append("")
    for sc in study.scenes:
        L += _scene_section(sc, plot_dir_rel)
    if study.fidelity:
        sys.path.insert(0, str(Path(__file__).resolve().parent))
        from adaptive_fidelity import render_section

        L += render_section(list(study.fidelity))
    return "\n".join(L) + "\n"


def _scene_section(sc: SceneStudy, plot_dir_rel: str) -> list[str]:
    ref = sc.reference
    om = sc.default["omega"]
    L = [f"## {sc.name}", "", f"*{sc.title}*", ""]
    L.append(
        f"Example settings (the default): elements {sc.default['elements']}, "
        f"{om['count']} ω on [{_g(om['min'])}, {_g(om['max'])}] rad/s ({om['spacing']}), "
        f"solver {sc.default['solver']}, modes {sc.default['modes']}, tolerance "
        f"{sc.default['tolerance']:g}. Motion point: s = {_g(sc.s_star, 6)} (unstretched "
        "arc length from end_a, scene units)."
    )
    L.append("")
    L.append(f"![error versus time, {sc.name}]({plot_dir_rel}/{sc.name}.png)")
    L.append("")
    L.append("### Reading")
    L.append("")
    L += _reading(sc)
    if sc.name in SCENE_NOTES:
        L += ["", "Note: " + SCENE_NOTES[sc.name]]
    L.append("")
    L.append("### Converged reference")
    L.append("")
    L.append("| run | elements | ω count | ω_max | fairlead σ | anchor σ | motion σ | time |")
    L.append("|---|---|---|---|---|---|---|---|")
    for st in ref.steps:
        L.append(
            f"| {st.label} | {st.elements} | {st.n_omega} | {_g(st.omega_max)} | "
            f"{_g(st.values['T_fairlead'], 7)} | {_g(st.values['T_anchor'], 7)} | "
            f"{_g(st.values['motion'], 7)} | {st.time_s:.2f} s |"
        )
    L.append(
        f"| **reference** | | {ref.count} | {_g(ref.omega_max)} | "
        f"**{_g(ref.values['T_fairlead'], 7)}** | **{_g(ref.values['T_anchor'], 7)}** | "
        f"**{_g(ref.values['motion'], 7)}** | |"
    )
    L.append("")
    L.append("| quantity | how | uncertainty | half count → count | 2·ω_max → 4·ω_max |")
    L.append("|---|---|---|---|---|")
    for q in QUANTITIES:
        L.append(
            f"| {QUANTITY_TEXT[q]} | {ref.method[q]} | {_pct(ref.uncertainty[q])} | "
            f"{_pct(ref.count_change[q])} | {_pct(ref.wmax_change[q])} |"
        )
    L.append("")
    if sc.td is not None:
        td = sc.td
        L.append("### Nonlinear time-domain reference")
        L.append("")
        if td.seeds:
            L.append(
                f"TD mesh {td.elements} elements, {td.seeds} seeds × {td.duration:g} s "
                f"(record {td.record:.0f} s after the ramp), Δt = {td.dt:.4g} s, band "
                f"[{_g(td.band[0])}, {_g(td.band[1])}] rad/s, {td.wall_s:.1f} s wall "
                "per seed (median)."
            )
            L.append("")
            L.append(
                "| quantity | σ_TD mean | 95 % CI | FD same mesh | FD/TD (95 % CI) "
                "| FD reference / TD |"
            )
            L.append("|---|---|---|---|---|---|")
            for q in QUANTITIES:
                m, hw = td.mean[q], td.halfwidth[q]
                L.append(
                    f"| {QUANTITY_TEXT[q]} | {_g(m, 5)} | {_g(m - hw, 5)} – {_g(m + hw, 5)} "
                    f"(±{_g(100 * hw / m, 2)} %) | {_g(td.fd_same_mesh[q], 5)} | "
                    f"{td.fd_same_mesh[q] / m:.3f} ({_ratio_ci(td, q)}) | "
                    f"{ref.values[q] / m:.3f} |"
                )
        else:
            L.append("The time-domain reference did not run: " + "; ".join(td.failures))
        if td.failures and td.seeds:
            L.append("")
            L.append("Failed seeds (excluded): " + "; ".join(td.failures))
        if td.refined:
            L.append("")
            L.append(
                "Diverged seeds rerun with a quarter of the step (the rerun is "
                "averaged in, not the diverged record): " + "; ".join(td.refined)
            )
        L.append("")
    elif sc.td_note:
        L += [f"*{sc.td_note}.*", ""]
    L.append("### All settings")
    L.append("")
    has_td = sc.td is not None and sc.td.seeds > 0
    head = (
        "| setting | elements | ω count to ω_max | modes kept | it. | time ms (n) | fairlead σ | "
        "err ref: fairlead | anchor | motion |"
    )
    sep = "|---|---|---|---|---|---|---|---|---|---|"
    if has_td:
        head += " err TD: fairlead | anchor | motion |"
        sep += "---|---|---|"
    L += [head, sep]
    for r in sc.rows:
        if r.failure is not None:
            L.append(
                f"| {r.setting.label} | {r.elements} | {r.n_omega} | failed: "
                f"{r.failure.replace('|', '/')} |"
            )
            continue
        mk = "**" if r.setting.group == "default" else ""
        line = (
            f"| {mk}{r.setting.label}{mk} | {r.elements} | {r.n_omega} to {_g(r.omega_max)} | "
            f"{r.modes_kept if r.modes_kept is not None else 'direct'} | {r.iterations} | "
            f"{1e3 * r.time_s:.1f} ({r.repeats}) | {_g(r.values['T_fairlead'], 6)} | "
            f"{_pct(r.err_ref['T_fairlead'])} | {_pct(r.err_ref['T_anchor'])} | "
            f"{_pct(r.err_ref['motion'])} |"
        )
        if has_td:
            line += (
                f" {_pct(r.err_td['T_fairlead'])} | {_pct(r.err_td['T_anchor'])} | "
                f"{_pct(r.err_td['motion'])} |"
            )
        L.append(line)
    L.append("")
    return L


def write_report(study: Study, out: Path) -> list[Path]:
    """Write the Markdown report to ``out`` and the plots to ``out.parent/accuracy``."""
    out = Path(out)
    plot_dir = out.parent / "accuracy"
    paths = []
    for sc in study.scenes:
        p = plot_dir / f"{sc.name}.png"
        _plot_scene(sc, p)
        paths.append(p)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(render_markdown(study, "accuracy"), encoding="utf-8")
    return [out] + paths


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--quick",
        action="store_true",
        help="smaller sweep, cheaper references, TD on taut_wire and chain_catenary (~1 min)",
    )
    ap.add_argument(
        "--write",
        action="store_true",
        help="write docs/ACCURACY.md and its plots (never with --quick)",
    )
    ap.add_argument(
        "--out",
        type=Path,
        default=None,
        help="write the Markdown report here instead (plots go to <dir>/accuracy/)",
    )
    ap.add_argument("--scenes", nargs="+", default=list(SCENES), choices=list(SCENES))
    ap.add_argument(
        "--td-scenes",
        nargs="*",
        default=None,
        help="time-domain reference scenes (default: all; quick: taut_wire chain_catenary)",
    )
    ap.add_argument(
        "--no-fidelity",
        action="store_true",
        help="leave out the adaptive-fidelity section (benchmarks/adaptive_fidelity.py; "
        "run by default except with --quick)",
    )
    ap.add_argument("--td-seeds", type=int, default=None)
    ap.add_argument("--td-duration", type=float, default=None)
    args = ap.parse_args(argv)

    def progress(msg: str) -> None:
        sys.stderr.write(msg + "\n")
        sys.stderr.flush()

    study = run_study(
        args.scenes,
        quick=args.quick,
        td_scenes=args.td_scenes,
        td_seeds=args.td_seeds,
        td_duration=args.td_duration,
        fidelity=not (args.quick or args.no_fidelity),
        progress=progress,
    )
    out = args.out
    if out is None and args.write and not args.quick:
        out = Path(__file__).resolve().parents[1] / "docs" / "ACCURACY.md"
    if out is None:  # the committed docs are written only when asked (--write)
        sys.stdout.write(render_markdown(study, "accuracy"))
    else:
        for p in write_report(study, out):
            progress(f"wrote {p}")
    progress(f"total {study.wall_s:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
