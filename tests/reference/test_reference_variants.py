"""The time-domain reference's controlled-experiment variants (drag="linear" |
"static_tangent", seabed="linear"; benchmarks/fd_budget.py): made as linear as the
frequency-domain model, the TD reproduces the FD end tension σ."""

from __future__ import annotations

import sys

import numpy as np
import pytest
from _paths import ROOT

from stochcable import load_scene
from stochcable.errors import InputError
from stochcable.reference.cable import simulate_line_timedomain

sys.path.insert(0, str(ROOT / "benchmarks"))
import fd_budget as fb  # noqa: E402


@pytest.mark.slow
def test_linear_td_reproduces_the_fd_end_tension():
    """The chain's line at 160 elements, the TD with the FD's converged linear drag, a
    bilateral linear bed and 1e-3 of the motion, over one whole period of a periodic
    DSA motion: a linear system in periodic steady state, so its σ is the FD's on the
    same lines without sampling error.  What is left: the Newmark period error
    (ωΔt)²/12 ≤ 0.05 % at 1.5 rad/s (the top of the motion table), the nodal bed of the
    TD against the FD's touchdown element split (measured 0.05 % / 0.08 % at 160
    elements; ±2 % at 40 / 80 elements, where the nodal bed is not converged), and the
    transient after the warm-up period: 0.3 %."""
    f = fb.fd(160)
    v = fb.td(160, 1, fb.SMALL, drag="linear", linear_drag=f["b"], seabed="linear")
    np.testing.assert_allclose(np.sqrt(v.sum(-1)), f["std"], rtol=3e-3)
    # linear: nothing off the input lines
    assert (v[:, 1] <= 1e-6 * v.sum(-1)).all()


def test_static_tangent_drag_equals_quadratic_drag_in_the_linear_limit():
    """Quadratic drag about the static or the instantaneous tangent: at a millionth of
    the motion the tangent hardly rotates, so the two records agree to the rotation's
    order (1e-6 relative); the drag itself is still quadratic."""
    doc = fb.chain_doc(20)
    surge = doc["lines"][0]["end_b"]["motion"]["surge"]
    surge["density"] = [1e-12 * v for v in surge["density"]]
    runs = [
        simulate_line_timedomain(doc, duration=60.0, dt=0.1, ramp=10.0, seed=3, drag=drag)
        for drag in ("quadratic", "static_tangent")
    ]
    d0 = runs[0].tension_b - runs[0].tension_b[0]
    d1 = runs[1].tension_b - runs[1].tension_b[0]
    assert np.abs(d0).max() > 0
    np.testing.assert_allclose(d1, d0, rtol=0, atol=1e-4 * np.abs(d0).max())


@pytest.mark.parametrize(
    "kw, name",
    [
        ({"drag": "cubic"}, "drag"),
        ({"seabed": "soft"}, "seabed"),
        ({"drag": "linear"}, "linear_drag"),
        ({"drag": "linear", "linear_drag": (-1.0, 0.0)}, "linear_drag"),
    ],
)
def test_variant_options_are_checked(kw, name):
    scene = load_scene(fb.chain_doc(10))
    with pytest.raises(InputError, match=name):
        simulate_line_timedomain(scene, duration=60.0, dt=0.1, ramp=10.0, **kw)
