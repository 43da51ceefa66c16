"""Spectrum documents of the scene: a sea state or an end motion as a spectrum
(the formulas are :mod:`stochcable.sea.spectra`'s; ``type`` is the discriminator).

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

import numpy as np
from pydantic import ConfigDict, Field, model_validator

from stochcable.scene.base import G_STANDARD, LocatedValueError, _Doc, _f
from stochcable.sea.limits import (
    GAMMA_RANGE,
    HEIGHT_RANGE,
    M0_RANGE,
    OMEGA_P_RANGE,
    PERIOD_RANGE,
    SHAPE_RANGE,
    SIGMA_RANGE,
    WIND_SPEED_RANGE,
)

__all__ = [
    "PiersonMoskowitz",
    "Jonswap",
    "Bretschneider",
    "Issc",
    "OchiHubble",
    "TableSpectrum",
    "Spectrum",
]


def _in(description: str, unit: str, limits: tuple[float, float], **kw: Any) -> Any:
    """A field of :func:`stochcable.scene.base._f` in ``limits`` (both ends accepted):
    one of the ranges of :mod:`stochcable.sea.limits`, which the sea's functions check."""
    return _f(description, unit, ge=limits[0], le=limits[1], **kw)


def _type_required(schema: dict[str, Any]) -> None:
    """``type`` selects the member of the discriminated union :data:`Spectrum`, so a
    document must give it: required in the JSON Schema (Python code constructing one
    class directly may omit it)."""
    required = schema.setdefault("required", [])
    if "type" not in required:
        required.insert(0, "type")


class _SpectrumBase(_Doc):
    model_config = ConfigDict(json_schema_extra=_type_required)

    def spectral_density(self, omega: np.ndarray, g: float = G_STANDARD) -> np.ndarray:
        """Spectral density S(omega), one-sided in omega. [unit²·s/rad]"""
        raise NotImplementedError  # pragma: no cover - every subclass overrides

    def statistics(self, omega: np.ndarray, g: float = G_STANDARD):
        """Moments and periods of the spectrum sampled on ``omega``."""
        from stochcable.sea.spectra import spectrum_statistics

        return spectrum_statistics(omega, self.spectral_density(omega, g))


class PiersonMoskowitz(_SpectrumBase):
    """Pierson–Moskowitz spectrum, given by (hs, tp), (m0, omega_p) or wind_speed.

    The (m0, omega_p) form is Tuah's (1982) example (m0 = 28 ft², omega_p = 0.5 rad/s).
    """

    type: Literal["pierson_moskowitz"] = "pierson_moskowitz"
    hs: float | None = _in("Significant wave height", "m", HEIGHT_RANGE, default=None)
    tp: float | None = _in("Peak period", "s", PERIOD_RANGE, default=None)
    m0: float | None = _in("Zeroth spectral moment (variance)", "m²", M0_RANGE, default=None)
    omega_p: float | None = _in("Peak angular frequency", "rad/s", OMEGA_P_RANGE, default=None)
    wind_speed: float | None = _in("Wind speed at 19.5 m", "m/s", WIND_SPEED_RANGE, default=None)

    @model_validator(mode="after")
    def _one_form(self) -> PiersonMoskowitz:
        forms = [
            self.hs is not None or self.tp is not None,
            self.m0 is not None or self.omega_p is not None,
            self.wind_speed is not None,
        ]
        if sum(forms) != 1:
            raise ValueError("give exactly one of (hs, tp), (m0, omega_p) or wind_speed")
        if forms[0] and (self.hs is None or self.tp is None):
            raise ValueError("hs and tp must be given together")
        if forms[1] and (self.m0 is None or self.omega_p is None):
            raise ValueError("m0 and omega_p must be given together")
        return self

    def spectral_density(self, omega: np.ndarray, g: float = G_STANDARD) -> np.ndarray:
        from stochcable.sea import spectra

        if self.hs is not None:
            return spectra.spectrum_pierson_moskowitz(omega, self.hs, self.tp)
        if self.m0 is not None:
            return spectra.spectrum_pierson_moskowitz_m0(omega, self.m0, self.omega_p)
        return spectra.spectrum_pierson_moskowitz_wind(omega, self.wind_speed, g)


class Jonswap(_SpectrumBase):
    """JONSWAP spectrum normalized so that Hs is exact for any gamma."""

    type: Literal["jonswap"] = "jonswap"
    hs: float = _in("Significant wave height", "m", HEIGHT_RANGE)
    tp: float = _in("Peak period", "s", PERIOD_RANGE)
    gamma: float = _in("Peak enhancement factor", "-", GAMMA_RANGE, default=3.3)
    sigma_a: float = _in(
        "Peak width below the peak (>= 0.001: a narrower peak is resolved by no grid)",
        "-",
        SIGMA_RANGE,
        default=0.07,
    )
    sigma_b: float = _in(
        "Peak width above the peak (>= 0.001: a narrower peak is resolved by no grid)",
        "-",
        SIGMA_RANGE,
        default=0.09,
    )

    def spectral_density(self, omega: np.ndarray, g: float = G_STANDARD) -> np.ndarray:
        from stochcable.sea import spectra

        return spectra.spectrum_jonswap(
            omega, self.hs, self.tp, self.gamma, self.sigma_a, self.sigma_b
        )


class Bretschneider(_SpectrumBase):
    """Bretschneider (two-parameter) spectrum in (hs, tp)."""

    type: Literal["bretschneider"] = "bretschneider"
    hs: float = _in("Significant wave height", "m", HEIGHT_RANGE)
    tp: float = _in("Peak period", "s", PERIOD_RANGE)

    def spectral_density(self, omega: np.ndarray, g: float = G_STANDARD) -> np.ndarray:
        from stochcable.sea import spectra

        return spectra.spectrum_bretschneider(omega, self.hs, self.tp)


class Issc(_SpectrumBase):
    """ISSC spectrum in (hs, t1), t1 the mean period Tm01."""

    type: Literal["issc"] = "issc"
    hs: float = _in("Significant wave height", "m", HEIGHT_RANGE)
    t1: float = _in("Mean period Tm01", "s", PERIOD_RANGE)

    def spectral_density(self, omega: np.ndarray, g: float = G_STANDARD) -> np.ndarray:
        from stochcable.sea import spectra

        return spectra.spectrum_issc(omega, self.hs, self.t1)


class OchiHubble(_SpectrumBase):
    """Ochi–Hubble two-peak spectrum (swell + wind sea)."""

    type: Literal["ochi_hubble"] = "ochi_hubble"
    hs1: float = _f(
        "Significant wave height of the low-frequency part (0: none)",
        "m",
        ge=0,
        le=HEIGHT_RANGE[1],
    )
    tp1: float = _in("Peak period of the low-frequency part", "s", PERIOD_RANGE)
    lambda1: float = _in("Shape factor of the low-frequency part", "-", SHAPE_RANGE)
    hs2: float = _f(
        "Significant wave height of the high-frequency part (0: none)",
        "m",
        ge=0,
        le=HEIGHT_RANGE[1],
    )
    tp2: float = _in("Peak period of the high-frequency part", "s", PERIOD_RANGE)
    lambda2: float = _in("Shape factor of the high-frequency part", "-", SHAPE_RANGE)

    @model_validator(mode="after")
    def _heights(self) -> OchiHubble:
        for key in ("hs1", "hs2"):  # as spectrum_ochi_hubble: 0 (no part) or in HEIGHT_RANGE
            hs = getattr(self, key)
            if 0.0 < hs < HEIGHT_RANGE[0]:
                raise LocatedValueError((key,), hs, f"{key} must be 0 or >= {HEIGHT_RANGE[0]:g}")
        if self.hs1 == 0.0 and self.hs2 == 0.0:
            raise LocatedValueError(("hs1",), 0.0, "hs1 and hs2 must not both be 0")
        return self

    def spectral_density(self, omega: np.ndarray, g: float = G_STANDARD) -> np.ndarray:
        from stochcable.sea import spectra

        return spectra.spectrum_ochi_hubble(
            omega, self.hs1, self.tp1, self.lambda1, self.hs2, self.tp2, self.lambda2
        )


class TableSpectrum(_SpectrumBase):
    """A user table (omega, density), linearly interpolated, zero outside."""

    type: Literal["table"] = "table"
    omega: tuple[float, ...] = _f(
        "Angular frequencies, strictly increasing, >= 0", "rad/s", min_length=2
    )
    density: tuple[float, ...] = _f("Spectral density at omega, >= 0", "unit²·s/rad", min_length=2)

    @model_validator(mode="after")
    def _check_table(self) -> TableSpectrum:
        if len(self.omega) != len(self.density):
            raise ValueError(
                f"omega ({len(self.omega)} values) and density ({len(self.density)} values)"
                " must have the same length"
            )
        w = np.asarray(self.omega)
        if w[0] < 0 or (np.diff(w) <= 0).any():
            raise ValueError("omega must be >= 0 and strictly increasing")
        if (np.asarray(self.density) < 0).any():
            raise ValueError("density must be >= 0")
        return self

    def spectral_density(self, omega: np.ndarray, g: float = G_STANDARD) -> np.ndarray:
        from stochcable.sea import spectra

        return spectra.spectrum_table(omega, np.asarray(self.omega), np.asarray(self.density))


Spectrum = Annotated[
    PiersonMoskowitz | Jonswap | Bretschneider | Issc | OchiHubble | TableSpectrum,
    Field(discriminator="type"),
]
