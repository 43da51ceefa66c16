"""One line: mesh, closed-form catenary, static equilibrium, finite-element model and
natural modes (Tuah (1982), ch. 4; Bliet (1984) for the modes).

``mesh`` (elements and nodes) · ``catenary`` (closed-form elastic catenary; its closure
integrals in ``catenary_kernel``, the multi-segment chain in ``multisegment``) ·
``statics`` (one line's static equilibrium: ``equilibrium`` the FE residual, tangent
and Newton solver, ``chain`` its start, ``banded`` the banded solves) · ``elements``
and ``fem`` (the finite-element model about the static shape; ``seabed`` its bed contact,
the touchdown element split at the static touchdown) · ``modes`` · the rooms
``strumming`` (shedding, lock-in, the wake oscillator's balance) and ``transport`` (a
line travelling along itself).  The
scene-level statics, with bodies, is :mod:`stochcable.statics`.

References
----------
Bliet, A. (1984), Dynamic analysis of single span cables, PhD thesis, Massachusetts
Institute of Technology.
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""
