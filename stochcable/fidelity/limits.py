"""The limits of the scene model that a fidelity plan must respect.

The planner never builds a scene the model would reject: the bounds are read from the
pydantic models' own constraints (``OmegaGrid.count``, ``Segment.elements``,
``Line.segments``), not copied here, so a change of the model moves the planner with it.
:func:`planned_scene_error` turns a rejection that still happens (a constraint between
fields the planner does not model) into an :class:`~stochcable.errors.InputError`
naming the fidelity request.
"""

from __future__ import annotations

import math
from typing import Any

from pydantic import BaseModel, ValidationError

from stochcable.errors import InputError
from stochcable.scene.model import OmegaGrid, Scene, Segment, input_error_from_validation

__all__ = [
    "check_plan_memory",
    "field_bound",
    "omega_count_limit",
    "elements_limit",
    "planned_scene_error",
    "clip",
]


def field_bound(model: type[BaseModel], name: str, kind: str) -> float:
    """The bound ``kind`` ("le", "lt", "ge", "gt", "max_length", "min_length") of a
    field of a pydantic model, from its constraints (inf / -inf when it has none)."""
    for meta in model.model_fields[name].metadata:
        value = getattr(meta, kind, None)
        if value is not None:
            return float(value)
    return math.inf if kind in ("le", "lt", "max_length") else -math.inf


def omega_count_limit() -> int:
    """Largest ``analysis.omega.count`` the scene model accepts."""
    le, lt = field_bound(OmegaGrid, "count", "le"), field_bound(OmegaGrid, "count", "lt")
    return int(min(le, lt - 1))


def elements_limit() -> int:
    """Largest ``lines[*].segments[*].elements`` the scene model accepts."""
    le, lt = field_bound(Segment, "elements", "le"), field_bound(Segment, "elements", "lt")
    return int(min(le, lt - 1))


def planned_scene_error(exc: ValidationError, target_error: float) -> InputError:
    """An :class:`InputError` for a planned scene the model rejects: it names the
    request ``analysis.fidelity.target_error``, its value and the constraint the plan
    could not meet (the model's own message, with its parameter path)."""
    inner = input_error_from_validation(exc, Scene)
    return InputError(
        "analysis.fidelity.target_error",
        target_error,
        "-",
        "no admissible plan: the settings this target needs break a limit of the scene "
        f"model ({inner}); use a larger target error",
    )


def clip(value: Any, limit: int) -> tuple[int, bool]:
    """``min(value, limit)`` and whether it was clipped."""
    v = int(value)
    return (limit, True) if v > limit else (v, False)


def check_plan_memory(planned: Scene, target_error: float) -> None:
    """Refuse a planned scene whose estimated peak memory
    (:func:`stochcable.cost.estimate_cost`) exceeds the memory available now: an
    InputError naming ``analysis.fidelity.target_error``, the estimate and the fix."""
    from stochcable.cost import available_memory, estimate_cost

    estimate, free = estimate_cost(planned), available_memory()
    if estimate.memory_bytes > free:
        raise InputError(
            "analysis.fidelity.target_error",
            target_error,
            "-",
            f"the plan for this target needs an {estimate.describe()}, more than the "
            f"memory available now ({free / 2**30:.3g} GiB): ask for a larger target error",
        )
