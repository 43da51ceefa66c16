"""The typed state of a group's drag fixed point
(:mod:`~stochcable.dynamics.groups.group_fixed_point`): the settings of one run
(:class:`FixedPointRun`), the outcome of one evaluation of the σ map
(:class:`Evaluation`) and the count the coarse and the full-grid maps share
(:class:`EvaluationCount`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from stochcable.dynamics.groups.freeline import FreeLine
from stochcable.dynamics.linearization.iteration import (
    ANDERSON_MIXING,
    FixedPointResult,
    fixed_point,
)
from stochcable.dynamics.model.system import Damping, Progress
from stochcable.scene.model import LinearizationSettings

__all__ = ["Evaluation", "EvaluationCount", "FixedPointRun", "LineSolution"]

#: A line's part of one group solve: its node displacements (frequency blocks) and
#: support forces, or, for a line without attached ends, its :class:`FreeLine`.
LineSolution = FreeLine | tuple[np.ndarray, np.ndarray]


@dataclass(frozen=True, eq=False)
class FixedPointRun:
    """What one drag fixed point of a group runs with, the same for its coarse and its
    full-grid stage.

    Attributes
    ----------
    method : str
        Drag linearization method
        (:func:`~stochcable.dynamics.linearization.variance.drag_coefficients`).
    rho : float
        Water density for the body drag. [kg/m³]
    progress : callable
        ``progress("linearization", {"group", "iteration", "change"})``.
    names : str
        The group's line names (progress).
    lin : LinearizationSettings
        Tolerance, iteration limit, relaxation, acceleration, ``allow_unconverged``.
    gname : str
        The iteration's name in messages.
    timing : dict, optional
        Accumulates ``solve_s`` of the full-grid solves. [s]
    """

    method: str
    rho: float
    progress: Progress
    names: str
    lin: LinearizationSettings
    gname: str
    timing: dict[str, float] | None

    def iterate(
        self,
        update: Callable[[np.ndarray], np.ndarray],
        x0: np.ndarray,
        *,
        tol: float,
        max_iterations: int,
        allow_unconverged: bool,
        name: str,
        before: tuple[np.ndarray, np.ndarray] | None = None,
    ) -> FixedPointResult:
        """:func:`~stochcable.dynamics.linearization.iteration.fixed_point` with this
        run's relaxation and acceleration (Anderson mixing ``ANDERSON_MIXING``;
        ``before``: an earlier evaluation opening its memory)."""
        return fixed_point(
            update,
            x0,
            tol=tol,
            max_iterations=max_iterations,
            relaxation=self.lin.relaxation,
            method="anderson" if self.lin.acceleration == "anderson" else "relaxed",
            mixing=ANDERSON_MIXING,
            allow_unconverged=allow_unconverged,
            name=name,
            before=before,
        )


@dataclass(eq=False)
class EvaluationCount:
    """The record the σ maps of one fixed point share: the evaluations so far (coarse
    and full grid, in order; the progress reports number them) and the relative change
    of the last.  Not frozen: every evaluation of either map advances it.

    Attributes
    ----------
    iterations : int
        Evaluations so far. [-]
    change : float
        Relative change of the last evaluation (NaN before the first). [-]
    """

    iterations: int = 0
    change: float = float("nan")


@dataclass(frozen=True, eq=False)
class Evaluation:
    """One evaluation of a group's σ map: what the fixed point's outcome reads of the
    last one.

    Attributes
    ----------
    damping : dict of str to Damping
        Each line's linear drag the group was solved with.
    sol : dict of str to LineSolution
        Each line's response (:func:`~stochcable.dynamics.groups.group.solve_group`,
        ``lazy``).
    xi : ndarray, complex, shape (n_w, nb, n_ch)
        Body motion per unit input. [m/unit, rad/unit]
    sigma : ndarray
        The σ of the response (lines' then bodies'). [m/s]
    body_b : dict of str to ndarray, shape (3,)
        Linear drag per direction of each drag body. [N·s/m]
    """

    damping: dict[str, Damping]
    sol: dict[str, LineSolution]
    xi: np.ndarray
    sigma: np.ndarray
    body_b: dict[str, np.ndarray]
