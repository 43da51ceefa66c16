"""Time series of one realization (Tuah 1982, §5.1, eq. 5.3.29 and step 14): the sea,
the end motions, the end tensions of every line and the motions of the bodies, all
synthesized from transfer functions solved on the realization grid: every group (a
line alone, lines on bodies) by :mod:`stochcable.dynamics.timeseries.group_transfer`.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from stochcable.dynamics.groups.analysis import CoupledGroup
from stochcable.dynamics.loads.channels import Channel
from stochcable.dynamics.loads.sea_channels import direction_channel, sea_channel_headings
from stochcable.dynamics.model.system import LineSystem
from stochcable.dynamics.timeseries.residual_series import (
    residual_motion_density,
    residual_series,
    residual_tension_series,
)
from stochcable.line.statics import LineStatics
from stochcable.results.documents import (
    TimeSeries,
)
from stochcable.scene.model import Scene, TimeSeriesSettings
from stochcable.sea.realization import SeaRealization, frequency_grid, simulate_sea, synthesize
from stochcable.sea.spreading import simulate_sea_directional

# ---------------------------------------------------------------------- time series


def simulate_timeseries(
    scene: Scene,
    settings: TimeSeriesSettings,
    groups: tuple[CoupledGroup, ...],
    *,
    timing: dict[str, float] | None = None,
    lines: Mapping[str, Any] | None = None,
    bodies: Mapping[str, Any] | None = None,
) -> TimeSeries:
    """One realization of every input channel and the end-tension and body-motion
    time series.

    Parameters
    ----------
    scene : Scene
    settings : TimeSeriesSettings
        method (dsa/nsa), duration, dt, seed.
    groups : tuple of CoupledGroup
        The converged groups of the scene
        (:class:`stochcable.dynamics.groups.analysis.CoupledGroup`): every line alone
        (a group without bodies), every coupled group and every free-floating body;
        their lines' end tensions and their free bodies' motions are synthesized.
    timing : dict, optional
        Accumulates ``solve_s``.
    lines : mapping of str to LineResult, optional
        The lines' frequency-domain results: where their residuals were applied
        (``corrected_spectra``), each end tension gets an independent Gaussian
        component with the residuals' spectral density
        (:mod:`stochcable.dynamics.timeseries.residual_series`), so the record's σ and
        spectrum are the corrected ones; none given: the linear model's series.
    bodies : mapping of str to BodyResult, optional
        The bodies' results: a free body whose motion carries the residuals
        (``corrected_spectra``) gets in every DOF an independent Gaussian component
        with the residuals' density likewise
        (:func:`~stochcable.dynamics.timeseries.residual_series.residual_motion_density`),
        from the seed's children after the lines' components (the other series are
        unchanged by it).

    Returns
    -------
    TimeSeries

    Notes
    -----
    The sea: :func:`stochcable.sea.realization.simulate_sea` with ``rng=seed`` (so η is the
    realization a stand-alone simulation with that seed gives).  End-motion spectrum
    channels, in the order of the scene's lines (alone and coupled alike) ×
    (end_a, end_b) × (surge, sway, heave), use the independent generators
    ``np.random.default_rng(c)`` for ``c in np.random.SeedSequence(seed).spawn(n)``.
    Responses are :func:`stochcable.sea.realization.synthesize` of the transfer functions solved
    on the realization grid ω_m = mΔω, restricted to the analysis band
    [omega.min, omega.max] (zero outside, as the response spectra are), so η, end
    motions, tensions and body motions of one realization are mutually consistent
    (Tuah 1982, §5.1, eq. 5.3.29 and step 14).  Every group: its linear system at its
    converged drag (lines' Damping, bodies' drag σ) solved on the band
    (:func:`stochcable.dynamics.timeseries.group_transfer.coupled_group_transfer`; an end on a
    vessel moves with the vessel RAO in the sea channel).  Vessels: their RAO times
    the sea.  The band is solved in chunks of frequencies, so only the end tensions
    and body motions of the whole band are held
    (:mod:`stochcable.dynamics.timeseries.group_transfer`, "Memory").
    """
    from stochcable.dynamics.timeseries.group_transfer import vessel_raos

    syn = _Synthesis(scene, settings)
    groups = tuple(groups)
    all_systems: dict[str, LineSystem] = {}
    for grp in groups:
        all_systems.update(grp.systems)
    scene_order = [ln.name for ln in scene.lines if ln.name in all_systems]
    names = scene_order + [n for n in all_systems if n not in scene_order]
    # channel names and densities of every line (scene order) from one frequency
    probe = {
        n: _channels_on(scene, all_systems[n], syn.w_band[:1]) if syn.band.size else ()
        for n in names
    }
    syn.realize_end_motions(probe)
    out = _Series()
    _groups(scene, groups, probe, syn, out, timing)
    for b in getattr(scene, "bodies", ()) or ():
        if getattr(b, "prescribed", None) is None or syn.sea is None:
            continue  # vessels: their RAO times the sea
        # one channel per direction of a short-crested sea, each with the RAO of its
        # heading and its own realization
        headings = sea_channel_headings(scene.sea)
        sea_names = tuple(headings)
        raos = vessel_raos(scene, syn.w_band)
        h = np.stack([syn.full(raos.at(b.name, headings[n]).T) for n in sea_names])
        mean = np.concatenate([np.asarray(b.position, dtype=float), np.zeros(3)])
        out.add_body(
            b.name,
            mean,
            ("surge", "sway", "heave", "roll", "pitch", "yaw"),
            h,
            syn.synthesized(h, ("sea",) * len(sea_names), tuple(("sea", n) for n in sea_names)),
            sea_names,
        )
    order = [n for n in names if n in out.end_tension]
    residual = _residual_components(syn, order, lines or {})
    for name, ends in residual.items():
        for end, comp in ends.items():
            out.end_tension[name][end] = out.end_tension[name][end] + comp
    body_order = [b.name for b in (getattr(scene, "bodies", ()) or ()) if b.name in out.body_motion]
    moved = _body_components(syn, body_order, bodies or {}, 2 * len(order))
    for name, dofs in moved.items():
        for dof, comp in dofs.items():
            out.body_motion[name][dof] = out.body_motion[name][dof] + comp
    return TimeSeries(
        time=syn.time_axis(),
        method=settings.method,
        seed=syn.seed,
        elevation=None
        if syn.sea is None
        else np.asarray(syn.sea.elevation if syn.elevation is None else syn.elevation),
        end_motion={
            f"{name}.{cname}": np.asarray(r.elevation) for (name, cname), r in syn.reals.items()
        },
        end_tension={n: out.end_tension[n] for n in order},
        end_tension_residual=residual,
        omega=syn.omega,
        channels={n: out.channels[n] for n in order},
        end_tension_transfer={n: out.transfer[n] for n in order},
        body_motion={n: out.body_motion[n] for n in body_order},
        body_channels={n: out.body_channels[n] for n in body_order},
        body_motion_transfer={n: out.body_transfer[n] for n in body_order},
        body_motion_residual=moved,
    )


def _body_components(
    syn: _Synthesis, order: list[str], bodies: Mapping[str, Any], after: int
) -> dict[str, dict[str, np.ndarray]]:
    """The residuals' Gaussian component of every DOF of the bodies of ``order`` whose
    result in ``bodies`` has them, from the seed's children after the end motions' and
    the ``after`` lines' components'."""
    names = [n for n in order if getattr(bodies.get(n), "corrected_spectra", None) is not None]
    if not names:
        return {}
    st = syn.settings
    start = len(syn.reals) + after
    count = sum(len(bodies[n].dofs) for n in names)
    children = iter(np.random.SeedSequence(syn.seed).spawn(start + count)[start:])
    out: dict[str, dict[str, np.ndarray]] = {}
    for name in names:
        body = bodies[name]
        for dof in body.dofs:
            rng = np.random.default_rng(next(children))
            dens = residual_motion_density(body, dof)
            comp = None if dens is None else residual_series(
                *dens, st.duration, st.dt, st.method, rng, f"body '{name}' {dof}"
            )  # fmt: skip
            if comp is not None:
                out.setdefault(name, {})[dof] = comp
    return out


def _residual_components(
    syn: _Synthesis, order: list[str], lines: Mapping[str, Any]
) -> dict[str, dict[str, np.ndarray]]:
    """The residuals' Gaussian component of every end tension of the lines of
    ``order`` whose result in ``lines`` has them (module notes of
    :mod:`stochcable.dynamics.timeseries.residual_series`), from the seed's children
    after the end motions'."""
    names = [n for n in order if getattr(lines.get(n), "corrected_spectra", None) is not None]
    if not names:
        return {}
    st = syn.settings
    n_motion = len(syn.reals)
    children = np.random.SeedSequence(syn.seed).spawn(n_motion + 2 * len(names))[n_motion:]
    out: dict[str, dict[str, np.ndarray]] = {}
    for i, name in enumerate(names):
        for k, end in enumerate(("end_a", "end_b")):
            rng = np.random.default_rng(children[2 * i + k])
            comp = residual_tension_series(lines[name], end, st.duration, st.dt, st.method, rng)
            if comp is not None:
                out.setdefault(name, {})[end] = comp
    return out


class _Synthesis:
    """The realization grid, the analysis band on it and the realizations of the sea
    and of the end-motion channels; synthesis of band transfer functions."""

    def __init__(self, scene: Scene, settings: TimeSeriesSettings) -> None:
        self.settings = settings
        self.seed = int(settings.seed)
        self.omega, _ = frequency_grid(settings.duration, settings.dt)
        grid = scene.analysis.omega
        w = self.omega
        self.band = np.flatnonzero((w >= grid.min) & (w <= grid.max) & (w > 0))
        self.w_band = w[self.band]
        self.n_t = int(round(settings.duration / settings.dt))
        self.sea = None
        self.elevation = None  # (the sea's η; a short-crested sea's sums its directions)
        self.directions: dict[str, SeaRealization] = {}  # sea channel name -> its realization
        if scene.sea is not None:
            spec, g = scene.sea.spectrum, scene.environment.g

            def sea_density(w: np.ndarray) -> np.ndarray:
                w = np.asarray(w, dtype=float)
                out = np.zeros_like(w)
                out[w > 0] = spec.spectral_density(w[w > 0], g)
                return out

            ds = scene.sea.direction_set()
            if ds is None or ds.count == 1:  # (one direction: the long-crested realization)
                self.sea = simulate_sea(
                    sea_density, settings.duration, settings.dt, settings.method, rng=self.seed
                )
            else:  # a short-crested sea: an independent realization per direction
                reals = simulate_sea_directional(
                    sea_density, ds, settings.duration, settings.dt, settings.method, self.seed
                )
                self.directions = {direction_channel(b): r for b, r in zip(ds.heading, reals)}
                self.sea = reals[0]
                self.elevation = np.sum([r.elevation for r in reals], axis=0)
        self.reals: dict[tuple[str, str], SeaRealization] = {}

    def realize_end_motions(self, probe: Mapping[str, tuple[Channel, ...]]) -> None:
        """One realization per end-motion channel, in the order of ``probe`` (lines)
        and of their channels, from independent children of the seed."""
        st = self.settings
        keys = [
            (name, ch.name) for name, chs in probe.items() for ch in chs if ch.kind == "end_motion"
        ]
        children = np.random.SeedSequence(self.seed).spawn(len(keys)) if keys else []
        for (name, cname), child in zip(keys, children):
            ch = next(c for c in probe[name] if c.name == cname)
            self.reals[(name, cname)] = simulate_sea(
                ch.density, st.duration, st.dt, st.method, rng=np.random.default_rng(child)
            )

    def full(self, h: np.ndarray) -> np.ndarray:
        """Band values (..., n_band) -> the realization grid (..., N+1), zero outside."""
        out = np.zeros(h.shape[:-1] + (self.omega.size,), dtype=complex)
        out[..., self.band] = h
        return out

    def synthesized(
        self, h: np.ndarray, kinds: tuple[str, ...], sources: tuple[tuple[str, str] | None, ...]
    ) -> np.ndarray:
        """Σ over channels of synthesize(realization, H), H (n_ch, ..., N+1)."""
        y = np.zeros(h.shape[1:-1] + (self.n_t,))
        for i, (kind, src) in enumerate(zip(kinds, sources)):
            if kind == "sea":
                real = self.directions.get(src[1]) if (self.directions and src) else None
                real = self.sea if real is None else real
            else:
                real = self.reals.get(src) if src else None
            if real is not None:
                y += synthesize(real, h[i])
        return y

    def time_axis(self) -> np.ndarray:
        if self.sea is not None:
            return np.asarray(self.sea.time)
        return (self.settings.duration / self.n_t) * np.arange(self.n_t)


class _Series:
    """The series and transfer functions collected per line and body."""

    def __init__(self) -> None:
        self.end_tension: dict[str, dict[str, np.ndarray]] = {}
        self.transfer: dict[str, dict[str, np.ndarray]] = {}
        self.channels: dict[str, tuple[str, ...]] = {}
        self.body_motion: dict[str, dict[str, np.ndarray]] = {}
        self.body_transfer: dict[str, np.ndarray] = {}
        self.body_channels: dict[str, tuple[str, ...]] = {}

    def add_line(
        self,
        name: str,
        statics: LineStatics,
        tr: dict[str, np.ndarray],
        syn: _Synthesis,
        kinds: tuple[str, ...],
        sources: tuple[tuple[str, str] | None, ...],
        channels: tuple[str, ...],
    ) -> None:
        """End tensions: the static tension plus the synthesis of the transfer ``tr``."""
        self.end_tension[name] = {
            e: float(t)
            + (syn.synthesized(tr[e], kinds, sources) if tr else 0.0)
            + np.zeros(syn.n_t)
            for e, t in (("end_a", statics.tension_a), ("end_b", statics.tension_b))
        }
        self.transfer[name] = tr
        self.channels[name] = channels

    def add_body(
        self,
        name: str,
        mean: np.ndarray,
        dofs: tuple[str, ...],
        h: np.ndarray,
        y: np.ndarray,
        channels: tuple[str, ...],
    ) -> None:
        self.body_motion[name] = {k: float(mean[i]) + y[i] for i, k in enumerate(dofs)}
        self.body_transfer[name] = h
        self.body_channels[name] = channels


def _channels_on(scene: Scene, system: LineSystem, w: np.ndarray) -> tuple[Channel, ...]:
    """The line's channels on w (an end on a vessel moves in the sea channel)."""
    from stochcable.dynamics.groups.inputs import scene_line_channels
    from stochcable.dynamics.timeseries.group_transfer import vessel_raos

    ch, _ = scene_line_channels(scene, system.line, system, w, vessel_raos(scene, w))
    return ch


def _groups(
    scene: Scene,
    groups: tuple[CoupledGroup, ...],
    probe: Mapping[str, tuple[Channel, ...]],
    syn: _Synthesis,
    out: _Series,
    timing: dict[str, float] | None,
) -> None:
    """Every group: its linear system at its converged drag solved on the band
    (:func:`stochcable.dynamics.timeseries.group_transfer.coupled_group_transfer`): the end
    tensions of its lines and the motions of its free bodies (a line alone without
    any channel: its static tension)."""
    from stochcable.dynamics.timeseries.group_transfer import coupled_group_transfer

    for grp in groups:
        silent = not grp.bodies and not any(probe.get(n) for n in grp.lines)
        gt = (
            coupled_group_transfer(scene, grp, syn.w_band, timing=timing)
            if syn.band.size and not silent
            else None
        )
        for name in grp.lines:
            tr = {} if gt is None else {e: syn.full(v) for e, v in gt.end_tension[name].items()}
            out.add_line(
                name,
                grp.systems[name].statics,
                tr,
                syn,
                () if gt is None else gt.kinds,
                () if gt is None else gt.sources,
                () if gt is None else gt.channels,
            )
        for b in grp.bodies:
            h = (
                np.zeros((0, b.n_dof, syn.omega.size), dtype=complex)
                if gt is None
                else syn.full(gt.body_motion[b.name])
            )
            y = (
                syn.synthesized(h, gt.kinds, gt.sources)
                if gt is not None
                else np.zeros((b.n_dof, syn.n_t))
            )
            out.add_body(
                b.name, grp.pose[b.name], b.dof_names, h, y, () if gt is None else gt.channels
            )
