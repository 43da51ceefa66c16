"""The frequency domain of several lines on one free body against the nonlinear time
domain (:func:`stochcable.reference.cable_bodies.simulate_lines_on_body`), seed by seed,
with the paired linear record as control variate: the estimator of
:mod:`stochcable.reference.cable_body_compare` per record (each line's end tensions,
the body's surge, heave and pitch), and a planar buoy on two or three legs built from
the bundled disc buoy (benchmarks/bodies_timedomain.py, the slow test
tests/reference/test_cable_bodies.py, docs/accuracy/bodies.md).

Per seed s and record, q_s = σ_TD,s / σ_P,s (P: the frequency domain's linear transfer
function driven by the same waves over the same window); σ̂_TD = mean(q) · σ_FD,linear
/ (1 + δ) with its 95 % Student interval over the seeds, δ the linear model offset (the
time domain with the frequency domain's converged drag, the bed frozen and the sea
×10⁻³ against its paired record, one seed).
"""

from __future__ import annotations

import copy
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from stochcable import analyze, load_example
from stochcable.errors import InputError
from stochcable.reference.cable_bodies import simulate_lines_on_body
from stochcable.reference.cable_body_compare import DOFS, ENDS, paired_estimate

__all__ = ["BodiesComparison", "compare_lines_on_body", "planar_buoy"]

#: One leg's static vertical pull on the disc buoy of the bundled examples (the
#: single-leg and three-leg bodies' masses differ by two of them). [lbf]
_LEG_PULL = 150.0


@dataclass(frozen=True, eq=False)
class BodiesComparison:
    """σ of every record of lines on one body: frequency domain against time domain.

    Attributes
    ----------
    fd_default, fd_linear : dict of str to float
        The frequency domain's σ with the residuals and without, per record
        ("LINE.end_a", "LINE.end_b", "surge", "heave", "pitch"). [N, m, rad]
    td : dict of str to (float, float)
        σ̂_TD and the half-width of its 95 % interval (module notes). [N, m, rad]
    offset : dict of str to float
        The linear model offset δ. [-]
    ratios, raw : dict of str to ndarray
        q_s per seed; σ_TD,s per seed (no control variate, no offset). [-], [N, m, rad]
    """

    fd_default: dict[str, float]
    fd_linear: dict[str, float]
    td: dict[str, tuple[float, float]]
    offset: dict[str, float]
    ratios: dict[str, np.ndarray]
    raw: dict[str, np.ndarray]


def planar_buoy(m0: float, elements: int, legs: int = 2, *, wind: float = 0.0) -> dict:
    """The bundled disc buoy (Tuah 1982, §6.5) on ``legs`` planar legs: two mirrored in
    x (anchors at x = ∓305 ft, fairleads at the rim x = ∓5 ft, 2.5 ft draft, 339 ft of
    the §6.2 cable each), a third beside the first (anchor at x = −255 ft, 289 ft long);
    the buoy's mass less one leg's pull per leg beyond the first (the static draft of
    the example), no wind by default (a mirror-symmetric scene).

    Parameters
    ----------
    m0 : float
        The PM sea's zeroth moment (ω_p = 0.5 rad/s). [ft²]
    elements : int
        Elements per leg. [-]
    legs : {2, 3}
    wind : float
        Wind force on the buoy along +x. [lbf]

    Returns
    -------
    dict
        The scene document (ft, slug, lbf).
    """
    if legs not in (2, 3):
        raise InputError("legs", legs, "-", "must be 2 or 3")
    doc = load_example("tuah_1982_disc_buoy_single_leg").model_dump(mode="json")
    doc["analysis"].pop("timeseries", None)
    doc["sea"]["spectrum"]["m0"] = m0
    base = doc["lines"][0]
    base["segments"][0]["elements"] = elements
    geometry = ((-305.0, -5.0, 339.0), (305.0, 5.0, 339.0), (-255.0, -5.0, 289.0))[:legs]
    doc["lines"] = []
    for j, (x_a, x_b, length) in enumerate(geometry):
        ln = copy.deepcopy(base)
        ln["name"] = f"leg{j + 1}"
        ln["end_a"]["position"] = [x_a, 0.0, -100.0]
        ln["end_b"]["attach"]["point"] = [x_b, 0.0, -2.5]
        ln["segments"][0]["length"] = length
        doc["lines"].append(ln)
    body = doc["bodies"][0]
    g = doc["environment"]["g"]
    body["mass"] -= (legs - 1) * _LEG_PULL / g
    body["wind_force"] = [wind, 0.0, 0.0]
    return doc


def _fd(doc: dict, residuals: bool) -> tuple[dict, dict, Any]:
    """σ per record and the transfer functions of the paired records (module notes)."""
    d = copy.deepcopy(doc)
    d["analysis"]["linearization"].update(drag_residual=residuals, geometric_residual=residuals)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = analyze(d)
    body = next(iter(res.bodies.values()))
    sigma, transfer = {}, {}
    for name, ln in res.lines.items():
        for e in ENDS:
            sigma[f"{name}.{e}"] = getattr(ln, e).std
            transfer[f"{name}.{e}"] = (ln.omega, ln.end_tension_transfer[e][0])
    for i, k in enumerate(DOFS):
        sigma[k] = body.motion[k].std
        transfer[k] = (body.omega, body.motion_transfer[0, i])
    return sigma, transfer, res


def compare_lines_on_body(
    doc: dict,
    *,
    seeds: int,
    duration: float,
    dt: float = 0.05,
    ramp: float = 100.0,
    seabed: str = "linear",
    internal_damping: float = 0.0,
) -> BodiesComparison:
    """The comparison of module notes for a scene accepted by
    :func:`~stochcable.reference.cable_bodies.simulate_lines_on_body` (its one body).

    Parameters
    ----------
    doc : dict
        The scene document.
    seeds, duration, dt, ramp, seabed, internal_damping
        As :func:`~stochcable.reference.cable_body_compare.compare_body_line`'s.

    Returns
    -------
    BodiesComparison
    """
    fd_default, _, _ = _fd(doc, True)
    fd_linear, transfer, res_l = _fd(doc, False)
    body_l = next(iter(res_l.bodies.values()))
    lin = {n: (r.linearization.b_normal, r.linearization.b_axial) for n, r in res_l.lines.items()}
    offset, td, ratios, raw = paired_estimate(
        simulate_lines_on_body, doc, (lin, body_l.drag_coefficient), transfer, fd_linear,
        seeds=seeds, duration=duration, dt=dt, ramp=ramp, seabed=seabed,
        internal_damping=internal_damping,
    )  # fmt: skip
    return BodiesComparison(
        fd_default=fd_default, fd_linear=fd_linear, td=td, offset=offset, ratios=ratios, raw=raw
    )
