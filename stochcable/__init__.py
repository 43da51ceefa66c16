"""stochcable: frequency-domain stochastic response of marine cables in random seas.

Pipeline (seed 001, Tuah 1982, ch. 5): scene -> statics -> finite-element model ->
drag linearization -> direct or Foss modal solve -> response spectra, statistics and
time series.  Conventions (SI, rad/s, one-sided spectra, Re{X e^{iwt}}, z up) are in
the README and DESIGN.md.
"""

from ._version import __version__
from .errors import (
    ConvergenceError,
    InputError,
    PhysicsWarning,
    ResolutionWarning,
    SolverError,
    StochcableError,
)

__all__ = [
    "__version__",
    "StochcableError",
    "InputError",
    "ConvergenceError",
    "SolverError",
    "PhysicsWarning",
    "ResolutionWarning",
]
