"""The data of a coupled line–body system: :class:`LineLink` (a line model and the
bodies its ends are attached to) and :class:`CoupledSystem` (the assembled matrices
and DOF maps, Tuah (1982), eq. 3.3.10).

Assembled by :func:`stochcable.bodies.coupling.couple`, which documents the system;
loaded and expanded by :func:`~stochcable.bodies.coupling.coupled_load` and
:func:`~stochcable.bodies.coupling.expand_line` (both names are re-exported there).

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.sparse as sp

from stochcable.bodies.rigid import RigidBody
from stochcable.line.fem import FEModel

__all__ = ["LineLink", "CoupledSystem"]


@dataclass(frozen=True, eq=False)
class LineLink:
    """A line model and the bodies its ends are attached to.

    Parameters
    ----------
    name : str
        Line name (unique among the links).
    model : FEModel
        The line's finite-element model about its static shape; the attached end
        nodes must be among its prescribed (``fixed``) nodes.
    end_a, end_b : str, optional
        Name of the body the end is attached to; None keeps the end prescribed.  The
        attachment point is the end node's static position relative to the body's
        reference point.
    force_a, force_b : array_like, shape (3,), optional
        Static force the line exerts on the body at that end (LineStatics.force_a /
        force_b, which include current drag and the loads lumped on the end node);
        when None it is computed from the model: the end element's tension along it
        plus the weight and attachment loads lumped on the end node (no drag). [N]
    damping : matrix, shape (n_dof, n_dof), optional
        Damping on all model DOFs added to the model's seabed damping ``Cs``, e.g. the
        linearized drag of the line. [N·s/m]
    """

    name: str
    model: FEModel
    end_a: str | None = None
    end_b: str | None = None
    force_a: Any = None
    force_b: Any = None
    damping: Any = None


@dataclass(frozen=True, eq=False)
class CoupledSystem:
    """Lines and bodies assembled into one linear system (Tuah (1982), eq. 3.3.10).

    Attributes
    ----------
    K, M, C : scipy.sparse.csr_array, shape (n, n)
        Stiffness (lines' tangent stiffness, body hydrostatic + extra stiffness and the
        attachment geometric stiffness), mass (lines' structural + added mass, rigid
        body mass) and frequency-independent damping (lines' seabed damping and link
        damping, body extra and drag damping) over x = [line free DOFs, body DOFs].
        Body added mass and radiation damping are not in M and C: see
        :meth:`body_hydrodynamics`.
    K_p, M_p, C_p : scipy.sparse.csr_array, shape (n, n_p)
        Coupling of x to the still-prescribed line DOFs p (fixed or moving ends).
    bodies : tuple of RigidBody
    lines : tuple of LineLink
    line_dofs : dict of str to ndarray of int
        Indices in x of each line's free DOFs (its model's ``free``, in order).
    body_dofs : dict of str to ndarray of int
        Indices in x of each body's DOFs.
    prescribed_dofs : dict of str to ndarray of int
        Indices in p of each line's still-prescribed model DOFs (model order).
    link_maps : dict of str to (L, P)
        Sparse maps u_line = L x + P p over all model DOFs of each line.
    geometric : dict of str to ndarray
        Per body the summed attachment geometric stiffness included in K.
    """

    K: sp.csr_array
    M: sp.csr_array
    C: sp.csr_array
    K_p: sp.csr_array
    M_p: sp.csr_array
    C_p: sp.csr_array
    bodies: tuple[RigidBody, ...]
    lines: tuple[LineLink, ...]
    line_dofs: dict[str, np.ndarray]
    body_dofs: dict[str, np.ndarray]
    prescribed_dofs: dict[str, np.ndarray]
    link_maps: dict[str, tuple[sp.csr_array, sp.csr_array]]
    geometric: dict[str, np.ndarray] = field(default_factory=dict)

    @property
    def n_dof(self) -> int:
        """Number of coupled DOFs n."""
        return int(self.K.shape[0])

    @property
    def n_prescribed(self) -> int:
        """Number of still-prescribed line DOFs n_p."""
        return int(self.K_p.shape[1])

    @property
    def body_index(self) -> np.ndarray:
        """Indices in x of all body DOFs, body order."""
        if not self.bodies:
            return np.zeros(0, dtype=int)
        return np.concatenate([self.body_dofs[b.name] for b in self.bodies])

    @property
    def frequency_dependent(self) -> bool:
        """True when some body's added mass or radiation damping varies with ω."""
        return any(b.frequency_dependent for b in self.bodies)

    def body_hydrodynamics(self, omega: Any) -> tuple[np.ndarray, np.ndarray]:
        """Added mass A(ω) and radiation damping B(ω) on the body DOFs.

        Returns
        -------
        A, B : ndarray, shape (n_w, n_b, n_b)
            Block-diagonal over the bodies, in the order of :attr:`body_index`.
        """
        w = np.atleast_1d(np.asarray(omega, dtype=float))
        nb = int(self.body_index.size)
        a = np.zeros((w.size, nb, nb))
        b = np.zeros((w.size, nb, nb))
        k = 0
        for body in self.bodies:
            d = body.n_dof
            a[:, k : k + d, k : k + d] = body.added_mass_at(w)
            b[:, k : k + d, k : k + d] = body.radiation_damping_at(w)
            k += d
        return a, b

    def asymmetry(self) -> float:
        """max|K − Kᵀ| / max|K|: nonzero when the static moments on a body do not
        balance within the model (see
        :func:`~stochcable.bodies.rigid.attachment_geometric_stiffness`). [-]"""
        d = abs(self.K - self.K.T)
        top = abs(self.K).max() if self.K.nnz else 0.0
        return float(d.max() / top) if top > 0 else 0.0
