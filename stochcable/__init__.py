"""stochcable: frequency-domain stochastic response of marine cables in random seas.

Pipeline (Tuah 1982, ch. 5): scene -> statics -> finite-element model ->
drag linearization -> direct or Foss modal solve -> response spectra, statistics and
time series.  Conventions (SI, rad/s, one-sided spectra, Re{X e^{iwt}}, z up) are in
the README and DESIGN.md.
"""

from stochcable._version import __version__
from stochcable.errors import (
    ConvergenceError,
    InputError,
    PhysicsWarning,
    ResolutionWarning,
    SolverError,
    StochcableError,
)

# The pipeline's top-level entry points, imported on first use so that
# ``import stochcable`` (and the CLI's start-up) stays light.
_LAZY = {
    "analyze": ("analysis", "analyze"),
    "build_engine": ("analysis", "build_engine"),
    "load_scene": ("io", "load_scene"),
    "read_moordyn": ("io", "read_moordyn"),
    "write_moordyn": ("io", "write_moordyn"),
    "Scene": ("scene.model", "Scene"),
    "solve_statics": ("statics", "solve_statics"),
    "natural_modes": ("statics", "natural_modes"),
    "simulate_sea": ("sea.realization", "simulate_sea"),
    "load_example": ("examples", "load_example"),
    "estimate_cost": ("cost", "estimate_cost"),
}


def __getattr__(name: str):
    if name in _LAZY:
        import gc
        import importlib

        module, attr = _LAZY[name]
        # no cyclic garbage collection while the pipeline imports: its ~800 modules
        # (NumPy, SciPy, pydantic and ours) leave ~50,000 tracked objects that live as
        # long as the process, and the collector traversed them ~130 times (20–40 ms
        # of the first analysis, docs/benchmarks/first_analysis.md).  After it, they
        # join the oldest generation as if they had survived (freeze then unfreeze,
        # unless the process keeps objects frozen itself) rather than being traversed
        # by the next young collections; the collector's state is restored.
        enabled = gc.isenabled()
        gc.disable()
        try:
            from stochcable import lazy_numpy

            lazy_numpy.defer()  # (numpy.f2py and numpy.testing, that SciPy's import loads)
            value = getattr(importlib.import_module(f".{module}", __name__), attr)
        finally:
            if gc.get_freeze_count() == 0:
                gc.freeze()
                gc.unfreeze()
            if enabled:
                gc.enable()
        globals()[name] = value
        return value
    raise AttributeError(f"module 'stochcable' has no attribute {name!r}")


__all__ = [
    *_LAZY,
    "__version__",
    "StochcableError",
    "InputError",
    "ConvergenceError",
    "SolverError",
    "PhysicsWarning",
    "ResolutionWarning",
]
