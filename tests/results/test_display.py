"""Summaries for the terminal and notebooks (stochcable.results.display,
stochcable.cases.display): ``repr`` is a few lines with the σ the result holds, the
HTML a table with units, both small, and every text escaped in the HTML."""

from __future__ import annotations

import dataclasses
import html
import re
import warnings
from html.parser import HTMLParser

import pytest

from stochcable import analyze, load_example
from stochcable.cases import LineFatigue, read_scatter, run_cases
from stochcable.client_batches import BatchJob
from stochcable.results.display import format_value, html_table

NASTY = '<script>alert("x")</script> & co'
TEXT_LIMIT = 1024  # "a few lines": the former repr(Result) was 117 kB [characters]
HTML_LIMIT = 16 * 1024  # one line's summary table and a few warnings [characters]


class _Tree(HTMLParser):
    """Collects the tags and the text of an HTML fragment (and whether it is balanced)."""

    def __init__(self) -> None:
        super().__init__()
        self.tags: list[str] = []
        self.open: list[str] = []
        self.text: list[str] = []

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)
        self.open.append(tag)

    def handle_endtag(self, tag):
        assert self.open and self.open.pop() == tag, tag

    def handle_data(self, data):
        self.text.append(data)


def _parse(fragment: str) -> _Tree:
    tree = _Tree()
    tree.feed(fragment)
    tree.close()
    assert tree.open == []  # balanced
    return tree


@pytest.fixture(scope="module")
def chain():
    return analyze(load_example("chain_catenary"))


@pytest.fixture(scope="module")
def disc():
    """Bodies, foot-slug-second units and three warnings (kept in the result)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return analyze(load_example("tuah_1982_disc_buoy_single_leg"))


def test_format_value():
    assert format_value(73901.48) == "73,900"
    assert format_value(0.67264) == "0.6726"
    assert format_value(-62209.4) == "-62,210"
    assert format_value(2.5e-5) == "2.500e-05"
    assert format_value(1.5e9) == "1.500e+09"
    assert format_value(None) == format_value(float("nan")) == "–"


def test_result_repr_is_a_few_lines_with_the_sigma(chain):
    text = repr(chain)
    assert len(text) < TEXT_LIMIT and len(text.splitlines()) <= 8
    assert text.startswith("<stochcable Result: DESIGN.md v1 example")
    assert "leg1 (converged, " in text
    assert "warnings: 0" in text
    # the σ shown is the result's, to 4 significant digits (half a unit of the 4th: 5e-4)
    shown = re.search(r"end tension σ \[N\]: leg1 end_a ([\d,.]+); leg1 end_b ([\d,.]+)", text)
    for value, end in zip(shown.groups(), ("end_a", "end_b")):
        expected = getattr(chain.lines["leg1"], end).std
        assert float(value.replace(",", "")) == pytest.approx(expected, rel=5e-4)
    assert str(chain) == text


def test_result_repr_names_units_bodies_and_warnings(disc):
    text = repr(disc)
    assert "end tension σ [lbf]" in text
    assert "bodies: disc" in text
    assert f"warnings: {len(disc.warnings)} (.warnings)" in text and disc.warnings


def test_result_html_is_a_table_with_units_and_warnings(disc):
    page = disc._repr_html_()
    assert len(page) < HTML_LIMIT
    tree = _parse(page)
    assert tree.tags.count("table") == 2 and "ul" in tree.tags
    text = "".join(tree.text)
    for head in ("mean [lbf]", "σ [lbf]", "Tz [s]", "MPM 3 h [lbf]"):
        assert head in text
    assert format_value(disc.lines["leg"].end_b.std) in text
    for w in disc.warnings:
        assert w in text  # each warning whole, with its fix
    assert f"{len(disc.warnings)} warning(s)" in text


def test_result_html_escapes_every_text(chain):
    scene = chain.scene.model_copy(update={"title": NASTY})
    nasty = dataclasses.replace(chain, scene=scene, warnings=(NASTY,))
    page = nasty._repr_html_()
    assert "<script>" not in page and html.escape(NASTY) in page
    assert "script" not in _parse(page).tags
    assert NASTY in "".join(_parse(page).text)
    assert NASTY[:20] in repr(nasty)  # the text repr is plain text


def test_html_table_escapes_headers_and_cells():
    page = html_table(["<a>"], [["<b>&"], [1.5]], caption="<i>")
    assert "<a>" not in page and "<b>" not in page and "<i>" not in page
    assert "&lt;b&gt;&amp;" in page and "<td>1.500</td>" in page


@pytest.fixture(scope="module")
def case_set():
    scatter = read_scatter(
        [{"hs": 1.0, "tp": 7.0, "probability": 0.6}, {"hs": 3.0, "tp": 9.0, "probability": 0.4}]
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the resolution warnings of the chain at Hs 3 m
        return run_cases(
            load_example("chain_catenary"),
            scatter,
            fatigue=LineFatigue("dnv-studless", nominal_diameter=0.076),
        )


def test_case_set_repr_and_html(case_set):
    text = repr(case_set)
    assert len(text) < TEXT_LIMIT and len(text.splitlines()) <= 6
    assert "2 cases (2 ok)" in text
    totals = case_set.totals["leg1"]
    assert f"annual damage {format_value(totals.annual_damage['end_b'])} [1/year]" in text
    mpm = max(case_set.stats["leg1"]["end_b"][:, 3])
    assert f"leg1 end_b: max MPM 3 h {format_value(mpm)} [N]" in text
    page = case_set._repr_html_()
    assert len(page) < HTML_LIMIT
    body = "".join(_parse(page).text)
    assert "annual damage [1/year]" in body and "fatigue life [years]" in body
    assert format_value(totals.fatigue_life["end_b"]) in body


def test_case_set_html_escapes_reasons(case_set):
    row = dataclasses.replace(case_set.rows[0], status="failed", reason=NASTY)
    bad = dataclasses.replace(case_set, rows=(row, *case_set.rows[1:]))
    page = bad._repr_html_()
    assert "<script>" not in page and html.escape(NASTY) in page
    assert "1 case(s) not ok" in page


def _status(**over) -> dict:
    doc = {
        "id": "abc123",
        "status": "running",
        "created": "2026-01-01T00:00:00Z",
        "started": "2026-01-01T00:00:01Z",
        "finished": None,
        "progress": {"total": 12, "done": 5, "not_ok": 1, "failed": 0, "fraction": 5 / 12,
                     "rate": 1.0, "eta_seconds": 7.0},
        "problems": [{"index": 3, "status": "flagged", "reason": NASTY}],
        "problems_total": 1,
        "error": None,
        "chunk_size": 2,
        "results": "/v1/batches/abc123/results",
        "warnings": [NASTY],
    }  # fmt: skip
    doc.update(over)
    return doc


def test_batch_job_repr_and_html():
    job = BatchJob.from_document(_status())
    text = repr(job)
    assert text == (
        "<stochcable BatchJob abc123: running, 5/12 cases, 1 not ok, about 7.0 s left, "
        "1 warning(s)>"
    )
    page = job._repr_html_()
    assert "<script>" not in page and page.count(html.escape(NASTY)) == 2
    body = "".join(_parse(page).text)
    assert "case 3: flagged" in body and "2026-01-01T00:00:00Z" in body
    failed = BatchJob.from_document(_status(status="failed", error="<boom>"))
    assert repr(failed).endswith("error: <boom>>") and "&lt;boom&gt;" in failed._repr_html_()


def test_service_document_summary_matches_the_result(disc):
    # the client's AnalysisDocument (the result document read back) shows what the
    # Result shows, apart from the first line (the document carries no scene title)
    from stochcable.results.views import AnalysisDocument

    doc = AnalysisDocument(disc.to_document())
    assert repr(doc).splitlines()[1:] == repr(disc).splitlines()[1:]
    assert repr(doc).startswith("<stochcable AnalysisDocument: result of the service>")
    page = doc._repr_html_()
    body = "".join(_parse(page).text)
    assert "σ [lbf]" in body and all(w in body for w in disc.warnings)


def test_a_result_with_residuals_says_so_with_the_linear_sigma_beside(chain):
    """The chain at the defaults (both residuals on): a line of the text summary and
    a column of the table name the residuals included and give the linear model's σ
    (4 significant digits: 5e-4); the document read back shows the same."""
    from stochcable.results.views import AnalysisDocument

    line = chain.lines["leg1"]
    text = repr(chain)
    shown = re.search(
        r"residuals included: drag_residual, geometric_residual "
        r"\(linear σ: leg1 end_a ([\d,.]+); leg1 end_b ([\d,.]+)\)",
        text,
    )
    assert shown, text
    for value, end in zip(shown.groups(), ("end_a", "end_b")):
        assert float(value.replace(",", "")) == pytest.approx(line.linear[end].std, rel=5e-4)
        assert line.linear[end].std < getattr(line, end).std
    body = "".join(_parse(chain._repr_html_()).text)
    assert "linear σ [N]" in body and format_value(line.linear["end_b"].std) in body
    doc = AnalysisDocument(chain.to_document())
    assert repr(doc).splitlines()[1:] == text.splitlines()[1:]
    assert doc.lines["leg1"].linear_end("end_b") == line.linear["end_b"]
    assert doc.lines["leg1"].residuals["drag_residual"].std == line.drag_residual.std
    om, dens = doc.lines["leg1"].end_tension_density("end_b")
    want = line.end_tension_density("end_b")
    assert (om == want[0]).all() and (dens == want[1]).all()


def test_a_linear_result_has_no_residual_line():
    """A scene with both residual switches false carries no residual: no line, no
    column (the disc buoy's leg on its free body carries them by default)."""
    doc = load_example("tuah_1982_disc_buoy_single_leg").model_dump(mode="json")
    doc["analysis"]["linearization"].update(drag_residual=False, geometric_residual=False)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        linear = analyze(doc)
    assert "residuals" not in repr(linear)
    assert "linear σ" not in linear._repr_html_()
