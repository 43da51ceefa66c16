"""The warnings page of the manual: every warning stochcable raises, with its threshold,
what it means and what to do.

:data:`WARNINGS` describes each warning and names the functions that raise it
(``module:function``) and the constants that set its threshold (``module:NAME``, read
at build time, so the page shows the values in force).  :func:`warning_sites` finds
every ``warn(...)`` / ``warnings.warn(...)`` call in the source; the build and
``tests/test_docs.py`` fail when a call site is described by no entry.
"""

from __future__ import annotations

import ast
import importlib
import math
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

from scene_reference import escape_bars

__all__ = [
    "WarningEntry",
    "WARNINGS",
    "warning_sites",
    "undocumented_sites",
    "warnings_reference_rst",
]


@dataclass(frozen=True)
class WarningEntry:
    """One warning: where it is raised, its threshold, its meaning and the remedy."""

    title: str
    category: str
    sites: tuple[str, ...]
    threshold: str
    meaning: str
    action: str
    constants: tuple[str, ...] = ()


WARNINGS: tuple[WarningEntry, ...] = (
    WarningEntry(
        "Too few elements for the end-tension σ",
        "ResolutionWarning",
        ("stochcable.fidelity.mesh_engine:__call__",),
        "A segment's estimated discretization error of the end-tension σ above "
        "MESH_ERROR_LIMIT: the larger of (kh)²/24, k = ω₂√⟨1/c²⟩ (string wave at the "
        "end tension's mean frequency ω₂ = √(m₂/m₀)), and (h/suspended length)² on a "
        "grounded segment (touchdown inside an element), and (kh)²/12, k the sea's "
        "wavenumber, on a segment wholly in the wave zone (nodal wave kinematics). "
        "Explicit ``elements`` only; "
        "a segment without ``elements`` gets a count that meets the limit, and warns "
        "only when that count hits the scene model's limit — or, on an engine "
        "(``stochcable.build_engine``) or a load-case set, for a sea state other than "
        "the one the count was chosen for, when that sea needs more (every solve and "
        "every case is checked)",
        "The segment's elements are too long for the string waves the end tension "
        "carries (or for its touchdown): σ is off by up to the estimate. The estimate "
        "is a bound: measured 0.4–0.5× it at 20 elements on the chain example and the "
        "accuracy page's deep catenary, 0.15× on the taut wire (which warns at its 20 "
        "elements: 1.4 % estimated, 0.2 % measured), less on finer meshes.",
        "Use the count the message names, or leave ``elements`` out so the analysis "
        "chooses it; keep a coarse count only to reproduce a source's model (the Tuah "
        "examples keep the seed's 3 elements).",
        ("stochcable.fidelity.mesh_check:MESH_ERROR_LIMIT",),
    ),
    WarningEntry(
        "Response spectrum cut by the top of the grid",
        "ResolutionWarning",
        ("stochcable.dynamics.outputs.resolution:tail_check",),
        "S(ω_max)·ω_max > TAIL_FRACTION · m0 of an end-tension spectrum, and an input "
        "goes on above ω_max (quiet when every input, a band-limited motion or a "
        "spectrum table, ends at the grid's top: nothing excites the line above it)",
        "The end-tension spectrum is still large at ``analysis.omega.max``: the variance "
        "beyond the grid is lost, so σ and every maximum are underestimated. Typical "
        "cause: an end-motion spectrum with an ω⁻⁵ tail, whose inertia loads give a "
        "tension spectrum that decays only like ω⁻¹.",
        "The message says where the input ends. Raise ``analysis.omega.max`` to there, "
        "or until the warning goes; give a fairlead motion as a "
        "vessel RAO over the sea (``motion.rao``) or as a band-limited spectrum instead "
        "of an unbounded one.",
        ("stochcable.dynamics.outputs.resolution:TAIL_FRACTION",),
    ),
    WarningEntry(
        "Natural frequency not resolved by the grid",
        "ResolutionWarning",
        ("stochcable.dynamics.outputs.resolution:resolution_check",),
        "a mode inside the grid whose nearest grid point is farther than the local "
        "spacing, or whose half-power bandwidth b = 2ζω is so narrow against the "
        "spacing Δω that the trapezoid rule may be off by more than "
        "RESONANCE_PEAK_ERROR on its peak (coth(πb/(2Δω)) − 1, Poisson summation for a "
        "Lorentzian: 1 % at Δω = 0.59 b)",
        "A resonance peak may fall between frequencies: the response near it, and σ, "
        "can be wrong by the error the message gives (4.5 % on the inclined guy's "
        "lightly damped mode 2 at 300 frequencies), or badly wrong for a mode the grid "
        "misses.",
        "Use the ``analysis.omega.count`` the message gives (or refine the grid around "
        "the mode); a mode without damping is resolved by no grid: add drag, seabed or "
        "structural damping.",
        ("stochcable.dynamics.outputs.resolution:RESONANCE_PEAK_ERROR",),
    ),
    WarningEntry(
        "Elements too long for the wave kinematics near the surface",
        "ResolutionWarning",
        ("stochcable.dynamics.outputs.resolution:surface_resolution_check",),
        "σ of the wave velocity varies by more than SURFACE_SIGMA_RATIO along an "
        "element whose larger end σ is at least SURFACE_MATTERS_FRACTION of the line's "
        "largest",
        "The drag linearization takes one drag coefficient per element (Tuah 1982, eq. "
        "5.2.2) while the wave kinematics decay like e^{kz}; on such an element the "
        "response carries an error of several per cent.",
        "Use the number of elements the message gives on that segment (the fix aims at a "
        "ratio SURFACE_TARGET_RATIO), or let ``analysis.fidelity`` choose the mesh.",
        (
            "stochcable.dynamics.outputs.resolution:SURFACE_SIGMA_RATIO",
            "stochcable.dynamics.outputs.resolution:SURFACE_MATTERS_FRACTION",
            "stochcable.dynamics.outputs.resolution:SURFACE_TARGET_RATIO",
        ),
    ),
    WarningEntry(
        "Snap loads likely (indicator ``snap``)",
        "PhysicsWarning",
        ("stochcable.dynamics.outputs.indicators:_snap",),
        "mean − SNAP_SIGMAS·σ of the tension below zero at an element or end",
        "The linear model predicts that the line goes slack: snap loads, which a "
        "frequency-domain model cannot represent, are likely. The result's "
        "``indicators.snap`` holds the margin.",
        "Run the nonlinear time-domain reference (:mod:`stochcable.reference.cable`) or "
        "increase the pretension.",
        ("stochcable.dynamics.outputs.indicators:SNAP_SIGMAS",),
    ),
    WarningEntry(
        "Lightly damped resonance in the excitation band (indicator ``resonance``)",
        "PhysicsWarning",
        ("stochcable.dynamics.outputs.indicators:_resonances",),
        "a mode where some input spectrum exceeds BAND_FRACTION of its peak, with modal "
        "damping ratio below RESONANCE_DAMPING_RATIO",
        "The response at that mode is set by damping the model may not represent "
        "(listed in ``indicators.resonances``).",
        "Check the drag coefficients; add structural damping "
        "(``analysis.structural_damping``) or seabed damping where physical.",
        (
            "stochcable.dynamics.outputs.indicators:BAND_FRACTION",
            "stochcable.dynamics.outputs.indicators:RESONANCE_DAMPING_RATIO",
        ),
    ),
    WarningEntry(
        "Motion large against the sag (indicator ``large_motion``)",
        "PhysicsWarning",
        ("stochcable.dynamics.outputs.indicators:_large_motion",),
        "a node motion σ above MOTION_SAG_FRACTION of the line's sag, on a line whose sag "
        "governs its stiffness (Irvine's λ² of at least MOTION_SAG_LAMBDA2)",
        "The model is linear about the static shape; the geometric stiffness of a "
        "sagging line depends on its sag at first order, so such motions change it by "
        "more than a linear model tolerates.  A taut line (small λ²: its stiffness is "
        "elastic) does not warn, however far its fairlead carries it.",
        "Check with the nonlinear time-domain reference (:mod:`stochcable.reference.cable`).",
        (
            "stochcable.dynamics.outputs.indicators:MOTION_SAG_FRACTION",
            "stochcable.dynamics.outputs.indicators:MOTION_SAG_LAMBDA2",
        ),
    ),
    WarningEntry(
        "Drag residual large (``analysis.linearization.drag_residual``)",
        "PhysicsWarning",
        ("stochcable.dynamics.residuals.drag_residual:_warn_large",),
        "the end-tension σ with the drag residual beyond RESIDUAL_WARN_RATIO times the "
        "linear σ (or below its inverse)",
        "The quadratic drag is far from its Gaussian linear fit: the first-order residual "
        "correction, exact for small corrections, is larger than any checked against the "
        "time domain (up to +18 %: the taut wire and the inclined guy, within the "
        "time domain's 95 % interval).",
        "Check with the nonlinear time-domain reference (:mod:`stochcable.reference.cable`).",
        ("stochcable.dynamics.residuals.drag_residual:RESIDUAL_WARN_RATIO",),
    ),
    WarningEntry(
        "Residuals out of their range (not applied)",
        "PhysicsWarning",
        ("stochcable.dynamics.residuals.corrected:residuals_in_range",),
        "a computed residual's end-tension variance beyond RESIDUAL_VARIANCE_LIMIT times "
        "the linear model's variance at that end",
        "The first-order closed forms of the residuals are out of their depth, typically "
        "on a line going slack (the geometric residual of a chain 2 m short of its "
        "vertical limit, 8·10⁵×, where the time domain snaps).  No residual is applied "
        "on that line: its "
        "statistics and spectra are the linear model's (no ``linear`` block), and every "
        "residual record says ``not applied: variance ratio X above its range Y``.  The "
        "bundled examples reach 0.41 (drag).",
        "Check with the nonlinear time-domain reference "
        "(:mod:`stochcable.reference.cable`); or make the line tauter (pretension), or "
        "its mesh finer.",
        ("stochcable.dynamics.residuals.corrected:RESIDUAL_VARIANCE_LIMIT",),
    ),
    WarningEntry(
        "Node motions out of the residuals' range (those left linear)",
        "PhysicsWarning",
        ("stochcable.dynamics.residuals.along_line_motion:_beyond_range",),
        "a node motion component whose residual variance is beyond "
        "RESIDUAL_VARIANCE_LIMIT times its linear variance (said where one of them moves "
        "at least 1 % of the line's largest σ; nearly at rest, silently)",
        "As at the ends, the first-order closed forms are out of their depth there: those "
        "node motions are the linear model's (no residual), node by node; the line's other "
        "motions keep their residuals.  The message names the nodes per axis, the largest "
        "ratio and the limit.  The cable-laying example reaches 42.8 in the x motion of "
        "its middle nodes.",
        "Check with the nonlinear time-domain reference "
        "(:mod:`stochcable.reference.cable`); or make the line tauter (pretension), or "
        "its mesh finer.",
        ("stochcable.dynamics.residuals.corrected:RESIDUAL_VARIANCE_LIMIT",),
    ),
    WarningEntry(
        "How a load-case set applies the residuals",
        "PhysicsWarning",
        ("stochcable.cases.run:_warn_interpolated", "stochcable.client_batches:submit_batch"),
        "the set's scene sets ``analysis.linearization.drag_residual`` or "
        "``geometric_residual`` (the default) and some cases' corrections are "
        "interpolated, not computed (``run_cases``'s default; a set that computes every "
        "case, as the service's batches do, does not warn; the Python client's "
        "``submit_batch`` issues a batch's planning warnings)",
        "Every case's end statistics and end damage are those of the corrected spectrum "
        "(the linear spectrum plus the residuals', "
        ":mod:`stochcable.dynamics.residuals.corrected_spectrum`); the along-line "
        "damage comes from the element tensions' corrected spectra where the analysis "
        "computes the residuals along the line, lines on free bodies included (their "
        "residuals through the coupled response, as ``analyze()``'s).  ``run_cases`` "
        "computes the residuals on the cases its adaptive anchors choose (per heading "
        "the shortest, middle and longest period, then the middle period of every "
        "interval where the corrections interpolated in the period miss the computed "
        "ones; in every computed period the smallest, middle and largest Hs, then the "
        "middle Hs of every interval where the corrections interpolated in Hs miss — "
        "by more than ``residual_tolerance``, default 2e-3) and interpolates their "
        "corrections on the others (:mod:`stochcable.cases.residual_anchors`: the "
        "measured error is in the benchmarks' load-case page); with ``residual_span`` "
        "and ``residual_tolerance=None`` on fixed anchors (up to 4.2 % on σ on the taut "
        "wire at Tp 10 s).  The warning says how many cases computed them.",
        "Keep the defaults; ``residual_tolerance=None`` computes every case.",
    ),
    WarningEntry(
        "Second-order stretching tension large (indicator ``second_order``)",
        "PhysicsWarning",
        ("stochcable.dynamics.residuals.second_order:with_second_order",),
        "σ of the second-order stretching tension above SECOND_ORDER_WARN_RATIO of the "
        "line's largest linear tension σ",
        "Transverse motion lengthens a line to second order, ½∫(∂u⊥/∂s)² ds; a taut line "
        "takes it up as tension that the linear model drops, so the linear tension σ is "
        "low by ``indicators.second_order.std_factor`` and the mean by "
        "``indicators.second_order.mean``.",
        "Use the corrected moments in ``indicators.second_order`` as an estimate; for a "
        "design value check with the nonlinear time-domain reference "
        "(:mod:`stochcable.reference.cable`).",
        ("stochcable.dynamics.residuals.second_order:SECOND_ORDER_WARN_RATIO",),
    ),
    WarningEntry(
        "Drag linearization did not converge",
        "PhysicsWarning",
        ("stochcable.dynamics.groups.group_fixed_point:linearize_coupled",),
        "relative change of the drag σ above ``analysis.linearization.tolerance`` after "
        "``max_iterations``",
        "The result is flagged unconverged (``linearization.converged`` false); its "
        "numbers are those of the last iteration.",
        "Increase ``analysis.linearization.max_iterations``, or lower "
        "``relaxation`` for an oscillating iteration.",
    ),
    WarningEntry(
        "Line without excitation",
        "PhysicsWarning",
        ("stochcable.dynamics.groups.analysis:_solve_line",),
        "no sea and no end motion on a line not attached to a free body",
        "The line's dynamic response is zero.",
        "Add a ``sea`` or an end ``motion``.",
    ),
    WarningEntry(
        "Body without lines or sea",
        "PhysicsWarning",
        ("stochcable.dynamics.groups.analysis:_solve_lonely",),
        "a free body with no line and no sea",
        "Its motion is zero.",
        "Add a ``sea`` or attach lines.",
    ),
    WarningEntry(
        "Large static rotation of a body",
        "PhysicsWarning",
        ("stochcable.dynamics.groups.model:_static_rotation_check",),
        "static rotation above STATIC_ROTATION_LIMIT",
        "The dynamics use the body's mass, inertia, hydrodynamic coefficients, "
        "hydrostatics, excitation and drag point at the input orientation (only the line "
        "attachment arms follow the rotation): they are off by about the sine of the "
        "angle.",
        "Give the body's data at its static orientation (rotate them and the attachment "
        "points) and re-run.",
        ("stochcable.dynamics.groups.model:STATIC_ROTATION_LIMIT",),
    ),
    WarningEntry(
        "Foss decomposition failed: direct modal solve instead",
        "DefectivePencilWarning (a PhysicsWarning)",
        (
            "stochcable.dynamics.solve.line_solve:_foss_solver",
            "stochcable.dynamics.model.modal_solvers:solve_modal",
        ),
        "the state-space pencil is defective (repeated eigenvalues without a full set "
        "of eigenvectors)",
        "The Foss decoupling does not exist for these matrices; the answer is computed "
        "by the direct solve in modal coordinates and is still right, only slower.",
        'Nothing, or ``analysis.solver = "direct"`` to skip the attempt.',
    ),
    WarningEntry(
        "Adaptive fidelity could not meet its target",
        "PhysicsWarning",
        ("stochcable.analysis:_with_plan",),
        "the response tail above the pilot's band is unbounded, the linear model's own "
        "error against the nonlinear time domain (calibrated, "
        "``stochcable.fidelity.model_error``) exceeds ``analysis.fidelity.target_error``, "
        "or the plan reached a limit of the scene model before the target",
        "The settings chosen are the best within the limits; the message gives the "
        "estimated σ error (discretization and model) and whether the target is met.",
        "Band-limit an end-motion spectrum (or give it as a vessel RAO), use a larger "
        "``target_error``, add damping to lightly damped modes, or check the design "
        "value against a nonlinear time-domain analysis.",
    ),
    WarningEntry(
        "Sea spectrum above the Nyquist frequency",
        "ResolutionWarning",
        ("stochcable.sea.realization:_nyquist_check",),
        "more than NYQUIST_LOSS_TOLERANCE of m0 above π/Δt",
        "A time-series realization with step Δt does not simulate that part of the "
        "spectrum: its variance is too small.",
        "Use the time step the message gives, or a spectrum with a decaying tail.",
        ("stochcable.sea.realization:NYQUIST_LOSS_TOLERANCE",),
    ),
    WarningEntry(
        "Residuals above the time series' Nyquist frequency",
        "ResolutionWarning",
        ("stochcable.dynamics.timeseries.residual_series:_nyquist_check",),
        "more than NYQUIST_SHARE of a line end's residual variance above π/dt",
        "The end-tension time series carry the residuals' Gaussian component up to "
        "π/dt only: the residuals' superharmonics (up to three times "
        "``analysis.omega.max``) above it are left out, and the record's σ is below "
        "the corrected σ of the statistics.",
        "Use the time step the message gives.",
        ("stochcable.dynamics.timeseries.residual_series:NYQUIST_SHARE",),
    ),
    WarningEntry(
        "Undamped seabed contact under-resolved by the nonlinear reference",
        "ResolutionWarning",
        ("stochcable.reference.cable_checks:check_seabed_contact",),
        "nodes resting on a seabed without contact damping ring on the contact spring "
        "at ω_c = √(k/m) with (ω_c Δt)²/12 above PERIOD_ERROR_TOLERANCE",
        "The time-domain reference's average-acceleration scheme does not dissipate the "
        "ringing, which can dominate the tension record (1.5–2.8× the σ on the chain "
        "example at Δt 0.05 s).",
        "Give ``environment.seabed.damping`` (MoorDyn's cBot) or the ``dt`` the message gives.",
        ("stochcable.reference.cable:PERIOD_ERROR_TOLERANCE",),
    ),
    WarningEntry(
        "Time step of the nonlinear reference too coarse",
        "ResolutionWarning",
        ("stochcable.reference.cable:_time_step",),
        "Newmark period error (ωΔt)²/12 above PERIOD_ERROR_TOLERANCE at the highest "
        "excitation frequency",
        "The time-domain reference misrepresents the highest frequencies it is driven at.",
        "Use the ``dt`` the message gives.",
        ("stochcable.reference.cable:PERIOD_ERROR_TOLERANCE",),
    ),
    WarningEntry(
        "Nonlinear reference not stationary",
        "ResolutionWarning",
        ("stochcable.reference.cable:_check_stationary",),
        "the end-tension σ over windows after the ramp varies by more than NONSTATIONARY_RATIO",
        "An under-resolved oscillation pumped by the time stepping (typically at "
        "slack–taut snaps), not the response.",
        "Re-run with the ``dt`` the message gives, or a quarter of the present step.",
        ("stochcable.reference.cable:NONSTATIONARY_RATIO",),
    ),
    WarningEntry(
        "Line modes of a scene with bodies (``stochcable modes``)",
        "PhysicsWarning",
        ("stochcable.cli.modes:run",),
        "the scene has bodies",
        "``stochcable modes`` lists each line's modes with its ends held at their static "
        "positions, not the coupled modes of lines and bodies.",
        "Read the coupled modes from ``stochcable analyze`` under ``bodies.<name>.modes``.",
    ),
    WarningEntry(
        "Real modes of a travelling line",
        "PhysicsWarning",
        ("stochcable.line.modes:natural_modes",),
        "the model's line has ``axial_speed`` ≠ 0 (``lines[i].axial_speed``)",
        "The real modes K φ = ω² M φ leave out the transport terms (the gyroscopic "
        "matrix and the centripetal stiffness): they are the line's modes at rest.",
        "Use ``stochcable modes`` (which lists the complex modes of a travelling line) "
        "or ``stochcable.line.transport.modes.complex_modes``. See :doc:`../travelling`.",
    ),
    WarningEntry(
        "Drag residual not computed on a Hu & Jin drag line",
        "PhysicsWarning",
        ("stochcable.dynamics.residuals.drag_form_guard:guarded",),
        '``lines[i].drag_form`` is ``"hu_jin"`` and the drag residual is on',
        "The drag residual expands the cross-flow drag |v|v only; the Hu & Jin form "
        "|V|V_n is not expanded, so the line's residual record is not computed (its "
        "reason says why) and its end-tension σ is the linear model's.",
        'Use ``drag_form`` ``"cross_flow"`` for a residual-corrected σ, or read the '
        "linear σ. See :doc:`../travelling`.",
    ),
    WarningEntry(
        "Coupled modes of a travelling line on a body",
        "PhysicsWarning",
        ("stochcable.line.transport.matrices:check_travelling_lines",),
        "a line with ``axial_speed`` ≠ 0 has an end attached to a body",
        "The coupled modes of lines and bodies (``bodies.<name>.modes``) solve the "
        "symmetric problem with the line's centripetal stiffness K + K_c but without "
        "its gyroscopic matrix G; the coupled response (the line's direct solve) has "
        "both.",
        "Read the line's complex modes with its ends held from ``stochcable modes``. "
        "See :doc:`../travelling`.",
    ),
    WarningEntry(
        "Strumming lock-in (or resonance) predicted",
        "PhysicsWarning",
        ("stochcable.dynamics.model.strumming:with_strumming",),
        "a mode whose reduced velocity V_R = 2πU_n/(ω_n D) is inside the cross-flow band "
        "3 ≤ V_R ≤ 16 (DNV-RP-C205 ch. 9) and for which the wake-oscillator harmonic "
        "balance has a locked-in solution, or whose shedding frequency is inside its "
        "half-power band, ω_s within 2ξω_n of ω_n (resonance with the free wakes)",
        "The line vibrates across the current at the mode's frequency with the amplitude "
        "A/D the message gives (the result's ``lines.<line>.strumming`` table); the "
        "normal drag coefficient is amplified (Vandiver 1983) in the drag linearization "
        "of every sea state, and the mode's tension range and cycle rate add a "
        "high-frequency fatigue component. See :doc:`../strumming`.",
        "Fit strakes or fairings on the segments concerned "
        "(``segments[i].strumming.suppression``), or move the mode out of the band "
        "(pretension, diameter); check the amplitude with a time-domain VIV analysis.",
    ),
    WarningEntry(
        "Strumming screening stops below the lock-in range",
        "ResolutionWarning",
        ("stochcable.dynamics.model.strumming:strumming_inputs",),
        "the 3-D model's modes, computed up to MAX_MODES, stay below 2πU/(3D), the "
        "highest natural frequency the current can lock in (reduced velocity 3)",
        "Modes above the last one computed are not screened for strumming: a lock-in of "
        "a high mode of a thin, fast-flowed line may be missed.",
        "Screen the line alone with fewer elements, or check its high modes separately.",
        ("stochcable.dynamics.model.strumming:MAX_MODES",),
    ),
    WarningEntry(
        "Compiled kernel unavailable or not cached",
        "UserWarning",
        ("stochcable.compiled:jit_cached", "stochcable.sea.realization:_compiled_kernel"),
        "numba cannot compile or cache a kernel (the sea coefficients, the strumming "
        "lock-in start grid)",
        "Results are the same; the NumPy sea kernel is slower, or the kernel is compiled "
        "again in each process (about 1 s at its first use).",
        "Set ``NUMBA_CACHE_DIR`` to a writable directory, or ``STOCHCABLE_NUMBA=0`` to skip numba.",
    ),
    WarningEntry(
        "MoorDyn file: parts read with a loss",
        "PhysicsWarning",
        (
            "stochcable.io.moordyn_read:read_moordyn",
            "stochcable.io.moordyn_read:_structural_beta",
            "stochcable.io.moordyn_read:_warn_ignored",
            "stochcable.io.moordyn_parts:_type_columns",
        ),
        "a MoorDyn file (docs/manual/moordyn.md) with options other than WtrDpth, rho, "
        "g, kBot and cBot; non-zero EI, CaAx or Cl; lines whose BA/−ζ give different "
        "β = BA/EA; sections other than line types, bodies, rods, points, lines, "
        "options and outputs; a free point joined to no line; or LINE TYPES columns "
        "named in v1's order",
        "The scene holds what it can of the file: the options MoorDyn uses for its own "
        "time stepping and initial conditions are dropped, bending stiffness, axial added "
        "mass and VIV lift have no counterpart, and the scene's one stiffness-proportional "
        "damping β takes the smallest of the lines'.",
        "Nothing, when the options listed are numerics; for a bending-stiff line "
        "(umbilical, riser) check that tension dominates; give "
        "``analysis.structural_damping.beta`` yourself if the lines' damping differs.",
    ),
    WarningEntry(
        "MoorDyn file written with a loss",
        "PhysicsWarning",
        (
            "stochcable.io.moordyn_write:write_moordyn",
            "stochcable.io.moordyn_write:_body_rows",
            "stochcable.io.moordyn_write:_joint_point",
            "stochcable.io.moordyn_pieces:line_pieces",
        ),
        "a scene written with write_moordyn that has a prescribed motion, a current, "
        "mass-proportional structural damping, an attachment at a line end, or added "
        "mass without buoyancy",
        "MoorDyn takes motions and currents from its driver and its own files; the file "
        "holds the mooring only.",
        "Drive the Coupled points from the program that runs MoorDyn.",
    ),
)


def _module_name(root: Path, path: Path) -> str:
    parts = list(path.relative_to(root).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def _is_warn(call: ast.Call) -> bool:
    f = call.func
    if isinstance(f, ast.Name):
        return f.id == "warn"
    return (
        isinstance(f, ast.Attribute)
        and f.attr == "warn"
        and isinstance(f.value, ast.Name)
        and f.value.id == "warnings"
    )


def warning_sites(root: Path, packages: Iterable[str] = ("stochcable", "service")) -> set[str]:
    """``module:function`` of every ``warn(...)`` / ``warnings.warn(...)`` call in the
    packages under ``root`` (the helper ``stochcable.errors:warn`` itself excluded)."""
    sites: set[str] = set()

    def visit(node: ast.AST, module: str, function: str) -> None:
        for child in ast.iter_child_nodes(node):
            name = function
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                name = child.name
            if isinstance(child, ast.Call) and _is_warn(child):
                sites.add(f"{module}:{function}")
            visit(child, module, name)

    for package in packages:
        for path in sorted((root / package).rglob("*.py")):
            module = _module_name(root, path)
            visit(ast.parse(path.read_text(encoding="utf-8")), module, "<module>")
    sites.discard("stochcable.errors:warn")
    return sites


def undocumented_sites(sites: Iterable[str]) -> list[str]:
    """The call sites no entry of :data:`WARNINGS` names."""
    known = {s for w in WARNINGS for s in w.sites}
    return sorted(set(sites) - known)


def _value(ref: str) -> str:
    module, name = ref.split(":")
    value = getattr(importlib.import_module(module), name)
    if name == "STATIC_ROTATION_LIMIT":
        return f"{math.degrees(value):g}°"
    return f"{value:g}"


def warnings_reference_rst() -> str:
    """The reStructuredText of the warnings: one section per entry."""
    out: list[str] = []
    for w in WARNINGS:
        threshold = w.threshold
        values = []
        for ref in w.constants:
            name = ref.split(":")[1]
            values.append(f"``{name}`` = {_value(ref)}")
        out += [w.title, "-" * len(w.title), ""]
        out += [
            f":Category: ``{w.category}``",
            f":Threshold: {threshold}" + (f" ({'; '.join(values)})" if values else ""),
            ":Raised by: " + ", ".join(f"``{s.replace(':', '.')}``" for s in w.sites),
            "",
            f"**What it means.** {escape_bars(w.meaning)}",
            "",
            f"**What to do.** {escape_bars(w.action)}",
            "",
        ]
    return "\n".join(out)
