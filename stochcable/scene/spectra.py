"""Spectrum documents of the scene: a sea state or an end motion as a spectrum
(the formulas are :mod:`stochcable.sea.spectra`'s; ``type`` is the discriminator)."""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import ConfigDict, Field, model_validator

from stochcable.scene.base import G_STANDARD, _Doc, _f

__all__ = [
    "PiersonMoskowitz",
    "Jonswap",
    "Bretschneider",
    "Issc",
    "OchiHubble",
    "TableSpectrum",
    "Spectrum",
]


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

    The (m0, omega_p) form is seed 001's example (m0 = 28 ft², omega_p = 0.5 rad/s).
    """

    type: Literal["pierson_moskowitz"] = "pierson_moskowitz"
    hs: float | None = _f("Significant wave height", "m", ge=1e-6, le=1e4, default=None)
    tp: float | None = _f("Peak period", "s", ge=1e-3, le=1e5, default=None)
    m0: float | None = _f(
        "Zeroth spectral moment (variance)", "m²", ge=6.25e-14, le=6.25e6, default=None
    )
    omega_p: float | None = _f(
        "Peak angular frequency", "rad/s", ge=2 * math.pi * 1e-5, le=2 * math.pi * 1e3, default=None
    )
    wind_speed: float | None = _f("Wind speed at 19.5 m", "m/s", ge=1e-3, le=1e3, default=None)

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
    hs: float = _f("Significant wave height", "m", ge=1e-6, le=1e4)
    tp: float = _f("Peak period", "s", ge=1e-3, le=1e5)
    gamma: float = _f("Peak enhancement factor", "-", ge=1, le=20, default=3.3)
    # σ >= 1e-3: a narrower peak is resolved by no frequency grid of the service's size,
    # and σ below ~1e-150 overflows ((ω/ωp − 1)/σ)² in the peak shape
    sigma_a: float = _f(
        "Peak width below the peak (>= 0.001: a narrower peak is resolved by no grid)",
        "-",
        ge=1e-3,
        le=1,
        default=0.07,
    )
    sigma_b: float = _f(
        "Peak width above the peak (>= 0.001: a narrower peak is resolved by no grid)",
        "-",
        ge=1e-3,
        le=1,
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
    hs: float = _f("Significant wave height", "m", ge=1e-6, le=1e4)
    tp: float = _f("Peak period", "s", ge=1e-3, le=1e5)

    def spectral_density(self, omega: np.ndarray, g: float = G_STANDARD) -> np.ndarray:
        from stochcable.sea import spectra

        return spectra.spectrum_bretschneider(omega, self.hs, self.tp)


class Issc(_SpectrumBase):
    """ISSC spectrum in (hs, t1), t1 the mean period Tm01."""

    type: Literal["issc"] = "issc"
    hs: float = _f("Significant wave height", "m", ge=1e-6, le=1e4)
    t1: float = _f("Mean period Tm01", "s", ge=1e-3, le=1e5)

    def spectral_density(self, omega: np.ndarray, g: float = G_STANDARD) -> np.ndarray:
        from stochcable.sea import spectra

        return spectra.spectrum_issc(omega, self.hs, self.t1)


class OchiHubble(_SpectrumBase):
    """Ochi–Hubble two-peak spectrum (swell + wind sea)."""

    type: Literal["ochi_hubble"] = "ochi_hubble"
    hs1: float = _f("Significant wave height of the low-frequency part", "m", ge=1e-6, le=1e4)
    tp1: float = _f("Peak period of the low-frequency part", "s", ge=1e-3, le=1e5)
    lambda1: float = _f("Shape factor of the low-frequency part", "-", ge=0.01, le=100)
    hs2: float = _f("Significant wave height of the high-frequency part", "m", ge=1e-6, le=1e4)
    tp2: float = _f("Peak period of the high-frequency part", "s", ge=1e-3, le=1e5)
    lambda2: float = _f("Shape factor of the high-frequency part", "-", ge=0.01, le=100)

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
