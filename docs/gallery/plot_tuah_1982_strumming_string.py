"""
Strumming of a string in a steady flow (Tuah 1982, Example 6)
=============================================================

The bundled example ``tuah_1982_strumming_string``: the horizontal string of Ramberg
and Griffin's experiment as Tuah (1982), §6.6 models it with a wake
oscillator (docs/strumming.md).  The screening gives, per mode near the shedding
frequency, the reduced velocity, whether the wake locks in and the cross-flow
amplitude; this string's first cross-flow mode is not locked in (ω_s/ω_n ≈ 1.11), so
the table reports the beat bound of its forced response, A/D 0.24 (0.0119 ft) against
the seed's 0.016 ft (docs/strumming.md says why).  The example is in SI units.
"""

import warnings

import matplotlib.pyplot as plt
import numpy as np

import stochcable

with warnings.catch_warnings():
    warnings.simplefilter("ignore")  # a string without sea: no wave excitation
    res = stochcable.analyze(stochcable.load_example("tuah_1982_strumming_string"))
line = res.lines["string"]
table = line.strumming
for m in table.modes:
    print(
        f"mode {m.index + 1}: ω_n {m.omega_n:.2f} rad/s, ω_s {m.omega_s:.2f} rad/s, "
        f"V_R {m.reduced_velocity:.2f}, locked {m.locked}, A/D {m.amplitude_over_d:.3f}"
    )

# %%
# The cross-flow amplitude of each screened mode along the string.
s = line.s_nodes
fig, ax = plt.subplots(figsize=(6, 3))
for m in table.modes:
    amp = np.linalg.norm(m.displacement, axis=1)
    ax.plot(s, amp, label=f"mode {m.index + 1} ({'locked' if m.locked else 'not locked'})")
ax.set(xlabel="arc length s [m]", ylabel="amplitude [m]")
ax.legend()
fig.tight_layout()
plt.show()
