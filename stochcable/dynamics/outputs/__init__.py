"""What a solved line gives: its spectra and statistics
(:mod:`~stochcable.dynamics.outputs.line_result`), the validity indicators
(:mod:`~stochcable.dynamics.outputs.indicators`) and the resolution checks of the grid,
the mesh and the tail (:mod:`~stochcable.dynamics.outputs.resolution`)."""
