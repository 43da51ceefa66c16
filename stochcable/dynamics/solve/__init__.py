"""One line solved for a given drag: its inputs in the node layout
(:mod:`~stochcable.dynamics.solve.node_inputs`), the load assembly (the right-hand side,
:mod:`~stochcable.dynamics.solve.line_loads`) and the direct and Foss solves with the
support forces and end tension (:mod:`~stochcable.dynamics.solve.line_solve`)."""
