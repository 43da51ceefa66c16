"""The closed forms of strumming (shedding, reduced velocity, damping, drag
amplification) and the Skop–Griffin wake oscillator of Tuah (1982), §3.2.b with its
harmonic balance.

The lift coefficient C_L(s, t) of every element obeys the wake oscillator of
Griffin, Skop & Ramberg (1975) (Tuah (1982), eq. 3.2.b.3)::

    C̈ + ω_s² C − [C_L0² − C² − (Ċ/ω_s)²]·(ω_s G Ċ − ω_s² H C) = ω_s F Ẏ/D

driven by the transverse velocity Ẏ of the element, and the cable responds in one
natural mode (Tuah (1982), eqs. 3.2.b.7–9)::

    z̈ + 2ξω_n ż + ω_n² z = Σ_e q_e ψ_e C_e,     q_e = ½ρ D_e U_e² L_e,

with ψ_e the mode's displacement at element e along its lift direction (mass-normalized
shapes, φᵀM_Tφ = 1).  Tuah (1982) prints C_L0 in the bracket; C_L0² is meant: with it the
free wake (Ẏ = 0) has the limit cycle C = C_L0 cos ω_s t exactly (C² + (Ċ/ω_s)² is then
constant), which is the definition of C_L0 ("lift amplitude of the fixed cylinder");
with C_L0 the free amplitude would be √C_L0.

:func:`wake_parameters` gives G, H, F from the reduced damping (Tuah (1982), eqs.
3.2.b.5–6); :func:`wake_response` solves the first-harmonic balance of the wake of
every element at a response frequency; :func:`lock_in_balance` solves the coupled
balance of a mode for its amplitude and frequency.  The time-domain check is
:mod:`stochcable.reference.wake_oscillator`.

References
----------
Griffin, O. M., Skop, R. A. and Ramberg, S. E. (1975), The resonant, vortex-excited
vibrations of structures and cable systems, Offshore Technology Conference, OTC 2319.
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from stochcable.errors import InputError
from stochcable.line.strumming.bound import LockInGrid, grid_is_proven
from stochcable.validation import finite_scalar

__all__ = [
    "CROSS_FLOW_BAND",
    "STROUHAL_DEFAULT",
    "LIFT_DEFAULT",
    "shedding_frequency",
    "strouhal_roshko",
    "reduced_velocity",
    "hydrodynamic_damping_ratio",
    "reduced_damping",
    "drag_amplification_vandiver",
    "WakeParameters",
    "wake_parameters",
    "wake_response",
    "LockIn",
    "lock_in_balance",
]

#: Relative residual below which a harmonic-balance root is accepted (the modal
#: balance |Z A − L|/(|Z A| + |L|), structure term Z A and lift term L; least_squares
#: reaches ~1e-12 on a true root, a local minimum that is not a root stays above ~1e-3).
_ROOT_TOL = 1.0e-7
#: Largest relative residual of a grid point refined by least squares (a root's
#: neighbours on the 20 x 29 grid stay below ~0.05). [-]
_START_TOL = 0.5
#: Most local minima of the grid refined. [-]
_STARTS = 4


#: Cross-flow lock-in band of the reduced velocity V_R = U/(f_n D), DNV-RP-C205
#: (2010) ch. 9 "Vortex induced oscillations" (cross-flow VIV for 3 ≤ V_R ≤ 16). [-]
CROSS_FLOW_BAND = (3.0, 16.0)
#: Strouhal number of a circular cylinder, subcritical 300 < Re < 2·10⁵ (Blevins 1990
#: Fig. 3-5; DNV-RP-C205 Fig. 9-2). [-]
STROUHAL_DEFAULT = 0.2
#: Lift-coefficient amplitude of the fixed cylinder (Tuah (1982), Example 6). [-]
LIFT_DEFAULT = 0.2


def shedding_frequency(speed, diameter, strouhal=STROUHAL_DEFAULT):
    """Vortex-shedding frequency ω_s = 2π St U_n/D.

    Parameters
    ----------
    speed : float or array_like
        Normal flow speed U_n (>= 0). [m/s]
    diameter : float or array_like
        Diameter (> 0). [m]
    strouhal : float or array_like, optional
        Strouhal number St (> 0). [-]

    Returns
    -------
    float or ndarray
        ω_s. [rad/s]

    Notes
    -----
    Tuah (1982), eq. 3.2.b.4.
    """
    u = np.asarray(speed, dtype=float)
    d = np.asarray(diameter, dtype=float)
    st = np.asarray(strouhal, dtype=float)
    _check_positive("strouhal", st, "-")
    _check_positive("diameter", d, "m")
    if np.any(~np.isfinite(u)) or np.any(u < 0):
        raise InputError("speed", speed, "m/s", "must be finite and >= 0")
    out = 2.0 * math.pi * st * u / d
    return float(out) if out.ndim == 0 else out


def strouhal_roshko(reynolds):
    """Strouhal number of a smooth circular cylinder from its Reynolds number.

    Parameters
    ----------
    reynolds : float or array_like
        Re = U_n D/ν (>= 0). [-]

    Returns
    -------
    float or ndarray
        St: 0 below Re = 40 (a steady wake, no shedding); 0.212 − 4.5/Re for
        40 ≤ Re < 300 and 0.212 − 2.7/Re for 300 ≤ Re < 2000 (Roshko 1954, NACA
        Report 1191: F = 0.212 Re − 4.5 in the stable and − 2.7 in the irregular
        range); 0.2 above, the subcritical plateau up to Re ≈ 2·10⁵ (Blevins 1990;
        DNV-RP-C205 Fig. 9-2), kept beyond it (the critical and supercritical values
        scatter from 0.2 to 0.45: give St per segment there). [-]
    """
    re = np.asarray(reynolds, dtype=float)
    if np.any(~np.isfinite(re)) or np.any(re < 0):
        raise InputError("reynolds", reynolds, "-", "must be finite and >= 0")
    safe = np.maximum(re, 1.0)
    out = np.where(
        re < 40.0,
        0.0,
        np.where(re < 300.0, 0.212 - 4.5 / safe, np.where(re < 2000.0, 0.212 - 2.7 / safe, 0.2)),
    )
    return float(out) if out.ndim == 0 else out


def reduced_velocity(speed, omega_n, diameter):
    """Reduced velocity V_R = U_n/(f_n D) = 2π U_n/(ω_n D).

    Parameters
    ----------
    speed : float or array_like
        Normal flow speed. [m/s]
    omega_n : float or array_like
        Natural frequency (> 0). [rad/s]
    diameter : float or array_like
        Diameter (> 0). [m]

    Returns
    -------
    float or ndarray
        V_R. [-]
    """
    _check_positive("omega_n", np.asarray(omega_n, dtype=float), "rad/s")
    _check_positive("diameter", np.asarray(diameter, dtype=float), "m")
    out = 2.0 * math.pi * np.asarray(speed, dtype=float) / (np.asarray(omega_n) * diameter)
    return float(out) if np.ndim(out) == 0 else out


def hydrodynamic_damping_ratio(rho, diameter, mass, viscosity, omega_n):
    """Still-water viscous damping ratio of a cylinder vibrating at ω_n.

    Parameters
    ----------
    rho : float
        Water density (> 0). [kg/m³]
    diameter : float
        Diameter (> 0). [m]
    mass : float
        Mass per length, structural + added (> 0). [kg/m]
    viscosity : float
        Kinematic viscosity ν (> 0). [m²/s]
    omega_n : float
        Natural frequency (> 0). [rad/s]

    Returns
    -------
    float
        ξ = (12 ρ D/(π m)) √(ν/ω_n). [-]

    Notes
    -----
    Tuah (1982), eq. 3.2.b.8.
    """
    for name, v, unit in (
        ("rho", rho, "kg/m³"),
        ("diameter", diameter, "m"),
        ("mass", mass, "kg/m"),
        ("viscosity", viscosity, "m²/s"),
        ("omega_n", omega_n, "rad/s"),
    ):
        if not finite_scalar(name, v, unit) > 0:
            raise InputError(name, v, unit, "must be > 0")
    return 12.0 * rho * diameter / (math.pi * mass) * math.sqrt(viscosity / omega_n)


def reduced_damping(mass, damping_ratio, rho, diameter, strouhal=STROUHAL_DEFAULT):
    """Skop–Griffin reduced damping S_G = 2π St² k_s, k_s = 4π m ξ/(ρ D²).

    Parameters
    ----------
    mass : float
        Mass per length, structural + added. [kg/m]
    damping_ratio : float
        ξ of the mode (structural + hydrodynamic, > 0). [-]
    rho : float
        Water density. [kg/m³]
    diameter : float
        Diameter. [m]
    strouhal : float, optional
        St. [-]

    Returns
    -------
    float
        S_G. [-]

    Notes
    -----
    Tuah (1982), eq. 3.2.b.6 (Griffin, Skop & Ramberg 1975).
    """
    if not finite_scalar("damping_ratio", damping_ratio, "-") > 0:
        raise InputError("damping_ratio", damping_ratio, "-", "must be > 0")
    ks = 4.0 * math.pi * mass * damping_ratio / (rho * diameter**2)
    return 2.0 * math.pi * strouhal**2 * ks


def drag_amplification_vandiver(y_rms_over_d):
    """In-line drag amplification of a vibrating cable, C_d/C_d0.

    Parameters
    ----------
    y_rms_over_d : float or array_like
        RMS cross-flow displacement over the diameter (>= 0). [-]

    Returns
    -------
    float or ndarray
        1 + 1.043 (2 Y_rms/D)^0.65. [-]

    Notes
    -----
    Vandiver, J. K. (1983), "Drag coefficients of long flexible cylinders", OTC 4490,
    fitted to field data of strumming cables; the magnification Tuah (1982) names (Skop,
    Griffin and Ramberg 1977) and leaves for future study (Tuah (1982), ch. 7).
    """
    y = np.asarray(y_rms_over_d, dtype=float)
    if np.any(~np.isfinite(y)) or np.any(y < 0):
        raise InputError("y_rms_over_d", y_rms_over_d, "-", "must be finite and >= 0")
    out = 1.0 + 1.043 * (2.0 * y) ** 0.65
    return float(out) if out.ndim == 0 else out


def _check_positive(name: str, value: np.ndarray, unit: str) -> None:
    if np.any(~np.isfinite(value)) or np.any(value <= 0):
        bad = value if value.ndim == 0 else value[~(np.isfinite(value) & (value > 0))][0]
        raise InputError(name, float(bad), unit, "must be finite and > 0")


@dataclass(frozen=True)
class WakeParameters:
    """Empirical parameters of the wake oscillator (Tuah (1982), eqs. 3.2.b.5–6).

    Attributes
    ----------
    reduced_damping : float
        S_G = 2π St² k_s, k_s = 4π m ξ/(ρ D²). [-]
    g, h, f : float
        Ḡ, the auxiliary h and F̄ = 4 Ḡ S_G/h. [-]
    big_h : float
        H̄ = ξ h. [-]
    """

    reduced_damping: float
    g: float
    h: float
    f: float
    big_h: float


def wake_parameters(reduced_damping: float, damping_ratio: float) -> WakeParameters:
    """Ḡ, H̄, F̄ of the wake oscillator from the reduced damping.

    Parameters
    ----------
    reduced_damping : float
        S_G = 2π St² k_s (> 0). [-]
    damping_ratio : float
        ξ of the mode (structural + hydrodynamic). [-]

    Returns
    -------
    WakeParameters

    Notes
    -----
    Tuah (1982), eqs. 3.2.b.5–6 (Griffin, Skop & Ramberg 1975, OTC 2319):
    log₁₀ Ḡ = 0.25 − 0.21 S_G, log₁₀(h S_G²) = −0.24 + 0.66 S_G, H̄ = ξ h,
    F̄ = 4 Ḡ S_G/h.
    """
    sg = float(reduced_damping)
    g = 10.0 ** (0.25 - 0.21 * sg)
    h = 10.0 ** (-0.24 + 0.66 * sg) / sg**2
    return WakeParameters(
        reduced_damping=sg, g=g, h=h, f=4.0 * g * sg / h, big_h=float(damping_ratio) * h
    )


def _largest_cubic_root(c3: np.ndarray, c2: np.ndarray, c1: np.ndarray, c0: np.ndarray):
    """Largest real root of c3 x³ + c2 x² + c1 x + c0 (c3 > 0, c0 < 0: it is > 0), per
    entry, by Cardano's formula (one real root) or the trigonometric form (three), then
    two Newton steps to polish it."""
    p2, p1, p0 = c2 / c3, c1 / c3, c0 / c3
    big_p = p1 - p2**2 / 3.0
    big_q = 2.0 * p2**3 / 27.0 - p2 * p1 / 3.0 + p0
    disc = (big_q / 2.0) ** 2 + (big_p / 3.0) ** 3
    one = disc >= 0
    sq = np.sqrt(np.where(one, disc, 0.0))
    t_one = np.cbrt(-big_q / 2.0 + sq) + np.cbrt(-big_q / 2.0 - sq)
    m = np.sqrt(np.maximum(-big_p / 3.0, 0.0))
    arg = np.where(one, 0.0, -big_q / (2.0 * np.where(one, 1.0, m**3)))
    t_three = 2.0 * m * np.cos(np.arccos(np.clip(arg, -1.0, 1.0)) / 3.0)
    x = np.where(one, t_one, t_three) - p2 / 3.0
    for _ in range(2):
        f = ((x + p2) * x + p1) * x + p0
        df = (3.0 * x + 2.0 * p2) * x + p1
        ok = np.abs(df) > 0
        x = np.where(ok, x - f / np.where(ok, df, 1.0), x)
    return np.maximum(x, 0.0)


def wake_response(
    forcing: np.ndarray,
    omega: float | np.ndarray,
    omega_s: np.ndarray,
    lift0: np.ndarray,
    params: WakeParameters,
) -> np.ndarray:
    """First-harmonic lift phasor of each element's wake oscillator at frequency ω.

    Parameters
    ----------
    forcing : ndarray, complex, shape (..., n)
        Phasor of Ẏ/D of each element, the transverse velocity over the diameter. [1/s]
    omega : float or ndarray broadcastable to ``forcing``
        Response (lock-in) frequency. [rad/s]
    omega_s : ndarray, shape (n,)
        Shedding frequency of each element. [rad/s]
    lift0 : ndarray, shape (n,)
        C_L0 of each element. [-]
    params : WakeParameters

    Returns
    -------
    ndarray, complex, shape of ``forcing``
        Phasor c of C_L = Re{c e^{iωt}}. [-]

    Notes
    -----
    With C = |c| cos θ and r = ω/ω_s the first harmonics of the bracket products are
    [C_L0² − |c|²(1 + 3r²)/4]·Ċ and [C_L0² − |c|²(3 + r²)/4]·C, so the balance is
    c·(a0 + a1 |c|²) = ω_s F̄ Ẏ/D with a0 = ω_s² − ω² − iωω_s Ḡ C_L0² + ω_s² H̄ C_L0²,
    a1 = iωω_s Ḡ (1 + 3r²)/4 − ω_s² H̄ (3 + r²)/4.  x = |c|² solves the cubic
    x |a0 + a1 x|² = |rhs|²; the largest positive root is the entrained branch (the wake
    is self-excited: the small root, a quenched wake, is the unstable one).
    """
    fz = np.asarray(forcing, dtype=complex)
    w = np.broadcast_to(np.asarray(omega, dtype=float), fz.shape)
    ws = np.broadcast_to(np.asarray(omega_s, dtype=float), fz.shape)
    c0sq = np.broadcast_to(np.asarray(lift0, dtype=float) ** 2, fz.shape)
    r2 = (w / ws) ** 2
    a0 = ws**2 - w**2 - 1j * w * ws * params.g * c0sq + ws**2 * params.big_h * c0sq
    a1 = 1j * w * ws * params.g * (1.0 + 3.0 * r2) / 4.0 - ws**2 * params.big_h * (3.0 + r2) / 4.0
    rhs = ws * params.f * fz
    k2 = np.abs(rhs) ** 2
    out = np.zeros(fz.shape, dtype=complex)
    live = k2 > 0
    if np.any(live):
        b0, b1 = a0[live], a1[live]
        x = _largest_cubic_root(
            np.abs(b1) ** 2, 2.0 * (b0 * np.conj(b1)).real, np.abs(b0) ** 2, -k2[live]
        )
        out[live] = rhs[live] / (b0 + b1 * x)
    return out


@dataclass(frozen=True)
class LockIn:
    """The locked-in steady state of one mode (:func:`lock_in_balance`).

    Attributes
    ----------
    locked : bool
        Whether a harmonic-balance solution exists.
    amplitude : float
        Modal amplitude A of z = A cos ωt (mass-normalized shapes). [kg^1/2·m]
    omega : float
        Response frequency. [rad/s]
    lift : ndarray, complex, shape (n,)
        Lift-coefficient phasor of every element. [-]
    residual : float
        Relative residual of the modal balance. [-]
    """

    locked: bool
    amplitude: float
    omega: float
    lift: np.ndarray
    residual: float


def lock_in_balance(
    omega_n: float,
    damping_ratio: float,
    psi: np.ndarray,
    q: np.ndarray,
    diameter: np.ndarray,
    omega_s: np.ndarray,
    lift0: np.ndarray,
    params: WakeParameters,
) -> LockIn:
    """Steady lock-in of one mode with the wake oscillators of its elements.

    Parameters
    ----------
    omega_n : float
        Natural frequency. [rad/s]
    damping_ratio : float
        ξ of the mode (structural + hydrodynamic). [-]
    psi : ndarray, shape (n,)
        Mode displacement at each element along its lift direction. [kg^-1/2]
    q : ndarray, shape (n,)
        ½ρ D U_n² L of each element (zero where the lift is off). [N]
    diameter : ndarray, shape (n,)
        Element diameter. [m]
    omega_s, lift0 : ndarray, shape (n,)
        Shedding frequency [rad/s] and C_L0 [-] of each element.
    params : WakeParameters

    Returns
    -------
    LockIn
        ``locked`` False (amplitude 0) when no first-harmonic solution exists within
        ω/ω_n ∈ [0.65, 1.35] and A·max|ψ|/D ∈ [1e-3, 3].

    Notes
    -----
    Unknowns A (real, the phase reference) and ω; the complex modal balance
    (ω_n² − ω² + 2iξω_nω) A = Σ_e q_e ψ_e c_e(A ψ_e iω/D_e, ω) (the wakes by
    :func:`wake_response`) is solved by least squares in (ln A, ω) from the local
    minima of a coarse grid, on the scale-free residual |ZA − L|/(|ZA| + |L|); of
    several roots the largest amplitude is taken.
    """
    psi = np.asarray(psi, dtype=float)
    q = np.asarray(q, dtype=float)
    diameter = np.asarray(diameter, dtype=float)
    live = (q > 0) & (psi != 0)
    none = LockIn(False, 0.0, float(omega_n), np.zeros(psi.size, complex), math.inf)
    if not np.any(live):
        return none
    ps, qs, ds, ws, c0 = psi[live], q[live], diameter[live], omega_s[live], lift0[live]
    y_scale = float(np.max(np.abs(ps) / ds))  # Y_max/D per unit modal amplitude

    def resid(x: np.ndarray) -> np.ndarray:
        a, w = math.exp(x[0]), float(x[1]) * omega_n
        c = wake_response(1j * w * a * ps / ds, w, ws, c0, params)
        left = (omega_n**2 - w**2 + 2j * damping_ratio * omega_n * w) * a
        right = np.sum(qs * ps * c)
        z = (left - right) / (abs(left) + abs(right))
        return np.array([z.real, z.imag])

    ln_a = np.log(np.geomspace(1e-3, 3.0, 20) / y_scale)
    ratio = np.linspace(0.65, 1.35, 29)
    start = LockInGrid(
        np.exp(ln_a), ratio * omega_n, omega_n, damping_ratio, ps, qs, ds, ws, c0,
        params.g, params.big_h, params.f,
    )  # fmt: skip
    if grid_is_proven(start):
        return none  # every point proven: no start, and no compiled kernel needed
    from stochcable.line.strumming.kernels import balance_grid  # numba: lazily

    grid = balance_grid(start)
    if not grid.min() < _START_TOL:  # no start: no root is refined (the common case)
        return none
    # starts: the grid's local minima below _START_TOL (a grid point farther than that
    # from a root is not refined: the balance is smooth on the grid's scale except at
    # branch switches, where a root has |z| << 1 nearby), best first
    pad = np.pad(grid, 1, constant_values=np.inf)
    neigh = np.min(
        [
            pad[1 + di : 1 + di + grid.shape[0], 1 + dj : 1 + dj + grid.shape[1]]
            for di in (-1, 0, 1)
            for dj in (-1, 0, 1)
            if di or dj
        ],
        axis=0,
    )
    minima = np.flatnonzero(((grid <= neigh) & (grid < _START_TOL)).ravel())
    starts = list(minima[np.argsort(grid.ravel()[minima])][:_STARTS])
    # and the best points overall (a root at a branch switch of the wakes sits on a
    # slope of the grid, not in a local minimum of it)
    starts += [f for f in np.argsort(grid, axis=None)[:3] if grid.flat[f] < _START_TOL]
    starts = list(dict.fromkeys(int(f) for f in starts))
    best = (np.array([ln_a[0], 1.0]), math.inf)
    roots = []
    for flat in starts:
        i, j = np.unravel_index(flat, grid.shape)
        from scipy.optimize import least_squares  # (only where a start is refined)

        sol = least_squares(
            resid,
            np.array([ln_a[i], ratio[j]]),
            bounds=([ln_a[0] - 1.0, 0.6], [ln_a[-1] + 1.0, 1.4]),
            xtol=1e-13,
            ftol=1e-13,
            gtol=1e-13,
            max_nfev=100,  # a true root converges in < 60 evaluations
        )
        res = float(np.hypot(*sol.fun))
        if res < best[1]:
            best = (sol.x, res)
        if res < _ROOT_TOL:
            roots.append((sol.x, res))
    if roots:
        # several branches: the largest amplitude is the one a run from rest reaches
        # (the wakes are self-excited; tests/line/test_strumming.py)
        best = max(roots, key=lambda r: r[0][0])
    x, res = best
    if res >= _ROOT_TOL:
        return LockIn(False, 0.0, float(omega_n), np.zeros(psi.size, complex), res)
    a, w = math.exp(x[0]), float(x[1]) * omega_n
    lift = np.zeros(psi.size, dtype=complex)
    lift[live] = wake_response(1j * w * a * ps / ds, w, ws, c0, params)
    return LockIn(True, a, w, lift, res)
