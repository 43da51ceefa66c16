"""Strumming of a line in a steady current: vortex shedding, the lock-in band, the
hydrodynamic damping and drag amplification (``screen``: :func:`strumming_screen`), the
wake oscillator's harmonic balance (``balance``; its proven-empty start grids in ``bound``
and the compiled start grid in ``kernels``, imported lazily) and the out-of-plane modes of
a 2-D model (``modes``).  User page: docs/strumming.md.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State
University, §6.6.
"""

from __future__ import annotations

from stochcable.line.strumming.screen import (  # noqa: F401  (the room's public names)
    CROSS_FLOW_BAND,
    LIFT_DEFAULT,
    STROUHAL_DEFAULT,
    ElementFlow,
    StrummingInput,
    StrummingMode,
    StrummingTable,
    amplitude_griffin,
    drag_amplification_vandiver,
    element_flow,
    hydrodynamic_damping_ratio,
    reduced_damping,
    reduced_velocity,
    shedding_frequency,
    strouhal_roshko,
    strumming_screen,
)

__all__ = [
    "CROSS_FLOW_BAND",
    "STROUHAL_DEFAULT",
    "LIFT_DEFAULT",
    "shedding_frequency",
    "strouhal_roshko",
    "reduced_velocity",
    "hydrodynamic_damping_ratio",
    "reduced_damping",
    "drag_amplification_vandiver",
    "amplitude_griffin",
    "StrummingInput",
    "ElementFlow",
    "element_flow",
    "StrummingMode",
    "StrummingTable",
    "strumming_screen",
]
