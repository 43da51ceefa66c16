"""Fatigue settings of a load-case set: which curve, area or breaking strength, method and
design fatigue factor each line is checked with."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from stochcable.design import FatigueCurve, fatigue_curve, tension_to_curve_quantity
from stochcable.errors import InputError
from stochcable.scene.units import unit_labels

__all__ = ["LineFatigue", "curve_factor", "fatigue_from_document"]

_METHODS = ("narrow_band", "wirsching_light", "dirlik", "benasciutti_tovo")


@dataclass(frozen=True)
class LineFatigue:
    """How one line's fatigue is assessed.

    Attributes
    ----------
    curve : str or FatigueCurve
        A catalogue name (:func:`stochcable.design.curve_names`) or a curve.
    nominal_diameter : float or None
        Nominal bar diameter of a chain (area 2·πd²/4). [m]
    nominal_area : float or None
        Nominal area of the stress (a rope's metallic area). [m²]
    mbs : float or None
        Minimum breaking strength, for tension-ratio (API) curves. [force unit]
    mean_load_ratio : float or None
        Mean tension / MBS of the API wire-rope curves. [-]
    method : {"narrow_band", "wirsching_light", "dirlik", "benasciutti_tovo"}
        Spectral method.
    design_factor : float
        Design fatigue factor (DFF): the life is divided by it. [-]
    """

    curve: str | FatigueCurve = "dnv-studless"
    nominal_diameter: float | None = None
    nominal_area: float | None = None
    mbs: float | None = None
    mean_load_ratio: float | None = None
    method: str = "dirlik"
    design_factor: float = 1.0

    @classmethod
    def from_mapping(cls, doc: Mapping[str, Any], where: str = "fatigue") -> LineFatigue:
        """From a JSON mapping with the attribute names as keys."""
        known = {f for f in cls.__dataclass_fields__}
        extra = sorted(set(doc) - known)
        if extra:
            raise InputError(f"{where}.{extra[0]}", doc[extra[0]], "-", "unknown setting")
        units = {"nominal_diameter": "m", "nominal_area": "m²", "mbs": "force unit",
                 "mean_load_ratio": "-", "design_factor": "-"}  # fmt: skip
        for key, unit in units.items():
            v = doc.get(key)
            if key in doc and not (v is None and key != "design_factor"):
                ok = isinstance(v, (int, float)) and not isinstance(v, bool)
                if not (ok and math.isfinite(v) and v > 0):
                    raise InputError(f"{where}.{key}", v, unit, "must be a finite number > 0")
        for key in ("curve", "method"):
            if key in doc and not isinstance(doc[key], str):
                raise InputError(f"{where}.{key}", doc[key], "-", "must be a name (string)")
        out = cls(**dict(doc))
        out.check(where)
        return out

    def check(self, where: str = "fatigue") -> None:
        """Validate the settings (InputError naming ``where.<field>``)."""
        if self.method not in _METHODS:
            raise InputError(f"{where}.method", self.method, "-", f"must be one of {_METHODS}")
        if not (math.isfinite(self.design_factor) and self.design_factor >= 1.0):
            raise InputError(f"{where}.design_factor", self.design_factor, "-", "must be >= 1")


def curve_factor(settings: LineFatigue, g: float, where: str) -> tuple[FatigueCurve, float]:
    """The curve and the factor from the scene's force unit to the curve's quantity.

    Stress curves take pascals, so they need an SI scene; tension-ratio curves work in
    any consistent unit system (the MBS is in the scene's force unit).
    """
    curve = settings.curve
    if isinstance(curve, str):
        try:
            curve = fatigue_curve(curve, mean_load_ratio=settings.mean_load_ratio)
        except InputError as exc:
            field = "curve" if exc.parameter == "name" else exc.parameter
            raise InputError(f"{where}.{field}", exc.value, exc.unit, exc.constraint) from None
    labels = unit_labels(g)
    if curve.quantity == "stress" and labels.system != "SI":
        raise InputError(
            f"{where}.curve",
            curve.name,
            "-",
            f"takes stress in Pa, but the scene is in {labels.system} units: use a "
            "tension-ratio curve (api-*) with mbs in the scene's force unit",
        )
    try:
        k = tension_to_curve_quantity(
            curve,
            nominal_diameter=settings.nominal_diameter,
            nominal_area=settings.nominal_area,
            mbs=settings.mbs,
        )
    except InputError as exc:
        raise InputError(f"{where}.{exc.parameter}", exc.value, exc.unit, exc.constraint) from None
    return curve, k


def fatigue_from_document(
    doc: Mapping[str, Any] | None, lines: tuple[str, ...], where: str = "fatigue"
) -> dict[str, LineFatigue]:
    """Fatigue settings from a JSON document: one mapping of :class:`LineFatigue`'s
    attributes for every line, or a mapping of line name to such a mapping.

    Parameters
    ----------
    doc : mapping or None
        ``{"curve": "dnv-studless", "nominal_diameter": 0.076}`` or
        ``{"<line>": {...}, ...}``; None: no fatigue check.
    lines : tuple of str
        The scene's line names.
    where : str
        Name of the document in error messages.

    Returns
    -------
    dict of LineFatigue
        Validated settings per line name.
    """
    if doc is None:
        return {}
    if not isinstance(doc, Mapping):
        raise InputError(where, type(doc).__name__, "-", "must be a mapping")
    fields = set(LineFatigue.__dataclass_fields__)
    if set(doc) <= fields:
        one = LineFatigue.from_mapping(doc, where)
        return dict.fromkeys(lines, one)
    out = {}
    for name, sub in doc.items():
        if name not in lines:
            raise InputError(
                f"{where}.{name}", name, "-", f"names no line of the scene ({list(lines)}) "
                f"and is not a setting ({sorted(fields)})"
            )  # fmt: skip
        if not isinstance(sub, Mapping):
            raise InputError(f"{where}.{name}", type(sub).__name__, "-", "must be a mapping")
        out[name] = LineFatigue.from_mapping(sub, f"{where}.{name}")
    return out
