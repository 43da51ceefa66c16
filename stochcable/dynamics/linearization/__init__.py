"""The statistical drag linearization: its formulas
(:mod:`~stochcable.dynamics.linearization.formulas`), the σ of the relative velocity and
the drag of a response (:mod:`~stochcable.dynamics.linearization.variance`; compiled
element sums in :mod:`~stochcable.dynamics.linearization.variance_kernels`), the
linearized drag of a body (:mod:`~stochcable.dynamics.linearization.bodydrag`), the
Anderson-accelerated fixed-point iteration
(:mod:`~stochcable.dynamics.linearization.iteration`) and the inputs on a frequency
subset for its coarse start (:mod:`~stochcable.dynamics.linearization.coarse_grid`).
The fixed point of a group, which uses all of these, is
:mod:`stochcable.dynamics.groups.group_fixed_point`."""
