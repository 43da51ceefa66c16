"""Adaptive fidelity: elements, frequencies, modes and tolerance chosen for an error
target."""
