"""Travelling lines (laying, payout, hauling): the transport terms of a line moving
axially through its supports about its static shape (``matrices``: the gyroscopic and
centripetal matrices, the critical speed), the complex modes and stability of the
gyroscopic system (``modes``; the lowest modes of long lines by shift-invert Arnoldi in
``sparse``) and the relative-flow loads and statics of a travelling cable in a current
(``relative_flow``).  User page: docs/travelling.md.

References
----------
Hu, J. and Jin, D. (2001), Non-linear dynamics of a suspended travelling cable subject to
transverse fluid excitation, Journal of Sound and Vibration 239(3), 515–529.
Wickert, J. A. and Mote, C. D. (1990), Classical vibration analysis of axially moving
continua, Journal of Applied Mechanics 57, 738–744.
"""

from __future__ import annotations

from stochcable.line.transport.matrices import (  # noqa: F401  (the room's public names)
    GYRO_PATTERN,
    CriticalSpeed,
    TransportMatrices,
    check_axial_speed,
    check_line_speeds,
    check_travelling_lines,
    critical_speed,
    transport_matrices,
)

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
