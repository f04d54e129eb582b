"""Command-line interface: ``fogdrift allan | noise | separate | model | analyze | compensate | batch``.

One module per command; :mod:`fogdrift.cli._app` holds the typer application, the shared load options and the
edge (:func:`~fogdrift.cli._app.run`).  Commands only declare options, call the library (:mod:`fogdrift.pipeline`)
and the renderer (:mod:`fogdrift.report`), and print rich tables.  A :class:`~fogdrift.errors.FogdriftError` is
printed as one red line with settings spelled as CLI flags, and exits 1 (``--traceback`` re-raises it); usage
errors keep typer's exit 2; Ctrl-C prints one line saying what was and was not written, and exits 130.

:func:`main` takes SIGINT over as its first statement, with nothing imported but what the interpreter itself loaded
(``_signal``, ``os``): until the SIGINT guard (:class:`fogdrift.interrupt.SigintGuard`) is in place, a Ctrl-C
prints ``interrupted: nothing was written`` and exits 130 at once (no command has started, so nothing can have
been written); the guard then covers the heavy imports, option parsing and the work; after it, a Ctrl-C only
sets the flag, so the run ends with its own status or 130, never a traceback.  ``app`` is imported on first use.
(A Ctrl-C during the interpreter's own start-up, before any fogdrift code runs, is Python's.)
"""

from __future__ import annotations

import os
import sys

__all__ = ["app", "entry", "main"]


#: Command name -> the module that declares it, in the order ``fogdrift --help`` lists them.  :func:`main` imports a
#: command's module only when that command runs (or when the top-level help lists them all): ``fogdrift allan``
#: does not import ``batch`` (and with it fleet, noise and scipy), ``compensate``, ``model`` ...
COMMAND_MODULES = {
    "allan": "allan", "model": "model", "analyze": "analyze", "noise": "noise", "batch": "batch",
    "compensate": "compensate", "consistency": "consistency", "export": "export", "separate": "separate",
    "plan": "plan",
}


def _commands():
    """The typer application with every command registered (imports every command module)."""
    import importlib

    for module in dict.fromkeys(COMMAND_MODULES.values()):
        importlib.import_module(f"{__name__}.{module}")
    from ._app import app

    return app


def _lazy_app():
    """The typer application whose click group imports a command's module when the command is looked up.

    The group class (``app.info.cls``) lists :data:`COMMAND_MODULES` (then any other registered command) and, for
    a name not registered yet, imports its module (``@app.command()`` registers it) and builds that command as
    typer would.  Everything else (the callback's options, help, errors, typer's exception hook) is typer's own.
    """
    import importlib

    import typer.core
    import typer.main

    from ._app import app

    built = set()

    class LazyGroup(typer.core.TyperGroup):
        def list_commands(self, ctx):
            return list(dict.fromkeys([*COMMAND_MODULES, *self.commands]))

        def get_command(self, ctx, name):
            if name not in self.commands and name in COMMAND_MODULES:
                importlib.import_module(f"{__name__}.{COMMAND_MODULES[name]}")
                for info in app.registered_commands:  # the module's commands (and those of modules it imports)
                    if id(info) in built:
                        continue
                    built.add(id(info))
                    cmd = typer.main.get_command_from_info(
                        info, pretty_exceptions_short=app.pretty_exceptions_short,
                        rich_markup_mode=app.rich_markup_mode)
                    if cmd.name and cmd.name not in self.commands:
                        self.add_command(cmd)
            return super().get_command(ctx, name)

    app.info.cls = LazyGroup
    return app


def __getattr__(name):  # ``from fogdrift.cli import app`` imports the commands on first use
    if name == "app":
        return _commands()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


NOTHING_WRITTEN = b"interrupted: nothing was written\n"


def _on_timeout():
    """Watchdog (another thread): the main thread did not stop within the grace time after Ctrl-C.

    Never imports: the main thread may hold an import lock (a Ctrl-C during the heavy imports), and a run whose
    edge (:mod:`fogdrift.cli._app`) is not loaded yet cannot have written anything."""
    exit_now = getattr(sys.modules.get(f"{__name__}._app"), "emergency_exit", None)
    if exit_now is None:
        os.write(2, NOTHING_WRITTEN)
        os._exit(130)
    exit_now()


_phase = {"command_over": False}


def _outside_the_guard(signum, frame):
    """SIGINT handler of :func:`main` outside the guard: before it nothing was written (exit 130 now); after the
    command only the flag is set (main() turns it into one line and exit 130)."""
    if not _phase["command_over"]:
        os.write(2, NOTHING_WRITTEN)
        os._exit(130)
    interrupt = sys.modules.get("fogdrift.interrupt")
    if interrupt is not None:
        interrupt.request()


def _edge_state() -> dict:
    """The state of the command's edge (:mod:`fogdrift.cli._app`), or {} before it is imported."""
    return getattr(sys.modules.get(f"{__name__}._app"), "_state", None) or {}


def _line_claimed() -> bool:
    """Whether the command's edge (its interruption handler or the watchdog's emergency exit) printed, or is
    printing, the interruption line: it holds the edge's lock while it does.

    typer ends a KeyboardInterrupt raised outside the edge (importing the command's module, parsing its options,
    or after the edge's block had finished) with exit 130 and no word; then no one holds the lock, and
    :func:`main` says what happened: nothing was written, or the run had finished (the edge's ``ran``).  Taking
    the lock here keeps the watchdog from printing a second line."""
    lock = _edge_state().get("finish")
    return lock is not None and not lock.acquire(blocking=False)


def _after_the_run(code: int) -> bytes:
    return (b"interrupted: after the run had finished (its files were all written)\n" if code == 0
            else b"interrupted: after the run had ended\n")


#: BLAS thread variables :func:`one_blas_thread` sets (OpenBLAS: NumPy's and SciPy's wheels; MKL: conda builds).
BLAS_THREAD_VARS = ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


def one_blas_thread() -> bool:
    """Run BLAS/LAPACK on one thread in this command unless the user chose a count.

    The CLI's matrices are small (the record screen's null law: ``eigvalsh`` of a few hundred square; GMWM's
    covariances): on a busy machine OpenBLAS's threads spin against each other and the other jobs, measured 3-37x
    slower per ``eigvalsh`` at load 5 on two cores and 1.6x on a whole ``fogdrift allan`` (bench/RESULTS.md),
    while on an idle machine the second thread saves a few ms.  Numba's threads are sized by the kernels
    themselves (``allan._kernels``).  A value the user set (``OPENBLAS_NUM_THREADS=4 fogdrift ...``) is kept.
    The variables are read when the library loads, so this acts only before NumPy is imported (a fresh command);
    called later (``main()`` inside a test or a notebook) it changes nothing, not even the environment its child
    processes inherit.  Returns whether it set the count.  A command's children (fleet workers, Monte-Carlo pools)
    inherit the setting.
    """
    if "numpy" in sys.modules:
        return False
    for var in BLAS_THREAD_VARS:
        os.environ.setdefault(var, "1")
    return True


def main():  # the command line; entry() is the console script's entry point
    import _signal  # loaded by the interpreter itself; ``signal`` (the enum wrapper) would import enum first

    _phase["command_over"] = False
    if _signal.getsignal(_signal.SIGINT) is not _signal.SIG_IGN:  # ignored: a background job asked for no Ctrl-C
        try:
            _signal.signal(_signal.SIGINT, _outside_the_guard)
        except ValueError:  # not the main thread: no handler can be set there
            pass
    one_blas_thread()
    from .. import interrupt

    code = 0
    try:  # outside the guard too: a Ctrl-C while the guard itself starts or stops
        with interrupt.SigintGuard(on_timeout=_on_timeout, grace_s=0.6):
            try:
                _lazy_app()(prog_name="fogdrift")
            except SystemExit as exc:
                code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
                if code == 130 and not _line_claimed():  # typer turned a Ctrl-C outside the command's edge into 130
                    os.write(2, _after_the_run(0) if _edge_state().get("ran") else NOTHING_WRITTEN)
            except KeyboardInterrupt:  # before a command's frame took over (imports, option parsing)
                os.write(2, NOTHING_WRITTEN)
                code = 130
            finally:
                _phase["command_over"] = True  # from here on a Ctrl-C cannot mean "nothing was written"
    except KeyboardInterrupt:
        if code != 130:
            os.write(2, _after_the_run(code) if _phase["command_over"] else NOTHING_WRITTEN)
        code = 130
    if interrupt.requested() and code != 130:  # Ctrl-C after the command's frame had finished
        os.write(2, _after_the_run(code))
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


def entry():
    """The ``fogdrift`` console script and ``python -m fogdrift``: :func:`main`, then the interpreter's own exit
    without its last garbage collections.

    At exit CPython finalises its modules and runs full collections of the cyclic garbage collector over every
    object the process still holds -- some 2e5 after ``fogdrift allan`` (numba's typing registries, matplotlib,
    SciPy), about 0.2-0.4 s of CPU -- only to free memory the process gives back anyway.  :func:`gc.freeze` moves
    them to the permanent generation, which no collection visits; the atexit handlers, the joining of threads, the
    flushing of the standard streams and the modules' teardown (objects freed by their reference counts) run as
    before, and a command's files are closed before it returns.

    While the command runs, the collector's youngest generation is collected every :data:`GC_THRESHOLDS` ``[0]``
    allocations instead of CPython's 700: the command's imports (numba's registries, matplotlib, SciPy) create some
    2e5 long-lived objects, and each of the ~500 young collections and ~50 older ones of ``fogdrift allan`` visited
    them again (0.3 s of CPU, 0.15 s with these thresholds); cyclic garbage still goes within a few MB.

    Only the process's entry point does this: :func:`main` called in a process that goes on (a test, a notebook)
    leaves the collector alone.
    """
    import gc

    gc.set_threshold(*GC_THRESHOLDS)
    try:
        main()
    finally:
        gc.freeze()


#: The collector's thresholds (:func:`gc.set_threshold`) in the ``fogdrift`` process (:func:`entry`): youngest
#: generation every 50 000 allocations, the older ones every 20 collections of the one below.
GC_THRESHOLDS = (50_000, 20, 20)
