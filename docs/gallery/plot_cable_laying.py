"""
A cable being laid: transport speed, waves and a cross-current
==============================================================

The bundled example ``cable_laying`` (docs/travelling.md, "A laying example"): a power
cable paid out at 1 m/s from a vessel's chute to its touchdown 100 m down, in a JONSWAP
sea with the chute following the vessel and a 0.5 m/s cross-current.  The line's
``axial_speed`` adds the transport terms (gyroscopic and centripetal) and the axial drag
of the travel; the same cable at rest is drawn beside it.

Its two warnings are documented (:mod:`stochcable.examples`): the result's modes are
those of the line at rest, and the strumming screening finds a negligible lock-in.
"""

import warnings

import matplotlib.pyplot as plt
import numpy as np

import stochcable
from stochcable import plots
from stochcable.reference.travelling_cable import swing_up_speed_hu_jin

scene = stochcable.load_example("cable_laying")
at_rest = scene.model_dump(mode="json")
at_rest["lines"][0]["axial_speed"] = 0.0
with warnings.catch_warnings():
    warnings.simplefilter("ignore")  # the documented warnings, listed below
    laying = stochcable.analyze(scene)
    rest = stochcable.analyze(at_rest)
for message in laying.warnings:
    print("warning:", message[:110], "...")
for name, res in (("laying at 1 m/s", laying), ("at rest", rest)):
    lr = res.lines["cable"]
    print(
        f"{name}: touchdown {lr.end_a.mean:.0f} ± {lr.end_a.std:.0f} N, "
        f"chute {lr.end_b.mean:.0f} ± {lr.end_b.std:.0f} N"
    )

# %%
# The speed at which the cross-flow's lift would carry the cable's weight (Hu & Jin's
# eq. 38, with an assumed lift coefficient 0.6): the swing-up speed.
print(f"swing-up speed: {swing_up_speed_hu_jin(117.2, 1025.0, 0.1, 0.6, 0.5):.2f} m/s")

# %%
# Static shape and the chute's end-tension spectrum, laying against at rest.
plots.plot_statics(laying)
fig, ax = plt.subplots()
for name, res in (("laying at 1 m/s", laying), ("at rest", rest)):
    lr = res.lines["cable"]
    ax.plot(lr.omega, np.asarray(lr.end_tension_spectrum("end_b")), label=name)
ax.set_xlabel("ω [rad/s]")
ax.set_ylabel("chute tension spectrum [N²·s/rad]")
ax.legend()
plt.show()
