"""Command-line interface: ``fogdrift allan | separate | model | analyze | batch``.

One module per command; :mod:`fogdrift.cli._app` holds the typer application, the shared load options and the
error edge.  Commands only declare options, call the library (:mod:`fogdrift.pipeline`) and the renderer
(:mod:`fogdrift.report`), and print rich tables.  A :class:`~fogdrift.errors.FogdriftError` is printed as one red
line with settings spelled as CLI flags, and exits 1 (``--traceback`` re-raises it); usage errors keep typer's
exit 2.
"""

from __future__ import annotations

from . import allan, analyze, batch, model, separate  # noqa: F401  (register the commands)
from ._app import app

__all__ = ["app", "main"]


def main():  # console-script entry point
    app()
