"""Design verification: fatigue curves, spectral and rainflow fatigue damage, and
short- and long-term extremes of a linear Gaussian response.

Pure functions on spectra, time series and sea-state statistics; the load-case sets
that call them over a scatter diagram live above this package.

Modules: :mod:`~stochcable.design.curves` (S-N and T-N curves),
:mod:`~stochcable.design.spectral_fatigue`, :mod:`~stochcable.design.rainflow_fatigue`
and :mod:`~stochcable.design.extremes`.  Their names below are imported on first use:
an analysis needs only the curves (the strumming screen), not the special functions of
SciPy that fatigue and extremes need.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .curves import (
        CurveSegment,
        FatigueCurve,
        curve_names,
        fatigue_curve,
        fatigue_curve_user,
        tension_to_curve_quantity,
    )
    from .extremes import (
        SECONDS_PER_YEAR,
        long_term_exceedance,
        maxima_exceedance_short_term,
        maximum_exceedance_rayleigh,
        mpm_short_term,
        return_level,
    )
    from .rainflow_fatigue import damage_rainflow, rainflow_ranges
    from .spectral_fatigue import (
        damage_rate,
        damage_rate_benasciutti_tovo,
        damage_rate_dirlik,
        damage_rate_narrow_band,
        damage_rate_wirsching_light,
        spectral_moments_along,
    )

#: The module of each public name.
_MODULE = {
    "CurveSegment": "curves",
    "FatigueCurve": "curves",
    "curve_names": "curves",
    "fatigue_curve": "curves",
    "fatigue_curve_user": "curves",
    "tension_to_curve_quantity": "curves",
    "SECONDS_PER_YEAR": "extremes",
    "long_term_exceedance": "extremes",
    "maxima_exceedance_short_term": "extremes",
    "maximum_exceedance_rayleigh": "extremes",
    "mpm_short_term": "extremes",
    "return_level": "extremes",
    "damage_rainflow": "rainflow_fatigue",
    "rainflow_ranges": "rainflow_fatigue",
    "damage_rate": "spectral_fatigue",
    "damage_rate_benasciutti_tovo": "spectral_fatigue",
    "damage_rate_dirlik": "spectral_fatigue",
    "damage_rate_narrow_band": "spectral_fatigue",
    "damage_rate_wirsching_light": "spectral_fatigue",
    "spectral_moments_along": "spectral_fatigue",
}

__all__ = [
    "SECONDS_PER_YEAR",
    "CurveSegment",
    "FatigueCurve",
    "curve_names",
    "fatigue_curve",
    "fatigue_curve_user",
    "tension_to_curve_quantity",
    "damage_rate",
    "damage_rate_narrow_band",
    "damage_rate_wirsching_light",
    "damage_rate_dirlik",
    "damage_rate_benasciutti_tovo",
    "spectral_moments_along",
    "damage_rainflow",
    "rainflow_ranges",
    "maxima_exceedance_short_term",
    "maximum_exceedance_rayleigh",
    "mpm_short_term",
    "long_term_exceedance",
    "return_level",
]


def __getattr__(name: str) -> Any:
    """A public name of the package, its module imported on first use."""
    if name in _MODULE:
        value = getattr(importlib.import_module(f".{_MODULE[name]}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
