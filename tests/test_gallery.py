"""The documentation gallery's scripts (docs/gallery/plot_*.py) run standalone."""

from __future__ import annotations

import ast
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
GALLERY = ROOT / "docs" / "gallery"
SCRIPTS = sorted(GALLERY.glob("plot_*.py"))
#: The scripts that take more than 10 s (a nonlinear time-domain simulation).
SLOW = {"plot_fd_vs_time_domain.py"}

pytest.importorskip("matplotlib")


def test_gallery_has_a_script_per_bundled_example():
    from stochcable.examples import list_examples

    text = "\n".join(p.read_text(encoding="utf-8") for p in SCRIPTS)
    for name in list_examples():
        assert f'load_example("{name}")' in text, name


@pytest.mark.slow
@pytest.mark.parametrize(
    "script",
    [pytest.param(p, marks=pytest.mark.slow) if p.name in SLOW else p for p in SCRIPTS],
    ids=lambda p: p.name,
)
def test_gallery_script_runs(script, tmp_path):
    doc = ast.get_docstring(ast.parse(script.read_text(encoding="utf-8")))
    # sphinx-gallery: a reST title (underlined with "=") opens the header docstring
    title, underline = doc.splitlines()[:2]
    assert underline == "=" * len(title), script.name
    env = dict(os.environ, MPLBACKEND="Agg", PYTHONPATH=str(ROOT))
    proc = subprocess.run(
        [sys.executable, str(script)],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    # the examples' warnings are caught and printed by the scripts, not leaked
    assert "Warning:" not in proc.stderr, proc.stderr[-2000:]
