"""The residuals of the linear model, in closed form: what the statistical drag
linearization drops (:mod:`.drag_residual`, evaluated on the pieces and panels of
:mod:`.drag_segments`), the second-order geometric forces of the linear response
(:mod:`.geometric_residual`), their shared steps (:mod:`.residual_lines`), the end
statistics with them (:mod:`.corrected`) and the stretching tension of the linear
response (:mod:`.second_order`)."""
