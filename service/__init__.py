"""stochcable HTTP service (FastAPI): ``service.app:app``, ``create_app(settings)``.

A thin layer over the core: routers parse requests into the core's pydantic models,
call the core and serialize.  Start it with ``stochcable serve``.
"""

__all__ = ["create_app"]


def __getattr__(name: str):  # lazy: importing service.settings must not build the app
    if name == "create_app":
        from .app import create_app

        return create_app
    raise AttributeError(name)
