"""The sea: wave spectra, random-sea realizations (DSA/NSA by FFT), linear wave
kinematics and FFT time series.

``stochcable.sea.spectra`` and ``stochcable.sea.kinematics`` are light;
:func:`simulate_sea` (``stochcable.sea.realization``) is imported on first use so that
``import stochcable.sea.spectra`` does not plan FFTs or load the compiled kernel.
"""

__all__ = ["simulate_sea"]


def __getattr__(name: str):  # noqa: ANN202
    if name == "simulate_sea":
        from stochcable.sea.realization import simulate_sea

        return simulate_sea
    raise AttributeError(f"module 'stochcable.sea' has no attribute {name!r}")
