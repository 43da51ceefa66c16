"""Dynamics about the static equilibrium, one room per stage (Tuah 1982, ch. 5):
:mod:`~stochcable.dynamics.loads` (input channels, element kinematics),
:mod:`~stochcable.dynamics.model` (one line's linear system and solvers),
:mod:`~stochcable.dynamics.solve` (load assembly and the solve of one line),
:mod:`~stochcable.dynamics.linearization` (statistical drag linearization),
:mod:`~stochcable.dynamics.outputs` (spectra, statistics, indicators of a line),
:mod:`~stochcable.dynamics.groups` (lines and bodies solved together: the one drag
fixed point), :mod:`~stochcable.dynamics.timeseries` and, on top,
:mod:`~stochcable.dynamics.engine` (build once, solve per sea state).

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""
