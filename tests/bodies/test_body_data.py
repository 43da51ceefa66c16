"""Hydrodynamic coefficient readers (stochcable.bodies.data).

Independent checks: a dataset written with xarray in Capytaine's layout (names from
capytaine.io.xarray.assemble_dataset) read back exactly, complex split and merged, DOFs
reordered, excitation conjugated to e^{+iωt}; with Capytaine installed, a small BEM
solve of a vertical cylinder: the excitation of the same body meshed at two places
agrees after the wave-phase shift only with the conjugation (the e^{−iωt} → e^{+iωt}
check), the long-wave heave force tends to ρ g A_wp and the surge force leads the
wave by 90° (inertia); the JSON table format and its error paths.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from stochcable.bodies.data import (
    body_from_hydrodynamics,
    load_hydrodynamics,
    read_capytaine,
    read_table,
)
from stochcable.bodies.rigid import body_excitation
from stochcable.errors import InputError

DOFS = ["Surge", "Sway", "Heave", "Roll", "Pitch", "Yaw"]


def _spd(rng, n, scale):
    a = rng.normal(size=(n, n))
    return scale * (a @ a.T + n * np.eye(n))


def _capytaine_like(rng, n_w=4, headings=(0.0, math.pi / 2)):
    """A dataset in Capytaine's layout: (omega, influenced_dof, radiating_dof),
    (omega, wave_direction, influenced_dof), Capytaine's e^{−iωt} complex values."""
    xr = pytest.importorskip("xarray")
    w = np.linspace(0.3, 2.1, n_w)
    am = np.array([_spd(rng, 6, 100.0) for _ in w])
    bd = np.array([_spd(rng, 6, 10.0) for _ in w])
    fx = rng.normal(size=(n_w, len(headings), 6)) + 1j * rng.normal(size=(n_w, len(headings), 6))
    ds = xr.Dataset(
        {
            "added_mass": (("omega", "influenced_dof", "radiating_dof"), am),
            "radiation_damping": (("omega", "influenced_dof", "radiating_dof"), bd),
            "diffraction_force": (("omega", "wave_direction", "influenced_dof"), 0.25 * fx),
            "Froude_Krylov_force": (("omega", "wave_direction", "influenced_dof"), 0.75 * fx),
            "hydrostatic_stiffness": (("influenced_dof", "radiating_dof"), np.diag(np.arange(6.0))),
        },
        coords={
            "omega": w,
            "wave_direction": list(headings),
            "radiating_dof": DOFS,
            "influenced_dof": DOFS,
            "rotation_center": ("space_coordinate", [1.0, 2.0, -0.5]),
            "g": 9.81,
            "rho": 1025.0,
            "water_depth": np.inf,
            "forward_speed": 0.0,
        },
    )
    return ds, w, am, bd, fx


def test_read_capytaine_layout_from_netcdf(tmp_path):
    """Round trip through NetCDF with complex values split over a 'complex' dimension
    (as capytaine.io.xarray.separate_complex_values) and DOFs stored out of order."""
    pytest.importorskip("netCDF4")
    rng = np.random.default_rng(7)
    ds, w, am, bd, fx = _capytaine_like(rng)
    perm = [2, 0, 1, 5, 3, 4]
    shuffled = ds.isel(radiating_dof=perm, influenced_dof=perm[::-1])
    split = shuffled.copy()
    for v in ("diffraction_force", "Froude_Krylov_force"):
        da = shuffled[v]
        split[v] = (("complex",) + da.dims, np.stack([da.values.real, da.values.imag]))
    split = split.assign_coords(complex=["re", "im"])
    path = tmp_path / "body.nc"
    split.to_netcdf(path)
    h = read_capytaine(path)
    np.testing.assert_allclose(h.added_mass, am, rtol=1e-15)
    np.testing.assert_allclose(h.radiation_damping, bd, rtol=1e-15)
    # excitation = diffraction + Froude–Krylov, conjugated, (heading, dof, omega)
    np.testing.assert_allclose(h.excitation, np.conj(np.transpose(fx, (1, 2, 0))), rtol=1e-14)
    np.testing.assert_array_equal(h.heading, [0.0, math.pi / 2])
    np.testing.assert_array_equal(h.hydrostatic_stiffness, np.diag(np.arange(6.0)))
    np.testing.assert_array_equal(h.reference_point, [1.0, 2.0, -0.5])
    np.testing.assert_array_equal(h.excitation_point, [-1.0, -2.0])
    assert load_hydrodynamics(path).omega.tolist() == w.tolist()


def test_read_capytaine_errors():
    rng = np.random.default_rng(8)
    ds, *_ = _capytaine_like(rng)
    with pytest.raises(InputError, match="has no 'radiation_damping' variable"):
        read_capytaine(ds.drop_vars("radiation_damping"))
    bad = ds.copy()
    a = bad["added_mass"].values
    a = a + 0.5 * np.abs(a).max() * (np.arange(6)[:, None] > np.arange(6)[None, :])
    bad["added_mass"] = (bad["added_mass"].dims, a)
    with pytest.raises(InputError, match=r"added_mass = .*must be symmetric within 0.02"):
        read_capytaine(bad)
    neg = ds.copy()
    b = neg["radiation_damping"].values.copy()
    b[1, 2, 2] = -0.5 * np.abs(b).max()
    neg["radiation_damping"] = (neg["radiation_damping"].dims, b)
    with pytest.raises(InputError, match=r"diagonal entry 2 .* at omega = 0.9 rad/s.*must be >= 0"):
        read_capytaine(neg)
    with pytest.raises(
        InputError, match=r"must include the six rigid-body DOFs; missing \['Yaw'\]"
    ):
        read_capytaine(ds.isel(radiating_dof=slice(0, 5)))
    moving = ds.assign_coords(forward_speed=1.0)
    with pytest.raises(InputError, match="must be 0"):
        read_capytaine(moving)


# ----------------------------------------------------------------- with Capytaine


def _cylinder_dataset(center_x):
    cpt = pytest.importorskip("capytaine")
    xr = pytest.importorskip("xarray")
    mesh = cpt.mesh_vertical_cylinder(
        length=3.0, radius=1.0, center=(center_x, 0.0, -0.5), resolution=(3, 16, 6)
    )
    body = cpt.FloatingBody(
        mesh=mesh,
        dofs=cpt.rigid_body_dofs(rotation_center=(center_x, 0, 0)),
        center_of_mass=(center_x, 0, -0.5),
    ).immersed_part()
    test = xr.Dataset(
        coords={
            "omega": [0.2, 0.8, 1.4],
            "wave_direction": [0.0, math.pi / 4],
            "radiating_dof": list(body.dofs),
            "water_depth": [np.inf],
            "rho": [1025.0],
            "g": [9.81],
        }
    )
    return cpt.BEMSolver().fill_dataset(test, body, hydrostatics=True)


@pytest.mark.slow
def test_capytaine_cylinder_phase_convention(tmp_path):
    """The same cylinder meshed at x = 0 and at x = 5, both placed at x = 5: the
    excitation agrees after the wave-phase shift e^{−ik x cos β} only with the
    e^{−iωt} → e^{+iωt} conjugation; long waves: heave ≈ ρ g A_wp, surge leads by 90°."""
    pytest.importorskip("netCDF4")
    cpt = pytest.importorskip("capytaine")
    ds0 = _cylinder_dataset(0.0)
    ds5 = _cylinder_dataset(5.0)
    cpt.export_dataset(tmp_path / "c0.nc", ds0)
    h0 = read_capytaine(tmp_path / "c0.nc")
    h5 = read_capytaine(ds5)
    w = h0.omega
    k = w**2 / 9.81  # Capytaine's deep-water wave number with its g
    place = [5.0, 0.0, 0.0]
    b0 = body_from_hydrodynamics(h0, "c0", place, 1000.0)
    b5 = body_from_hydrodynamics(h5, "c5", place, 1000.0)
    for beta in (0.0, math.pi / 4):
        f0 = body_excitation(b0, w, beta, wavenumber=k)
        f5 = body_excitation(b5, w, beta, wavenumber=k)
        scale = np.abs(f0[:, :3]).max()
        # two BEM solves of the same translated mesh: equal to round-off of the solver
        np.testing.assert_allclose(f5[:, :3], f0[:, :3], atol=1e-6 * scale)
        # raw tables (phase at each dataset's origin): the shifted body sees the wave
        # later by k·5·cos β, X5 = X0·e^{−ik 5 cos β} in e^{+iωt} (e^{+ik…} without the
        # conjugation); ω = 1.4 gives k·5 = 1 rad, so the two signs differ clearly
        r0 = body_excitation(b0, w, beta)[:, 2]
        r5 = body_excitation(b5, w, beta)[:, 2]
        shift = np.exp(-1j * k * 5.0 * math.cos(beta))
        np.testing.assert_allclose(r5, r0 * shift, atol=1e-6 * np.abs(r0).max())
        if beta == 0.0:
            assert np.abs(r5 - r0 * np.conj(shift)).max() > 0.1 * np.abs(r0).max()
    # translation invariance of the radiation matrices about each body's own centre
    np.testing.assert_allclose(
        h5.added_mass, h0.added_mass, atol=1e-6 * np.abs(h0.added_mass).max()
    )
    # long waves (ω = 0.2, kR = 0.004): heave → ρ g A_wp (Froude–Krylov), in phase
    f = body_excitation(b0, w, 0.0)
    awp = math.pi * 1.0**2
    assert f[0, 2].real == pytest.approx(1025.0 * 9.81 * awp, rel=0.05)  # coarse mesh area
    assert abs(f[0, 2].imag) < 0.01 * abs(f[0, 2])
    # surge: inertia force ∝ fluid acceleration iω·u, leading η by +90° in e^{+iωt}
    assert math.degrees(np.angle(f[1, 0])) == pytest.approx(90.0, abs=5.0)


# ------------------------------------------------------------------ JSON table


def _table(rng, d=6, n_w=3, n_h=2):
    w = [0.4, 0.9, 1.6][:n_w]
    return {
        "dofs": ["surge", "sway", "heave", "roll", "pitch", "yaw"]
        if d == 6
        else ["surge", "heave", "pitch"],
        "omega": w,
        "added_mass": [_spd(rng, d, 50.0).tolist() for _ in w],
        "radiation_damping": [_spd(rng, d, 5.0).tolist() for _ in w],
        "excitation": {
            "heading": [0.0, 45.0][:n_h],
            "re": rng.normal(size=(n_h, d, n_w)).tolist(),
            "im": rng.normal(size=(n_h, d, n_w)).tolist(),
        },
        "hydrostatic_stiffness": np.diag(np.arange(1.0, d + 1)).tolist(),
    }


def test_read_table_file_and_body(tmp_path):
    rng = np.random.default_rng(11)
    doc = _table(rng)
    path = tmp_path / "buoy.json"
    path.write_text(json.dumps(doc))
    h = load_hydrodynamics(path)
    np.testing.assert_allclose(h.added_mass, np.array(doc["added_mass"]), rtol=1e-15)
    np.testing.assert_allclose(h.heading, np.radians([0.0, 45.0]), rtol=1e-15)
    exc = np.array(doc["excitation"]["re"]) + 1j * np.array(doc["excitation"]["im"])
    np.testing.assert_allclose(h.excitation, exc, rtol=1e-15)
    body = body_from_hydrodynamics(h, "buoy", [0, 0, 0], 500.0, planar=True)
    # planar reduction: surge, heave, pitch rows/columns of the 6×6 table
    np.testing.assert_allclose(
        body.added_mass_at([0.9])[0], np.array(doc["added_mass"][1])[np.ix_([0, 2, 4], [0, 2, 4])]
    )
    np.testing.assert_allclose(body_excitation(body, [0.4], 0.0)[0], exc[0][[0, 2, 4], 0])
    planar = read_table(json.dumps(_table(rng, d=3)))
    assert planar.planar and planar.added_mass.shape == (3, 3, 3)


@pytest.mark.parametrize(
    "mutate, match",
    [
        (lambda d: d.pop("omega"), r"omega = None: is missing from the table"),
        (
            lambda d: d.update(omega=[0.4, 0.9]),
            r"added_mass = \(3, 6, 6\).*has 3 frequencies but "
            r"omega has 2",
        ),
        (lambda d: d["excitation"].pop("heading"), r"excitation.heading = None: is missing"),
        (
            lambda d: d["excitation"].update(heading=[0.0]),
            r"has 2 headings but excitation.heading has 1",
        ),
        (
            lambda d: d.update(added_mass=np.ones((3, 6, 5)).tolist()),
            r"must have shape \(n_omega, 6, 6\)",
        ),
        (lambda d: d.update(dofs=["surge", "pitch"]), r"dofs = .*must be \["),
        (lambda d: d.update(omega=[0.9, 0.4, 1.6]), r"omega .* strictly increasing"),
        (lambda d: d.update(colour="red"), r"unknown keys"),
    ],
)
def test_read_table_errors(mutate, match):
    rng = np.random.default_rng(12)
    doc = _table(rng)
    mutate(doc)
    with pytest.raises(InputError, match=match):
        read_table(doc)


def test_read_table_symmetry_and_damping_checks():
    rng = np.random.default_rng(13)
    doc = _table(rng)
    a = np.array(doc["added_mass"])
    a[2, 0, 1] += 0.1 * np.abs(a[2]).max()
    doc["added_mass"] = a.tolist()
    with pytest.raises(InputError, match=r"at omega = 1.6 rad/s.*must be symmetric within"):
        read_table(doc)
    assert read_table(doc, symmetry_tolerance=0.2).added_mass[2, 0, 1] == pytest.approx(
        0.5 * (a[2, 0, 1] + a[2, 1, 0])
    )
    doc = _table(rng)
    b = np.array(doc["radiation_damping"])
    b[0, 5, 5] = -1.0
    doc["radiation_damping"] = b.tolist()
    with pytest.raises(InputError, match=r"radiation_damping = 'diagonal entry 5 = -1"):
        read_table(doc)
