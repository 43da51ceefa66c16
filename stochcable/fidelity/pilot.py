"""The pilot of the fidelity planner: the input spectra's band and a cheap analysis of
the scene whose *response* spectra set the band, the grid and the kept modes.

The pilot analysis is not run here: the planner is given it as ``evaluate(scene) ->
result`` (the orchestrator passes :func:`stochcable.analyze` with fidelity off), so
this package does not depend on the analysis above it.  The result must have
``lines`` (a mapping of line results with ``name``, ``omega``, ``input_spectra``,
``end_tension_transfer``, ``motion_transfer``, ``model``, ``modes``,
``modes_omega`` and ``linearization``, as :class:`stochcable.results` line results).
"""

from __future__ import annotations

import math
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from stochcable.dynamics.loads.channels import drag_matrix
from stochcable.fidelity.meshing import LineGeometry, mesh_rules, segments_scene
from stochcable.fidelity.rules import (
    MIN_TAIL_EXCESS,
    crossing_up,
    spectrum_tail_frequency,
    tail_above,
    tail_below,
    tail_exponent,
)
from stochcable.scene.model import Scene
from stochcable.sea.kinematics import wavenumber

__all__ = [
    "PILOT_INPUT_FRACTION",
    "PILOT_LOW_FRACTION",
    "PILOT_EXTENSIONS",
    "PILOT_COUNT",
    "PILOT_KH",
    "PILOT_MAX_ELEMENTS",
    "Evaluate",
    "InputBand",
    "Pilot",
    "input_densities",
    "input_band",
    "input_summary",
    "sea_load_wavenumber",
    "sea_omega2",
    "base_count",
    "base_error",
    "response_spectra",
    "modal_bandwidths",
    "pilot_analysis",
    "pilot_suffices",
    "run_pilot",
]

#: Variance fraction of each input spectrum left outside the pilot's first band. [-]
PILOT_INPUT_FRACTION = 1e-4
#: Same below the band: the pilot bounds the response below its first frequency by
#: S(ω₀)·ω₀, so it starts where the inputs are negligible. [-]
PILOT_LOW_FRACTION = 1e-9
#: Times the pilot's top frequency is doubled while the response tail is unbounded or
#: the pilot does not reach twice the ω_max it gives.
PILOT_EXTENSIONS = 4
#: Pilot frequencies (log spaced). [-]
PILOT_COUNT = 200
#: Pilot mesh: kh at the pilot's top frequency (frequency error (kh)²/24 ≈ 4 %). [-]
PILOT_KH = 1.0
#: Pilot elements per line at most (the pilot is a rough estimate). [-]
PILOT_MAX_ELEMENTS = 400

Evaluate = Callable[[Scene], Any]
"""The pilot analysis: scene -> result (see the module docstring)."""


# ------------------------------------------------------------------------- inputs


def input_densities(scene: Scene) -> list[tuple[str, Callable[[np.ndarray], np.ndarray]]]:
    """(name, ω -> S(ω)) of every input spectrum: the sea and the end-motion spectra
    (not the RAO-driven end motions, which follow the sea)."""
    g = scene.environment.g
    out: list[tuple[str, Callable[[np.ndarray], np.ndarray]]] = []
    if scene.sea is not None:
        spec = scene.sea.spectrum
        out.append(("sea", lambda w, spec=spec: spec.spectral_density(w, g)))
    for line in scene.lines:
        for end in ("end_a", "end_b"):
            m = getattr(line, end).motion
            if m is None or m.rao is not None:
                continue
            for dof in ("surge", "sway", "heave"):
                spec = getattr(m, dof)
                if spec is not None:
                    out.append(
                        (
                            f"{line.name}.{end}.{dof}",
                            lambda w, spec=spec: spec.spectral_density(w, g),
                        )
                    )
    return out


_WIDE = np.geomspace(1e-4, 1e4, 16001)
#: ω² on :data:`_WIDE` (formed once: :func:`sea_omega2` runs for every sea state of a set)
_WIDE_SQ = _WIDE**2


def input_band(scene: Scene, fraction: float) -> tuple[float, float, dict[str, tuple]]:
    """Union of the inputs' bands at ``fraction``, and per input (ω_lo, ω_hi, ω₂)."""
    per: dict[str, tuple] = {}
    for name, dens in input_densities(scene):
        s = np.asarray(dens(_WIDE), dtype=float)
        s = np.where(np.isfinite(s), s, 0.0)
        lo, hi = spectrum_tail_frequency(_WIDE, s, fraction)
        m0 = np.trapezoid(s, _WIDE)
        w2 = math.sqrt(np.trapezoid(_WIDE**2 * s, _WIDE) / m0)
        per[name] = (lo, hi, w2)
    if not per:
        return 0.05, 2.0, per
    return (min(v[0] for v in per.values()), max(v[1] for v in per.values()), per)


@dataclass(frozen=True)
class InputBand:
    """What the input spectra alone say: the pilot's first band, the largest ω₂ and the
    wavenumber of the wave-load element rule.

    Attributes
    ----------
    omega_lo, omega_hi : float
        Band outside which every input holds at most :data:`PILOT_LOW_FRACTION` below
        and :data:`PILOT_INPUT_FRACTION` above. [rad/s]
    omega2 : float
        Largest ω₂ = √(m₂/m₀) of the inputs (1.0 without inputs). [rad/s]
    k_load : float or None
        Wavenumber at the sea's ω₂ (None without a sea). [rad/m]
    """

    omega_lo: float
    omega_hi: float
    omega2: float
    k_load: float | None


def input_summary(scene: Scene) -> InputBand:
    """The :class:`InputBand` of a scene."""
    w_lo, w_hi, per = input_band(scene, PILOT_INPUT_FRACTION)
    w_lo = min(w_lo, input_band(scene, PILOT_LOW_FRACTION)[0])
    w2 = max((v[2] for v in per.values()), default=1.0)
    return InputBand(w_lo, w_hi, w2, sea_load_wavenumber(scene))


def sea_load_wavenumber(scene: Scene) -> float | None:
    """:attr:`InputBand.k_load` alone: the wavenumber at the sea spectrum's ω₂
    (:func:`sea_omega2`; None without a sea). [rad/m]"""
    w2 = sea_omega2(scene)
    if w2 is None:
        return None
    return float(wavenumber(w2, scene.environment.depth, scene.environment.g))


def sea_omega2(scene: Scene) -> float | None:
    """ω₂ = √(m₂/m₀) of the scene's sea spectrum, from one evaluation of its density
    (what the element check of every sea state of an engine needs,
    :mod:`stochcable.fidelity.mesh_check`); None without a sea. [rad/s]"""
    if scene.sea is None:
        return None
    s = np.asarray(scene.sea.spectrum.spectral_density(_WIDE, scene.environment.g), dtype=float)
    s = np.where(np.isfinite(s), s, 0.0)
    m0 = np.trapezoid(s, _WIDE)
    if not m0 > 0.0:
        return None
    return math.sqrt(np.trapezoid(_WIDE_SQ * s, _WIDE) / m0)


def base_error(scene: Scene, w_min: float, w_max: float, n: int) -> float:
    """Largest relative error of the trapezoid sums of S, ω²S, ω⁴S of every input on
    a linear grid of ``n`` points of [w_min, w_max] against a fine quadrature (the
    measure :func:`base_count` keeps within eps/2). [-]"""
    fine = np.linspace(w_min, w_max, 20001)
    x = np.linspace(w_min, w_max, n)
    worst = 0.0
    for _, d in input_densities(scene):
        s = np.asarray(d(fine), dtype=float)
        sx = np.interp(x, fine, s)
        for p in (0, 2, 4):
            ref = np.trapezoid(fine**p * s, fine)
            if ref > 0:
                worst = max(worst, abs(np.trapezoid(x**p * sx, x) / ref - 1.0))
    return float(worst)


def base_count(scene: Scene, w_min: float, w_max: float, eps: float) -> int:
    """Coarsest linear count whose trapezoid sums of S, ω²S, ω⁴S of every input on
    [w_min, w_max] are within eps/2 of a fine quadrature."""
    fine = np.linspace(w_min, w_max, 20001)
    dens = [np.asarray(d(fine), dtype=float) for _, d in input_densities(scene)]
    refs = [[np.trapezoid(fine**p * s, fine) for p in (0, 2, 4)] for s in dens]

    def ok(n: int) -> bool:
        x = np.linspace(w_min, w_max, n)
        for s, r in zip(dens, refs):
            sx = np.interp(x, fine, s)
            for p, rp in zip((0, 2, 4), r):
                if rp > 0 and abs(np.trapezoid(x**p * sx, x) / rp - 1.0) > eps / 2.0:
                    return False
        return True

    lo, hi = 8, 16
    while not ok(hi) and hi < 20000:
        lo, hi = hi, 2 * hi
    while hi - lo > 1:
        mid = (lo + hi) // 2
        lo, hi = (lo, mid) if ok(mid) else (mid, hi)
    return hi


# ------------------------------------------------------------------------ pilot


def response_spectra(line_result: Any) -> dict[str, np.ndarray]:
    """The pilot's response spectra of one line: both end tensions [N²·s/rad] and the
    line-summed motion [m²·s/rad], keyed "<line>.end_a.tension", ..., "<line>.motion"."""
    spectra = line_result.input_spectra
    out = {}
    for end in ("end_a", "end_b"):
        out[f"{line_result.name}.{end}.tension"] = np.einsum(
            "cw,cw->w", np.abs(line_result.end_tension_transfer[end]) ** 2, spectra
        )
    out[f"{line_result.name}.motion"] = np.einsum(
        "cnkw,cw->w", np.abs(line_result.motion_transfer) ** 2, spectra
    )
    return out


def modal_bandwidths(line_result: Any, scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """Natural frequencies and half-power bandwidths 2ζω of the pilot's modes."""
    model, modes, rec = line_result.model, line_result.modes, line_result.linearization
    wn = np.asarray(modes.omega, dtype=float)
    if rec is None or wn.size == 0:
        return wn, np.zeros_like(wn)
    c = drag_matrix(model, rec.b_normal, rec.b_axial)
    phi = modes.shapes[model.free]
    cff = c[model.free][:, model.free]
    band = np.einsum("ij,ij->j", phi, cff @ phi)
    sd = scene.analysis.structural_damping
    band = band + sd.alpha + sd.beta * wn**2
    return wn, np.maximum(band, 0.0)


def pilot_analysis(
    scene: Scene,
    geo: dict[str, LineGeometry],
    w_lo: float,
    w_top: float,
    k_load: float | None,
    exact: bool,
    evaluate: Evaluate,
) -> tuple[Any, dict, float]:
    """One pilot: ``evaluate`` on the scene meshed with kh = :data:`PILOT_KH` at
    ``w_top`` (at most :data:`PILOT_MAX_ELEMENTS` per line), a log grid of
    :data:`PILOT_COUNT` points on [w_lo, w_top], direct solve, tolerance 1e-3, no time
    series, warnings silenced.  Returns the result, its description and its wall time
    [s]."""
    eps_pilot = PILOT_KH**2 / 24.0
    segs, _, _ = mesh_rules(scene, geo, w_top, w_top, eps_pilot, k_load, exact)
    total = {k: sum(n for _, _, n in v) for k, v in segs.items()}
    for name, n in total.items():
        if n > PILOT_MAX_ELEMENTS:
            f = PILOT_MAX_ELEMENTS / n
            segs[name] = tuple((i, L, max(1, int(round(m * f)))) for i, L, m in segs[name])
    update = {
        "omega": scene.analysis.omega.model_copy(
            update={"min": w_lo, "max": w_top, "count": PILOT_COUNT, "spacing": "log"}
        ),
        "solver": "direct",
        "modes": "auto",
        "timeseries": None,
        "linearization": scene.analysis.linearization.model_copy(update={"tolerance": 1e-3}),
    }
    pscene = segments_scene(scene, segs, update)
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = evaluate(pscene)
    wall = time.perf_counter() - t0
    info = {
        "elements": {k: sum(n for _, _, n in v) for k, v in segs.items()},
        "omega_min": w_lo,
        "omega_max": w_top,
        "count": PILOT_COUNT,
        "spacing": "log",
        "wall_s": wall,
    }
    return res, info, wall


@dataclass(frozen=True, eq=False)
class Pilot:
    """The last pilot run: its result, response spectra on its grid ``omega``, whether
    every response tail beyond its top is bounded, and its description (``info``)."""

    result: Any
    spectra: dict[str, np.ndarray]
    omega: np.ndarray
    bounded: bool
    info: dict[str, Any]


def run_pilot(
    scene: Scene,
    geo: dict[str, LineGeometry],
    inputs: InputBand,
    band_share: float,
    exact: bool,
    evaluate: Evaluate,
    after: Pilot | None = None,
) -> Pilot:
    """Pilots from the input band, the top doubled up to :data:`PILOT_EXTENSIONS` times
    while a response tail beyond it holds more than ``band_share`` of the variance
    or the pilot does not cover twice the ω_max it gives.  ``after``: a pilot run
    for a larger ``band_share`` (the target's, before the model's own error was known
    from it), returned if it suffices for this one, else extended from its top, one
    doubling more allowed (the smaller share reaches further: the chain's PM surge at
    1 %, whose model leaves 0.5 %, needs the band to 83 rad/s, the pilot to 166)."""
    w_top, pilot_wall, first, cap = inputs.omega_hi, 0.0, 0, PILOT_EXTENSIONS
    if after is not None:
        cap += 1
        if pilot_suffices(after, band_share) or after.info["extensions"] >= cap:
            return after
        w_top = 2.0 * float(after.omega[-1])
        pilot_wall, first = after.info["wall_s"], after.info["extensions"] + 1
    for ext in range(first, cap + 1):
        res, info, wall = pilot_analysis(
            scene, geo, inputs.omega_lo, w_top, inputs.k_load, exact, evaluate
        )
        pilot_wall += wall
        pilot_info = {**info, "extensions": ext, "wall_s": pilot_wall}
        spectra: dict[str, np.ndarray] = {}
        for lr in res.lines.values():
            spectra.update(response_spectra(lr))
        w = next(iter(res.lines.values())).omega
        bounded = _tails_bounded(w, spectra, band_share)
        # the pilot must also *cover* [ω_max, 2·ω_max] (resonances in the tail make a
        # power-law extrapolation unreliable: on the chain it missed 3 % of the variance)
        covered = bounded and _covers_twice_omega_max(w, spectra, band_share)
        if (bounded and covered) or ext == cap:
            break
        w_top *= 2.0
    return Pilot(res, spectra, w, bounded, pilot_info)


def pilot_suffices(pilot: Pilot, band_share: float) -> bool:
    """Whether ``pilot`` bounds every response tail within ``band_share`` of its
    variance and covers twice the ω_max that share gives."""
    w, spectra = pilot.omega, pilot.spectra
    return _tails_bounded(w, spectra, band_share) and _covers_twice_omega_max(
        w, spectra, band_share
    )


def _tails_bounded(w: np.ndarray, spectra: dict[str, np.ndarray], band_share: float) -> bool:
    """Whether every response tail beyond the pilot's top is bounded and holds at most
    ``band_share`` of its variance."""
    bounded = True
    for s in spectra.values():
        if s.max() <= 0:
            continue
        ab = tail_above(w, s, tail_exponent(w, s))
        m0 = ab[0] + tail_below(w, s)[0]
        frac = (
            s[-1] * w[-1] / (tail_exponent(w, s) - 1.0) / m0
            if tail_exponent(w, s) > 1 + MIN_TAIL_EXCESS
            else math.inf
        )
        if not np.isfinite(ab[0]) or frac > band_share:
            bounded = False
    return bounded


def _covers_twice_omega_max(
    w: np.ndarray, spectra: dict[str, np.ndarray], band_share: float
) -> bool:
    """Whether the pilot's top reaches twice the ω_max of every response spectrum."""
    lim = 2.0 * band_share * 0.8
    covered = True
    for s in spectra.values():
        if s.max() <= 0:
            continue
        ab = tail_above(w, s, tail_exponent(w, s))
        m0 = ab[0] + tail_below(w, s)[0]
        if 2.0 * crossing_up(w, ab / m0, lim) > w[-1] * (1 + 1e-9):
            covered = False
    return covered
