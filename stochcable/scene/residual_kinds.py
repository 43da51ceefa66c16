"""The registry of the residuals of the linear model: what every layer below the
computation needs to know of a residual kind, as plain data.

A residual kind is the end-tension variance one closed-form correction adds to the
linear model (:mod:`stochcable.dynamics.residuals`).  Its :class:`ResidualKind` names

- the scene switch ``analysis.linearization.<name>`` (its description is the
  pydantic field's, :func:`residual_switch`);
- the record ``LineResult.residuals[<name>]`` and the document key
  ``lines.<line>.<name>`` (:class:`stochcable.results.records.ResidualRecord`);
- its cost terms (peak memory and time per line, :mod:`stochcable.cost`);
- the text of its document keys (the manual's result reference).

:data:`RESIDUAL_KINDS` lists them in the order they are computed and written; the
outputs, the result document, the load-case plan, the cost model and the manual
iterate over it.  The compute functions live above, in
:mod:`stochcable.dynamics.residuals.registry`.  Adding a kind: one module in
``dynamics/residuals/``, one entry here, one in ``registry.COMPUTE`` and one line
``<name>: bool = residual_switch("<name>")`` on
:class:`stochcable.scene.analysis_settings.LinearizationSettings` (docs/ARCHITECTURE.md).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from pydantic import Field

__all__ = ["RESIDUAL_KINDS", "ResidualKind", "asked_residuals", "residual_switch"]


@dataclass(frozen=True)
class ResidualKind:
    """One residual of the linear model (module notes).

    Attributes
    ----------
    name : str
        The switch ``analysis.linearization.<name>``, the record key and the document
        key ``lines.<line>.<name>``.
    switch : str
        Description of the scene switch (the schema's).
    document : str
        Description of the document key ``lines.<line>.<name>``.
    scope : str
        Where the closed form does not reach (the document's ``computed`` is false).
    order : str
        Description of its ``order``.
    panels : str
        Description of its ``panels``.
    memory_bytes : int
        Peak memory of the residual, bounded by its blocks. [B]
    seconds : callable (n_elements, n_lines, in_sea) -> float
        Estimated time of the residual on one line of ``n_elements`` elements with
        ``n_lines`` variance lines, in a sea or not (calibration machine). [s]
    """

    name: str
    switch: str
    document: str
    scope: str
    order: str
    panels: str
    memory_bytes: int
    seconds: Callable[[int, int, bool], float]

    def asked(self, linearization: Any) -> bool:
        """Whether ``linearization`` (the scene's ``analysis.linearization``) asks for
        this residual."""
        return bool(getattr(linearization, self.name, False))


# The time per component pair and FFT sample·log₂, and the caps of
# stochcable.dynamics.residuals (drag_residual.MAX_PANELS, geometric_residual.MAX_ELEMENTS
# and .MAX_LINES; tests/test_cost.py checks they agree) — measured as told in
# stochcable.cost's notes on the residuals.
_DRAG_PANELS, _GEOMETRIC_ELEMENTS, _GEOMETRIC_LINES = 32, 400, 31
_DRAG_SECONDS, _GEOMETRIC_SECONDS = 2.0e-9, 3.0e-10
# peak memory bounded by the blocks: the drag's ≤ 64 components on ≤ 128 lines (≤ 1024
# and 128 before issue 31, when the times were measured), the geometric covariance
# blocks of 64 MiB and its transfer functions
_RESIDUAL_BYTES = 256 * 2**20


def _drag_seconds(n_el: int, n_j: int, in_sea: bool) -> float:
    fft = 2 ** math.ceil(math.log2(6 * n_j + 2))  # (orders 2 and 3)
    # in a sea the elements near the surface split: a quarter of the panel cap more
    panels = min(n_el + (_DRAG_PANELS // 4 if in_sea else 0), _DRAG_PANELS)
    return _DRAG_SECONDS * 2 * panels**2 * fft * math.log2(fft)  # (pairs f ≥ e: half)


def _geometric_seconds(n_el: int, n_j: int, in_sea: bool) -> float:
    if n_el > _GEOMETRIC_ELEMENTS:  # not computed
        return 0.0
    fft = 2 ** math.ceil(math.log2(4 * min(n_j, _GEOMETRIC_LINES + 1) + 2))
    return _GEOMETRIC_SECONDS * 12 * n_el**2 * fft * math.log2(fft)


RESIDUAL_KINDS: dict[str, ResidualKind] = {
    k.name: k
    for k in (
        ResidualKind(
            name="drag_residual",
            switch="Compute the end-tension variance the linearization drops: the "
            "closed-form Hermite residual of the quadratic drag, and carry it in the end "
            "statistics (lines.<name>.drag_residual; seed method, or vector on 3-D lines; "
            "lines on free bodies through the group; false: the linear model alone)",
            document="The end-tension variance the statistical drag linearization drops, "
            "in closed form (the Hermite residual of the quadratic drag; present unless "
            "``analysis.linearization.drag_residual`` is false); see "
            ":doc:`../benchmarks/drag_residual`.",
            scope="the harmonic linearization; the vector linearization of a planar line; "
            "a travelling line on free bodies",
            order="Highest Hermite order kept.",
            panels="Element groups the residual was evaluated on.",
            memory_bytes=_RESIDUAL_BYTES,
            seconds=_drag_seconds,
        ),
        ResidualKind(
            name="geometric_residual",
            switch="Compute the end-tension variance of the second-order geometric "
            "forces of the linear response (stretching and rotation of the tension), "
            "and carry it in the end statistics (lines.<name>.geometric_residual; at most "
            "400 elements; false: the linear model alone)",
            document="The end-tension variance of the second-order geometric forces of the "
            "linear response (stretching and rotation of the tension; present unless "
            "``analysis.linearization.geometric_residual`` is false); see "
            ":doc:`../benchmarks/drag_residual`.",
            scope="more than 400 elements, a travelling line on free bodies",
            order="2: the forces are quadratic in the response.",
            panels="The elements the residual was evaluated on.",
            memory_bytes=_RESIDUAL_BYTES,
            seconds=_geometric_seconds,
        ),
    )
}
"""The registered residual kinds by name, in the order they are computed and written."""


def residual_switch(name: str) -> Any:
    """The pydantic field of the scene switch ``analysis.linearization.<name>``
    (default on since issue 31: the corrected answer is the answer; described by the
    kind's ``switch``)."""
    return Field(default=True, description=RESIDUAL_KINDS[name].switch)


def asked_residuals(linearization: Any) -> tuple[ResidualKind, ...]:
    """The registered kinds ``linearization`` (the scene's
    ``analysis.linearization``) asks for, in registry order."""
    return tuple(k for k in RESIDUAL_KINDS.values() if k.asked(linearization))
