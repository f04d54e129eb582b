"""Command-line interface: ``fogdrift allan | noise | separate | model | analyze | compensate | batch``.

One module per command; :mod:`fogdrift.cli._app` holds the typer application, the shared load options and the
edge (:func:`~fogdrift.cli._app.run`).  Commands only declare options, call the library (:mod:`fogdrift.pipeline`)
and the renderer (:mod:`fogdrift.report`), and print rich tables.  A :class:`~fogdrift.errors.FogdriftError` is
printed as one red line with settings spelled as CLI flags, and exits 1 (``--traceback`` re-raises it); usage
errors keep typer's exit 2; Ctrl-C prints one line saying what was and was not written, and exits 130.

:func:`main` installs the SIGINT guard (:class:`fogdrift.interrupt.SigintGuard`) before the heavy imports, so
Ctrl-C at any point, the start included, ends the run within a second.  ``app`` is imported on first use.
"""

from __future__ import annotations

import os
import sys

__all__ = ["app", "main"]


def _commands():
    from . import allan, analyze, batch, compensate, model, noise, separate  # noqa: F401  (register the commands)
    from ._app import app

    return app


def __getattr__(name):  # ``from fogdrift.cli import app`` imports the commands on first use
    if name == "app":
        return _commands()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _on_timeout():
    """Watchdog (another thread): the main thread did not stop within the grace time after Ctrl-C."""
    try:
        from ._app import emergency_exit
    except BaseException:  # still importing: nothing can have been written
        os.write(2, b"interrupted: nothing was written\n")
        os._exit(130)
    emergency_exit()


def main():  # console-script entry point
    from .. import interrupt

    code = 0
    try:  # outside the guard too: a Ctrl-C while the guard itself starts (handler set, watchdog not yet running)
        with interrupt.SigintGuard(on_timeout=_on_timeout, grace_s=0.6):
            try:
                _commands()(prog_name="fogdrift")
            except SystemExit as exc:
                code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
            except KeyboardInterrupt:  # before a command's frame took over (imports, option parsing)
                os.write(2, b"interrupted: nothing was written\n")
                code = 130
    except KeyboardInterrupt:
        if code != 130:
            os.write(2, b"interrupted: nothing was written\n")
        code = 130
    if interrupt.requested() and code != 130:  # Ctrl-C after the command's frame had finished
        os.write(2, b"interrupted: after the run had finished (its files were all written)\n")
        code = 130
    if code == 130:
        # skip interpreter teardown: compiler threads (XLA, numba) still running can crash it; all files are closed
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except (OSError, ValueError):
                pass
        os._exit(130)
    sys.exit(code)
