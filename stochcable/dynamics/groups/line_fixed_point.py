"""The drag linearization of one line on its own (Tuah 1982, §5.3 steps 5–13): the one
drag fixed point of the engine (:func:`stochcable.dynamics.groups.group_fixed_point.
linearize_coupled`) applied to the degenerate group of one line and no bodies.

A line is a group without bodies: its σ are iterated to the fixed point by the same
code as lines coupled to bodies, with the same coarse start (frequency subset,
interpolatory weights, defect correction, warm Anderson step;
:mod:`stochcable.dynamics.groups.coarse`).  :func:`linearize` is the entry point of
a user (or a test) who holds one :class:`~stochcable.dynamics.model.system.LineSystem` and
its channels; the engine itself solves every line as a group
(:func:`stochcable.dynamics.groups.analysis.solve_coupled`).

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import numpy as np

from stochcable.dynamics.groups.group_fixed_point import linearize_coupled
from stochcable.dynamics.groups.inputs import CoupledLine
from stochcable.dynamics.loads.channels import Channel
from stochcable.dynamics.model.system import Linearization, LineSystem, Progress
from stochcable.errors import InputError
from stochcable.scene.model import AnalysisSettings

__all__ = ["linearize"]


def linearize(
    system: LineSystem,
    channels: tuple[Channel, ...],
    settings: AnalysisSettings,
    *,
    progress: Progress | None = None,
    timing: dict[str, float] | None = None,
    coarse: bool = True,
) -> Linearization:
    """Drag linearization of one line: iterate the σ of the relative velocities to a
    fixed point (Tuah 1982, §5.3 steps 5–13).

    Parameters
    ----------
    system : LineSystem
        The line, both ends prescribed (fixed or moving with the channels).
    channels : tuple of Channel
        Inputs on the analysis grid.
    settings : AnalysisSettings
        ``linearization`` (method, tolerance, max_iterations, relaxation,
        acceleration, allow_unconverged).
    progress : callable, optional
        Called as ``progress("linearization", {"line", "group", "iteration",
        "change"})`` after every response evaluation.
    timing : dict, optional
        Accumulates ``solve_s``. [s]
    coarse : bool, optional
        Allow the coarse start (:mod:`stochcable.dynamics.groups.coarse`; used on
        grids of at least ``COARSE_MIN_FREQUENCIES`` points and tolerances of at least
        ``COARSE_MIN_TOLERANCE``).  False iterates on the full grid from the at-rest
        start.  Both converge to the full-grid fixed point (the same convergence test
        on the full grid).

    Returns
    -------
    Linearization
        The drag of the last evaluation, the record (every response evaluation in
        order, coarse and full-grid) and the response computed with that drag (its σ
        are the record's final σ: no extra solve).

    Raises
    ------
    ConvergenceError
        If the σ do not settle within ``max_iterations`` and ``allow_unconverged`` is
        false (the message names the line).
    InputError
        For the harmonic form with a current (not defined).

    Notes
    -----
    :func:`~stochcable.dynamics.groups.group_fixed_point.linearize_coupled` with this line
    alone and no bodies: the start is the fluid velocity relative to the line at
    rest (following its moving ends quasi-statically), the first response starts the
    iteration unmixed, then Anderson (mixing ``ANDERSON_MIXING``) or relaxed steps.
    """
    if settings.linearization.method == "harmonic" and (
        np.any(system.current_el) or np.any(system.current_node)
    ):
        raise InputError(
            "analysis.linearization.method",
            "harmonic",
            "-",
            "the harmonic (regular-wave) form has no current term: use "
            "'seed' or 'vector' with a current",
        )
    clin = linearize_coupled(
        [CoupledLine(system, tuple(channels))],
        [],
        settings,
        rho=float(system.environment.rho),
        progress=progress,
        timing=timing,
        coarse=None if coarse else False,
    )
    return clin.lines[system.name]
