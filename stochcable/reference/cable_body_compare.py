"""The frequency domain of a line on a free body against the nonlinear time domain
(:func:`stochcable.reference.cable_body.simulate_line_on_body`), seed by seed, with the
paired linear record as control variate (benchmarks/body_timedomain.py, the slow test
tests/reference/test_cable_body.py, docs/accuracy/bodies.md).

Per seed s and end, the ratio q_s = σ_TD,s / σ_P,s of the time domain's end-tension σ to
that of the paired linear record P (the frequency domain's linear transfer function
driven by the same waves over the same window,
:meth:`~stochcable.reference.cable_body.BodyLineHistory.linear`): the window's sampling
error is common to both and cancels to first order.  The time-domain estimate of σ is

    σ̂_TD = mean(q) · σ_FD,linear / (1 + δ),

with its 95 % Student interval over the seeds, and δ the linear model offset: the
same time domain made as linear as the frequency domain (the frequency domain's
converged drag coefficients on the line and the body, the seabed frozen at its static
tangent, the amplitude ×10⁻³ so that the geometry stays linear) against its paired
record, one seed (a linear record has no sampling error against its paired one).  δ
is the two discretizations' difference (the time domain's nodal bed against the
frequency domain's split touchdown element, the static re-solve), not physics; it is
reported and divided out.
"""

from __future__ import annotations

import copy
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from stochcable.reference.cable_body import simulate_line_on_body
from stochcable.reference.moordyn_compare import student_interval

__all__ = ["DOFS", "ENDS", "BodyComparison", "compare_body_line", "paired_estimate"]

ENDS = ("end_a", "end_b")
DOFS = ("surge", "heave", "pitch")

#: Amplitude factor of the linear-offset run: geometric terms scale with it, so at
#: 10⁻³ the time domain with linear drag and bed is linear to ~0.1 % of σ. [-]
LINEAR_AMPLITUDE = 1e-3


@dataclass(frozen=True, eq=False)
class BodyComparison:
    """End-tension σ of a line on a body: frequency domain against time domain.

    Attributes
    ----------
    fd_default, fd_linear : dict of str to float
        The frequency domain's σ with the residuals (through the body) and without. [N]
    td : dict of str to (float, float)
        σ̂_TD and the half-width of its 95 % interval (module notes). [N]
    offset : dict of str to float
        The linear model offset δ (module notes). [-]
    ratios : dict of str to ndarray
        q_s per seed. [-]
    raw : dict of str to ndarray
        σ_TD,s per seed (no control variate, no offset). [N]
    motion : dict of str to (float, float, float)
        Per body DOF: the frequency domain's σ (the residuals do not change it), the
        time domain's estimate and its 95 % half-width (the same estimator with the
        motion transfer functions). [m, rad]
    """

    fd_default: dict[str, float]
    fd_linear: dict[str, float]
    td: dict[str, tuple[float, float]]
    offset: dict[str, float]
    ratios: dict[str, np.ndarray]
    raw: dict[str, np.ndarray]
    motion: dict[str, tuple[float, float, float]]


def _scaled(doc: dict, factor: float) -> dict:
    """The scene with the sea's spectral density times ``factor``² (a PM or JONSWAP
    given by m0 or hs)."""
    d = copy.deepcopy(doc)
    spec = d["sea"]["spectrum"]
    if spec.get("m0") is not None:
        spec["m0"] = spec["m0"] * factor**2
    else:
        spec["hs"] = spec["hs"] * factor
    return d


def compare_body_line(
    doc: dict,
    fd_default: Any,
    fd_linear: tuple[Any, Any],
    *,
    seeds: int,
    duration: float,
    dt: float = 0.05,
    ramp: float = 100.0,
    seabed: str = "linear",
    internal_damping: float = 0.0,
) -> BodyComparison:
    """The comparison of module notes for a scene accepted by
    :func:`~stochcable.reference.cable_body.simulate_line_on_body`.

    Parameters
    ----------
    doc : dict
        The scene document (its one line, end_b on the free body).
    fd_default : LineResult
        The line's frequency-domain result at the defaults (residuals on).
    fd_linear : (LineResult, BodyResult)
        The line's and the body's results with the residuals off (``drag_residual``
        and ``geometric_residual`` false): the transfer functions of the paired
        records and the converged drag of the linear-offset run.
    seeds : int
        Seeds 1 … ``seeds`` of the sea realization. [-]
    duration : float
        Record length per seed. [s]
    dt : float
        Time step. [s]
    ramp : float
        Excitation ramp, excluded from the statistics; long against the slowest
        lightly damped mode (the buoy's surge). [s]
    seabed : {"linear", "one_sided"}
        The time domain's bed in the nonlinear runs (the linear-offset run always
        freezes it). [-]
    internal_damping : float
        The time domain's axial internal damping BA. [N·s]

    Returns
    -------
    BodyComparison
    """
    leg_l, body_l = fd_linear
    transfer = {e: (leg_l.omega, leg_l.end_tension_transfer[e][0]) for e in ENDS}
    transfer.update({k: (body_l.omega, body_l.motion_transfer[0, i]) for i, k in enumerate(DOFS)})
    fd_sigma = {e: getattr(leg_l, e).std for e in ENDS}
    fd_sigma.update({k: body_l.motion[k].std for k in DOFS})
    lz = leg_l.linearization
    offset, td, ratios, raw = paired_estimate(
        simulate_line_on_body, doc, (lz.b_normal, lz.b_axial, body_l.drag_coefficient),
        transfer, fd_sigma, seeds=seeds, duration=duration, dt=dt, ramp=ramp,
        seabed=seabed, internal_damping=internal_damping,
    )  # fmt: skip
    return BodyComparison(
        fd_default={e: getattr(fd_default, e).std for e in ENDS},
        fd_linear={e: getattr(leg_l, e).std for e in ENDS},
        td={e: td[e] for e in ENDS},
        offset=offset,
        ratios={e: ratios[e] for e in ENDS + DOFS},
        raw={e: raw[e] for e in ENDS + DOFS},
        motion={k: (fd_sigma[k],) + td[k] for k in DOFS},
    )


def paired_estimate(
    simulate: Callable[..., Any],
    doc: dict,
    linear_drag: Any,
    transfer: dict[str, tuple[np.ndarray, np.ndarray]],
    fd_sigma: dict[str, float],
    *,
    seeds: int,
    duration: float,
    dt: float,
    ramp: float,
    seabed: str,
    internal_damping: float,
) -> tuple[dict[str, float], dict[str, tuple[float, float]], dict, dict]:
    """The estimator of module notes for a time domain ``simulate`` (:func:`simulate_line_on_body`
    or :func:`~stochcable.reference.cable_bodies.simulate_lines_on_body`: its history's
    ``records()`` and ``linear(omega, transfer)``).

    Parameters
    ----------
    simulate : callable
        The time domain (scene, seed=, seabed=, linear_drag=, and the run's keywords).
    doc : dict
        The scene document.
    linear_drag : object
        ``simulate``'s ``linear_drag`` for the linear-offset run (the frequency domain's
        converged drag).
    transfer : dict of str to (ndarray, ndarray)
        Per record: ω [rad/s] and the frequency domain's linear transfer function.
    fd_sigma : dict of str to float
        Per record: the frequency domain's linear σ. [N, m, rad]
    seeds, duration, dt, ramp, seabed, internal_damping
        As :func:`compare_body_line`'s.

    Returns
    -------
    offset, td, ratios, raw : dict of str
        δ; (σ̂_TD, its 95 % half-width); q per seed; σ_TD per seed (ndarrays).
    """
    w = doc["analysis"]["omega"]
    kw = dict(duration=duration, dt=dt, band=(w["min"], w["max"]), ramp=ramp,
              tolerance=1e-6, max_iterations=60, internal_damping=internal_damping)  # fmt: skip
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        h = simulate(
            _scaled(doc, LINEAR_AMPLITUDE), seed=1, seabed="linear", linear_drag=linear_drag, **kw
        )
        keep = h.t >= h.ramp
        offset = {
            k: float(np.std(x[keep]) / np.std(h.linear(*transfer[k])[keep]) - 1.0)
            for k, x in h.records().items()
        }
        ratios: dict[str, list[float]] = {k: [] for k in offset}
        raw: dict[str, list[float]] = {k: [] for k in offset}
        for seed in range(1, seeds + 1):
            h = simulate(doc, seed=seed, seabed=seabed, **kw)
            keep = h.t >= h.ramp
            for k, x in h.records().items():
                s_td = float(np.std(x[keep]))
                raw[k].append(s_td)
                ratios[k].append(s_td / float(np.std(h.linear(*transfer[k])[keep])))
    td = {}
    for k in offset:
        mean, half = student_interval(np.array(ratios[k]))
        scale = fd_sigma[k] / (1.0 + offset[k])
        td[k] = (mean * scale, half * scale)
    return (
        offset,
        td,
        {k: np.array(v) for k, v in ratios.items()},
        {k: np.array(v) for k, v in raw.items()},
    )
