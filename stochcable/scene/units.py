"""Unit labels of a scene's consistent unit system, for messages and documents.

Scenes are in consistent units (DESIGN.md "Units and frames"): SI by default, the
seeds' imperial examples in feet, slugs and pounds-force.  The numbers never need
conversion, but a message that says "mean tension 100 N" about a scene in pounds is
wrong to its reader.  The unit system is read off the gravitational acceleration the
scene gives, the one dimensional constant every scene carries:

- g within 1 % of 9.80665 m/s²  -> SI (m, kg, N);
- g within 1 % of 32.174 ft/s²  -> foot–slug–second (ft, slug, lbf);
- anything else                 -> generic labels ("length unit", ...), since no
  other system is recognised.

A scene whose ``g`` and lengths disagree (g in m/s², lengths in feet) is inconsistent
and gets SI labels; nothing here can detect that.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

__all__ = ["UnitLabels", "unit_labels", "labels_of_document", "SI", "FOOT_SLUG_SECOND"]

#: Standard gravity. [m/s²]
G_SI = 9.80665
#: Standard gravity in feet. [ft/s²]
G_FOOT = G_SI / 0.3048
#: Relative band around each standard g that identifies the system. [-]
G_MATCH = 0.01


@dataclass(frozen=True)
class UnitLabels:
    """Labels of a consistent unit system.

    Attributes
    ----------
    system : str
        ``"SI"``, ``"foot-slug-second"`` or ``"consistent"`` (unrecognised).
    length, mass, force, time : str
        Unit labels.
    """

    system: str
    length: str
    mass: str
    force: str
    time: str = "s"

    @property
    def velocity(self) -> str:
        """Velocity label."""
        return f"{self.length}/s"

    @property
    def force_per_length(self) -> str:
        """Force per unit length (weight per length, stiffness of a unit motion)."""
        return f"{self.force}/{self.length}"

    def convert(self, unit: str) -> str:
        """An SI unit label (a scene field's, e.g. ``"kg/m"``, ``"N·m/rad"``) in this system.

        The SI base symbols m, kg, N and Pa are replaced as whole symbols (``"m²"`` ->
        ``"ft²"``, ``"Pa/m"`` -> ``"(lbf/ft²)/ft"``); s, rad, deg and "-" are kept.
        Labels only: the numbers of a consistent scene need no conversion.

        Parameters
        ----------
        unit : str
            A unit label in SI symbols. [-]

        Returns
        -------
        str
            The label in this system's symbols. [-]
        """
        if self.system == "SI" or not unit:
            return unit
        table = {
            "m": self.length,
            "kg": self.mass,
            "N": self.force,
            "Pa": f"({self.force}/{self.length}²)",
        }
        return _SI_SYMBOL.sub(lambda mt: table[mt.group(0)], unit)

    def as_dict(self) -> dict[str, str]:
        """The labels as a JSON-ready mapping."""
        return {
            "system": self.system,
            "length": self.length,
            "mass": self.mass,
            "force": self.force,
            "time": self.time,
        }


#: Whole SI symbols in a unit label (not the "m" of "mm" or of a word).
_SI_SYMBOL = re.compile(r"(?<![A-Za-z])(?:kg|Pa|m|N)(?![A-Za-z])")

SI = UnitLabels("SI", "m", "kg", "N")
FOOT_SLUG_SECOND = UnitLabels("foot-slug-second", "ft", "slug", "lbf")
_GENERIC = UnitLabels("consistent", "length unit", "mass unit", "force unit")


def unit_labels(g: float) -> UnitLabels:
    """Unit labels of the consistent system a scene's gravity implies.

    Parameters
    ----------
    g : float
        The scene's gravitational acceleration (``environment.g``). [length unit/s²]

    Returns
    -------
    UnitLabels
        SI for g ≈ 9.80665, foot–slug–second for g ≈ 32.174 (each within
        :data:`G_MATCH`), generic labels otherwise.
    """
    g = float(g)
    if abs(g / G_SI - 1.0) <= G_MATCH:
        return SI
    if abs(g / G_FOOT - 1.0) <= G_MATCH:
        return FOOT_SLUG_SECOND
    return _GENERIC


def labels_of_document(document: Any) -> UnitLabels:
    """Unit labels of a scene document that may not be valid (for its error messages).

    Parameters
    ----------
    document : Any
        The scene as received (a mapping, or anything else). [-]

    Returns
    -------
    UnitLabels
        :func:`unit_labels` of ``environment.g`` when it is a finite positive number,
        SI otherwise (the scene's default g).
    """
    env = document.get("environment") if isinstance(document, Mapping) else None
    g = env.get("g") if isinstance(env, Mapping) else None
    if isinstance(g, bool) or not isinstance(g, (int, float)) or not math.isfinite(g) or g <= 0:
        return SI
    return unit_labels(g)
