"""Reference simulators: nonlinear time-domain solvers that check the frequency-domain
pipeline (:mod:`~stochcable.reference.cable`), the direct solves of the assembled
lines–bodies system that check the coupled engine (:mod:`~stochcable.reference.bodies`),
and MoorDyn as an independent check of the time-domain solver
(:mod:`~stochcable.reference.moordyn`, :mod:`~stochcable.reference.moordyn_compare`;
the optional ``moordyn`` package).  A validation tool beside the pipeline, not a stage
of it."""
