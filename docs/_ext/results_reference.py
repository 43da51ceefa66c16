"""The results reference of the manual: every key of the result document with its unit.

The keys are read off result documents the code produces (analyses of bundled
examples at build time, :func:`example_documents`); their meanings and units are the
table :data:`KEYS` below.  :func:`undocumented_keys` lists the keys of a document that
the table lacks, so the build (and ``tests/test_docs.py``) fails when the document
grows a key nobody described.

Paths name the document's parts with placeholders for the names a scene chooses:
``<line>`` a line name, ``<body>`` a body name, ``<end>`` ``end_a`` or ``end_b``,
``<dof>`` a body DOF (surge, sway, heave, roll, pitch, yaw), ``<channel>`` an
end-motion channel ``"<line>.<end>.<dof>"``, ``[]`` an item of a list.  Units are
templates in the scene's consistent unit system: ``{L}`` length, ``{M}`` mass, ``{F}``
force (SI: m, kg, N; foot–slug–second: ft, slug, lbf).
"""

from __future__ import annotations

import warnings
from collections.abc import Iterable, Mapping
from typing import Any

from scene_reference import escape_bars

from stochcable.scene.residual_kinds import RESIDUAL_KINDS

__all__ = [
    "KEYS",
    "OPAQUE",
    "STATS",
    "document_paths",
    "example_documents",
    "undocumented_keys",
    "results_reference_rst",
]

#: The statistics of one Gaussian response (``ResponseStats.as_dict``), by key:
#: (unit as a power of the response's unit ``{U}``, meaning).
STATS: dict[str, tuple[str, str]] = {
    "mean": ("{U}", "Static (mean) value."),
    "std": ("{U}", "Standard deviation σ = √m0 of the dynamic part."),
    "tz": ("s", "Mean zero-upcrossing period 2π√(m0/m2) (0 for a zero process)."),
    "mpm_3h": (
        "{U}",
        "mean + most probable maximum of the dynamic part in 3 hours, σ√(2 ln(10800/Tz)).",
    ),
    "significant": ("{U}", "Significant value 2σ."),
    "m0": ("{U}²", "Spectral moment ∫S dω (trapezoid on the analysis grid)."),
    "m1": ("{U}²·rad/s", "Spectral moment ∫ωS dω."),
    "m2": ("{U}²·(rad/s)²", "Spectral moment ∫ω²S dω."),
    "m4": ("{U}²·(rad/s)⁴", "Spectral moment ∫ω⁴S dω."),
    "bandwidth": ("-", "Spectral bandwidth √(1 − m2²/(m0·m4))."),
    "mpm": (
        "{U}",
        "mean + most probable maximum over the scene's ``analysis.timeseries.duration``.",
    ),
    "expected_max": ("{U}", "mean + expected maximum over the same duration."),
}

_STATIC_LINE = {
    "statics": ("", "Static equilibrium of every line (and body)."),
    "statics.lines.<line>.<end>.tension": (
        "{F}",
        "Static end tension: magnitude of the force on the support.",
    ),
    "statics.lines.<line>.<end>.force": (
        "{F}",
        "Force (x, y, z) the line exerts on the support, global frame.",
    ),
    "statics.lines.<line>.touchdown": (
        "{L}",
        "Unstretched arc length from end_a where the line leaves the seabed; null without seabed "
        "contact.",
    ),
    "statics.lines.<line>.nodes": ("{L}", "Static node positions (x, y, z), shape (n_nodes, 3)."),
    "statics.lines.<line>.s": ("{L}", "Unstretched arc length of the nodes from end_a."),
    "statics.lines.<line>.tension": ("{F}", "Static effective tension per element."),
    "statics.lines.<line>.iterations": (
        "-",
        "Newton or relaxation iterations (0 for the closed-form catenary).",
    ),
    "statics.lines.<line>.residual": (
        "-",
        "Final largest nodal residual force over the reference force.",
    ),
    "statics.lines.<line>.method": (
        "",
        '``"fe"`` (finite elements) or ``"catenary"`` (closed form).',
    ),
    "statics.bodies.<body>.position": ("{L}", "Reference point of the body at equilibrium."),
    "statics.bodies.<body>.rotation": (
        "rad",
        "Rotation vector from the input orientation (planar: only θ_y).",
    ),
    "statics.bodies.<body>.line_forces.<line>": (
        "{F}",
        'Force each attached line exerts on the body (``"<line>.<end>"`` when both ends are on '
        "it).",
    ),
    "statics.bodies.<body>.iterations": (
        "-",
        "Newton iterations of the body equilibrium (0 for a prescribed body).",
    ),
    "statics.bodies.<body>.residual": (
        "-",
        "Final largest generalized force over the reference force.",
    ),
    "statics.bodies.<body>.dofs": (
        "",
        "DOF names of ``stiffness``: the six, or surge, heave, pitch when planar.",
    ),
    "statics.bodies.<body>.stiffness": (
        "{F}/{L}, {F}, {F}·{L}/rad",
        "Quasi-static stiffness −dQ/dq at equilibrium over ``dofs``, shape (d, d).",
    ),
    "statics.bodies.<body>.prescribed": ("", "True for a vessel (pose imposed, not solved)."),
}

_MODES_LIN = {
    "modes.omega": ("rad/s", "Natural frequencies of the first line (with added mass)."),
    "modes.lines.<line>": (
        "rad/s",
        "Natural frequencies of each line about its static shape, those up to 2.5·ω_max and at "
        "least 10.",
    ),
    "linearization.converged": ("", "Whether the drag linearization converged on every line."),
    "linearization.iterations": ("-", "Largest number of iterations over the lines."),
    "linearization.relative_change": (
        "-",
        "Largest relative change of the drag coefficients at the last iteration.",
    ),
    "linearization.lines.<line>.method": (
        "",
        'Iteration used (``"seed"``: Tuah (1982), §5.2, or an accelerated variant).',
    ),
    "linearization.lines.<line>.converged": (
        "",
        "Whether the line's drag linearization converged.",
    ),
    "linearization.lines.<line>.iterations": ("-", "Iterations used."),
    "linearization.lines.<line>.relative_change": (
        "-",
        "Relative change of the drag coefficients at the last iteration.",
    ),
    "linearization.lines.<line>.tolerance": (
        "-",
        "Tolerance asked (``analysis.linearization.tolerance``).",
    ),
    "linearization.lines.<line>.history": ("-", "Relative change at each iteration."),
}


def residual_keys() -> dict[str, tuple[str, str]]:
    """The document keys ``lines.<line>.<name>`` of every registered residual kind
    (:mod:`stochcable.scene.residual_kinds`): (unit, meaning)."""
    out: dict[str, tuple[str, str]] = {}
    for name, kind in RESIDUAL_KINDS.items():
        key = f"lines.<line>.{name}"
        out[key] = ("", kind.document)
        out[f"{key}.computed"] = (
            "-",
            f"False where the line is outside the closed form's scope ({kind.scope}).",
        )
        out[f"{key}.reason"] = ("-", "Why not computed; empty when computed.")
        out[f"{key}.order"] = ("-", kind.order)
        out[f"{key}.panels"] = ("-", kind.panels)
        out[f"{key}.<end>"] = ("", "The residual at the end.")
        out[f"{key}.<end>.variance"] = (
            "{F}²",
            "Variance the residual adds to the end tension (in band, superharmonics and "
            "difference frequencies).",
        )
        out[f"{key}.<end>.in_band"] = ("{F}²", "Its part on the analysis band [ω_min, ω_max].")
        out[f"{key}.<end>.std_linear"] = ("{F}", "σ of the linear model.")
        out[f"{key}.<end>.std"] = (
            "{F}",
            "√(σ_linear² + variance): the end-tension σ with the residual.",
        )
        out[f"{key}.<end>.ratio"] = ("-", "std / std_linear.")
    return out


_LINES = {
    "lines.<line>.<end>.tension": (
        "",
        "Statistics of the end tension (table of statistics below; U = force).  With "
        + " or ".join(f"``analysis.linearization.{k}``" for k in RESIDUAL_KINDS)
        + ": with the residuals, their spectra's moments added to the linear spectrum's (the "
        "superharmonics above the band included), the linear model's alone in "
        "``lines.<line>.linear``; their spectral density in "
        "``lines.<line>.corrected_spectra`` (``lines.<line>.spectra`` stays the linear "
        "model's).",
    ),
    "lines.<line>.linear": (
        "",
        "Only where a residual of the linear model was computed: the linear model's own "
        "end statistics, beside the corrected ones of ``lines.<line>.<end>``.",
    ),
    "lines.<line>.linear.<end>": ("", "The end."),
    "lines.<line>.linear.<end>.tension": (
        "",
        "Statistics of the linear model's end tension (table of statistics below).",
    ),
    "lines.<line>.corrected_spectra": (
        "",
        "Only where a residual of the linear model was computed: the end tensions' "
        "spectral density with the residuals' spectra "
        "(:mod:`stochcable.dynamics.residuals.corrected_spectrum`; "
        "``LineResult.end_tension_density``), whose area is the corrected σ² of "
        "``lines.<line>.<end>.tension`` (to round-off); spectral fatigue and the "
        "load-case sets' end statistics and end damage read it.",
    ),
    "lines.<line>.corrected_spectra.<end>": ("", "The end."),
    "lines.<line>.corrected_spectra.<end>.omega": (
        "rad/s",
        "The analysis frequencies and the residual lines outside them (the "
        "superharmonics up to the drag residual's highest order times ω_max).",
    ),
    "lines.<line>.corrected_spectra.<end>.tension": (
        "{F}²·s/rad",
        "One-sided spectral density of the end tension with the residuals.",
    ),
    "lines.<line>.<end>.force_std": ("{F}", "σ of the x, y, z force on the support."),
    "lines.<line>.tension.s": (
        "{L}",
        "Unstretched arc length of the element midpoints from end_a.",
    ),
    "lines.<line>.tension.std": (
        "{F}",
        "σ of the dynamic effective tension per element (with the residuals of the linear "
        "model where ``std_linear`` is present).",
    ),
    "lines.<line>.tension.std_linear": (
        "{F}",
        "σ of the dynamic effective tension per element of the linear model alone; present "
        "where the residuals were computed along the line "
        "(:mod:`stochcable.dynamics.residuals.along_line`: the end kinds' load "
        "cross-spectra through each element's tension, at up to 7 stations, interpolated "
        "in arc length between them).",
    ),
    "lines.<line>.tension.mean": ("{F}", "Static effective tension per element."),
    "lines.<line>.motion.s": ("{L}", "Unstretched arc length of the nodes from end_a."),
    "lines.<line>.motion.std": (
        "{L}",
        "σ of the x, y, z node displacements, shape (n_nodes, 3) (with the residuals of the "
        "linear model where ``std_linear`` is present).",
    ),
    "lines.<line>.motion.std_linear": (
        "{L}",
        "σ of the x, y, z node displacements of the linear model alone; present where the "
        "residuals were computed in the motions "
        "(:mod:`stochcable.dynamics.residuals.along_line_motion`: at up to 7 station nodes, "
        "interpolated in arc length between them).",
    ),
    "lines.<line>.spectra.omega": ("rad/s", "Analysis frequencies."),
    "lines.<line>.spectra.<end>.tension": ("{F}²·s/rad", "One-sided spectrum of the end tension."),
    "lines.<line>.channels": (
        "",
        'Independent input channels: ``"sea"``, ``"end_b.surge"``, ``"<line>.<end>.<dof>"``…',
    ),
    "lines.<line>.linearization": (
        "",
        "The line's drag-linearization record (as ``linearization.lines.<line>``).",
    ),
    "lines.<line>.modes.omega": ("rad/s", "Natural frequencies listed for the line."),
    "lines.<line>.modes.kept": ("-", "Modes kept by the Foss solve; null for the direct solve."),
    **residual_keys(),
    "lines.<line>.strumming": (
        "",
        "Strumming screening of the line in the current (present only with a current "
        "and unsuppressed segments); see :doc:`../strumming`.",
    ),
    "lines.<line>.strumming.modes": (
        "",
        "Screened modes: in the cross-flow band 3 ≤ V_R ≤ 16, nearest the shedding frequency.",
    ),
    "lines.<line>.strumming.modes[].mode": ("-", "Mode index (0 = lowest)."),
    "lines.<line>.strumming.modes[].omega_n": ("rad/s", "Natural frequency."),
    "lines.<line>.strumming.modes[].omega_s": ("rad/s", "Shedding frequency 2π·St·U_n/D."),
    "lines.<line>.strumming.modes[].omega": (
        "rad/s",
        "Response frequency: lock-in frequency, or ω_s when unlocked.",
    ),
    "lines.<line>.strumming.modes[].reduced_velocity": ("-", "V_R = 2π U_n/(ω_n D)."),
    "lines.<line>.strumming.modes[].locked": ("-", "Whether the wake oscillator locks in."),
    "lines.<line>.strumming.modes[].resonant": (
        "-",
        "Unlocked but ω_s inside the mode's half-power band: the free wakes drive a resonance.",
    ),
    "lines.<line>.strumming.modes[].amplitude_over_d": (
        "-",
        "Cross-flow amplitude over D: steady lock-in amplitude; resonant: the forced "
        "amplitude capped by Griffin et al. (1975); otherwise twice the forced amplitude "
        "(the beat bound).",
    ),
    "lines.<line>.strumming.modes[].damping_ratio": (
        "-",
        "Modal damping ratio ξ: structural + viscous (Tuah 1982, eq. 3.2.b.8).",
    ),
    "lines.<line>.strumming.modes[].reduced_damping": ("-", "Skop–Griffin S_G = 2π St² k_s."),
    "lines.<line>.strumming.modes[].tension_range": (
        "{F}",
        "Peak-to-peak dynamic tension of the mode per element (a narrow-band fatigue component).",
    ),
    "lines.<line>.strumming.modes[].cycle_rate": ("1/s", "Its cycles per second ω/2π."),
    "lines.<line>.strumming.governing": (
        "-",
        "Index in ``modes`` of the strumming mode that amplifies the drag (null: none).",
    ),
    "lines.<line>.strumming.cd_normal": (
        "-",
        "Normal drag coefficient per element, amplified where the line strums.",
    ),
    "lines.<line>.strumming.omega_s": ("rad/s", "Shedding frequency per element."),
    "lines.<line>.indicators": (
        "",
        "Quality indicators of the linear model (null when not computed); see :doc:`warnings`.",
    ),
    "lines.<line>.indicators.borgman_ratio.min": (
        "-",
        "Smallest Borgman variance ratio Var(B v)/Var(½ρC_dD|v|v) over the elements (0.849 "
        "without current).",
    ),
    "lines.<line>.indicators.borgman_ratio.max": (
        "-",
        "Largest Borgman variance ratio over the elements.",
    ),
    "lines.<line>.indicators.borgman_ratio.elements": ("-", "Borgman variance ratio per element."),
    "lines.<line>.indicators.drag_inertia_ratio.min": (
        "-",
        "Smallest ratio of σ of the linearized drag to σ of the Morison inertia force.",
    ),
    "lines.<line>.indicators.drag_inertia_ratio.max": (
        "-",
        "Largest such ratio (null when infinite: no fluid acceleration).",
    ),
    "lines.<line>.indicators.drag_inertia_ratio.elements": ("-", "Drag/inertia ratio per element."),
    "lines.<line>.indicators.snap.risk": (
        "",
        "True when mean − 3σ of the tension is below zero somewhere.",
    ),
    "lines.<line>.indicators.snap.margin": (
        "-",
        "Smallest (T_mean − 3σ_T)/|T_mean| over elements and ends.",
    ),
    "lines.<line>.indicators.resonances": (
        "",
        "Modes in the excitation band with modal damping ratio below 1 %.",
    ),
    "lines.<line>.indicators.resonances[].mode": ("-", "Mode number (1-based)."),
    "lines.<line>.indicators.resonances[].omega": ("rad/s", "Its natural frequency."),
    "lines.<line>.indicators.resonances[].damping_ratio": ("-", "Its modal damping ratio ζ."),
    "lines.<line>.indicators.motion.std_max": (
        "{L}",
        "Largest node motion σ (magnitude of the x, y, z σ).",
    ),
    "lines.<line>.indicators.motion.sag": (
        "{L}",
        "Largest distance of the static shape from the chord of the ends.",
    ),
    "lines.<line>.indicators.motion.to_sag": ("-", "``std_max / sag``."),
    "lines.<line>.indicators.motion.to_diameter": ("-", "``std_max`` over the largest diameter."),
    "lines.<line>.indicators.flags": (
        "",
        'Raised flags: ``"snap"``, ``"resonance"``, ``"large_motion"``, ``"second_order"``.',
    ),
    "lines.<line>.indicators.second_order": (
        "",
        "Second-order stretching tension T₂ = κ·½∫(∂u⊥/∂s)² ds of the linear response, "
        "a Gaussian quadratic form (:mod:`stochcable.dynamics.residuals.second_order`).",
    ),
    "lines.<line>.indicators.second_order.mean": ("N", "Mean of T₂: a shift of the mean tension."),
    "lines.<line>.indicators.second_order.std": (
        "N",
        "σ of T₂ (uncorrelated with the linear tension).",
    ),
    "lines.<line>.indicators.second_order.ratio": (
        "-",
        "σ of T₂ over the largest linear element tension σ (null: no linear tension σ).",
    ),
    "lines.<line>.indicators.second_order.lambda2": (
        "-",
        "Irvine's λ*² of the static shape (Bliet 1984, eq. 4.3); the sag relieves T₂ by "
        "1/(1 + λ*²/12) (null: no positive tension).",
    ),
    "lines.<line>.indicators.second_order.std_factor": (
        "-",
        "√(1 + ratio²): σ of linear + second-order tension over the linear σ.",
    ),
}

_BODIES = {
    "bodies.<body>.prescribed": ("", "True for a vessel whose motion is its RAO (not solved for)."),
    "bodies.<body>.dofs": ("", "DOF names in order."),
    "bodies.<body>.motion.<dof>": (
        "",
        "Statistics of each DOF (table of statistics below; U = length or rad); the mean is the "
        "static pose.",
    ),
    "bodies.<body>.motion.<dof>.std_deg": ("deg", "σ of a rotation in degrees."),
    "bodies.<body>.motion.<dof>.std_linear": (
        "U",
        "A free body whose motion carries its lines' residuals (docs/BODIES.md): σ of the "
        "linear model; the other statistics are then the corrected ones.",
    ),
    "bodies.<body>.corrected_spectra": (
        "",
        "Only where the motion carries the residuals (``std_linear`` given): each DOF's "
        "spectral density with the residuals' spectra "
        "(:mod:`stochcable.dynamics.residuals.corrected_spectrum`; "
        "``BodyResult.motion_density``), whose area is the corrected σ² of "
        "``bodies.<body>.motion.<dof>`` (to round-off; ``bodies.<body>.spectra`` stays "
        "the linear model's).",
    ),
    "bodies.<body>.corrected_spectra.<dof>": ("", "The DOF."),
    "bodies.<body>.corrected_spectra.<dof>.omega": (
        "rad/s",
        "The analysis frequencies and the residual lines outside them.",
    ),
    "bodies.<body>.corrected_spectra.<dof>.motion": (
        "{L}²·s/rad or rad²·s/rad",
        "One-sided spectral density of the DOF's motion with the residuals.",
    ),
    "bodies.<body>.spectra.omega": ("rad/s", "Analysis frequencies."),
    "bodies.<body>.spectra.<dof>": (
        "{L}²·s/rad or rad²·s/rad",
        "One-sided motion spectrum of each DOF.",
    ),
    "bodies.<body>.channels": ("", "Input channels of the body's coupled group."),
    "bodies.<body>.drag": ("", "Linearized drag at the drag point (null without one)."),
    "bodies.<body>.drag.sigma": (
        "{L}/s",
        "σ of the relative velocity at the drag point along x, y, z.",
    ),
    "bodies.<body>.drag.coefficient": ("{F}·s/{L}", "Linear drag coefficient per direction."),
    "bodies.<body>.modes": (
        "",
        "Natural modes of the coupled group the body belongs to (null for a vessel).",
    ),
    "bodies.<body>.modes.omega": (
        "rad/s",
        "Natural frequencies of the coupled group, lowest first.",
    ),
    "bodies.<body>.modes.body_fraction": (
        "-",
        "Share of each mode's kinetic energy in the body DOFs.",
    ),
    "bodies.<body>.modes.omega_ref": (
        "rad/s",
        "Frequency at which the added mass was frozen for the modes.",
    ),
    "bodies.<body>.modes.asymmetry": (
        "-",
        "max|K − Kᵀ|/max|K| of the coupled stiffness (its symmetric part is used).",
    ),
}

_REST = {
    "timing": ("s", "Wall-clock seconds per stage."),
    "timing.statics_s": ("s", "Statics."),
    "timing.model_s": ("s", "Finite-element models."),
    "timing.modes_s": ("s", "Natural modes."),
    "timing.linearization_s": ("s", "Drag linearization."),
    "timing.solve_s": ("s", "Final solve."),
    "timing.outputs_s": ("s", "Statistics and document outputs."),
    "timing.timeseries_s": ("s", "Time-series synthesis."),
    "timing.total_s": ("s", "The whole analysis."),
    "warnings": ("", "Messages of the warnings raised during the analysis (see :doc:`warnings`)."),
    "units.system": (
        "",
        '``"SI"``, ``"foot-slug-second"`` or ``"consistent"``: the unit system, read off '
        "``environment.g``.",
    ),
    "units.length": ("", "Length label of every number of the document."),
    "units.mass": ("", "Mass label."),
    "units.force": ("", "Force label."),
    "units.time": ("", "Time label."),
    "timeseries.method": ("", '``"dsa"`` or ``"nsa"``: how the sea realization was drawn.'),
    "timeseries.seed": ("-", "Root random seed."),
    "timeseries.dt": ("s", "Time step."),
    "timeseries.samples": ("-", "Length of the whole realization."),
    "timeseries.window": (
        "-",
        'Samples in the document (the first 2048, or all with ``timeseries="full"``).',
    ),
    "timeseries.time": ("s", "Sample times."),
    "timeseries.elevation": ("{L}", "Wave elevation at the origin (null without a sea)."),
    "timeseries.end_motion.<channel>": ("{L}", "Prescribed end motion of each end-motion channel."),
    "timeseries.lines.<line>.<end>.tension": (
        "{F}",
        "Total end tension, mean + dynamic; with the residuals of the linear model where "
        "they were applied: an independent Gaussian component with their spectral "
        "density, so the record's σ and spectrum are the corrected ones.",
    ),
    "timeseries.lines.<line>.<end>.tension_linear": (
        "{F}",
        "The linear model's end tension (without the residuals' component), beside "
        "``tension`` where that carries it, when asked for (``timeseries_linear``: "
        "``--timeseries-linear``, ``?timeseries_linear=true``).",
    ),
    "timeseries.bodies.<body>.motion.<dof>": (
        "{L} or rad",
        "Body motion, static pose + dynamic part.",
    ),
    "fidelity": (
        "",
        "Present when ``analysis.fidelity`` is set: the settings adaptive fidelity chose.",
    ),
    "fidelity.target_error": ("-", "Target relative error of the response σ."),
    "fidelity.omega.min": ("rad/s", "Lowest frequency chosen."),
    "fidelity.omega.max": ("rad/s", "Highest frequency chosen."),
    "fidelity.omega.count": ("-", "Points of the base linear grid."),
    "fidelity.omega.values_count": (
        "-",
        "Points of the grid applied (base grid plus refinements at lightly damped modes).",
    ),
    "fidelity.segments.<line>": (
        "-, {L}, -",
        "Per line, the new segments as (source segment index, length, elements).",
    ),
    "fidelity.solver": ("", "Solver chosen."),
    "fidelity.modes": ("", 'Modes kept (``"auto"`` or a number).'),
    "fidelity.tolerance": ("-", "Linearization tolerance chosen."),
    "fidelity.choices[].setting": ("", "The setting chosen (a path in the scene)."),
    "fidelity.choices[].value": ("", "Its value."),
    "fidelity.choices[].reason": ("", "Why."),
    "fidelity.choices[].error": ("-", "Estimated relative error of σ the choice leaves."),
    "fidelity.error_estimate": (
        "-",
        "Estimated relative error per part of the discretization (band, grid, elements, "
        "modes, linearization: the fixed point's tolerance), their sum ``discretization``, "
        "``linearization_model`` (the model's own error against the nonlinear time "
        "domain: with the residuals computed, the square of the σ change they make plus "
        "the one-sided bed's share on a grounded line; otherwise calibrated per class "
        "of line: ``stochcable.fidelity.model_error``) and ``total``.",
    ),
    "fidelity.model_error_basis": (
        "",
        "Which line and term give ``linearization_model``: the residuals' σ change, or "
        "the source of its calibration.",
    ),
    "fidelity.cost": ("-", "Elements, frequencies and their product of the plan applied."),
    "fidelity.tail_bounded": ("", "Whether the response variance above the band could be bounded."),
    "fidelity.omega_response": (
        "rad/s",
        "ω₂ = √(m2/m0) of the pilot analysis' response spectra (largest).",
    ),
    "fidelity.pilot": ("", "The pilot analysis the plan is built on (grid and sizes)."),
    "fidelity.grid_resolved": (
        "",
        "Present when a limit was hit: whether the grid resolves every lightly damped mode.",
    ),
    "fidelity.limits": (
        "",
        "Present when a limit was hit: the scene model's limits the plan reached.",
    ),
}

#: Every key path of the result document: (unit template, meaning).
KEYS: dict[str, tuple[str, str]] = {**_STATIC_LINE, **_MODES_LIN, **_LINES, **_BODIES, **_REST}

#: Paths whose value is described as a whole (not descended into).
OPAQUE = frozenset(
    {
        "timing",
        "lines.<line>.linearization",
        "fidelity.error_estimate",
        "fidelity.cost",
        "fidelity.pilot",
        "fidelity.segments.<line>",
    }
)

# Where a document key is a name the scene chooses: parent path -> placeholder.
_NAMED = {
    "statics.lines": "<line>",
    "statics.bodies": "<body>",
    "statics.bodies.<body>.line_forces": "<line>",
    "modes.lines": "<line>",
    "linearization.lines": "<line>",
    "lines": "<line>",
    "bodies": "<body>",
    "bodies.<body>.motion": "<dof>",
    "timeseries.end_motion": "<channel>",
    "timeseries.lines": "<line>",
    "timeseries.bodies": "<body>",
    "timeseries.bodies.<body>.motion": "<dof>",
    "fidelity.segments": "<line>",
}
_DOFS = frozenset({"surge", "sway", "heave", "roll", "pitch", "yaw"})
_STATS_PARENTS = (
    "lines.<line>.<end>.tension",
    "lines.<line>.linear.<end>.tension",
    "bodies.<body>.motion.<dof>",
)


def _child(parent: str, key: str) -> str:
    if parent in _NAMED:
        name = _NAMED[parent]
    elif key in ("end_a", "end_b"):
        name = "<end>"
    elif parent in ("bodies.<body>.spectra", "bodies.<body>.corrected_spectra") and key in _DOFS:
        name = "<dof>"
    else:
        name = key
    return f"{parent}.{name}" if parent else name


def document_paths(doc: Any, parent: str = "") -> set[str]:
    """Every key path of a result document, names replaced by their placeholders."""
    out: set[str] = set()
    if isinstance(doc, Mapping):
        for key, value in doc.items():
            path = _child(parent, str(key))
            out.add(path)
            if path not in OPAQUE:
                out |= document_paths(value, path)
    elif isinstance(doc, list):
        for item in doc:
            if isinstance(item, Mapping):
                out |= document_paths(item, f"{parent}[]")
    return out


def _is_stat(path: str) -> bool:
    head, _, key = path.rpartition(".")
    return head in _STATS_PARENTS and key in STATS


def undocumented_keys(paths: Iterable[str]) -> list[str]:
    """The paths :data:`KEYS` (and the statistics table) do not describe."""
    return sorted(
        p
        for p in paths
        if p not in KEYS
        and not _is_stat(p)
        # a container whose children are described
        and not any(k.startswith(p + ".") or k.startswith(p + "[]") for k in KEYS)
    )


def example_documents() -> dict[str, dict[str, Any]]:
    """Result documents of bundled examples that hold every part of the document:
    a line with end motion and time series, a body, and adaptive fidelity."""
    import stochcable

    docs = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the examples' warnings belong to their pages
        for name in ("chain_catenary", "tuah_1982_disc_buoy_single_leg"):
            docs[name] = stochcable.analyze(stochcable.load_example(name)).to_document(
                timeseries_linear=True
            )
        scene = stochcable.load_example("taut_wire").model_dump()
        scene["analysis"]["fidelity"] = {"target_error": 0.05}
        for name in RESIDUAL_KINDS:  # every residual kind in the reference
            scene["analysis"]["linearization"][name] = True
        result = stochcable.analyze(stochcable.Scene.model_validate(scene))
        docs["taut_wire with analysis.fidelity"] = result.to_document()
    return docs


def _unit(template: str, system: Mapping[str, str], response: str = "") -> str:
    return template.format(L=system["L"], M=system["M"], F=system["F"], U=response)


_SI = {"L": "m", "M": "kg", "F": "N"}
_FSS = {"L": "ft", "M": "slug", "F": "lbf"}


def _table(rows: list[tuple[str, str, str, str]]) -> list[str]:
    out = [
        ".. list-table::",
        "   :header-rows: 1",
        "   :widths: 34 14 14 38",
        "",
        "   * - Key",
        "     - SI",
        "     - foot–slug–second",
        "     - Meaning",
    ]
    for key, si, fss, meaning in rows:
        out += [
            f"   * - ``{key}``",
            f"     - {si or '—'}",
            f"     - {fss or '—'}",
            f"     - {escape_bars(meaning)}",
        ]
    return out + [""]


def results_reference_rst(paths: Iterable[str]) -> str:
    """The reStructuredText of the key table (every :data:`KEYS` entry; those seen in no
    example document marked) and of the statistics table."""
    seen = set(paths)
    rows = []
    for key, (unit, meaning) in KEYS.items():
        under_seen = any(key.startswith(o + ".") and o in seen for o in OPAQUE)
        note = "" if key in seen or under_seen else " (not in the example documents)"
        rows.append((key, _unit(unit, _SI), _unit(unit, _FSS), meaning + note))
    stats = [
        (
            f"….{key}",
            _unit(unit, _SI, "U"),
            _unit(unit, _FSS, "U"),
            meaning,
        )
        for key, (unit, meaning) in STATS.items()
    ]
    lines = ["Keys", "----", ""]
    lines += _table(rows)
    lines += [
        "Statistics",
        "----------",
        "",
        "``lines.<line>.<end>.tension`` (U = force: N or lbf) and "
        "``bodies.<body>.motion.<dof>`` (U = length or rad) hold these statistics of a "
        "Gaussian response (static mean plus a zero-mean dynamic part):",
        "",
    ]
    lines += _table(stats)
    return "\n".join(lines)
