"""The sea's input channels: its spectrum as a function, one channel per direction of a
short-crested sea, and a channel's spectrum swapped for another sea state's (the
engine's reuse of a line's inputs across sea states,
:mod:`stochcable.dynamics.groups.seainputs`).

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Callable
from typing import TypeVar

import numpy as np

from stochcable.scene.model import Sea, Spectrum

#: A channel (:class:`~stochcable.dynamics.loads.channels.Channel`, which imports this
#: module): :func:`with_spectrum` returns the type it is given.
ChannelT = TypeVar("ChannelT")

__all__ = [
    "direction_channel",
    "sea_channel_densities",
    "sea_channel_headings",
    "spectrum_callable",
    "with_spectrum",
]


def with_spectrum(channel: ChannelT, density: Callable[[np.ndarray], np.ndarray]) -> ChannelT:
    """``channel`` (a :class:`~stochcable.dynamics.loads.channels.Channel`) with the spectrum
    ``density`` (sampled on its grid) instead of its own; its transfer functions shared
    (the lazy nodal kinematics not computed)."""
    out = copy.copy(channel)
    object.__setattr__(out, "density", density)
    object.__setattr__(out, "spectrum", density(channel.omega))
    return out


def sea_channel_densities(
    sea: Sea, g: float
) -> list[tuple[str, float, Callable[[np.ndarray], np.ndarray]]]:
    """The sea's input channels: (name, heading [rad], ω -> spectrum).  A long-crested
    sea is one channel "sea"; a short-crested one a channel "sea@<heading in deg>" per
    discrete direction k (:meth:`stochcable.scene.environment.Sea.direction_set`) with
    the share w_k S(ω) of the spectrum: independent inputs whose variances add (the
    directional spectrum S(ω)D(θ), Tuah (1982), §5.1 per direction)."""
    density = spectrum_callable(sea.spectrum, g)
    ds = sea.direction_set()
    if ds is None:
        return [("sea", sea.heading_rad, density)]
    return [
        (direction_channel(b), float(b), lambda w, f=float(wk): f * density(w))
        for b, wk in zip(ds.heading, ds.weight)
    ]


def sea_channel_headings(sea: Sea) -> dict[str, float]:
    """The heading [rad] of each of the sea's input channels by name
    (:func:`sea_channel_densities`: ``{"sea": β}`` for a long-crested sea, one
    ``"sea@<deg>"`` per direction θ_k of a short-crested one)."""
    ds = sea.direction_set()
    if ds is None:
        return {"sea": sea.heading_rad}
    return {direction_channel(b): float(b) for b in ds.heading}


def direction_channel(heading: float) -> str:
    """The name of the sea channel of direction ``heading`` [rad]: "sea@<deg>" (six
    significant digits; the round-off of a centroid on the mean, |θ| < 1e-9 deg, as
    0: "sea@0", not "sea@-1.27092e-14")."""
    deg = math.degrees(heading)
    return f"sea@{0.0 if abs(deg) < 1e-9 else deg:.6g}"


def spectrum_callable(spec: Spectrum, g: float) -> Callable[[np.ndarray], np.ndarray]:
    """ω -> S(ω) of a scene spectrum ``spec`` (one-sided, zero at ω <= 0), ω in
    [rad/s], S in [m²·s/rad]; ``g`` [m/s²] for the spectra that need it."""

    def density(w: np.ndarray) -> np.ndarray:
        w = np.asarray(w, dtype=float)
        out = np.zeros_like(w)
        pos = w > 0
        out[pos] = spec.spectral_density(w[pos], g)
        return out

    return density
