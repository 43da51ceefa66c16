"""Environment and sea of the scene: depth, fluid, gravity, current profile, seabed
contact, and the long-crested random sea."""

from __future__ import annotations

import math

import numpy as np
from pydantic import Field, model_validator

from stochcable.scene.base import G_STANDARD, RHO_SEAWATER, _Doc, _f
from stochcable.scene.spectra import Spectrum
from stochcable.scene.spreading import Spreading

__all__ = ["CurrentPoint", "Seabed", "Environment", "Sea"]


class CurrentPoint(_Doc):
    """One point of a current profile (linear between points, constant beyond)."""

    z: float = _f("Elevation, z up from the still-water level", "m", le=0)
    speed: float = _f("Current speed", "m/s", ge=0)
    heading: float = _f("Direction the current flows toward, from +x toward +y", "deg", default=0.0)

    @property
    def heading_rad(self) -> float:
        """Heading. [rad]"""
        return math.radians(self.heading)


class Seabed(_Doc):
    """Linear seabed contact, per unit contact area (times diameter per unit length)."""

    stiffness: float = _f("Contact stiffness per unit area", "Pa/m", ge=0, default=3.0e6)
    damping: float = _f("Contact damping per unit area", "Pa·s/m", ge=0, default=0.0)


class Environment(_Doc):
    """Water depth, fluid, gravity, current profile and seabed."""

    depth: float = _f("Water depth; the seabed is the plane z = -depth", "m", gt=0)
    rho: float = _f("Water density", "kg/m³", gt=0, default=RHO_SEAWATER)
    g: float = _f("Gravitational acceleration", "m/s²", gt=0, default=G_STANDARD)
    current: tuple[CurrentPoint, ...] = Field(
        default=(), description="Current profile points, any order; empty for no current"
    )
    seabed: Seabed = Field(default_factory=Seabed, description="Seabed contact model")
    viscosity: float = _f(
        "Kinematic viscosity of the water (strumming: viscous damping); sea water at "
        "15 °C (ITTC 2011)",
        "m²/s",
        gt=0,
        default=1.19e-6,
    )

    @model_validator(mode="after")
    def _current_in_water(self) -> Environment:
        for i, p in enumerate(self.current):
            if p.z < -self.depth:
                raise ValueError(
                    f"current[{i}].z = {p.z} m is below the seabed (depth {self.depth} m)"
                )
        return self

    def current_velocity(self, z: np.ndarray) -> np.ndarray:
        """Current velocity vector at elevations ``z``, shape (..., 3). [m/s]

        Linear interpolation of the (x, y) components between profile points, constant
        beyond the shallowest and deepest point; zero everywhere without a profile and
        above z = 0.
        """
        z = np.asarray(z, dtype=float)
        out = np.zeros(z.shape + (3,))
        if not self.current:
            return out
        pts = sorted(self.current, key=lambda p: p.z)
        zz = np.array([p.z for p in pts])
        ux = np.array([p.speed * math.cos(p.heading_rad) for p in pts])
        uy = np.array([p.speed * math.sin(p.heading_rad) for p in pts])
        wet = z <= 0.0
        out[..., 0] = np.where(wet, np.interp(z, zz, ux), 0.0)
        out[..., 1] = np.where(wet, np.interp(z, zz, uy), 0.0)
        return out


class Sea(_Doc):
    """Random sea: a spectrum, a (mean) heading and, for a short-crested sea, its
    directional spreading (long-crested without)."""

    spectrum: Spectrum
    heading: float = _f("Direction the waves travel toward, from +x toward +y", "deg", default=0.0)
    spreading: Spreading | None = Field(
        default=None,
        description="Directional spreading about the heading (a short-crested sea); "
        "none: long-crested",
    )

    def direction_set(self):
        """The discrete directions (:class:`stochcable.sea.spreading.DirectionSet`,
        headings in rad) of the spreading; None for a long-crested sea."""
        return None if self.spreading is None else self.spreading.direction_set(self.heading)

    @property
    def heading_rad(self) -> float:
        """Heading. [rad]"""
        return math.radians(self.heading)
