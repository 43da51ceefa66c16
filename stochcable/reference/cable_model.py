"""The nonlinear finite-element model of one line for the time-domain reference
(:mod:`stochcable.reference.cable`): element forces and tangents, drag, seabed contact,
and the static start of this same model.

Model (the same finite-element discretization as the frequency-domain model):

- 2-node straight elements (:func:`stochcable.line.mesh.mesh_line`), geometrically exact
  elastic bar: with current length l, unstretched l0 and unit vector e, the effective
  tension is T = EA (l/l0 − 1); a slack element (l < l0) keeps the small stiffness
  ε·EA (ε = :data:`SLACK_STIFFNESS_RATIO`), so T → 0⁻ instead of a compression strut.
  Tangent stiffness K_e = [(EA/l0) e eᵀ + (T/l)(I − e eᵀ)] ⊗ [[1, −1], [−1, 1]]
  (DESIGN.md; Tuah (1982), eqs. 3.1.8–3.1.11).
- Consistent mass m l0 [[1/3, 1/6], [1/6, 1/3]] ⊗ I (Tuah (1982), eq. 3.1.12) plus the normal
  added mass Can ρ (πD²/4) l0 [[1/3, 1/6], [1/6, 1/3]] ⊗ (I − e₀e₀ᵀ) and attachment
  masses.  The added mass is evaluated about the *static* tangents e₀ so the mass
  matrix is constant (as in the frequency-domain model).
- Net weight (gravity minus buoyancy) per length and attachment weight/buoyancy as in
  the statics (elements above z = 0 keep the submerged weight); a one-sided seabed
  penalty spring k·D and dashpot c·D per unit length (per unit contact area times the
  diameter, as MoorDyn's kBot, cBot) on nodes below z = −h, lumped over the node's
  tributary length, blended in smoothly over the static penetration p₀ = w/(kD)
  (:meth:`LineModel.seabed`), the dashpot's engagement lagged by one step: a kinked
  contact law makes Newton cycle when a node lands within a step.
- Wave loads use the load model of the frequency-domain analysis
  (:func:`stochcable.dynamics.loads.channels.wave_loads`), the wave kinematics taken at the
  *static* positions (linear wave theory; the error is second order in the motion;
  zero above z = 0):

  * wave inertia (linear in the kinematics) — **exact** along each straight element:
    node i of element j gets l0_j ρ(πD²/4)(1 + Can)(I − e₀e₀ᵀ)·∫₀¹ N_i a dξ with the
    closed-form consistent moments of
    :func:`stochcable.dynamics.loads.element_kinematics.element_wave_kinematics` (split at the
    waterline), synthesized in time with the realization's coefficients like any transfer
    function; attachments get (buoyancy/g + added mass)·a at their node.
  * Morison drag with the relative velocity v_r = U_current + v_wave − u̇ − c e (c e:
    the transport of a travelling line, :mod:`~stochcable.reference.cable_transport`;
    Tuah (1982), eqs. 3.2.a.2–3.2.a.5), normal ½ρ Cdn D |v_rn| v_rn and axial
    ½ρ Cdt πD |v_rt| v_rt with
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

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from scipy import linalg as sla
from scipy import sparse

from stochcable.errors import ConvergenceError
from stochcable.line.mesh import LineMesh
from stochcable.reference.cable_transport import lift_nodal_forces, transport_terms
from stochcable.scene.model import Environment, Line, Scene
from stochcable.statics import solve_statics

__all__ = [
    "SLACK_STIFFNESS_RATIO",
    "GAUSS_POINTS",
    "CONSISTENT",
    "LUMPED",
    "DRAG_EPS",
    "axes",
    "LineModel",
    "static_equilibrium",
    "statics_guess",
]

SLACK_STIFFNESS_RATIO = 1e-6
"""Fraction of EA kept by a slack (compressed) element. [-]"""

GAUSS_POINTS = 3
"""Gauss–Legendre points per element of the drag quadrature. [-]"""

CONSISTENT = np.array([[1.0 / 3.0, 1.0 / 6.0], [1.0 / 6.0, 1.0 / 3.0]])
"""Consistent-mass weights of a linear element, ∫N_a N_c dξ. [-]"""

LUMPED = np.array([[0.5, 0.0], [0.0, 0.5]])
"""Lumped-mass weights (half of the element on each node, as MoorDyn's nodes). [-]"""

DRAG_EPS = 1e-9
"""Regularization of |v| in the drag and its Jacobian. [m/s]"""


def axes(dim: int) -> np.ndarray:
    """Columns: the global unit vectors of the model's coordinates (3, dim)."""
    if dim == 3:
        return np.eye(3)
    return np.array([[1.0, 0.0], [0.0, 0.0], [0.0, 1.0]])


class LineModel:
    """The discrete equations of one line; everything vectorized over elements.

    Arrays: X, V, A of shape (n_nodes, dim); the DOF of node i, coordinate c is i·dim + c.
    """

    def __init__(
        self,
        mesh: LineMesh,
        env: Environment,
        x_static: np.ndarray,
        dim: int,
        internal_damping: float = 0.0,
        lumped_mass: bool = False,
    ):
        self.mesh = mesh
        self.dim = d = dim
        self.n = n = mesh.n_nodes
        self.ne = ne = mesh.n_elements
        self.N = n * d
        self.l0 = mesh.l0
        self.ea = mesh.ea
        # axial internal damping BA [N·s] per element: T_d = BA·(dl/dt)/l0 (MoorDyn's)
        self.ba = np.full(ne, float(internal_damping))
        self.rho = env.rho
        self.g = env.g
        self.depth = env.depth
        area = math.pi * mesh.diameter**2 / 4.0
        self.cn = 0.5 * env.rho * mesh.cd_normal * mesh.diameter  # [kg/m²]
        self.ct = 0.5 * env.rho * mesh.cd_axial * math.pi * mesh.diameter
        self.node_cda = 0.5 * env.rho * mesh.node_drag_area  # [kg/m]
        trib = np.zeros(n)
        trib[:-1] += 0.5 * mesh.l0
        trib[1:] += 0.5 * mesh.l0
        trib_d = np.zeros(n)
        trib_d[:-1] += 0.5 * mesh.l0 * mesh.diameter
        trib_d[1:] += 0.5 * mesh.l0 * mesh.diameter
        self.k_bed = env.seabed.stiffness * trib_d  # [N/m] per node
        self.c_bed = env.seabed.damping * trib_d  # [N·s/m] per node
        # static penetration of a grounded node under its weight: w·L / (k·D·L)
        w_node = np.zeros(n)
        w_node[:-1] += 0.5 * np.abs(mesh.weight) * mesh.l0
        w_node[1:] += 0.5 * np.abs(mesh.weight) * mesh.l0
        with np.errstate(divide="ignore", invalid="ignore"):
            pen0 = np.where(self.k_bed > 0, w_node / self.k_bed, 0.0)
        self.pen0 = np.maximum(pen0, 1e-6 * max(1.0, float(np.sum(mesh.l0)) * 1e-3))
        ax = axes(d)
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
        self.inertia_el = mw  # (ne, d, d)
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
        self.u = u = 2 * d - 1  # half bandwidth
        loc = np.arange(2 * d)
        gi = np.arange(ne)[:, None] * d + loc[None, :]  # (ne, 2d)
        rows = np.broadcast_to(gi[:, :, None], (ne, 2 * d, 2 * d))
        cols = np.broadcast_to(gi[:, None, :], (ne, 2 * d, 2 * d))
        self._el_rows = rows.ravel()
        self._el_cols = cols.ravel()
        self._el_band = ((u + rows - cols) * self.N + cols).ravel()
        nd = np.arange(n)[:, None] * d + np.arange(d)[None, :]  # (n, d)
        nrows = np.broadcast_to(nd[:, :, None], (n, d, d))
        ncols = np.broadcast_to(nd[:, None, :], (n, d, d))
        self._nd_band = ((u + nrows - ncols) * self.N + ncols).ravel()
        self._nd_rows = nrows.ravel()
        self._nd_cols = ncols.ravel()
        self._band_size = (2 * u + 1) * self.N

        def el_matrix(blocks3: np.ndarray) -> np.ndarray:
            """Element (ne, d, d) densities ⊗ consistent weights -> (ne, 2d, 2d)."""
            weights = LUMPED if lumped_mass else CONSISTENT
            return np.einsum("ab,eij->eaibj", weights, blocks3).reshape(ne, 2 * d, 2 * d)

        node_m = (mesh.node_mass + mesh.node_added_mass)[:, None, None] * I  # (n, d, d)
        mel = el_matrix(m_struct + m_add)
        self.M_band = self.band_matrix(mel, node_m)
        self.M_sparse = self.sparse_matrix(mel, node_m)
        self.free = slice(d, self.N - d)
        # controlled-experiment variants (set_variant); defaults: the nonlinear model
        self.drag_tangent = "instantaneous"
        self.linear_drag: tuple[np.ndarray, np.ndarray] | None = None
        self.bed_linear: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None = None
        # a travelling line (reference.cable_transport): the material velocity u̇ + c e
        self.speed = float(getattr(mesh, "axial_speed", 0.0))
        self.transport = transport_terms(self, self.speed) if self.speed else None

    def set_variant(
        self,
        drag: str = "quadratic",
        linear_drag: tuple[np.ndarray, np.ndarray] | None = None,
        seabed: str = "one_sided",
    ) -> None:
        """Switch terms of the model to their linear (frequency-domain) form.

        Parameters
        ----------
        drag : {"quadratic", "static_tangent", "linear"}
            Morison drag with the instantaneous element tangent (the default), with the
            static tangent e₀ (the frequency-domain model's normal/axial split), or
            linear: f = B_n (I − e₀e₀ᵀ) v_r + B_t e₀e₀ᵀ v_r with ``linear_drag``. [-]
        linear_drag : (ndarray, ndarray), optional
            (B_n, B_t) per element for ``drag="linear"`` (e.g. the frequency-domain
            analysis' converged ``linearization.b_normal``/``b_axial``). [N·s/m²]
        seabed : {"one_sided", "linear"}
            The one-sided penalty bed (default) or its tangent at the static start,
            bilateral (spring and dashpot frozen at the static contact). [-]
        """
        self.drag_tangent = "static" if drag in ("static_tangent", "linear") else "instantaneous"
        if drag == "linear":
            b_n, b_t = (np.asarray(b, dtype=float) for b in linear_drag)
            self.linear_drag = (b_n, b_t)
        if seabed == "linear":
            zeros = np.zeros_like(self.x_static)
            f0, k0, c0 = self.seabed(self.x_static, zeros)
            self.bed_linear = (f0[:, -1].copy(), k0.copy(), c0.copy(), self.x_static[:, -1].copy())

    # ---- assembly helpers
    def band_matrix(self, el: np.ndarray | None, nd: np.ndarray | None) -> np.ndarray:
        """Element (ne, 2d, 2d) and node (n, d, d) blocks assembled in LAPACK band
        storage, shape (2u + 1, N)."""
        out = np.zeros(self._band_size)
        if el is not None:
            out += np.bincount(self._el_band, el.ravel(), minlength=self._band_size)
        if nd is not None:
            out += np.bincount(self._nd_band, nd.ravel(), minlength=self._band_size)
        return out.reshape(2 * self.u + 1, self.N)

    def sparse_matrix(self, el: np.ndarray | None, nd: np.ndarray | None) -> sparse.csr_matrix:
        """The same blocks assembled as a sparse (N, N) matrix."""
        r, c, v = [], [], []
        if el is not None:
            r.append(self._el_rows)
            c.append(self._el_cols)
            v.append(el.ravel())
        if nd is not None:
            r.append(self._nd_rows)
            c.append(self._nd_cols)
            v.append(nd.ravel())
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

    def damping_tension(self, V: np.ndarray, e: np.ndarray) -> np.ndarray | None:
        """Internal (axial) damping tension T_d = BA·e·(v_b − v_a)/l0 of every element,
        None without internal damping. [N]"""
        if not np.any(self.ba):
            return None
        dv = V[1:] - V[:-1]
        return self.ba / self.l0 * np.einsum("ij,ij->i", e, dv)

    def damping_blocks(self, e: np.ndarray) -> np.ndarray | None:
        """Element blocks of ∂(T_d forces)/∂u̇: (BA/l0) e eᵀ ⊗ [[1, −1], [−1, 1]] (the
        rotation of e left out, as for the drag), None without internal damping."""
        if not np.any(self.ba):
            return None
        zero = np.zeros_like(self.ba)
        return self.stiffness_blocks(e, np.ones_like(self.ba), zero, self.ba)

    def stiffness_blocks(
        self, e: np.ndarray, l: np.ndarray, T: np.ndarray, ea: np.ndarray
    ) -> np.ndarray:
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

    def drag(
        self,
        X: np.ndarray,
        V: np.ndarray,
        e: np.ndarray,
        u_fluid: np.ndarray,
        u_gauss: np.ndarray,
        jacobian: bool,
    ):
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
        if self.drag_tangent == "static":
            dx0 = np.diff(self.x_static, axis=0)
            e = dx0 / np.linalg.norm(dx0, axis=1)[:, None]
        if self.linear_drag is not None:
            F, c_el = self._linear_drag(V, e, u_gauss, jacobian)
        elif np.any(self.cn) or np.any(self.ct):
            # relative velocity at the quadrature points: (ne, ng, d)
            w = u_gauss - self.gauss_points(V) - self.speed * e[:, None, :]
            s = np.einsum("egd,ed->eg", w, e)  # axial component
            wn = w - s[:, :, None] * e[:, None, :]
            mag = np.sqrt(np.einsum("egd,egd->eg", wn, wn) + DRAG_EPS**2)
            f = (self.cn[:, None] * mag)[:, :, None] * wn + (self.ct[:, None] * np.abs(s) * s)[
                :, :, None
            ] * e[:, None, :]
            nodal = self.l0[:, None, None] * np.einsum(
                "g,ga,egd->ead", self.gauss_w, self.gauss_N, f
            )
            F[:-1] += nodal[:, 0]
            F[1:] += nodal[:, 1]
            if jacobian:
                P = np.eye(d)[None, None] - e[:, None, :, None] * e[:, None, None, :]
                J = (
                    (self.cn[:, None] * mag)[:, :, None, None] * P
                    + (
                        self.cn[:, None, None, None]
                        * wn[:, :, :, None]
                        * wn[:, :, None, :]
                        / mag[:, :, None, None]
                    )
                    + (2.0 * self.ct[:, None] * np.abs(s))[:, :, None, None]
                    * (e[:, None, :, None] * e[:, None, None, :])
                )  # (ne, ng, d, d)
                # block (a, c) = l0 Σ_g w_g N_a N_c J_g
                blk = np.einsum("gac,egij->eaicj", self._gauss_wNN, J)
                c_el = self.l0[:, None, None] * blk.reshape(self.ne, 2 * d, 2 * d)
        lift = lift_nodal_forces(  # the steady lift of the relative flow (cl_steady)
            self, e, u_gauss - self.gauss_points(V) - self.speed * e[:, None, :]
        )
        if lift is not None:
            F += lift
        c_nd = np.zeros((self.n, d, d)) if jacobian else None
        if np.any(self.node_cda):
            vr = u_fluid - V
            mag = np.sqrt(np.einsum("nd,nd->n", vr, vr) + DRAG_EPS**2)
            F += (self.node_cda * mag)[:, None] * vr
            if jacobian:
                c_nd += (self.node_cda * mag)[:, None, None] * np.eye(d)[None] + self.node_cda[
                    :, None, None
                ] * vr[:, :, None] * vr[:, None, :] / mag[:, None, None]
        return F, c_el, c_nd

    def _linear_drag(self, V: np.ndarray, e: np.ndarray, u_gauss: np.ndarray, jacobian: bool):
        """Linear drag B_n (I − e₀e₀ᵀ) v_r + B_t e₀e₀ᵀ v_r at the quadrature points:
        nodal forces (n, d) and the constant element blocks l0 B ⊗ [[1/3, 1/6], ...]."""
        d = self.dim
        b_n, b_t = self.linear_drag
        w = u_gauss - self.gauss_points(V) - self.speed * e[:, None, :]
        s = np.einsum("egd,ed->eg", w, e)
        wn = w - s[:, :, None] * e[:, None, :]
        f = b_n[:, None, None] * wn + (b_t[:, None] * s)[:, :, None] * e[:, None, :]
        nodal = self.l0[:, None, None] * np.einsum("g,ga,egd->ead", self.gauss_w, self.gauss_N, f)
        F = np.zeros_like(V)
        F[:-1] += nodal[:, 0]
        F[1:] += nodal[:, 1]
        c_el = None
        if jacobian:
            ee = e[:, :, None] * e[:, None, :]
            J = b_n[:, None, None] * (np.eye(d)[None] - ee) + b_t[:, None, None] * ee
            blk = np.einsum("ac,eij->eaicj", CONSISTENT, J)
            c_el = self.l0[:, None, None] * blk.reshape(self.ne, 2 * d, 2 * d)
        return F, c_el

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
        if self.bed_linear is not None:
            f0, k0, c0, z0 = self.bed_linear
            F = np.zeros_like(X)
            F[:, -1] = f0 - k0 * (X[:, -1] - z0) - c0 * V[:, -1]
            return F, k0, c0
        pen = -self.depth - X[:, -1]
        p0 = self.pen0
        on = pen > 0.0
        full = pen >= p0
        x = np.clip(pen / p0, 0.0, 1.0)
        s = x * x * (3.0 - 2.0 * x)  # smoothstep blend, C1
        spring = np.where(
            full, self.k_bed * (pen - 0.5 * p0), self.k_bed * p0 * x**3 * (1.0 - 0.5 * x)
        )  # k ∫₀ᵖ s
        kz = self.k_bed * s  # ∂spring/∂p
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


def static_equilibrium(
    model: LineModel,
    X: np.ndarray,
    u_current: np.ndarray,
    u_current_gauss: np.ndarray,
    f_ref: float,
    tol: float,
    max_iter: int = 200,
) -> tuple[np.ndarray, float]:
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
    for _ in range(max_iter):
        if rn <= tol:
            return X, rn
        e, l, T, ea, kb = st
        kel = model.stiffness_blocks(e, l, np.maximum(T, 0.0), ea)
        knd = np.zeros((model.n, d, d))
        knd[:, -1, -1] = kb
        ab = model.band_matrix(kel, knd)[:, fr]
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
        raise ConvergenceError(
            "time-domain static start (Newton)",
            max_iter,
            rn,
            tol,
            hint="the statics solution is far from this model's "
            "equilibrium; check the seabed stiffness and current",
        )
    return X, rn


def statics_guess(scene: Scene, line: Line, mesh: LineMesh, statics: Any) -> np.ndarray:
    """Static node positions (n_nodes, 3) from the statics module (or a given result)."""
    if statics is None:
        res = solve_statics(scene)
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
