"""The scene document: one definition of a cable analysis for Python, CLI and service.

A scene is environment + sea + lines + analysis settings (DESIGN.md, "Scene and result
documents", v1 contract).  The models are frozen pydantic models; they validate every
field with its unit and bounds once, at the boundary, and the numerical code below
trusts them.  :func:`load_scene` turns pydantic's validation errors into
:class:`~stochcable.errors.InputError` messages naming the field path, value, unit and
constraint.

Units are consistent units, SI by default (m, kg, s, N, rad/s); the seeds' imperial
examples run unchanged when ``g`` and ``rho`` are given in feet and slugs.  Headings
in the document are in degrees (the document is an edge); the models expose radians
(``heading_rad``) to the core.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Annotated, Any, Literal, Union

import numpy as np
from pydantic import (BaseModel, ConfigDict, Discriminator, Field, Tag, ValidationError,
                      model_validator)

from stochcable.errors import InputError
from stochcable.scene.units import UnitLabels, labels_of_document

__all__ = [
    "PiersonMoskowitz",
    "Jonswap",
    "Bretschneider",
    "Issc",
    "OchiHubble",
    "TableSpectrum",
    "Spectrum",
    "CurrentPoint",
    "Seabed",
    "Environment",
    "Sea",
    "ComplexTable",
    "MotionRao",
    "EndMotion",
    "BodyAttachment",
    "End",
    "Segment",
    "Attachment",
    "Line",
    "BodyExcitation",
    "BodyHydrodynamics",
    "BodyHydrodynamicsFile",
    "VesselMotion",
    "Body",
    "BODY_DOFS",
    "PLANAR_BODY_DOFS",
    "OmegaGrid",
    "LinearizationSettings",
    "TimeSeriesSettings",
    "StructuralDamping",
    "FidelitySettings",
    "AnalysisSettings",
    "Scene",
    "load_scene",
    "scene_json_schema",
    "field_path_and_unit",
]

G_STANDARD = 9.80665  # standard gravity [m/s²]
RHO_SEAWATER = 1025.0  # sea water density [kg/m³]


def _f(description: str, unit: str, **kw: Any) -> Any:
    """A pydantic Field whose description carries the unit, as ``text [unit]``."""
    extra = {"unit": unit}
    return Field(description=f"{description} [{unit}]", json_schema_extra=extra, **kw)


class _Doc(BaseModel):
    model_config = ConfigDict(frozen=True, extra="forbid", allow_inf_nan=False)


# --------------------------------------------------------------------------- spectra


class _SpectrumBase(_Doc):
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
    m0: float | None = _f("Zeroth spectral moment (variance)", "m²", ge=6.25e-14, le=6.25e6, default=None)
    omega_p: float | None = _f("Peak angular frequency", "rad/s", ge=2 * math.pi * 1e-5, le=2 * math.pi * 1e3, default=None)
    wind_speed: float | None = _f("Wind speed at 19.5 m", "m/s", ge=1e-3, le=1e3, default=None)

    @model_validator(mode="after")
    def _one_form(self) -> "PiersonMoskowitz":
        forms = [
            self.hs is not None or self.tp is not None,
            self.m0 is not None or self.omega_p is not None,
            self.wind_speed is not None,
        ]
        if sum(forms) != 1:
            raise ValueError(
                "give exactly one of (hs, tp), (m0, omega_p) or wind_speed"
            )
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
    sigma_a: float = _f("Peak width below the peak", "-", gt=0, le=1, default=0.07)
    sigma_b: float = _f("Peak width above the peak", "-", gt=0, le=1, default=0.09)

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
    omega: tuple[float, ...] = _f("Angular frequencies, strictly increasing, >= 0", "rad/s",
                                  min_length=2)
    density: tuple[float, ...] = _f("Spectral density at omega, >= 0", "unit²·s/rad",
                                    min_length=2)

    @model_validator(mode="after")
    def _check_table(self) -> "TableSpectrum":
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
    Union[PiersonMoskowitz, Jonswap, Bretschneider, Issc, OchiHubble, TableSpectrum],
    Field(discriminator="type"),
]


# ----------------------------------------------------------------------- environment


class CurrentPoint(_Doc):
    """One point of a current profile (linear between points, constant beyond)."""

    z: float = _f("Elevation, z up from the still-water level", "m", le=0)
    speed: float = _f("Current speed", "m/s", ge=0)
    heading: float = _f("Direction the current flows toward, from +x toward +y", "deg",
                        default=0.0)

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

    @model_validator(mode="after")
    def _current_in_water(self) -> "Environment":
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
    """Long-crested random sea: a spectrum and a heading."""

    spectrum: Spectrum
    heading: float = _f("Direction the waves travel toward, from +x toward +y", "deg",
                        default=0.0)

    @property
    def heading_rad(self) -> float:
        """Heading. [rad]"""
        return math.radians(self.heading)


# ---------------------------------------------------------------------------- lines


class ComplexTable(_Doc):
    """Complex values as separate real and imaginary parts."""

    re: tuple[float, ...]
    im: tuple[float, ...]

    @model_validator(mode="after")
    def _same_length(self) -> "ComplexTable":
        if len(self.re) != len(self.im):
            raise ValueError(f"re ({len(self.re)}) and im ({len(self.im)}) differ in length")
        return self

    def values(self) -> np.ndarray:
        """The complex values."""
        return np.asarray(self.re) + 1j * np.asarray(self.im)


class MotionRao(_Doc):
    """End motion RAOs relative to the sea: metres of motion per metre of wave amplitude."""

    omega: tuple[float, ...] = _f("Angular frequencies, strictly increasing", "rad/s",
                                  min_length=2)
    surge: ComplexTable | None = None
    sway: ComplexTable | None = None
    heave: ComplexTable | None = None

    @model_validator(mode="after")
    def _check(self) -> "MotionRao":
        w = np.asarray(self.omega)
        if w[0] < 0 or (np.diff(w) <= 0).any():
            raise ValueError("omega must be >= 0 and strictly increasing")
        given = {k: getattr(self, k) for k in ("surge", "sway", "heave")}
        if all(v is None for v in given.values()):
            raise ValueError("give at least one of surge, sway, heave")
        for k, v in given.items():
            if v is not None and len(v.re) != len(self.omega):
                raise ValueError(
                    f"{k} has {len(v.re)} values but omega has {len(self.omega)}"
                )
        return self

    def transfer(self, omega: np.ndarray) -> np.ndarray:
        """Motion per unit wave amplitude at ``omega``, shape (3, n), zero outside the table."""
        omega = np.asarray(omega, dtype=float)
        out = np.zeros((3, omega.size), dtype=complex)
        w = np.asarray(self.omega)
        for i, k in enumerate(("surge", "sway", "heave")):
            t = getattr(self, k)
            if t is None:
                continue
            v = t.values()
            out[i] = np.interp(omega, w, v.real, 0.0, 0.0) + 1j * np.interp(
                omega, w, v.imag, 0.0, 0.0
            )
        return out


class EndMotion(_Doc):
    """Prescribed motion of a line end.

    Either independent motion spectra per translational DOF (``surge``, ``sway``,
    ``heave``: spectrum documents in metres) or an RAO table relative to the sea
    (``rao``), not both.
    """

    surge: Spectrum | None = None
    sway: Spectrum | None = None
    heave: Spectrum | None = None
    rao: MotionRao | None = None

    @model_validator(mode="after")
    def _one_kind(self) -> "EndMotion":
        spectra_given = any(getattr(self, k) is not None for k in ("surge", "sway", "heave"))
        if spectra_given and self.rao is not None:
            raise ValueError("give motion spectra (surge/sway/heave) or rao, not both")
        if not spectra_given and self.rao is None:
            raise ValueError("give at least one of surge, sway, heave or rao")
        return self


class BodyAttachment(_Doc):
    """Where a line end is fixed to a body (the end follows the body's rigid motion)."""

    body: str = Field(min_length=1, max_length=64, description="Name of the body")
    point: tuple[float, float, float] = _f(
        "Attachment point relative to the body reference point, global axes, at the "
        "static pose", "m", default=(0.0, 0.0, 0.0))


class End(_Doc):
    """A line end: fixed at ``position`` unless a ``motion`` is prescribed about it, or
    attached to a body (``attach``), which then carries it (seed 001 eqs. 3.3.6–3.3.7)."""

    position: tuple[float, float, float] | None = _f("Position (x, y, z), z up", "m",
                                                     default=None)
    motion: EndMotion | None = None
    attach: BodyAttachment | None = None

    @model_validator(mode="after")
    def _position_or_attach(self) -> "End":
        if self.attach is None and self.position is None:
            raise ValueError("give the end's position or attach it to a body")
        if self.attach is not None and self.position is not None:
            raise ValueError("give position or attach, not both (an attached end's "
                             "position is the body position plus attach.point)")
        if self.attach is not None and self.motion is not None:
            raise ValueError("an end attached to a body cannot have a motion: the body "
                             "moves it (give the body a 'prescribed' motion instead)")
        return self


class Segment(_Doc):
    """A homogeneous stretch of line."""

    length: float = _f("Unstretched length", "m", gt=0)
    ea: float = _f("Axial stiffness EA", "N", gt=0)
    mass: float = _f("Mass per unit length in air", "kg/m", gt=0)
    diameter: float = _f("Hydrodynamic (volume-equivalent) diameter", "m", gt=0)
    cd_normal: float = _f("Normal drag coefficient, on the diameter", "-", ge=0, default=1.2)
    cd_axial: float = _f("Axial drag coefficient, on pi·diameter (as MoorDyn's CdAx)", "-",
                         ge=0, default=0.0)
    ca_normal: float = _f("Normal added-mass coefficient", "-", ge=0, default=1.0)
    weight: float | None = _f(
        "Net submerged weight per unit length, overriding (mass - rho·pi·D²/4)·g; "
        "negative for buoyant line", "N/m", default=None,
    )
    elements: int = _f("Number of finite elements", "-", ge=1, le=100_000, default=20)

    def submerged_weight(self, rho: float, g: float) -> float:
        """Net weight per unit length in water. [N/m]"""
        if self.weight is not None:
            return self.weight
        return (self.mass - rho * math.pi * self.diameter**2 / 4.0) * g


class Attachment(_Doc):
    """A point mass (clump weight) and/or buoy at an arc length of the line."""

    at: float = _f("Unstretched arc length from end_a", "m", ge=0)
    mass: float = _f("Mass in air", "kg", ge=0, default=0.0)
    buoyancy: float = _f("Upward buoyancy force (weight of displaced water)", "N", ge=0,
                         default=0.0)
    added_mass: float = _f("Added mass, all directions", "kg", ge=0, default=0.0)
    drag_area: float = _f("Drag coefficient times projected area, Cd·A", "m²", ge=0,
                          default=0.0)


class Line(_Doc):
    """A line from end_a (the anchor or lower end) to end_b, of one or more segments."""

    name: str = Field(min_length=1, max_length=64, pattern=r"^[A-Za-z0-9_.\-]+$",
                      description="Unique line name (letters, digits, _ . -)")
    end_a: End
    end_b: End
    segments: tuple[Segment, ...] = Field(min_length=1, max_length=1000)
    attachments: tuple[Attachment, ...] = Field(default=(), max_length=10_000)

    @property
    def length(self) -> float:
        """Total unstretched length. [m]"""
        return float(sum(s.length for s in self.segments))

    @property
    def elements(self) -> int:
        """Total number of finite elements."""
        return int(sum(s.elements for s in self.segments))

    @model_validator(mode="after")
    def _check_line(self) -> "Line":
        total = self.length
        for i, a in enumerate(self.attachments):
            if a.at > total * (1 + 1e-12):
                raise ValueError(
                    f"attachments[{i}].at = {a.at} m is beyond the line length {total} m"
                )
        if self.end_a.position is not None and self.end_b.position is not None:
            # attached ends: checked by Scene._check_scene with the body positions
            _check_span(self.end_a.position, self.end_b.position, total)
        return self


def _check_span(a: Sequence[float], b: Sequence[float], total: float) -> None:
    span = math.dist(a, b)
    if span == 0.0:
        raise ValueError("end_a and end_b are at the same position")
    # Strain needed to reach the span if the line were straight: a line that must
    # stretch more than 10 % is a data error (EA or length in the wrong unit).
    strain = span / total - 1.0
    if strain > 0.1:
        raise ValueError(
            f"the line ({total:g} m unstretched) is shorter than its span "
            f"({span:g} m): it would have to stretch {strain:.1%} (> 10 %)"
        )


# --------------------------------------------------------------------------- bodies

#: Rigid-body DOF names (global axes, rotations about the reference point), as
#: :data:`stochcable.bodies.rigid.SPATIAL_DOFS`; planar scenes use the x–z subset.
BODY_DOFS = ("surge", "sway", "heave", "roll", "pitch", "yaw")
PLANAR_BODY_DOFS = ("surge", "heave", "pitch")

Matrix = tuple[tuple[float, ...], ...]
Vec3 = tuple[float, float, float]


class BodyExcitation(_Doc):
    """Wave excitation table of a body (docs/BODIES.md JSON table format)."""

    heading: tuple[float, ...] = _f("Wave headings, increasing, spanning < 360", "deg",
                                    min_length=1)
    re: tuple[Matrix, ...] = _f("Real part, (n_heading, n_dof, n_omega), per unit wave "
                                "amplitude, e^{+iωt}", "N/m, N·m/m")
    im: tuple[Matrix, ...] = _f("Imaginary part, shape as re", "N/m, N·m/m")


class BodyHydrodynamics(_Doc):
    """Hydrodynamic coefficients over ω, inline (the JSON table of docs/BODIES.md).

    Checked with :func:`stochcable.bodies.data.read_table` (shapes, symmetry within
    2 %, non-negative damping diagonal).
    """

    dofs: tuple[str, ...] | None = Field(
        default=None, description="DOF order: the six (default) or surge, heave, pitch")
    omega: tuple[float, ...] = _f("Angular frequencies, strictly increasing", "rad/s",
                                  min_length=1)
    added_mass: tuple[Matrix, ...] = _f("Added mass (n_omega, d, d) about the reference "
                                        "point", "kg, kg·m, kg·m²")
    radiation_damping: tuple[Matrix, ...] = _f("Radiation damping (n_omega, d, d)",
                                               "N·s/m, N·s, N·m·s")
    excitation: BodyExcitation | None = None
    hydrostatic_stiffness: Matrix | None = _f("Hydrostatic restoring (d, d), weight terms "
                                              "included", "N/m, N, N·m/rad", default=None)
    reference_point: Vec3 | None = _f("Reference point of the table (informative)", "m",
                                      default=None)

    @model_validator(mode="after")
    def _check_table(self) -> "BodyHydrodynamics":
        from stochcable.bodies.data import read_table

        try:
            read_table(self.table())
        except InputError as exc:
            raise ValueError(str(exc)) from None
        return self

    def table(self) -> dict[str, Any]:
        """The table as a mapping for :func:`stochcable.bodies.data.read_table`."""
        return self.model_dump(mode="python", exclude_none=True)

    @property
    def planar(self) -> bool:
        """True for a (surge, heave, pitch) table."""
        return self.dofs is not None and len(self.dofs) == 3


class BodyHydrodynamicsFile(_Doc):
    """Hydrodynamic coefficients in a file: Capytaine NetCDF (.nc) or a JSON table.

    A relative path is relative to the scene file (:func:`load_scene` makes it
    absolute); the HTTP service refuses files (``load_scene(..., allow_files=False)``).
    """

    file: str = Field(min_length=1, max_length=4096,
                      description="Path of a Capytaine .nc or JSON table file")


class VesselMotion(_Doc):
    """A prescribed (vessel) body motion: 6-DOF RAOs per unit wave amplitude.

    Translations in m/m, rotations in rad/m, about the body reference point, for the
    scene's sea heading (v1: no heading dimension); zero outside the table.  The
    body is not solved for: lines attached to it see the end motion T(r)·ξ (seed 001
    eqs. 3.3.6–3.3.7), nothing couples back.
    """

    omega: tuple[float, ...] = _f("Angular frequencies, strictly increasing", "rad/s",
                                  min_length=2)
    surge: ComplexTable | None = None
    sway: ComplexTable | None = None
    heave: ComplexTable | None = None
    roll: ComplexTable | None = None
    pitch: ComplexTable | None = None
    yaw: ComplexTable | None = None

    @model_validator(mode="after")
    def _check(self) -> "VesselMotion":
        w = np.asarray(self.omega)
        if w[0] < 0 or (np.diff(w) <= 0).any():
            raise ValueError("omega must be >= 0 and strictly increasing")
        given = {k: getattr(self, k) for k in BODY_DOFS}
        if all(v is None for v in given.values()):
            raise ValueError(f"give at least one of {', '.join(BODY_DOFS)}")
        for k, v in given.items():
            if v is not None and len(v.re) != len(self.omega):
                raise ValueError(f"{k} has {len(v.re)} values but omega has "
                                 f"{len(self.omega)}")
        return self

    def transfer(self, omega: np.ndarray) -> np.ndarray:
        """RAO per unit wave amplitude at ``omega``, shape (6, n), zero outside the
        table. [m/m, rad/m]"""
        omega = np.asarray(omega, dtype=float)
        out = np.zeros((6, omega.size), dtype=complex)
        w = np.asarray(self.omega)
        for i, k in enumerate(BODY_DOFS):
            t = getattr(self, k)
            if t is None:
                continue
            v = t.values()
            out[i] = np.interp(omega, w, v.real, 0.0, 0.0) + 1j * np.interp(
                omega, w, v.imag, 0.0, 0.0)
        return out

    @property
    def out_of_plane(self) -> bool:
        """True when a sway, roll or yaw RAO is non-zero."""
        return any(getattr(self, k) is not None and np.any(getattr(self, k).values() != 0)
                   for k in ("sway", "roll", "yaw"))


def _hydro_kind(v: Any) -> str:
    """Discriminator of Body.hydrodynamics: a mapping with 'file' is a file reference."""
    if isinstance(v, Mapping):
        return "file" if "file" in v else "table"
    return "file" if isinstance(v, BodyHydrodynamicsFile) else "table"


class Body(_Doc):
    """A large rigid body (buoy, disc, vessel; seed 001 §3.2.c, eq. 3.2.c.20).

    DOFs and signs as :mod:`stochcable.bodies.rigid`: (surge, sway, heave, roll, pitch, yaw)
    about the reference point ``position``, global axes; in a planar scene (surge,
    heave, pitch).  Matrices are 6×6, or 3×3 (surge, heave, pitch) in a planar scene.
    Explicit constant ``added_mass``, ``radiation_damping``, ``hydrostatic_stiffness``
    replace the corresponding matrix of ``hydrodynamics``.

    Statics: the weight m·g acts at ``cog``.  With ``displaced_volume`` the buoyancy
    ρ g ∇ acts at ``centre_of_buoyancy`` (exact for a submerged body; for a floating
    one the ``hydrostatic_stiffness`` adds the restoring about ``position``); without
    it the body is taken as freely floating in equilibrium at ``position``, restored
    by ``hydrostatic_stiffness`` only.
    """

    name: str = Field(min_length=1, max_length=64, pattern=r"^[A-Za-z0-9_.\-]+$",
                      description="Unique body name (letters, digits, _ . -)")
    position: Vec3 = _f("Reference point at the static pose (initial guess of the "
                        "statics for a free body)", "m")
    mass: float = _f("Mass", "kg", gt=0)
    inertia: Matrix | None = _f("Inertia tensor about the centre of gravity, global axes, "
                                "3×3", "kg·m²", default=None)
    cog: Vec3 = _f("Centre of gravity relative to the reference point", "m",
                   default=(0.0, 0.0, 0.0))
    added_mass: Matrix | None = _f("Constant added mass", "kg, kg·m, kg·m²", default=None)
    radiation_damping: Matrix | None = _f("Constant radiation damping",
                                          "N·s/m, N·s, N·m·s", default=None)
    hydrostatic_stiffness: Matrix | None = _f(
        "Hydrostatic restoring about the reference point, weight terms included",
        "N/m, N, N·m/rad", default=None)
    extra_stiffness: Matrix | None = _f("Additional linear stiffness", "N/m, N, N·m/rad",
                                        default=None)
    extra_damping: Matrix | None = _f("Additional linear damping", "N·s/m, N·s, N·m·s",
                                      default=None)
    hydrodynamics: Annotated[
        Union[Annotated[BodyHydrodynamicsFile, Tag("file")],
              Annotated[BodyHydrodynamics, Tag("table")]],
        Discriminator(_hydro_kind)] | None = Field(
        default=None, description="Frequency-dependent coefficients: inline table or file")
    displaced_volume: float | None = _f("Displaced volume for the static buoyancy", "m³",
                                        ge=0, default=None)
    centre_of_buoyancy: Vec3 = _f("Centre of buoyancy relative to the reference point",
                                  "m", default=(0.0, 0.0, 0.0))
    drag_area: Vec3 = _f("Drag coefficient times area, Cd·A, for flow along x, y, z",
                         "m²", default=(0.0, 0.0, 0.0))
    drag_point: Vec3 = _f("Point of application of the drag relative to the reference "
                          "point", "m", default=(0.0, 0.0, 0.0))
    wind_force: Vec3 = _f("Static wind force at the reference point (seed 001 §6.5)", "N",
                          default=(0.0, 0.0, 0.0))
    wind_moment: Vec3 = _f("Static wind moment about the reference point", "N·m",
                           default=(0.0, 0.0, 0.0))
    extrapolation: Literal["error", "hold"] = Field(
        default="error", description="Outside the frequencies of the hydrodynamic table: "
        "refuse, or hold the end values")
    prescribed: VesselMotion | None = Field(
        default=None, description="Prescribed motion (a vessel): the body is not solved "
        "for; its static pose is position, no rotation")
    fixed_dofs: tuple[Literal["surge", "sway", "heave", "roll", "pitch", "yaw"], ...] = \
        Field(default=(), description="DOFs held fixed (statics and dynamics), e.g. yaw "
              "of a buoy on one line")

    @model_validator(mode="after")
    def _check_body(self) -> "Body":
        for k in ("added_mass", "radiation_damping", "hydrostatic_stiffness",
                  "extra_stiffness", "extra_damping"):
            m = getattr(self, k)
            if m is None:
                continue
            n = len(m)
            if n not in (3, 6) or any(len(row) != n for row in m):
                raise ValueError(f"{k} must be a 6×6 or (planar) 3×3 matrix")
        if self.inertia is not None and (len(self.inertia) != 3
                                         or any(len(r) != 3 for r in self.inertia)):
            raise ValueError("inertia must be a 3×3 tensor")
        if any(v < 0 for v in self.drag_area):
            raise ValueError(f"drag_area = {list(self.drag_area)} m²: must be >= 0")
        if len(set(self.fixed_dofs)) != len(self.fixed_dofs):
            raise ValueError("fixed_dofs are repeated")
        return self

    @property
    def planar_data(self) -> bool:
        """True when a matrix or the table is 3×3 (surge, heave, pitch)."""
        mats = [getattr(self, k) for k in ("added_mass", "radiation_damping",
                                           "hydrostatic_stiffness", "extra_stiffness",
                                           "extra_damping")]
        if any(m is not None and len(m) == 3 for m in mats):
            return True
        h = self.hydrodynamics
        return isinstance(h, BodyHydrodynamics) and h.planar

    @property
    def out_of_plane(self) -> bool:
        """True when the body leaves the x–z plane: y of its points, sway forces,
        roll/yaw moments, out-of-plane vessel RAOs."""
        tol = 1e-9
        ys = [self.position[1], self.cog[1], self.centre_of_buoyancy[1],
              self.drag_point[1], self.wind_force[1], self.wind_moment[0],
              self.wind_moment[2]]
        if any(abs(v) > tol for v in ys):
            return True
        return self.prescribed is not None and self.prescribed.out_of_plane


# ------------------------------------------------------------------------- analysis


class OmegaGrid(_Doc):
    """Frequency grid of the analysis."""

    min: float = _f("Lowest frequency", "rad/s", gt=0, default=0.05)
    max: float = _f("Highest frequency", "rad/s", gt=0, default=2.0)
    count: int = _f("Number of frequencies", "-", ge=2, le=100_000, default=200)
    spacing: Literal["linear", "log"] = Field(default="linear",
                                              description="Grid spacing")

    @model_validator(mode="after")
    def _order(self) -> "OmegaGrid":
        if self.max <= self.min:
            raise ValueError(f"max ({self.max} rad/s) must exceed min ({self.min} rad/s)")
        return self

    def values(self) -> np.ndarray:
        """The grid. [rad/s]"""
        if self.spacing == "log":
            return np.geomspace(self.min, self.max, self.count)
        return np.linspace(self.min, self.max, self.count)


class LinearizationSettings(_Doc):
    """Statistical drag linearization and its fixed-point iteration (seed 001 §5.2)."""

    method: Literal["seed", "vector", "harmonic"] = Field(
        default="seed",
        description="seed: scalar sqrt(8/pi) form (eq. 5.2.2); vector: exact normal-plane "
        "Gaussian form; harmonic: 8/(3 pi) regular-wave form",
    )
    tolerance: float = _f("Relative change of every sigma at convergence", "-", gt=0, lt=1,
                          default=1e-4)
    max_iterations: int = _f("Iteration limit", "-", ge=1, le=10_000, default=100)
    relaxation: float = _f("Under-relaxation factor of the plain iteration", "-", gt=0, le=1,
                           default=0.5)
    acceleration: Literal["anderson", "none"] = Field(default="anderson",
                                                      description="Fixed-point accelerator")
    allow_unconverged: bool = Field(
        default=False,
        description="Return a flagged partial result instead of an error when the "
        "iteration does not converge",
    )


class TimeSeriesSettings(_Doc):
    """Time series synthesized from the response spectra (seed 001 §5.1)."""

    method: Literal["dsa", "nsa"] = Field(default="dsa", description="Spectral amplitude model")
    duration: float = _f("Record length", "s", gt=0, le=1.0e7, default=600.0)
    dt: float = _f("Time step", "s", gt=0, default=0.25)
    seed: int = Field(default=1, ge=0, description="Random seed (numpy PCG64)")


class StructuralDamping(_Doc):
    """Rayleigh structural damping C_s = alpha·M + beta·K (added to the drag damping)."""

    alpha: float = _f("Mass-proportional coefficient", "1/s", ge=0, default=0.0)
    beta: float = _f("Stiffness-proportional coefficient", "s", ge=0, default=0.0)


class FidelitySettings(_Doc):
    """Adaptive fidelity: the engine chooses elements, frequencies, modes and tolerance."""

    target_error: float = _f(
        "Target relative error of the response standard deviations", "-", gt=0, le=0.5,
        default=0.01,
    )


class AnalysisSettings(_Doc):
    """How to solve: frequencies, solver, modes, linearization, time series."""

    omega: OmegaGrid = Field(default_factory=OmegaGrid)
    solver: Literal["foss", "direct"] = Field(default="foss",
                                              description="Modal Foss or direct solve")
    modes: Literal["auto"] | Annotated[int, Field(ge=1)] = Field(
        default="auto", description="Number of modes kept, or auto from the frequency content"
    )
    linearization: LinearizationSettings = Field(default_factory=LinearizationSettings)
    structural_damping: StructuralDamping = Field(default_factory=StructuralDamping)
    fidelity: FidelitySettings | None = Field(
        default=None,
        description="When set, the engine chooses elements, frequency grid, modes and "
        "tolerance itself for this target error (the other settings are replaced); the "
        "choices and their error estimates are reported under 'fidelity'",
    )
    timeseries: TimeSeriesSettings | None = None
    duration: float = _f("Storm duration for extreme-value statistics", "s", gt=0,
                         default=10800.0)


class Scene(_Doc):
    """A complete analysis: environment, sea, lines and settings (DESIGN.md v1)."""

    title: str = Field(default="", max_length=2000, description="Free text: source and assumptions")
    environment: Environment
    sea: Sea | None = None
    lines: tuple[Line, ...] = Field(min_length=1, max_length=100)
    bodies: tuple[Body, ...] = Field(default=(), max_length=100,
                                     description="Large rigid bodies the lines attach to")
    analysis: AnalysisSettings = Field(default_factory=AnalysisSettings)

    @model_validator(mode="after")
    def _check_scene(self) -> "Scene":
        names = [ln.name for ln in self.lines]
        dup = {n for n in names if names.count(n) > 1}
        if dup:
            raise ValueError(f"line names must be unique; repeated: {sorted(dup)}")
        bnames = [b.name for b in self.bodies]
        dup = {n for n in bnames if bnames.count(n) > 1}
        if dup:
            raise ValueError(f"body names must be unique; repeated: {sorted(dup)}")
        bodies = {b.name: b for b in self.bodies}
        depth = self.environment.depth
        for i, ln in enumerate(self.lines):
            for end in ("end_a", "end_b"):
                e = getattr(ln, end)
                if e.attach is not None:
                    if e.attach.body not in bodies:
                        raise ValueError(
                            f"lines[{i}].{end}.attach.body = {e.attach.body!r}: no body of "
                            f"that name; bodies: {bnames}")
                    continue
                z = e.position[2]
                if z < -depth * (1 + 1e-9):
                    raise ValueError(
                        f"lines[{i}].{end}.position z = {z} m is below the seabed "
                        f"(depth {depth} m)"
                    )
            if ln.end_a.attach is None:
                za = ln.end_a.position[2]
                if za > 0.0:
                    raise ValueError(
                        f"lines[{i}].end_a.position z = {za} m: the anchor end (end_a) is "
                        "above the still-water surface (z must be <= 0)"
                    )
            if ln.end_a.attach is not None or ln.end_b.attach is not None:
                try:
                    _check_span(self.end_position(ln, "end_a"), self.end_position(ln, "end_b"),
                                ln.length)
                except ValueError as exc:
                    raise ValueError(f"lines[{i}]: {exc}") from None
        if self.bodies:
            planar = self.is_planar
            for j, b in enumerate(self.bodies):
                if b.planar_data and not planar:
                    raise ValueError(
                        f"bodies[{j}] ({b.name!r}) has 3×3 (surge, heave, pitch) data but "
                        "the scene is not planar (a line, body, sea or current leaves the "
                        "x–z plane): give 6×6 matrices and a 6-DOF table")
                if planar:
                    bad = [d for d in b.fixed_dofs if d not in PLANAR_BODY_DOFS]
                    if bad:
                        raise ValueError(
                            f"bodies[{j}].fixed_dofs {bad}: the scene is planar, its bodies "
                            f"have only {list(PLANAR_BODY_DOFS)}")
        return self

    @property
    def uses_files(self) -> bool:
        """True when a body's hydrodynamics refers to a file (refused by the service)."""
        return any(isinstance(b.hydrodynamics, BodyHydrodynamicsFile) for b in self.bodies)

    def body(self, name: str) -> "Body":
        """The body called ``name``."""
        for b in self.bodies:
            if b.name == name:
                return b
        raise InputError("body", name, "-", f"no body of that name; bodies: "
                         f"{[b.name for b in self.bodies]}")

    def end_position(self, line: "Line | str", end: Literal["end_a", "end_b"],
                     poses: Mapping[str, Any] | None = None) -> np.ndarray:
        """Position of a line end, shape (3,). [m]

        Parameters
        ----------
        line : Line or str
            The line or its name.
        end : {"end_a", "end_b"}
        poses : mapping of body name to pose, optional
            Body poses: objects with ``position`` (3,) [m] and ``rotation`` (3,)
            rotation vector [rad] (:class:`stochcable.bodies.statics.BodyStatics`), or
            ``(position, rotation)`` pairs.  Default: the bodies' ``position``, no
            rotation.

        Returns
        -------
        ndarray, shape (3,)
            ``end.position``, or for an attached end X + R(θ)·r (seed 001 eq. 3.3.6
            to first order), X, θ the body pose and r ``attach.point``. [m]
        """
        if isinstance(line, str):
            found = [ln for ln in self.lines if ln.name == line]
            if not found:
                raise InputError("line", line, "-", "no line of that name")
            line = found[0]
        e = getattr(line, end)
        if e.attach is None:
            return np.asarray(e.position, dtype=float)
        name = e.attach.body
        r = np.asarray(e.attach.point, dtype=float)
        pose = None if poses is None else poses.get(name)
        if pose is None:
            return np.asarray(self.body(name).position, dtype=float) + r
        if hasattr(pose, "position"):
            x, rot = pose.position, pose.rotation
        else:
            x, rot = pose
        return np.asarray(x, dtype=float) + rotate(np.asarray(rot, dtype=float), r)

    def resolved_line(self, line: "Line", poses: Mapping[str, Any] | None = None) -> "Line":
        """The line with its attached ends replaced by fixed positions at ``poses``
        (:meth:`end_position`), for the code that needs ``end.position``."""
        upd = {}
        for end in ("end_a", "end_b"):
            if getattr(line, end).attach is not None:
                p = self.end_position(line, end, poses)
                upd[end] = End(position=tuple(float(v) for v in p))
        return line.model_copy(update=upd) if upd else line

    @property
    def is_planar(self) -> bool:
        """True when every line, the sea, current and end motions lie in one vertical
        plane through the x axis (y = 0, headings 0 or 180 deg), so a 2-D model suffices."""
        tol = 1e-9
        for b in self.bodies:
            if b.out_of_plane:
                return False
        for ln in self.lines:
            for end in ("end_a", "end_b"):
                e = getattr(ln, end)
                y = e.position[1] if e.attach is None else e.attach.point[1]
                if abs(y) > tol:
                    return False
            for end in (ln.end_a, ln.end_b):
                m = end.motion
                if m is not None and (m.sway is not None or (m.rao is not None and m.rao.sway is not None)):
                    return False
        if self.sea is not None and abs(math.sin(self.sea.heading_rad)) > tol:
            return False
        for p in self.environment.current:
            if p.speed > 0 and abs(math.sin(p.heading_rad)) > tol:
                return False
        return True


# ---------------------------------------------------------------------- boundary


def field_path_and_unit(model: type[BaseModel] | None, loc: Sequence[Any]) -> tuple[str, str]:
    """Dotted path and declared unit of the field at a pydantic error location.

    Parameters
    ----------
    model : pydantic model class or None
        The model the location is relative to.
    loc : sequence of str and int
        A pydantic error location, e.g. ``("sea", "spectrum", "jonswap", "hs")``.

    Returns
    -------
    path : str
        ``"sea.spectrum.hs"``: discriminator tags (a union member's ``type`` default)
        and pydantic's validator labels are dropped, list indices become ``[i]``.
    unit : str
        The unit in the field's ``json_schema_extra`` (``"m"``), or ``""``.
    """
    from typing import get_args

    unit = ""
    candidates: list[type[BaseModel]] = [model] if model is not None else []
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
            continue
        tagged = [
            c for c in candidates
            if "type" in c.model_fields and c.model_fields["type"].default == part
        ]
        if tagged:
            candidates = tagged
            continue
        if isinstance(part, str) and part.startswith("function-"):
            continue
        if part in ("file", "table") and any(
                c in (BodyHydrodynamicsFile, BodyHydrodynamics) for c in candidates) \
                and not any(part in c.model_fields for c in candidates
                            if c is not BodyHydrodynamicsFile):
            if part == "table":
                candidates = [BodyHydrodynamics]
                continue
            if out.endswith("hydrodynamics"):
                candidates = [BodyHydrodynamicsFile]
                continue
        out += ("." if out else "") + str(part)
        current = next((c for c in candidates if part in c.model_fields), None)
        if current is None:
            candidates, unit = [], ""
            continue
        info = current.model_fields[part]
        extra = info.json_schema_extra
        unit = extra.get("unit", "") if isinstance(extra, dict) else ""
        found: list[type[BaseModel]] = []
        stack: list[Any] = [info.annotation]
        while stack:
            t = stack.pop()
            if isinstance(t, type) and issubclass(t, BaseModel):
                found.append(t)
                continue
            stack.extend(get_args(t))
        candidates = found
    return out, unit


#: A number followed by an SI unit symbol in a validator's message ("-120 m", "5 m²").
_QUOTED_UNIT = re.compile(r"([\d\]] )((?:kg|m|N)(?:[²³]|/m|/s)?)(?![\w/·])")


def input_error_from_validation(
    exc: ValidationError, model: type[BaseModel], prefix: str = "",
    labels: UnitLabels | None = None,
) -> InputError:
    """Convert the first error of a pydantic ValidationError into an InputError.

    ``labels``: the scene's unit system (:func:`stochcable.scene.units.labels_of_document`);
    the field's SI unit label is given in it (default SI).
    """
    errors = exc.errors(include_url=False)
    locs = [tuple(e.get("loc", ())) for e in errors]
    # pydantic repeats a nested failure at every enclosing tuple ("should have at least
    # 1 item"): keep only errors whose location is not a prefix of another's.
    leaves = [
        e for e, lc in zip(errors, locs)
        if not any(o != lc and o[: len(lc)] == lc for o in locs)
    ] or errors
    err = leaves[0]
    path, unit = field_path_and_unit(model, tuple(err.get("loc", ())))
    if labels is not None:
        unit = labels.convert(unit)
    path = path or "scene"
    if prefix:
        path = f"{prefix}.{path}" if path != "scene" else prefix
    msg = str(err.get("msg", "invalid"))
    if msg.startswith("Value error, "):
        msg = msg[len("Value error, "):]
    if labels is not None and labels.system != "SI":
        # the validators' own messages quote values with SI symbols ("z = -120 m")
        msg = _QUOTED_UNIT.sub(lambda mt: mt.group(1) + labels.convert(mt.group(2)), msg)
    more = len(leaves) - 1
    if more:
        msg += f" (and {more} more error{'s' if more > 1 else ''})"
    value = err.get("input")
    if isinstance(value, Mapping):
        value = InputError._NO_VALUE
    elif isinstance(value, (list, tuple)) and len(value) > 6:
        value = f"[{len(value)} values]"
    return InputError(path, value, unit, msg)


def rotate(rotation: np.ndarray, r: np.ndarray) -> np.ndarray:
    """R(θ)·r for a rotation vector θ (Rodrigues' formula). [m]"""
    th = float(np.linalg.norm(rotation))
    if th == 0.0:
        return np.array(r, dtype=float)
    k = rotation / th
    return (r * math.cos(th) + np.cross(k, r) * math.sin(th)
            + k * float(k @ r) * (1.0 - math.cos(th)))


def load_scene(source: Scene | Mapping[str, Any] | str | Path, *,
               allow_files: bool = True) -> Scene:
    """Validate a scene given as a model, a mapping, a JSON string or a path to a file.

    Parameters
    ----------
    source : Scene, mapping, str or path
        The scene document. A ``str`` that does not start with ``{`` is a file path.
    allow_files : bool, optional
        Accept bodies whose ``hydrodynamics`` is a ``{"file": ...}`` (the HTTP
        service passes False).  Relative paths are made absolute against the scene
        file's folder (a path source) or the working folder; the file must exist.

    Returns
    -------
    Scene
        The validated, frozen scene.

    Raises
    ------
    InputError
        Naming the first offending field path, its value, unit and constraint.
    """
    if isinstance(source, Scene):
        return _check_files(source, allow_files)
    base = Path.cwd()
    if isinstance(source, (str, Path)):
        text = str(source)
        if isinstance(source, Path) or not text.lstrip().startswith("{"):
            try:
                text = Path(source).read_text(encoding="utf-8")
                base = Path(source).resolve().parent
            except OSError as exc:
                raise InputError("scene", str(source), "-",
                                 f"cannot be read ({exc.strerror})") from None
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise InputError("scene", str(source)[:80], "-",
                             f"is not valid JSON ({exc.msg} at line {exc.lineno})") from None
    else:
        data = source
    try:
        scene = Scene.model_validate(data)
    except ValidationError as exc:
        raise input_error_from_validation(exc, Scene,
                                          labels=labels_of_document(data)) from None
    return _check_files(scene, allow_files, base)


def _check_files(scene: Scene, allow_files: bool, base: Path | None = None) -> Scene:
    """Refuse or resolve the bodies' hydrodynamics files (see :func:`load_scene`)."""
    if not scene.uses_files:
        return scene
    bodies = list(scene.bodies)
    for i, b in enumerate(bodies):
        h = b.hydrodynamics
        if not isinstance(h, BodyHydrodynamicsFile):
            continue
        where = f"bodies[{i}].hydrodynamics.file"
        if not allow_files:
            raise InputError(where, h.file, "-", "files are not accepted here: give the "
                             "coefficient table inline (docs/BODIES.md JSON table)")
        p = Path(h.file)
        if not p.is_absolute():
            p = (base if base is not None else Path.cwd()) / p
        if not p.is_file():
            raise InputError(where, h.file, "-", f"file not found (looked for {p})")
        if str(p) != h.file:
            bodies[i] = b.model_copy(update={"hydrodynamics": BodyHydrodynamicsFile(file=str(p))})
    if bodies == list(scene.bodies):
        return scene
    return scene.model_copy(update={"bodies": tuple(bodies)})


def scene_json_schema() -> dict[str, Any]:
    """The JSON Schema of the scene document (committed as openapi/scene.schema.json)."""
    schema = Scene.model_json_schema()
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = "stochcable scene (v1)"
    return schema
