"""Cooperative interruption of long runs, and the stage reports that come with it.

Why not just ``KeyboardInterrupt``?  Python runs a signal handler in the main thread between bytecodes.  While
the main thread is inside compiled code (a numba kernel, an XLA compilation) the handler waits, possibly for
seconds; when the handler happens to run inside a callback that compiled code made into Python (llvmlite's
object-cache callbacks during numba compilation are ctypes callbacks), the ``KeyboardInterrupt`` it raises is
printed as "Exception ignored on calling ctypes callback function" and dropped, and the run goes on.

So an interruption here is a **flag** that survives such a loss:

* :func:`request` sets it; :class:`SigintGuard` installs a SIGINT handler that sets it, and raises
  :class:`Interrupted` (a ``KeyboardInterrupt``) at once unless a JAX/numba/llvmlite frame is on the main
  thread's stack or a :func:`critical` section is running (there an exception could be dropped, or unwind
  through a compiler and crash it);
* :func:`check` and :func:`checkpoint` raise :class:`Interrupted` whenever the flag is set.  The library calls
  :func:`checkpoint` between stages, axes and models (:mod:`fogdrift.pipeline`); progress callbacks (Allan
  taus, training epochs) call :func:`check`, so a dropped interrupt is raised again within one step;
* a watchdog thread, woken by the signal itself (``signal.set_wakeup_fd``, written by the C-level handler even
  while the main thread is stuck in compiled code that released the GIL), calls ``on_timeout`` when the main
  thread has not finished ``grace_s`` seconds after the signal.  The CLI uses it to clean up and exit.  While
  the main thread runs a :func:`shielded` block (a batch starting its worker processes, or killing them and
  removing what they left), the watchdog waits for it (at most :data:`SHIELD_MAX_S`) and then gives the run its
  grace again: a loaded machine slows such a block down, and ending the process in the middle of it would leave
  processes and files behind.

:func:`checkpoint` also tells registered listeners (:func:`stage_listener`) which stage, axis and model a run
is in; the CLI shows them on its progress bar.  Without a guard or a listener, a checkpoint costs one flag test.
"""

from __future__ import annotations

import contextlib
import signal
import socket
import sys
import threading
from typing import Callable

__all__ = [
    "Interrupted",
    "SigintGuard",
    "check",
    "checkpoint",
    "critical",
    "request",
    "requested",
    "reset",
    "shielded",
    "stage_listener",
    "FOREIGN_RUNTIMES",
]


class Interrupted(KeyboardInterrupt):
    """The run was interrupted (SIGINT / Ctrl-C, or :func:`request`)."""

    def __init__(self, message: str = "interrupted"):
        super().__init__(message)


_flag = threading.Event()
_listeners: list[Callable] = []
_critical_depth = 0
_shields = threading.Condition()
_shield_depth = 0
#: Seconds the watchdog waits at most for a :func:`shielded` block before it ends the process anyway.
SHIELD_MAX_S = 60.0


def request() -> None:
    """Ask the running computation to stop at its next checkpoint."""
    _flag.set()


def requested() -> bool:
    """True once an interruption was requested (until :func:`reset`)."""
    return _flag.is_set()


def reset() -> None:
    """Forget a requested interruption (a new run starts)."""
    _flag.clear()


def check() -> None:
    """Raise :class:`Interrupted` if an interruption was requested (and we are not in a :func:`critical` section).

    Examples
    --------
    >>> check()  # nothing requested: returns
    >>> request()
    >>> try:
    ...     check()
    ... except Interrupted as exc:
    ...     print("stopped:", exc)
    stopped: interrupted
    >>> reset()
    """
    if _flag.is_set() and _critical_depth == 0:
        raise Interrupted()


def checkpoint(stage: str, *, axis: str | None = None, model: str | None = None) -> None:
    """A point where a run may stop: raise :class:`Interrupted` if requested, else tell the stage listeners.

    Parameters
    ----------
    stage : str
        What starts now, in words ("Allan variance", "separation", "fitting", ...).
    axis, model : str, optional
        The axis and the drift model it concerns.
    """
    check()
    for listener in tuple(_listeners):
        listener(stage, axis, model)


@contextlib.contextmanager
def stage_listener(listener: Callable):
    """Call ``listener(stage, axis, model)`` at every :func:`checkpoint` inside the block."""
    _listeners.append(listener)
    try:
        yield listener
    finally:
        _listeners.remove(listener)


@contextlib.contextmanager
def critical():
    """A block that a SIGINT does not cut: the handler only sets the flag; :func:`check` raises after the block.

    For short bookkeeping that must be all-or-nothing (rename a finished file and record it).
    """
    global _critical_depth
    _critical_depth += 1
    try:
        yield
    finally:
        _critical_depth -= 1
    check()


@contextlib.contextmanager
def shielded():
    """A bounded block that an interruption must not cut short (see the module docstring): a SIGINT only sets the
    flag (as in :func:`critical`, a second one too), and the :class:`SigintGuard` watchdog waits for the block (at
    most :data:`SHIELD_MAX_S`) instead of ending the process in the middle of it.  Unlike :func:`critical` it does
    not raise at its end: the caller checks (:func:`check`) where it can stop."""
    global _shield_depth, _critical_depth
    with _shields:
        _shield_depth += 1
    _critical_depth += 1
    try:
        yield
    finally:
        _critical_depth -= 1
        with _shields:
            _shield_depth -= 1
            _shields.notify_all()


def _wait_for_shields(timeout: float) -> bool:
    """Wait until no :func:`shielded` block runs (at most ``timeout`` seconds); True if one ran."""
    with _shields:
        busy = _shield_depth > 0
        _shields.wait_for(lambda: _shield_depth == 0, timeout)
    return busy


#: Packages whose Python code runs inside compiled runtimes (tracing, lowering, compiling, object-cache
#: callbacks): an exception raised in the middle of them can be dropped or leave the runtime broken (a crash at
#: exit was seen when a KeyboardInterrupt unwound through XLA lowering), so the handler only sets the flag there.
FOREIGN_RUNTIMES = ("jax", "jaxlib", "numba", "llvmlite", "optax")


def _safe_to_raise(frame) -> bool:
    """Raise at once unless a compiled runtime's Python frame is on the stack (see FOREIGN_RUNTIMES)."""
    if frame is None:
        return False
    while frame is not None:
        top = str(frame.f_globals.get("__name__", "")).partition(".")[0]
        if top in FOREIGN_RUNTIMES:
            return False
        frame = frame.f_back
    return True


class SigintGuard:
    """Context manager: SIGINT sets the interruption flag and raises :class:`Interrupted` where that is safe (see
    the module docstring); a watchdog calls ``on_timeout()`` if the block is still running ``grace_s`` seconds
    after the first SIGINT.

    Only effective in the main thread, and not when SIGINT is ignored on entry (a background job of a
    non-interactive shell: the shell asked for Ctrl-C not to reach it).  On exit the previous handler, wakeup
    fd and ``sys.unraisablehook`` are restored.  While an interruption is requested, a ``KeyboardInterrupt``
    that Python could not raise (an "unraisable" one, e.g. in a ctypes callback) is not printed.

    Parameters
    ----------
    on_timeout : callable or None
        Called from the watchdog thread; it should end the process (the CLI prints what was written and calls
        ``os._exit(130)``).  None: no watchdog.
    grace_s : float
        Seconds the main thread has to reach a checkpoint before ``on_timeout`` runs.
    """

    def __init__(self, on_timeout: Callable | None = None, grace_s: float = 0.6):
        self.on_timeout = on_timeout
        self.grace_s = float(grace_s)
        self.installed = False
        self._done = threading.Event()

    # -- the handler -------------------------------------------------------------------------------
    def _handler(self, signum, frame):
        request()
        if _critical_depth == 0 and _safe_to_raise(frame):
            raise Interrupted()

    def _unraisable(self, unraisable):
        if requested() and isinstance(unraisable.exc_value, KeyboardInterrupt):
            return  # the flag keeps the interruption; the checkpoints raise it again
        self._prev_hook(unraisable)

    def _watch(self, sock: socket.socket):
        while True:
            try:
                data = sock.recv(64)
            except OSError:
                return
            if not data:  # closed on exit
                return
            if signal.SIGINT in data:
                if self._done.wait(self.grace_s):
                    return
                if _wait_for_shields(SHIELD_MAX_S) and self._done.wait(self.grace_s):
                    return  # the shielded block ended, then the run within its grace
                if self.on_timeout is not None:
                    self.on_timeout()
                return

    # -- context -----------------------------------------------------------------------------------
    def __enter__(self):
        reset()
        if threading.current_thread() is not threading.main_thread():
            return self
        if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
            return self
        self._prev_handler = signal.signal(signal.SIGINT, self._handler)
        self._prev_hook = sys.unraisablehook
        sys.unraisablehook = self._unraisable
        self._sock_r = self._sock_w = None
        self._prev_fd = -1
        if self.on_timeout is not None:
            self._sock_r, self._sock_w = socket.socketpair()
            self._sock_w.setblocking(False)
            self._prev_fd = signal.set_wakeup_fd(self._sock_w.fileno(), warn_on_full_buffer=False)
            self._thread = threading.Thread(target=self._watch, args=(self._sock_r,), name="fogdrift-sigint-watchdog",
                                            daemon=True)
            self._thread.start()
        self.installed = True
        return self

    def __exit__(self, *exc):
        self._done.set()
        if not self.installed:
            return False
        signal.signal(signal.SIGINT, self._prev_handler)
        sys.unraisablehook = self._prev_hook
        if self._sock_w is not None:
            signal.set_wakeup_fd(self._prev_fd)
            with contextlib.suppress(OSError):
                self._sock_w.close()
            with contextlib.suppress(OSError):
                self._sock_r.shutdown(socket.SHUT_RDWR)
            self._thread.join(timeout=1.0)
            with contextlib.suppress(OSError):
                self._sock_r.close()
        self.installed = False
        return False
