"""One line: mesh, closed-form catenary, static equilibrium, finite-element model and
natural modes (seed 001 ch. 4; seed 000 for the modes)."""
