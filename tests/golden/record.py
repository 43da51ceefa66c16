"""Golden result documents: the numbers the restructure must not change.

``python tests/golden/record.py`` writes ``tests/golden/<case>.json.gz`` for every case
of :data:`CASES`: each bundled example, DESIGN.md's chain verbatim (``chain_design``: the
example with its untapered fairlead surge), and variants that reach the other paths (the
direct and Foss solvers for single lines and lines on bodies, time series of lines on
bodies, statics with current, the adaptive-fidelity plan).  Each case stores the CLI's
documents — ``statics``, ``modes`` (10 per line) and ``analyze`` (time-series window) —
produced through the public command line, so the record does not depend on where the
code inside lives.  ``tests/test_golden.py`` recomputes them and compares numbers to
1e-10 relative (see tests/_compare.py for why that and not bit-equality).

The residuals of the linear model are on by default since issue 31 (the corrected
answer is the answer): the documents here were re-recorded with them.  The documents
recorded before, by the linear model alone, are in ``linear/``; the same scenes with
both switches false (:func:`linear`) must still reproduce them
(``python tests/golden/record.py --linear <case>`` writes one there; they are not
meant to change).
"""

from __future__ import annotations

import copy
import gzip
import io
import json
import sys
import warnings
from contextlib import redirect_stdout
from pathlib import Path

HERE = Path(__file__).resolve().parent
#: The documents of the linear model alone (the residual switches false).
LINEAR = HERE / "linear"
#: The residual switches of the scene (stochcable.scene.residual_kinds).
SWITCHES = ("drag_residual", "geometric_residual")
EXAMPLES = HERE.parents[1] / "stochcable" / "examples"


def _example(name: str) -> dict:
    return json.loads((EXAMPLES / f"{name}.json").read_text())


def _variant(name: str, **analysis: object) -> dict:
    doc = _example(name)
    doc.setdefault("analysis", {}).update(copy.deepcopy(analysis))
    return doc


def _design_chain() -> dict:
    """DESIGN.md's v1 chain verbatim: the bundled example with its fairlead surge the
    untapered Pierson–Moskowitz spectrum (the example band-limits it)."""
    doc = _example("chain_catenary")
    doc["lines"][0]["end_b"]["motion"] = {
        "surge": {"type": "pierson_moskowitz", "hs": 2.0, "tp": 10.0}
    }
    return doc


def _chain_current() -> dict:
    doc = _design_chain()
    doc["environment"]["current"] = [
        {"z": 0.0, "speed": 1.0, "heading": 30.0},
        {"z": -200.0, "speed": 0.3, "heading": 30.0},
    ]
    doc["analysis"].pop("timeseries", None)
    return doc


def cases() -> dict[str, dict]:
    """The scene documents of every golden case, by case name."""
    out = {p.stem: _example(p.stem) for p in sorted(EXAMPLES.glob("*.json"))}
    out["chain_design"] = _design_chain()
    out["chain_direct"] = _design_chain()
    out["chain_direct"]["analysis"]["solver"] = "direct"
    out["chain_current"] = _chain_current()
    out["taut_wire_fidelity"] = _variant("taut_wire", fidelity={"target_error": 0.02})
    ts = {"method": "dsa", "duration": 256.0, "dt": 0.25, "seed": 3}
    out["disc_buoy_single_leg_timeseries"] = _variant(
        "tuah_1982_disc_buoy_single_leg", timeseries=ts
    )
    out["disc_buoy_three_legs_foss"] = _variant(
        "tuah_1982_disc_buoy_three_legs", solver="foss", timeseries={**ts, "method": "nsa"}
    )
    return out


def linear(doc: dict) -> dict:
    """``doc`` with both residual switches explicitly false: the linear model alone."""
    out = copy.deepcopy(doc)
    lin = out.setdefault("analysis", {}).setdefault("linearization", {})
    lin.update(dict.fromkeys(SWITCHES, False))
    return out


STAGES = {
    "statics": ["statics"],
    "modes": ["modes", "--count", "10"],
    "analyze": ["analyze", "--timeseries", "window"],
}


def compute(doc: dict, tmp: Path) -> dict:
    """The CLI's documents of one scene: {stage: document}."""
    from stochcable.cli import main

    path = tmp / "scene.json"
    path.write_text(json.dumps(doc))
    out = {}
    for stage, argv in STAGES.items():
        buf = io.StringIO()
        with warnings.catch_warnings(), redirect_stdout(buf):
            warnings.simplefilter("ignore")
            code = main([argv[0], str(path), *argv[1:]])
        if code != 0:
            raise RuntimeError(f"{stage} exited {code}")
        out[stage] = json.loads(buf.getvalue())
    return out


def path_of(case: str, folder: Path = HERE) -> Path:
    return folder / f"{case}.json.gz"


def load(case: str, folder: Path = HERE) -> dict:
    with gzip.open(path_of(case, folder), "rt") as f:
        return json.load(f)


def main(argv: list[str]) -> int:
    import tempfile

    as_linear = "--linear" in argv
    wanted = [a for a in argv if a != "--linear"] or list(cases())
    folder = LINEAR if as_linear else HERE
    all_cases = cases()
    with tempfile.TemporaryDirectory() as tmp:
        for case in wanted:
            doc = linear(all_cases[case]) if as_linear else all_cases[case]
            docs = compute(doc, Path(tmp))
            with gzip.open(path_of(case, folder), "wt") as f:
                json.dump(docs, f)
            sys.stderr.write(f"{case}: {path_of(case, folder).stat().st_size} bytes\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
