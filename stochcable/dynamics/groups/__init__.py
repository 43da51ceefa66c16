"""The engine's groups: lines and large rigid bodies solved together (Tuah
1982, §3.2.c, §3.3, ch. 5), a line alone being the group of one line and no bodies.

Lines attached to a freely moving body are solved together with it: one drag
linearization loop over every attached line and body, the response at every frequency
by substructuring, the outputs of each line as
:func:`stochcable.dynamics.outputs.line_result.line_result` gives them and the body motions as
:class:`stochcable.results.documents.BodyResult`.
A line attached to no free body goes through the same fixed point and solve, its
line part being its own response
(:class:`~stochcable.dynamics.groups.freeline.FreeLine`).

Modules, lowest first (each imports only the ones above it):

- :mod:`~stochcable.dynamics.groups.freeline`: the line part of a line alone;
- :mod:`~stochcable.dynamics.groups.fixed_point_state`: the fixed point's typed state
  (its run, one evaluation, the evaluation count);

- :mod:`~stochcable.dynamics.groups.inputs`: a group's lines (:class:`CoupledLine`),
  body loads, vessel-driven ends and the group's channels;
- :mod:`~stochcable.dynamics.groups.modal_parts`: a line's Foss state-modal and modal
  parts;
- :mod:`~stochcable.dynamics.groups.lineparts`: a line before the body solve (node
  level, Foss state-modal, modal per frequency), linear in its end motion;
- :mod:`~stochcable.dynamics.groups.group`: the group on a grid
  (:class:`~stochcable.dynamics.groups.group.GroupSystem`), the substructured solve
  for given drag and the σ map;
- :mod:`~stochcable.dynamics.groups.coarse`: the coarse start of the fixed point;
- :mod:`~stochcable.dynamics.groups.group_fixed_point`: the coupled drag linearization
  (:func:`linearize_coupled`);
- :mod:`~stochcable.dynamics.groups.modes`: the coupled natural modes;
- :mod:`~stochcable.dynamics.groups.results`: line and body results;
- :mod:`~stochcable.dynamics.groups.model`: the sea-independent build of a scene
  (:func:`build_coupled`);
- :mod:`~stochcable.dynamics.groups.analysis`: its solve for a sea state
  (:func:`solve_coupled`) and :func:`analyze_coupled` = build + solve;
- :mod:`~stochcable.dynamics.groups.line_fixed_point`: the same fixed point for one
  :class:`~stochcable.dynamics.model.system.LineSystem` and its channels
  (:func:`linearize`, a convenience for users and tests).

The linearized drag of a body is :mod:`stochcable.dynamics.linearization.bodydrag`.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from stochcable.dynamics.groups.analysis import (
    CoupledAnalysis,
    CoupledGroup,
    analyze_coupled,
    solve_coupled,
)
from stochcable.dynamics.groups.group_fixed_point import (
    CoupledLinearization,
    linearize_coupled,
    warm_starts,
)
from stochcable.dynamics.groups.inputs import (
    BodyLoads,
    CoupledLine,
    body_gravity_stiffness,
    body_loads,
    scene_line_channels,
)
from stochcable.dynamics.groups.model import CoupledModel, build_coupled
from stochcable.dynamics.groups.modes import CoupledModes, coupled_modes
from stochcable.dynamics.groups.results import body_result, coupled_results
from stochcable.dynamics.groups.vessels import fairlead_motion

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
