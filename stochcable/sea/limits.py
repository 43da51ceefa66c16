"""The accepted ranges of the sea's parameters: one table that the spectrum and
spreading functions (:mod:`stochcable.sea.spectra`, :mod:`stochcable.sea.spreading`), the
scene's models (:mod:`stochcable.scene.spectra`, :mod:`stochcable.scene.spreading`) and the
command line (``stochcable spectrum``, ``stochcable simulate``) all read.

Each range is ``(lo, hi)``, both ends accepted unless the name says otherwise.  The
ranges are far wider than any sea (model basin to swell, in metres or feet) and narrow
enough that ωp⁴, Hs², Γ(λ) and the JONSWAP peak shape stay finite in float64: a value
outside is a data error, reported as such instead of as an overflow.
"""

from __future__ import annotations

import math

__all__ = [
    "HEIGHT_RANGE",
    "PERIOD_RANGE",
    "OMEGA_P_RANGE",
    "M0_RANGE",
    "WIND_SPEED_RANGE",
    "GAMMA_RANGE",
    "SIGMA_RANGE",
    "SHAPE_RANGE",
    "SPREADING_EXPONENT_MAX",
]

HEIGHT_RANGE = (1e-6, 1e4)
"""Significant wave heights Hs. [m] (or the scene's length unit)"""

PERIOD_RANGE = (1e-3, 1e5)
"""Periods (Tp, T1). [s]"""

OMEGA_P_RANGE = (2.0 * math.pi / PERIOD_RANGE[1], 2.0 * math.pi / PERIOD_RANGE[0])
"""Peak angular frequencies ωp = 2π/Tp of the periods above. [rad/s]"""

M0_RANGE = (HEIGHT_RANGE[0] ** 2 / 16.0, HEIGHT_RANGE[1] ** 2 / 16.0)
"""Zeroth spectral moments m0 = Hs²/16 of the heights above. [m²]"""

WIND_SPEED_RANGE = (1e-3, 1e3)
"""Wind speeds at 19.5 m (Pierson–Moskowitz fully developed sea). [m/s]"""

GAMMA_RANGE = (1, 20)
"""JONSWAP peak enhancement factors γ (γ = 1 is Pierson–Moskowitz). [-]"""

SIGMA_RANGE = (1e-3, 1)
"""JONSWAP peak widths σa, σb.  Below 1e-3 the peak is resolved by no frequency grid of
the service's size (and below ~1e-150 ((ω/ωp − 1)/σ)² overflows). [-]"""

SHAPE_RANGE = (1e-2, 100)
"""Ochi–Hubble shape factors λ. [-]"""

SPREADING_EXPONENT_MAX = 1e6
"""Largest exponent s of cos-2s and n of cosⁿ spreading (> 0; a larger one is a
long-crested sea to round-off). [-]"""
