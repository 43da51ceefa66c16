"""Directional spreading documents of the scene: a short-crested sea (the functions
are :mod:`stochcable.sea.spreading`'s; ``type`` is the discriminator)."""

from __future__ import annotations

import math
from typing import Annotated, Literal

import numpy as np
from pydantic import ConfigDict, Field, model_validator

from stochcable.scene.base import _Doc, _f
from stochcable.scene.spectra import _type_required
from stochcable.sea.limits import SPREADING_EXPONENT_MAX

__all__ = ["MAX_DIRECTIONS", "Cos2sSpreading", "CosnSpreading", "TableSpreading", "Spreading"]

#: Most discrete directions of a spread sea (each is an input channel of every line). [-]
MAX_DIRECTIONS = 64


def _directions() -> int:
    return Field(
        default=16,
        ge=1,
        le=MAX_DIRECTIONS,
        description="Discrete directions: equal bins over the spreading's support, each "
        "with the exact share of the spreading and its centroid heading [-]",
        json_schema_extra={"unit": "-"},
    )


class _SpreadingBase(_Doc):
    model_config = ConfigDict(json_schema_extra=_type_required)

    def direction_set(self, mean_deg: float):
        """The discrete directions about the mean heading ``mean_deg`` [deg]
        (:class:`stochcable.sea.spreading.DirectionSet`, headings in rad)."""
        raise NotImplementedError  # pragma: no cover - every subclass overrides


class Cos2sSpreading(_SpreadingBase):
    """Cosine-2s spreading D ∝ cos^{2s}((θ − θ̄)/2) over the whole circle
    (Longuet-Higgins et al. 1963; DNV-RP-C205 §3.5.8)."""

    type: Literal["cos2s"] = "cos2s"
    s: float = _f("Spreading exponent s (larger: narrower)", "-", gt=0, le=SPREADING_EXPONENT_MAX)
    directions: int = _directions()

    def direction_set(self, mean_deg: float):
        from stochcable.sea.spreading import directions_cos2s

        return directions_cos2s(math.radians(mean_deg), self.s, self.directions)


class CosnSpreading(_SpreadingBase):
    """Cosine-power spreading D ∝ cosⁿ(θ − θ̄) for |θ − θ̄| ≤ 90° (DNV-RP-C205
    §3.5.8: n = 2–4 wind sea, n ≥ 6 swell)."""

    type: Literal["cosn"] = "cosn"
    n: float = _f("Spreading exponent n (larger: narrower)", "-", gt=0, le=SPREADING_EXPONENT_MAX)
    directions: int = _directions()

    def direction_set(self, mean_deg: float):
        from stochcable.sea.spreading import directions_cosn

        return directions_cosn(math.radians(mean_deg), self.n, self.directions)


class TableSpreading(_SpreadingBase):
    """Spreading as a table of directions relative to the mean heading and their
    relative weights (normalized to sum 1)."""

    type: Literal["table"] = "table"
    offset: list[float] = _f(
        "Directions relative to the sea's heading, distinct", "deg", min_length=1,
        max_length=MAX_DIRECTIONS,
    )  # fmt: skip
    weight: list[float] = _f(
        "Relative weight of each direction, >= 0, not all zero", "-", min_length=1,
        max_length=MAX_DIRECTIONS,
    )  # fmt: skip

    @model_validator(mode="after")
    def _check(self) -> TableSpreading:
        if len(self.weight) != len(self.offset):
            raise ValueError(
                f"weight has {len(self.weight)} values: give one per offset ({len(self.offset)})"
            )
        if any(w < 0 for w in self.weight):
            raise ValueError(f"weight {self.weight}: every weight must be >= 0")
        if not sum(self.weight) > 0:
            raise ValueError("weight: not all zero (the spreading cannot be normalized)")
        if len(set(self.offset)) != len(self.offset):
            raise ValueError(f"offset {self.offset}: the directions must be distinct")
        return self

    def direction_set(self, mean_deg: float):
        from stochcable.sea.spreading import directions_table

        return directions_table(
            np.radians(np.asarray(self.offset, dtype=float) + mean_deg), self.weight
        )


Spreading = Annotated[
    Cos2sSpreading | CosnSpreading | TableSpreading,
    Field(discriminator="type"),
]
