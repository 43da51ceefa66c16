"""Nonlinear time-domain reference simulation of one line (seed 001 §4.2, §3.1–3.2).

This is the yardstick of the frequency-domain method, not its main path: tests and
benchmarks run it with the *same* sea realization (the same FFT coefficients X_m of
:mod:`stochcable.sea.realization`) as the linear analysis and compare statistics and time series,
which measures the error of the statistical drag linearization and of the small-motion
assumption.

Model (the same finite-element discretization as the frequency-domain model):

- 2-node straight elements (:func:`stochcable.line.mesh.mesh_line`), geometrically exact
  elastic bar: with current length l, unstretched l0 and unit vector e, the effective
  tension is T = EA (l/l0 − 1); a slack element (l < l0) keeps the small stiffness
  ε·EA (ε = :data:`SLACK_STIFFNESS_RATIO`), so T → 0⁻ instead of a compression strut.
  Tangent stiffness K_e = [(EA/l0) e eᵀ + (T/l)(I − e eᵀ)] ⊗ [[1, −1], [−1, 1]]
  (DESIGN.md; seed 001 eqs. 3.1.8–3.1.11).
- Consistent mass m l0 [[1/3, 1/6], [1/6, 1/3]] ⊗ I (seed eq. 3.1.12) plus the normal
  added mass Can ρ (πD²/4) l0 [[1/3, 1/6], [1/6, 1/3]] ⊗ (I − e₀e₀ᵀ) and attachment
  masses.  The added mass is evaluated about the *static* tangents e₀ so the mass
  matrix is constant (as in the frequency-domain model).
- Net weight (gravity minus buoyancy) per length and attachment weight/buoyancy as in
  the statics (elements above z = 0 keep the submerged weight); a one-sided seabed
  penalty spring k·D and dashpot c·D per unit length (per unit contact area times the
  diameter, as MoorDyn's kBot, cBot) on nodes below z = −h, lumped over the node's
  tributary length, blended in smoothly over the static penetration p₀ = w/(kD)
  (:meth:`_LineModel.seabed`), the dashpot's engagement lagged by one step: a kinked
  contact law makes Newton cycle when a node lands within a step.
- Wave loads use the load model of the frequency-domain analysis
  (:func:`stochcable.dynamics.loads.wave_loads`), the wave kinematics taken at the
  *static* positions (linear wave theory; the error is second order in the motion;
  zero above z = 0):

  * wave inertia (linear in the kinematics) — **exact** along each straight element:
    node i of element j gets l0_j ρ(πD²/4)(1 + Can)(I − e₀e₀ᵀ)·∫₀¹ N_i a dξ with the
    closed-form consistent moments of
    :func:`stochcable.dynamics.loads.element_wave_kinematics` (split at the waterline),
    synthesized in time with the realization's coefficients like any transfer
    function; attachments get (buoyancy/g + added mass)·a at their node.
  * Morison drag with the relative velocity v_r = U_current + v_wave − u̇ (seed eqs.
    3.2.a.2–3.2.a.5), normal ½ρ Cdn D |v_rn| v_rn and axial ½ρ Cdt πD |v_rt| v_rt with
    the *instantaneous* element tangent e — **quadrature**: v_r is formed at
    :data:`GAUSS_POINTS` Gauss–Legendre points ξ_g per element (fluid velocity of
    :func:`stochcable.sea.kinematics.wave_kinematics` and the current profile at the
    static quadrature points, structural velocity interpolated linearly between the
    nodes) and the consistent nodal load is l0 Σ_g w_g N_i(ξ_g) f(v_r(ξ_g)),
    N_a = 1 − ξ, N_b = ξ; the Newton tangent uses the same quadrature.  Exact
    (to rounding) when f(v_r(ξ)) is a polynomial of degree <= 2·GAUSS_POINTS − 2 in ξ,
    e.g. v_r linear in ξ with a fixed direction and sign (tested); in the linear limit
    about a current uniform over the element the structural-velocity part is the
    consistent damping matrix l0 [[1/3, 1/6], [1/6, 1/3]] ⊗ ∂f/∂v_r of the
    frequency-domain model exactly; the wave part
    carries the Gauss error of e^{kz} over the element (small unless k·Δz of an
    element near the surface is several units at frequencies carrying energy), and
    the |v_r| kink and the waterline crossing are not resolved exactly.
    Attachments add ½ρ (Cd·A) |v_r| v_r with the nodal fluid velocity.
- Ends are prescribed: end-motion spectra are realized per channel with independent
  seeds (``SeedSequence(seed).spawn``) or RAO × sea coefficients, synthesized by FFT to
  displacement, velocity (iω) and acceleration (−ω²) on the simulation grid.

Time stepping: Newmark average acceleration (β = 1/4, γ = 1/2; seed eqs. 4.2.7–4.2.11)
with full Newton iterations per step on the residual
R = M ü + F_int(x) − F_ext(t, x, u̇) of the free DOFs, Jacobian
4/Δt² M + K_T + 2/Δt C_T (C_T the drag and seabed velocity Jacobians; the drag's
dependence on the tangent's rotation is left out of the Jacobian — seed eq. 3.2.a.6's
S_ij, "negligible" — so Newton converges linearly-fast rather than quadratically when
the current is strong), with a backtracking line search on the residual norm.  Linear
solves are banded LAPACK (half-bandwidth 2·dim − 1).  End tensions are the support
reactions (the residual rows of the prescribed end nodes), the quantity of the
statics' ``tension_a``/``tension_b`` and of the frequency-domain end tension.  The
excitation starts from the static equilibrium of this same model and is ramped in by a
half-cosine over ``ramp`` seconds; statistics skip the ramp.

The integrator is written here rather than taken from :mod:`stochcable.sea.timeseries`
because the ends are *prescribed* and time-dependent: the internal force of the
elements next to the ends depends on t, which the generic protocol's
``internal_force(u)`` cannot express without losing the consistent tangent, and the
banded Jacobian assembly is specific to the line topology.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy import linalg as sla
from scipy import sparse

from stochcable.sea import fft as _fft
from stochcable import validation as _v
from stochcable.errors import ConvergenceError, InputError, ResolutionWarning, warn
from stochcable.line.mesh import LineMesh, mesh_line
from stochcable.scene.model import Environment, Line, Scene, load_scene

__all__ = [
    "CableTimeHistory",
    "simulate_line_timedomain",
    "SLACK_STIFFNESS_RATIO",
    "PERIOD_ERROR_TOLERANCE",
    "newmark_period_error",
    "GAUSS_POINTS",
    "NONSTATIONARY_RATIO",
]

SLACK_STIFFNESS_RATIO = 1e-6
"""Fraction of EA kept by a slack (compressed) element. [-]"""

PERIOD_ERROR_TOLERANCE = 0.01
"""Largest accepted relative period elongation (ωΔt)²/12 of the average-acceleration
scheme at the highest excitation frequency before a ResolutionWarning. [-]"""

NONSTATIONARY_RATIO = 8.0
"""Largest accepted ratio of the largest to the smallest end-tension σ over windows of
the record after the ramp (:meth:`CableTimeHistory.stationarity_ratio`) before a
ResolutionWarning: the response to a stationary sea is stationary. [-]"""

_ENERGY_QUANTILE = 0.99  # fraction of excitation variance below the "highest" frequency
_CONSISTENT = np.array([[1.0 / 3.0, 1.0 / 6.0], [1.0 / 6.0, 1.0 / 3.0]])
GAUSS_POINTS = 3
"""Gauss–Legendre points per element of the drag quadrature. [-]"""

_DRAG_EPS = 1e-9  # regularization of |v| in the drag Jacobian [m/s]
_BACKTRACK = 12  # largest number of step halvings in a Newton line search


def newmark_period_error(omega: float | np.ndarray, dt: float) -> float | np.ndarray:
    """Relative period elongation of Newmark average acceleration.

    Parameters
    ----------
    omega : float or array
        Angular frequency. [rad/s]
    dt : float
        Time step. [s]

    Returns
    -------
    float or array
        ΔT/T = ωΔt / (2 arctan(ωΔt/2)) − 1 ≈ (ωΔt)²/12. [-]

    Notes
    -----
    The trapezoidal rule maps s = iω to i(2/Δt) tan(ωΔt/2): a linear undamped mode of
    frequency ω oscillates at (2/Δt) arctan(ωΔt/2) with no amplitude error.
    """
    x = np.asarray(omega, dtype=float) * dt
    with np.errstate(invalid="ignore", divide="ignore"):
        r = np.where(x > 0, x / (2.0 * np.arctan(0.5 * np.where(x > 0, x, 1.0))) - 1.0, 0.0)
    return float(r) if r.ndim == 0 else r


# --------------------------------------------------------------------------- result


@dataclass(frozen=True, eq=False)
class CableTimeHistory:
    """Nonlinear time-domain response of one line.

    Attributes
    ----------
    line : str
        Line name.
    t : ndarray, shape (n_t,)
        Time, t = 0 at the static start. [s]
    positions : ndarray, shape (n_t, n_nodes, 3)
        Node positions. [m]
    static_positions : ndarray, shape (n_nodes, 3)
        Static equilibrium of this model (the start). [m]
    tension_a, tension_b : ndarray, shape (n_t,)
        End tensions: magnitude of the force between the line and the support at end_a
        and end_b (the reaction rows of the equations of motion: element force plus the
        inertia, weight and hydrodynamic loads lumped on the end node), as the statics'
        ``tension_a``/``tension_b`` and the frequency-domain end tension. [N]
    element_tension : ndarray, shape (n_te, n_el)
        Effective tension of every element at ``element_time``. [N]
    element_time : ndarray, shape (n_te,)
        Times of ``element_tension`` (every ``element_every``-th step). [s]
    static_tension : ndarray, shape (n_el,)
        Element tension at the static start. [N]
    iterations : ndarray of int, shape (n_t,)
        Newton iterations per step (0 at t = 0). [-]
    max_residual : float
        Largest final residual norm (max abs) of all steps. [N]
    tolerance : float
        Newton residual tolerance. [N]
    dt : float
        Integration time step. [s]
    ramp : float
        Length of the half-cosine excitation ramp, excluded from statistics. [s]
    s0 : ndarray, shape (n_nodes,)
        Unstretched arc length of the nodes from end_a. [m]
    """

    line: str
    t: np.ndarray
    positions: np.ndarray
    static_positions: np.ndarray
    tension_a: np.ndarray
    tension_b: np.ndarray
    element_tension: np.ndarray
    element_time: np.ndarray
    static_tension: np.ndarray
    iterations: np.ndarray
    max_residual: float
    tolerance: float
    dt: float
    ramp: float
    s0: np.ndarray
    _meta: dict = field(default_factory=dict, repr=False)

    @property
    def displacements(self) -> np.ndarray:
        """Node displacements from the static position, shape (n_t, n_nodes, 3). [m]"""
        return self.positions - self.static_positions

    def steady(self, start: float | None = None) -> np.ndarray:
        """Boolean mask of the samples used for statistics (t >= start, default the ramp)."""
        t0 = self.ramp if start is None else float(start)
        return self.t >= t0 - 1e-9 * max(self.dt, 1.0)

    def tension_statistics(self, end: str = "b", start: float | None = None) -> dict[str, float]:
        """Mean, standard deviation, min and max of an end tension after the ramp.

        Parameters
        ----------
        end : {"a", "b"}
            Which end. [-]
        start : float, optional
            First time used (default: the ramp length). [s]

        Returns
        -------
        dict
            ``mean``, ``std``, ``min``, ``max``. [N]
        """
        if end not in ("a", "b"):
            raise InputError("end", end, "-", "must be 'a' or 'b'")
        x = (self.tension_a if end == "a" else self.tension_b)[self.steady(start)]
        return {"mean": float(x.mean()), "std": float(x.std()),
                "min": float(x.min()), "max": float(x.max())}

    def stationarity_ratio(self, windows: int | None = None) -> tuple[float, float, float]:
        """Largest over smallest σ of the end tensions over windows after the ramp.

        Parameters
        ----------
        windows : int, optional
            Number of equal windows (default: one per 5 peak periods of the
            excitation, 4 to 16). [-]

        Returns
        -------
        (float, float, float)
            The ratio (the larger of the two ends) [-], the start time of the window of
            the largest σ [s] and the frequency of the largest spectral line of the end
            tension in that window [rad/s].

        Notes
        -----
        The response to a stationary excitation is stationary: window σ's of 5 peak
        periods scatter by a factor of about 2–3 even with slack–taut snaps (measured
        on tuah_1982_single_leg, 8 seeds).  A record that jumps to a persistent
        oscillation tens of times larger is a numerical artefact: the
        average-acceleration scheme conserves the energy of a *linear* system only;
        with the slack/taut switch of an element inside a step it can pump an
        under-resolved axial oscillation (ωΔt of order 2).
        """
        keep = self.steady()
        t = self.t[keep]
        if windows is None:
            w_peak = float(self._meta.get("omega_peak", 0.0)) or 1.0
            windows = int((t[-1] - t[0]) / (5.0 * 2.0 * math.pi / w_peak))
            windows = min(16, max(4, windows))
        n_w = _v.positive_int("windows", windows)
        size = t.size // n_w
        if size < 4:
            return 1.0, float(t[0]), 0.0
        worst = (1.0, float(t[0]), 0.0)
        for x in (self.tension_a[keep], self.tension_b[keep]):
            sig = np.array([x[j * size:(j + 1) * size].std() for j in range(n_w)])
            lo = float(sig.min())
            ratio = float(sig.max()) / lo if lo > 0 else (math.inf if sig.max() > 0 else 1.0)
            if ratio > worst[0]:
                j = int(np.argmax(sig))
                seg = x[j * size:(j + 1) * size]
                spec = np.abs(np.fft.rfft(seg - seg.mean())) ** 2
                w = 2.0 * math.pi * np.fft.rfftfreq(seg.size, self.dt)
                worst = (ratio, float(t[j * size]), float(w[int(np.argmax(spec))]))
        return worst

    def motion_std(self, start: float | None = None) -> np.ndarray:
        """Standard deviation of every node's x, y, z motion after the ramp. [m]"""
        return self.displacements[self.steady(start)].std(axis=0)

    def element_tension_std(self, start: float | None = None) -> np.ndarray:
        """Standard deviation of every element's tension after the ramp. [N]"""
        t0 = self.ramp if start is None else float(start)
        return self.element_tension[self.element_time >= t0 - 1e-9].std(axis=0)


# --------------------------------------------------------------------------- model


def _axes(dim: int) -> np.ndarray:
    """Columns: the global unit vectors of the model's coordinates (3, dim)."""
    if dim == 3:
        return np.eye(3)
    return np.array([[1.0, 0.0], [0.0, 0.0], [0.0, 1.0]])


class _LineModel:
    """The discrete equations of one line; everything vectorized over elements.

    Arrays: X, V, A of shape (n_nodes, dim); the DOF of node i, coordinate c is i·dim + c.
    """

    def __init__(self, mesh: LineMesh, env: Environment, x_static: np.ndarray, dim: int):
        self.mesh = mesh
        self.dim = d = dim
        self.n = n = mesh.n_nodes
        self.ne = ne = mesh.n_elements
        self.N = n * d
        self.l0 = mesh.l0
        self.ea = mesh.ea
        self.rho = env.rho
        self.g = env.g
        self.depth = env.depth
        area = math.pi * mesh.diameter**2 / 4.0
        self.cn = 0.5 * env.rho * mesh.cd_normal * mesh.diameter        # [kg/m²]
        self.ct = 0.5 * env.rho * mesh.cd_axial * math.pi * mesh.diameter
        self.node_cda = 0.5 * env.rho * mesh.node_drag_area               # [kg/m]
        trib = np.zeros(n)
        trib[:-1] += 0.5 * mesh.l0
        trib[1:] += 0.5 * mesh.l0
        trib_d = np.zeros(n)
        trib_d[:-1] += 0.5 * mesh.l0 * mesh.diameter
        trib_d[1:] += 0.5 * mesh.l0 * mesh.diameter
        self.k_bed = env.seabed.stiffness * trib_d   # [N/m] per node
        self.c_bed = env.seabed.damping * trib_d     # [N·s/m] per node
        # static penetration of a grounded node under its weight: w·L / (k·D·L)
        w_node = np.zeros(n)
        w_node[:-1] += 0.5 * np.abs(mesh.weight) * mesh.l0
        w_node[1:] += 0.5 * np.abs(mesh.weight) * mesh.l0
        with np.errstate(divide="ignore", invalid="ignore"):
            pen0 = np.where(self.k_bed > 0, w_node / self.k_bed, 0.0)
        self.pen0 = np.maximum(pen0, 1e-6 * max(1.0, float(np.sum(mesh.l0)) * 1e-3))
        ax = _axes(d)
        self.axes = ax
        self.x_static = x_static  # (n, d)

        # gravity / buoyancy (constant), shape (n, d); the last coordinate is z
        fg = np.zeros((n, d))
        wl = mesh.weight * mesh.l0
        fg[:-1, -1] -= 0.5 * wl
        fg[1:, -1] -= 0.5 * wl
        fg[:, -1] += mesh.node_buoyancy - mesh.node_mass * env.g
        self.f_gravity = fg

        # static tangents for added mass and wave inertia
        dx = np.diff(x_static, axis=0)
        e0 = dx / np.linalg.norm(dx, axis=1)[:, None]
        P0 = np.eye(d)[None] - e0[:, :, None] * e0[:, None, :]
        I = np.eye(d)[None]
        m_struct = (mesh.mass * mesh.l0)[:, None, None] * I
        m_add = (mesh.ca_normal * env.rho * area * mesh.l0)[:, None, None] * P0
        mw = ((1.0 + mesh.ca_normal) * env.rho * area * mesh.l0)[:, None, None] * P0
        self.P0 = P0
        # wave inertia: per element l0·ρ(πD²/4)(1 + Can)(I − e₀e₀ᵀ) (acts on the exact
        # element moments ∫N_i a dξ), per attachment (buoyancy/g + added mass) (on a_node)
        self.inertia_el = mw                                              # (ne, d, d)
        self.node_mw = mesh.node_buoyancy / env.g + mesh.node_added_mass  # (n,)
        # drag quadrature: Gauss–Legendre points ξ_g on [0, 1], weights w_g (Σ = 1),
        # shape functions N_a = 1 − ξ, N_b = ξ at the points
        xg, wg = np.polynomial.legendre.leggauss(GAUSS_POINTS)
        self.gauss_xi = 0.5 * (xg + 1.0)
        self.gauss_w = 0.5 * wg
        self.gauss_N = np.stack([1.0 - self.gauss_xi, self.gauss_xi], axis=1)  # (ng, 2)
        # Σ_g w_g N_a N_c N (= the consistent [[1/3, 1/6], [1/6, 1/3]] for ng >= 2)
        self._gauss_wNN = np.einsum("g,ga,gc->gac", self.gauss_w, self.gauss_N, self.gauss_N)

        # banded/sparse index maps -------------------------------------------------
        self.u = u = 2 * d - 1                       # half bandwidth
        loc = np.arange(2 * d)
        gi = (np.arange(ne)[:, None] * d + loc[None, :])          # (ne, 2d)
        rows = np.broadcast_to(gi[:, :, None], (ne, 2 * d, 2 * d))
        cols = np.broadcast_to(gi[:, None, :], (ne, 2 * d, 2 * d))
        self._el_rows = rows.ravel()
        self._el_cols = cols.ravel()
        self._el_band = ((u + rows - cols) * self.N + cols).ravel()
        nd = np.arange(n)[:, None] * d + np.arange(d)[None, :]    # (n, d)
        nrows = np.broadcast_to(nd[:, :, None], (n, d, d))
        ncols = np.broadcast_to(nd[:, None, :], (n, d, d))
        self._nd_band = ((u + nrows - ncols) * self.N + ncols).ravel()
        self._nd_rows = nrows.ravel()
        self._nd_cols = ncols.ravel()
        self._band_size = (2 * u + 1) * self.N

        def el_matrix(blocks3: np.ndarray) -> np.ndarray:
            """Element (ne, d, d) densities ⊗ consistent weights -> (ne, 2d, 2d)."""
            return np.einsum("ab,eij->eaibj", _CONSISTENT, blocks3).reshape(ne, 2 * d, 2 * d)

        node_m = (mesh.node_mass + mesh.node_added_mass)[:, None, None] * I  # (n, d, d)
        mel = el_matrix(m_struct + m_add)
        self.M_band = self._band(mel, node_m)
        self.M_sparse = self._sparse(mel, node_m)
        self.free = slice(d, self.N - d)

    # ---- assembly helpers
    def _band(self, el: np.ndarray | None, nd: np.ndarray | None) -> np.ndarray:
        out = np.zeros(self._band_size)
        if el is not None:
            out += np.bincount(self._el_band, el.ravel(), minlength=self._band_size)
        if nd is not None:
            out += np.bincount(self._nd_band, nd.ravel(), minlength=self._band_size)
        return out.reshape(2 * self.u + 1, self.N)

    def _sparse(self, el: np.ndarray | None, nd: np.ndarray | None) -> sparse.csr_matrix:
        r, c, v = [], [], []
        if el is not None:
            r.append(self._el_rows); c.append(self._el_cols); v.append(el.ravel())
        if nd is not None:
            r.append(self._nd_rows); c.append(self._nd_cols); v.append(nd.ravel())
        return sparse.csr_matrix(
            (np.concatenate(v), (np.concatenate(r), np.concatenate(c))), shape=(self.N, self.N)
        )

    # ---- element kinematics and internal force
    def elements(self, X: np.ndarray):
        dx = X[1:] - X[:-1]
        l = np.sqrt(np.einsum("ij,ij->i", dx, dx))
        e = dx / l[:, None]
        strain = l / self.l0 - 1.0
        ea = np.where(strain >= 0.0, self.ea, SLACK_STIFFNESS_RATIO * self.ea)
        T = ea * strain
        return e, l, T, ea

    def internal_force(self, X: np.ndarray, e: np.ndarray, T: np.ndarray) -> np.ndarray:
        f = T[:, None] * e
        out = np.zeros_like(X)
        out[:-1] -= f
        out[1:] += f
        return out

    def stiffness_blocks(self, e: np.ndarray, l: np.ndarray, T: np.ndarray,
                         ea: np.ndarray) -> np.ndarray:
        d = self.dim
        ee = e[:, :, None] * e[:, None, :]
        k = (ea / self.l0)[:, None, None] * ee + (T / l)[:, None, None] * (np.eye(d)[None] - ee)
        out = np.empty((self.ne, 2, d, 2, d))
        out[:, 0, :, 0, :] = k
        out[:, 1, :, 1, :] = k
        out[:, 0, :, 1, :] = -k
        out[:, 1, :, 0, :] = -k
        return out.reshape(self.ne, 2 * d, 2 * d)

    # ---- drag, attachments and seabed
    def gauss_points(self, X: np.ndarray) -> np.ndarray:
        """Positions of the drag quadrature points, shape (ne, ng, X.shape[1]). [m]"""
        N = self.gauss_N
        return N[None, :, 0, None] * X[:-1, None, :] + N[None, :, 1, None] * X[1:, None, :]

    def drag(self, X: np.ndarray, V: np.ndarray, e: np.ndarray, u_fluid: np.ndarray,
             u_gauss: np.ndarray, jacobian: bool):
        """Drag nodal forces (n, d) and the element/node blocks of −∂F/∂u̇.

        ``u_fluid`` (n, d): fluid velocity at the nodes (attachment drag);
        ``u_gauss`` (ne, ng, d): fluid velocity at the element quadrature points.
        The element drag is the consistent load F_a = l0 Σ_g w_g N_a(ξ_g) f(v_r(ξ_g)),
        v_r(ξ_g) = u_gauss − (N_a u̇_a + N_b u̇_b); its velocity Jacobian
        −∂F_a/∂u̇_c = l0 Σ_g w_g N_a N_c ∂f/∂v_r uses the same quadrature.
        """
        d = self.dim
        F = np.zeros_like(X)
        c_el = None
        if np.any(self.cn) or np.any(self.ct):
            # relative velocity at the quadrature points: (ne, ng, d)
            w = u_gauss - self.gauss_points(V)
            s = np.einsum("egd,ed->eg", w, e)              # axial component
            wn = w - s[:, :, None] * e[:, None, :]
            mag = np.sqrt(np.einsum("egd,egd->eg", wn, wn) + _DRAG_EPS**2)
            f = (self.cn[:, None] * mag)[:, :, None] * wn + \
                (self.ct[:, None] * np.abs(s) * s)[:, :, None] * e[:, None, :]
            nodal = self.l0[:, None, None] * np.einsum(
                "g,ga,egd->ead", self.gauss_w, self.gauss_N, f)
            F[:-1] += nodal[:, 0]
            F[1:] += nodal[:, 1]
            if jacobian:
                P = np.eye(d)[None, None] - e[:, None, :, None] * e[:, None, None, :]
                J = (self.cn[:, None] * mag)[:, :, None, None] * P + \
                    (self.cn[:, None, None, None] * wn[:, :, :, None] * wn[:, :, None, :]
                     / mag[:, :, None, None]) + \
                    (2.0 * self.ct[:, None] * np.abs(s))[:, :, None, None] * \
                    (e[:, None, :, None] * e[:, None, None, :])      # (ne, ng, d, d)
                # block (a, c) = l0 Σ_g w_g N_a N_c J_g
                blk = np.einsum("gac,egij->eaicj", self._gauss_wNN, J)
                c_el = (self.l0[:, None, None] * blk.reshape(self.ne, 2 * d, 2 * d))
        c_nd = np.zeros((self.n, d, d)) if jacobian else None
        if np.any(self.node_cda):
            vr = u_fluid - V
            mag = np.sqrt(np.einsum("nd,nd->n", vr, vr) + _DRAG_EPS**2)
            F += (self.node_cda * mag)[:, None] * vr
            if jacobian:
                c_nd += (self.node_cda * mag)[:, None, None] * np.eye(d)[None] + \
                    self.node_cda[:, None, None] * vr[:, :, None] * vr[:, None, :] / mag[:, None, None]
        return F, c_el, c_nd

    def contact_blend(self, X: np.ndarray) -> np.ndarray:
        """Blend factor s(p/p₀) of every node (0 off the bed, 1 in full contact)."""
        x = np.clip((-self.depth - X[:, -1]) / self.pen0, 0.0, 1.0)
        return x * x * (3.0 - 2.0 * x)

    def seabed(self, X: np.ndarray, V: np.ndarray, s_damp: np.ndarray | None = None):
        """Seabed contact force (n, d), its stiffness −∂F_z/∂z and damping (n,).

        For a penetration p > 0 below z = −h, with the blending depth p₀ (the
        penetration under the line's own weight, w/(k·D)):

            F_z = k ∫₀ᵖ s(q/p₀) dq − c·s(p/p₀)·ż,   s(x) = 3x² − 2x³ (x < 1), 1 (x ≥ 1)

        i.e. k·(p − p₀/2) − c·ż beyond p₀: a one-sided penalty spring and dashpot (k, c
        per unit length = stiffness and damping per area × D) blended in smoothly so
        force and stiffness are continuous: a kink (or the jump c·ż when a node lands)
        makes Newton cycle.  Nodes resting on the bed
        (p = 1.5 p₀) have the full k and c, as the frequency-domain model's grounded
        nodes; the blend only shifts the resting depth by p₀/2 (millimetres).
        """
        pen = -self.depth - X[:, -1]
        p0 = self.pen0
        on = pen > 0.0
        full = pen >= p0
        x = np.clip(pen / p0, 0.0, 1.0)
        s = x * x * (3.0 - 2.0 * x)                      # smoothstep blend, C1
        spring = np.where(full, self.k_bed * (pen - 0.5 * p0),
                          self.k_bed * p0 * x**3 * (1.0 - 0.5 * x))   # k ∫₀ᵖ s
        kz = self.k_bed * s                              # ∂spring/∂p
        vz = V[:, -1]
        F = np.zeros_like(X)
        if s_damp is not None:
            # dashpot engagement taken from the start of the step (lagged one step)
            c = self.c_bed * s_damp
            F[:, -1] = spring - c * vz
            return F, kz, c
        c = self.c_bed * s
        F[:, -1] = spring - c * vz
        # K = −∂F_z/∂z = ∂F_z/∂p = kz − c_bed·(∂s/∂p)·ż
        dsdp = np.where(on & ~full, 6.0 * x * (1.0 - x) / p0, 0.0)
        return F, kz - self.c_bed * dsdp * vz, c


# --------------------------------------------------------------------------- statics


def _static_equilibrium(model: _LineModel, X: np.ndarray, u_current: np.ndarray,
                        u_current_gauss: np.ndarray, f_ref: float, tol: float,
                        max_iter: int = 200) -> tuple[np.ndarray, float]:
    """Newton (with backtracking) on the static residual of this model, from ``X``.

    The start is the statics module's solution; this re-solve removes the small
    differences of discretization (seabed penalty, drag distribution) so the dynamic
    start is an exact equilibrium of the equations integrated.
    """
    d = model.dim
    fr = model.free
    zeros = np.zeros_like(X)

    def residual(Xc):
        e, l, T, ea = model.elements(Xc)
        fd, _, _ = model.drag(Xc, zeros, e, u_current, u_current_gauss, jacobian=False)
        fb, kb, _ = model.seabed(Xc, zeros)
        r = model.internal_force(Xc, e, T) - model.f_gravity - fd - fb
        return r.ravel()[fr], (e, l, T, ea, kb)

    r, st = residual(X)
    rn = float(np.abs(r).max()) if r.size else 0.0
    for it in range(max_iter):
        if rn <= tol:
            return X, rn
        e, l, T, ea, kb = st
        kel = model.stiffness_blocks(e, l, np.maximum(T, 0.0), ea)
        knd = np.zeros((model.n, d, d))
        knd[:, -1, -1] = kb
        ab = model._band(kel, knd)[:, fr]
        # tiny mass-like regularization keeps slack/zero-tension starts solvable
        ab[model.u] += 1e-9 * np.abs(ab[model.u]).max()
        step = sla.solve_banded((model.u, model.u), ab, -r, check_finite=False)
        lam = 1.0
        for _ in range(30):
            Xn = X.copy()
            Xn.reshape(-1)[fr] += lam * step
            rn_new, st_new = None, None
            try:
                r_new, st_new = residual(Xn)
                rn_new = float(np.abs(r_new).max())
            except FloatingPointError:  # pragma: no cover
                rn_new = math.inf
            if np.isfinite(rn_new) and rn_new < rn:
                break
            lam *= 0.5
        X, r, rn, st = Xn, r_new, rn_new, st_new
    if rn > tol:
        raise ConvergenceError("time-domain static start (Newton)", max_iter, rn, tol,
                               hint="the statics solution is far from this model's "
                                    "equilibrium; check the seabed stiffness and current")
    return X, rn


def _statics_guess(scene: Scene, line: Line, mesh: LineMesh, statics: Any) -> np.ndarray:
    """Static node positions (n_nodes, 3) from the statics module (or a given result)."""
    if statics is None:
        from stochcable.line import statics as _st  # written by the statics helper

        res = _st.solve_statics(scene)
        ls = res.lines[line.name]
    elif hasattr(statics, "lines"):
        ls = statics.lines[line.name]
    else:
        ls = statics
    pos = np.asarray(ls.positions, dtype=float)
    if pos.shape != (mesh.n_nodes, 3):
        # a statics mesh with other nodes: interpolate along the unstretched arc length
        s_st = np.asarray(ls.mesh.s0, dtype=float)
        pos = np.stack([np.interp(mesh.s0, s_st, pos[:, k]) for k in range(3)], axis=1)
    return pos


# --------------------------------------------------------------------------- excitation


def _spectrum_density(spec: Any, g: float):
    """ω -> S(ω) with S(0) = 0 (as :mod:`stochcable.dynamics.line` samples it)."""
    def density(w: np.ndarray) -> np.ndarray:
        w = np.asarray(w, dtype=float)
        out = np.zeros_like(w)
        pos = w > 0
        out[pos] = spec.spectral_density(w[pos], g)
        return out

    return density


def _end_motion_generators(scene: Scene, seed: int) -> dict[tuple[str, str, str], Any]:
    """The generator of every end-motion spectrum channel, keyed (line, end, dof).

    The rule of :func:`stochcable.dynamics.line.simulate_timeseries`: channels in the order
    lines × (end_a, end_b) × (surge, sway, heave), channel k drawing from
    ``default_rng(SeedSequence(seed).spawn(n)[k])``.
    """
    keys = []
    for ln in scene.lines:
        for end in ("a", "b"):
            m = getattr(ln, "end_" + end).motion
            if m is None or m.rao is not None:
                continue
            keys += [(ln.name, end, dof) for dof in ("surge", "sway", "heave")
                     if getattr(m, dof) is not None]
    children = np.random.SeedSequence(int(seed)).spawn(len(keys)) if keys else []
    return {k: np.random.default_rng(c) for k, c in zip(keys, children)}


def _upsample(coeff: np.ndarray, n_t: int, k: int, dtype_factor: np.ndarray | None = None) -> np.ndarray:
    """irfft of coefficients (..., N+1) on a grid k times finer: shape (..., k·n_t)."""
    n_fine = k * n_t
    shape = coeff.shape[:-1] + (n_fine // 2 + 1,)
    big = np.zeros(shape, dtype=complex)
    big[..., : coeff.shape[-1]] = coeff
    big[..., n_t // 2] = 0.0  # the coarse Nyquist term (zero by construction)
    return _fft.irfft(big * k, n_fine)


def _wave_series(model: _LineModel, x_static: np.ndarray, omega: np.ndarray, X: np.ndarray,
                 heading: float, env: Environment, ax: np.ndarray, n_t: int, k_up: int,
                 sl: np.ndarray, r: np.ndarray):
    """Wave excitation on the simulation steps, ramped by ``r``.

    Returns the fluid velocity at the nodes (n_steps+1, n, d) (attachment drag), at
    the drag quadrature points (n_steps+1, ne, ng, d), and the wave-inertia nodal load
    (n_steps+1, N): per element l0·ρ(πD²/4)(1 + Can)(I − e₀e₀ᵀ)·∫₀¹ N_i a dξ with the
    exact element moments of :func:`stochcable.dynamics.loads.element_wave_kinematics`
    (the load of :func:`stochcable.dynamics.loads.wave_loads`), plus the attachments'
    (buoyancy/g + added mass)·a_node.  All are linear transfer functions per unit wave
    amplitude at the static positions, synthesized with the realization's coefficients.
    """
    from stochcable.dynamics.element_kinematics import element_wave_kinematics
    from stochcable.sea.kinematics import wave_kinematics

    pts = np.array(x_static, dtype=float)
    pts[:, 2] = np.maximum(pts[:, 2], -env.depth)  # nodes pressed into the seabed
    gp = model.gauss_points(pts).reshape(-1, 3)
    kin = wave_kinematics(omega, np.vstack([pts, gp]), heading, env.depth, env.g)
    vel = np.einsum("pcw,cd->pdw", kin.velocity, ax)           # (n + ne·ng, d, n_w)
    acc_n = np.einsum("ncw,cd->ndw", kin.acceleration[: model.n], ax)
    el = element_wave_kinematics(omega, pts, heading, env.depth, env.g)
    mom = el.acceleration @ ax                                  # (n_w, ne, 2, d)
    f_el = np.einsum("eij,wesj->wesi", model.inertia_el, mom)  # (n_w, ne, 2, d)
    f_nodes = np.zeros((omega.size, model.n, model.dim), dtype=complex)
    f_nodes[:, :-1] += f_el[:, :, 0]
    f_nodes[:, 1:] += f_el[:, :, 1]
    f_nodes += model.node_mw[None, :, None] * np.moveaxis(acc_n, 2, 0)
    coeff = np.concatenate([vel, np.moveaxis(f_nodes, 0, 2)], axis=0) * X  # (p, d, n_w)
    series = _upsample(coeff, n_t, k_up)[..., sl] * r             # (p, d, n_steps+1)
    series = np.moveaxis(series, 2, 0)                             # (n_steps+1, p, d)
    n, ne = model.n, model.ne
    u_nodes = series[:, :n]
    u_gauss = series[:, n:n + gp.shape[0]].reshape(-1, ne, model.gauss_xi.size, model.dim)
    f_in = np.ascontiguousarray(series[:, n + gp.shape[0]:]).reshape(-1, model.N)
    return u_nodes, u_gauss, f_in


def _half_cosine(t: np.ndarray, t_r: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    if t_r <= 0.0:
        one = np.ones_like(t)
        return one, np.zeros_like(t), np.zeros_like(t)
    x = np.clip(t / t_r, 0.0, 1.0)
    inside = t < t_r
    r = np.where(inside, 0.5 * (1.0 - np.cos(math.pi * x)), 1.0)
    r1 = np.where(inside, 0.5 * math.pi / t_r * np.sin(math.pi * x), 0.0)
    r2 = np.where(inside, 0.5 * (math.pi / t_r) ** 2 * np.cos(math.pi * x), 0.0)
    return r, r1, r2


def _omega_quantile(omega: np.ndarray, power: np.ndarray, q: float) -> float:
    tot = power.sum()
    if tot <= 0.0:
        return 0.0
    c = np.cumsum(power) / tot
    return float(omega[min(int(np.searchsorted(c, q)), omega.size - 1)])


# --------------------------------------------------------------------------- public


def simulate_line_timedomain(
    scene: Scene | dict | str,
    line_name: str | None = None,
    *,
    realization: Any = None,
    duration: float | None = None,
    dt: float | None = None,
    seed: int | None = None,
    ramp: float | None = None,
    method: str | None = None,
    statics: Any = None,
    dim: int | None = None,
    tolerance: float = 1e-7,
    max_iterations: int = 30,
    element_every: int = 1,
    end_realizations: dict | None = None,
    band: tuple[float, float] | None = None,
) -> CableTimeHistory:
    """Nonlinear time-domain response of one line to the scene's sea and end motions.

    Parameters
    ----------
    scene : Scene, mapping or JSON
        The scene document.
    line_name : str, optional
        Which line (default: the first). [-]
    realization : SeaRealization, optional
        The sea realization to use (the same one the frequency-domain analysis
        synthesizes from).  Default: ``simulate_sea`` of the scene's spectrum with
        ``duration``, the scene's time-series ``dt`` and ``seed``. [-]
    duration : float, optional
        Simulated length, at most the realization's length (default: the
        realization's length, or the scene's time-series duration, else 600 s). [s]
    dt : float, optional
        Integration step; the realization's step is divided by the smallest integer k
        with Δt_sea/k <= dt (default: the largest step keeping the period error
        (ωΔt)²/12 at the highest excitation frequency below 0.5 %). [s]
    seed : int, optional
        Seed of the realization(s) (default: the scene's time-series seed, else 1). [-]
    ramp : float, optional
        Half-cosine ramp length of the excitation (default 3 peak periods). [s]
    method : {"dsa", "nsa"}, optional
        Spectral amplitude method of new realizations (default: the scene's, else DSA). [-]
    statics : StaticsResult or LineStatics, optional
        Static solution to start from (default: ``statics.solve_statics(scene)``). [-]
    dim : {2, 3}, optional
        Model dimension (default 2 when the scene is planar, else 3). [-]
    tolerance : float, default 1e-7
        Newton tolerance on max |residual| relative to the largest static tension. [-]
    max_iterations : int, default 30
        Newton iterations per step before a ConvergenceError. [-]
    element_every : int, default 1
        Store the element tensions every this many steps. [-]
    end_realizations : dict, optional
        Pre-computed end-motion coefficient arrays ``{"a"|"b": (3, N+1) complex}`` on
        the realization's grid (overrides the scene's end motions). [m]
    band : (float, float), optional
        Keep only the excitation components with band[0] <= ω <= band[1]; the
        frequency-domain analysis synthesizes its series on its ``omega`` range, so
        ``band=(omega.min, omega.max)`` reproduces its excitation exactly.  Default:
        every component of the realization. [rad/s]

    Returns
    -------
    CableTimeHistory
        Positions, tensions and Newton record.

    Raises
    ------
    InputError
        Unknown line, non-integer step ratio, duration beyond the realization.
    ConvergenceError
        Newton did not converge in a step (the message gives step, time, residual).

    Warns
    -----
    ResolutionWarning
        When (ωΔt)²/12 at the highest excitation frequency (99 % of the excitation
        variance below it) exceeds 1 %; when the record after the ramp is not
        stationary (:meth:`CableTimeHistory.stationarity_ratio` above
        :data:`NONSTATIONARY_RATIO`: a numerical blow-up, e.g. of a 3-element slack line
        at Δt = 0.125 s, seeds 3 and 6 of tuah_1982_single_leg).

    Notes
    -----
    Newmark average acceleration (seed 001 eqs. 4.2.7a,b) with Newton iterations
    (eqs. 4.2.8–4.2.11, but with the full tangent re-formed at every iteration) on the
    element equations of seed §3.1 and the Morison loads of eqs. 3.2.a.2–3.2.a.5.  See
    the module docstring for the modelling choices.
    """
    from stochcable.sea import realization as _sea

    scene = load_scene(scene)
    if line_name is None:
        line = scene.lines[0]
    else:
        names = [ln.name for ln in scene.lines]
        if line_name not in names:
            raise InputError("line_name", line_name, "-", f"must be one of {names}")
        line = scene.lines[names.index(line_name)]
    env = scene.environment
    ts = scene.analysis.timeseries
    tolerance = _v.positive("tolerance", tolerance, "-")
    max_iterations = _v.positive_int("max_iterations", max_iterations)
    element_every = _v.positive_int("element_every", element_every)
    if dim is None:
        dim = 2 if scene.is_planar else 3
    if dim not in (2, 3):
        raise InputError("dim", dim, "-", "must be 2 or 3")
    if seed is None:
        seed = ts.seed if ts is not None else 1
    method = method or (ts.method if ts is not None else "dsa")

    # ---- the realization grid -------------------------------------------------------
    if realization is not None:
        if not isinstance(realization, _sea.SeaRealization):
            raise InputError("realization", type(realization).__name__, "-",
                             "must be a SeaRealization")
        t_l, dt_sea, n_t = realization.duration, realization.dt, realization.n_samples
        omega = np.asarray(realization.omega)
    else:
        t_l = _v.positive("duration", duration, "s") if duration is not None else \
            (ts.duration if ts is not None else 600.0)
        dt_sea = ts.dt if ts is not None else (dt if dt is not None else 0.25)
        dt_sea = _v.positive("dt", dt_sea, "s")
        n_t = 2 * max(1, int(math.ceil(t_l / dt_sea / 2.0 - 1e-9)))
        t_l = n_t * dt_sea
        omega = 2.0 * math.pi / t_l * np.arange(n_t // 2 + 1)
        if scene.sea is not None:
            realization = _sea.simulate_sea(_spectrum_density(scene.sea.spectrum, env.g),
                                            t_l, dt_sea, method, rng=int(seed))
    sim_len = t_l if duration is None else _v.positive("duration", duration, "s")
    if sim_len > t_l * (1 + 1e-9):
        raise InputError("duration", duration, "s",
                         f"must be <= the realization's length {t_l:g} s")

    # ---- end motion coefficients on the grid ----------------------------------------
    ends: dict[str, np.ndarray] = {}
    if end_realizations is not None:
        for k_, v_ in end_realizations.items():
            arr = np.asarray(v_, dtype=complex)
            if k_ not in ("a", "b") or arr.shape != (3, omega.size):
                raise InputError(f"end_realizations[{k_!r}]", f"shape {arr.shape}", "m",
                                 f"keys must be 'a' or 'b' and values of shape (3, "
                                 f"{omega.size}) on the realization's grid")
            ends[k_] = arr
    else:
        gens = _end_motion_generators(scene, int(seed))
        for key, end in (("a", line.end_a), ("b", line.end_b)):
            m = end.motion
            c = np.zeros((3, omega.size), dtype=complex)
            for k_, dof in enumerate(("surge", "sway", "heave")):
                gen = gens.get((line.name, key, dof))
                if gen is None:
                    continue
                r = _sea.simulate_sea(_spectrum_density(getattr(m, dof), env.g), t_l, dt_sea,
                                      method, rng=gen)
                c[k_] = r.coefficients
            if m is not None and m.rao is not None:
                if realization is None:
                    raise InputError(f"{line.name}.{'end_' + key}.motion.rao", "rao", "-",
                                     "needs a sea (the RAO multiplies the sea's amplitudes)")
                c = m.rao.transfer(omega) * np.asarray(realization.coefficients)[None]
            if np.any(c):
                ends[key] = c
    keep = np.ones(omega.size)
    if band is not None:
        lo = _v.nonnegative("band[0]", band[0], "rad/s")
        hi = _v.positive("band[1]", band[1], "rad/s")
        if hi <= lo:
            raise InputError("band", band, "rad/s", "must be (low, high) with high > low")
        keep = ((omega >= lo) & (omega <= hi)).astype(float)
        ends = {k_: c * keep for k_, c in ends.items()}
    X_sea = None if realization is None else np.asarray(realization.coefficients) * keep
    if realization is None and not ends:
        raise InputError("scene", "no sea and no end motion", "-",
                         "needs a sea or a prescribed end motion to excite the line")

    # ---- highest excitation frequency and the step ------------------------------------
    power = np.zeros(omega.size)
    wmax = 0.0
    chans = [X_sea] if X_sea is not None else []
    chans += [c for v_ in ends.values() for c in v_]
    for c in chans:
        p = np.abs(c) ** 2
        if p.sum() > 0:
            wmax = max(wmax, _omega_quantile(omega, p, _ENERGY_QUANTILE))
            power = power + p / p.sum()
    w_peak = float(omega[int(np.argmax(power))]) if power.any() else 1.0
    if dt is None:
        # (ωΔt)²/12 <= 0.5 %  ->  ωΔt <= 0.245
        dt_target = 0.245 / wmax if wmax > 0 else dt_sea
    else:
        dt_target = _v.positive("dt", dt, "s")
    k_up = max(1, int(math.ceil(dt_sea / dt_target - 1e-9)))
    h = dt_sea / k_up
    err = newmark_period_error(wmax, h)
    if err > PERIOD_ERROR_TOLERANCE:
        dt_ok = 2.0 * math.sqrt(3.0 * PERIOD_ERROR_TOLERANCE) / wmax
        warn(
            f"time step {h:.4g} s gives a Newmark period error (omega dt)^2/12 = {err:.2%} "
            f"at the highest excitation frequency {wmax:.4g} rad/s (> "
            f"{PERIOD_ERROR_TOLERANCE:.0%}); use dt <= {dt_ok:.4g} s",
            ResolutionWarning, stacklevel=2)
    n_steps = int(round(sim_len / h))
    t = h * np.arange(n_steps + 1)
    if ramp is None:
        ramp = 3.0 * 2.0 * math.pi / w_peak if w_peak > 0 else 0.0
    ramp = _v.nonnegative("ramp", ramp, "s")
    if ramp >= sim_len:
        raise InputError("ramp", ramp, "s", f"must be shorter than the duration {sim_len:g} s")

    # ---- model and static start -----------------------------------------------------
    mesh = mesh_line(line, env.rho, env.g)
    ax = _axes(dim)
    x3 = _statics_guess(scene, line, mesh, statics)
    model0 = _LineModel(mesh, env, x3 @ ax, dim)
    u_cur = env.current_velocity(x3[:, 2]) @ ax                     # (n, d)
    # current at the drag quadrature points (of the statics shape; the profile is
    # interpolated in z, the points move millimetres in the re-solve)
    u_cur_g = env.current_velocity(model0.gauss_points(x3)[..., 2]) @ ax   # (ne, ng, d)
    e0, _, T0, _ = model0.elements(x3 @ ax)
    f_ref = max(float(np.abs(T0).max()), float(np.abs(model0.f_gravity).max()), 1e-12)
    tol_abs = tolerance * f_ref
    xs, _ = _static_equilibrium(model0, x3 @ ax, u_cur, u_cur_g, f_ref,
                                max(1e-3 * tol_abs, 1e-11 * f_ref))
    model = _LineModel(mesh, env, xs, dim)  # added mass about the re-solved tangents

    # ---- excitation time series on the fine grid ------------------------------------
    r, r1, r2 = _half_cosine(t, ramp)
    n_fine = k_up * n_t
    sl = np.arange(n_steps + 1) % n_fine  # the realization is periodic in T_L
    u_wave = None
    u_wave_g = None
    f_in = None
    x_static_3 = xs @ ax.T
    if realization is not None:
        u_wave, u_wave_g, f_in = _wave_series(model, x_static_3, omega, X_sea, scene.sea.heading_rad,
                                              env, ax, n_t, k_up, sl, r)
    end_disp = {}
    for key, c in ends.items():
        node = 0 if key == "a" else mesh.n_nodes - 1
        xyz = _upsample(np.stack([c, 1j * omega * c, -(omega**2) * c]), n_t, k_up)[..., sl]
        x_, v_, a_ = (np.einsum("ct,cd->td", xyz[j], ax) for j in range(3))
        # ramped motion r·x with its exact derivatives
        xr = r[:, None] * x_
        vr = r[:, None] * v_ + r1[:, None] * x_
        ar = r[:, None] * a_ + 2.0 * r1[:, None] * v_ + r2[:, None] * x_
        end_disp[node] = (xr, vr, ar)

    hist = _integrate(model, xs, u_cur, u_cur_g, u_wave, u_wave_g, f_in, end_disp, t, h,
                      tol_abs,
                      max_iterations, element_every)
    pos, ten_el, iters, maxres = hist
    pos3 = pos @ ax.T + (0.0 if dim == 3 else np.array([0.0, 1.0, 0.0]) * x3[0, 1])
    xs3 = xs @ ax.T + (0.0 if dim == 3 else np.array([0.0, 1.0, 0.0]) * x3[0, 1])
    _, _, Ts, _ = model.elements(xs)
    out = CableTimeHistory(
        line=line.name, t=t, positions=pos3, static_positions=xs3,
        tension_a=ten_el[0], tension_b=ten_el[1],
        element_tension=ten_el[2], element_time=t[::element_every],
        static_tension=Ts, iterations=iters, max_residual=maxres, tolerance=tol_abs,
        dt=h, ramp=ramp, s0=mesh.s0,
        _meta={"omega_max": wmax, "omega_peak": w_peak, "upsample": k_up, "dim": dim,
               "realization": realization, "ends": ends, "model": model},
    )
    ratio, t_jump, w_dom = out.stationarity_ratio()
    if ratio > NONSTATIONARY_RATIO:
        dt_ok = 2.0 * math.sqrt(3.0 * PERIOD_ERROR_TOLERANCE) / max(w_dom, 1e-12)
        warn(
            f"the end tension is not stationary: its σ over windows after the ramp varies "
            f"by a factor {ratio:.3g} (threshold {NONSTATIONARY_RATIO:g}), largest in the "
            f"window from t = {t_jump:.4g} s, dominated by {w_dom:.4g} rad/s (omega dt = "
            f"{w_dom * h:.3g}, period error {newmark_period_error(w_dom, h):.0%}): an "
            "under-resolved oscillation pumped by the time stepping (typically at "
            f"slack–taut snaps), not the response; rerun with dt <= {dt_ok:.3g} s or at "
            "least a quarter of the present step",
            ResolutionWarning, stacklevel=2)
    return out


def _integrate(model: _LineModel, xs: np.ndarray, u_cur: np.ndarray, u_cur_g: np.ndarray,
               u_wave, u_wave_g, f_in, end_disp: dict, t: np.ndarray, h: float, tol: float,
               max_it: int, every: int):
    """Newmark average acceleration with Newton iterations (seed 001 eqs. 4.2.7–4.2.11)."""
    d, n, N = model.dim, model.n, model.N
    fr = model.free
    nf = N - 2 * d
    nt = t.size
    u_b = model.u
    pos = np.empty((nt, n, d))
    ten_a = np.empty(nt)
    ten_b = np.empty(nt)
    ten_el = np.empty(((nt - 1) // every + 1, model.ne))
    iters = np.zeros(nt, dtype=int)
    X = xs.copy()
    V = np.zeros_like(X)
    A = np.zeros_like(X)
    pos[0] = X
    e, _, T, _ = model.elements(X)
    fd0, _, _ = model.drag(X, V, e, u_cur, u_cur_g, jacobian=False)
    fb0, _, _ = model.seabed(X, V)
    R0 = (model.internal_force(X, e, T) - model.f_gravity - fd0 - fb0).reshape(-1)
    # An end node resting on the seabed: the bed carries the load lumped on it, so the
    # end tension is the line's own end force, as in the statics (stochcable.line.statics).
    fgr = model.f_gravity.reshape(n, d)
    zbed_tol = 1e-9 * max(model.depth, 1.0)
    carry_a = fgr[0] if xs[0, -1] <= -model.depth + zbed_tol else np.zeros(d)
    carry_b = fgr[-1] if xs[-1, -1] <= -model.depth + zbed_tol else np.zeros(d)
    ten_a[0] = np.linalg.norm(R0[:d] + carry_a)
    ten_b[0] = np.linalg.norm(R0[N - d:] + carry_b)
    ten_el[0] = T
    M_band_f = model.M_band[:, fr]
    M = model.M_sparse
    fg = model.f_gravity
    c1, c2 = 4.0 / h**2, 2.0 / h
    maxres = 0.0
    xs_flat = xs.reshape(-1)
    # initial acceleration: static start with zero excitation at t = 0 -> A = 0, except a
    # prescribed end acceleration (zero with the half-cosine ramp); keep A = 0.
    for k in range(1, nt):
        Xp, Vp, Ap = X.reshape(-1).copy(), V.reshape(-1).copy(), A.reshape(-1).copy()
        # prescribed ends at t_k
        Xn = xs_flat.copy()
        Vn = np.zeros(N)
        An = np.zeros(N)
        for node, (xe, ve, ae) in end_disp.items():
            sl = slice(node * d, node * d + d)
            Xn[sl] += xe[k]
            Vn[sl] = ve[k]
            An[sl] = ae[k]
        uf = u_cur if u_wave is None else u_cur + u_wave[k]
        ug = u_cur_g if u_wave_g is None else u_cur_g + u_wave_g[k]
        fi = None if f_in is None else f_in[k]
        s_bed = model.contact_blend(X)

        def residual(du: np.ndarray, jac: bool):
            """Residual of the step for the free increment ``du`` (eqs. 4.2.7a,b)."""
            Xn[fr] = Xp[fr] + du
            Vn[fr] = c2 * du - Vp[fr]
            An[fr] = c1 * du - 2.0 * c2 * Vp[fr] - Ap[fr]
            Xm = Xn.reshape(n, d)
            Vm = Vn.reshape(n, d)
            e, l, T, ea = model.elements(Xm)
            fd, c_el, c_nd = model.drag(Xm, Vm, e, uf, ug, jacobian=jac)
            fb, kb, cb = model.seabed(Xm, Vm, s_bed)
            R = (M @ An) + (model.internal_force(Xm, e, T) - fg - fd - fb).reshape(-1)
            if fi is not None:
                R -= fi
            rn = float(np.abs(R[fr]).max()) if nf else 0.0
            return rn, R, T, (e, l, ea, c_el, c_nd, kb, cb)

        def norm2(R: np.ndarray) -> float:
            return float(np.dot(R[fr], R[fr]))

        # predictor (constant acceleration) for the free DOFs
        du = h * Vp[fr] + 0.25 * h * h * Ap[fr]
        rn, R, T, st = residual(du, True)
        res_hist = [rn]
        it = 0
        while rn > tol:
            if it >= max_it:
                raise ConvergenceError(
                    f"time-domain Newton at step {k} (t = {t[k]:.6g} s)", it, rn, tol,
                    hint=f"reduce dt (now {h:.4g} s) or check the excitation amplitude",
                    partial={"t": t[:k], "positions": pos[:k], "residuals": res_hist,
                             "worst_dof": int(np.argmax(np.abs(R[fr]))) + d})
            e, l, ea, c_el, c_nd, kb, cb = st
            kel = model.stiffness_blocks(e, l, T, ea)
            if c_el is not None:
                kel = kel + c2 * c_el
            c_nd[:, -1, -1] += c2 * cb + kb
            ab = model._band(kel, c_nd)[:, fr] + c1 * M_band_f
            ddu = sla.solve_banded((u_b, u_b), ab, -R[fr], check_finite=False)
            # backtracking: the one-sided seabed and slack elements make the residual
            # nonsmooth; halve the correction until the residual decreases
            lam = 1.0
            r2 = norm2(R)
            for _ in range(_BACKTRACK):
                rn_new, R_new, T_new, st_new = residual(du + lam * ddu, True)
                if rn_new <= tol or norm2(R_new) < r2 or lam < 2.0 ** (1 - _BACKTRACK):
                    break
                lam *= 0.5
            du = du + lam * ddu
            rn, R, T, st = rn_new, R_new, T_new, st_new
            res_hist.append(rn)
            it += 1
        maxres = max(maxres, rn)
        iters[k] = it
        X, V, A = Xn.reshape(n, d).copy(), Vn.reshape(n, d).copy(), An.reshape(n, d).copy()
        pos[k] = X
        # support reactions: the residual rows of the prescribed end nodes
        ten_a[k] = np.linalg.norm(R[:d] + carry_a)
        ten_b[k] = np.linalg.norm(R[N - d:] + carry_b)
        if k % every == 0:
            ten_el[k // every] = T
    return pos, (ten_a, ten_b, ten_el), iters, maxres
