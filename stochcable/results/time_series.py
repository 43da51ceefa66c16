"""The time series of a result: one realization of the sea and the responses.

:class:`TimeSeries` is :attr:`stochcable.results.documents.Result.timeseries` (re-exported
there); its document part is a window of :data:`DOCUMENT_WINDOW` samples.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["DOCUMENT_WINDOW", "TimeSeries"]

# Number of time samples of the time-series window put in the result document.
DOCUMENT_WINDOW = 2048


@dataclass(frozen=True, eq=False)
class TimeSeries:
    """One realization of the sea (and of each end-motion channel) and the responses.

    All series share the time axis and the complex amplitudes of their channels, so
    elevation, motions and tensions are mutually consistent (DESIGN.md "Random sea
    simulation").

    Attributes
    ----------
    time : ndarray, shape (N_t,)
        Sample times. [s]
    method : str
        ``"dsa"`` or ``"nsa"``.
    seed : int
        Root seed: the sea uses ``rng=seed``; end-motion spectrum channel k (every
        line in scene order × end_a, end_b × surge, sway, heave) uses
        ``np.random.SeedSequence(seed).spawn(n)[k]``.
    elevation : ndarray or None, shape (N_t,)
        Wave elevation at the origin (None without a sea). [m]
    end_motion : dict
        ``{"line.end_b.surge": series}`` for end-motion spectrum channels. [m]
    end_tension : dict
        ``{line: {"end_a": series, "end_b": series}}`` total tension mean + dynamic,
        with the residuals of the linear model where they were applied (their
        independent Gaussian component, ``end_tension_residual``). [N]
    omega : ndarray, shape (N+1,)
        Realization grid ω_m = mΔω. [rad/s]
    channels : dict
        ``{line: (channel names)}``, the order of the transfer arrays: the line's
        own (``"sea"``, ``"end_b.surge"``) for an independent line, its coupled
        group's (``"sea"``, ``"<line>.<end>.<dof>"``) for a line on a free body.
    end_tension_transfer : dict
        ``{line: {"end_a": H, "end_b": H}}``, H of shape (n_ch, N+1) on ``omega``
        (zero outside the analysis band), the transfer functions synthesized. [N/unit]
    body_motion : dict
        ``{body: {dof: series}}`` motion of each body's reference point, static pose
        plus dynamic part, in the body's DOF names (``BodyResult.dofs``): positions
        [m], small rotations about the global axes [rad].  Free bodies from the
        coupled solve, prescribed bodies (vessels) from their RAO.
    body_channels : dict
        ``{body: (channel names)}``, the order of the body transfer arrays (the
        coupled group's channels; the sea's for a vessel: ``("sea",)``, or one
        ``"sea@<deg>"`` per direction of a short-crested sea).
    body_motion_transfer : dict
        ``{body: H}``, H of shape (n_ch, d, N+1) on ``omega`` (zero outside the
        analysis band), the transfer functions synthesized. [m/unit, rad/unit]
    end_tension_residual : dict
        ``{line: {"end_a": series, ...}}``, the residuals' Gaussian component of the end
        tensions (:mod:`stochcable.dynamics.timeseries.residual_series`), for the lines
        and ends where the residuals were applied (empty with
        ``analysis.linearization.drag_residual`` and ``geometric_residual`` false). [N]
    body_motion_residual : dict
        ``{body: {dof: series}}``, the residuals' Gaussian component of the free bodies'
        motions whose statistics carry them (``body_motion`` includes it). [m, rad]
    """

    time: np.ndarray
    method: str
    seed: int
    elevation: np.ndarray | None
    end_motion: dict[str, np.ndarray]
    end_tension: dict[str, dict[str, np.ndarray]]
    omega: np.ndarray
    channels: dict[str, tuple[str, ...]]
    end_tension_transfer: dict[str, dict[str, np.ndarray]]
    body_motion: dict[str, dict[str, np.ndarray]] = field(default_factory=dict)
    body_channels: dict[str, tuple[str, ...]] = field(default_factory=dict)
    body_motion_transfer: dict[str, np.ndarray] = field(default_factory=dict)
    end_tension_residual: dict[str, dict[str, np.ndarray]] = field(default_factory=dict)
    body_motion_residual: dict[str, dict[str, np.ndarray]] = field(default_factory=dict)

    @property
    def body_motion_linear(self) -> dict[str, dict[str, np.ndarray]]:
        """``{body: {dof: series}}``, the linear model's body motions: ``body_motion``
        without the residuals' component. [m, rad]"""
        return {
            name: {
                k: s - self.body_motion_residual.get(name, {}).get(k, 0.0) for k, s in dofs.items()
            }
            for name, dofs in self.body_motion.items()
        }

    @property
    def end_tension_linear(self) -> dict[str, dict[str, np.ndarray]]:
        """``{line: {"end_a": series, "end_b": series}}``, the linear model's end
        tensions: ``end_tension`` without the residuals' component. [N]"""
        return {
            name: {
                e: s - self.end_tension_residual.get(name, {}).get(e, 0.0) for e, s in ends.items()
            }
            for name, ends in self.end_tension.items()
        }

    def to_document(self, full: bool = False, linear: bool = False) -> dict[str, Any]:
        """Document part: the first :data:`DOCUMENT_WINDOW` samples, or all if ``full``;
        with ``linear``, the linear model's end tensions (``tension_linear``) beside the
        tensions of the lines and ends that carry the residuals' component."""
        n = self.time.size if full else min(self.time.size, DOCUMENT_WINDOW)
        doc: dict[str, Any] = {
            "method": self.method,
            "seed": int(self.seed),
            "dt": float(self.time[1] - self.time[0]) if self.time.size > 1 else 0.0,
            "samples": int(self.time.size),
            "window": int(n),
            "time": self.time[:n].tolist(),
            "elevation": None if self.elevation is None else self.elevation[:n].tolist(),
            "end_motion": {k: v[:n].tolist() for k, v in self.end_motion.items()},
            "lines": {
                name: {end: {"tension": s[:n].tolist()} for end, s in ends.items()}
                for name, ends in self.end_tension.items()
            },
        }
        if linear:
            for name, ends in self.end_tension_residual.items():
                for end, comp in ends.items():
                    base = self.end_tension[name][end][:n] - comp[:n]
                    doc["lines"][name][end]["tension_linear"] = base.tolist()
        if self.body_motion:
            # {body: {"motion": {dof: [...]}}} (rad for rotations), as the result's
            # "bodies" part
            doc["bodies"] = {
                name: {"motion": {k: s[:n].tolist() for k, s in dofs.items()}}
                for name, dofs in self.body_motion.items()
            }
        return doc
