"""The linear model's own error against the nonlinear time domain, for the fidelity plan.

The fidelity plan controls the discretization (band, grid, elements, modes, fixed-point
tolerance): its parts converge to the *linear* frequency-domain answer.  The
linearization itself — the statistical (Borgman) drag linearization, the geometry
linearized about the static shape, the bed linearized about the static touchdown —
leaves an error against the nonlinear time domain that no fidelity removes.  This
module estimates it per line, from what the pilot analysis shows of the line, so that
a target below it is reported as not met instead of claimed
(:func:`linearization_model_error`).

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
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

__all__ = ["CALIBRATION", "Calibration", "linearization_model_error"]


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
        so = getattr(getattr(lr, "indicators", None), "second_order", None)
        factor = getattr(so, "std_factor", None)
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
