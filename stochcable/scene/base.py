"""The base of the scene's pydantic models: frozen documents whose fields carry units."""

from __future__ import annotations

import typing
from typing import Any

from pydantic import BaseModel, ConfigDict, Field, model_validator

G_STANDARD = 9.80665  # standard gravity [m/s²]
RHO_SEAWATER = 1025.0  # sea water density [kg/m³]


def _f(description: str, unit: str, **kw: Any) -> Any:
    """A pydantic Field whose description carries the unit, as ``text [unit]``."""
    extra = {"unit": unit}
    return Field(description=f"{description} [{unit}]", json_schema_extra=extra, **kw)


def _admits_bool(annotation: Any) -> bool:
    if annotation is bool or annotation is Any:
        return True
    return any(_admits_bool(a) for a in typing.get_args(annotation))


def _bool_at(value: Any) -> tuple[int, ...] | None:
    """Where a bool sits in a value or its (nested) lists; None if nowhere."""
    if isinstance(value, bool):
        return ()
    if isinstance(value, (list, tuple)):
        for i, item in enumerate(value):
            at = _bool_at(item)
            if at is not None:
                return (i, *at)
    return None


class _Doc(BaseModel):
    # defer_build: a part's validator is built on its first use on its own, not at
    # import: the scene's validator, built at import, holds them all (9 ms less,
    # docs/benchmarks/first_analysis.md); a model that an HTTP body extends is built at
    # import too (FastAPI warns on a deferred body)
    model_config = ConfigDict(frozen=True, extra="forbid", allow_inf_nan=False, defer_build=True)

    @model_validator(mode="before")
    @classmethod
    def _numbers_are_not_bools(cls, data: Any) -> Any:
        # pydantic's lax mode reads true/false as 1/0 where a number is expected, and
        # 0/1 or "yes" where a bool is; either is a mistake in a document
        if isinstance(data, dict):
            for name, field in cls.model_fields.items():
                key = field.alias or name
                if key not in data:
                    continue
                value = data[key]
                if field.annotation is bool and not isinstance(value, bool):
                    raise LocatedValueError((key,), value, f"{key} must be true or false")
                if not _admits_bool(field.annotation):
                    at = _bool_at(value)
                    if at is not None:
                        raise LocatedValueError(
                            (key, *at), value, f"{key} must be a number, not true/false"
                        )
        return data


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
