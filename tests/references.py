"""Named reference values from the seeds and from closed forms, shared by the tests.

Each constant is named after its source.  Values copied from a paper are exactly as
printed; values computed here say how (and which test checks them).  Helpers owning
other test files may ask for additions.
"""

from __future__ import annotations

from types import MappingProxyType

# --------------------------------------------------------------------------------
# Bliet 1984: Bliet (1984), §7.3 "Linear cable model with the non-linear drag force":
# the guy of a guyed tower (SI units).  Printed data and static results.
# Note: the printed "net weight 494.98 N/m" is inconsistent with the printed tensions
# and angles (V_top - V_bot = w L needs w = 415 N/m = (48.7 - 6.3) kg/m x g, i.e. mass
# minus displaced mass, the "added mass" 6.3 kg/m being rho pi D^2/4 with Ca = 1).
BLIET_1984_GUY = MappingProxyType(
    {
        "top_tension": 1_332_000.0,  # T_top [N]
        "bottom_tension": 1_155_096.0,  # T_bot [N]
        "mass": 48.7,  # [kg/m]
        "added_mass": 6.3,  # [kg/m] (= displaced mass, rho pi D^2 / 4)
        "net_weight_printed": 494.98,  # [N/m], inconsistent (see above)
        "diameter": 0.0889,  # D_o [m]
        "ea": 1.30e9,  # [N]
        "length": 1036.32,  # [m] (3400 ft, §7.2; the table of §7.3 rounds to 1036 m)
        "depth": 426.70,  # vertical span [m] (1400 ft)
        "cd_normal": 1.2,
        "cd_tangential": 0.05,
        "angle_top_deg": 33.056,  # phi_top [deg]
        "angle_bottom_deg": 14.874,  # phi_bot [deg]
        "horizontal_span": 940.68,  # Delta x [m]
        "chord_angle_deg": 24.399,  # phi_av [deg]
    }
)

# Bliet 1984, Table 7-II: eigenfrequencies of the guy above [rad/s].
BLIET_1984_TABLE_7_II = (0.9011, 1.1949, 1.6086, 1.8228, 2.3115, 2.7527, 3.2335, 3.7059)

# --------------------------------------------------------------------------------
# Tuah 1982: Tuah (1982) §6.2 Example 2, static response of a suspended cable
# (ft, slug, s, lbf).  Two segments 500 ft + 1000 ft from (0, 0) to (1200, 500) ft with
# a 900 lb buoy at the junction.
TUAH_1982_EX2 = MappingProxyType(
    {
        "segment_lengths": (500.0, 1000.0),  # [ft]
        "span": (1200.0, 500.0),  # (horizontal, vertical) [ft]
        "area": 0.0218,  # A0 [ft^2]
        "youngs_modulus": 8.12e6,  # E [psf]
        "cable_density": 3.35,  # [slug/ft^3]
        "fluid_density": 2.0,  # [slug/ft^3]
        "buoy": 900.0,  # upward point load at the junction [lbf]
        "g": 32.174,  # [ft/s^2] (DESIGN.md)
        "elements": 6,
        "initial_straight_end": (1417.0, 500.0),  # the seed's initial configuration [ft]
    }
)

# The elastic two-segment catenary solution of TUAH_1982_EX2 computed by
# stochcable.line.catenary.catenary_multisegment (w = (3.35 - 2.0) * 0.0218 * 32.174 lbf/ft,
# EA = 177016 lbf), checked in tests/line/test_catenary.py by numerical quadrature of the
# cable equations and node equilibrium.  The FE statics must reproduce it.
TUAH_1982_EX2_ELASTIC_CATENARY = MappingProxyType(
    {
        "H": 359.3657987864305,  # [lbf]
        "V_a": 70.78658267196036,  # vertical force at (0, 0), upward on the line end [lbf]
        "V_junction_below": 544.2269926719604,  # end of segment 1 [lbf]
        "V_junction_above": -355.7730073280396,  # start of segment 2 (jump of -900) [lbf]
        "V_b": 591.1078126719605,  # [lbf]
        "tension_a": 366.271098537386,  # [lbf]
        "tension_b": 691.774691311585,  # [lbf]
        "junction": (383.1996737540527, 302.8070436682464),  # (x, z) [ft]
    }
)

# --------------------------------------------------------------------------------
# Tuah 1982: Tuah (1982) §6.5 Example 5, one-leg single point mooring (ft, slug, s, lbf).
TUAH_1982_EX5 = MappingProxyType(
    {
        "m0": 28.0,  # [ft^2] (Hurricane Carla record)
        "omega_p": 0.5,  # [rad/s]
        "n_frequencies": 200,
        "d_omega": 0.0245,  # [rad/s]
        "record_length": 256.0,  # [s]
        "dt": 0.25,  # [s]
        "wind_load": 100.0,  # [lbf]
        "buoy_position": (300.0, 2.5),  # [ft], as printed (frame not stated in the text)
        "linearization_tolerance": 0.01,
        "linearization_iterations": 8,
        "elements": (3, 8),
    }
)
