"""Cooperative interruption: the flag, checkpoints, stage listeners, the SIGINT guard and its watchdog.

Real signals to this process (os.kill); the CLI-level tests with a real Ctrl-C in a subprocess are in
tests/test_cli_safety.py.
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


def test_sigint_raises_interrupted_and_the_handler_is_restored():
    before = signal.getsignal(signal.SIGINT)
    with pytest.raises(Interrupted):
        with SigintGuard():
            os.kill(os.getpid(), signal.SIGINT)
            for _ in range(100):  # the handler runs at the next bytecode boundary
                time.sleep(0.01)
    assert interrupt.requested()
    assert signal.getsignal(signal.SIGINT) is before


def test_a_swallowed_interrupt_is_raised_again_at_the_next_check():
    # what happens inside a ctypes callback: the KeyboardInterrupt is lost, the flag is not
    with SigintGuard():
        try:
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.5)
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
    t0 = time.monotonic()
    with SigintGuard(on_timeout=fired.set, grace_s=0.3):
        with pytest.raises(Interrupted):
            with critical():  # stands for compiled code that never returns to a checkpoint in time
                os.kill(os.getpid(), signal.SIGINT)
                fired.wait(3.0)
    assert fired.is_set() and time.monotonic() - t0 < 2.0


def test_watchdog_stays_quiet_when_the_run_stops_in_time():
    fired = threading.Event()
    with pytest.raises(Interrupted):
        with SigintGuard(on_timeout=fired.set, grace_s=0.3):
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(1.0)
    time.sleep(0.5)
    assert not fired.is_set()


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
