"""Adaptive fidelity: elements, frequencies, modes and tolerance chosen for an error
target.

Modules, lowest first: :mod:`~stochcable.fidelity.rules` (the error → resolution
rules and constants), :mod:`~stochcable.fidelity.plan` (:class:`FidelityPlan`),
:mod:`~stochcable.fidelity.limits` (the scene model's limits a plan respects),
:mod:`~stochcable.fidelity.meshing` (the element rules on a scene),
:mod:`~stochcable.fidelity.pilot` (input band and pilot analysis) and
:mod:`~stochcable.fidelity.planner` (:func:`choose_fidelity`, :func:`apply_fidelity`).
The pilot analysis is passed in (``choose_fidelity(..., evaluate=analyze)``): this
package does not import the analysis that uses it.  The planner is imported on first
use: every analysis imports :mod:`~stochcable.fidelity.mesh_check` (the element check),
only a fidelity target the planner.
"""

from typing import TYPE_CHECKING, Any

from stochcable.fidelity.meshing import static_touchdowns
from stochcable.fidelity.plan import Choice, FidelityPlan

if TYPE_CHECKING:
    from stochcable.fidelity.planner import apply_fidelity, choose_fidelity
from stochcable.fidelity.rules import (
    BUDGET,
    CUTOFF_KH,
    elements_wavelength,
    points_per_bandwidth,
    spectrum_tail_frequency,
)

__all__ = [
    "BUDGET",
    "CUTOFF_KH",
    "Choice",
    "FidelityPlan",
    "spectrum_tail_frequency",
    "elements_wavelength",
    "points_per_bandwidth",
    "choose_fidelity",
    "apply_fidelity",
    "static_touchdowns",
]


def __getattr__(name: str) -> Any:
    """:func:`choose_fidelity` and :func:`apply_fidelity`, imported on first use."""
    if name in ("choose_fidelity", "apply_fidelity"):
        from stochcable.fidelity import planner

        return getattr(planner, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
