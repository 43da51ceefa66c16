"""Reference simulators: nonlinear time-domain solvers that check the frequency-domain
pipeline.  A validation tool beside the pipeline, not a stage of it."""
