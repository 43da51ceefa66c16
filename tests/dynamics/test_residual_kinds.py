"""The registry of residual kinds (stochcable.scene.residual_kinds and
stochcable.dynamics.residuals.registry): every registered kind has its scene switch,
compute function and cost terms, and a toy kind registered in a fixture alone (no
other module touched) appears in the outputs, the result document, the cost model and
the load-case plan."""

from __future__ import annotations

import math
import sys
import warnings

import numpy as np
import pytest
from _paths import ROOT
from _scenes import chain_surge_doc

sys.path.insert(0, str(ROOT / "docs" / "_ext"))
import results_reference  # noqa: E402  (the manual's result reference)

from stochcable import analyze, estimate_cost
from stochcable.cases import LineFatigue, run_cases, scatter_from_rows
from stochcable.dynamics.residuals import registry
from stochcable.errors import PhysicsWarning
from stochcable.results.records import ResidualRecord
from stochcable.scene import residual_kinds
from stochcable.scene.analysis_settings import LinearizationSettings
from stochcable.scene.model import Scene

TOY = "toy_residual"
TOY_MEMORY = 3 * 2**30  # above every registered kind's, so that it shows [B]
TOY_SECONDS = 7.0  # per line [s]
TOY_SHARE = 0.25  # the toy's variance over the linear σ² at each end [-]


def _toy(system, channels, linearization, std, *, influence=None) -> ResidualRecord:
    """A residual of TOY_SHARE·σ_linear² at each end, one spectral line at the top of
    the band."""
    w = float(linearization.response.omega[-1])
    var = {e: TOY_SHARE * s**2 for e, s in std.items()}
    lines = ((np.array([w]), {e: np.array([v]) for e, v in var.items()}),)
    return ResidualRecord.from_variances(var, dict(var), std, 1, 0, lines)


@pytest.fixture
def toy_kind(monkeypatch):
    """The toy kind registered (the registry's two entries), undone after the test."""
    kind = residual_kinds.ResidualKind(
        name=TOY,
        switch="A toy residual of the tests",
        document="The toy residual.",
        scope="none",
        order="1.",
        panels="0.",
        memory_bytes=TOY_MEMORY,
        seconds=lambda n_el, n_j, in_sea: TOY_SECONDS,
    )
    monkeypatch.setitem(residual_kinds.RESIDUAL_KINDS, TOY, kind)
    monkeypatch.setitem(registry.COMPUTE, TOY, _toy)
    return kind


def _with_toy(doc: dict) -> Scene:
    """The scene with the toy's switch on (the one line a kind adds to Linearization,
    ``toy_residual: bool = residual_switch("toy_residual")``, stood in for here)."""
    scene = Scene.model_validate(doc)
    lin = scene.analysis.linearization.model_copy(update={TOY: True})
    return scene.model_copy(
        update={"analysis": scene.analysis.model_copy(update={"linearization": lin})}
    )


def test_registered_kinds_are_complete():
    """Every registered kind has its scene switch (described by the registry, on by
    default since issue 31), its compute function and positive cost terms."""
    assert list(residual_kinds.RESIDUAL_KINDS) == list(registry.COMPUTE)
    for name, kind in residual_kinds.RESIDUAL_KINDS.items():
        field = LinearizationSettings.model_fields[name]
        assert field.annotation in (bool, "bool") and field.default is True
        assert field.description == kind.switch
        size = residual_kinds.ResidualSize(40, 200, 2, 2, 64, 200, 32, 200)
        assert kind.memory(size) > 0 and kind.seconds(40, 32, True) > 0


def test_toy_kind_reaches_outputs_document_cost_and_cases(toy_kind):
    doc = chain_surge_doc(20, residual=False)
    plain = Scene.model_validate(doc)
    scene = _with_toy(doc)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        base = analyze(plain).lines["leg1"]
        line = analyze(scene).lines["leg1"]
    rec = line.residuals[TOY]
    assert line.toy_residual is rec and rec.computed
    assert list(line.residuals) == [TOY] and line.drag_residual is None
    # the end σ with the toy: its variance added to the linear spectrum's moment
    # m0 (σ² = σ_lin² (1 + TOY_SHARE)); the linear σ kept in ``linear``
    for end in ("end_a", "end_b"):
        s_lin = base.linear_end(end).std
        assert line.linear[end].std == pytest.approx(s_lin, rel=1e-12)
        assert getattr(line, end).std == pytest.approx(s_lin * math.sqrt(1 + TOY_SHARE), rel=1e-9)
    out = line.to_document()
    assert out[TOY]["computed"] and out[TOY]["end_a"]["ratio"] == pytest.approx(
        math.sqrt(1 + TOY_SHARE), rel=1e-9
    )
    assert TOY not in base.to_document()
    # the manual's result reference documents its keys
    paths = results_reference.document_paths({"lines": {"leg1": out}})
    toy_paths = {p for p in paths if p.startswith(f"lines.<line>.{TOY}")}
    assert len(toy_paths) > 5 and toy_paths <= set(results_reference.residual_keys())
    # the cost model: the toy's memory (the largest) and its time on the one line
    cost, cost0 = estimate_cost(scene), estimate_cost(plain)
    assert cost.memory_bytes - cost0.memory_bytes == TOY_MEMORY
    assert cost.seconds - cost0.seconds == pytest.approx(TOY_SECONDS, rel=1e-12)
    # a load-case set that interpolates the corrections names it among the residuals
    # it computed on the anchors (fixed anchors 4 Hs steps apart: 2 of 5 cases)
    small = scatter_from_rows([{"hs": h, "tp": 8, "probability": 0.2} for h in (1, 2, 3, 4, 5)])
    fatigue = LineFatigue("dnv-studless", nominal_diameter=0.076)
    with pytest.warns(PhysicsWarning, match=rf"analysis.linearization.{TOY} computed on 2 of"):
        run_cases(scene, small, fatigue=fatigue, residual_span=4, residual_tolerance=None)


def test_kind_without_compute_function_is_refused(toy_kind, monkeypatch):
    monkeypatch.delitem(registry.COMPUTE, TOY)
    with pytest.raises(LookupError, match=TOY):
        registry.residual_parts(
            _with_toy(chain_surge_doc(20, residual=False)).analysis.linearization
        )
