"""Dynamics about the static equilibrium: wave and end loads, statistical drag
linearization, direct and Foss modal solves, coupled lines and bodies, time series
(seed 001 ch. 5)."""
