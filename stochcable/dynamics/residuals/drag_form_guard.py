"""The drag residual's scope by drag form: skip lines with ``drag_form = "hu_jin"``.

The drag residual (:mod:`stochcable.dynamics.residuals.drag_residual`) expands the
cross-flow drag |v|v of each element in Hermite polynomials of its normal relative
velocity; the Hu & Jin form |V|V_n (docs/travelling.md) also depends on the axial
relative flow, and that expansion is not derived.  Such a line gets a not-computed
record and a PhysicsWarning naming the reason, never a residual of the wrong form.
"""

from __future__ import annotations

from typing import Any

from stochcable.errors import PhysicsWarning, warn
from stochcable.results.records import ResidualRecord

__all__ = ["HU_JIN_REASON", "guard_drag_form"]

HU_JIN_REASON = (
    "drag_form 'hu_jin': the drag residual expands the cross-flow drag |v|v only "
    "(the |V|V_n expansion is not derived; docs/travelling.md)"
)


def guard_drag_form(compute: Any) -> Any:
    """``compute`` (a residual kind's function) skipping lines with the Hu & Jin drag."""

    def guarded(system: Any, channels: Any, linearization: Any, std: dict, **kw: Any):
        if getattr(system.model.mesh, "drag_form", "cross_flow") == "hu_jin":
            warn(
                f"line '{system.name}': drag residual not computed: {HU_JIN_REASON}", PhysicsWarning
            )
            return ResidualRecord.not_computed(HU_JIN_REASON, std)
        return compute(system, channels, linearization, std, **kw)

    guarded.__doc__ = compute.__doc__
    return guarded
