"""One router per resource.  Every module here exposing ``router`` is mounted by
:func:`service.app.create_app` (so adding ``analyses.py`` adds ``POST /v1/analyses``)."""
