"""
Seed examples: a suspended cable and a buoy on one leg (foot–slug–second)
=========================================================================

Two bundled examples of Tuah (1982) in feet, slugs and pounds-force:
``tuah_1982_suspended_cable`` (§6.2 Example 2, statics: a cable with a 900 lb buoy
between two points) and ``tuah_1982_single_leg`` (§6.5 Example 5, a leg whose top
heaves with the sea surface, with the seed's DSA time series).

Both warn on purpose (their descriptions in :mod:`stochcable.examples` say why): the
suspended cable has no excitation (a statics example), and the single leg keeps the
seed's three elements and is slack enough for snap loads.
"""

import warnings

import matplotlib.pyplot as plt

import stochcable
from stochcable import plots

with warnings.catch_warnings():
    warnings.simplefilter("ignore")  # the documented warnings, listed below
    cable = stochcable.analyze(stochcable.load_example("tuah_1982_suspended_cable"))
    leg = stochcable.analyze(stochcable.load_example("tuah_1982_single_leg"))
for message in cable.warnings + leg.warnings:
    print("warning:", message[:110], "...")

# %%
# The suspended cable: its static shape, kinked at the buoy, and its modes.
plots.plot_statics(cable)
plots.plot_mode_shapes(cable, "cable", count=3)

# %%
# The single leg: static shape, end tension spectra, tension along the leg.
plots.plot_statics(leg)
plots.plot_end_tension_spectra(leg, "leg")
plots.plot_tension_along_line(leg, "leg")

# %%
# A window of the seed's DSA record: the sea surface and the end tensions.
plots.plot_timeseries(leg, window=120.0)
plt.show()
