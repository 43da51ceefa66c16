"""Tests of stochcable.dynamics.loads.channels: input channels and hydrodynamic matrices."""

from __future__ import annotations

import math

import numpy as np
import pytest

from stochcable.dynamics.linearization import variance as dvariance
from stochcable.dynamics.loads.channels import (
    drag_matrix,
    element_frames,
    inertia_matrix,
    line_channels,
    prescribed_motion,
)
from stochcable.dynamics.model import system as dsystem
from stochcable.errors import InputError
from stochcable.scene.model import load_scene
from stochcable.sea.kinematics import wave_kinematics
from stochcable.statics import solve_statics

RHO = 1025.0
G = 9.80665


def straight_doc(*, sea=True, motion=None, heading=20.0, attachments=()):
    """An inclined taut weightless straight line (3-D: out of the x-z plane)."""
    end_b = {"position": [60.0, 30.0, -20.0]}
    if motion is not None:
        end_b["motion"] = motion
    doc = {
        "environment": {"depth": 100.0, "rho": RHO, "g": G},
        "lines": [
            {
                "name": "l",
                "end_a": {"position": [0.0, 0.0, -80.0]},
                "end_b": end_b,
                "segments": [
                    {
                        "length": 89.0,
                        "ea": 1.0e8,
                        "mass": 20.0,
                        "diameter": 0.2,
                        "cd_normal": 1.2,
                        "cd_axial": 0.3,
                        "ca_normal": 0.8,
                        "weight": 0.0,
                        "elements": 9,
                    }
                ],
                "attachments": list(attachments),
            }
        ],
        "analysis": {"omega": {"min": 0.2, "max": 1.5, "count": 7}},
    }
    if sea:
        doc["sea"] = {
            "spectrum": {"type": "pierson_moskowitz", "hs": 3.0, "tp": 8.0},
            "heading": heading,
        }
    return doc


def built(doc):
    scene = load_scene(doc)
    st = solve_statics(scene).lines["l"]
    system = dsystem.build_line_system(scene, scene.lines[0], st)
    return scene, system


def test_inertia_matrix_rigid_acceleration_gives_morison_force():
    """A uniform fluid acceleration a on a straight line: total force
    ρ(πD²/4)(1+Ca)·L0·(I − eeᵀ)a (Tuah 1982, eq. 5.2.1), plus the attachment's
    (buoyancy/g + added mass)·a."""
    # neutrally buoyant attachment, so the weightless line stays straight
    att = {"at": 40.0, "mass": 500.0, "buoyancy": 500.0 * G, "added_mass": 300.0}
    scene, system = built(straight_doc(attachments=[att]))
    model = system.model
    b = inertia_matrix(model, G)
    a = np.array([0.3, -0.2, 0.5])
    force = (b @ np.tile(a, model.n_nodes)).reshape(-1, 3).sum(axis=0)
    e = element_frames(model.positions)[0][0]
    line = RHO * math.pi * 0.2**2 / 4 * 1.8 * 89.0 * (a - e * (e @ a))
    node = (500.0 + 300.0) * a
    np.testing.assert_allclose(force, line + node, rtol=1e-12)
    # symmetric (element direction constant over the element)
    assert abs(b - b.T).max() == 0.0


def test_inertia_minus_added_mass_is_froude_krylov():
    """Ü = A (line moving with the fluid): B_I A − Ma A = ρ(πD²/4)(I − eeᵀ)A per length."""
    scene, system = built(straight_doc())
    model = system.model
    b = inertia_matrix(model, G)
    a = np.tile(np.array([0.0, 1.0, 0.0]), model.n_nodes)
    fk = ((b - model.Ma) @ a).reshape(-1, 3).sum(axis=0)
    e = element_frames(model.positions)[0][0]
    expected = RHO * math.pi * 0.2**2 / 4 * 89.0 * (np.array([0, 1.0, 0]) - e * e[1])
    np.testing.assert_allclose(fk, expected, rtol=1e-12)


def test_drag_matrix_uniform_velocity_and_vector_form():
    scene, system = built(straight_doc())
    model = system.model
    n_el = model.n_elements
    bn, bt = 37.0, 5.0
    c = drag_matrix(model, np.full(n_el, bn), np.full(n_el, bt))
    v = np.array([0.4, 0.1, -0.3])
    force = (c @ np.tile(v, model.n_nodes)).reshape(-1, 3).sum(axis=0)
    e = element_frames(model.positions)[0][0]
    vt = e * (e @ v)
    np.testing.assert_allclose(force, 89.0 * (bn * (v - vt) + bt * vt), rtol=1e-12)
    # the 2×2 normal-plane form with B = bn I equals the scalar form
    c2 = drag_matrix(model, np.broadcast_to(bn * np.eye(2), (n_el, 2, 2)), np.full(n_el, bt))
    assert abs(c2 - c).max() < 1e-12 * bn * 89.0


def test_element_frames_are_orthonormal_and_n2_out_of_plane():
    pos = np.array([[0, 0, -50.0], [10, 0, -40.0], [20, 0, -35.0], [20, 0, -20.0]])
    e, n1, n2 = element_frames(pos)
    for a in (e, n1, n2):
        np.testing.assert_allclose(np.linalg.norm(a, axis=1), 1.0, rtol=1e-14)
    np.testing.assert_allclose(np.einsum("ij,ij->i", e, n1), 0.0, atol=1e-15)
    np.testing.assert_allclose(np.einsum("ij,ij->i", e, n2), 0.0, atol=1e-15)
    np.testing.assert_allclose(np.abs(n2[:, 1]), 1.0)  # x-z line: n2 = ±y (vertical too)


def test_channels_order_kinematics_and_prescribed_motion():
    motion = {
        "surge": {"type": "pierson_moskowitz", "hs": 1.0, "tp": 9.0},
        "heave": {"type": "jonswap", "hs": 0.5, "tp": 7.0},
    }
    doc = straight_doc(motion=motion)
    scene, system = built(doc)
    w = scene.analysis.omega.values()
    chans = line_channels(scene, scene.lines[0], system.positions, w)
    assert [c.name for c in chans] == ["sea", "end_b.surge", "end_b.heave"]
    sea = chans[0]
    kin = wave_kinematics(w, system.positions, math.radians(20.0), 100.0, G)
    np.testing.assert_array_equal(sea.velocity, np.transpose(kin.velocity, (2, 0, 1)))
    np.testing.assert_array_equal(sea.acceleration, np.transpose(kin.acceleration, (2, 0, 1)))
    np.testing.assert_allclose(sea.spectrum, scene.sea.spectrum.spectral_density(w, G))
    np.testing.assert_allclose(
        chans[2].spectrum, scene.lines[0].end_b.motion.heave.spectral_density(w, G)
    )
    ub = prescribed_motion(system.model, chans, w.size)  # (n_w, n_fixed=6, n_ch)
    assert np.all(ub[:, :, 0] == 0)
    np.testing.assert_array_equal(ub[:, :, 1], np.tile([0, 0, 0, 1, 0, 0], (w.size, 1)))
    np.testing.assert_array_equal(ub[:, :, 2], np.tile([0, 0, 0, 0, 0, 1], (w.size, 1)))


def test_rao_end_motion_is_part_of_the_sea_channel():
    rao = {"rao": {"omega": [0.1, 2.0], "heave": {"re": [1.0, 0.0], "im": [0.0, 0.5]}}}
    scene, system = built(straight_doc(motion=rao))
    w = np.array([0.1, 1.05, 2.0])
    chans = line_channels(scene, scene.lines[0], system.positions, w)
    assert [c.name for c in chans] == ["sea"]
    np.testing.assert_allclose(chans[0].motion_b[:, 2], [1.0, 0.5 + 0.25j, 0.5j])
    assert chans[0].motion_a is None


def test_rao_without_sea_names_the_field():
    rao = {"rao": {"omega": [0.1, 2.0], "surge": {"re": [1.0, 1.0], "im": [0.0, 0.0]}}}
    scene, system = built(straight_doc(sea=False, motion=rao))
    with pytest.raises(InputError, match=r"lines\[l\]\.end_b\.motion\.rao.*needs a 'sea'"):
        line_channels(scene, scene.lines[0], system.positions, np.array([0.5]))


def test_sigma_of_line_at_rest_is_element_mean_of_fluid_velocity_sigma():
    """Seed step 5 (cable at rest): σ_n² + σ_t² = ∫ S ∫₀¹ |v(ξ)|² dξ dω, the element mean
    of the wave velocity, computed here independently by a 12-point Gauss–Legendre rule
    along each element on the nodal kinematics of wave_kinematics (trapezoid in ω)."""
    scene, system = built(straight_doc())
    w = np.linspace(0.3, 1.8, 31)
    chans = line_channels(scene, scene.lines[0], system.positions, w)
    sig = dvariance.relative_velocity_sigmas(system, chans, None, "seed")
    n = system.model.n_elements
    pos = system.positions
    xg, wg = np.polynomial.legendre.leggauss(12)
    xi, wg = 0.5 * (xg + 1.0), 0.5 * wg
    pts = pos[:-1, None, :] + xi[None, :, None] * (pos[1:] - pos[:-1])[:, None, :]
    kin = wave_kinematics(w, pts.reshape(-1, 3), math.radians(20.0), 100.0, G).velocity
    kin = kin.reshape(n, xi.size, 3, w.size)
    s = scene.sea.spectrum.spectral_density(w, G)
    e = element_frames(pos)[0]
    total = np.trapezoid(np.einsum("epkw,p->ew", np.abs(kin) ** 2, wg) * s, w, axis=-1)
    axial = np.trapezoid(
        np.einsum("epw,p->ew", np.abs(np.einsum("epkw,ek->epw", kin, e)) ** 2, wg) * s, w, axis=-1
    )
    # 12-point Gauss on e^{2kz} over Δz = 6.7 m with 2k <= 0.46/m (kΔz <= 3): exact to
    # ~1e-15; the rest is round-off
    np.testing.assert_allclose(sig[:n] ** 2 + sig[n : 2 * n] ** 2, total, rtol=1e-12)
    np.testing.assert_allclose(sig[n : 2 * n] ** 2, axial, rtol=1e-12)


def test_fully_wet_exp_moments_are_the_general_formula():
    """_exp_moments drops the factors 1 and 0 when every element is wet over its whole
    length (the speed pass of issue 4); the general expressions give the same numbers
    to the bit (x·1 and 0 + x are exact), growing and decaying exponents alike."""
    from stochcable.dynamics.loads.kinematics_closed_forms import _complex, _exp_moments, _phi1_psi
    from stochcable.sea.kinematics import _wavenumber

    def general(e0, alpha, p, q):  # the formula for any wet part [p, q]
        length = q - p
        grow = alpha.real >= 0.0
        c = np.where(grow, q, p)
        s = np.where(grow, -1.0, 1.0)
        f1, f2 = _phi1_psi(s * alpha * length)
        ref = np.exp(e0 + alpha * c)
        t1 = length * f1
        t2 = s * (length * length) * f2
        return ref * ((1.0 - c) * t1 - t2), ref * (c * t1 + t2)

    rng = np.random.default_rng(11)
    k = _wavenumber(np.linspace(0.05, 3.0, 60), 200.0, 9.80665)
    za = rng.uniform(-200.0, -1.0, 25)
    zb = np.minimum(za + rng.uniform(-8.0, 8.0, 25), -0.5)
    chi = rng.uniform(-800.0, 0.0, 26)
    p, q = np.zeros((25, 1)), np.ones((25, 1))
    for sign in (1.0, -1.0):
        e0 = _complex(np.multiply.outer(za, k), -np.multiply.outer(chi[:-1], k))
        alpha = _complex(
            sign * np.multiply.outer(zb - za, k), -np.multiply.outer(chi[1:] - chi[:-1], k)
        )
        for got, ref in zip(_exp_moments(e0, alpha, p, q), general(e0, alpha, p, q)):
            np.testing.assert_array_equal(got, ref)


def test_sea_nodal_kinematics_are_computed_on_first_access_only():
    """The sea channel's nodal velocity/acceleration (used by attachments only) are
    computed when first read, once for both fields, and equal the nodal kinematics of
    stochcable.sea.kinematics.wave_kinematics; explicit fields are kept as given."""
    import dataclasses

    from stochcable.dynamics.loads.channels import Channel

    scene, system = built(straight_doc())
    w = scene.analysis.omega.values()
    sea = line_channels(scene, scene.lines[0], system.positions, w)[0]
    assert sea.nodal is not None and sea.__dict__["_velocity"] is None  # not yet built
    calls = []
    nodal = sea.nodal

    def counted():
        calls.append(1)
        return nodal()

    lazy = Channel(
        name="sea", kind="sea", omega=w, spectrum=sea.spectrum, density=sea.density, nodal=counted
    )
    assert calls == []
    acc = lazy.acceleration
    vel = lazy.velocity
    assert len(calls) == 1 and lazy.velocity is vel and lazy.acceleration is acc
    kin = wave_kinematics(w, system.positions, math.radians(20.0), 100.0, G)
    np.testing.assert_array_equal(vel, np.transpose(kin.velocity, (2, 0, 1)))
    np.testing.assert_array_equal(acc, np.transpose(kin.acceleration, (2, 0, 1)))
    given = Channel(
        name="x",
        kind="sea",
        omega=w,
        spectrum=np.zeros_like(w),
        density=np.zeros_like,
        velocity=vel,
        nodal=counted,
    )
    assert given.velocity is vel and given.acceleration is None and len(calls) == 1
    plain = Channel(name="x", kind="sea", omega=w, spectrum=np.zeros_like(w), density=np.zeros_like)
    assert plain.velocity is None and plain.acceleration is None
    with pytest.raises(dataclasses.FrozenInstanceError):
        lazy.velocity = vel
    # dataclasses.replace reads the fields: the copy carries the computed arrays
    copy = dataclasses.replace(lazy, name="y")
    assert copy.velocity is vel and len(calls) == 1


def test_second_exponent_shares_phi_psi_by_conjugation():
    """The finite-depth kinematics take φ1, ψ of the second exponent (slope −dz + i·dφ)
    as the conjugates of the first one's where dz ≠ 0 and as themselves where dz = 0,
    and the φ1 of ∫e^{−2k(z+2h)} as that of ∫e^{2kz} (issue 6 pass E6): the moments
    equal those of their own φ1, ψ to the bit, for rising, sinking and horizontal
    elements, at ω = 0, fully wet (the short path) and partly wet (the general one)."""
    from stochcable.dynamics.loads.kinematics_closed_forms import (
        _complex,
        _exp_integral,
        _exp_moments,
        _moment_argument,
        _phi1_psi,
    )
    from stochcable.sea.kinematics import _wavenumber

    rng = np.random.default_rng(13)
    h = 150.0
    k = _wavenumber(np.r_[0.0, np.linspace(0.05, 3.0, 40)], h, 9.80665)
    za = rng.uniform(-h, -1.0, 30)
    zb = za + rng.uniform(-6.0, 6.0, 30)
    zb[::5] = za[::5]  # horizontal elements: dz = 0
    zb = np.minimum(zb, -0.5)
    chi = rng.uniform(-500.0, 0.0, 31)
    chi[3] = chi[2]  # an element across the waves: dφ = 0
    dz = np.multiply.outer(k, zb - za)
    dphase = -np.multiply.outer(k, chi[1:] - chi[:-1])
    phase0 = -np.multiply.outer(k, chi[:-1])
    e2a = -np.multiply.outer(k, za + 2.0 * h)
    partly = (np.full((1, 30), 0.0), rng.uniform(0.2, 1.0, (1, 30)))
    for p, q in ((np.zeros((1, 30)), np.ones((1, 30))), partly):
        alpha1 = _complex(dz, dphase)
        f12 = _phi1_psi(_moment_argument(alpha1, p, q))
        f12_2 = tuple(np.where(dz != 0.0, f.conj(), f) for f in f12)
        alpha2 = _complex(-dz, dphase)
        e0 = _complex(e2a, phase0)
        for got, want in zip(_exp_moments(e0, alpha2, p, q, f12_2), _exp_moments(e0, alpha2, p, q)):
            np.testing.assert_array_equal(got, want)
        two_dz = 2.0 * dz
        phi_k, _ = _phi1_psi(np.where(two_dz >= 0.0, -two_dz, two_dz) * (q - p), want_psi=False)
        np.testing.assert_array_equal(
            _exp_integral(2.0 * e2a, -two_dz, p, q, phi_k), _exp_integral(2.0 * e2a, -two_dz, p, q)
        )
        np.testing.assert_array_equal(
            _exp_moments(_complex(np.multiply.outer(k, za), phase0), alpha1, p, q, f12),
            _exp_moments(_complex(np.multiply.outer(k, za), phase0), alpha1, p, q),
        )
