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

__all__ = [
    "RESIDUAL_KINDS",
    "RESIDUAL_MEMORY_MARGIN",
    "ResidualKind",
    "ResidualSize",
    "asked_residuals",
    "residual_switch",
]


@dataclass(frozen=True)
class ResidualSize:
    """The sizes of one line that its residuals' cost terms read (from the scene alone).

    Attributes
    ----------
    elements : int
        Finite elements of the line. [-]
    frequencies : int
        ``analysis.omega.count``. [-]
    channels : int
        Input channels of the line. [-]
    dim : int
        Model dimension: 2 for a planar scene, 3 otherwise. [-]
    lines : int
        Lines n_j of the drag residual's uniform grid. [-]
    samples : int
        Amplitude lines n_j · ranks of that grid (every analysis frequency on its own
        channel of its line; ≥ ``frequencies``). [-]
    half_lines, half_samples : int
        The same of the geometric residual's grid (every second line). [-]
    """

    elements: int
    frequencies: int
    channels: int
    dim: int
    lines: int
    samples: int
    half_lines: int
    half_samples: int


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
    memory_bytes : int or callable (ResidualSize) -> float
        Peak memory of the residual's temporaries on one line above what the linear
        model holds (:meth:`memory`; an int: a constant). [B]
    seconds : callable (n_elements, n_lines, in_sea) -> float
        Estimated time of the residual on one planar line of ``n_elements`` elements
        with ``n_lines`` variance lines, in a sea or not (calibration machine). [s]
    seconds_3d : float
        Factor on ``seconds`` for a line of a 3-D model. [-]
    """

    name: str
    switch: str
    document: str
    scope: str
    order: str
    panels: str
    memory_bytes: int | Callable[[ResidualSize], float]
    seconds: Callable[[int, int, bool], float]
    seconds_3d: float = 1.0

    def memory(self, size: ResidualSize) -> int:
        """Peak memory of the residual on a line of ``size``. [B]"""
        m = self.memory_bytes
        return int(m) if isinstance(m, int) else int(math.ceil(m(size)))

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
#: Factor on the counted arrays of a residual's peak memory (:meth:`ResidualKind.memory`):
#: numpy's temporaries of the expressions not counted one by one, the allocator's
#: slack, and what the kinds' arrays feed that is not counted from the sizes: the
#: element tensions' and node motions' station rows, the kinds' dense pair lines kept
#: for them, a shared body's joint sums over all its legs' loads (tests/test_cost.py
#: measures the bound: with those, the inclined guy at 200 elements needed 1.29× the
#: arrays at 1.25 and the three-leg buoy 1.36×; 2.0 covers both with 10 % to spare). [-]
RESIDUAL_MEMORY_MARGIN = 2.0
_WORD = 16  # bytes of a complex amplitude
# the vector drag residual's covariance blocks (drag_residual_3d._BLOCK_BYTES) and what
# is formed from them at once: twice the block
_DRAG_3D_BLOCKS = 2 * 48 * 2**20


def _drag_memory(size: ResidualSize) -> float:
    """Peak memory of the drag residual of one line (issue 31). [B]

    Counted in complex words: the pieces' relative velocity per channel on the
    analysis grid (drag_segments.segment_velocity: the array, four interpolation
    temporaries of d components, one output per direction, and the sea's element
    moments: (3 + 4d + directions)·n_ch + 9 per piece and frequency; a sea splits at
    most half the panel cap more pieces), the panels' amplitude lines (three
    copies), and the panel pairs' covariance lines (planar: 2 directions × the panel
    cap squared on n_j + 3(n_j − 1) lines; 3-D: the covariance blocks)."""
    d, c, w = size.dim, size.channels, size.frequencies
    pieces = size.elements + _DRAG_PANELS // 2
    directions = 2 if d == 2 else 3
    components = directions * _DRAG_PANELS
    words = ((3 + 4 * d + directions) * c + 9) * pieces * w
    words += 3 * components * c * max(size.samples, w)
    words += components**2 * (size.lines + 3 * max(size.lines - 1, 1))
    extra = _DRAG_3D_BLOCKS if d == 3 else 0
    return RESIDUAL_MEMORY_MARGIN * (_WORD * words + extra)


def _geometric_memory(size: ResidualSize) -> float:
    """Peak memory of the geometric residual of one line (issue 31): none above its
    element cap (not computed). [B]

    Counted in complex words: the node displacements and their differences per channel
    on the analysis grid (2 × 3 per node, frequency and channel), each of the d
    processes' element values with two temporaries while it is put on its lines, the d
    processes' amplitude lines, and the element pairs' cross-spectral lines (d² on
    n_j) and covariance lines (d² components on 2(n_j − 1) lines) of every element
    (those whose forces do not reach the ends, skipped at run time, are counted: on a
    line with seabed contact the bound is the more pessimistic)."""
    n = size.elements
    if n > _GEOMETRIC_ELEMENTS:
        return 0.0
    d, c, w = size.dim, size.channels, size.frequencies
    n_j = size.half_lines
    words = 6 * c * (n + 1) * w + 3 * c * n * w + d * c * n * max(size.half_samples, w)
    words += d * d * n * n * (n_j + 2 * max(n_j - 1, 1))
    return RESIDUAL_MEMORY_MARGIN * _WORD * words


# a 3-D line (measured in stochcable.cost's notes): the vector drag residual's bivariate
# Hermite monomials on three outputs per panel, the geometric residual's three processes
_DRAG_SECONDS_3D, _GEOMETRIC_SECONDS_3D = 14.0, 3.0


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
            memory_bytes=_drag_memory,
            seconds=_drag_seconds,
            seconds_3d=_DRAG_SECONDS_3D,
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
            memory_bytes=_geometric_memory,
            seconds=_geometric_seconds,
            seconds_3d=_GEOMETRIC_SECONDS_3D,
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
