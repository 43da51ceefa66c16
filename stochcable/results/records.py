"""Records of one analysed line: response statistics, the drag-linearization record and
the quality indicators of the linear model.

Small frozen dataclasses filled by the engine (``stochcable.dynamics``) and written
into the result document by their ``as_dict`` (:mod:`stochcable.results.documents`
holds the result objects that carry them).  :func:`stats_from_spectrum` turns a
one-sided response spectrum on the analysis grid into :class:`ResponseStats`
(DESIGN.md "Outputs").

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from stochcable.errors import InputError

__all__ = [
    "THREE_HOURS",
    "stats_from_moments",
    "ResponseStats",
    "LinearizationRecord",
    "LineIndicators",
    "ResidualRecord",
    "stats_from_spectrum",
    "stats_from_spectrum_unchecked",
]

THREE_HOURS = 10800.0
"""Storm duration of the ``mpm_3h`` statistic. [s]"""


@dataclass(frozen=True)
class ResponseStats:
    """Statistics of one Gaussian response: static mean + zero-mean dynamic part.

    Attributes
    ----------
    mean : float
        Static (mean) value. [unit]
    std : float
        Standard deviation of the dynamic part, √m0. [unit]
    m0, m1, m2, m4 : float
        Spectral moments ∫ωⁿ S dω (trapezoid on the analysis grid). [unit²·(rad/s)ⁿ]
    tz : float
        Mean zero-upcrossing period 2π√(m0/m2) (0 for a zero process). [s]
    significant : float
        Significant value 2σ (DESIGN.md "Outputs"). [unit]
    bandwidth : float
        Spectral bandwidth √(1 − m2²/(m0 m4)). [-]
    mpm_3h : float
        mean + Rayleigh most probable maximum of the dynamic part over three hours,
        σ√(2 ln(10800/Tz)). [unit]
    mpm : float
        mean + the same over the scene's ``analysis.duration``. [unit]
    expected_max : float
        mean + expected maximum over ``analysis.duration``. [unit]
    """

    mean: float
    std: float
    m0: float
    m1: float
    m2: float
    m4: float
    tz: float
    significant: float
    bandwidth: float
    mpm_3h: float
    mpm: float
    expected_max: float

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready dict of the fields."""
        return {
            k: float(getattr(self, k))
            for k in (
                "mean",
                "std",
                "tz",
                "mpm_3h",
                "significant",
                "m0",
                "m1",
                "m2",
                "m4",
                "bandwidth",
                "mpm",
                "expected_max",
            )
        }


def stats_from_spectrum(
    omega: np.ndarray, density: np.ndarray, mean: float, duration: float
) -> ResponseStats:
    """Statistics of a response from its one-sided spectrum on the analysis grid.

    Parameters
    ----------
    omega : ndarray, shape (n,)
        Frequency grid. [rad/s]
    density : ndarray, shape (n,)
        One-sided spectrum of the dynamic part. [unit²·s/rad]
    mean : float
        Static value of the response. [unit]
    duration : float
        Storm duration for ``mpm`` and ``expected_max``. [s]

    Returns
    -------
    ResponseStats

    Notes
    -----
    :func:`stochcable.results.statistics.response_statistics` (trapezoid moments, Rayleigh
    maxima); mpm_3h = mean + σ√(2 ln(10800/Tz)) (DESIGN.md "Outputs").
    """
    from stochcable.results.statistics import check_response_spectrum

    w, s, dur = check_response_spectrum(omega, density, duration)
    if s.ndim != 1:
        raise InputError("density", density, "unit^2*s/rad", f"must be 1-D of {w.size} entries")
    return stats_from_spectrum_unchecked(w, s, mean, dur)


def stats_from_spectrum_unchecked(
    omega: np.ndarray, density: np.ndarray, mean: float, duration: float
) -> ResponseStats:
    """:func:`stats_from_spectrum` of a validated grid and spectrum (the analysis grid,
    validated once at the boundary; a 1-D float density >= 0 of its size, duration
    > 0): no second validation per call."""
    from stochcable.results.statistics import response_statistics_unchecked as stats

    st = stats(omega, density, THREE_HOURS)
    sd = st if duration == THREE_HOURS else stats(omega, density, float(duration))
    return _response_stats(st, sd, mean)


def stats_from_moments(moments: Any, mean: float, duration: float) -> ResponseStats:
    """Statistics of a Gaussian response from its spectral moments (m0, m1, m2, m4)
    [unit²·(rad/s)ⁿ], e.g. of a spectrum in parts on different grids whose moments
    add; ``mean`` and ``duration`` as in :func:`stats_from_spectrum`."""
    from stochcable.results.statistics import statistics_from_moments

    st = statistics_from_moments(*moments, THREE_HOURS)
    sd = st if duration == THREE_HOURS else statistics_from_moments(*moments, float(duration))
    return _response_stats(st, sd, mean)


def _response_stats(st: Any, sd: Any, mean: float) -> ResponseStats:
    """ResponseStats from the statistics over three hours (st) and the duration (sd)."""
    mean = float(mean)
    return ResponseStats(
        mean=mean,
        std=float(st.std),
        m0=float(st.m0),
        m1=float(st.m1),
        m2=float(st.m2),
        m4=float(st.m4),
        tz=float(st.tz),
        significant=float(st.significant),
        bandwidth=float(st.bandwidth),
        mpm_3h=mean + float(st.mpm),
        mpm=mean + float(sd.mpm),
        expected_max=mean + float(sd.expected_max),
    )


@dataclass(frozen=True, eq=False)
class LinearizationRecord:
    """The drag-linearization fixed point of one line (Tuah (1982), §5.3 steps 5–13).

    Attributes
    ----------
    method : str
        ``"seed"``, ``"vector"`` or ``"harmonic"``.
    converged : bool
        Whether the relative change of every σ fell below the tolerance.
    iterations : int
        Number of response evaluations. [-]
    relative_change : float
        Final max relative change of the σ. [-]
    history : tuple of float
        Relative change after each iteration. [-]
    tolerance : float
        Tolerance asked for. [-]
    sigma_normal, sigma_axial : ndarray, shape (n_el,)
        Final σ of the normal and axial relative velocity at element midpoints. [m/s]
    b_normal, b_axial : ndarray, shape (n_el,)
        Final linear drag coefficients per unit length (normal: the trace/2 of the
        normal-plane matrix for the vector form). [N·s/m²]
    """

    method: str
    converged: bool
    iterations: int
    relative_change: float
    history: tuple[float, ...]
    tolerance: float
    sigma_normal: np.ndarray
    sigma_axial: np.ndarray
    b_normal: np.ndarray
    b_axial: np.ndarray

    def as_dict(self) -> dict[str, Any]:
        return {
            "method": self.method,
            "converged": bool(self.converged),
            "iterations": int(self.iterations),
            "relative_change": float(self.relative_change),
            "tolerance": float(self.tolerance),
            "history": [float(h) for h in self.history],
        }


def _finite_or_none(x: float) -> float | None:
    x = float(x)
    return x if math.isfinite(x) else None


@dataclass(frozen=True, eq=False)
class LineIndicators:
    """Quality indicators of the linear model of one line.

    Attributes
    ----------
    borgman_ratio : ndarray, shape (n_el,)
        Var(B v)/Var(½ρCdD|v|v) of the normal drag per element for the Gaussian
        normal relative velocity with the element's normal current
        (:func:`stochcable.dynamics.linearization.formulas.borgman_variance_ratio`; 0.849 without
        current; elements at rest — normal velocity σ below 1e-6 of the line's
        largest, such as grounded chain — take the σ → 0 limit: 1 with a normal
        current, 0.849 without). [-]
    drag_inertia_ratio : ndarray, shape (n_el,)
        σ of the linearized normal drag force over σ of the Morison inertia force
        ρ C_M (πD²/4) a_n of the sea per element (inf without fluid acceleration;
        :func:`stochcable.dynamics.linearization.formulas.drag_inertia_ratio`; 0 at rest). [-]
    snap_margin : float
        min over elements and ends of (T_mean − 3σ_T)/|T_mean|; below 0 the linear
        model predicts slack (snap loads likely). [-]
    snap_risk : bool
        ``snap_margin < 0``.
    resonances : tuple of dict
        Modes inside the excitation band with modal damping ratio below 1 %:
        ``{"mode": j (1-based), "omega": ω_j [rad/s], "damping_ratio": ζ_j [-]}``.
    motion_std_max : float
        Largest node motion σ (magnitude of the x, y, z σ). [m]
    sag : float
        Largest distance of the static shape from the chord of the ends. [m]
    motion_to_sag : float
        motion_std_max / sag (inf for a straight line). [-]
    motion_to_diameter : float
        motion_std_max / largest diameter. [-]
    flags : tuple of str
        Raised flags: ``"snap"``, ``"resonance"``, ``"large_motion"``,
        ``"second_order"``.
    second_order : object or None
        Moments of the second-order stretching tension
        (:class:`stochcable.dynamics.residuals.second_order.SecondOrderTension`; its ``as_dict``).
    """

    borgman_ratio: np.ndarray
    drag_inertia_ratio: np.ndarray
    snap_margin: float
    snap_risk: bool
    resonances: tuple[dict[str, Any], ...]
    motion_std_max: float
    sag: float
    motion_to_sag: float
    motion_to_diameter: float
    flags: tuple[str, ...]
    second_order: Any = None

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready dict (non-finite numbers as None)."""
        br, di = self.borgman_ratio, self.drag_inertia_ratio
        return {
            "borgman_ratio": {
                "min": _finite_or_none(br.min()) if br.size else None,
                "max": _finite_or_none(br.max()) if br.size else None,
                "elements": [_finite_or_none(x) for x in br],
            },
            "drag_inertia_ratio": {
                "min": _finite_or_none(di.min()) if di.size else None,
                "max": _finite_or_none(di.max()) if di.size else None,
                "elements": [_finite_or_none(x) for x in di],
            },
            "snap": {"risk": bool(self.snap_risk), "margin": _finite_or_none(self.snap_margin)},
            "resonances": [dict(r) for r in self.resonances],
            "motion": {
                "std_max": float(self.motion_std_max),
                "sag": float(self.sag),
                "to_sag": _finite_or_none(self.motion_to_sag),
                "to_diameter": _finite_or_none(self.motion_to_diameter),
            },
            "flags": list(self.flags),
            "second_order": None if self.second_order is None else self.second_order.as_dict(),
        }


@dataclass(frozen=True)
class ResidualRecord:
    """The end-tension variance a closed-form residual of the linear model adds, and σ
    with it: the drag the linearization drops
    (:func:`stochcable.dynamics.residuals.drag_residual.drag_residual`) or the second-order
    geometric forces (:func:`stochcable.dynamics.residuals.geometric_residual.geometric_residual`).

    Attributes
    ----------
    computed : bool
        False where the line is outside the closed form's scope (``reason`` says why).
    reason : str
        Why not computed ("" when computed).
    variance : dict {"end_a", "end_b"} of float
        Variance the residual adds to the end tension (negative where it lowers it:
        the drag residual's linear part, :mod:`stochcable.dynamics.residuals.drag_segments`). [N²]
    in_band : dict {"end_a", "end_b"} of float
        Its part on the analysis band (the rest: superharmonics above ω_max, and
        difference frequencies below ω_min). [N²]
    std_linear : dict {"end_a", "end_b"} of float
        σ of the linear model (the result's end statistics). [N]
    std : dict {"end_a", "end_b"} of float
        √(σ_linear² + variance): the end-tension σ with the residual. [N]
    order : int
        Highest order kept (Hermite order of the drag; 2 for the quadratic geometric
        forces). [-]
    panels : int
        Element groups the residual was evaluated on (the elements for the geometric
        forces). [-]
    lines : tuple of (ndarray, dict {"end_a", "end_b"} of ndarray)
        The variance as spectral lines: parts (ω [rad/s], the end tensions' variance at
        each ω [N²]) whose sums are ``variance`` (the residual's uniform lines up to
        its highest order times ω_max; the drag's linear misfit on the analysis grid).
        Empty when not computed.
    """

    computed: bool
    reason: str
    variance: dict[str, float]
    in_band: dict[str, float]
    std_linear: dict[str, float]
    std: dict[str, float]
    order: int = 0
    panels: int = 0
    lines: tuple = ()

    @classmethod
    def not_computed(cls, reason: str, std: dict[str, float]) -> ResidualRecord:
        """A record that says why the residual was not computed."""
        zero = {e: 0.0 for e in std}
        return cls(False, reason, zero, dict(zero), dict(std), dict(std))

    @classmethod
    def from_variances(
        cls,
        variance: dict[str, float],
        in_band: dict[str, float],
        std: dict[str, float],
        order: int,
        panels: int,
        lines: tuple = (),
    ) -> ResidualRecord:
        """The record of computed residual variances (a variance change may be
        negative: it is clipped at −σ_linear², σ with it at 0) and their ``lines``."""
        var = {e: max(-(float(std[e]) ** 2), float(v)) for e, v in variance.items()}
        band = {e: max(-(float(std[e]) ** 2), float(v)) for e, v in in_band.items()}
        total = {e: math.sqrt(max(0.0, float(std[e]) ** 2 + var[e])) for e in var}
        return cls(True, "", var, band, dict(std), total, order, panels, tuple(lines))

    @classmethod
    def from_document(cls, doc: Mapping[str, Any]) -> ResidualRecord:
        """The record of its :meth:`as_dict` (without its spectral ``lines``)."""
        ends = {k: {e: float(doc[e][k]) for e in ("end_a", "end_b")}
                for k in ("variance", "in_band", "std_linear", "std")}  # fmt: skip
        return cls(bool(doc["computed"]), str(doc["reason"]), **ends,
                   order=int(doc["order"]), panels=int(doc["panels"]))  # fmt: skip

    def ratio(self, end: str) -> float:
        """σ with the residual over the linear σ at ``end`` (1 when not computed). [-]"""
        lin = self.std_linear[end]
        return self.std[end] / lin if lin > 0 else 1.0

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        ends = {
            e: {
                "variance": self.variance[e],
                "in_band": self.in_band[e],
                "std_linear": self.std_linear[e],
                "std": self.std[e],
                "ratio": self.ratio(e),
            }
            for e in ("end_a", "end_b")
        }
        return {
            "computed": self.computed,
            "reason": self.reason,
            "order": self.order,
            "panels": self.panels,
            **ends,
        }


# Former name of stats_from_spectrum_unchecked (ARCHITECTURE.md "Conventions"), kept importable.
stats_from_validated = stats_from_spectrum_unchecked
