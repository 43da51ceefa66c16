"""Design verification: fatigue curves, spectral and rainflow fatigue damage, and
short- and long-term extremes of a linear Gaussian response.

Pure functions on spectra, time series and sea-state statistics; the load-case sets
that call them over a scatter diagram live above this package.
"""

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
