"""The element check on every way a scene is solved: an engine whose mesh meets the
element rules (:mod:`stochcable.fidelity.mesh_check`) and whose every result says
where it does not.

One seam for :func:`stochcable.analyze`, an engine (``stochcable.build_engine(scene)``
then ``engine.solve(sea)``) and a load-case set (:func:`stochcable.cases.run_cases`,
whose engines are built here, wherever an executor runs them):

- a segment without ``elements`` is built at the scene model's default count, solved
  once for the *pilot sea* (the scene's own, or the one given) and rebuilt at the
  count the element rules need when the default is too coarse for it;
- every result of the engine passes :class:`MeshCheck` (the engine's ``check``): a
  ResolutionWarning per segment whose estimate for *that result's* sea exceeds the
  limit — an explicit count (naming the count that fixes it), a default count clipped
  by the scene model's limit, and, for a sea other than the pilot's, a default count
  that sea needs more than.

The check of a result reads its statics, its end-tension spectra's ω₂ and its sea's
ω₂ (≈ 1 ms a sea state on the chain example), so a set's cases pay it too.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from typing import Any

from stochcable.dynamics.engine import Engine, build_engine
from stochcable.dynamics.model.system import Progress
from stochcable.errors import ResolutionWarning, warn
from stochcable.fidelity.mesh_check import (
    MESH_ERROR_LIMIT,
    default_counts,
    mesh_estimates,
    mesh_warnings,
    omitted_counts,
)
from stochcable.fidelity.meshing import segment_geometry
from stochcable.results.documents import Result
from stochcable.scene.model import Scene, Sea, load_scene
from stochcable.statics import StaticsResult

__all__ = ["MeshCheck", "checked_build", "checked_engine"]


@dataclasses.dataclass(frozen=True)
class MeshCheck:
    """The element check of every result of one engine (its ``check``).

    Attributes
    ----------
    omitted : frozenset of (str, int)
        (line, segment index) of the segments whose ``elements`` the scene left out.
    pilot : Sea or None
        The sea their counts were chosen for (None: the scene had none).
    limit : float
        Largest estimated relative error of the end-tension σ. [-]
    """

    omitted: frozenset[tuple[str, int]]
    pilot: Sea | None
    limit: float = MESH_ERROR_LIMIT
    #: (statics, its segment geometry) of the last result: an engine's every result
    #: has the same statics
    _kept: list[Any] = dataclasses.field(default_factory=list, compare=False, repr=False)

    def __call__(self, result: Result) -> Result:
        """``result`` with a ResolutionWarning (raised and listed first in its
        ``warnings``) per segment above the limit (module notes)."""
        if not (self._kept and self._kept[0] is result.statics):
            self._kept[:] = [result.statics, segment_geometry(result.scene, result.statics)]
        other = bool(self.omitted) and result.scene.sea != self.pilot
        est = mesh_estimates(result, self.limit, self._kept[1])
        texts = mesh_warnings(est, self.omitted, self.limit, other_sea=other)
        if not texts:
            return result
        for text in texts:
            warn(text, ResolutionWarning)
        return dataclasses.replace(result, warnings=(*texts, *result.warnings))


def checked_build(
    scene: Scene,
    *,
    statics: StaticsResult | None = None,
    progress: Progress | None = None,
    pilot: Sea | None = None,
) -> tuple[Engine, Result | None]:
    """:func:`checked_engine` on a loaded scene, and the pilot's result when it is the
    engine's answer for the pilot sea (the default counts met the rules: no rebuild),
    checked; None otherwise (no pilot was needed, or the mesh was refined)."""
    omitted = omitted_counts(scene)
    engine = build_engine(scene, statics=statics, progress=progress)
    first = None
    if omitted:
        first = engine.solve(pilot, progress=progress)
        finer = default_counts(scene, mesh_estimates(first), omitted)
        if finer is not None:
            engine = build_engine(finer, progress=progress)
            first = None
    check = MeshCheck(frozenset(omitted), scene.sea if pilot is None else pilot)
    engine = dataclasses.replace(engine, check=check)
    return engine, (None if first is None else check(first))


def checked_engine(
    scene: Scene | Mapping[str, Any] | str,
    *,
    statics: StaticsResult | None = None,
    progress: Progress | None = None,
    pilot: Sea | None = None,
) -> Engine:
    """The engine of a scene (:func:`stochcable.dynamics.engine.build_engine`) with the
    element check: default counts that meet the element rules for the pilot sea, and a
    warning on every result whose sea a count does not meet them for (module notes).

    Parameters
    ----------
    scene : Scene, mapping, JSON string or path
        The scene document.
    statics : StaticsResult, optional
        A precomputed static equilibrium (not used for a refined mesh).
    progress : callable, optional
        ``progress(stage, info)`` (:data:`~stochcable.dynamics.model.system.Progress`).
    pilot : Sea, optional
        The sea state the default counts are chosen for (default: the scene's sea).

    Returns
    -------
    Engine
        Its ``scene`` has the chosen counts; its ``check`` is a :class:`MeshCheck`.
    """
    return checked_build(load_scene(scene), statics=statics, progress=progress, pilot=pilot)[0]
