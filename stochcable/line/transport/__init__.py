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

from stochcable.line.transport.matrices import *  # noqa: F403  (the room's public names)
from stochcable.line.transport.matrices import __all__  # noqa: F401
