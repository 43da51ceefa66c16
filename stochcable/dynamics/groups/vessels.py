"""Vessels: prescribed bodies whose motion is an RAO table relative to the sea (Tuah
1982, eqs. 3.3.6–3.3.7): their RAOs on the analysis grid per wave heading, and the motion of a
point on them (a fairlead) that drives the lines attached to it.  Nothing couples back
from the lines to a vessel.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from stochcable.bodies.rigid import rigid_link_matrix
from stochcable.errors import InputError
from stochcable.scene.model import VesselMotion

__all__ = ["VesselRaos", "fairlead_motion", "vessel_rao"]


def fairlead_motion(rao: ArrayLike, r: ArrayLike) -> np.ndarray:
    """Motion of a point of a prescribed (vessel) body from its 6-DOF RAO.

    Parameters
    ----------
    rao : array_like, complex, shape (n_omega, 6)
        Vessel motion per unit wave amplitude (surge, sway, heave [m/m], roll, pitch,
        yaw [rad/m]) about its reference point, global axes.
    r : array_like, shape (3,)
        The point relative to the reference point at the static pose. [m]

    Returns
    -------
    ndarray, complex, shape (n_omega, 3)
        u = T(r)·ξ = ξ_t + θ × r (Tuah 1982, eqs. 3.3.6–3.3.7). [m/m]
    """
    a = np.asarray(rao, dtype=complex)
    if a.ndim != 2 or a.shape[1] != 6:
        raise InputError("rao", a.shape, "m/m", "must have shape (n_omega, 6)")
    t = rigid_link_matrix(r)
    return a @ t.T


def vessel_rao(motion: VesselMotion, omega: np.ndarray, heading: float | None = None) -> np.ndarray:
    """A vessel's 6-DOF motion RAO on the grid for waves travelling toward ``heading``.

    Parameters
    ----------
    motion : VesselMotion
        The scene's prescribed body motion (an object with ``transfer(omega, heading)``).
    omega : ndarray, shape (n_omega,)
        [rad/s]
    heading : float, optional
        Wave direction [rad]; needed by a table with headings only.

    Returns
    -------
    ndarray, complex, shape (n_omega, 6)
        Surge, sway, heave [m/m], roll, pitch, yaw [rad/m]; zero outside the table
        (as end-motion RAOs).
    """
    return np.asarray(motion.transfer(omega, heading), dtype=complex).T


@dataclass(frozen=True, eq=False)
class VesselRaos:
    """The prescribed bodies' (vessels') RAOs on a frequency grid, per wave heading.

    Parameters
    ----------
    omega : ndarray, shape (n_omega,)
        [rad/s]
    motions : mapping of str to VesselMotion
        The prescribed motion of each vessel by body name.
    """

    omega: np.ndarray
    motions: Mapping[str, VesselMotion]
    _kept: dict[tuple[str, float], np.ndarray] = dataclasses.field(default_factory=dict, repr=False)

    def __contains__(self, name: object) -> bool:
        return name in self.motions

    def at(self, name: str, heading: float) -> np.ndarray:
        """Vessel ``name``'s RAO (n_omega, 6) for waves toward ``heading`` [rad]
        (:func:`vessel_rao`; kept per heading)."""
        key = (name, float(heading))
        if key not in self._kept:
            self._kept[key] = vessel_rao(self.motions[name], self.omega, heading)
        return self._kept[key]
