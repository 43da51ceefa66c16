"""A line of a group with no end on a body: the degenerate line part (Tuah 1982, eq.
5.2.6, §5.3).

A line attached to no free body is a group of its own without bodies
(:mod:`stochcable.dynamics.groups`): nothing couples back to it, so there is no end
motion u_e to solve for and its line part is its plain response, U = U_0 (both ends
prescribed, moving with their channels).  :class:`FreeLine` solves it on the free
nodes (:func:`stochcable.dynamics.solve.line_solve.solve_free`: the banded direct solve, the Foss
modal solve, or in the coarse stage the same modal equations per frequency), gives
the σ of the drag fixed point from the free-node part
(:func:`stochcable.dynamics.linearization.variance.sigmas_from_free`) and forms the node
displacements and the support forces only when they are asked for (the outputs of
the last evaluation): the fixed point of a single line costs per evaluation what its
own solve costs.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np

from stochcable.dynamics.linearization.variance import sigmas_from_free
from stochcable.dynamics.loads.freqblocks import FrequencyIndex, frequency_slices
from stochcable.dynamics.model.blocks import line_prep, to_freq
from stochcable.dynamics.model.system import Damping, LineSystem
from stochcable.dynamics.solve.line_loads import end_following_at, end_loads
from stochcable.dynamics.solve.line_solve import reactions, solve_free, total_displacement
from stochcable.dynamics.solve.node_inputs import LineInputs

__all__ = ["FreeLine"]


class FreeLine:
    """The line part of a line without attached ends.

    Parameters
    ----------
    system : LineSystem
        The line, both end nodes prescribed.
    inp : LineInputs
        Its inputs (the physical channels).
    damping : Damping
        Its linear drag.
    modal_direct : bool, optional
        Foss lines: the modal equations solved per frequency (the coarse stage), not
        by the Foss eigenproblem (:func:`stochcable.dynamics.solve.line_solve.solve_free`).

    Attributes
    ----------
    u_free : ndarray, complex, shape (n_nodes − 2, d, n_omega, n_ch)
        Dynamic displacement of the free nodes. [m/unit]
    c : NodeBlocks
        The damping C = C_s + C_d it was solved with. [N·s/m]
    """

    def __init__(
        self, system: LineSystem, inp: LineInputs, damping: Damping, modal_direct: bool = False
    ) -> None:
        self.system, self.inp, self.damping = system, inp, damping
        self.u_free, self.c = solve_free(system, inp, damping, modal_direct=modal_direct)
        self._nodes: np.ndarray | None = None
        self._support: np.ndarray | None = None

    def reactions(self, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """R_0 and R_e on the attached rows: none (shapes (n_w, 0, n_ch), (n_w, 0, 0))."""
        n_w, n_ch = self.inp.weights.shape
        return np.zeros((n_w, 0, n_ch), dtype=complex), np.zeros((n_w, 0, 0), dtype=complex)

    def sigmas(self, method: str) -> np.ndarray:
        """σ of the relative velocities (:func:`~stochcable.dynamics.linearization.variance.
        drag_coefficients` layout) from the free-node part. [m/s]"""
        return sigmas_from_free(self.system, self.inp, self.u_free, method)

    def nodes(self) -> np.ndarray:
        """Total node displacement (n_nodes, d, n_w, n_ch), formed once. [m/unit]"""
        if self._nodes is None:
            self._nodes = total_displacement(self.system, self.inp, self.u_free)
        return self._nodes

    def support(self) -> np.ndarray:
        """Support forces (n_w, 2d, n_ch) of the line on its ends, formed once. [N/unit]"""
        if self._support is None:
            system = self.system
            self._support = reactions(
                system,
                line_prep(system),
                self.c,
                self.nodes(),
                end_loads(system, self.inp, self.damping),
                self.inp.omega,
            )
        return self._support

    def response(
        self,
    ) -> tuple[Callable[[FrequencyIndex], np.ndarray], Callable[[], np.ndarray], np.ndarray]:
        """The converged response without the whole grid's frequency-major copy:
        ``nodes(freq)``, the total node displacement (n_nodes, d, n_f, n_ch) on a
        slice of the frequencies (:attr:`~stochcable.dynamics.model.system.Response.nodes`);
        a zero-argument callable forming the frequency-major displacement (n_w,
        n_nodes·d, n_ch) when it is read; and the support forces (n_w, 2d, n_ch),
        formed here from the two nodes at each end.  They keep the free-node part and
        the end motions only (not the inputs' fluid arrays). [m/unit, N/unit]"""
        system, inp = self.system, self.inp
        prep = line_prep(system)
        n, d = prep.n, prep.d
        n_w, n_ch = inp.weights.shape
        light = replace(
            inp,
            velocity=None,
            square=None,
            fluid=tuple(None for _ in inp.fluid),
            inertia_extra=None,
            cache={k: v for k, v in inp.cache.items() if k == ("following", system.solver)},
        )
        u_free, omega = self.u_free, inp.omega  # (the closures hold no fluid arrays)

        def nodes(freq: slice = slice(None)) -> np.ndarray:
            n_f = omega[freq].size
            u = np.zeros((n, d, n_f, n_ch), dtype=complex)
            up = end_following_at(system, prep, light, freq)
            if up is not None:
                u += up
            u[1:-1] += u_free[:, :, freq]
            return u

        def displacement() -> np.ndarray:
            disp = np.empty((n_w, n * d, n_ch), dtype=complex)
            for sl in frequency_slices(n_w, 3 * 16 * n * d * max(n_ch, 1)):
                disp[sl] = to_freq(nodes(sl))
            return disp

        ends = np.array([0, 1, n - 2, n - 1])
        u_end = np.zeros((4, d, n_w, n_ch), dtype=complex)
        for sl in frequency_slices(n_w, 2 * 16 * n * d * max(n_ch, 1)):
            u_end[:, :, sl] = nodes(sl)[ends]
        support = reactions(
            system, prep, self.c, u_end, end_loads(system, inp, self.damping), inp.omega
        )
        return nodes, displacement, support

    def combine(self, ue: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Node displacements and support forces; ``ue`` has no columns (no attached
        end)."""
        return self.nodes(), self.support()
