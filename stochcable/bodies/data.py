"""Hydrodynamic coefficients of large bodies from files (Tuah (1982), §3.2.c).

Tuah (1982) leaves the added mass m_a, radiation damping c and exciting force C_l of a
large body to a diffraction–radiation code (eqs. 3.2.c.16–3.2.c.19: "no attempt is
made to evaluate [them]").  Two sources are read here into one
:class:`Hydrodynamics` record:

- a Capytaine dataset (NetCDF file or ``xarray.Dataset``), :func:`read_capytaine`;
- a plain JSON table, :func:`read_table` (format in docs/BODIES.md and
  :mod:`stochcable.scene.tables`, which reads and checks it for the scene too).

:func:`body_from_hydrodynamics` turns a record into a :class:`~stochcable.bodies.rigid.RigidBody`.

Conventions of the record (those of the library, DESIGN.md): ω in rad/s, headings in
rad (direction of travel from +x toward +y), DOFs (surge, sway, heave, roll, pitch, yaw)
about the reference point (or (surge, heave, pitch) for a planar table), complex
amplitudes of Re{X e^{iωt}}, excitation per unit wave amplitude.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np

from stochcable.bodies.rigid import SPATIAL_DOFS, RigidBody
from stochcable.bodies.tables import ExcitationTable, FrequencyTable
from stochcable.errors import InputError
from stochcable.scene.tables import SYMMETRY_TOLERANCE, checked_table, parse_table
from stochcable.validation import nonnegative

__all__ = [
    "Hydrodynamics",
    "read_capytaine",
    "read_table",
    "load_hydrodynamics",
    "body_from_hydrodynamics",
    "SYMMETRY_TOLERANCE",
]

# Capytaine's names of the rigid-body DOFs (capytaine.rigid_body_dofs).
_CAPYTAINE_DOFS = ("Surge", "Sway", "Heave", "Roll", "Pitch", "Yaw")


@dataclass(frozen=True, eq=False)
class Hydrodynamics:
    """Frequency-domain hydrodynamic coefficients of one body.

    Attributes
    ----------
    dofs : tuple of str
        DOF names, ``SPATIAL_DOFS`` or ``PLANAR_DOFS``.
    omega : ndarray, shape (n_w,)
        Strictly increasing angular frequencies. [rad/s]
    added_mass : ndarray, shape (n_w, d, d)
        Symmetric added mass. [kg, kg·m, kg·m²]
    radiation_damping : ndarray, shape (n_w, d, d)
        Symmetric radiation damping, non-negative diagonal. [N·s/m, N·s, N·m·s]
    heading : ndarray, shape (n_h,) or None
        Wave headings of the excitation, direction of travel from +x toward +y. [rad]
    excitation : ndarray, complex, shape (n_h, d, n_w) or None
        Excitation force per unit wave amplitude, Re{X e^{iωt}}. [N/m, N·m/m]
    hydrostatic_stiffness : ndarray, shape (d, d) or None
        [N/m, N, N·m]
    reference_point : ndarray, shape (3,)
        The point the matrices and moments refer to, in the data's own frame. [m]
    excitation_point : ndarray, shape (2,)
        Horizontal offset from ``reference_point`` of the point where the excitation
        phases are referred to the incident wave (Capytaine: the frame origin). [m]
    source : str
        Where the data came from.
    """

    dofs: tuple[str, ...]
    omega: np.ndarray
    added_mass: np.ndarray
    radiation_damping: np.ndarray
    heading: np.ndarray | None
    excitation: np.ndarray | None
    hydrostatic_stiffness: np.ndarray | None
    reference_point: np.ndarray
    excitation_point: np.ndarray
    source: str = ""

    @property
    def planar(self) -> bool:
        """True for a (surge, heave, pitch) table."""
        return len(self.dofs) == 3

    def added_mass_table(self, extrapolation: Literal["error", "hold"] = "error") -> FrequencyTable:
        """The added mass as a :class:`~stochcable.bodies.tables.FrequencyTable`."""
        return FrequencyTable(self.omega, self.added_mass, extrapolation)

    def radiation_damping_table(
        self, extrapolation: Literal["error", "hold"] = "error"
    ) -> FrequencyTable:
        """The radiation damping as a :class:`~stochcable.bodies.tables.FrequencyTable`."""
        return FrequencyTable(self.omega, self.radiation_damping, extrapolation)

    def excitation_table(
        self, extrapolation: Literal["error", "hold"] = "error"
    ) -> ExcitationTable | None:
        """The excitation as an :class:`~stochcable.bodies.tables.ExcitationTable`
        (None if absent)."""
        if self.excitation is None:
            return None
        return ExcitationTable(self.omega, self.heading, self.excitation, extrapolation)


# ---------------------------------------------------------------------- checks


def _build(dofs, omega, am, bd, heading, exc, hs, ref, exc_point, source, tol) -> Hydrodynamics:
    """The checked record (:func:`stochcable.scene.tables.checked_table`)."""
    return Hydrodynamics(
        **checked_table(dofs, omega, am, bd, heading, exc, hs, ref, exc_point, source, tol)
    )


# ------------------------------------------------------------------- Capytaine


def _require_xarray():
    try:
        import xarray as xr
    except ImportError:  # pragma: no cover - exercised only without the extra
        raise InputError(
            "source",
            "Capytaine dataset",
            "-",
            "reading NetCDF needs xarray and netCDF4: pip install 'stochcable[bodies]'",
        ) from None
    return xr


def read_capytaine(
    source: Any,
    *,
    symmetry_tolerance: float = SYMMETRY_TOLERANCE,
) -> Hydrodynamics:
    """Read the hydrodynamic coefficients of one rigid body from a Capytaine dataset.

    Parameters
    ----------
    source : str, Path or xarray.Dataset
        A NetCDF file written by ``capytaine.export_dataset`` /
        ``save_dataset_as_netcdf`` or the dataset of ``assemble_dataset`` /
        ``BEMSolver.fill_dataset``.
    symmetry_tolerance : float
        Accepted max|A − Aᵀ|/max|A| per frequency (the matrices are then symmetrized). [-]

    Returns
    -------
    Hydrodynamics
        Six DOFs about Capytaine's ``rotation_center`` (reference_point), excitation
        conjugated to the e^{+iωt} convention.

    Raises
    ------
    InputError
        Missing variables or DOFs, several bodies or water depths in one dataset,
        forward speed, non-symmetric matrices, negative damping.

    Notes
    -----
    Capytaine's dataset layout (``capytaine.io.xarray.assemble_dataset``; user manual,
    "Outputs": https://capytaine.org): variables ``added_mass`` and
    ``radiation_damping`` with dimensions (omega, influenced_dof, radiating_dof);
    ``excitation_force`` — or ``diffraction_force`` + ``Froude_Krylov_force``, summed
    here — with dimensions (omega, wave_direction, influenced_dof); optional
    ``hydrostatic_stiffness`` (influenced_dof, radiating_dof); coordinates ``omega``
    [rad/s], ``wave_direction`` [rad], ``radiating_dof`` and ``influenced_dof`` (names
    "Surge" … "Yaw" of ``rigid_body_dofs``), ``rotation_center``; complex values split
    over a ``complex`` dimension (re, im) in NetCDF files (``separate_complex_values``).
    Entry [i, j] is the force in DOF i (influenced) from the motion of DOF j (radiating).

    Capytaine writes harmonic quantities as Re{X e^{−iωt}} with the incident wave
    η = Re{e^{i(k(x cos β + y sin β) − ωt)}} (its ``airy_waves_potential``): the same
    real wave as the library's Re{e^{iωt} e^{−ik(x cos β + y sin β)}}, so the
    excitation is conjugated, X = conj(X_capytaine), and its phase is referred to the
    origin of the dataset's frame (``excitation_point`` = −rotation_center in x, y).
    Added mass and damping are real and need no change.  Tuah (1982), eqs. 3.2.c.16–17
    define the same quantities (f_lj = −ω² m_a + iω c, C_l).
    """
    ds, name = _open_dataset(source)
    if "complex" in ds.dims:
        for v in list(ds.data_vars):
            if "complex" in ds[v].dims:
                da = ds[v]
                ds[v] = da.sel(complex="re", drop=True) + 1j * da.sel(complex="im", drop=True)
        ds = ds.drop_vars("complex", errors="ignore")
    for req in ("added_mass", "radiation_damping"):
        if req not in ds:
            raise InputError(
                "source",
                name,
                "-",
                f"has no '{req}' variable (a Capytaine radiation dataset is needed)",
            )
    if "omega" not in ds.coords:
        raise InputError("source", name, "-", "has no 'omega' coordinate")
    freq_dim = ds["omega"].dims[0] if ds["omega"].dims else None
    if freq_dim is None:
        raise InputError(
            "source",
            name,
            "-",
            "has a single scalar omega: at least one frequency dimension is needed",
        )
    if "forward_speed" in ds.coords:
        fs = np.atleast_1d(ds["forward_speed"].values)
        if np.any(fs != 0):
            raise InputError("forward_speed", fs.tolist(), "m/s", "must be 0 (no forward speed)")
    sel, sel_i = _capytaine_dofs(ds)

    order = np.argsort(ds["omega"].values)
    w = np.asarray(ds["omega"].values, dtype=float)[order]

    def matrices(var):
        da = _squeeze_extra(ds[var], (freq_dim, "influenced_dof", "radiating_dof"), name)
        da = da.sel(influenced_dof=sel_i, radiating_dof=sel)
        return np.asarray(
            da.transpose(freq_dim, "influenced_dof", "radiating_dof").values, dtype=float
        )[order]

    am = matrices("added_mass")
    bd = matrices("radiation_damping")
    heading, exc = _capytaine_excitation(ds, name, freq_dim, sel_i, order)
    hs = None
    if "hydrostatic_stiffness" in ds:
        da = _squeeze_extra(ds["hydrostatic_stiffness"], ("influenced_dof", "radiating_dof"), name)
        hs = np.asarray(
            da.sel(influenced_dof=sel_i, radiating_dof=sel)
            .transpose("influenced_dof", "radiating_dof")
            .values,
            dtype=float,
        )
    ref = np.zeros(3)
    if "rotation_center" in ds:
        ref = np.asarray(ds["rotation_center"].values, dtype=float).reshape(3)
    return _build(
        tuple(SPATIAL_DOFS),
        w,
        am,
        bd,
        heading,
        exc,
        hs,
        ref,
        -ref[:2],
        f"capytaine:{name}",
        nonnegative("symmetry_tolerance", symmetry_tolerance, "-"),
    )


def _open_dataset(source: Any) -> tuple[Any, str]:
    """The dataset, loaded (a file is closed after loading), and its name."""
    xr = _require_xarray()
    if isinstance(source, xr.Dataset):
        ds, name = source, "xarray.Dataset"
    else:
        path = Path(source)
        if not path.is_file():
            raise InputError("source", str(source), "-", "file not found")
        ds, name = xr.open_dataset(path), str(path)
    try:
        ds = ds.load()
    finally:
        if not isinstance(source, xr.Dataset):
            ds.close()
    return ds, name


def _squeeze_extra(da: Any, keep: tuple[str, ...], name: str) -> Any:
    """``da`` without its dimensions other than ``keep``, each of which must have one
    value (InputError naming the dataset ``name`` otherwise)."""
    for dim in list(da.dims):
        if dim in keep:
            continue
        if da.sizes[dim] != 1:
            raise InputError(
                "source",
                name,
                "-",
                f"variable '{da.name}' varies over '{dim}' "
                f"({da.sizes[dim]} values): select one before reading",
            )
        da = da.isel({dim: 0})
    return da


def _capytaine_dofs(ds: Any) -> tuple[list[str], list[str]]:
    """The dataset's radiating and influenced DOF labels of the six rigid-body DOFs, in
    the library's order (any case)."""
    dofs_present = [str(v) for v in ds["radiating_dof"].values]
    lower = {v.lower(): v for v in dofs_present}
    missing = [d for d in _CAPYTAINE_DOFS if d.lower() not in lower]
    if missing:
        raise InputError(
            "radiating_dof",
            dofs_present,
            "-",
            f"must include the six rigid-body DOFs; missing {missing}",
        )
    sel = [lower[d.lower()] for d in _CAPYTAINE_DOFS]
    infl = {str(v).lower(): str(v) for v in ds["influenced_dof"].values}
    if any(d.lower() not in infl for d in _CAPYTAINE_DOFS):
        raise InputError(
            "influenced_dof", list(infl.values()), "-", "must include the six rigid-body DOFs"
        )
    return sel, [infl[d.lower()] for d in _CAPYTAINE_DOFS]


def _capytaine_excitation(
    ds: Any, name: str, freq_dim: str, sel_i: list[str], order: np.ndarray
) -> tuple[np.ndarray | None, np.ndarray | None]:
    """Headings [rad] (one turn from the first, increasing) and the excitation
    (n_h, 6, n_w), conjugated to e^{+iωt} (read_capytaine's Notes); None, None without
    an excitation (or diffraction + Froude–Krylov) force."""
    if "excitation_force" in ds:
        fx = ds["excitation_force"]
    elif "diffraction_force" in ds and "Froude_Krylov_force" in ds:
        fx = ds["diffraction_force"] + ds["Froude_Krylov_force"]
        fx.name = "excitation_force"
    else:
        return None, None
    fx = _squeeze_extra(fx, (freq_dim, "wave_direction", "influenced_dof"), name)
    if "wave_direction" not in fx.dims:
        fx = fx.expand_dims("wave_direction")
        hvals = (
            np.atleast_1d(ds["wave_direction"].values)
            if "wave_direction" in ds.coords
            else np.zeros(1)
        )
    else:
        hvals = np.asarray(fx["wave_direction"].values, dtype=float)
    fx = fx.sel(influenced_dof=sel_i).transpose("wave_direction", "influenced_dof", freq_dim)
    vals = np.conj(np.asarray(fx.values, dtype=complex))[:, :, order]
    two_pi = 2.0 * math.pi
    hw = np.asarray(hvals, dtype=float)
    hw = hw[0] + (hw - hw[0]) % two_pi  # one turn from the first heading
    ho = np.argsort(hw)
    return hw[ho], vals[ho]


# ------------------------------------------------------------------ JSON table


def read_table(
    source: Mapping[str, Any] | str | Path,
    *,
    symmetry_tolerance: float = SYMMETRY_TOLERANCE,
) -> Hydrodynamics:
    """Read hydrodynamic coefficients from the JSON table format (module docstring).

    Parameters
    ----------
    source : mapping, JSON string or path
        The table document.
    symmetry_tolerance : float
        Accepted max|A − Aᵀ|/max|A| per frequency. [-]

    Returns
    -------
    Hydrodynamics
        Excitation headings converted from degrees to radians; phases referred to the
        reference point (``excitation_point`` = 0).

    Raises
    ------
    InputError
        Missing keys, missing frequencies or headings, wrong shapes, non-symmetric
        matrices, negative damping diagonal.
    """
    return Hydrodynamics(**parse_table(source, symmetry_tolerance=symmetry_tolerance))


def load_hydrodynamics(path: str | Path, **kw: Any) -> Hydrodynamics:
    """Read a ``.nc`` (Capytaine) or ``.json`` (table) file by its suffix."""
    p = Path(path)
    if p.suffix.lower() in (".nc", ".nc4", ".netcdf"):
        return read_capytaine(p, **kw)
    if p.suffix.lower() == ".json":
        return read_table(p, **kw)
    raise InputError("path", str(path), "-", "must end in .nc (Capytaine) or .json (table)")


def body_from_hydrodynamics(
    hydro: Hydrodynamics,
    name: str,
    position: Any,
    mass: float,
    *,
    inertia: Any = None,
    cog: Any = None,
    planar: bool = False,
    extrapolation: Literal["error", "hold"] = "error",
    **kw: Any,
) -> RigidBody:
    """A :class:`~stochcable.bodies.rigid.RigidBody` with the coefficients of ``hydro``.

    Parameters
    ----------
    hydro : Hydrodynamics
    name : str
    position : array_like, shape (3,)
        Global position of the data's reference point (the body reference point). [m]
    mass : float
        [kg]
    inertia, cog
        See :class:`~stochcable.bodies.rigid.RigidBody`.
    planar : bool
        Three-DOF body (a 6-DOF table is reduced to surge, heave, pitch).
    extrapolation : {"error", "hold"}
        Outside the table's frequencies.
    **kw
        Other RigidBody fields (``drag_area``, ``extra_damping``, …); a
        ``hydrostatic_stiffness`` given here replaces the table's.

    Returns
    -------
    RigidBody
    """
    if hydro.planar and not planar:
        raise InputError("planar", planar, "-", "a (surge, heave, pitch) table needs planar=True")
    hs = kw.pop("hydrostatic_stiffness", hydro.hydrostatic_stiffness)
    return RigidBody(
        name=name,
        position=position,
        mass=mass,
        inertia=inertia,
        cog=cog,
        added_mass=hydro.added_mass_table(extrapolation),
        radiation_damping=hydro.radiation_damping_table(extrapolation),
        hydrostatic_stiffness=hs,
        excitation=hydro.excitation_table(extrapolation),
        excitation_point=hydro.excitation_point,
        planar=planar,
        **kw,
    )
