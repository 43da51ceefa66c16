"""The engine's groups: lines and large rigid bodies solved together (seed 001
§3.2.c, §3.3, ch. 5), a line alone being the group of one line and no bodies.

Lines attached to a freely moving body are solved together with it: one drag
linearization loop over every attached line and body, the response at every frequency
by substructuring, the outputs of each line as :func:`stochcable.dynamics.outputs.line_result`
gives them and the body motions as :class:`stochcable.results.documents.BodyResult`.
A line attached to no free body goes through the same fixed point and solve, its
line part being its own response
(:class:`~stochcable.dynamics.coupled.freeline.FreeLine`).

Modules, lowest first (each imports only the ones above it):

- :mod:`~stochcable.dynamics.coupled.bodydrag`: the linearized drag of a body;
- :mod:`~stochcable.dynamics.coupled.freeline`: the line part of a line alone;

- :mod:`~stochcable.dynamics.coupled.inputs`: a group's lines (:class:`CoupledLine`),
  body loads, vessel-driven ends and the group's channels;
- :mod:`~stochcable.dynamics.coupled.lineparts`: a line before the body solve (node
  level, Foss state-modal, modal per frequency), linear in its end motion;
- :mod:`~stochcable.dynamics.coupled.group`: the group on a grid
  (:class:`~stochcable.dynamics.coupled.group.GroupSystem`), the substructured solve
  for given drag and the σ map;
- :mod:`~stochcable.dynamics.coupled.coarse`: the coarse start of the fixed point;
- :mod:`~stochcable.dynamics.coupled.fixedpoint`: the coupled drag linearization
  (:func:`linearize_coupled`);
- :mod:`~stochcable.dynamics.coupled.modes`: the coupled natural modes;
- :mod:`~stochcable.dynamics.coupled.results`: line and body results;
- :mod:`~stochcable.dynamics.coupled.model`: the sea-independent build of a scene
  (:func:`build_coupled`);
- :mod:`~stochcable.dynamics.coupled.analysis`: its solve for a sea state
  (:func:`solve_coupled`) and :func:`analyze_coupled` = build + solve.
"""

from stochcable.dynamics.coupled.analysis import (
    CoupledAnalysis,
    CoupledGroup,
    analyze_coupled,
    solve_coupled,
)
from stochcable.dynamics.coupled.fixedpoint import (
    CoupledLinearization,
    linearize_coupled,
    warm_starts,
)
from stochcable.dynamics.coupled.inputs import (
    BodyLoads,
    CoupledLine,
    body_gravity_stiffness,
    body_loads,
    scene_line_channels,
)
from stochcable.dynamics.coupled.model import CoupledModel, build_coupled
from stochcable.dynamics.coupled.modes import CoupledModes, coupled_modes
from stochcable.dynamics.coupled.results import body_result, coupled_results
from stochcable.dynamics.coupled.vessels import fairlead_motion

__all__ = [
    "BodyLoads",
    "CoupledAnalysis",
    "CoupledGroup",
    "CoupledLine",
    "CoupledLinearization",
    "CoupledModel",
    "CoupledModes",
    "analyze_coupled",
    "body_gravity_stiffness",
    "body_loads",
    "body_result",
    "build_coupled",
    "coupled_modes",
    "coupled_results",
    "fairlead_motion",
    "linearize_coupled",
    "warm_starts",
    "solve_coupled",
    "scene_line_channels",
]
