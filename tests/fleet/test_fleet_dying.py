"""A Dask worker or scheduler dying mid-batch (issue 36): the file fails with one line, the others finish, the
command exits 1 with no traceback, no hang, no lock file and no process of its group left behind.

The deaths come at an event, not a time: ``FOGDRIFT_TEST_KILL=FILE:PID`` (:data:`fogdrift.fleet.tasks.TEST_KILL_ENV`)
makes the task of one file SIGKILL a process (``self``: its own worker) once it holds its folder's lock.  A
``tcp://`` cluster is a ``dask scheduler`` and a ``dask worker`` started here on 127.0.0.1.  Every wait is on an
event, with a bound that only guards against a hang.
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from fogdrift.fleet import tasks as fleet_tasks
from fogdrift.fleet.tasks import MANIFEST as BATCH_JSON
from fogdrift.output import LOCK, TMP_PREFIX

pytest.importorskip("pyarrow")
psutil = pytest.importorskip("psutil")

HANG_GUARD_S = 300


def _logs(folder: Path, n: int) -> list[Path]:
    rng = np.random.default_rng(36)
    folder.mkdir(parents=True, exist_ok=True)
    paths = []
    for k in range(n):
        p = folder / f"unit{k}.npy"
        np.save(p, rng.normal(0.0, 1.0, 20_000))
        paths.append(p)
    return paths


def _live(pgid: int) -> list[tuple[int, str]]:
    live = []
    for p in psutil.process_iter():
        try:
            if os.getpgid(p.pid) == pgid and p.status() != psutil.STATUS_ZOMBIE:
                live.append((p.pid, " ".join(p.cmdline())))
        except (OSError, psutil.Error):
            continue
    return live


def _batch(tmp_path: Path, files, *args, env=None) -> tuple[int, str, str, Path]:
    """``fogdrift batch`` in a process group of its own; checks that nothing of the group outlives it (but
    multiprocessing's resource tracker, which ends by itself once the batch has: waited for, with a hang guard)."""
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-m", "fogdrift", "batch", *map(str, files), "--unit", "deg/h", "--rate",
                             "100", *args, "--out", str(out)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True, env={**os.environ, **(env or {})})
    try:
        stdout, stderr = proc.communicate(timeout=HANG_GUARD_S)
        left = [(pid, cmd) for pid, cmd in _live(proc.pid) if cmd and "resource_tracker" not in cmd]
        assert left == [], left
        deadline = time.monotonic() + 60
        while _live(proc.pid) and time.monotonic() < deadline:
            time.sleep(0.02)
        assert _live(proc.pid) == []
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGKILL)
    return proc.returncode, stdout, stderr, out


def _assert_clean(out: Path, stderr: str) -> None:
    assert "Traceback" not in stderr and "ERROR" not in stderr and "leaked" not in stderr, stderr
    assert sorted(p.relative_to(out).as_posix() for p in out.rglob(LOCK)) == []
    assert sorted(p.relative_to(out).as_posix() for p in out.rglob(TMP_PREFIX + "*")) == []


def _failed_lines(stdout: str) -> dict[str, str]:
    """The ``  FILE: error`` lines under the batch's count line."""
    rows = [ln.strip() for ln in stdout.splitlines() if ln.startswith("  unit")]
    return dict(ln.split(": ", 1) for ln in rows)


def test_the_kill_hook_is_inert_unless_set_and_naming_the_file(monkeypatch):
    task = fleet_tasks.FileTask(path="/d/unit0.npy", file="unit0.npy", out_dir="/o/unit0.npy", rel_out="unit0.npy",
                                command="allan", settings={}, settings_sha256="0" * 64)
    monkeypatch.delenv(fleet_tasks.TEST_KILL_ENV, raising=False)
    fleet_tasks._test_kill(task)                       # unset: nothing
    monkeypatch.setenv(fleet_tasks.TEST_KILL_ENV, "unit1.npy:self")
    fleet_tasks._test_kill(task)                       # another file: nothing (this process is still here)
    monkeypatch.setenv(fleet_tasks.TEST_KILL_ENV, "")
    fleet_tasks._test_kill(task)


def test_a_cluster_left_without_workers_cancels_the_files_not_done(monkeypatch):
    """The watch thread: no worker left for NO_WORKERS_TIMEOUT_S -> the futures not done are cancelled (each then
    an error row saying so); workers present, or none yet (an adaptive cluster starting them) -> nothing.  A
    stand-in client, no clock beyond the bounds."""
    import threading

    from fogdrift.fleet import runner

    monkeypatch.setattr(runner, "WATCH_INTERVAL_S", 0.005)
    monkeypatch.setattr(runner, "NO_WORKERS_TIMEOUT_S", 0.02)

    class Future:
        def __init__(self, done):
            self._done = done

        def done(self):
            return self._done

    class Client:
        def __init__(self, *workers):
            self.workers, self.cancelled = list(workers), threading.Event()
            self.which = None
            self.looks = 0

        def nthreads(self):
            self.looks += 1
            return self.workers.pop(0) if len(self.workers) > 1 else self.workers[0]

        def cancel(self, futures, reason=None):
            self.which = (futures, reason)
            self.cancelled.set()

    pending, finished = Future(False), Future(True)
    empty = Client({"tcp://w:1": 1}, {})      # had a worker, then none
    watch = runner._Watch(empty, {pending: 0, finished: 1}, "Dask cluster at tcp://x:1")
    assert empty.cancelled.wait(HANG_GUARD_S)
    watch.stop()
    assert empty.which == ([pending], "no-workers")
    assert watch.reason == "the Dask cluster at tcp://x:1 had no worker for 0.02 s (all died, none restarted)"
    row, = runner._error_rows(fleet_tasks.FileTask(path="/d/u.npy", file="u.npy", out_dir="/o/u.npy", rel_out="u.npy",
                                                   command="allan", settings={}, settings_sha256="0" * 64),
                              RuntimeError("cancelled"), runner._lost(RuntimeError("x"), "tcp://x:1", watch))
    assert row["error"].startswith("not finished: the Dask cluster at tcp://x:1 had no worker for 0.02 s")
    for workers in ({"tcp://w:1": 1}, {}):            # a worker all along; none yet: some looks, nothing cancelled
        busy = Client(workers)
        watch = runner._Watch(busy, {pending: 0}, "local Dask cluster")
        deadline = time.monotonic() + HANG_GUARD_S
        while busy.looks < 20 and time.monotonic() < deadline:
            time.sleep(0.005)
        watch.stop()
        assert watch.reason is None and not busy.cancelled.is_set() and busy.looks >= 20


@pytest.mark.slow
def test_a_local_worker_killed_mid_file(tmp_path):
    """The worker running unit1 is SIGKILLed holding its folder's lock: unit1 fails with one line (not retried:
    runner.ALLOWED_FAILURES), the nanny's new worker and the other worker run the rest, exit 1."""
    files = _logs(tmp_path / "in", 4)
    rc, stdout, stderr, out = _batch(tmp_path, files, "--workers", "2", env={"FOGDRIFT_TEST_KILL": "unit1.npy:self"})
    assert rc == 1, stdout + stderr
    assert _failed_lines(stdout) == {"unit1.npy": "KilledWorker: the worker process running unit1.npy died (out of "
                                     "memory is the usual cause: run it alone, or with fewer --workers)"}, stdout
    assert "4 files on local Dask cluster, 2 worker processes" in stdout and "3 done" in stdout and "1 failed" in stdout
    _assert_clean(out, stderr)
    assert not (out / "unit1.npy" / BATCH_JSON).exists()
    assert all((out / f"unit{k}.npy" / BATCH_JSON).exists() for k in (0, 2, 3))


@contextlib.contextmanager
def _tcp_cluster(tmp_path: Path, worker_env: dict | None = None, scheduler_env: dict | None = None):
    """A ``dask scheduler`` on 127.0.0.1 (a free port) and one ``dask worker`` (its nanny, one thread), each in a
    process group of its own; ``{scheduler}`` in a worker_env value is the scheduler's process id; yields
    (address, scheduler process); kills both groups after."""
    info = tmp_path / "scheduler.json"
    procs = []
    try:
        procs.append(subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1",
                                       "--port", "0", "--no-dashboard", "--scheduler-file", str(info)],
                                      stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True,
                                      env={**os.environ, **(scheduler_env or {})}))
        deadline = time.monotonic() + HANG_GUARD_S
        address = None
        while address is None and time.monotonic() < deadline and procs[0].poll() is None:
            with contextlib.suppress(OSError, ValueError, KeyError):
                address = json.loads(info.read_text())["address"]
            time.sleep(0.02)
        assert address, "the scheduler did not start"
        procs.append(subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_worker", address, "--nthreads", "1",
                                       "--nworkers", "1", "--no-dashboard"], stdout=subprocess.DEVNULL,
                                      stderr=subprocess.DEVNULL, start_new_session=True,
                                      env={**os.environ, **{k: v.format(scheduler=procs[0].pid)
                                                            for k, v in (worker_env or {}).items()}}))
        yield address, procs[0]
    finally:
        for p in procs:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(p.pid, signal.SIGKILL)
            p.wait()


@pytest.mark.slow
def test_a_tcp_scheduler_killed_mid_batch(tmp_path):
    """unit1's task kills the scheduler: unit0 is done, unit1 and unit2 fail with one line each naming the lost
    scheduler, without waiting for a reconnection, exit 1, no traceback; the worker finishes the file it was running
    (its lock goes with it: waited for, as an event)."""
    files = _logs(tmp_path / "in", 3)
    with _tcp_cluster(tmp_path, worker_env={"FOGDRIFT_TEST_KILL": "unit1.npy:{scheduler}"}) as (address, sched):
        t0 = time.monotonic()
        rc, stdout, stderr, out = _batch(tmp_path, files, "--scheduler", address)
        assert sched.wait(timeout=60) == -signal.SIGKILL
        lost = (f"not finished: the Dask scheduler {address} was lost (its connection closed) before it finished; a "
                "re-run of the batch computes it (finished files are skipped)")
        assert rc == 1, stdout + stderr
        assert _failed_lines(stdout) == {"unit1.npy": lost, "unit2.npy": lost}, stdout
        assert f"3 files on Dask cluster at {address}" in stdout and "1 done" in stdout, stdout
        assert time.monotonic() - t0 < 120          # no connection timeout of 30 s or more waited out
        deadline = time.monotonic() + HANG_GUARD_S   # the orphaned worker finishes unit1's folder
        while not (out / "unit1.npy" / BATCH_JSON).exists() and time.monotonic() < deadline:
            time.sleep(0.02)
        deadline = time.monotonic() + 60
        while list(out.rglob(LOCK)) and time.monotonic() < deadline:
            time.sleep(0.02)
    _assert_clean(out, stderr)
    assert (out / "unit0.npy" / BATCH_JSON).exists() and not (out / "unit2.npy").exists()


@pytest.mark.slow
def test_a_tcp_worker_killed_mid_file(tmp_path):
    """The worker running unit1 is SIGKILLed; the cluster's scheduler allows no retry (its own setting, as the
    module docstring of fleet.runner says): unit1 fails with one line, the nanny's new worker runs the others,
    the dead worker's lock is removed, exit 1."""
    files = _logs(tmp_path / "in", 3)
    with _tcp_cluster(tmp_path, worker_env={"FOGDRIFT_TEST_KILL": "unit1.npy:self"},
                      scheduler_env={"DASK_DISTRIBUTED__SCHEDULER__ALLOWED_FAILURES": "0"}) as (address, _):
        rc, stdout, stderr, out = _batch(tmp_path, files, "--scheduler", address)
    assert rc == 1, stdout + stderr
    assert _failed_lines(stdout) == {"unit1.npy": "KilledWorker: the worker process running unit1.npy died (out of "
                                     "memory is the usual cause: run it alone, or with fewer --workers)"}, stdout
    _assert_clean(out, stderr)
    assert (out / "unit0.npy" / BATCH_JSON).exists() and (out / "unit2.npy" / BATCH_JSON).exists()
