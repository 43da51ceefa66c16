"""The excitation of a line: the independent input channels (sea, end motions) and the
Morison matrices (:mod:`~stochcable.dynamics.loads.channels`), the sea as channels
(:mod:`~stochcable.dynamics.loads.sea_channels`), the sea's kinematics integrated along
the elements (:mod:`~stochcable.dynamics.loads.element_kinematics`, kept compact by
:mod:`~stochcable.dynamics.loads.element_parts`; its closed forms in NumPy
:mod:`~stochcable.dynamics.loads.kinematics_closed_forms` and compiled
:mod:`~stochcable.dynamics.loads.kinematics_kernels`) and the frequency blocks every
later stage runs over (:mod:`~stochcable.dynamics.loads.freqblocks`)."""
