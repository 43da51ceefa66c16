"""The public entry points of ``stochcable`` resolve, lazily, to the pipeline's stages.

``import stochcable`` stays light (the entry points are imported on first use); each name
of ``stochcable.__all__`` must resolve, and the stage functions must be the ones the
layered modules define (``stochcable.solve_statics`` is the scene-level statics of
``stochcable.statics``, not one line's).
"""

from __future__ import annotations

import subprocess
import sys

import pytest

import stochcable

EXPECTED = {
    "analyze": "stochcable.analysis",
    "build_engine": "stochcable.fidelity.mesh_engine",  # (with the element check)
    "load_scene": "stochcable.io",  # (also reads MoorDyn input files)
    "Scene": "stochcable.scene.model",
    "solve_statics": "stochcable.statics",
    "natural_modes": "stochcable.statics",
    "simulate_sea": "stochcable.sea.realization",
    "load_example": "stochcable.examples",
}


@pytest.mark.parametrize("name", sorted(stochcable.__all__))
def test_every_public_name_resolves(name):
    assert getattr(stochcable, name) is not None


@pytest.mark.parametrize("name, module", sorted(EXPECTED.items()))
def test_entry_points_come_from_their_stage(name, module):
    assert getattr(stochcable, name).__module__ == module


def test_entry_points_run_on_an_example():
    scene = stochcable.load_example("taut_wire")
    statics = stochcable.solve_statics(scene)
    assert set(statics.lines) == {line.name for line in scene.lines}


def test_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'nope'"):
        stochcable.nope  # noqa: B018


def test_import_is_light():
    # the entry points are imported on first use: a bare import loads no engine
    code = (
        "import sys, stochcable; "
        "print(any(m.startswith(('stochcable.dynamics', 'stochcable.line')) "
        "for m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "False"


def test_lazy_entry_points_leave_the_collector_as_they_found_it():
    # the lazy import runs without cyclic garbage collection, then restores it; its
    # ~50,000 objects join the oldest generation (otherwise the young ones hold them
    # until collections traverse them), nothing stays frozen, and objects the process
    # froze itself stay frozen
    code = (
        "import gc, stochcable; stochcable.build_engine; on = gc.isenabled(); "
        "young = sum(len(gc.get_objects(generation=g)) for g in (0, 1)); "
        "frozen = gc.get_freeze_count(); gc.disable(); "
        "x = [[] for _ in range(100)]; gc.freeze(); n = gc.get_freeze_count(); "
        "stochcable.analyze; print(on, gc.isenabled(), young < 1000, frozen, "
        "gc.get_freeze_count() == n > 0)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["True", "False", "True", "0", "True"]


_FIRST_ANALYSIS = """
import json, sys, warnings
warnings.simplefilter("ignore")
import stochcable
scene = json.load(open("stochcable/examples/chain_catenary.json"))
scene["analysis"]["linearization"].update(drag_residual={on}, geometric_residual={on})
stochcable.analyze(scene)
print(json.dumps(sorted(m for m in {heavy!r} if m in sys.modules)))
"""


@pytest.mark.parametrize("residuals", [False, True], ids=["residuals_off", "residuals_on"])
def test_the_first_analysis_imports_what_the_scene_uses(residuals):
    # the chain (current: strumming screening; no fidelity target, no bodies' fits):
    # its candidate modes are proven without a lock-in start by the NumPy bound and its
    # grids are below the compiled kernels' threshold, so numba is not loaded, nor the
    # fidelity planner (its element check, fidelity.mesh_check, is) or scipy.optimize;
    # its 2,400-sample record is transformed by numpy.fft, not pyfftw (nor xarray,
    # pandas); the drag formulas' erf is math.erf and the residuals' FFT length needs
    # no scipy.fft, so scipy.special (~25 ms of import) is not loaded either, with the
    # residual switches on or off; numpy.f2py and numpy.testing stay unexecuted
    # (docs/benchmarks/first_analysis.md)
    heavy = ("numba", "pyfftw", "xarray", "pandas", "matplotlib", "scipy.special", "scipy.fft")
    heavy += ("scipy.optimize", "scipy.stats", "scipy.sparse.linalg", "stochcable.fidelity.planner")
    # nor NumPy's tool submodules that SciPy's import binds (stochcable.lazy_numpy)
    heavy += ("numpy.f2py.f2py2e", "numpy.testing._private.utils", "charset_normalizer")
    # nor the fatigue curves (a strumming fatigue rate's) or the result's display
    heavy += ("stochcable.design.curves", "stochcable.results.display")
    heavy += ("concurrent.futures",)  # (stochcable.runtime's pool: not started)
    code = _FIRST_ANALYSIS.format(on=residuals, heavy=heavy)
    root = __import__("pathlib").Path(__file__).resolve().parents[1]
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=120, cwd=root
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "[]"
