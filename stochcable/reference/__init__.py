"""Reference simulators: nonlinear time-domain solvers that check the frequency-domain
pipeline (:mod:`~stochcable.reference.cable`), and the direct solves of the assembled
lines–bodies system that check the coupled engine (:mod:`~stochcable.reference.bodies`).
A validation tool beside the pipeline, not a stage of it."""
