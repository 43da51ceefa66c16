"""Resolution checks of the nonlinear time-domain reference
(:mod:`stochcable.reference.cable`) that concern its model rather than its input."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from stochcable.errors import ResolutionWarning, warn
from stochcable.reference.cable_newmark import newmark_period_error, newmark_step_for
from stochcable.scene.model import Scene

__all__ = ["check_seabed_contact"]


def check_seabed_contact(
    scene: Scene, mesh: Any, model: Any, xs: np.ndarray, h: float, tolerance: float
) -> None:
    """A ResolutionWarning when nodes resting on an undamped seabed (contact damping 0)
    ring on the contact spring faster than the step resolves: ω_c = √(k_bed/m_node)
    with (ω_c h)²/12 above ``tolerance``
    (:data:`stochcable.reference.cable.PERIOD_ERROR_TOLERANCE`).  The average-acceleration
    scheme does not dissipate that ringing and the record is then dominated by it
    (1.5–2.8× the tension σ on the chain example with Δt 0.05 s, ω_c ≈ 45 rad/s;
    docs/benchmarks/moordyn.md)."""
    env = scene.environment
    if env.seabed.stiffness <= 0 or env.seabed.damping > 0 or not math.isfinite(env.depth):
        return
    n = xs.shape[0]
    grounded = np.flatnonzero(xs[:, -1] <= -env.depth + 1e-9)
    grounded = grounded[(grounded > 0) & (grounded < n - 1)]  # (the ends are prescribed)
    if grounded.size == 0:
        return
    m_node = np.asarray(mesh.node_mass + mesh.node_added_mass, dtype=float).copy()
    per_length = (
        np.asarray(mesh.mass, dtype=float)
        + env.rho
        * np.asarray(mesh.ca_normal, dtype=float)
        * math.pi
        * np.asarray(mesh.diameter, dtype=float) ** 2
        / 4.0
    )
    m_el = 0.5 * per_length * np.asarray(mesh.l0, dtype=float)
    full = np.zeros(n)
    full[:-1] += m_el
    full[1:] += m_el
    m_node += full
    k = np.asarray(model.k_bed, dtype=float)[grounded]
    w_c = float(np.max(np.sqrt(k / np.maximum(m_node[grounded], 1e-300))))
    err = newmark_period_error(w_c, h)
    if err > tolerance:
        dt_ok = newmark_step_for(w_c, tolerance)
        warn(
            f"{grounded.size} node(s) rest on an undamped seabed (environment.seabed."
            f"damping = 0) and ring on the contact spring at {w_c:.4g} rad/s, which the "
            f"time step {h:.4g} s does not resolve ((omega dt)^2/12 = {err:.2%} > "
            f"{tolerance:.0%}): the undissipated ringing can dominate the "
            f"record; give seabed damping or dt <= {dt_ok:.4g} s",
            ResolutionWarning,
            stacklevel=4,
        )
