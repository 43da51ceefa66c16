"""Lines of the scene: ends (fixed, moving or attached to a body), segments and
attachments (clump weights, buoys).

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Literal

from pydantic import Field, field_validator, model_validator

from stochcable.scene.base import LocatedValueError, _Doc, _f
from stochcable.scene.raos import MotionRao
from stochcable.scene.spectra import Spectrum

__all__ = [
    "EndMotion",
    "BodyAttachment",
    "End",
    "SegmentStrumming",
    "Segment",
    "Attachment",
    "Line",
    "check_span",
]


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
    def _one_kind(self) -> EndMotion:
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
        "Attachment point relative to the body reference point, global axes, at the static pose",
        "m",
        default=(0.0, 0.0, 0.0),
    )


class End(_Doc):
    """A line end: fixed at ``position`` unless a ``motion`` is prescribed about it, or
    attached to a body (``attach``), which then carries it (Tuah (1982), eqs. 3.3.6–3.3.7)."""

    position: tuple[float, float, float] | None = _f(
        "Position (x, y, z), z up from the still-water level; end_a: z <= 0 (the part of "
        "a line above z = 0 has its weight in air, no buoyancy, no wave or current load)",
        "m",
        default=None,
    )
    motion: EndMotion | None = None
    attach: BodyAttachment | None = None

    @model_validator(mode="after")
    def _position_or_attach(self) -> End:
        if self.attach is None and self.position is None:
            raise ValueError("give the end's position or attach it to a body")
        if self.attach is not None and self.position is not None:
            raise ValueError(
                "give position or attach, not both (an attached end's "
                "position is the body position plus attach.point)"
            )
        if self.attach is not None and self.motion is not None:
            raise ValueError(
                "an end attached to a body cannot have a motion: the body "
                "moves it (give the body a 'prescribed' motion instead)"
            )
        return self


class SegmentStrumming(_Doc):
    """Strumming (vortex-induced vibration) settings of a segment (docs/strumming.md).

    The screening runs only where a current flows; ``suppression`` "strakes" or
    "fairings" turns the vortex shedding of the segment off.
    """

    strouhal: float | Literal["reynolds"] = _f(
        "Strouhal number St of the shedding frequency 2π·St·U_n/D, or 'reynolds': from "
        "the Reynolds number (Roshko 1954 below Re 2000, 0.2 above)",
        "-",
        default=0.2,
    )
    lift_coefficient: float = _f(
        "Lift-coefficient amplitude C_L0 of the fixed cylinder (wake oscillator)",
        "-",
        ge=0,
        le=5,
        default=0.2,
    )
    damping_ratio: float = _f(
        "Structural damping ratio of the modes (added to the viscous damping)",
        "-",
        ge=0,
        lt=1,
        default=0.0,
    )
    suppression: Literal["none", "strakes", "fairings"] = Field(
        default="none",
        description="VIV suppression fitted: strakes or fairings turn strumming off",
    )

    @field_validator("strouhal")
    @classmethod
    def _strouhal_range(cls, v: float | str) -> float | str:
        if not isinstance(v, str) and not 0.0 < v <= 1.0:
            raise ValueError(f"St = {v} must be > 0 and <= 1")
        return v


class Segment(_Doc):
    """A homogeneous stretch of line."""

    length: float = _f("Unstretched length", "m", gt=0)
    ea: float = _f("Axial stiffness EA", "N", gt=0)
    mass: float = _f("Mass per unit length in air", "kg/m", gt=0)
    diameter: float = _f("Hydrodynamic (volume-equivalent) diameter", "m", gt=0)
    cd_normal: float = _f("Normal drag coefficient, on the diameter", "-", ge=0, default=1.2)
    cd_axial: float = _f(
        "Axial drag coefficient, on pi·diameter (as MoorDyn's CdAx)", "-", ge=0, default=0.0
    )
    ca_normal: float = _f("Normal added-mass coefficient", "-", ge=0, default=1.0)
    cl_steady: float = _f(
        "Steady lift coefficient, on the diameter and the relative flow speed squared: "
        "½ρ·C_L·D·|U − c·t|² per length, across the element and the cross-flow, "
        "upward for C_L > 0 (Hu & Jin 2001, eq. 6; only where a current crosses the "
        "element; docs/travelling.md)",
        "-",
        ge=-5,
        le=5,
        default=0.0,
    )
    weight: float | None = _f(
        "Net submerged weight per unit length, overriding (mass - rho·pi·D²/4)·g; "
        "negative for buoyant line",
        "N/m",
        default=None,
    )
    elements: int = _f(
        "Number of finite elements.  Left out: the analysis runs once at 20 and again "
        "at the count whose estimated discretization error of the end-tension σ is at "
        "most 1 % (the fidelity planner's string-wave and touchdown element rules, "
        "stochcable.fidelity.mesh_check), when 20 does not meet it; an explicit count "
        "above that estimate gives a ResolutionWarning naming the count that does",
        "-",
        ge=1,
        le=100_000,
        default=20,
    )
    strumming: SegmentStrumming | None = Field(
        default=None,
        description="Strumming settings (default: St 0.2, C_L0 0.2, no suppression)",
    )

    def submerged_weight(self, rho: float, g: float) -> float:
        """Net weight per unit length in water. [N/m]"""
        if self.weight is not None:
            return self.weight
        return (self.mass - rho * math.pi * self.diameter**2 / 4.0) * g


class Attachment(_Doc):
    """A point mass (clump weight) and/or buoy at an arc length of the line."""

    at: float = _f("Unstretched arc length from end_a", "m", ge=0)
    mass: float = _f("Mass in air", "kg", ge=0, default=0.0)
    buoyancy: float = _f(
        "Upward buoyancy force (weight of displaced water)", "N", ge=0, default=0.0
    )
    added_mass: float = _f("Added mass, all directions", "kg", ge=0, default=0.0)
    drag_area: float = _f("Drag coefficient times projected area, Cd·A", "m²", ge=0, default=0.0)


class Line(_Doc):
    """A line from end_a (the anchor or lower end) to end_b, of one or more segments."""

    name: str = Field(
        min_length=1,
        max_length=64,
        pattern=r"^[A-Za-z0-9_.\-]+$",
        description="Unique line name (letters, digits, _ . -)",
    )
    end_a: End
    end_b: End
    segments: tuple[Segment, ...] = Field(min_length=1, max_length=1000)
    attachments: tuple[Attachment, ...] = Field(default=(), max_length=10_000)
    axial_speed: float = _f(
        "Transport speed of the line's material along itself (laying, payout, hauling), "
        "positive from end_a to end_b, negative from end_b to end_a; |c| must stay "
        "below the critical speed √(T/m) of the static line (docs/travelling.md)",
        "m/s",
        ge=-1000.0,
        le=1000.0,
        default=0.0,
    )

    @property
    def length(self) -> float:
        """Total unstretched length. [m]"""
        return float(sum(s.length for s in self.segments))

    @property
    def elements(self) -> int:
        """Total number of finite elements."""
        return int(sum(s.elements for s in self.segments))

    @model_validator(mode="after")
    def _check_line(self) -> Line:
        total = self.length
        if self.axial_speed != 0.0 and self.attachments:
            raise LocatedValueError(
                ("axial_speed",),
                self.axial_speed,
                "a travelling line cannot have "
                "attachments (they would travel with it: no steady state)",
            )
        for i, a in enumerate(self.attachments):
            if a.at > total * (1 + 1e-12):
                raise ValueError(
                    f"attachments[{i}].at = {a.at} m is beyond the line length {total} m"
                )
        if self.end_a.position is not None and self.end_b.position is not None:
            # attached ends: checked by Scene._check_scene with the body positions
            check_span(self.end_a.position, self.end_b.position, total)
        return self


def check_span(a: Sequence[float], b: Sequence[float], total: float) -> None:
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
