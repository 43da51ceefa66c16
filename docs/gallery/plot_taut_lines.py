"""
Taut lines: a spiral strand and an inclined guy
===============================================

Two bundled examples of taut lines: ``taut_wire``, a 52 mm spiral strand at about
1.3 MN, and ``inclined_guy``, the guy of Bliet (1984), §7.3.  A taut line's
tension response is quasi-static over much of the sea's band, its first modes are
high, and its touchdown is absent.

``inclined_guy`` warns on purpose (its description in :mod:`stochcable.examples` says
why): it keeps the thesis's 40 elements, coarse near the surface, and its second mode
lies in the sea's band with drag damping only.  ``taut_wire`` keeps its 20 elements,
whose discretization error the mesh check estimates above 1 % (measured: 0.2 %).
"""

import warnings

import matplotlib.pyplot as plt

import stochcable
from stochcable import plots

with warnings.catch_warnings():
    warnings.simplefilter("ignore")  # the documented warnings, listed below
    wire = stochcable.analyze(stochcable.load_example("taut_wire"))
    guy = stochcable.analyze(stochcable.load_example("inclined_guy"))
for message in (*wire.warnings, *guy.warnings):
    print("warning:", message[:110], "...")

# %%
# The static shapes (the sag of the strand is a thousandth of its span).
plots.plot_statics(wire)
plots.plot_statics(guy)

# %%
# End tension spectra and the tension along each line.
plots.plot_end_tension_spectra(wire, "wire")
plots.plot_tension_along_line(wire, "wire")
plots.plot_end_tension_spectra(guy, "guy")
plots.plot_tension_along_line(guy, "guy")

# %%
# The guy's lowest modes: mode 2 is the lightly damped one in the sea's band.
plots.plot_mode_shapes(guy, "guy", count=3)
plt.show()
