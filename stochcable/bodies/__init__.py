"""Rigid bodies: mass and hydrodynamic data, their coupling to lines, body statics."""
