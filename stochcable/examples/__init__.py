"""Example scenes shipped with stochcable (package data, so an installed service can serve them).

Each ``<name>.json`` is a scene document (DESIGN.md "Scene and result documents") whose
``title`` states its source and assumptions in short; the details:

- ``chain_catenary``: the v1 contract example of DESIGN.md, without the (load-free)
  attachment: 120 mm studless chain, 288 kg/m, hydrodynamic diameter 0.216 m
  (1.8 x nominal), EA 1.2326e9 N, 850 m from an anchor at (-800, 0, -200) m to a
  fairlead at (0, 0, -20) m moving in surge.  The fairlead surge is a vessel's motion
  spectrum, band-limited as a vessel's is (its surge RAO falls off above the wave
  frequencies it follows): DESIGN.md's Pierson–Moskowitz spectrum Hs 2 m, Tp 10 s
  times a cos² taper from 1 at 0.9 rad/s to 0 at 1.5 rad/s, tabulated every 0.05
  rad/s (σ 0.47 m).  DESIGN.md's untapered spectrum has an ω⁻⁵ tail whose inertia
  loads keep the tension spectrum large at the top of any grid (a ResolutionWarning).
- ``tuah_1982_suspended_cable``: Tuah (1982) §6.2 Example 2 in ft, slug, s,
  lbf (g = 32.174 ft/s², fluid 2.0 slug/ft³ as the seed).  Cable A0 = 0.0218 ft²
  (D = sqrt(4 A0/π) = 0.1666 ft), E = 8.12e6 psf (EA = 177 016 lbf), density
  3.35 slug/ft³ (mass 0.07303 slug/ft), 900 lb buoy at the junction.  Tuah's span
  (0, 0) -> (1200, 500) ft is placed at z = -1500 and -1000 ft in an assumed 2000 ft
  depth; drag and added-mass coefficients are assumed (statics do not need them).
- ``taut_wire``: illustrative (not from a seed).  52 mm spiral strand; unstretched
  length 100 m between (-100, 0, -50) (on the seabed) and (0, 0, -40): the elastic
  catenary gives T about 1.30 MN (strain 0.5 %), sag/span 1.08e-3.
- ``inclined_guy``: Bliet (1984) §7.3.  The thesis's span 940.68 m and height
  426.70 m are used for the ends; the net weight is (48.7 kg/m - ρπD²/4) g = 415.2 N/m
  (the thesis's printed 494.98 N/m is inconsistent with its own tensions and angles);
  CDt is taken on πD.  Sea state assumed (the thesis excites the top end only).
- ``tuah_1982_single_leg``: Tuah 1982, §6.5 Example 5, sea PM m0 = 28 ft²,
  ωp = 0.5 rad/s, 200 frequencies of 0.0245 rad/s, 3 elements, DSA record 256 s at
  0.25 s, drag linearization tolerance 0.01 (all as the seed).  The cable and depth are
  in Tuah's Figure 6.5-1 only, not in its text: assumed the §6.2 cable, 100 ft
  depth, anchor 300 ft from the buoy, and L = 339 ft so that the horizontal tension
  balances Tuah's 100 lb wind load.  The disc buoy is not a body here: it is
  end_b, at its assumed 2.5 ft draft, heaving with the sea surface (heave RAO 1, which
  the seed reports for the disc).
- ``tuah_1982_disc_buoy_single_leg``: Tuah 1982, §6.5 Example 5 with the disc buoy as a
  body, planar (surge, heave, pitch), ft-slug-lbf, sea and frequencies as
  ``tuah_1982_single_leg``, Tuah's static wind load of 100 lb along +x.  The
  figures' numbers are not in the seed text; assumed: depth 100 ft, the §6.2 cable
  (EA 177 016 lbf, 0.07303 slug/ft, D 0.1666 ft), L 339 ft, 3 elements, anchor at
  (-300, 0, -100) ft, the line attached at the disc bottom (0, 0, -2.5) ft.  Disc
  radius 5 ft, draft 2.5 ft (∇ = 196.35 ft³), uniform (CoG = CoB = -1.25 ft below the
  waterline reference point), mass = (ρ g ∇ - 150 lbf)/g (the cable's vertical pull,
  the statics settle the rest), inertia of a uniform cylinder.  Hudspeth's (1980)
  coefficients are not in Tuah (1982): constant added mass (Tuah's §5.2 also assumes
  it constant) surge 0.5 ρ∇, heave 4/3 ρa³, pitch 8/45 ρa⁵ (half the deeply submerged
  disc values); radiation damping 10 % of critical in heave and pitch, none in surge;
  hydrostatics ρ g A_wp in heave, ρ g (I_wp + ∇ z_B) - m g z_G in pitch; excitation
  the Froude–Krylov force of the cylinder (side and bottom pressure of the incident
  wave, finite-depth profile) for heading 0 only, in an inline table over
  0 … 6 rad/s ("hold" outside); body drag Cd 1.0 on 10 ft × 2.5 ft in surge at the
  CoB.  Solver "direct".
- ``tuah_1982_disc_buoy_three_legs``: Tuah 1982, §6.7 Example 7 ("cable, fluid and wave
  data are the same as for Example 5"): the same disc (6 DOF) with three identical
  legs at 120° (leg1 toward -x, upwind), anchors 305 ft from the centre at -100 ft,
  each leg attached at the disc rim (5 ft out, 2.5 ft down) facing its anchor (rim
  attachments give the yaw restoring), mass (ρ g ∇ - 450 lbf)/g, wind 100 lb along +x
  kept from Example 5.
- ``tuah_1982_strumming_string``: Tuah 1982, §6.6 Example 6, the strumming experiment of
  Ramberg et al. (1980), converted to SI (ft 0.3048 m, slug 14.5939 kg, lbf
  4.44822 N): D 0.05 ft = 0.01524 m, span 14.37 ft = 4.379976 m, density
  7.78 slug/ft³ = 4009.65 kg/m³ (mass 0.731419 kg/m), E 8 113 100 psf = 3.88457e8 Pa
  (EA 70 860.3 N), initial stress 33 100 psf = 1.58484 MPa (T0 289.10 N: unstretched
  length span/(1 + σ0/E) = 4.362179 m), flow 0.695 ft/s = 0.211836 m/s across the
  string (heading 90°, the string along x), water 2.0 slug/ft³ = 1030.76 kg/m³,
  ν 1.13e-5 ft²/s = 1.04980e-6 m²/s, C_L0 0.2, 4 elements (Tuah's).  Assumed:
  St 0.18 (Tuah's ω_s = 15.73 rad/s back-computed: 2π·0.18·0.695/0.05 = 15.72),
  C_a 1, C_d 1.2, the string 0.5 m deep in 1 m of water.  No sea: the example is the
  strumming screening (docs/strumming.md).
- ``cable_laying``: a cable being laid (docs/travelling.md, "A laying example"):
  a 100 mm power cable, 20 kg/m (submerged weight 117.2 N/m), EA 5e8 N, C_d 1.2,
  C_t 0.02, C_a 1, 155 m paid out at 1 m/s (``axial_speed`` −1: from the vessel's
  chute, end_b at (110, 0, −5) m, to its touchdown, end_a on the seabed 100 m down,
  held there as a fixed point: the cable already laid is not modelled), 30 elements.
  JONSWAP sea Hs 2 m, Tp 8 s, γ 3.3, heading 0; the chute follows the vessel with an
  assumed surge and heave RAO (in phase with the waves, 1 at long waves, falling to 0
  at 3 rad/s); a 0.5 m/s current across the laying plane (heading 90°), hence the
  vector form of the drag linearization.  Critical speed
  √(T/m) = 20.2 m/s.
"""

from __future__ import annotations

from importlib import resources

from stochcable.errors import InputError
from stochcable.scene.model import Scene, load_scene

__all__ = ["list_examples", "load_example", "DOCUMENTED_WARNINGS"]

#: The warnings an example raises on purpose, by example name: a phrase the warning's
#: message contains, and why the example keeps it.  Every other example analyses
#: without a warning (tests/test_examples.py checks both).
DOCUMENTED_WARNINGS: dict[str, dict[str, str]] = {
    "tuah_1982_suspended_cable": {
        "has no excitation": "a statics example (Tuah 1982, §6.2 Example 2): no sea, no "
        "end motion, so the dynamic response is zero by design",
    },
    "inclined_guy": {
        "wave-velocity σ varies": "the thesis's (Bliet 1984, §7.3) 40 elements are kept so "
        "the example matches its source; the warning says what a finer mesh near the "
        "surface would change",
        "near-undamped resonance": "the guy's second mode lies in the sea's band with "
        "drag damping only: the warning is the physics of a taut guy in waves",
        "does not resolve mode 2": "that mode's half-power bandwidth (ζ = 0.67 %) is "
        "narrow against the example's 300 frequencies: the warning gives the error on "
        "its peak (≈ ±4.6 %) and the count that brings it under 1 %",
    },
    "taut_wire": {
        "error of the end-tension σ": "the example's 20 elements are kept (its numbers "
        "are the goldens'): the wave-load rule's bound is 1.4 % on a line wholly in the "
        "wave zone, the measured error 0.2 % (mesh convergence, 20 → 160 elements)",
    },
    "tuah_1982_single_leg": {
        "error of the end-tension σ": "Tuah's 3 elements are kept: the element rules "
        "ask for more (the warning names the count)",
        "wave-velocity σ varies": "Tuah's 3 elements (Tuah 1982, §6.5 Example 5) are "
        "kept so the example reproduces Tuah's model",
        "snap loads likely": "Tuah's slack 100 lb leg in a 28 ft² sea: σ exceeds a "
        "third of the mean tension; the example shows where the linear model stops",
        "of the line's sag": "the heaving end moves as much as a tenth of the slack leg's "
        "sag: the linearization about the static shape is at its limit",
    },
    "tuah_1982_disc_buoy_single_leg": {
        "error of the end-tension σ": "Tuah's 3 elements are kept: the element rules "
        "ask for more (the warning names the count)",
        "wave-velocity σ varies": "Tuah's 3 elements are kept (Tuah 1982, §6.5)",
        "snap loads likely": "Tuah's slack leg: σ exceeds a third of the mean tension",
        "of the line's sag": "the buoy's motion is large against the slack leg's sag",
    },
    "tuah_1982_strumming_string": {
        "has no excitation": "a strumming example (Tuah 1982, §6.6 Example 6): no sea, no "
        "end motion; its result is the strumming table of the line in the current",
    },
    "cable_laying": {
        "travels: these are its modes at rest": "the result lists the natural modes of "
        "the line at rest; a travelling line's complex modes and stability are those "
        "of 'stochcable modes' (docs/travelling.md)",
        "strumming lock-in predicted": "the cross-current locks in a high mode of the "
        "cable (A/D ≈ 0.01, drag x1.07): the screening's finding, negligible here",
        "of the node motions is up to": "the residuals would raise the suspended middle "
        "nodes' motions beyond their range (x variance up to 42.8-fold): those stay "
        "linear, the others and the end tensions keep the residuals",
    },
    "tuah_1982_disc_buoy_three_legs": {
        "error of the end-tension σ": "Tuah's 3 elements are kept: the element rules "
        "ask for more (the warning names the count)",
        "wave-velocity σ varies": "Tuah's 3 elements are kept (Tuah 1982, §6.7)",
        "snap loads likely": "Tuah's slack legs: σ exceeds a third of the mean tension",
        "of the line's sag": "the buoy's motion is large against the legs' sag",
    },
}


def _files():
    return resources.files(__name__)


def list_examples() -> list[str]:
    """Names of the example scenes (without the ``.json`` suffix), sorted."""
    return sorted(p.name[: -len(".json")] for p in _files().iterdir() if p.name.endswith(".json"))


def load_example(name: str) -> Scene:
    """Load and validate an example scene by name.

    Parameters
    ----------
    name : str
        One of :func:`list_examples` (a trailing ``.json`` is accepted).

    Returns
    -------
    Scene
        The validated scene.

    Raises
    ------
    InputError
        For an unknown name, listing the known ones.
    """
    known = list_examples()
    key = str(name)
    if key.endswith(".json"):
        key = key[: -len(".json")]
    if key not in known:
        raise InputError("example", name, "-", f"is not a known example; known: {', '.join(known)}")
    return load_scene(_files().joinpath(f"{key}.json").read_text(encoding="utf-8"))
