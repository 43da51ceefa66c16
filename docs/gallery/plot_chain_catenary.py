"""
Chain catenary moored to a moving fairlead
==========================================

The bundled example ``chain_catenary`` (the v1 scene of the design document): 850 m of
120 mm studless chain in 200 m of water, from an anchor to a fairlead 20 m deep whose
surge is a vessel's band-limited motion spectrum, in a Pierson–Moskowitz sea
(Hs 6 m, Tp 10 s) with a 0.5 m/s surface current.  It analyses without a warning.
"""

import matplotlib.pyplot as plt

import stochcable
from stochcable import plots

result = stochcable.analyze(stochcable.load_example("chain_catenary"))
print(f"warnings: {len(result.warnings)}")

# %%
# The static shape: the chain lies on the seabed from the anchor to the touchdown point.
plots.plot_statics(result)

# %%
# The spectra of the dynamic tension at the anchor (end_a) and the fairlead (end_b).
plots.plot_end_tension_spectra(result, "leg1")

# %%
# Static tension along the chain with the band mean ± 3σ of the dynamic tension.
plots.plot_tension_along_line(result, "leg1")

# %%
# The lowest natural modes about the static shape (with added mass).
plots.plot_mode_shapes(result, "leg1")

# %%
# The first 600 s of the time series synthesized from the same transfer functions.
plots.plot_timeseries(result)
plt.show()
