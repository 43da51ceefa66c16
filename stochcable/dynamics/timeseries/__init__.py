"""Time series of one realization of the sea: the synthesis of the sea, end motions, end
tensions and body motions (:mod:`~stochcable.dynamics.timeseries.synthesis`) from the
transfer functions of every group on the realization grid
(:mod:`~stochcable.dynamics.timeseries.group_transfer`)."""
