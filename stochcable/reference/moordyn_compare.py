"""The time-domain reference against MoorDyn on one line: both driven by the same
periodic DSA fairlead surge, several seeds, tension σ at both ends with Student-t
confidence intervals (:mod:`stochcable.reference.moordyn` has the conventions).

A record is one warm-up period (the half-cosine ramp inside it) and one measured
period T of the motion, so the motion's sample variance over the measured window is
exactly Σ a_j²/2 for every seed: a seed's tension σ carries no sampling error of the
input, only the phases' effect on the nonlinear response.  The two simulators see the
same phases per seed, so their ratio is paired and its spread across seeds is small.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy import stats as _st

from stochcable import validation as _v
from stochcable.errors import InputError
from stochcable.reference.cable import simulate_line_timedomain
from stochcable.reference.moordyn import (
    EndTensionHistory,
    SurgeMotion,
    comparison_scene,
    internal_damping_coefficient,
    periodic_dsa_surge,
    simulate_line_moordyn,
)
from stochcable.scene.model import Scene, load_scene
from stochcable.sea.spectra import spectrum_pierson_moskowitz

__all__ = [
    "SeedResult",
    "LineComparison",
    "student_interval",
    "simulate_line_reference",
    "compare_line",
    "window_std",
    "QUANTITIES",
]

QUANTITIES = ("a", "b", "reaction_a", "reaction_b")
"""The σ compared: end-segment tension at end_a and end_b, support reaction at end_a and
end_b (the reactions are what the frequency domain's end tensions are)."""


def student_interval(x: np.ndarray, level: float = 0.95) -> tuple[float, float]:
    """Mean and half-width of the Student-t confidence interval of the mean.

    Parameters
    ----------
    x : array
        Independent samples (one per seed). [any]
    level : float, default 0.95
        Two-sided confidence level. [-]

    Returns
    -------
    (float, float)
        Mean and t_{(1+level)/2, n−1}·s/√n (inf for one sample). [same as x]
    """
    x = np.asarray(x, dtype=float)
    level = _v.in_range("level", level, "-", 0.0, 1.0)
    if x.size == 0:
        raise InputError("x", "empty", "-", "needs at least one sample")
    if x.size == 1:
        return float(x[0]), math.inf
    half = float(_st.t.ppf(0.5 * (1.0 + level), x.size - 1) * x.std(ddof=1) / math.sqrt(x.size))
    return float(x.mean()), half


def simulate_line_reference(
    scene: Scene | dict | str,
    motion: SurgeMotion,
    *,
    duration: float,
    ramp: float,
    dt: float = 0.05,
    **options: Any,
) -> EndTensionHistory:
    """Run the line of a :func:`~stochcable.reference.moordyn.comparison_scene` in the
    reference simulator with end_b surging.

    Parameters
    ----------
    scene : Scene, mapping or JSON
        One-line comparison scene.
    motion : SurgeMotion
        Surge of end_b; ``duration`` must be a whole number of its periods.
    duration : float
        Simulated time. [s]
    ramp : float
        Half-cosine ramp length. [s]
    dt : float, default 0.05
        Integration step; duration/dt must be an even integer. [s]
    **options
        Passed to :func:`~stochcable.reference.cable.simulate_line_timedomain`.

    Returns
    -------
    EndTensionHistory
        End-element tensions (``element_tension`` of the first and last element) and
        the support reactions ``tension_a``, ``tension_b`` at both ends.
    """
    sc = load_scene(scene)
    n_per = duration / motion.period
    n_t = duration / dt
    if abs(n_per - round(n_per)) > 1e-9 or round(n_per) < 1:
        raise InputError(
            "duration", duration, "s", f"must be a whole number of periods {motion.period} s"
        )
    if abs(n_t - round(n_t)) > 1e-6 or round(n_t) % 2:
        raise InputError(
            "dt", dt, "s", f"must divide duration {duration} s an even number of times"
        )
    n_t = int(round(n_t))
    coeff = np.zeros((3, n_t // 2 + 1), dtype=complex)
    coeff[0] = motion.coefficients(int(round(n_per)), n_t)
    h = simulate_line_timedomain(
        sc,
        end_realizations={"b": coeff},
        duration=duration,
        dt=dt,
        ramp=ramp,
        **options,
    )
    x = h.positions[:, -1, 0] - h.static_positions[-1, 0]
    return EndTensionHistory(
        t=h.t,
        tension_a=h.element_tension[:, 0],
        tension_b=h.element_tension[:, -1],
        reaction_b=h.tension_b,
        reaction_a=h.tension_a,
        static_a=float(h.static_tension[0]),
        static_b=float(h.static_tension[-1]),
        motion=x,
        simulator="reference",
    )


@dataclass(frozen=True)
class SeedResult:
    """σ of one seed over the measured period.

    Attributes
    ----------
    seed : int
        Seed of the motion's phases. [-]
    motion_std : float
        σ of the applied surge over the measured window (both simulators). [m]
    reference, moordyn : dict
        σ per quantity of :data:`QUANTITIES`. [N]
    """

    seed: int
    motion_std: float
    reference: dict[str, float]
    moordyn: dict[str, float]


@dataclass(frozen=True)
class LineComparison:
    """The reference against MoorDyn on one line, over several seeds.

    Attributes
    ----------
    line : str
        Line name.
    seeds : tuple of SeedResult
    motion_std : float
        σ of the periodic DSA motion, √(Σ a_j²/2). [m]
    static : dict
        End-segment static tensions ``{"reference"|"moordyn": (T_a, T_b)}``. [N]
    settings : dict
        Elements, period, band, spectrum, steps and options of the run.
    """

    line: str
    seeds: tuple[SeedResult, ...]
    motion_std: float
    static: dict[str, tuple[float, float]]
    settings: dict = field(default_factory=dict)

    def sigma(self, simulator: str, quantity: str) -> tuple[float, float]:
        """Mean σ over the seeds and its 95 % Student-t half-width. [N]"""
        if simulator not in ("reference", "moordyn"):
            raise InputError("simulator", simulator, "-", "must be 'reference' or 'moordyn'")
        return student_interval(np.array([getattr(s, simulator)[quantity] for s in self.seeds]))

    def normalized(self, simulator: str, quantity: str) -> tuple[float, float]:
        """σ per unit realized motion σ, mean and 95 % half-width. [N/m]"""
        return student_interval(
            np.array([getattr(s, simulator)[quantity] / s.motion_std for s in self.seeds])
        )

    def ratio(self, quantity: str) -> tuple[float, float]:
        """Paired ratio σ_reference/σ_moordyn − 1, mean and 95 % half-width. [-]"""
        return student_interval(
            np.array([s.reference[quantity] / s.moordyn[quantity] - 1.0 for s in self.seeds])
        )


def window_std(h: EndTensionHistory, t0: float, t1: float) -> tuple[dict[str, float], float]:
    """σ of every quantity of :data:`QUANTITIES` [N] and of the applied motion [m] over
    t0 <= t < t1 (one whole period: the motion's σ is exact); ``reaction_a`` only when
    the history has it."""
    w = h.window(t0, t1)
    out = {
        "a": float(h.tension_a[w].std()),
        "b": float(h.tension_b[w].std()),
        "reaction_b": float(h.reaction_b[w].std()),
    }
    if h.reaction_a is not None:
        out["reaction_a"] = float(h.reaction_a[w].std())
    return out, float(h.motion[w].std())


def compare_line(
    scene: Scene | dict | str,
    line_name: str | None = None,
    *,
    elements: int = 80,
    seeds: tuple[int, ...] = (1, 2, 3, 4, 5),
    period: float = 200.0,
    band: tuple[float, float] = (0.05, 2.0),
    hs: float = 2.0,
    tp: float = 10.0,
    ramp: float | None = None,
    reference_dt: float = 0.05,
    moordyn_dt: float = 1e-3,
    coupling_dt: float = 5e-3,
    moordyn_internal_damping: float = 0.0,
    moordyn_scheme: str = "RK4",
    match_internal_damping: bool = False,
    reference_options: dict | None = None,
) -> LineComparison:
    """Tension σ of the reference simulator and MoorDyn on one line and several seeds.

    Parameters
    ----------
    scene : Scene, mapping or JSON
        Any scene; its line ``line_name`` (default the first) is run alone
        (:func:`~stochcable.reference.moordyn.comparison_scene`).
    line_name : str, optional
        Which line. [-]
    elements : int, default 80
        Elements of the reference = MoorDyn segments. [-]
    seeds : tuple of int
        Seeds of the motion's phases. [-]
    period : float, default 200
        Period T of the DSA motion; the record is 2T (warm-up, measured). [s]
    band : (float, float), default (0.05, 2.0)
        Band of the motion components. [rad/s]
    hs, tp : float
        Pierson–Moskowitz surge spectrum: "significant" motion [m] and peak period [s].
    ramp : float, optional
        Half-cosine ramp length (default min(3·tp, T/2)). [s]
    reference_dt : float, default 0.05
        Reference time step, also the sampling interval of both records. [s]
    moordyn_dt, coupling_dt : float
        MoorDyn's dtM and the interval of its coupling calls. [s]
    moordyn_internal_damping : float, default 0
        MoorDyn's BA (N·s, or minus a damping ratio). [N·s]
    moordyn_scheme : str, default "RK4"
        MoorDyn's tScheme (RK2 needs internal damping). [-]
    match_internal_damping : bool, default False
        Give the reference MoorDyn's BA too (in N·s for this element count,
        :func:`~stochcable.reference.moordyn.internal_damping_coefficient`). [-]
    reference_options : dict, optional
        Extra keywords of :func:`~stochcable.reference.cable.simulate_line_timedomain`.

    Returns
    -------
    LineComparison
    """
    sc = comparison_scene(scene, line_name, elements)
    period = _v.positive("period", period, "s")
    ramp = min(3.0 * tp, 0.5 * period) if ramp is None else _v.nonnegative("ramp", ramp, "s")
    if ramp > period:
        raise InputError("ramp", ramp, "s", f"must fit in the warm-up period {period} s")
    if not seeds:
        raise InputError("seeds", seeds, "-", "needs at least one seed")
    duration = 2.0 * period
    opts = dict(reference_options or {})
    if match_internal_damping:
        opts["internal_damping"] = internal_damping_coefficient(sc, moordyn_internal_damping)

    def density(w: np.ndarray) -> np.ndarray:
        return spectrum_pierson_moskowitz(w, hs, tp)

    results = []
    static: dict[str, tuple[float, float]] = {}
    std0 = 0.0
    for seed in seeds:
        motion = periodic_dsa_surge(density, period, band, int(seed))
        std0 = motion.std
        ref = simulate_line_reference(
            sc, motion, duration=duration, ramp=ramp, dt=reference_dt, **opts
        )
        md = simulate_line_moordyn(
            sc,
            motion,
            duration=duration,
            ramp=ramp,
            sample_dt=reference_dt,
            coupling_dt=coupling_dt,
            dt=moordyn_dt,
            internal_damping=moordyn_internal_damping,
            scheme=moordyn_scheme,
        )
        s_ref, x_ref = window_std(ref, period, duration)
        s_md, _ = window_std(md, period, duration)
        results.append(SeedResult(int(seed), x_ref, s_ref, s_md))
        static = {
            "reference": (ref.static_a, ref.static_b),
            "moordyn": (md.static_a, md.static_b),
        }
    settings = {
        "elements": elements,
        "period": period,
        "band": tuple(band),
        "spectrum": {"type": "pierson_moskowitz", "hs": hs, "tp": tp},
        "ramp": ramp,
        "reference_dt": reference_dt,
        "moordyn_dt": moordyn_dt,
        "coupling_dt": coupling_dt,
        "moordyn_internal_damping": moordyn_internal_damping,
        "moordyn_scheme": moordyn_scheme,
        "reference_options": opts,
    }
    return LineComparison(sc.lines[0].name, tuple(results), std0, static, settings)
