"""The compute functions of the registered residual kinds
(:data:`stochcable.scene.residual_kinds.RESIDUAL_KINDS`, whose plain data the layers
below read): :data:`COMPUTE` maps a kind's name to the function that evaluates it on
one line, and :func:`residual_parts` pairs every registered kind with its function for
the outputs (:func:`stochcable.dynamics.outputs.line_result.line_result`).

A compute function takes ``(system, channels, linearization, std, *, influence)`` —
the line, its input channels, its linearization, the linear end-tension σ by end [N]
and the end-tension influence shared by the kinds of one line — and returns a
:class:`stochcable.results.records.ResidualRecord`.
"""

from __future__ import annotations

from typing import Any, Protocol

from stochcable.dynamics.residuals.drag_form_guard import guard_drag_form
from stochcable.dynamics.residuals.drag_residual import drag_residual
from stochcable.dynamics.residuals.drag_residual_3d import drag_residual_3d
from stochcable.dynamics.residuals.geometric_residual import geometric_residual
from stochcable.dynamics.residuals.residual_lines import EndInfluence
from stochcable.results.records import ResidualRecord
from stochcable.scene.residual_kinds import RESIDUAL_KINDS, ResidualKind

__all__ = ["COMPUTE", "ResidualFunction", "drag_residual_lines", "residual_parts"]


class ResidualFunction(Protocol):
    """The signature of a residual kind's compute function (module notes)."""

    def __call__(
        self,
        system: Any,
        channels: Any,
        linearization: Any,
        std: dict[str, float],
        *,
        influence: EndInfluence | None = None,
    ) -> ResidualRecord: ...


def drag_residual_lines(
    system: Any,
    channels: Any,
    linearization: Any,
    std: dict[str, float],
    *,
    influence: Any = None,
) -> ResidualRecord:
    """The drag residual of a line of either dimension:
    :func:`~stochcable.dynamics.residuals.drag_residual_3d.drag_residual_3d` for a 3-D
    model, else :func:`~stochcable.dynamics.residuals.drag_residual.drag_residual` (the
    registered compute function of ``drag_residual``)."""
    fn = drag_residual_3d if system.model.dim == 3 else drag_residual
    return fn(system, channels, linearization, std, influence=influence)


COMPUTE: dict[str, ResidualFunction] = {
    "drag_residual": guard_drag_form(drag_residual_lines),
    "geometric_residual": geometric_residual,
}
"""The compute function of every registered residual kind, by its name."""


def residual_parts(linearization: Any) -> tuple[tuple[ResidualKind, ResidualFunction], ...]:
    """The kinds ``linearization`` (the scene's ``analysis.linearization``) asks for,
    each with its compute function, in registry order.

    Raises
    ------
    LookupError
        A kind asked for is registered without a compute function.
    """
    out = []
    for kind in RESIDUAL_KINDS.values():
        if not kind.asked(linearization):
            continue
        if kind.name not in COMPUTE:
            raise LookupError(f"residual kind {kind.name!r} has no compute function in COMPUTE")
        out.append((kind, COMPUTE[kind.name]))
    return tuple(out)
