"""Nonlinear time-domain reference of several lines on one free planar body: each line
of :mod:`stochcable.reference.cable` with end_a fixed and end_b on the body, and the
body's surge, heave and pitch, integrated together; the yardstick of the frequency
domain's groups of lines on a shared body and of their joint residuals
(:mod:`stochcable.dynamics.residuals.body_residual`).
:func:`stochcable.reference.cable_body.simulate_line_on_body` is its one-line case.

The body is the frequency domain's (:class:`stochcable.bodies.rigid.RigidBody` at the
static pose of :func:`stochcable.statics.solve_statics`, Tuah (1982), eq. 3.2.c.20):
rigid-body mass and inertia about the reference point, constant added mass and
radiation damping (a frequency-dependent table is refused: no Cummins convolution
here), the hydrostatic stiffness and the extra stiffness and damping, and the wave
excitation table synthesized from the same sea coefficients as the lines' waves.  What
is nonlinear besides the lines: the body's quadratic drag ½ρ·CdA·|u|u per direction on
the relative velocity u at the drag point (the frequency domain linearizes it), the
finite pitch of the fairlead and drag-point arms (R(θ)r, the frequency domain's
T(r)ξ plus the attachment geometric stiffness to first order) and the inertia of
each end node's share of its line moving with the fairlead.  Linear, as in the
frequency domain: the inertia (no centripetal terms of the CoG offset), the
hydrostatics, and the excitation and wave velocity at the static pose.

Integration: the lines' Newmark average acceleration (:mod:`~stochcable.reference.cable_newmark`)
with the body's three DOFs in the same Newton iteration (monolithic): line l's end node
follows the body, X_b,l = X_b,l,s + ξ_t + R(θ)r₀,l − r₀,l, and the body carries every
line's support reaction R_b,l at its fairlead.  The Newton correction solves each
line's band for its residual and for the three unit body motions (bordered band), then
one 3×3 body system with every line's reactions: the Schur complement summed over the
lines.  The body's static balance (buoyancy, weight, wind, line pulls) is the static
start: its residual is written about the start, with each line's static reaction
R_b,l,0 and the static drag (current) subtracted.

Known limit: with the one-sided penalty bed a light slack line whose nodes lift off
and land gains energy in the non-dissipative scheme (docs/accuracy/bodies.md).

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from stochcable import validation as _v
from stochcable.bodies.from_scene import scene_rigid_bodies
from stochcable.bodies.rigid import body_excitation
from stochcable.errors import InputError
from stochcable.line.mesh import mesh_line
from stochcable.reference.cable import _static_start, _time_step
from stochcable.reference.cable_bodies_newmark import Leg, integrate_lines_on_body, link, rot
from stochcable.reference.cable_excitation import (
    band_limited,
    half_cosine,
    realization_grid,
    upsample,
    wave_series,
)
from stochcable.reference.cable_model import axes, statics_guess
from stochcable.scene.model import Scene, load_scene
from stochcable.sea.kinematics import wave_kinematics, wavenumber
from stochcable.statics import solve_statics

__all__ = ["BodyLinesHistory", "paired_linear", "simulate_lines_on_body"]


def paired_linear(excitation: tuple, omega: np.ndarray, transfer: np.ndarray) -> np.ndarray:
    """The linear response of transfer function ``transfer`` (per unit wave amplitude
    on ``omega``) to a record's sea, ramp and steps (``excitation``, the record's):
    the paired linear record of the same waves.

    Parameters
    ----------
    excitation : tuple
        A history's ``excitation`` (grid, sea coefficients, samples, upsampling,
        step indices, ramp).
    omega : ndarray, shape (n_w,)
        [rad/s]
    transfer : ndarray, complex, shape (n_w,)
        Interpolated (real and imaginary parts) on the realization's grid, zero
        outside ``omega``. [unit/m]

    Returns
    -------
    ndarray, shape (n_t,)
    """
    w_grid, x_sea, n_samples, k_up, sl, r = excitation
    w = np.asarray(omega, dtype=float)
    hh = np.asarray(transfer)
    inside = (w_grid >= w[0]) & (w_grid <= w[-1])
    h_grid = (np.interp(w_grid, w, hh.real) + 1j * np.interp(w_grid, w, hh.imag)) * inside
    return upsample(h_grid * x_sea, n_samples, k_up)[sl] * r


@dataclass(frozen=True, eq=False)
class BodyLinesHistory:
    """Nonlinear time-domain response of several lines on one free body.

    Attributes
    ----------
    lines : tuple of str
        The lines with end_b on the body, in scene order (the columns below).
    body : str
    t : ndarray, shape (n_t,)
        Time, 0 at the static start. [s]
    tension_a, tension_b : ndarray, shape (n_t, n_lines)
        End tensions: the support reactions (as the frequency domain's). [N]
    motion : ndarray, shape (n_t, 3)
        Body motion (surge, heave, pitch) from its static pose. [m, m, rad]
    iterations : ndarray of int, shape (n_t,)
        Newton iterations per step. [-]
    dt, ramp : float
        Step and half-cosine ramp (excluded from the statistics). [s]
    excitation : tuple
        The sea's synthesis (:func:`paired_linear`).
    """

    lines: tuple[str, ...]
    body: str
    t: np.ndarray
    tension_a: np.ndarray
    tension_b: np.ndarray
    motion: np.ndarray
    iterations: np.ndarray
    dt: float
    ramp: float
    excitation: tuple = ()

    def linear(self, omega: np.ndarray, transfer: np.ndarray) -> np.ndarray:
        """The paired linear record of ``transfer`` (:func:`paired_linear`)."""
        return paired_linear(self.excitation, omega, transfer)

    def records(self) -> dict[str, np.ndarray]:
        """Every record by name: "LINE.end_a", "LINE.end_b", "surge", "heave", "pitch"."""
        out = {}
        for j, name in enumerate(self.lines):
            out[f"{name}.end_a"] = self.tension_a[:, j]
            out[f"{name}.end_b"] = self.tension_b[:, j]
        out.update({k: self.motion[:, i] for i, k in enumerate(("surge", "heave", "pitch"))})
        return out

    def std(self, start: float | None = None) -> dict[str, float]:
        """σ of every record (:meth:`records`) after ``start`` (default the ramp). [N, m, rad]"""
        keep = self.t >= (self.ramp if start is None else start)
        return {k: float(np.std(x[keep])) for k, x in self.records().items()}


def _lines_of(sc: Scene, body_name: str | None) -> tuple[str, list]:
    """The free body and the lines on it (end_b attached, end_a fixed without motion)."""
    on: dict[str, list] = {}
    for ln in sc.lines:
        for e in (ln.end_a, ln.end_b):
            if e.attach is not None:
                on.setdefault(e.attach.body, []).append(ln)
    if body_name is None:
        if len(on) != 1:
            raise InputError("body_name", None, "-", f"must name one of {sorted(on)}")
        body_name = next(iter(on))
    if body_name not in on:
        raise InputError("body_name", body_name, "-", f"must be a body with lines: {sorted(on)}")
    lines = on[body_name]
    for ln in lines:
        a, b = ln.end_a, ln.end_b
        if b.attach is None or b.attach.body != body_name or a.attach or a.motion:
            raise InputError(
                "line", ln.name, "-", "needs end_b on a free body and end_a fixed without motion"
            )
    return body_name, lines


def simulate_lines_on_body(
    scene: Scene | dict[str, Any] | str,
    body_name: str | None = None,
    *,
    duration: float,
    seed: int,
    dt: float | None = None,
    ramp: float | None = None,
    band: tuple[float, float] | None = None,
    method: str = "dsa",
    tolerance: float = 1e-7,
    max_iterations: int = 30,
    linear_drag: tuple[Mapping[str, tuple[Any, Any]], Any] | None = None,
    seabed: str = "one_sided",
    internal_damping: float = 0.0,
) -> BodyLinesHistory:
    """Nonlinear time-domain response of the lines on a free planar body (module notes).

    Parameters
    ----------
    scene : Scene, mapping or JSON
        A planar scene with a long-crested sea: every line on the body has end_b
        attached to it and end_a fixed (no end motion).
    body_name : str, optional
        The body (default the only body with lines). [-]
    duration : float
        Length of the sea realization and of the record. [s]
    seed : int
        Seed of the sea realization (:func:`stochcable.sea.realization.simulate_sea`). [-]
    dt : float, optional
        Integration step (default: the period error (ωΔt)²/12 ≤ 0.5 % at the highest
        excitation frequency). [s]
    ramp : float, optional
        Half-cosine ramp of the excitation (default 3 peak periods). [s]
    band : (float, float), optional
        Wave components kept (the frequency domain's ω range reproduces its
        excitation). [rad/s]
    method : {"dsa", "nsa"}
        Spectral amplitude method of the realization. [-]
    tolerance : float
        Newton tolerance on max |residual| relative to the largest static force (the
        smallest over the lines). [-]
    max_iterations : int
        Newton iterations per step before a ConvergenceError. [-]
    linear_drag : (mapping, array_like), optional
        A controlled experiment: each line's drag linear with (B_n, B_t) per element
        (by line name; :func:`stochcable.reference.cable.simulate_line_timedomain`'s
        ``drag="linear"``) and the body's with the linear coefficient per direction
        (x, y, z) at the drag point (a frequency-domain result's
        ``linearization.b_normal``, ``b_axial`` and the body's ``drag_coefficient``).
        [N·s/m², N·s/m², N·s/m]
    seabed : {"one_sided", "linear"}
        The one-sided penalty bed, or its tangent at the static start
        (:meth:`stochcable.reference.cable_model.LineModel.set_variant`). [-]
    internal_damping : float
        Axial internal damping BA of every element, T_d = BA·(dl/dt)/l0; 0: none. [N·s]

    Returns
    -------
    BodyLinesHistory

    Raises
    ------
    InputError
        A scene outside the scope above, or a body with frequency-dependent added mass
        or radiation damping over the band.
    ConvergenceError
        Newton did not converge in a step.
    """
    sc = load_scene(scene)
    if not sc.is_planar or sc.sea is None or sc.sea.spreading is not None:
        raise InputError("scene", "-", "-", "needs a planar scene with a long-crested sea")
    body_name, lines = _lines_of(sc, body_name)
    tolerance = _v.positive("tolerance", tolerance, "-")
    internal_damping = _v.nonnegative("internal_damping", internal_damping, "N·s")
    if seabed not in ("one_sided", "linear"):
        raise InputError("seabed", seabed, "-", "must be 'one_sided' or 'linear'")
    env = sc.environment
    statics = solve_statics(sc)
    bst = statics.bodies[body_name]
    if bst.prescribed:
        raise InputError("body", body_name, "-", "must be free (not prescribed)")
    body = dataclasses.replace(
        scene_rigid_bodies(sc)[body_name], position=np.asarray(bst.position, float)
    )
    if not np.any(body.hydrostatic_stiffness):
        raise InputError("body", body.name, "-", "needs a hydrostatic_stiffness matrix")

    # ---- excitation: the lines' waves, the body's excitation and drag-point velocity
    grid = realization_grid(sc, None, duration, dt, seed, method)
    ends, seas = band_limited(grid, {}, band)
    _, w_peak, k_up, h = _time_step(grid, seas, ends, dt)
    w_lo = 0.0 if band is None else band[0]
    w_hi = float(grid.omega[-1]) if band is None else band[1]
    inb = (grid.omega >= w_lo) & (grid.omega <= w_hi) & (grid.omega > 0)
    am, bm = body.added_mass_at(grid.omega[inb]), body.radiation_damping_at(grid.omega[inb])
    for nm, a in (("added_mass", am), ("radiation_damping", bm)):
        if np.abs(a - a[0]).max() > 1e-9 * max(np.abs(a).max(), 1e-30):
            raise InputError(
                f"bodies[{body.name}].{nm}", "frequency-dependent", "-",
                "must be constant over the band (no radiation convolution here)",
            )  # fmt: skip
    n_steps = int(round(grid.duration / h))
    t = h * np.arange(n_steps + 1)
    if ramp is None:
        ramp = 3.0 * 2.0 * math.pi / w_peak
    ramp = _v.nonnegative("ramp", ramp, "s")
    r = half_cosine(t, ramp)
    sl = np.arange(n_steps + 1) % (k_up * grid.n_samples)
    ((heading, x_sea),) = seas
    ax = axes(2)
    legs = []
    for line in lines:
        mesh = mesh_line(line, env.rho, env.g)
        x3 = statics_guess(sc, line, mesh, statics)
        model, xs, u_cur, u_cur_g, tol_abs = _static_start(
            sc, mesh, x3, 2, tolerance, internal_damping
        )
        if linear_drag is not None:
            model.set_variant(drag="linear", linear_drag=linear_drag[0][line.name], seabed=seabed)
        else:
            model.set_variant(seabed=seabed)
        u_wave, u_wave_g, f_in = wave_series(
            model, xs @ ax.T, grid.omega, x_sea, heading, env, ax, grid.n_samples, k_up, sl, r[0]
        )
        r0 = xs[-1] - body.position[[0, 2]]
        legs.append(Leg(line.name, model, xs, u_cur, u_cur_g, u_wave, u_wave_g, f_in, r0, tol_abs))
    b_lin = None if linear_drag is None else np.asarray(linear_drag[1], dtype=float)[[0, 2]]
    k = wavenumber(np.maximum(grid.omega, 1e-9), env.depth, env.g)
    f_exc = body_excitation(body, grid.omega, heading, wavenumber=k)  # (n_w, 3)
    dp3 = body.position + body.drag_point
    dp3[2] = max(dp3[2], -env.depth)
    kin = wave_kinematics(grid.omega, dp3[None], heading, env.depth, env.g)
    v_dp = kin.velocity[0][[0, 2]]  # (2, n_w)
    coeff = np.concatenate([f_exc.T, v_dp], axis=0) * x_sea
    series = np.moveaxis(upsample(coeff, grid.n_samples, k_up)[..., sl] * r[0], -1, 0)
    f_body, v_fluid = series[:, :3], series[:, 3:]
    u_body_cur = np.asarray(env.current_velocity(np.array([min(dp3[2], 0.0)]))[0])[[0, 2]]

    # ---- the body's matrices (perturbation about the static pose)
    m_b = body.mass_matrix() + am[0]
    c_b = bm[0] + body.extra_damping
    k_b = body.hydrostatic_stiffness + body.extra_stiffness
    half_rho_cda = 0.5 * env.rho * np.asarray(body.drag_area, float)[[0, 2]]
    p0 = np.asarray(body.drag_point, float)[[0, 2]]
    free_q = np.asarray(body.free_index, dtype=int)

    def body_drag(q: np.ndarray, qd: np.ndarray, vf: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Generalized drag force and its Jacobian on q̇."""
        g = link(rot(q[2], p0))
        u = u_body_cur + vf - g @ qd
        if b_lin is not None:
            return g.T @ (b_lin * u), g.T @ np.diag(b_lin) @ g
        f = half_rho_cda * np.abs(u) * u
        return g.T @ f, g.T @ np.diag(2.0 * half_rho_cda * np.abs(u)) @ g

    excitation = (grid.omega, x_sea, grid.n_samples, k_up, sl, r[0])
    ten_a, ten_b, motion, iters = integrate_lines_on_body(
        legs, f_body, v_fluid, body_drag, (m_b, c_b, k_b, free_q), t, h, max_iterations
    )
    names = tuple(leg.name for leg in legs)
    return BodyLinesHistory(names, body.name, t, ten_a, ten_b, motion, iters, h, ramp, excitation)
