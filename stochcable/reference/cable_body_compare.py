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
from dataclasses import dataclass
from typing import Any

import numpy as np

from stochcable.reference.cable_body import simulate_line_on_body
from stochcable.reference.moordyn_compare import student_interval

__all__ = ["DOFS", "ENDS", "BodyComparison", "compare_body_line"]

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
    w = doc["analysis"]["omega"]
    band = (w["min"], w["max"])
    kw = dict(duration=duration, dt=dt, band=band, ramp=ramp, tolerance=1e-6,
              max_iterations=60, internal_damping=internal_damping)  # fmt: skip
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        leg_c = fd_default
        leg_l, body_l = fd_linear
        transfer = {e: (leg_l.omega, leg_l.end_tension_transfer[e][0]) for e in ENDS}
        transfer.update(
            {k: (body_l.omega, body_l.motion_transfer[0, i]) for i, k in enumerate(DOFS)}
        )
        lz = leg_l.linearization
        small = _scaled(doc, LINEAR_AMPLITUDE)
        h = simulate_line_on_body(
            small, seed=1, seabed="linear",
            linear_drag=(lz.b_normal, lz.b_axial, body_l.drag_coefficient), **kw,
        )  # fmt: skip
        keep = h.t >= h.ramp
        offset = {
            k: float(np.std(x[keep]) / np.std(h.linear(*transfer[k])[keep]) - 1.0)
            for k, x in _records(h).items()
        }
        ratios: dict[str, list[float]] = {k: [] for k in ENDS + DOFS}
        raw: dict[str, list[float]] = {k: [] for k in ENDS + DOFS}
        for seed in range(1, seeds + 1):
            h = simulate_line_on_body(doc, seed=seed, seabed=seabed, **kw)
            keep = h.t >= h.ramp
            for k, x in _records(h).items():
                s_td = float(np.std(x[keep]))
                raw[k].append(s_td)
                ratios[k].append(s_td / float(np.std(h.linear(*transfer[k])[keep])))
    fd_sigma = {e: getattr(leg_l, e).std for e in ENDS}
    fd_sigma.update({k: body_l.motion[k].std for k in DOFS})
    td = {}
    for k in ENDS + DOFS:
        mean, half = student_interval(np.array(ratios[k]))
        scale = fd_sigma[k] / (1.0 + offset[k])
        td[k] = (mean * scale, half * scale)
    return BodyComparison(
        fd_default={e: getattr(leg_c, e).std for e in ENDS},
        fd_linear={e: getattr(leg_l, e).std for e in ENDS},
        td={e: td[e] for e in ENDS},
        offset=offset,
        ratios={e: np.array(v) for e, v in ratios.items()},
        raw={e: np.array(v) for e, v in raw.items()},
        motion={k: (fd_sigma[k],) + td[k] for k in DOFS},
    )


def _records(h: Any) -> dict[str, np.ndarray]:
    """The end tensions and body DOFs of a record by name."""
    out = {"end_a": h.tension_a, "end_b": h.tension_b}
    out.update({k: h.motion[:, i] for i, k in enumerate(DOFS)})
    return out
