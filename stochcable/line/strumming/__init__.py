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

from stochcable.line.strumming.screen import *  # noqa: F403  (the room's public names)
from stochcable.line.strumming.screen import __all__  # noqa: F401
