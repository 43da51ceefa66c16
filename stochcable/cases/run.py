"""Running a load-case set: one engine per scene, one solve per sea state, fatigue
damage and extremes per case, and the totals over the scatter diagram.

The sea-independent work — statics (with current), the finite-element models, modes,
factorizations and drag-independent arrays — is built once
(:func:`stochcable.dynamics.engine.build_engine`) and shared by every sea state; each
case is ``engine.solve(sea)``, which equals ``analyze`` of the scene with that sea.  A
case that fails or does not converge is a row with its status and reason, never a lost
set.
"""

from __future__ import annotations

import math
import traceback
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from stochcable.cases.fatigue_settings import LineFatigue, curve_factor
from stochcable.cases.scatter import ScatterDiagram
from stochcable.design import SECONDS_PER_YEAR, damage_rate, return_level
from stochcable.dynamics.engine import Engine, build_engine
from stochcable.errors import InputError, StochcableError, collect_warnings
from stochcable.scene.model import Scene, Sea, load_scene

__all__ = ["CaseRow", "LineTotals", "CaseSetResult", "run_cases", "ENDS"]

ENDS = ("end_a", "end_b")
#: Spectra kept at once before their damage is computed (memory bound of a set). [bytes]
_DAMAGE_BUFFER_BYTES = 64 * 2**20

Progress = Callable[[int, int], None]


@dataclass(frozen=True)
class CaseRow:
    """One sea state of the set and its outcome.

    Attributes
    ----------
    index : int
        Position in the scatter diagram.
    status : {"ok", "flagged", "not_converged", "failed"}
        ``flagged``: an indicator of a line raised a flag (listed in ``flags``).
    reason : str
        Why the case is not ``ok`` ("" otherwise).
    flags : tuple of str
        ``"<line>:<flag>"`` of every raised indicator flag.
    warnings : tuple of str
        Messages of the warnings of this case's solve.
    """

    index: int
    status: str
    reason: str = ""
    flags: tuple[str, ...] = ()
    warnings: tuple[str, ...] = ()

    @property
    def has_numbers(self) -> bool:
        """Whether the case produced a response (every status but ``failed``)."""
        return self.status != "failed"


@dataclass(frozen=True)
class LineTotals:
    """Totals of one line over the set, per end (``end_a``, ``end_b``) where keyed.

    Attributes
    ----------
    annual_damage : dict of float, and ``along`` ndarray (n_el,)
        Probability-weighted damage per year (365.25 days). [1/year]
    fatigue_life : dict of float, and ``along`` ndarray (n_el,)
        1/(DFF · annual damage). [years]
    return_level : dict of float
        The ``years``-year most probable maximum tension. [force unit]
    governing_mpm_case, governing_damage_case : dict of int
        Index of the case with the largest 3-h MPM, and with the largest contribution
        p·D to the damage.
    """

    annual_damage: dict[str, Any]
    fatigue_life: dict[str, Any]
    return_level: dict[str, float]
    governing_mpm_case: dict[str, int]
    governing_damage_case: dict[str, int]


@dataclass(frozen=True)
class CaseSetResult:
    """Results of a load-case set (:func:`run_cases`).

    Attributes
    ----------
    scatter : ScatterDiagram
    rows : tuple of CaseRow
    lines : tuple of str
        Line names, in scene order.
    s_elements : dict of ndarray
        Element midpoint arc length per line. [m]
    stats : dict of ndarray
        ``stats[line][end]`` shape (n_case, 4): mean, σ, Tz, 3-h MPM of the end tension
        (NaN for failed cases). [force unit, force unit, s, force unit]
    damage_rate_ends : dict of ndarray
        ``[line]`` shape (n_case, 2): damage rate at end_a, end_b (NaN: failed or no
        fatigue settings). [1/s]
    damage_rate_along : dict of ndarray
        ``[line]`` shape (n_case, n_el): damage rate of every element. [1/s]
    totals : dict of LineTotals
        Per line with fatigue settings (extremes for every line).
    coverage : dict of float
        Probability of the ``ok`` cases, of every case with a response, and of the
        failed cases. [-]
    years : float
        Return period of ``return_level``. [years]
    fatigue : dict of LineFatigue
        The settings used, per line.
    """

    scatter: ScatterDiagram
    rows: tuple[CaseRow, ...]
    lines: tuple[str, ...]
    s_elements: dict[str, np.ndarray]
    stats: dict[str, dict[str, np.ndarray]]
    damage_rate_ends: dict[str, np.ndarray]
    damage_rate_along: dict[str, np.ndarray]
    totals: dict[str, LineTotals]
    coverage: dict[str, float]
    years: float
    fatigue: dict[str, LineFatigue] = field(default_factory=dict)

    @property
    def probabilities(self) -> np.ndarray:
        """Probability of every case. [-]"""
        return np.array([s.probability for s in self.scatter.states])


def _fatigue_settings(
    scene: Scene, fatigue: LineFatigue | Mapping[str, LineFatigue] | None
) -> dict[str, LineFatigue]:
    names = [ln.name for ln in scene.lines]
    if fatigue is None:
        return {}
    if isinstance(fatigue, LineFatigue):
        return dict.fromkeys(names, fatigue)
    unknown = sorted(set(fatigue) - set(names))
    if unknown:
        raise InputError("fatigue", unknown[0], "-", f"names no line of the scene ({names})")
    return dict(fatigue)


def _template(scene: Scene, scatter: ScatterDiagram) -> Scene:
    """The scene the engine is built from: no time series, and the sea of an
    out-of-plane state when the diagram has one (the models are then 3-D, and in-plane
    states are solved by them exactly as by 2-D models)."""
    upd: dict[str, Any] = {
        "analysis": scene.analysis.model_copy(update={"timeseries": None}),
    }
    for state in scatter.states:
        if abs(math.sin(math.radians(state.heading))) > 1e-9:
            upd["sea"] = Sea(spectrum=state.spectrum(scatter.family), heading=state.heading)
            break
    return scene.model_copy(update=upd)


class _DamageBuffer:
    """Spectra of the cases of one line, turned into damage rates in batches."""

    def __init__(self, omega: np.ndarray, curve: Any, k: float, method: str, out: np.ndarray):
        self.omega, self.curve, self.k2, self.method, self.out = omega, curve, k * k, method, out
        self.idx: list[int] = []
        self.spectra: list[np.ndarray] = []

    def add(self, case: int, spectra: np.ndarray) -> None:
        self.idx.append(case)
        self.spectra.append(spectra)
        if len(self.spectra) * spectra.nbytes >= _DAMAGE_BUFFER_BYTES:
            self.flush()

    def flush(self) -> None:
        if self.spectra:
            dens = np.stack(self.spectra) * self.k2
            self.out[self.idx] = damage_rate(self.omega, dens, self.curve, method=self.method)
            self.idx, self.spectra = [], []


def _solve_case(engine: Engine, sea: Sea, index: int) -> tuple[CaseRow, Any]:
    with collect_warnings() as caught:
        try:
            res = engine.solve(sea)
        except StochcableError as exc:
            return CaseRow(index, "failed", f"{type(exc).__name__}: {exc}"), None
        except Exception as exc:  # a defect must cost its case only, with its trace
            tb = traceback.format_exception_only(type(exc), exc)[-1].strip()
            return CaseRow(index, "failed", f"internal error: {tb}"), None
    msgs = tuple(dict.fromkeys(str(w) for w in caught))
    flags = tuple(
        f"{name}:{f}"
        for name, lr in res.lines.items()
        if lr.indicators is not None
        for f in lr.indicators.flags
    )
    if not res.converged:
        lin = res.linearization
        reason = (
            f"drag linearization not converged after {lin['iterations']} iterations "
            f"(relative change {lin['relative_change']:.3g})"
        )
        return CaseRow(index, "not_converged", reason, flags, msgs), res
    if flags:
        return CaseRow(index, "flagged", "indicator flags: " + ", ".join(flags), flags, msgs), res
    return CaseRow(index, "ok", "", (), msgs), res


def run_cases(
    scene: Scene | Mapping[str, Any] | str,
    scatter: ScatterDiagram,
    *,
    fatigue: LineFatigue | Mapping[str, LineFatigue] | None = None,
    years: float = 100.0,
    progress: Progress | None = None,
    engine: Engine | None = None,
) -> CaseSetResult:
    """Solve every sea state of a scatter diagram on one scene.

    Parameters
    ----------
    scene : Scene, mapping or path
        The scene template; its sea is replaced by each state's, its time-series
        settings are dropped (a set needs spectra, not records).
    scatter : ScatterDiagram
    fatigue : LineFatigue or mapping of line name to LineFatigue, optional
        Fatigue settings of every line (one for all) or per line; no damage without.
    years : float
        Return period of the long-term extremes. [years]
    progress : callable, optional
        ``progress(done, total)`` after every case.
    engine : Engine, optional
        A built engine of the same scene (reused as is).

    Returns
    -------
    CaseSetResult
    """
    scene = load_scene(scene)
    if not (isinstance(years, (int, float)) and math.isfinite(years) and years > 0):
        raise InputError("years", years, "years", "must be finite and > 0")
    settings = _fatigue_settings(scene, fatigue)
    factors = {
        name: curve_factor(s, scene.environment.g, f"fatigue[{name}]")
        for name, s in settings.items()
    }
    for name, s in settings.items():
        s.check(f"fatigue[{name}]")
    if engine is None:
        engine = build_engine(_template(scene, scatter))
    n = len(scatter.states)
    names = tuple(ln.name for ln in scene.lines)
    n_el = {ln.name: sum(seg.elements for seg in ln.segments) for ln in scene.lines}
    stats = {ln: {e: np.full((n, 4), np.nan) for e in ENDS} for ln in names}
    d_ends = {ln: np.full((n, 2), np.nan) for ln in names}
    d_along = {ln: np.full((n, n_el[ln]), np.nan) for ln in names}
    s_el: dict[str, np.ndarray] = {}
    buffers: dict[str, _DamageBuffer] = {}
    rows: list[CaseRow] = []
    for i, state in enumerate(scatter.states):
        sea = Sea(spectrum=state.spectrum(scatter.family), heading=state.heading)
        row, res = _solve_case(engine, sea, i)
        rows.append(row)
        if res is not None:
            for name, lr in res.lines.items():
                s_el.setdefault(name, lr.s_elements)
                for e in ENDS:
                    st = getattr(lr, e)
                    stats[name][e][i] = (st.mean, st.std, st.tz, st.mpm_3h)
                if name in factors:
                    if name not in buffers:
                        curve, k = factors[name]
                        out = np.full((n, n_el[name] + 2), np.nan)
                        buffers[name] = _DamageBuffer(
                            lr.omega, curve, k, settings[name].method, out
                        )
                    spectra = np.concatenate(
                        [np.stack([lr.end_tension_spectrum(e) for e in ENDS]), lr.tension_spectrum]
                    )
                    buffers[name].add(i, spectra)
        if progress is not None:
            progress(i + 1, n)
    for name, buf in buffers.items():
        buf.flush()
        d_ends[name], d_along[name] = buf.out[:, :2], buf.out[:, 2:]
    p = np.array([s.probability for s in scatter.states])
    has = np.array([r.has_numbers for r in rows])
    ok = np.array([r.status == "ok" for r in rows])
    coverage = {
        "ok": float(p[ok].sum()),
        "with_response": float(p[has].sum()),
        "failed": float(p[~has].sum()),
    }
    totals = {
        name: _line_totals(
            p, has, stats[name], d_ends[name], d_along[name], settings.get(name), years
        )  # fmt: skip
        for name in names
    }
    return CaseSetResult(
        scatter, tuple(rows), names, s_el, stats, d_ends, d_along, totals, coverage,
        float(years), settings,
    )  # fmt: skip


def _line_totals(
    p: np.ndarray,
    has: np.ndarray,
    stats: dict[str, np.ndarray],
    d_ends: np.ndarray,
    d_along: np.ndarray,
    settings: LineFatigue | None,
    years: float,
) -> LineTotals:
    pw = np.where(has, p, 0.0)
    annual: dict[str, Any] = {}
    life: dict[str, Any] = {}
    gov_d: dict[str, int] = {}
    if settings is not None and has.any():
        dff = settings.design_factor
        for j, e in enumerate(ENDS):
            d = float(np.sum(pw[has] * d_ends[has, j])) * SECONDS_PER_YEAR
            annual[e], life[e] = d, (math.inf if d == 0 else 1.0 / (dff * d))
            gov_d[e] = int(np.argmax(np.where(has, p * np.nan_to_num(d_ends[:, j]), -1.0)))
        along = np.sum(pw[has, None] * d_along[has], axis=0) * SECONDS_PER_YEAR
        annual["along"] = along
        with np.errstate(divide="ignore"):
            life["along"] = np.where(along > 0, 1.0 / (dff * along), np.inf)
    levels: dict[str, float] = {}
    gov_m: dict[str, int] = {}
    for e in ENDS:
        st = stats[e]
        if has.any():
            levels[e] = float(return_level(years, p[has], st[has, 0], st[has, 1], st[has, 2]))
            gov_m[e] = int(np.argmax(np.where(has, st[:, 3], -np.inf)))
    return LineTotals(annual, life, levels, gov_m, gov_d)
