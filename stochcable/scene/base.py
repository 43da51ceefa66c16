"""The base of the scene's pydantic models: frozen documents whose fields carry units."""

from __future__ import annotations

from typing import Any

from pydantic import BaseModel, ConfigDict, Field

G_STANDARD = 9.80665  # standard gravity [m/s²]
RHO_SEAWATER = 1025.0  # sea water density [kg/m³]


def _f(description: str, unit: str, **kw: Any) -> Any:
    """A pydantic Field whose description carries the unit, as ``text [unit]``."""
    extra = {"unit": unit}
    return Field(description=f"{description} [{unit}]", json_schema_extra=extra, **kw)


class _Doc(BaseModel):
    model_config = ConfigDict(frozen=True, extra="forbid", allow_inf_nan=False)


class LocatedValueError(ValueError):
    """A ValueError of a check across fields (a model validator) that names the one field
    it is about: ``loc``, its location relative to the validated model
    (``("lines", 0, "end_b", "position")``), and ``value``, the field's value.  The
    converters of validation errors (:func:`stochcable.scene.model.error_location`)
    report that field instead of the enclosing model."""

    def __init__(self, loc: tuple[str | int, ...], value: Any, message: str) -> None:
        super().__init__(message)
        self.loc = tuple(loc)
        self.value = value
