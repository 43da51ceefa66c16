"""Rigid bodies: mass and hydrodynamic data, their coupling to lines, body statics.

``rigid`` (the body, rigid links; ``tables`` its frequency tables) · ``data``
(hydrodynamic coefficients from Capytaine or a JSON table) · ``from_scene`` (bodies of
a scene) · ``coupling`` (lines and bodies in one linear system) · ``statics`` (the body
poses; ``mooring`` the lines' condensed stiffness).  The independent coupled solvers
that check the engine are in :mod:`stochcable.reference.bodies`.
"""
