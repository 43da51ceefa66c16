"""The linear model's own error against the nonlinear time domain, for the fidelity plan.

The fidelity plan controls the discretization (band, grid, elements, modes, fixed-point
tolerance): its parts converge to the *linear* frequency-domain answer.  The
linearization itself — the statistical (Borgman) drag linearization, the geometry
linearized about the static shape, the bed linearized about the static touchdown —
leaves an error against the nonlinear time domain that no fidelity removes.  This
module estimates it per line, from what the pilot analysis shows of the line, so that
a target below it is reported as not met instead of claimed
(:func:`linearization_model_error`).

Where the analysis computes the residuals of the linear model
(``analysis.linearization.drag_residual``, :mod:`stochcable.dynamics.residuals`) its
answer is the corrected σ, and the estimate is what the computed residuals leave, not a
calibration constant (:func:`residual_model_error`):

- the residuals are the first-order term of the response's Wiener–Hermite expansion
  about the equivalent linear system (Roberts and Spanos, §5): what they drop — their
  feedback on the linearized damping and on themselves — is one order higher, so a line
  whose computed residuals move its end-tension σ by the share r is left with ≈ r²
  (the larger end).  Against the nonlinear time domain (docs/benchmarks/drag_residual.md,
  TD / (FD + residuals) − 1): the chain's line +0.40 ± 1.9 / +0.17 ± 2.6 % (r = 4.7 /
  8.2 %, r² = 0.2 / 0.7 %), the taut wire +1.5 ± 2.9 % (r = 18 %, r² = 3.4 %), the
  inclined guy −0.6 ± 3.7 % (r = 19 %, r² = 3.5 %): every measured remainder within r²
  and its interval, none resolving it — an order estimate, not a calibrated bound;
- a line with a static grounded length adds what no residual covers, the one-sided
  bed: +0.30 ± 0.14 / +0.45 ± 0.23 % (fairlead / anchor, docs/benchmarks/fd_budget.md,
  the reference TD with it against without), :data:`BED_ERROR`;
- without the geometric residual, the second-order stretching term below still counts
  (it is part of the geometric residual when that is computed).

A line whose drag residual was not computed (not asked, or out of its scope: the
record's reason) keeps the linear model's estimate:

Two terms, the larger counts:

- **Second-order stretching** of near-straight lines: the linear tension misses the
  quadratic term EA/(2L)∫(∂u⊥/∂s)² ds; the pilot's indicators carry its σ as the
  factor √(1 + r²) on the linear σ (:mod:`stochcable.dynamics.residuals.second_order`), so the
  shortfall is 1 − 1/√(1 + r²).
- **Calibrated shortfall** of the linear answer against the reconciled time-domain
  reference (the project's nonlinear reference simulator, itself within 0.26 % of
  MoorDyn; docs/benchmarks/moordyn.md; the budget of the shortfall by term:
  docs/benchmarks/fd_budget.md), per class of line (:data:`CALIBRATION`):
  lines that touch the seabed (catenaries, where the moving touchdown, the one-sided
  bed and the quadratic drag of the transverse motion act) and lines that do not.
  The figures are the measured relative errors of the fairlead and anchor tension σ
  with their source; the estimate takes the larger end.

References
----------
Roberts, J. B. and Spanos, P. D. (2003), Random Vibration and Statistical
Linearization, Dover, §5 (the Wiener–Hermite expansion about the equivalent linear
system).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

__all__ = [
    "BED_ERROR",
    "CALIBRATION",
    "Calibration",
    "linearization_model_error",
    "residual_model_error",
]

#: The one-sided seabed's share of the σ error, which no residual covers: +0.30 ± 0.14 %
#: / +0.45 ± 0.23 % at the fairlead / anchor (docs/benchmarks/fd_budget.md, the chain's
#: line at 160 elements, the reference TD with the one-sided bed against the bilateral
#: one); the larger end. [-]
BED_ERROR = 0.0045


@dataclass(frozen=True)
class Calibration:
    """Measured error of the linear FD tension σ against the nonlinear time domain.

    Attributes
    ----------
    fairlead, anchor : float
        |σ_FD/σ_TD − 1| at the two ends (the largest over the calibration lines). [-]
    lines : str
        The lines measured. [-]
    source : str
        Where the figures come from and how to regenerate them. [-]
    """

    fairlead: float
    anchor: float
    lines: str
    source: str

    @property
    def error(self) -> float:
        """The larger end's error. [-]"""
        return max(self.fairlead, self.anchor)


#: Calibration per line class: "touchdown" (a static grounded length) and "suspended".
CALIBRATION: dict[str, Calibration] = {
    "touchdown": Calibration(
        fairlead=0.049,
        anchor=0.077,
        lines="the chain_catenary example's line (850 m chain, 200 m water; the "
        "largest) and a 1,000 m wire catenary in deep water, fairlead surge PM Hs 2 m "
        "Tp 10 s",
        source="docs/benchmarks/fd_budget.md: the nonlinear TD σ +5.1 ± 2.0 % / "
        "+8.3 ± 2.8 % above the FD (fairlead / anchor; 160 elements in both, 5 seeds, "
        "whole DSA periods; mostly the quadratic drag the Borgman linearization drops); "
        "docs/accuracy/lines.md: the deep catenary −2.4 ± 1.1 % / −3.3 ± 0.9 % (FD and TD "
        "on the same 160-element line)",
    ),
    "suspended": Calibration(
        fairlead=0.0002,
        anchor=0.0002,
        lines="a taut synthetic rope (no seabed contact), the same surge",
        source="docs/benchmarks/moordyn.md: FD σ +0.01 % against the reference "
        "simulator (itself within 0.03 % of MoorDyn) at both ends",
    ),
}


def linearization_model_error(
    pilot_lines: Mapping[str, Any], touchdown: Mapping[str, float | None]
) -> tuple[float, str]:
    """The linear model's estimated σ error against the nonlinear time domain.

    Parameters
    ----------
    pilot_lines : mapping of line name to line result
        The pilot analysis's lines (their ``indicators.second_order``, when present).
    touchdown : mapping of line name to float or None
        Static touchdown arc length of each line (None: no seabed contact). [m]

    Returns
    -------
    error : float
        The largest estimate over the lines (relative σ error). [-]
    basis : str
        Which line and term give it, and the calibration's source.
    """
    best, basis = 0.0, "no line"
    for name, lr in pilot_lines.items():
        klass = "touchdown" if touchdown.get(name) is not None else "suspended"
        cal = CALIBRATION[klass]
        err, why = cal.error, f"line {name!r} ({klass}): calibrated on {cal.lines}; {cal.source}"
        residuals = getattr(lr, "residuals", None) or {}
        drag = residuals.get("drag_residual")
        if drag is not None and drag.computed:
            err, why = residual_model_error(name, lr, klass == "touchdown")
        elif drag is not None:
            why += f" (the drag residual was not computed: {drag.reason})"
        geometric = residuals.get("geometric_residual")
        so = getattr(getattr(lr, "indicators", None), "second_order", None)
        factor = getattr(so, "std_factor", None)
        if geometric is not None and geometric.computed:
            factor = None  # (the stretching is part of the geometric residual)
        if factor is not None and math.isfinite(factor) and factor > 1.0:
            stretch = 1.0 - 1.0 / factor
            if stretch > err:
                err = stretch
                why = (
                    f"line {name!r}: second-order stretching of a near-straight line, "
                    f"the linear σ low by the factor {factor:.3f} "
                    "(stochcable.dynamics.residuals.second_order)"
                )
        if err > best:
            best, basis = err, why
    return best, basis


def residual_model_error(name: str, line_result: Any, grounded: bool) -> tuple[float, str]:
    """The error the computed residuals leave of one line's corrected end-tension σ
    (module notes): r² of the residuals' share r = max over the ends of |σ/σ_linear −
    1|, plus :data:`BED_ERROR` on a line with a grounded length.

    Parameters
    ----------
    name : str
        The line's name (for the basis).
    line_result : LineResult
        A line result whose drag residual was computed (its ``end_a``/``end_b`` the
        corrected statistics, ``linear_end(end)`` the linear ones).
    grounded : bool
        Whether the line has a static grounded length.

    Returns
    -------
    error : float
        The estimate (relative σ error). [-]
    basis : str
        The share, the end and the terms.
    """
    share, end = 0.0, "end_b"
    for e in ("end_a", "end_b"):
        lin = line_result.linear_end(e).std
        if lin > 0.0:
            r = abs(getattr(line_result, e).std / lin - 1.0)
            if r > share:
                share, end = r, e
    err = share * share + (BED_ERROR if grounded else 0.0)
    why = (
        f"line {name!r}: the computed residuals change the {end} tension σ by "
        f"{100 * share:.3g} %; the corrected σ's remaining error is estimated as its "
        f"square, {100 * share * share:.2g} % (the next order of the residuals' "
        "expansion; stochcable.fidelity.model_error)"
    )
    if grounded:
        why += f", plus the one-sided bed's {100 * BED_ERROR:.2g} % (docs/benchmarks/fd_budget.md)"
    return err, why
