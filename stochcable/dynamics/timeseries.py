"""Time series of one realization (seed 001 §5.1, eq. 5.3.29 and step 14): the sea,
the end motions, the end tensions of every line and the motions of the bodies, all
synthesized from transfer functions solved on the realization grid.  Lines on bodies
go through :mod:`stochcable.dynamics.coupled_timeseries`.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from stochcable.dynamics.loads import (
    Channel,
)
from stochcable.dynamics.solve import (
    solve,
)
from stochcable.dynamics.system import (
    Damping,
    LineSystem,
)
from stochcable.results.documents import (
    TimeSeries,
)
from stochcable.scene.model import Scene, TimeSeriesSettings
from stochcable.sea.realization import frequency_grid, simulate_sea, synthesize

# ---------------------------------------------------------------------- time series


def simulate_timeseries(
    scene: Scene,
    systems: Mapping[str, LineSystem],
    dampings: Mapping[str, Damping],
    settings: TimeSeriesSettings,
    *,
    coupled: tuple[Any, ...] = (),
    timing: dict[str, float] | None = None,
) -> TimeSeries:
    """One realization of every input channel and the end-tension and body-motion
    time series.

    Parameters
    ----------
    scene : Scene
    systems : mapping of LineSystem by line name
        The independent lines (not attached to a free body).
    dampings : mapping of Damping by line name
        The converged linear drag of each of them.
    settings : TimeSeriesSettings
        method (dsa/nsa), duration, dt, seed.
    coupled : tuple of CoupledGroup, optional
        The converged coupled groups of a scene with bodies
        (:attr:`stochcable.dynamics.coupled.CoupledAnalysis.groups`): their lines' end
        tensions and their free bodies' motions are synthesized too.
    timing : dict, optional
        Accumulates ``solve_s``.

    Returns
    -------
    TimeSeries

    Notes
    -----
    The sea: :func:`stochcable.sea.realization.simulate_sea` with ``rng=seed`` (so η is the
    realization a stand-alone simulation with that seed gives).  End-motion spectrum
    channels, in the order of the scene's lines (independent and coupled alike) ×
    (end_a, end_b) × (surge, sway, heave), use the independent generators
    ``np.random.default_rng(c)`` for ``c in np.random.SeedSequence(seed).spawn(n)``.
    Responses are :func:`stochcable.sea.realization.synthesize` of the transfer functions solved
    on the realization grid ω_m = mΔω, restricted to the analysis band
    [omega.min, omega.max] (zero outside, as the response spectra are), so η, end
    motions, tensions and body motions of one realization are mutually consistent
    (seed 001 §5.1, eq. 5.3.29 and step 14).  Independent lines: :func:`solve` with
    their converged drag; an end on a vessel moves with the vessel RAO in the sea
    channel.  Coupled groups: the group's linear system at its converged drag
    (lines' Damping, bodies' drag σ) solved on the band
    (:func:`stochcable.dynamics.coupled_timeseries.coupled_group_transfer`).  Vessels: their
    RAO times the sea.  The band is solved in chunks of frequencies, so only the
    end tensions and body motions of the whole band are held
    (:mod:`stochcable.dynamics.coupled_timeseries`, "Memory").
    """
    from stochcable.dynamics.coupled import _scene_line_channels
    from stochcable.dynamics.coupled_timeseries import (
        CHUNK_BYTES,
        coupled_group_transfer,
        frequency_chunks,
        line_entry_bytes,
        vessel_raos,
    )

    seed = int(settings.seed)
    omega_r, _ = frequency_grid(settings.duration, settings.dt)
    grid = scene.analysis.omega
    band = np.flatnonzero((omega_r >= grid.min) & (omega_r <= grid.max) & (omega_r > 0))
    w_band = omega_r[band]
    env = scene.environment
    sea_real = None
    if scene.sea is not None:
        spec = scene.sea.spectrum

        def sea_density(w: np.ndarray) -> np.ndarray:
            w = np.asarray(w, dtype=float)
            out = np.zeros_like(w)
            out[w > 0] = spec.spectral_density(w[w > 0], env.g)
            return out

        sea_real = simulate_sea(sea_density, settings.duration, settings.dt,
                                settings.method, rng=seed)
    groups = tuple(coupled)
    all_systems = dict(systems)
    for grp in groups:
        all_systems.update(grp.systems)
    scene_order = [ln.name for ln in scene.lines if ln.name in all_systems]
    names = scene_order + [n for n in all_systems if n not in scene_order]

    def channels_on(name: str, w: np.ndarray) -> tuple[Channel, ...]:
        """The line's channels on w (an end on a vessel moves in the sea channel)."""
        system = all_systems[name]
        ch, _ = _scene_line_channels(scene, system.line, system, w, vessel_raos(scene, w))
        return ch

    # channel names and densities of every line (scene order) from one frequency
    probe = {n: channels_on(n, w_band[:1]) if band.size else () for n in names}
    motion_keys = [(name, ch.name) for name, chs in probe.items() for ch in chs
                   if ch.kind == "end_motion"]
    children = np.random.SeedSequence(seed).spawn(len(motion_keys)) if motion_keys else []
    reals: dict[tuple[str, str], Any] = {}
    for (name, cname), child in zip(motion_keys, children):
        ch = next(c for c in probe[name] if c.name == cname)
        reals[(name, cname)] = simulate_sea(ch.density, settings.duration, settings.dt,
                                            settings.method, rng=np.random.default_rng(child))
    end_motion = {f"{name}.{cname}": np.asarray(r.elevation) for (name, cname), r in reals.items()}
    n_t = int(round(settings.duration / settings.dt))

    def full(h: np.ndarray) -> np.ndarray:
        """Band values (..., n_band) -> the realization grid (..., N+1), zero outside."""
        out = np.zeros(h.shape[:-1] + (omega_r.size,), dtype=complex)
        out[..., band] = h
        return out

    def synthesized(h: np.ndarray, kinds: tuple[str, ...],
                    sources: tuple[tuple[str, str] | None, ...]) -> np.ndarray:
        """Σ over channels of synthesize(realization, H), H (n_ch, ..., N+1)."""
        y = np.zeros(h.shape[1:-1] + (n_t,))
        for i, (kind, src) in enumerate(zip(kinds, sources)):
            real = sea_real if kind == "sea" else reals.get(src) if src else None
            if real is not None:
                y += synthesize(real, h[i])
        return y

    end_tension: dict[str, dict[str, np.ndarray]] = {}
    transfer: dict[str, dict[str, np.ndarray]] = {}
    chan_names: dict[str, tuple[str, ...]] = {}
    for name, system in systems.items():
        chs = probe.get(name, ())
        tr = {}
        if chs:
            n_ch = len(chs)
            h = {e: np.zeros((n_ch, band.size), dtype=complex) for e in ("end_a", "end_b")}
            entry = line_entry_bytes(system.model, n_ch)
            for sl in frequency_chunks(band.size, entry, CHUNK_BYTES):
                resp = solve(system, channels_on(name, w_band[sl]), dampings[name], timing)
                for e in h:
                    h[e][:, sl] = resp.end_tension[e]
            tr = {e: full(v) for e, v in h.items()}
        kinds = tuple(c.kind for c in chs)
        src = tuple((name, c.name) for c in chs)
        st = system.statics
        end_tension[name] = {
            e: float(t) + (synthesized(tr[e], kinds, src) if tr else 0.0) + np.zeros(n_t)
            for e, t in (("end_a", st.tension_a), ("end_b", st.tension_b))}
        transfer[name] = tr
        chan_names[name] = tuple(c.name for c in chs)
    body_motion: dict[str, dict[str, np.ndarray]] = {}
    body_transfer: dict[str, np.ndarray] = {}
    body_channels: dict[str, tuple[str, ...]] = {}
    for grp in groups:
        gt = coupled_group_transfer(scene, grp, w_band, timing=timing) if band.size else None
        for name in grp.lines:
            st = grp.systems[name].statics
            tr = {} if gt is None else {e: full(v) for e, v in gt.end_tension[name].items()}
            end_tension[name] = {
                e: float(t) + (synthesized(tr[e], gt.kinds, gt.sources) if tr else 0.0)
                + np.zeros(n_t) for e, t in (("end_a", st.tension_a), ("end_b", st.tension_b))}
            transfer[name] = tr
            chan_names[name] = () if gt is None else gt.channels
        for b in grp.bodies:
            mean = grp.pose[b.name]
            h = (np.zeros((0, b.n_dof, omega_r.size), dtype=complex) if gt is None
                 else full(gt.body_motion[b.name]))
            y = (synthesized(h, gt.kinds, gt.sources) if gt is not None
                 else np.zeros((b.n_dof, n_t)))
            body_motion[b.name] = {k: float(mean[i]) + y[i] for i, k in enumerate(b.dof_names)}
            body_transfer[b.name] = h
            body_channels[b.name] = () if gt is None else gt.channels
    vessels = [b for b in (getattr(scene, "bodies", ()) or ())
               if getattr(b, "prescribed", None) is not None]
    for b in vessels:
        if sea_real is None:
            continue
        h = full(vessel_raos(scene, w_band)[b.name].T)[None]      # (1, 6, N+1)
        y = synthesized(h, ("sea",), (None,))
        mean = np.concatenate([np.asarray(b.position, dtype=float), np.zeros(3)])
        body_motion[b.name] = {k: float(mean[i]) + y[i] for i, k in enumerate(
            ("surge", "sway", "heave", "roll", "pitch", "yaw"))}
        body_transfer[b.name] = h
        body_channels[b.name] = ("sea",)
    order = [n for n in names if n in end_tension]
    body_order = [b.name for b in (getattr(scene, "bodies", ()) or ()) if b.name in body_motion]
    time_axis = (np.asarray(sea_real.time) if sea_real is not None
                 else (settings.duration / n_t) * np.arange(n_t))
    return TimeSeries(
        time=time_axis, method=settings.method, seed=seed,
        elevation=None if sea_real is None else np.asarray(sea_real.elevation),
        end_motion=end_motion, end_tension={n: end_tension[n] for n in order},
        omega=omega_r, channels={n: chan_names[n] for n in order},
        end_tension_transfer={n: transfer[n] for n in order},
        body_motion={n: body_motion[n] for n in body_order},
        body_channels={n: body_channels[n] for n in body_order},
        body_motion_transfer={n: body_transfer[n] for n in body_order},
    )
