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
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Annotated, Any, Literal, Union

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from .errors import InputError

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
    "End",
    "Segment",
    "Attachment",
    "Line",
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
        from .spectra import spectrum_statistics

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
        from . import spectra

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
        from . import spectra

        return spectra.spectrum_jonswap(
            omega, self.hs, self.tp, self.gamma, self.sigma_a, self.sigma_b
        )


class Bretschneider(_SpectrumBase):
    """Bretschneider (two-parameter) spectrum in (hs, tp)."""

    type: Literal["bretschneider"] = "bretschneider"
    hs: float = _f("Significant wave height", "m", ge=1e-6, le=1e4)
    tp: float = _f("Peak period", "s", ge=1e-3, le=1e5)

    def spectral_density(self, omega: np.ndarray, g: float = G_STANDARD) -> np.ndarray:
        from . import spectra

        return spectra.spectrum_bretschneider(omega, self.hs, self.tp)


class Issc(_SpectrumBase):
    """ISSC spectrum in (hs, t1), t1 the mean period Tm01."""

    type: Literal["issc"] = "issc"
    hs: float = _f("Significant wave height", "m", ge=1e-6, le=1e4)
    t1: float = _f("Mean period Tm01", "s", ge=1e-3, le=1e5)

    def spectral_density(self, omega: np.ndarray, g: float = G_STANDARD) -> np.ndarray:
        from . import spectra

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
        from . import spectra

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
        from . import spectra

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


class End(_Doc):
    """A line end: fixed at ``position`` unless a ``motion`` is prescribed about it."""

    position: tuple[float, float, float] = _f("Position (x, y, z), z up", "m")
    motion: EndMotion | None = None


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
        span = math.dist(self.end_a.position, self.end_b.position)
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
        return self


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
    analysis: AnalysisSettings = Field(default_factory=AnalysisSettings)

    @model_validator(mode="after")
    def _check_scene(self) -> "Scene":
        names = [ln.name for ln in self.lines]
        dup = {n for n in names if names.count(n) > 1}
        if dup:
            raise ValueError(f"line names must be unique; repeated: {sorted(dup)}")
        depth = self.environment.depth
        for i, ln in enumerate(self.lines):
            for end in ("end_a", "end_b"):
                z = getattr(ln, end).position[2]
                if z < -depth * (1 + 1e-9):
                    raise ValueError(
                        f"lines[{i}].{end}.position z = {z} m is below the seabed "
                        f"(depth {depth} m)"
                    )
            za = ln.end_a.position[2]
            if za > 0.0:
                raise ValueError(
                    f"lines[{i}].end_a.position z = {za} m: the anchor end (end_a) is "
                    "above the still-water surface (z must be <= 0)"
                )
        return self

    @property
    def is_planar(self) -> bool:
        """True when every line, the sea, current and end motions lie in one vertical
        plane through the x axis (y = 0, headings 0 or 180 deg), so a 2-D model suffices."""
        tol = 1e-9
        for ln in self.lines:
            if abs(ln.end_a.position[1]) > tol or abs(ln.end_b.position[1]) > tol:
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


def input_error_from_validation(
    exc: ValidationError, model: type[BaseModel], prefix: str = ""
) -> InputError:
    """Convert the first error of a pydantic ValidationError into an InputError."""
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
    path = path or "scene"
    if prefix:
        path = f"{prefix}.{path}" if path != "scene" else prefix
    msg = str(err.get("msg", "invalid"))
    if msg.startswith("Value error, "):
        msg = msg[len("Value error, "):]
    more = len(leaves) - 1
    if more:
        msg += f" (and {more} more error{'s' if more > 1 else ''})"
    value = err.get("input")
    if isinstance(value, Mapping):
        value = InputError._NO_VALUE
    elif isinstance(value, (list, tuple)) and len(value) > 6:
        value = f"[{len(value)} values]"
    return InputError(path, value, unit, msg)


def load_scene(source: Scene | Mapping[str, Any] | str | Path) -> Scene:
    """Validate a scene given as a model, a mapping, a JSON string or a path to a file.

    Parameters
    ----------
    source : Scene, mapping, str or path
        The scene document. A ``str`` that does not start with ``{`` is a file path.

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
        return source
    if isinstance(source, (str, Path)):
        text = str(source)
        if isinstance(source, Path) or not text.lstrip().startswith("{"):
            try:
                text = Path(source).read_text(encoding="utf-8")
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
        return Scene.model_validate(data)
    except ValidationError as exc:
        raise input_error_from_validation(exc, Scene) from None


def scene_json_schema() -> dict[str, Any]:
    """The JSON Schema of the scene document (committed as openapi/scene.schema.json)."""
    schema = Scene.model_json_schema()
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = "stochcable scene (v1)"
    return schema
