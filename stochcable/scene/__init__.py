"""The scene document: pydantic models, loading, units and the JSON Schema export.

The first stage of the pipeline.  A scene (environment, sea, lines, bodies, analysis
settings) is validated and resolved here, once; the layers below trust what they get.
"""

from stochcable.scene.model import *  # noqa: F403  (the scene's public models)
from stochcable.scene.model import __all__ as __all__
