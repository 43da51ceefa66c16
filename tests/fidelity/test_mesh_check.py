"""Default element counts and the warning on coarse explicit ones
(stochcable.fidelity.mesh_check), checked against mesh convergence."""

from __future__ import annotations

import copy
import math
import re
import sys
import warnings

import pytest
from _paths import ROOT

from stochcable import analyze, load_example
from stochcable.fidelity.mesh_check import MESH_ERROR_LIMIT, mesh_estimates

sys.path.insert(0, str(ROOT / "benchmarks"))
import accuracy_lines  # noqa: E402

_PHRASE = "error of the end-tension σ"


def _run(doc: dict, elements: int | None) -> object:
    doc = copy.deepcopy(doc)
    seg = doc["lines"][0]["segments"][0]
    if elements is None:
        seg.pop("elements", None)
    else:
        seg["elements"] = elements
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return analyze(doc)


def _ends(res: object) -> tuple[float, float]:
    lr = next(iter(res.lines.values()))
    return lr.linear_end("end_b").std, lr.linear_end("end_a").std


def _taut() -> dict:
    return load_example("taut_wire").model_dump(mode="json", exclude_none=True)


def test_string_rule_is_the_dispersion_of_consistent_linear_elements():
    """(kh)²/24 against the exact dispersion ω_h²/ω² = 6(1 − cos kh)/((kh)²(2 + cos
    kh)) of the string (Tuah (1982), eq. 3.1.12) at the kh the 1 % limit allows: the
    next order, (kh)⁴·3/640 relative to (kh)²/24, is below 5 % of it there."""
    kh = math.sqrt(24.0 * MESH_ERROR_LIMIT)
    exact = math.sqrt(6.0 * (1.0 - math.cos(kh)) / (kh**2 * (2.0 + math.cos(kh)))) - 1.0
    assert exact == pytest.approx(MESH_ERROR_LIMIT, rel=0.05)


def test_explicit_coarse_count_warns_and_the_count_it_names_is_quiet():
    """The taut wire at 10 elements warns, naming a count; that count is quiet and its
    own estimate is within the limit, one element less is not."""
    coarse = _run(_taut(), 10)
    msgs = [w for w in coarse.warnings if _PHRASE in w]
    assert len(msgs) == 1 and "lines[wire].segments[0].elements = 10" in msgs[0]
    n = int(re.search(r"use elements = (\d+)", msgs[0]).group(1))
    fixed = _run(_taut(), n)
    assert not [w for w in fixed.warnings if _PHRASE in w]
    est = mesh_estimates(fixed)[0]
    assert est.error <= MESH_ERROR_LIMIT
    assert mesh_estimates(_run(_taut(), n - 1))[0].error > MESH_ERROR_LIMIT


def test_omitted_count_is_the_rule_count_and_quiet():
    """Without ``elements`` the taut wire gets the count the rule names for it (more
    than the pilot's 20) and no mesh warning; an explicit count is kept as given."""
    auto = _run(_taut(), None)
    named = int(re.search(r"use elements = (\d+)", _run(_taut(), 20).warnings[0]).group(1))
    assert auto.scene.lines[0].elements == named > 20
    assert not [w for w in auto.warnings if _PHRASE in w]
    assert _run(_taut(), 17).scene.lines[0].elements == 17


@pytest.mark.slow
def test_deep_catenary_default_count_meets_one_percent():
    """The accuracy page's deep catenary (no ``elements``): its default count gives
    end-tension σ within 1 % of 160 elements (the reference: 40, 80 and 160 elements
    agree to 0.25 %, the touchdown's element makes the convergence non-monotone, so no
    Richardson extrapolation), where 20 elements were 4.4 % / 6.1 % low; the estimate
    at 20 bounds that measured error (and is at most 3× it: a useful bound)."""
    doc = accuracy_lines.fd_document("deep")
    ref = _ends(_run(doc, 160))
    auto = _run(doc, None)
    assert auto.scene.lines[0].elements > 20
    for got, want in zip(_ends(auto), ref):
        assert abs(got / want - 1.0) <= MESH_ERROR_LIMIT
    coarse = _run(doc, 20)
    measured = max(abs(g / w - 1.0) for g, w in zip(_ends(coarse), ref))
    est = mesh_estimates(coarse)[0].error
    assert measured <= est <= 3.0 * measured
    assert any(_PHRASE in w for w in coarse.warnings)


@pytest.mark.slow
def test_estimate_bounds_the_chain_and_taut_wire_mesh_error():
    """Chain example and taut wire at 20 elements: the estimate bounds the measured σ
    error against 160 elements (taut wire: 20/40/80/160 converge at order 2, the 160
    reference within 0.003 % of Richardson's; chain: its touchdown in an element
    makes the convergence non-monotone, 40/80/160 agree to 0.2 %)."""
    for name in ("chain_catenary", "taut_wire"):
        doc = load_example(name).model_dump(mode="json", exclude_none=True)
        ref = _ends(_run(doc, 160))
        coarse = _run(doc, 20)
        measured = max(abs(g / w - 1.0) for g, w in zip(_ends(coarse), ref))
        assert measured <= mesh_estimates(coarse)[0].error, name


def test_sea_omega2_of_pierson_moskowitz_is_its_closed_form():
    # m_n = (Hs²/64) ωpⁿ (5/4)^(n/4) Γ(1 − n/4): ω₂ = ωp (5/4)^(1/4) √Γ(1/2); the
    # trapezoid over 16001 geometric points of 8 decades errs by ≈ (Δ ln ω)² ≈ 1e-6
    from types import SimpleNamespace

    from stochcable.fidelity.pilot import sea_omega2
    from stochcable.scene.model import Sea

    tp = 9.0
    wp = 2.0 * math.pi / tp
    exact = wp * 1.25**0.25 * math.sqrt(math.gamma(0.5))
    sea = Sea(spectrum={"type": "pierson_moskowitz", "hs": 3.0, "tp": tp})
    scene = SimpleNamespace(sea=sea, environment=SimpleNamespace(g=9.80665))
    assert sea_omega2(scene) == pytest.approx(exact, rel=1e-5)
