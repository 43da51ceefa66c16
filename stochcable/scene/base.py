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
