"""The finite-element statics of one line: residual, tangent and the Newton solver
(Tuah (1982), §4.1, §3.1).

:class:`LocalFrame` is the line's local frame (planar problems with two DOFs per
node); :class:`StaticsModel` the nodal residual forces of the 2-node elastic bars with
their lumped loads (weight by wet fraction, attachments, current drag and lift, seabed
springs)
and the exact banded tangent; :class:`StaticsSolver` Newton–Raphson with a
backtracking line search, falling back to the viscous relaxation of Tuah (1982), eqs.
4.1.5–4.1.8.  The model is described in :func:`stochcable.line.statics.solve_line_statics`.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.linalg import LinAlgError

from stochcable.line.banded import banded_solve, block_band_indices
from stochcable.line.mesh import LineMesh
from stochcable.line.transport.relative_flow import steady_lift_force
from stochcable.scene.model import Environment

__all__ = ["SLACK_FACTOR", "LocalFrame", "StaticsModel", "StaticsSolver", "reference_force"]

#: Axial stiffness factor of a slack (compressed) element: E -> eps E (Tuah (1982), §6.2).
SLACK_FACTOR = 1e-6

_EPS = np.finfo(float).eps


class LocalFrame:
    """Local frame: x' along the horizontal projection of end_a -> end_b, z up.

    A planar problem (every load in the vertical plane through the ends) is solved with
    two DOFs per node (x', z); otherwise with three (x', y', z).
    """

    def __init__(self, mesh: LineMesh, env: Environment, force_3d: bool = False) -> None:
        a, b = mesh.end_a, mesh.end_b
        h = b[:2] - a[:2]
        hn = math.hypot(*h)
        cur = [
            (p.speed * math.cos(p.heading_rad), p.speed * math.sin(p.heading_rad))
            for p in env.current
            if p.speed > 0.0
        ]
        if hn > 1e-12 * max(1.0, mesh.length):
            ux = h / hn
        elif cur:
            c = np.sum(np.asarray(cur), axis=0)
            cn = math.hypot(*c)
            ux = c / cn if cn > 0 else np.array([1.0, 0.0])
        else:
            ux = np.array([1.0, 0.0])
        self.Q = np.array([[ux[0], ux[1], 0.0], [-ux[1], ux[0], 0.0], [0.0, 0.0, 1.0]])
        self.origin = np.array([a[0], a[1], 0.0])
        out_of_plane = any(
            abs(-ux[1] * cx + ux[0] * cy) > 1e-12 * math.hypot(cx, cy) for cx, cy in cur
        )
        self.dim = 3 if (force_3d or out_of_plane) else 2
        self.cols = [0, 1, 2] if self.dim == 3 else [0, 2]

    def to_local(self, X: np.ndarray) -> np.ndarray:
        return ((X - self.origin) @ self.Q.T)[:, self.cols]

    def to_global(self, Xl: np.ndarray) -> np.ndarray:
        full = np.zeros((Xl.shape[0], 3))
        full[:, self.cols] = Xl
        return full @ self.Q + self.origin

    def vec_to_global(self, v: np.ndarray) -> np.ndarray:
        full = np.zeros(3)
        full[self.cols] = v
        return full @ self.Q


# -------------------------------------------------------------------------- FE model


class StaticsModel:
    """Residual and banded tangent of the FE statics of one line (local frame)."""

    def __init__(self, mesh: LineMesh, env: Environment, frame: LocalFrame) -> None:
        self.n = mesh.n_nodes
        self.dim = dim = frame.dim
        self.zi = dim - 1
        self.l0 = mesh.l0
        self.ea = mesh.ea
        self.w_sub = mesh.weight
        self.w_dry = mesh.mass * env.g
        self.node_fz = mesh.node_buoyancy - mesh.node_mass * env.g
        self.zbed = -env.depth
        trib_kd = 0.5 * mesh.l0 * mesh.diameter * env.seabed.stiffness
        kb = np.zeros(self.n)
        kb[:-1] += trib_kd
        kb[1:] += trib_kd
        self.kb = kb
        # current profile in the local frame
        pts = sorted((p for p in env.current), key=lambda p: p.z)
        self.has_current = any(p.speed > 0 for p in pts)
        if self.has_current:
            self.cz = np.array([p.z for p in pts])
            uv = np.array(
                [
                    [p.speed * math.cos(p.heading_rad), p.speed * math.sin(p.heading_rad), 0.0]
                    for p in pts
                ]
            )
            loc = uv @ frame.Q.T
            self.cu = loc[:, frame.cols]  # (n_pts, dim)
        self.c_n = 0.5 * env.rho * mesh.cd_normal * mesh.diameter
        self.c_t = 0.5 * env.rho * mesh.cd_axial * math.pi * mesh.diameter
        self.c_node = 0.5 * env.rho * mesh.node_drag_area
        # a travelling line: its axial drag acts on the relative axial velocity u_t − c
        self.speed = float(mesh.axial_speed)
        # the steady lift of the relative flow (3-D only: planar, it is zero)
        cl = mesh.cl_steady
        self.has_lift = self.has_current and dim == 3 and cl is not None and bool(cl.any())
        if self.has_lift:
            self.c_l = 0.5 * env.rho * cl * mesh.diameter
        coefs = np.concatenate([self.c_n, self.c_t, self.c_node])
        self.has_drag = (self.has_current or self.speed != 0.0) and bool((coefs > 0).any())
        self.has_drag = self.has_drag or self.has_lift
        # load-stepping factor of the drag (1 = full current)
        self.beta = 1.0
        self._band_index()

    # ---- loads that do not depend on position, for the reference force
    def weight_scale(self) -> float:
        """Σ max(|w_sub|, |w_dry|)·l0 + Σ |node loads| (position-independent: computed
        once per model; the Newton asks for it at every residual test). [N]"""
        ws = self.__dict__.get("_weight_scale")
        if ws is None:
            w = np.maximum(np.abs(self.w_sub), np.abs(self.w_dry))
            ws = self._weight_scale = float(np.sum(w * self.l0) + np.sum(np.abs(self.node_fz)))
        return ws

    def energy(self, X: np.ndarray) -> float:
        """Potential energy of the conservative loads (all but drag); -grad = R - drag."""
        zi, l0 = self.zi, self.l0
        d = X[1:] - X[:-1]
        l = np.sqrt(np.einsum("ij,ij->i", d, d))
        strain = l / l0 - 1.0
        eae = np.where(strain > 0.0, self.ea, self.ea * SLACK_FACTOR)
        z = X[:, zi]
        za, zb = z[:-1], z[1:]
        wet = (za <= 0.0) & (zb <= 0.0)
        W = l0 * np.where(wet, self.w_sub, self.w_dry)
        pen = np.maximum(self.zbed - z, 0.0)
        return float(
            0.5 * np.sum(eae * l0 * strain**2)
            + np.sum(W * 0.5 * (za + zb))
            - np.sum(self.node_fz * z)
            + 0.5 * np.sum(self.kb * pen**2)
        )

    def current(self, z: np.ndarray) -> np.ndarray:
        if not self.has_current:
            return np.zeros(z.shape + (self.dim,))
        u = np.empty(z.shape + (self.dim,))
        for k in range(self.dim):
            u[:, k] = np.interp(z, self.cz, self.cu[:, k])
        u[z > 0.0] = 0.0
        return u

    def _band_index(self) -> None:
        dim, nf = self.dim, self.n - 2
        bw = 2 * dim - 1
        self.bw = bw
        self.band_rows, self.band_cols = block_band_indices(nf, dim)

    _memo: dict | None = None

    def forces(self, X: np.ndarray, tangent: bool = True) -> tuple:
        """Nodal residual forces R (n, dim) (force on each node, zero at equilibrium),
        element tensions, drag magnitude, and the tangent blocks -dR/dX.

        The residual of the last position is remembered: the Newton iteration asks for
        it twice at every accepted point (line search, then with the tangent) and the
        result once more; a repeated call (same X and drag factor) reuses it and only
        adds the tangent (the same numbers, ≈ 0.4 ms of the reference chain's
        statics)."""
        memo = self._memo
        if (
            memo is not None
            and memo["beta"] == self.beta
            and memo["X"].shape == X.shape
            and np.array_equal(memo["X"], X)
        ):
            if self.has_drag:
                self.drag_nodes = memo["drag_nodes"].copy()
            R = memo["R"].copy()
        else:
            memo = self._residual(X)
            self._memo = memo
            R = memo["R"].copy()
        if not tangent:
            return R, memo["T"], memo["drag"], None
        return R, memo["T"], memo["drag"], self._tangent(memo)

    def _residual(self, X: np.ndarray) -> dict:
        """The residual part of :meth:`forces` and the intermediates of the tangent."""
        zi, l0 = self.zi, self.l0
        beta = self.beta
        d = X[1:] - X[:-1]
        l = np.sqrt(np.einsum("ij,ij->i", d, d))
        e = d / l[:, None]
        strain = l / l0 - 1.0
        taut = strain > 0.0
        eae = np.where(taut, self.ea, self.ea * SLACK_FACTOR)
        T = eae * strain
        Fe = T[:, None] * e
        R = np.zeros_like(X)
        R[:-1] += Fe
        R[1:] -= Fe
        # weight, wet fraction of each element
        z = X[:, zi]
        za, zb = z[:-1], z[1:]
        w_sub, w_dry = self.w_sub, self.w_dry
        mixed = (np.minimum(za, zb) < 0.0) & (np.maximum(za, zb) > 0.0)
        if mixed.any():
            dz = np.where(mixed, zb - za, 1.0)
            f = np.where(za <= 0.0, 1.0, 0.0) * np.where(zb <= 0.0, 1.0, 0.0)
            f = np.where(mixed, -np.minimum(za, zb) / np.abs(dz), f)
            W = l0 * (w_dry + f * (w_sub - w_dry))
            # derivatives of the wet fraction, mixed elements only
            dfa = np.where(mixed, np.where(za < zb, -zb, zb) / dz**2, 0.0)
            dfb = np.where(mixed, np.where(za < zb, za, -za) / dz**2, 0.0)
        else:
            wet = (za <= 0.0) & (zb <= 0.0)
            W = l0 * np.where(wet, w_sub, w_dry)
        R[:-1, zi] -= 0.5 * W
        R[1:, zi] -= 0.5 * W
        R[:, zi] += self.node_fz
        drag = 0.0
        if self.has_drag:
            u = self.current(0.5 * (za + zb))
            ua = np.einsum("ij,ij->i", u, e)
            un = u - ua[:, None] * e
            unn = np.sqrt(np.einsum("ij,ij->i", un, un))
            # relative axial velocity of the water past the travelling line (wet part)
            rel = ua - self.speed * (0.5 * (za + zb) <= 0.0)
            g = (self.c_n * unn)[:, None] * un + (self.c_t * np.abs(rel) * rel)[:, None] * e
            if self.has_lift:  # docs/travelling.md
                g = g + steady_lift_force(e, u, ua - rel, self.c_l)
            Fd = beta * l[:, None] * g
            R[:-1] += 0.5 * Fd
            R[1:] += 0.5 * Fd
            un_node = self.current(z)
            speed_node = np.sqrt(np.einsum("ij,ij->i", un_node, un_node))
            Fn = beta * (self.c_node * speed_node)[:, None] * un_node
            R += Fn
            self.drag_nodes = np.zeros_like(X)
            self.drag_nodes[:-1] += 0.5 * Fd
            self.drag_nodes[1:] += 0.5 * Fd
            self.drag_nodes += Fn
            drag = float(np.sum(np.sqrt(np.einsum("ij,ij->i", Fd, Fd))) + np.sum(np.abs(Fn)))
        pen = self.zbed - z
        contact = pen > 0.0
        R[:, zi] += np.where(contact, self.kb * pen, 0.0)
        st = {
            "X": X.copy(),
            "beta": beta,
            "R": R,
            "T": T,
            "drag": drag,
            "e": e,
            "l": l,
            "eae": eae,
            "mixed": mixed,
            "pen": pen,
        }
        if mixed.any():
            st["dfa"], st["dfb"] = dfa, dfb
        if self.has_drag:
            st.update(u=u, ua=ua, rel=rel, un=un, unn=unn, g=g, drag_nodes=self.drag_nodes.copy())
        return st

    def _tangent(self, st: dict) -> tuple:
        """Tangent blocks (Kd, Ku, Kl) = −dR/dX from the intermediates of
        :meth:`_residual`."""
        dim, zi, l0 = self.dim, self.zi, self.l0
        beta = st["beta"]
        e, l, eae, T, mixed, pen = (st[k] for k in ("e", "l", "eae", "T", "mixed", "pen"))
        w_sub, w_dry = self.w_sub, self.w_dry
        if self.has_drag:
            u, ua, rel, un, unn, g = (st[k] for k in ("u", "ua", "rel", "un", "unn", "g"))
        if mixed.any():
            dfa, dfb = st["dfa"], st["dfb"]
        I = np.eye(dim)
        ee = e[:, :, None] * e[:, None, :]
        k = (eae / l0)[:, None, None] * ee + (T / l)[:, None, None] * (I - ee)
        Kd = np.zeros((self.n, dim, dim))
        Kd[:-1] += k
        Kd[1:] += k
        Ku = -k
        Kl = -k.copy()
        if self.has_drag:
            # D = dF/dd = g eᵀ + (dg/de)(I - e eᵀ)
            safe = np.where(unn > 0.0, unn, 1.0)
            A = (
                unn[:, None, None] * I
                + np.where(unn > 0.0, 1.0 / safe, 0.0)[:, None, None]
                * un[:, :, None]
                * un[:, None, :]
            )
            B = e[:, :, None] * u[:, None, :] + ua[:, None, None] * I
            dg = -self.c_n[:, None, None] * (A @ B) + (self.c_t * np.abs(rel))[:, None, None] * (
                2.0 * e[:, :, None] * u[:, None, :] + rel[:, None, None] * I
            )
            if self.has_lift:
                dg = dg + self._lift_jacobian(e, u, ua - rel)
            D = beta * (g[:, :, None] * e[:, None, :] + dg @ (I - ee))
            Kd[:-1] += 0.5 * D
            Kd[1:] -= 0.5 * D
            Ku = Ku - 0.5 * D
            Kl = Kl + 0.5 * D
        if mixed.any():
            dWa = 0.5 * l0 * (w_sub - w_dry) * dfa
            dWb = 0.5 * l0 * (w_sub - w_dry) * dfb
            Kd[:-1, zi, zi] += dWa
            Kd[1:, zi, zi] += dWb
            Ku[:, zi, zi] += dWb
            Kl[:, zi, zi] += dWa
        # nodes resting exactly on the bed get the contact stiffness too
        Kd[:, zi, zi] += np.where(pen >= 0.0, self.kb, 0.0)
        return Kd, Ku, Kl

    def _lift_jacobian(self, e: np.ndarray, u: np.ndarray, speed: np.ndarray) -> np.ndarray:
        """∂f_L/∂e (n_el, 3, 3) by central differences (a tangent: the residual is
        exact)."""
        h = 1e-6
        jac = np.empty(e.shape + (3,))
        for k in range(3):
            de = np.zeros(3)
            de[k] = h
            fp = steady_lift_force(e + de, u, speed, self.c_l)
            fm = steady_lift_force(e - de, u, speed, self.c_l)
            jac[:, :, k] = (fp - fm) / (2.0 * h)
        return jac

    def band(self, K: tuple, lam: float) -> np.ndarray:
        """The free–free tangent (+ the relaxation λ) in the layout of
        :func:`banded_solve`: rows ``bw:`` the general banded storage
        (``A[i, j] -> ab[2·bw + i − j, j]``), rows ``:bw`` zeros (LAPACK's room for
        the fill-in of the pivoting)."""
        Kd, Ku, Kl = K
        nf = self.n - 2
        N = nf * self.dim
        bw = self.bw
        ab = np.zeros((3 * bw + 1, N), order="F")
        vals = np.concatenate([Kd[1:-1].ravel(), Ku[1:-1].ravel(), Kl[1:-1].ravel()])
        ab[self.band_rows + bw, self.band_cols] = vals
        if lam > 0.0:
            diag = np.abs(ab[2 * bw])
            ab[2 * bw] += lam * (diag + 1e-3 * float(np.mean(diag)))
        return ab


def reference_force(model: StaticsModel, T: np.ndarray, drag: float) -> float:
    return model.weight_scale() + float(np.max(np.abs(T))) + drag


class StaticsSolver:
    """Newton with line search, then viscous relaxation (Tuah (1982), eqs. 4.1.5-4.1.8)."""

    def __init__(self, model: StaticsModel, tol: float, budget: int) -> None:
        self.m = model
        self.tol = tol
        self.budget = budget
        self.used = 0
        scale = float(np.max(model.ea / model.l0))
        self._floor_k = 8.0 * _EPS * scale

    def status(
        self, X: np.ndarray, tangent: bool = True
    ) -> tuple[float, float, np.ndarray, tuple | None]:
        """Relative residual, tolerance (raised to the round-off floor), nodal
        residual and, with ``tangent``, the tangent blocks (else None: a converged
        point needs no tangent; ``m.forces(X)`` adds it later from the memo)."""
        R, T, drag, K = self.m.forces(X, tangent=tangent)
        ref = reference_force(self.m, T, drag)
        r = float(np.max(np.abs(R[1:-1]))) / ref if self.m.n > 2 else 0.0
        floor = self._floor_k * float(np.max(np.abs(X))) / ref
        return r, max(self.tol, floor), R, K

    def _step(self, R: np.ndarray, K: tuple, lam: float) -> np.ndarray | None:
        ab = self.m.band(K, lam)
        try:
            dx = banded_solve(ab, R[1:-1].ravel(), self.m.bw)
        except (LinAlgError, ValueError):
            return None
        if not np.all(np.isfinite(dx)):
            return None
        return dx.reshape(-1, self.m.dim)

    def solve(self, X: np.ndarray, limit: int) -> tuple[bool, np.ndarray, float]:
        """Iterate from X; returns (converged, X, relative residual)."""
        m = self.m
        if m.n <= 2:
            return True, X, 0.0
        X = X.copy()
        r, tol, R, K = self.status(X, tangent=False)
        if r <= tol:
            return True, X, r
        span = float(np.sum(m.l0))
        cap = 0.25 * span
        lam = 0.0
        phi = float(np.sum(R[1:-1] ** 2))
        # the energy at X only matters when a trial step fails the residual test: on
        # demand (Newton from the chain start takes full steps, 0.1 ms of energies)
        energy: float | None = None
        fd = m.drag_nodes.copy() if m.has_drag else None
        best = (r, X.copy())
        for _ in range(limit):
            if self.used >= self.budget:
                break
            self.used += 1
            if K is None:
                # the tangent at X, from the residual memo of the status at X (the
                # same numbers as computing it with the status)
                K = m.forces(X)[3]
            dx = self._step(R, K, lam)
            if dx is None:
                lam = max(10.0 * lam, 1e-3)
                continue
            big = float(np.max(np.sqrt(np.sum(dx * dx, axis=1))))
            t = min(1.0, cap / big) if big > 0 else 1.0
            slope = float(np.sum(R[1:-1] * dx))  # -dPi/dt along dx
            accepted = False
            # backtracking line search: accept a decrease of the total potential energy
            # (Armijo, when the loads are conservative) or of the residual norm
            for _ls in range(10):
                Xt = X.copy()
                Xt[1:-1] += t * dx
                Rt = m.forces(Xt, tangent=False)[0]
                phit = float(np.sum(Rt[1:-1] ** 2))
                if not np.isfinite(phit):
                    t *= 0.5
                    continue
                if phit <= (1.0 - 1e-4 * t) * phi:
                    accepted = True
                elif slope > 0.0:
                    # energy with the drag frozen at X (its work t·Fd·dx): exact for
                    # conservative loads, a local merit of the follower drag
                    et = m.energy(Xt)
                    if fd is not None:
                        et -= t * float(np.sum(fd[1:-1] * dx))
                    if energy is None:
                        energy = m.energy(X)
                    accepted = et <= energy - 1e-4 * t * slope
                if accepted:
                    break
                t *= 0.5
            if not accepted:
                # Newton stalls: viscous relaxation, artificial damping C ∝ diag(K)
                # (Tuah (1982), eqs. 4.1.5-4.1.8), stiffened until a step is taken
                lam = max(4.0 * lam, 1e-2)
                continue
            X = Xt
            r, tol, R, K = self.status(X, tangent=False)
            phi = float(np.sum(R[1:-1] ** 2))
            energy = None
            if fd is not None:
                fd = m.drag_nodes.copy()
            if r < best[0]:
                best = (r, X.copy())
            if r <= tol:
                return True, X, r
            if lam > 0.0 and _ls == 0:
                # relax the damping toward zero (pure Newton) while full steps succeed
                lam *= 0.3
                if lam < 1e-6:
                    lam = 0.0
        return False, best[1], best[0]
