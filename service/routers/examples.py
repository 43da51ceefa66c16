"""GET /v1/examples and GET /v1/examples/{name}: the example scenes."""

from __future__ import annotations

from functools import lru_cache
from typing import Annotated

from fastapi import APIRouter, Path

from service.encoding import error_responses
from service.errors import NotFound
from service.schemas import ExampleSummary
from stochcable.scene.model import Scene

router = APIRouter(prefix="/v1", tags=["examples"])


@lru_cache(maxsize=1)
def _catalog() -> dict[str, Scene]:
    from stochcable.examples import list_examples, load_example

    return {name: load_example(name) for name in list_examples()}


@router.get(
    "/examples",
    operation_id="list_examples",
    response_model=list[ExampleSummary],
    summary="List the example scenes",
)
def list_examples() -> list[ExampleSummary]:
    """Names and titles of the scenes shipped with stochcable."""
    return [ExampleSummary(name=n, title=s.title) for n, s in _catalog().items()]


@router.get(
    "/examples/{name}",
    operation_id="get_example",
    response_model=Scene,
    responses=error_responses(404, 422),
    summary="Get an example scene document",
)
def get_example(
    name: Annotated[str, Path(max_length=64, description="Example name from GET /v1/examples")],
) -> Scene:
    """The scene document, ready for ``POST /v1/analyses`` or ``stochcable analyze``."""
    catalog = _catalog()
    if name not in catalog:
        raise NotFound(
            ["path", "name"], f"unknown example {name!r}; known examples: {', '.join(catalog)}"
        )
    return catalog[name]
