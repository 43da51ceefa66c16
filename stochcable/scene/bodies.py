"""Bodies of the scene: large rigid bodies (buoys, discs, vessels), their mass,
hydrodynamic coefficients (inline table or file) and prescribed motions.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Annotated, Any, Literal

from pydantic import Discriminator, Field, Tag, model_validator

from stochcable.errors import InputError
from stochcable.scene.base import _Doc, _f
from stochcable.scene.raos import VesselMotion
from stochcable.scene.tables import BODY_DOFS, PLANAR_BODY_DOFS, parse_table

__all__ = [
    "BODY_DOFS",
    "PLANAR_BODY_DOFS",
    "BodyExcitation",
    "BodyHydrodynamics",
    "BodyHydrodynamicsFile",
    "Body",
]


Matrix = tuple[tuple[float, ...], ...]
Vec3 = tuple[float, float, float]


class BodyExcitation(_Doc):
    """Wave excitation table of a body (docs/BODIES.md JSON table format)."""

    heading: tuple[float, ...] = _f(
        "Wave headings, increasing, spanning < 360", "deg", min_length=1
    )
    re: tuple[Matrix, ...] = _f(
        "Real part, (n_heading, n_dof, n_omega), per unit wave amplitude, e^{+iωt}", "N/m, N·m/m"
    )
    im: tuple[Matrix, ...] = _f("Imaginary part, shape as re", "N/m, N·m/m")


class BodyHydrodynamics(_Doc):
    """Hydrodynamic coefficients over ω, inline (the JSON table of docs/BODIES.md).

    Checked with :func:`stochcable.bodies.data.read_table` (shapes, symmetry within
    2 %, non-negative damping diagonal).
    """

    dofs: tuple[str, ...] | None = Field(
        default=None, description="DOF order: the six (default) or surge, heave, pitch"
    )
    omega: tuple[float, ...] = _f("Angular frequencies, strictly increasing", "rad/s", min_length=1)
    added_mass: tuple[Matrix, ...] = _f(
        "Added mass (n_omega, d, d) about the reference point", "kg, kg·m, kg·m²"
    )
    radiation_damping: tuple[Matrix, ...] = _f(
        "Radiation damping (n_omega, d, d)", "N·s/m, N·s, N·m·s"
    )
    excitation: BodyExcitation | None = None
    hydrostatic_stiffness: Matrix | None = _f(
        "Hydrostatic restoring (d, d), weight terms included", "N/m, N, N·m/rad", default=None
    )
    reference_point: Vec3 | None = _f(
        "Reference point of the table (informative)", "m", default=None
    )

    @model_validator(mode="after")
    def _check_table(self) -> BodyHydrodynamics:
        try:
            parse_table(self.table())
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

    file: str = Field(
        min_length=1, max_length=4096, description="Path of a Capytaine .nc or JSON table file"
    )


def _hydro_kind(v: Any) -> str:
    """Discriminator of Body.hydrodynamics: a mapping with 'file' is a file reference."""
    if isinstance(v, Mapping):
        return "file" if "file" in v else "table"
    return "file" if isinstance(v, BodyHydrodynamicsFile) else "table"


class Body(_Doc):
    """A large rigid body (buoy, disc, vessel; Tuah (1982), §3.2.c, eq. 3.2.c.20).

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

    name: str = Field(
        min_length=1,
        max_length=64,
        pattern=r"^[A-Za-z0-9_.\-]+$",
        description="Unique body name (letters, digits, _ . -)",
    )
    position: Vec3 = _f(
        "Reference point at the static pose (initial guess of the statics for a free body)", "m"
    )
    mass: float = _f("Mass", "kg", gt=0)
    inertia: Matrix | None = _f(
        "Inertia tensor about the centre of gravity, global axes, 3×3", "kg·m²", default=None
    )
    cog: Vec3 = _f(
        "Centre of gravity relative to the reference point", "m", default=(0.0, 0.0, 0.0)
    )
    added_mass: Matrix | None = _f("Constant added mass", "kg, kg·m, kg·m²", default=None)
    radiation_damping: Matrix | None = _f(
        "Constant radiation damping", "N·s/m, N·s, N·m·s", default=None
    )
    hydrostatic_stiffness: Matrix | None = _f(
        "Hydrostatic restoring about the reference point, weight terms included",
        "N/m, N, N·m/rad",
        default=None,
    )
    extra_stiffness: Matrix | None = _f(
        "Additional linear stiffness", "N/m, N, N·m/rad", default=None
    )
    extra_damping: Matrix | None = _f(
        "Additional linear damping", "N·s/m, N·s, N·m·s", default=None
    )
    hydrodynamics: (
        Annotated[
            Annotated[BodyHydrodynamicsFile, Tag("file")]
            | Annotated[BodyHydrodynamics, Tag("table")],
            Discriminator(_hydro_kind),
        ]
        | None
    ) = Field(default=None, description="Frequency-dependent coefficients: inline table or file")
    displaced_volume: float | None = _f(
        "Displaced volume for the static buoyancy", "m³", ge=0, default=None
    )
    centre_of_buoyancy: Vec3 = _f(
        "Centre of buoyancy relative to the reference point", "m", default=(0.0, 0.0, 0.0)
    )
    drag_area: Vec3 = _f(
        "Drag coefficient times area, Cd·A, for flow along x, y, z", "m²", default=(0.0, 0.0, 0.0)
    )
    drag_point: Vec3 = _f(
        "Point of application of the drag relative to the reference point",
        "m",
        default=(0.0, 0.0, 0.0),
    )
    wind_force: Vec3 = _f(
        "Static wind force at the reference point (Tuah (1982), §6.5)", "N", default=(0.0, 0.0, 0.0)
    )
    wind_moment: Vec3 = _f(
        "Static wind moment about the reference point", "N·m", default=(0.0, 0.0, 0.0)
    )
    extrapolation: Literal["error", "hold"] = Field(
        default="error",
        description="Outside the frequencies of the hydrodynamic table: "
        "refuse, or hold the end values",
    )
    prescribed: VesselMotion | None = Field(
        default=None,
        description="Prescribed motion (a vessel): the body is not solved "
        "for; its static pose is position, no rotation",
    )
    fixed_dofs: tuple[Literal["surge", "sway", "heave", "roll", "pitch", "yaw"], ...] = Field(
        default=(),
        description="DOFs held fixed (statics and dynamics), e.g. yaw of a buoy on one line",
    )

    @model_validator(mode="after")
    def _check_body(self) -> Body:
        for k in (
            "added_mass",
            "radiation_damping",
            "hydrostatic_stiffness",
            "extra_stiffness",
            "extra_damping",
        ):
            m = getattr(self, k)
            if m is None:
                continue
            n = len(m)
            if n not in (3, 6) or any(len(row) != n for row in m):
                raise ValueError(f"{k} must be a 6×6 or (planar) 3×3 matrix")
        if self.inertia is not None and (
            len(self.inertia) != 3 or any(len(r) != 3 for r in self.inertia)
        ):
            raise ValueError("inertia must be a 3×3 tensor")
        if any(v < 0 for v in self.drag_area):
            raise ValueError(f"drag_area = {list(self.drag_area)} m²: must be >= 0")
        if len(set(self.fixed_dofs)) != len(self.fixed_dofs):
            raise ValueError("fixed_dofs are repeated")
        return self

    @property
    def planar_data(self) -> bool:
        """True when a matrix or the table is 3×3 (surge, heave, pitch)."""
        mats = [
            getattr(self, k)
            for k in (
                "added_mass",
                "radiation_damping",
                "hydrostatic_stiffness",
                "extra_stiffness",
                "extra_damping",
            )
        ]
        if any(m is not None and len(m) == 3 for m in mats):
            return True
        h = self.hydrodynamics
        return isinstance(h, BodyHydrodynamics) and h.planar

    @property
    def out_of_plane(self) -> bool:
        """True when the body leaves the x–z plane: y of its points, sway forces,
        roll/yaw moments, out-of-plane vessel RAOs."""
        tol = 1e-9
        ys = [
            self.position[1],
            self.cog[1],
            self.centre_of_buoyancy[1],
            self.drag_point[1],
            self.wind_force[1],
            self.wind_moment[0],
            self.wind_moment[2],
        ]
        if any(abs(v) > tol for v in ys):
            return True
        return self.prescribed is not None and self.prescribed.out_of_plane
