"""Closed-form equilibrium of a sagged travelling cable in a transverse flow.

Hu & Jin (2001) reduce a suspended cable that travels at speed c through two eyelets in
a uniform cross-flow V_f to the rotation φ of its mid-span section about the chord
(φ = 0 hanging at the bottom, φ = π at the top, measured clockwise with the flow from
right to left) and its radial stretch ξ.  The equilibria solve their eq. (39),

    [μ² − m(X + πσ₂ sin²φ)] sin φ − (X + nπσ₂ sin²φ) cos φ = 0,   X = D_f v_f,

with b = √(1 + λ₀²), k = dλ₀/(1 + λ₀²), m = b c_f, n = 1 + λ₀², σ₂ = πk²X/3 (eqs. 4,
10, 13, 18): a cubic in θ = sin²φ (eqs. 40–41) whose root in [0, 1] gives the left
equilibrium φ₀₁ ∈ (0, π) and the right one φ₀₂ = φ₀₁ + π (eq. 42).  The stability
follows from the linearized slow equation (31) (eqs. 43–44).

**Correction** (docs/travelling.md, "The closed form and its misprint"): evaluated with
the parameters printed for the figures (d = 0.1, c_f = 0.5, v_f = 0.1, D_f = 0.1) the
equations put the μ = 0.1 cable at φ₀ = 2.90 (near the top) already at λ₀ = 10, where
the paper's Fig. 7(a) has it return to the low equilibrium, and the μ = 0.3 cable at
φ₀ = 3.08 at λ₀ = 50, where Fig. 9(a) keeps it at the bottom.  Every stated case (Fig.
8: φ₀ ≈ π/2 at μ = 0.1, λ₀ = 20; Figs. 5, 9: near the bottom at μ = 0.3, λ₀ = 50 and
φ → 3.04 at λ₀ = 200; Fig. 7: low at μ = 0.1, λ₀ = 10, top at λ₀ = 100) is reproduced
when the fluid terms carry one more factor d = D/H than printed: X = d·D_f v_f.  The
other readings tried (b or k of the defined-but-unused λ = dλ₀, k without its d) miss
at least one case.  ``figure_scaling=True`` (the default) applies it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stochcable.errors import InputError
from stochcable.validation import nonnegative, positive

__all__ = [
    "OMEGA0_SQUARED",
    "HuJinGroups",
    "HuJinEquilibrium",
    "groups_hu_jin",
    "residual_hu_jin",
    "equilibrium_hu_jin",
    "swing_up_speed_hu_jin",
]

#: ω₀² = π⁴/2, the stretching stiffness of the reduced model (Hu & Jin 2001, eq. 18).
OMEGA0_SQUARED = np.pi**4 / 2.0
_DELTA1 = 4.0 / np.pi  # δ₁, the Galerkin weight of a uniform load on sin(πη) (eq. 13)


@dataclass(frozen=True)
class HuJinGroups:
    """The derived groups of Hu & Jin (2001), eqs. 4, 10, 13, 18.

    Attributes
    ----------
    mu : float
        μ = √(ρ_c g H⁴/(E D³)), the weight group. [-]
    x : float
        X, the drag group D_f v_f as used (times d with ``figure_scaling``). [-]
    m, n : float
        m = b c_f (lift) and n = 1 + λ₀². [-]
    sigma1, sigma2 : float
        σ₁ = π²k²D_f/4 and σ₂ = πk²X/3. [-]
    damping : float
        D_f, the damping of the slow equation (31). [-]
    """

    mu: float
    x: float
    m: float
    n: float
    sigma1: float
    sigma2: float
    damping: float


@dataclass(frozen=True)
class HuJinEquilibrium:
    """The two equilibria of the mid-span section and their stability.

    Attributes
    ----------
    phi : tuple of float
        (φ₀₁, φ₀₂): left equilibrium in (0, π), right one φ₀₁ + π. [rad]
    xi : tuple of float
        Radial stretch ξ₀ of each (eq. 33a). [-]
    stiffness : tuple of float
        The restoring coefficient of eq. (44) at each: > 0 stable, < 0 a saddle. [-]
    kind : tuple of str
        "stable focus", "stable node" or "saddle" (eq. 31 with damping Q₂).
    theta : float
        The root θ₁ = sin²φ₀ of the cubic (40) in [0, 1]. [-]
    """

    phi: tuple[float, float]
    xi: tuple[float, float]
    stiffness: tuple[float, float]
    kind: tuple[str, str]
    theta: float


def groups_hu_jin(
    mu: float,
    lambda0: float,
    d: float = 0.1,
    c_f: float = 0.5,
    v_f: float = 0.1,
    d_f: float = 0.1,
    figure_scaling: bool = True,
) -> HuJinGroups:
    """The groups of the reduced travelling-cable model.

    Parameters
    ----------
    mu : float
        Weight group μ. [-]
    lambda0 : float
        Relative travelling velocity λ₀ = c/V_f. [-]
    d : float
        Sag-to-span ratio D/H. [-]
    c_f : float
        Lift-to-drag coefficient ratio C_L/C_D. [-]
    v_f : float
        Dimensionless flow velocity (eq. 10). [-]
    d_f : float
        Dimensionless drag D_f (eq. 10). [-]
    figure_scaling : bool
        Apply the correction X = d·D_f v_f that reproduces the paper's figures (module
        docstring); False: the equations as printed, X = D_f v_f.

    Returns
    -------
    HuJinGroups
    """
    mu = positive("mu", mu, "-")
    lam0 = nonnegative("lambda0", lambda0, "-")
    d = positive("d", d, "-")
    c_f = nonnegative("c_f", c_f, "-")
    v_f = nonnegative("v_f", v_f, "-")
    d_f = positive("d_f", d_f, "-")
    if d >= 0.5:
        raise InputError("d", d, "-", "must be < 0.5 (a small sag-to-span ratio)")
    b = np.sqrt(1.0 + lam0 * lam0)
    k = d * lam0 / (1.0 + lam0 * lam0)
    x = d_f * v_f * (d if figure_scaling else 1.0)
    return HuJinGroups(
        mu=mu,
        x=float(x),
        m=float(b * c_f),
        n=float(1.0 + lam0 * lam0),
        sigma1=float(np.pi**2 * k * k * d_f / 4.0),
        sigma2=float(np.pi * k * k * x / 3.0),
        damping=d_f,
    )


def residual_hu_jin(phi: np.ndarray, g: HuJinGroups) -> np.ndarray:
    """Left side of the equilibrium equation (39) at angles ``phi`` [rad]."""
    s, c = np.sin(phi), np.cos(phi)
    th = s * s
    ps2 = np.pi * g.sigma2
    return (g.mu**2 - g.m * (g.x + ps2 * th)) * s - (g.x + g.n * ps2 * th) * c


def _cubic_root(g: HuJinGroups) -> float:
    """The root θ₁ ∈ [0, 1] of eq. (40) that solves eq. (39) (not a pseudo-root)."""
    ps2 = np.pi * g.sigma2
    mu2, x, m, n = g.mu**2, g.x, g.m, g.n
    a0 = ps2 * ps2 * (m * m + n * n)
    a1 = ps2 * (2.0 * x * (m * m + n) - (2.0 * m * mu2 + ps2 * n * n))
    a2 = (mu2 - m * x) ** 2 + x * x - 2.0 * n * ps2 * x
    a3 = -x * x
    # eq. (41), which is eq. (39) squared (checked: the printing is right); the
    # squaring adds pseudo-roots, so each root's angle (42) is checked against (39)
    roots = np.roots([a0, a1, a2, a3]) if a0 > 0 else np.roots([a1, a2, a3])
    cands = [float(r.real) for r in roots if abs(r.imag) <= 1e-9 and -1e-12 <= r.real <= 1 + 1e-12]
    best = None
    for th in cands:
        th = min(max(th, 0.0), 1.0)
        phi = _angle(g, th)
        res = abs(float(residual_hu_jin(np.array(phi), g)))
        if best is None or res < best[0]:
            best = (res, th)
    if best is None:
        raise InputError("groups", g, "-", "eq. (40) has no root in [0, 1]")
    return best[1]


def _angle(g: HuJinGroups, theta: float) -> float:
    """φ₀₁ of eq. (42) for θ₁."""
    ps2 = np.pi * g.sigma2
    num = g.mu**2 - g.m * (g.x + ps2 * theta)
    other = g.x + g.n * ps2 * theta
    return float(np.arctan2(other, num))  # = arccos(num/√(num² + other²)), in (0, π)


def _stiffness(g: HuJinGroups, phi: float) -> float:
    """The coefficient of Δφ in eq. (43), the left side of eq. (44)."""
    s, c = np.sin(phi), np.cos(phi)
    ps2 = np.pi * g.sigma2
    q3 = _DELTA1 * (g.x + g.n * ps2 * s * s)
    q4 = _DELTA1 * (g.mu**2 - g.m * (g.x + ps2 * s * s))
    dq3 = _DELTA1 * g.n * ps2 * 2.0 * s * c
    dq4 = -_DELTA1 * g.m * ps2 * 2.0 * s * c
    return float((q3 + dq4) * s + (q4 - dq3) * c)


def equilibrium_hu_jin(
    mu: float,
    lambda0: float,
    d: float = 0.1,
    c_f: float = 0.5,
    v_f: float = 0.1,
    d_f: float = 0.1,
    figure_scaling: bool = True,
) -> HuJinEquilibrium:
    """Equilibria of the mid-span section of a travelling cable and their stability.

    Parameters
    ----------
    mu, lambda0, d, c_f, v_f, d_f, figure_scaling
        As :func:`groups_hu_jin`.

    Returns
    -------
    HuJinEquilibrium
        φ₀₁, φ₀₂ (eq. 42), ξ₀ (eq. 33a), the stiffness of eq. (44) and the kind of
        each equilibrium.

    References
    ----------
    Hu, H. Y. & Jin, D. P. (2001), Non-linear dynamics of a suspended travelling cable
    subject to transverse fluid excitation, Journal of Sound and Vibration 239(3),
    515–529, eqs. 31, 33, 39–44.
    """
    g = groups_hu_jin(mu, lambda0, d, c_f, v_f, d_f, figure_scaling)
    theta = _cubic_root(g)
    p1 = _angle(g, theta)
    phis = (p1, p1 + np.pi)
    xis, ks, kinds = [], [], []
    for p in phis:
        s, c = np.sin(p), np.cos(p)
        df = _DELTA1 * ((g.mu**2 - g.m * g.x) * c + g.x * s)  # dF/dφ, eq. (17)
        xis.append(float((df + 4.0 * g.sigma2 * (g.n * s - g.m * c) * s * s) / OMEGA0_SQUARED))
        kap = _stiffness(g, p)
        ks.append(kap)
        q2 = g.damping + g.n * g.sigma1 * s * s  # Q₂ of eq. (30)
        if kap < 0.0:
            kinds.append("saddle")
        else:
            kinds.append("stable focus" if q2 * q2 < 4.0 * kap else "stable node")
    return HuJinEquilibrium(
        phi=(float(phis[0]), float(phis[1])),
        xi=(xis[0], xis[1]),
        stiffness=(ks[0], ks[1]),
        kind=(kinds[0], kinds[1]),
        theta=float(theta),
    )


def swing_up_speed_hu_jin(
    weight: float, rho: float, diameter: float, cl: float, flow_speed: float
) -> float:
    """Axial speed at which the lift of the relative flow carries the weight.

    Parameters
    ----------
    weight : float
        Weight per unit length that the lift must carry (Hu & Jin use ρ_c A g; a
        submerged line: its net submerged weight). [N/m]
    rho : float
        Fluid density. [kg/m³]
    diameter : float
        Hydrodynamic diameter. [m]
    cl : float
        Lift coefficient on |V_r|². [-]
    flow_speed : float
        Cross-flow speed V_f. [m/s]

    Returns
    -------
    float
        c with ½ρ C_L D (V_f² + c²) = weight (inf when C_L = 0 or V_f = 0, 0 when
        the flow alone lifts it). [m/s]

    Notes
    -----
    Eq. (38) of Hu & Jin (2001) with V_r² = V_f² + c²: the lift term m D_f v_f of eq. (39)
    equals μ².  There the mid-span section of the cable stands level with the chord,
    φ₀ = π/2 up to the drag and the slope terms (σ₂): the speed at which a sagged
    cable in a cross-flow swings up from the bottom towards the top.  Below it the
    cable hangs below the chord, above it rises above it.

    References
    ----------
    Hu, H. Y. & Jin, D. P. (2001), Non-linear dynamics of a suspended travelling cable
    subject to transverse fluid excitation, Journal of Sound and Vibration 239(3),
    515–529, eq. 38.
    """
    w = positive("weight", weight, "N/m")
    rho = positive("rho", rho, "kg/m³")
    dia = positive("diameter", diameter, "m")
    cl = nonnegative("cl", cl, "-")
    vf = nonnegative("flow_speed", flow_speed, "m/s")
    if cl == 0.0 or vf == 0.0:
        return float("inf")
    vr2 = w / (0.5 * rho * cl * dia)
    return float(np.sqrt(max(vr2 - vf * vf, 0.0)))
