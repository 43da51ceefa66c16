"""Transport terms of a line travelling along itself (laying, payout, hauling).

A line whose material moves at speed c along its static shape (from end_a to end_b for
c > 0) has, about that shape, the small-motion equation

    M_T ü + (C + G) u̇ + (K + K_c) u = F,

with the control-volume (Eulerian) transport terms of its structural mass m per unit
length (Wickert & Mote 1990, eq. 1):

- the gyroscopic (Coriolis) term 2 m c ∂²u/∂s∂t: skew-symmetric G, consistent 2-node
  element G_e = m c [[0, 1], [−1, 0]] ⊗ I (the skew part of 2 m c ∫ N_i N_j′ ds, which
  is the whole of it once assembled on a uniform line with prescribed ends);
- the centripetal term m c² ∂²u/∂s²: K_c,e = −(m c²/l) I ⊗ [[1, −1], [−1, 1]], so the
  geometric stiffness carries the effective tension T − m c² (and the axial stiffness
  EA/l0 − m c²/l).

Only the line's own mass travels: the added mass of the water is not convected along
the line (an axial motion of a cylinder does not move its surface normally).  The
static tension T is the one the statics gives (the tension of the line at rest with
the same shape); the centripetal load m c² κ of the steady travel on the curved static
shape is not in the statics (docs/travelling.md: exact for a straight line, an error of
order m c²/T elsewhere).

The complex modes and the stability of the gyroscopic system are in
:mod:`stochcable.line.transport.modes`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.sparse as sp

from stochcable.errors import InputError, PhysicsWarning, warn
from stochcable.line.elements import STIFFNESS_PATTERN, expand_blocks
from stochcable.line.fem import FEModel, chain_csr
from stochcable.validation import finite_scalar

__all__ = [
    "GYRO_PATTERN",
    "TransportMatrices",
    "CriticalSpeed",
    "critical_speed",
    "check_axial_speed",
    "transport_matrices",
    "check_line_speeds",
    "check_travelling_lines",
]

#: The 2×2 node pattern of the consistent skew-symmetric gyroscopic element.
GYRO_PATTERN = np.array([[0.0, 1.0], [-1.0, 0.0]])


@dataclass(frozen=True, eq=False)
class TransportMatrices:
    """Transport terms of one line at one axial speed, on all model DOFs.

    Attributes
    ----------
    speed : float
        Axial speed c, positive from end_a to end_b. [m/s]
    G : scipy.sparse.csr_array, shape (n_dof, n_dof)
        Gyroscopic matrix (skew-symmetric). [N·s/m]
    Kc : scipy.sparse.csr_array, shape (n_dof, n_dof)
        Centripetal stiffness, −m c² ∂²/∂s² (negative semi-definite). [N/m]
    K : scipy.sparse.csr_array, shape (n_dof, n_dof)
        The model's stiffness plus ``Kc``. [N/m]
    mass_per_length : ndarray, shape (n_el,)
        Travelling (structural) mass per unit current length, m l0/l. [kg/m]
    """

    speed: float
    G: sp.csr_array
    Kc: sp.csr_array
    K: sp.csr_array
    mass_per_length: np.ndarray


@dataclass(frozen=True)
class CriticalSpeed:
    """The lowest critical speed √(T/m) of a line's elements.

    Attributes
    ----------
    speed : float
        min over elements of √(T/m) (0 when an element is slack). [m/s]
    element : int
        Element where it is reached.
    s : float
        Unstretched arc length of that element's midpoint from end_a. [m]
    tension : float
        Static tension of that element. [N]
    mass_per_length : float
        Its travelling mass per unit current length. [kg/m]
    """

    speed: float
    element: int
    s: float
    tension: float
    mass_per_length: float


def _check_model(model: Any) -> FEModel:
    if not isinstance(model, FEModel):
        raise InputError("model", type(model).__name__, "-", "must be an FEModel")
    return model


def _travelling_mass(model: FEModel) -> np.ndarray:
    """Structural mass per unit current length of each element, m l0/l. [kg/m]"""
    return model.mesh.mass * model.l0 / model.length


def critical_speed(model: FEModel) -> CriticalSpeed:
    """Lowest critical transport speed √(T/m) of a line about its static shape.

    Parameters
    ----------
    model : FEModel
        The line's model (:func:`stochcable.line.fem.assemble`).

    Returns
    -------
    CriticalSpeed
        The speed and where it is reached (for a uniform line: the lowest-tension
        point).

    Notes
    -----
    At c² = T/m the effective tension T − m c² of that element vanishes: the transverse
    wave speed against the travelling material, √(T/m) − |c|, reaches zero and a taut
    travelling string diverges (Wickert & Mote 1990, eq. 22).
    """
    model = _check_model(model)
    m = _travelling_mass(model)
    t = np.where(model.slack, 0.0, model.tension)
    ratio = np.where(m > 0.0, t / np.where(m > 0.0, m, 1.0), np.inf)
    j = int(np.argmin(ratio))
    s_mid = 0.5 * (model.mesh.s0[j] + model.mesh.s0[j + 1])
    return CriticalSpeed(
        speed=float(np.sqrt(max(ratio[j], 0.0))),
        element=j,
        s=float(s_mid),
        tension=float(model.tension[j]),
        mass_per_length=float(m[j]),
    )


def check_axial_speed(model: FEModel, speed: float, parameter: str = "axial_speed") -> float:
    """The axial speed, checked below the line's critical speed (InputError else).

    Parameters
    ----------
    model : FEModel
        The line's model about its static shape.
    speed : float
        Axial speed, positive from end_a to end_b. [m/s]
    parameter : str
        Name of the speed in the error message (``"lines[0].axial_speed"``).

    Returns
    -------
    float
        ``speed``.
    """
    c = finite_scalar(parameter, speed, "m/s")
    if c == 0.0:
        return c
    crit = critical_speed(model)
    if abs(c) >= crit.speed:
        raise InputError(
            parameter,
            c,
            "m/s",
            f"|c| must be below the critical speed √(T/m) = {crit.speed:.4g} m/s of line "
            f"'{model.mesh.name}' (T = {crit.tension:.4g} N, m = "
            f"{crit.mass_per_length:.4g} kg/m at s = {crit.s:.4g} m from end_a, its "
            "lowest √(T/m)): at and above it the effective tension T − m c² is not "
            "positive and the travelling line diverges",
        )
    return c


def transport_matrices(model: FEModel, speed: float) -> TransportMatrices:
    """Gyroscopic and centripetal matrices of a line travelling at ``speed``.

    Parameters
    ----------
    model : FEModel
        The line's model about its static shape.
    speed : float
        Axial speed c, positive from end_a to end_b. [m/s]

    Returns
    -------
    TransportMatrices
        G, K_c and K + K_c on all model DOFs (partition them with
        :meth:`FEModel.partition`).

    Notes
    -----
    Element matrices (module docstring; Wickert & Mote 1990, eq. 1, discretized with
    the 2-node elements of :mod:`stochcable.line.elements`): G_e = m c [[0, 1],
    [−1, 0]] ⊗ I and K_c,e = −(m c²/l) [[1, −1], [−1, 1]] ⊗ I, with m the structural
    mass per unit current length m0 l0/l.  The model's seabed springs and the split
    touchdown element are kept in K; the transport applies to the whole line.
    """
    model = _check_model(model)
    c = finite_scalar("speed", speed, "m/s")
    m = _travelling_mass(model)
    d = model.dim
    eye = np.eye(d)[None]
    g_el = expand_blocks((m * c)[:, None, None] * eye, GYRO_PATTERN)
    kc_el = expand_blocks((-m * c * c / model.length)[:, None, None] * eye, STIFFNESS_PATTERN)
    G = chain_csr(g_el, model.n_nodes, d)
    Kc = chain_csr(kc_el, model.n_nodes, d)
    K = (model.K + Kc).tocsr()
    return TransportMatrices(speed=c, G=G, Kc=Kc, K=K, mass_per_length=m)


def check_line_speeds(lines: Any, models: dict[str, FEModel]) -> dict[str, float]:
    """Check every line's ``axial_speed`` against its critical speed.

    Parameters
    ----------
    lines : sequence of scene Line
        The scene's lines (``scene.lines``), in order.
    models : dict of str to FEModel
        Each line's model about its static shape, by name.

    Returns
    -------
    dict of str to float
        The axial speed of every travelling line (c ≠ 0), by name. [m/s]

    Raises
    ------
    InputError
        ``lines[i].axial_speed`` at or above the critical speed √(T/m) (named).
    """
    out = {}
    for i, line in enumerate(lines):
        c = float(getattr(line, "axial_speed", 0.0))
        if c != 0.0:
            out[line.name] = check_axial_speed(models[line.name], c, f"lines[{i}].axial_speed")
    return out


def check_travelling_lines(scene: Any, statics: Any) -> None:
    """Check the travelling lines of a scene before its response is solved.

    Parameters
    ----------
    scene : Scene
        The validated scene.
    statics : StaticsResult
        Its statics (``statics.lines[name]``).

    Raises
    ------
    InputError
        ``lines[i].axial_speed`` at or above the critical speed (named);
        ``analysis.linearization.method`` "harmonic" (no mean-flow term) with a
        travelling line.

    Warns
    -----
    PhysicsWarning
        A travelling line on a body: the coupled modes of its group are those without
        the gyroscopic term (the coupled response has it: the line's direct solve).
    """
    from stochcable.line.fem import build_fe_model

    for i, line in enumerate(scene.lines):
        if line.axial_speed == 0.0:
            continue
        model = build_fe_model(statics.lines[line.name], scene.environment, dim=3)
        check_axial_speed(model, line.axial_speed, f"lines[{i}].axial_speed")
        if scene.analysis.linearization.method == "harmonic":
            raise InputError(
                "analysis.linearization.method",
                "harmonic",
                "-",
                f"line '{line.name}' travels (lines[{i}].axial_speed = {line.axial_speed:g} "
                "m/s): its drag acts on the mean relative flow U − c e, which the harmonic "
                "(regular-wave) form has no term for; use 'seed' or 'vector'",
            )
        bodies = [e.attach.body for e in (line.end_a, line.end_b) if e.attach is not None]
        if bodies:
            warn(
                f"line '{line.name}' travels (lines[{i}].axial_speed = "
                f"{line.axial_speed:g} m/s) on body '{bodies[0]}': the coupled modes of its "
                "group leave out the gyroscopic term (K + K_c and M only); the response "
                "has it",
                PhysicsWarning,
            )
