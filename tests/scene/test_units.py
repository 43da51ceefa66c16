"""Unit labels inferred from a scene's gravity (stochcable.scene.units)."""

from __future__ import annotations

import pytest

from stochcable.scene.units import FOOT_SLUG_SECOND, SI, unit_labels


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
    from stochcable.scene.model import load_scene

    feet = load_scene(load_example("tuah_1982_single_leg"))
    metric = load_scene(load_example("chain_catenary"))
    assert unit_labels(feet.environment.g).length == "ft"
    assert unit_labels(metric.environment.g).length == "m"


@pytest.mark.parametrize(
    ("si", "feet"),
    [
        ("m", "ft"),
        ("kg/m", "slug/ft"),
        ("N/m, N, N·m/rad", "lbf/ft, lbf, lbf·ft/rad"),
        ("m/s²", "ft/s²"),
        ("kg/m³", "slug/ft³"),
        ("Pa·s/m", "(lbf/ft²)·s/ft"),
        ("kg, kg·m, kg·m²", "slug, slug·ft, slug·ft²"),
        # symbols that are not SI base symbols stay
        ("rad/s", "rad/s"),
        ("s", "s"),
        ("deg", "deg"),
        ("-", "-"),
        ("1/s", "1/s"),
        ("unit²·s/rad", "unit²·s/rad"),
        ("", ""),
    ],
)
def test_si_labels_converted_symbol_by_symbol(si: str, feet: str) -> None:
    assert FOOT_SLUG_SECOND.convert(si) == feet
    assert SI.convert(si) == si


def test_generic_labels_convert_to_words() -> None:
    assert unit_labels(1.0).convert("N·m") == "force unit·length unit"


@pytest.mark.parametrize(
    ("doc", "system"),
    [
        ({"environment": {"g": 32.174}}, "foot-slug-second"),
        ({"environment": {"g": 9.81}}, "SI"),
        ({"environment": {}}, "SI"),  # the scene's default g
        ({"environment": {"g": "x"}}, "SI"),  # invalid g: the default's labels
        ({"environment": {"g": -32.174}}, "SI"),
        ({"environment": {"g": float("nan")}}, "SI"),
        ({"environment": {"g": True}}, "SI"),
        ({"environment": [1, 2]}, "SI"),
        ([], "SI"),
        (None, "SI"),
    ],
)
def test_labels_of_a_document_that_may_be_invalid(doc, system: str) -> None:
    from stochcable.scene.units import labels_of_document

    assert labels_of_document(doc).system == system


def test_scene_validation_messages_use_the_scene_units() -> None:
    """A bad field of a scene in feet is reported with its unit in feet."""
    import copy

    from stochcable.errors import InputError
    from stochcable.examples import load_example
    from stochcable.scene.model import load_scene

    feet = load_example("tuah_1982_single_leg").model_dump(mode="json", exclude_none=True)
    bad = copy.deepcopy(feet)
    bad["lines"][0]["segments"][0]["mass"] = -1.0
    with pytest.raises(InputError, match=r"mass = -1.0 \[slug/ft\]") as info:
        load_scene(bad)
    assert info.value.unit == "slug/ft"
    bad = copy.deepcopy(feet)
    bad["environment"]["seabed"]["stiffness"] = -1.0
    with pytest.raises(InputError, match=r"stiffness = -1.0 \[\(lbf/ft²\)/ft\]"):
        load_scene(bad)
    metric = load_example("chain_catenary").model_dump(mode="json", exclude_none=True)
    metric["lines"][0]["segments"][0]["mass"] = -1.0
    with pytest.raises(InputError, match=r"mass = -1.0 \[kg/m\]"):
        load_scene(metric)


def test_validator_messages_quote_values_in_the_scene_units() -> None:
    """The scene validators write SI symbols after the values they quote; a scene in
    feet gets them in feet (and an SI scene keeps them)."""
    from stochcable.errors import InputError
    from stochcable.examples import load_example
    from stochcable.scene.model import load_scene

    for name, unit in (("tuah_1982_single_leg", "ft"), ("chain_catenary", "m")):
        doc = load_example(name).model_dump(mode="json", exclude_none=True)
        depth = doc["environment"]["depth"]
        doc["environment"]["current"] = [{"z": -2.0 * depth, "speed": 0.1}]
        with pytest.raises(
            InputError,
            match=rf"z = {-2.0 * depth} {unit} is below the "
            rf"seabed \(depth {depth} {unit}\)",
        ):
            load_scene(doc)
