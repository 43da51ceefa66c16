"""The drag residual's scope by drag form (stochcable.dynamics.residuals.drag_form_guard)."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from stochcable.dynamics.residuals.drag_form_guard import HU_JIN_REASON, guard_drag_form
from stochcable.dynamics.residuals.registry import COMPUTE
from stochcable.errors import PhysicsWarning


def _system(form: str):
    mesh = SimpleNamespace(drag_form=form)
    return SimpleNamespace(name="cable", model=SimpleNamespace(mesh=mesh))


def test_hu_jin_line_gets_a_not_computed_record_and_a_warning():
    calls = []

    def compute(system, channels, linearization, std, **kw):
        calls.append(system.name)
        return "computed"

    guarded = guard_drag_form(compute)
    std = {"end_a": 3.0, "end_b": 4.0}
    with pytest.warns(PhysicsWarning, match="line 'cable'.*hu_jin"):
        rec = guarded(_system("hu_jin"), None, None, std, influence=None)
    assert not rec.computed and rec.reason == HU_JIN_REASON and rec.std == std
    assert calls == []
    assert guarded(_system("cross_flow"), None, None, std, influence=None) == "computed"
    assert calls == ["cable"]


def test_the_registry_guards_the_drag_residual():
    with pytest.warns(PhysicsWarning):
        rec = COMPUTE["drag_residual"](_system("hu_jin"), None, None, {"end_a": 1.0})
    assert not rec.computed
