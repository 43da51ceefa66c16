"""
Disc buoy on one and three legs (foot–slug–second)
==================================================

The bundled examples ``tuah_1982_disc_buoy_single_leg`` and
``tuah_1982_disc_buoy_three_legs`` (Tuah 1982, §6.5 and §6.7): a disc buoy,
a rigid body, on slack cable legs in 100 ft of water.  The scenes are in feet, slugs
and pounds-force, and so are the plots' labels.

The examples warn on purpose (their descriptions in :mod:`stochcable.examples` say
why): the seed's three elements per leg are coarse near the surface, and the slack
legs' dynamic tension exceeds a third of their mean tension, so snap loads are likely
and the linear model is at its limit.
"""

import warnings

import matplotlib.pyplot as plt

import stochcable
from stochcable import plots

with warnings.catch_warnings():
    warnings.simplefilter("ignore")  # the documented warnings, listed below
    three = stochcable.analyze(stochcable.load_example("tuah_1982_disc_buoy_three_legs"))
    single = stochcable.analyze(stochcable.load_example("tuah_1982_disc_buoy_single_leg"))
for message in three.warnings:
    print("warning:", message[:110], "...")

# %%
# The three legs' static shapes, each measured from the buoy, with their touchdown.
plots.plot_statics(three)

# %%
# End tension spectra of the upwind leg: at the anchor (end_a) and at the buoy (end_b).
plots.plot_end_tension_spectra(three, "leg1")

# %%
# Tension along the upwind leg: mean − 3σ falls below zero (the snap warning).
plots.plot_tension_along_line(three, "leg1")

# %%
# Mode shapes of a downwind leg (out-of-plane modes move in y).
plots.plot_mode_shapes(three, "leg2", count=3)

# %%
# The single-leg buoy: its leg's tension spectra and a window of its time series.
plots.plot_end_tension_spectra(single, "leg")
plots.plot_timeseries(single, window=120.0)
plt.show()
