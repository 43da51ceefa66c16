"""A moored vessel in MoorDyn, driven by its motion RAOs in a random sea: the time-domain
check of the frequency domain on a whole mooring read from a MoorDyn file
(benchmarks/moordyn_platform.py, docs/ACCURACY.md).

The vessel (the scene's one prescribed body) moves as ξ(t) = Σ_j a_j Re{R(ω_j)
e^{i(ω_j t − θ_j)}}, a periodic DSA realization of the sea (a_j = √(2 S(ω_j) Δω),
Δω = 2π/T) times its 6-DOF RAO R (per unit wave amplitude, phase relative to the wave
elevation at the origin); each fairlead p moves by ξ_t + ξ_r × (p − X) (rotations to
first order, as the frequency domain's T(r)·ξ).  MoorDyn's lines see no waves
(``WaveKin 0``): the comparison is of the vessel-driven response only, and the
frequency domain's wave loads on the lines are a difference it keeps (small where the
lines are deep).  A record is one warm-up period (a half-cosine ramp over its first
half) and one measured period, over which the motion's variance is exact.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from stochcable import validation as _v
from stochcable.errors import InputError, PhysicsWarning, SolverError
from stochcable.io import moordyn_lines, write_moordyn
from stochcable.reference.cable_excitation import half_cosine
from stochcable.reference.moordyn import (
    import_moordyn,
    moordyn_system,
    quiet_moordyn,
    sample_stride,
)
from stochcable.scene.model import Scene, load_scene

__all__ = ["VesselRecord", "simulate_vessel_moordyn"]


@dataclass(frozen=True, eq=False)
class VesselRecord:
    """Fairlead tensions of the MoorDyn lines that end on the vessel.

    Attributes
    ----------
    lines : tuple of str
        The scene line of each record.
    mean, std : ndarray, shape (n_lines,)
        Mean and standard deviation of the fairlead support reaction over the measured
        period (the last segment's force plus the loads lumped on the fairlead node,
        its inertia included: what the frequency domain's end_b tension is). [N]
    static : ndarray, shape (n_lines,)
        MoorDyn's static fairlead tension. [N]
    """

    lines: tuple[str, ...]
    mean: np.ndarray
    std: np.ndarray
    static: np.ndarray


def simulate_vessel_moordyn(
    scene: Scene | dict | str,
    *,
    period: float,
    band: tuple[float, float],
    rng: np.random.Generator | int,
    dt: float = 1e-3,
    coupling_dt: float = 0.01,
    sample_dt: float = 0.1,
) -> VesselRecord:
    """Run the scene's mooring in MoorDyn with its vessel moving in the scene's sea.

    Parameters
    ----------
    scene : Scene, mapping or JSON
        A scene with a sea (long-crested) and one prescribed body whose lines end on
        it (end_b), e.g. a MoorDyn file read with a ``--vessel-rao``.
    period : float
        Period T of the sea realization (Δω = 2π/T); the record is 2T. [s]
    band : (float, float)
        Wave components kept. [rad/s]
    rng : Generator or int
        Source of the phases. [-]
    dt, coupling_dt, sample_dt : float
        MoorDyn's ``dtM``, the interval of ``moordyn.Step`` calls, the sampling. [s]

    Returns
    -------
    VesselRecord
    """
    md = import_moordyn()
    sc = load_scene(scene)
    period = _v.positive("period", period, "s")
    vessels = [b for b in sc.bodies if b.prescribed is not None]
    if sc.sea is None or len(vessels) != 1 or sc.sea.spreading is not None:
        raise InputError(
            "scene", "-", "-", "needs a long-crested sea and exactly one prescribed body"
        )
    vessel = vessels[0]
    g = sc.environment.g
    dw = 2.0 * math.pi / period
    j = np.arange(max(1, math.ceil(band[0] / dw)), math.floor(band[1] / dw) + 1)
    w = j * dw
    a = np.sqrt(2.0 * sc.sea.spectrum.spectral_density(w, g) * dw)
    theta = np.random.default_rng(rng).uniform(-math.pi, math.pi, w.size)
    rao = vessel.prescribed.transfer(w, sc.sea.heading_rad if vessel.prescribed.heading else None)
    amp = rao * (a * np.exp(-1j * theta))  # (6, n): ξ(t) = Re Σ amp e^{iωt}
    coupling_dt = _v.positive("coupling_dt", coupling_dt, "s")
    every = sample_stride(sample_dt, coupling_dt)
    n_steps = int(round(2.0 * period / coupling_dt))
    tc = coupling_dt * np.arange(n_steps + 1)

    def motion(t: np.ndarray, order: int) -> np.ndarray:
        out = np.empty((t.size, 6))
        for s0 in range(0, t.size, 4096):  # blocks: (block, n) complex at a time
            e = np.exp(1j * np.multiply.outer(t[s0 : s0 + 4096], w))
            out[s0 : s0 + 4096] = (((1j * w) ** order * e) @ amp.T).real
        return out

    r, r1, r2 = half_cosine(tc, 0.5 * period)
    x0, x1, x2 = (motion(tc, k) for k in (0, 1, 2))
    xs = r[:, None] * x0
    acc = r[:, None] * x2 + 2.0 * r1[:, None] * x1 + r2[:, None] * x0
    with warnings.catch_warnings():  # the motion is driven here, not written: expected
        warnings.simplefilter("ignore", PhysicsWarning)
        text = write_moordyn(sc, dt=dt, ic_threshold=1e-6, ic_tmax=300.0)
    pieces = moordyn_lines(sc)
    with moordyn_system(text, "vessel.txt") as system:
        pts = []
        for i in range(md.GetNumberPoints(system)):
            p = md.GetPoint(system, i + 1)
            if md.GetPointType(p) == md.POINT_TYPE_COUPLED:
                pts.append(np.asarray(md.GetPointPos(p), float))
        if md.GetNumberBodies(system):
            raise InputError("scene", vessel.name, "-", "the vessel must be Coupled points")
        arm = np.array(pts) - np.asarray(vessel.position, float)  # (n_p, 3)

        def fairleads(xi: np.ndarray) -> np.ndarray:
            return np.array(pts) + xi[:3] + np.cross(xi[3:], arm)

        with quiet_moordyn():
            err = md.Init(system, list(fairleads(xs[0]).ravel()), [0.0] * 3 * len(pts))
        if err:
            raise InputError("scene", "MoorDyn Init", "-", f"failed with error code {err}")
        # the MoorDyn lines that end on the vessel: the last piece of each scene line
        ends = [k for k in range(len(pieces)) if k + 1 == len(pieces) or
                pieces[k + 1][0] != pieces[k][0]]  # fmt: skip
        ends = [k for k in ends if sc.lines[[ln.name for ln in sc.lines].index(
            pieces[k][0])].end_b.attach is not None]  # fmt: skip
        if len(ends) != len(pts):
            raise InputError(
                "scene", len(pts), "-", "every Coupled point must end one line on the vessel"
            )
        handles = [md.GetLine(system, k + 1) for k in ends]
        nodes = [md.GetLineNumberNodes(h) - 1 for h in handles]
        static = np.array([md.GetLineFairTen(h) for h in handles])
        n_s = n_steps // every + 1
        rec = np.empty((n_s, len(handles)))
        for k in range(n_steps + 1):
            if k % every == 0:
                a_f = acc[k, :3] + np.cross(acc[k, 3:], arm)  # fairlead accelerations
                for i, (h, n) in enumerate(zip(handles, nodes)):
                    f = np.asarray(md.GetLineNodeForce(h, n))
                    m = np.asarray(md.GetLineNodeM(h, n))
                    # the i-th vessel line's fairlead is the i-th Coupled point
                    rec[k // every, i] = np.linalg.norm(m @ a_f[i] - f)
            if k == n_steps:
                break
            x = fairleads(xs[k])
            v = (fairleads(xs[k + 1]) - x) / coupling_dt
            md.Step(system, list(x.ravel()), list(v.ravel()), float(tc[k]), coupling_dt)
    if not np.all(np.isfinite(rec)):
        raise SolverError(f"MoorDyn's fairlead tensions are not finite (dtM {dt} s)")
    ts = tc[::every]
    keep = ts >= period - 1e-9 * period
    keep[-1] = False  # one whole period: [T, 2T)
    return VesselRecord(
        tuple(pieces[k][0] for k in ends),
        rec[keep].mean(axis=0),
        rec[keep].std(axis=0),
        static,
    )
