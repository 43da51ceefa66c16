"""Nonlinear time-domain reference of a line whose end_b is on a free rigid body: the
one-line case of :func:`stochcable.reference.cable_bodies.simulate_lines_on_body` (the
line of :mod:`stochcable.reference.cable` and a planar body, surge, heave and pitch,
integrated together; its module notes give the model and the scheme), the yardstick of
the frequency domain's lines on bodies and of their residuals
(:mod:`stochcable.dynamics.residuals.body_residual`).

Known limit: with the one-sided penalty bed a light slack line whose nodes lift off
and land gains energy in the non-dissipative scheme (the disc buoy's 20-element leg
at m0 = 0.1 ft²: element tensions above 10⁴ lbf on a 10² lbf mean before Newton
fails); ``seabed="linear"`` (the bed frozen at its static contact, the frequency
domain's kind) or axial ``internal_damping`` keeps such records bounded
(docs/accuracy/bodies.md).

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from stochcable.errors import InputError
from stochcable.reference.cable import _select_line
from stochcable.reference.cable_bodies import paired_linear, simulate_lines_on_body
from stochcable.scene.model import Scene, load_scene

__all__ = ["BodyLineHistory", "simulate_line_on_body"]


@dataclass(frozen=True, eq=False)
class BodyLineHistory:
    """Nonlinear time-domain response of a line on a free body.

    Attributes
    ----------
    line, body : str
        The line and the body at its end_b.
    t : ndarray, shape (n_t,)
        Time, 0 at the static start. [s]
    tension_a, tension_b : ndarray, shape (n_t,)
        End tensions: the support reactions (as the frequency domain's). [N]
    motion : ndarray, shape (n_t, 3)
        Body motion (surge, heave, pitch) from its static pose. [m, m, rad]
    iterations : ndarray of int, shape (n_t,)
        Newton iterations per step. [-]
    dt, ramp : float
        Step and half-cosine ramp (excluded from the statistics). [s]
    """

    line: str
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
        """The linear response of transfer function ``transfer`` (per unit wave
        amplitude on ``omega``, e.g. a frequency-domain result's end tension) to this
        record's sea, ramp and steps: the paired linear record of the same waves.

        Parameters
        ----------
        omega : ndarray, shape (n_w,)
            [rad/s]
        transfer : ndarray, complex, shape (n_w,)
            Interpolated (real and imaginary parts) on the realization's grid, zero
            outside ``omega``. [unit/m]

        Returns
        -------
        ndarray, shape (n_t,)
        """
        return paired_linear(self.excitation, omega, transfer)

    def records(self) -> dict[str, np.ndarray]:
        """Every record by name: "end_a", "end_b", "surge", "heave", "pitch"."""
        out = {"end_a": self.tension_a, "end_b": self.tension_b}
        out.update({k: self.motion[:, i] for i, k in enumerate(("surge", "heave", "pitch"))})
        return out

    def std(self, start: float | None = None) -> dict[str, float]:
        """σ of the end tensions and body DOFs after ``start`` (default the ramp). [N, m, rad]"""
        keep = self.t >= (self.ramp if start is None else start)
        return {k: float(np.std(x[keep])) for k, x in self.records().items()}


def simulate_line_on_body(
    scene: Scene | dict[str, Any] | str,
    line_name: str | None = None,
    *,
    duration: float,
    seed: int,
    dt: float | None = None,
    ramp: float | None = None,
    band: tuple[float, float] | None = None,
    method: str = "dsa",
    tolerance: float = 1e-7,
    max_iterations: int = 30,
    linear_drag: tuple[Any, Any, Any] | None = None,
    seabed: str = "one_sided",
    internal_damping: float = 0.0,
) -> BodyLineHistory:
    """Nonlinear time-domain response of a line with end_b on a free planar body.

    Parameters
    ----------
    scene : Scene, mapping or JSON
        A planar scene: the line's end_a fixed (no end motion), its end_b attached to
        a free body (the body's only line), a long-crested sea.
    line_name : str, optional
        The line (default the first). [-]
    duration : float
        Length of the sea realization and of the record. [s]
    seed, dt, ramp, band, method, tolerance, max_iterations
        As :func:`~stochcable.reference.cable_bodies.simulate_lines_on_body`'s.
    linear_drag : (array_like, array_like, array_like), optional
        A controlled experiment: the line's drag linear with (B_n, B_t) per element
        (:func:`stochcable.reference.cable.simulate_line_timedomain`'s ``drag="linear"``)
        and the body's with the linear coefficient per direction (x, y, z) at the drag
        point (a frequency-domain result's ``linearization.b_normal``, ``b_axial`` and
        the body's ``drag_coefficient``): what is left nonlinear is the geometry and
        the seabed. [N·s/m², N·s/m², N·s/m]
    seabed, internal_damping
        As :func:`~stochcable.reference.cable_bodies.simulate_lines_on_body`'s.

    Returns
    -------
    BodyLineHistory

    Raises
    ------
    InputError
        A scene outside the scope above, or a body with frequency-dependent added mass
        or radiation damping over the band.
    ConvergenceError
        Newton did not converge in a step.
    """
    sc = load_scene(scene)
    line = _select_line(sc, line_name)
    att = line.end_b.attach
    if att is None or line.end_a.attach is not None or line.end_a.motion is not None:
        raise InputError(
            "line", line.name, "-", "needs end_b on a free body and end_a fixed without motion"
        )
    if any(ln.name != line.name and att.body in _bodies_of(ln) for ln in sc.lines):
        raise InputError("body", att.body, "-", "must carry only this line")
    if linear_drag is not None:
        linear_drag = ({line.name: tuple(linear_drag[:2])}, linear_drag[2])
    h = simulate_lines_on_body(
        sc, att.body, duration=duration, seed=seed, dt=dt, ramp=ramp, band=band,
        method=method, tolerance=tolerance, max_iterations=max_iterations,
        linear_drag=linear_drag, seabed=seabed, internal_damping=internal_damping,
    )  # fmt: skip
    return BodyLineHistory(
        line.name, h.body, h.t, h.tension_a[:, 0], h.tension_b[:, 0], h.motion,
        h.iterations, h.dt, h.ramp, h.excitation,
    )  # fmt: skip


def _bodies_of(ln: Any) -> tuple[str, ...]:
    return tuple(e.attach.body for e in (ln.end_a, ln.end_b) if e.attach is not None)
