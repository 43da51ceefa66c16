"""Unit labels inferred from a scene's gravity (stochcable.units)."""

from __future__ import annotations

import pytest

from stochcable.units import FOOT_SLUG_SECOND, SI, unit_labels


@pytest.mark.parametrize("g", [9.80665, 9.81, 9.8])
def test_si_from_metric_gravity(g: float) -> None:
    assert unit_labels(g) is SI
    assert unit_labels(g).force_per_length == "N/m"


@pytest.mark.parametrize("g", [32.174, 32.2, 32.17])
def test_feet_from_imperial_gravity(g: float) -> None:
    labels = unit_labels(g)
    assert labels is FOOT_SLUG_SECOND
    assert (labels.length, labels.force, labels.mass) == ("ft", "lbf", "slug")
    assert labels.velocity == "ft/s"


@pytest.mark.parametrize("g", [1.0, 9.5, 10.0, 31.5, 386.1])
def test_unrecognised_gravity_gets_generic_labels(g: float) -> None:
    # 9.5 and 10.0 lie outside the 1 % band around 9.80665 (3.1 % and 2.0 % away):
    # an approximate g is not taken for a unit system
    labels = unit_labels(g)
    assert labels.system == "consistent"
    assert labels.force == "force unit"


def test_examples_in_feet_are_labelled_in_feet() -> None:
    from stochcable.examples import load_example
    from stochcable.scene import load_scene

    feet = load_scene(load_example("tuah_1982_single_leg"))
    metric = load_scene(load_example("chain_catenary"))
    assert unit_labels(feet.environment.g).length == "ft"
    assert unit_labels(metric.environment.g).length == "m"
