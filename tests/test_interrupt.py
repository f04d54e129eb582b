"""Cooperative interruption: the flag, checkpoints, stage listeners, the SIGINT guard and its watchdog.

Real signals to this process (os.kill); the CLI-level tests with a real Ctrl-C in a subprocess are in
tests/cli/test_cli_safety.py.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
import time

import pytest

from fogdrift import interrupt
from fogdrift.interrupt import Interrupted, SigintGuard, check, checkpoint, critical, stage_listener


@pytest.fixture(autouse=True)
def _clean_flag():
    """A fresh flag, and Python's own SIGINT handler even when the suite runs as a background job (where a
    non-interactive shell starts it with SIGINT ignored, which the guard respects)."""
    interrupt.reset()
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)
    interrupt.reset()


def test_checkpoint_reports_stages_and_raises_once_requested():
    seen = []
    with stage_listener(lambda *a: seen.append(a)):
        checkpoint("separation", axis="gz")
        checkpoint("fitting", axis="gz", model="AR(p)")
        interrupt.request()
        with pytest.raises(Interrupted):
            checkpoint("Table 2", axis="gz")
    checkpoint_after = seen[:]
    assert checkpoint_after == [("separation", "gz", None), ("fitting", "gz", "AR(p)")]
    assert isinstance(Interrupted(), KeyboardInterrupt)


def test_critical_section_defers_the_interruption_to_its_end():
    done = []
    with pytest.raises(Interrupted):
        with critical():
            interrupt.request()
            check()  # deferred
            done.append("renamed and recorded")
    assert done == ["renamed and recorded"]


def _run_as(module: str, source: str, steps: list | None = None):
    """Run ``source`` as if it were code of ``module`` (the handler decides by the frame's module); ``steps``
    collects the loop steps that ran after the signal."""
    exec(compile(source, f"<{module}>", "exec"), {"__name__": module, "steps": [] if steps is None else steps})


WAIT = ("import os, signal, time\nos.kill(os.getpid(), signal.SIGINT)\nfor _ in range(50):\n    steps.append(1)\n"
        "    time.sleep(0.01)\n")


@pytest.mark.parametrize("module", ["fogdrift.pipeline_like", "matplotlib.figure_like"])
def test_sigint_in_plain_python_raises_at_once_and_the_handler_is_restored(module):
    before = signal.getsignal(signal.SIGINT)
    steps = []
    with pytest.raises(Interrupted):
        with SigintGuard():
            _run_as(module, WAIT, steps)
    assert len(steps) <= 1  # raised at the first step after the signal, not after the 50 steps
    assert interrupt.requested()
    assert signal.getsignal(signal.SIGINT) is before


@pytest.mark.parametrize("module", ["jax._src.interpreters.mlir", "numba.core.compiler", "llvmlite.binding"])
def test_sigint_elsewhere_only_sets_the_flag_for_the_next_checkpoint(module):
    steps = []
    with SigintGuard():
        _run_as(module, WAIT, steps)  # runs to its end: nothing is unwound through foreign (compiled) code
        assert len(steps) == 50
        assert interrupt.requested()
        with pytest.raises(Interrupted):
            checkpoint("next stage")


def test_sigint_in_fogdrift_code_called_from_jax_only_sets_the_flag():
    # e.g. fogdrift's training step being traced by jax: raising there would unwind through the compiler
    inner = "import os, signal, time\nos.kill(os.getpid(), signal.SIGINT)\nfor _ in range(30):\n    time.sleep(0.01)\n"
    outer = f"run_as({'fogdrift.models.training'!r}, {inner!r})\n"
    with SigintGuard():
        exec(compile(outer, "<jax>", "exec"), {"__name__": "jax._src.tracing", "run_as": _run_as})
        assert interrupt.requested()


def test_a_swallowed_interrupt_is_raised_again_at_the_next_check():
    # what happens inside a ctypes callback: the KeyboardInterrupt is lost, the flag is not
    with SigintGuard():
        try:
            _run_as("fogdrift.callback_like", WAIT)
        except KeyboardInterrupt:
            pass  # swallowed by "compiled code"
        with pytest.raises(Interrupted):
            check()


def test_unraisable_keyboard_interrupt_is_silent_while_interrupted(capsys):
    class Unraisable:
        exc_type, exc_value, exc_traceback, err_msg, object = KeyboardInterrupt, KeyboardInterrupt(), None, "x", None

    calls = []
    previous = sys.unraisablehook
    sys.unraisablehook = lambda u: calls.append(u)
    try:
        with SigintGuard():
            interrupt.request()
            sys.unraisablehook(Unraisable())  # dropped
            other = Unraisable()
            other.exc_value = ValueError("real problem")
            sys.unraisablehook(other)  # passed on
    finally:
        sys.unraisablehook = previous
    assert len(calls) == 1 and isinstance(calls[0].exc_value, ValueError)


def test_watchdog_ends_a_run_stuck_after_sigint():
    fired = threading.Event()
    with SigintGuard(on_timeout=fired.set, grace_s=0.3):
        with pytest.raises(Interrupted):
            with critical():  # stands for compiled code that never returns to a checkpoint in time
                os.kill(os.getpid(), signal.SIGINT)
                stuck = fired.wait(60.0)  # a hang guard only: returns as soon as the watchdog acts
    assert stuck  # the watchdog acted while the main thread was still stuck


def test_watchdog_stays_quiet_when_the_run_stops_in_time():
    fired = threading.Event()
    guard = SigintGuard(on_timeout=fired.set, grace_s=30.0)  # the run stops in time even on a loaded machine
    with pytest.raises(Interrupted):
        with guard:
            os.kill(os.getpid(), signal.SIGINT)
            for _ in range(100):  # a checkpoint every 10 ms
                time.sleep(0.01)
                check()
    guard._thread.join(60.0)  # the watchdog ends when the block ends, not when the grace time is over
    assert not guard._thread.is_alive() and not fired.is_set()


def test_watchdog_waits_for_a_shielded_block_instead_of_cutting_it_short(monkeypatch):
    # a batch starting its workers, or killing them and removing their lock files, runs in interrupt.shielded(): on
    # a loaded machine it outlasts the grace time, and the watchdog ending the process then left workers running
    # and a lock file behind (issue 36).  The rule, without a clock: once its grace is over the watchdog waits
    wanted = interrupt._wait_for_shields
    waiting = threading.Event()

    def wait_for_shields(timeout):
        waiting.set()
        return wanted(timeout)

    monkeypatch.setattr(interrupt, "_wait_for_shields", wait_for_shields)
    fired = threading.Event()
    with SigintGuard(on_timeout=fired.set, grace_s=0.01) as guard:
        with interrupt.shielded():
            os.kill(os.getpid(), signal.SIGINT)  # only the flag
            for _ in range(6000):  # a hang guard only: ends as soon as the watchdog waits, or acts
                if waiting.is_set() or fired.is_set():
                    break
                time.sleep(0.01)
            assert waiting.is_set() and not fired.is_set()
            assert interrupt.requested()
        # the block is over: the watchdog gives the run its grace again, then acts (the run is still here)
        assert fired.wait(60.0)
        guard_thread = guard._thread
    guard_thread.join(60.0)
    assert not guard_thread.is_alive()


def test_ignored_sigint_is_respected():
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        with SigintGuard() as guard:
            assert not guard.installed
            assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
    finally:
        signal.signal(signal.SIGINT, previous)


def test_pipeline_reports_its_stages_and_stops_between_models():
    import numpy as np

    from fogdrift.io import from_array
    from fogdrift.pipeline import AnalysisConfig, run_models, run_separation

    rng = np.random.default_rng(7)
    rec = from_array(np.cumsum(rng.normal(size=(4000, 2)), axis=0) * 0.01 + rng.normal(size=(4000, 2)),
                     dt_s=1.0, axis_names=("gx", "gz"))
    cfg = AnalysisConfig(models=("ar", "gm11", "persistence"), model_rate_hz=None)
    seen = []
    with stage_listener(lambda *a: seen.append(a)):
        seps = run_separation(rec, cfg)
    assert seen == [("separation", "gx", None), ("separation", "gz", None)]
    assert [s.mean_removed_dph for s in seps] == pytest.approx(rec.rate_dph.mean(axis=0).tolist())

    seen.clear()

    def stop_at_second_model(stage, axis, model):
        seen.append((stage, axis, model))
        if model == "gm11":
            interrupt.request()  # Ctrl-C while GM(1,1) is announced: it must not be fitted

    with stage_listener(stop_at_second_model), pytest.raises(Interrupted):
        with stage_listener(lambda s, a, m: interrupt.check()):
            run_models(rec, cfg)
    assert seen == [("separation", "gx", None), ("fitting", "gx", "ar"), ("fitting", "gx", "gm11")]


def _sigint_after(event: threading.Event, events: list, pause: float = 0.05):
    """A thread that sends this process a real SIGINT once ``event`` is set (compiled code is running by then),
    first appending "SIGINT" to ``events``: the steps the run logs there after it are the steps it took after the
    signal (at most the one in flight), whatever the machine's load."""
    def run():
        if event.wait(120):
            time.sleep(pause)
            events.append("SIGINT")
            os.kill(os.getpid(), signal.SIGINT)
    threading.Thread(target=run, daemon=True).start()


def _steps_after_the_signal(events: list) -> int:
    assert "SIGINT" in events, "the signal was never sent"
    return len(events) - 1 - events.index("SIGINT")


@pytest.mark.slow
def test_real_sigint_during_numba_allan_kernels_stops_at_the_next_tau_group():
    import numpy as np

    from fogdrift.allan import allan_variance

    x = np.random.default_rng(3).normal(size=6_000_000)
    started, events = threading.Event(), []

    def progress(done, total):  # what the CLI's progress callback does
        check()
        events.append(done)
        started.set()

    _sigint_after(started, events)
    with SigintGuard(), pytest.raises(Interrupted):
        allan_variance(x, 0.01, taus=400, progress=progress)
    assert events[0] != "SIGINT"  # the kernels were running
    assert _steps_after_the_signal(events) <= 1  # stopped at the next tau group (the one in flight at most)


@pytest.mark.slow
def test_real_sigint_during_jax_training_stops_at_the_next_epoch():
    import numpy as np

    from fogdrift.models import build_model
    from fogdrift.pipeline import AnalysisConfig

    t = np.arange(3000.0)
    y = np.sin(2 * np.pi * t / 300) + 0.3 * np.sin(2 * np.pi * t / 47) + np.random.default_rng(4).normal(0, 0.05, t.size)
    started, events = threading.Event(), []

    def epoch_cb(epoch, n_epochs, train_loss, val_loss):  # what the CLI's epoch callback does
        check()
        events.append(epoch)
        started.set()

    model = build_model("elman", AnalysisConfig(epochs=200_000, hidden=8), epoch_cb)
    _sigint_after(started, events)
    with SigintGuard(), pytest.raises(Interrupted):
        model.fit(y[:2000], y[2000:])
    assert events[0] != "SIGINT"  # training was running
    assert _steps_after_the_signal(events) <= 1  # stopped at the next epoch (the one in flight at most)
    assert len(events) - 1 < 200_000
