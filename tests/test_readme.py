"""The README's Python examples run as written (from the repository root).

They are the first code a new user pastes: the entry points (``stochcable.analyze``,
``load_scene``, ``simulate_sea``, ``build_engine``), the module paths after the
restructure and ``stochcable.runtime.configure``.  The engine example solves one scene
for three sea states; its answers are compared with fresh analyses of the same scenes
(build once, solve per sea: the same documents to round-off, 1e-12).
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
BLOCKS = re.findall(r"```python\n(.*?)```", (ROOT / "README.md").read_text(), re.S)


def test_readme_has_python_examples():
    assert len(BLOCKS) >= 2


@pytest.mark.parametrize("index", range(len(BLOCKS)))
def test_readme_python_block_runs(index, monkeypatch):
    monkeypatch.chdir(ROOT)
    namespace: dict = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        exec(compile(BLOCKS[index], f"README.md python block {index}", "exec"), namespace)
    if "engine" in namespace:
        from _compare import assert_close_documents

        import stochcable

        scene = namespace["scene"]
        doc = scene.model_dump(mode="json")
        doc["sea"]["spectrum"] = {"type": "pierson_moskowitz", "hs": 6.0, "tp": 10.0}
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            fresh = stochcable.analyze(stochcable.load_scene(doc)).to_document()
        got = namespace["r"].to_document()
        for d in (fresh, got):
            d.pop("timing")
        assert_close_documents(got, fresh, rtol=1e-12)


def test_readme_test_command_is_the_fast_tier_ci_runs():
    # the README's first two commands set up: install and serve, then install the test
    # extras and run the fast tier; .ci/run runs the same command, then the slow tier
    first = re.search(r"```bash\n(.*?)```", (ROOT / "README.md").read_text(), re.S)
    commands = first.group(1).strip().splitlines()
    assert commands[0].startswith("python3 -m pip install -e . && stochcable serve")
    install, _, tests = commands[1].partition(" && ")
    assert install == 'python3 -m pip install -e ".[test]"'
    assert tests == 'python3 -m pytest -q -n auto -m "not slow"'
    ci = (ROOT / ".ci" / "run").read_text()
    fast, slow = f"tier {tests}\n", "tier python3 -m pytest -q -n auto -m slow\n"
    assert fast in ci and slow in ci and ci.index(fast) < ci.index(slow)
