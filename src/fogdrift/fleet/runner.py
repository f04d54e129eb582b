"""Run one command over many logs on Dask: inputs, settings hash, scheduling, the summary and the fleet page.

Scheduling (``scheduler``):

* ``None`` (default): chosen by the work's size (:mod:`fogdrift.fleet.schedule`): the serial loop for a small
  batch (less input than a local cluster's start-up pays for, one file, or one usable core), else a local
  cluster as with ``"local"``; an explicit ``workers`` asks for the local cluster.
* ``"local"``: a local Dask cluster of worker *processes*, one per usable core but no more than the files
  (``workers`` to change it), one thread each; numeric libraries inside a worker get ``cores // workers``
  threads so that workers do not oversubscribe the machine.  The cluster listens on 127.0.0.1 only (its
  scheduler's HTTP server on a free port: distributed's default 8787 may be another cluster's, and taking
  another port prints a warning).
* ``"tcp://HOST:8786"``: an existing cluster (``dask scheduler`` + ``dask worker`` on other machines); the
  workers need fogdrift installed and must see the input and output paths (a shared file system).
* ``"serial"``: no Dask, a loop in this process.

Each file is one task (:func:`fogdrift.fleet.tasks.run_file`); a task that fails, or a worker that dies,
becomes an error row, never a crashed batch.  A file whose worker process dies (killed, out of memory) fails
with one line and is not retried on the local cluster (:data:`ALLOWED_FAILURES`: the worker restarts for the
other files; a re-run of the batch retries it and skips the finished ones); its dead worker's lock and temporary
files are removed.  On an existing cluster the scheduler's own ``distributed.scheduler.allowed-failures``
decides (Dask's default: 3 retries).  A lost scheduler fails every file not finished with one line each; a
cluster whose workers have all gone (none restarted) for :data:`NO_WORKERS_TIMEOUT_S` does the same.  Results are collected as they
finish (``progress``); the stages (the cluster starting, the files running, the summary being written) are
announced at :func:`fogdrift.interrupt.checkpoint` (the CLI shows them).

Outputs: the batch folder is a :class:`BatchOutputDir` (a :class:`fogdrift.output.OutputDir` that also
counts the files whose folders are finished); each file's folder is its own ``OutputDir`` (written by the
worker, ``batch.json`` last); ``summary.parquet`` and ``fleet.html`` are written through
:func:`~fogdrift.output.atomic_path` after every file has finished.  An interruption (Ctrl-C,
:mod:`fogdrift.interrupt`) stops the batch: finished folders stay complete (a re-run skips them), unfinished
ones have no ``batch.json``, and no summary or page is written.  Local workers ignore SIGINT (a Ctrl-C in
the terminal reaches the whole process group): the batch process alone decides, and its workers end before it
does (killed after an interruption, the lock and temporary files they left removed: :func:`_shut_down`).
"""

from __future__ import annotations

import contextlib
import glob as _glob
import hashlib
import json
import logging
import os
import re
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

from .. import interrupt
from ..errors import ConfigError
from ..io import load as load_fn
from ..io.load import check_load_options
from ..io.readers.base import require
from ..output import LOCK, TMP_PREFIX, OutputDir, FolderLock, active, recover, remove_stale_temporaries
from .commands import command_spec, spec_from_settings
from .schedule import choose, usable_cores, work_bytes
from .summary import COLUMNS, write_summary
from .tasks import MANIFEST, FileTask, run_file

__all__ = ["BatchResult", "BatchOutputDir", "run_batch", "find_inputs", "settings_sha256", "SUMMARY", "PAGE"]

#: Seconds to wait for an existing cluster's scheduler (``scheduler="tcp://..."``) before giving up.
CONNECT_TIMEOUT_S = 20.0
#: The local scheduler's HTTP server (health/metrics; the dashboard needs bokeh): loopback, a free port.
HTTP_ADDRESS = "127.0.0.1:0"
#: Seconds to wait for killed workers' folder locks to die with them (the kernel drops a lock as its process exits).
STALE_LOCK_WAIT_S = 2.0
#: Retries of a file whose worker process died, on the local cluster (distributed's ``allowed-failures``): none,
#: the file fails with one line (a worker dies of the file it runs: memory, most often) and a re-run retries it.
ALLOWED_FAILURES = 0
#: Seconds a cluster may have no worker left (all died, none restarted) before the files not finished fail.
NO_WORKERS_TIMEOUT_S = 60.0
#: Seconds between two looks at the cluster's workers while files run.
WATCH_INTERVAL_S = 1.0

#: File names written into the batch folder.
SUMMARY = "summary.parquet"
PAGE = "fleet.html"


@dataclass
class BatchResult:
    """What :func:`run_batch` did."""

    rows: list
    summary_path: Path
    page_path: Path | None
    n_files: int
    n_ok: int
    n_cached: int
    n_error: int
    wall_s: float
    scheduler: str
    notes: list = field(default_factory=list)


class BatchOutputDir(OutputDir):
    """The batch folder: an :class:`~fogdrift.output.OutputDir` whose :meth:`summary` also says which files'
    folders are finished (the workers write those, each as its own ``OutputDir``).

    :func:`run_batch` calls :meth:`start` with the number of files and :meth:`finished_file` as each
    file's folder is complete; the CLI's Ctrl-C line is :meth:`summary`.
    """

    def __init__(self, path, **kwargs):
        super().__init__(path, **kwargs)
        self.tasks: list = []
        self.finished: list[str] = []
        self._t0 = 0.0

    def start(self, tasks) -> None:
        """The batch's :class:`~fogdrift.fleet.tasks.FileTask` list (before any is run)."""
        self.tasks = list(tasks)
        self.finished = []
        self._t0 = time.time()

    def finished_file(self, rel_out: str) -> None:
        """A task's result arrived (its folder holds ``batch.json``, or it was unchanged)."""
        if rel_out not in self.finished:
            self.finished.append(rel_out)

    def finished_files(self) -> list[str]:
        """Folders finished in this run: reported, or holding a ``batch.json`` of these settings written since
        the batch started (a worker may have finished a file its result has not yet reached us for)."""
        done = list(self.finished)
        for t in self.tasks:
            if t.rel_out in done:
                continue
            man = Path(t.out_dir) / MANIFEST
            try:
                fresh = man.stat().st_mtime >= self._t0 - 1.0
                same = fresh and json.loads(man.read_text()).get("settings_sha256") == t.settings_sha256
            except (OSError, ValueError, AttributeError, RecursionError):
                same = False
            if same:
                done.append(t.rel_out)
        return done

    def summary(self) -> str:
        if not self.tasks:
            return super().summary()
        finished = self.finished_files()
        k, n = len(finished), len(self.tasks)
        shown = ", ".join(finished[:4]) + (f" and {k - 4} more" if k > 4 else "")
        text = (f"{k} of {n} files finished" + (f" ({shown}: their folders in {self.path} are complete and a "
                                                   "re-run skips them)" if k else "")
                + (f"; {n - k} not finished (no batch.json: a re-run computes them)" if k < n else ""))
        top = [name for name in (SUMMARY, PAGE) if name not in self.written]
        if top:
            earlier = " (the earlier run's are unchanged)" if any((self.path / t).exists() for t in top) else ""
            text += f"; {' and '.join(top)} not written{earlier}"
        return text + "; no partial file left"


def settings_sha256(command: str, settings: dict) -> str:
    """SHA-256 of the command and its settings as canonical JSON (key order does not matter).

    Examples
    --------
    >>> settings_sha256("allan", {"a": 1, "b": 2}) == settings_sha256("allan", {"b": 2, "a": 1})
    True
    """
    text = json.dumps({"command": command, "settings": settings}, sort_keys=True, default=str)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def _is_bag_dir(p: Path) -> bool:
    return p.is_dir() and (p / "metadata.yaml").is_file()


def find_inputs(inputs, pattern: str | None = None) -> list[Path]:
    """Input files from paths, directories (searched recursively with ``pattern``) and unexpanded wildcards.

    A ROS 2 bag directory (holding ``metadata.yaml``) is one input.  The result is sorted and free of
    duplicates.

    Raises
    ------
    ConfigError
        No inputs, a path that does not exist, a directory without ``pattern``, or nothing found.
    """
    found = []
    if not inputs:
        raise ConfigError("no inputs; expected log files, folders (with {opt:glob}) or wildcards")
    for item in inputs:
        p = Path(item)
        if _is_bag_dir(p):
            found.append(p)
        elif p.is_dir():
            if not pattern:
                raise ConfigError(f"{p} is a folder; pass {{opt:glob}} (e.g. '*.csv.gz') to choose its files")
            found += [q for q in p.rglob(pattern) if q.is_file() or _is_bag_dir(q)]
        elif p.exists():
            if pattern is None or p.match(pattern):
                found.append(p)
        elif any(c in str(item) for c in "*?["):
            found += [Path(q) for q in _glob.glob(str(item), recursive=True)]
        else:
            raise ConfigError(f"input {str(item)!r} does not exist; expected a file, a folder or a wildcard")
    out = sorted({q.resolve() for q in found})
    if not out:
        raise ConfigError(f"no input files found in {list(map(str, inputs))}"
                          + (f" matching {pattern!r}" if pattern else ""))
    return out


def _names(paths: list[Path]) -> list[str]:
    """Display names relative to the inputs' common folder (unique, as long as the paths are)."""
    parents = [str(p.parent) for p in paths]
    common = Path(os.path.commonpath(parents)) if len(paths) > 1 else paths[0].parent
    return [p.relative_to(common).as_posix() for p in paths]


def _folder(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9._-]+", "_", name.replace("/", "__"))


def _worker_env(n_workers: int) -> dict:
    threads = str(max(1, usable_cores() // max(1, n_workers)))
    return {k: threads for k in ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")}


def _error_rows(task: FileTask, exc: BaseException, lost: str | None = None) -> list[dict]:
    """The error row of a task whose result did not come back; ``lost``: why the cluster cancelled it."""
    if type(exc).__name__ == "KilledWorker":  # distributed: every worker that ran it died (memory, most often)
        error = (f"KilledWorker: the worker process running {task.file} died{_retries(exc)} (out of memory is the "
                 "usual cause: run it alone, or with fewer --workers)")
    elif lost:
        error = f"not finished: {lost}; a re-run of the batch computes it (finished files are skipped)"
    else:
        error = f"{type(exc).__name__}: {' '.join(str(exc).split())} (the task or its worker failed)"
    return [{"file": task.file, "path": task.path, "command": task.command, "out_dir": task.rel_out,
             "settings_sha256": task.settings_sha256, "status": "error", "error": error, "wall_s": 0.0}]


def _retries(exc: BaseException) -> str:
    m = re.search(r"on (\d+) different workers", str(exc))
    return f", on {m.group(1)} workers in turn" if m and int(m.group(1)) > 1 else ""


def run_batch(inputs, out_dir, *, command: str = "allan", settings: dict | None = None, pattern: str | None = None,
              scheduler: str | None = None, workers: int | None = None, page: bool = True,
              progress: Callable | None = None, flags: dict | None = None) -> BatchResult:
    """Run ``command`` over every input; write per-file folders, ``summary.parquet`` and ``fleet.html``.

    Parameters
    ----------
    inputs : sequence of str or Path
        Files, folders (with ``pattern``), ROS 2 bag directories or wildcards.
    out_dir : str or Path
        Batch folder: ``<out_dir>/<file>/`` per input (as the single command writes it, plus
        ``batch.json``), ``summary.parquet`` and ``fleet.html``.  Checked before any work; its parent
        must exist.
    command : str
        A name of :data:`fogdrift.fleet.commands.COMMANDS` (``"allan"``, ``"analyze"``).
    settings : dict, optional
        ``{"load": {...keywords of fogdrift.io.load...}, "gaps": "error"|"longest", "analysis":
        {...fields of fogdrift.pipeline.AnalysisConfig...}}``, optionally ``"spec"`` (datasheet limits as a spec
        file's mapping, :func:`fogdrift.fleet.commands.spec_from_settings`: each row gets ``spec_<item>`` verdict
        columns); validated before any work.
    pattern : str, optional
        Glob for the files inside folders (``"*.csv.gz"``); also filters explicit files.
    scheduler : None, "serial", "local" or str
        See the module docstring: chosen by the work's size, in-process loop, local process cluster, or a
        scheduler address.
    workers : int, optional
        Workers of the local cluster (default: the usable cores, at most one per file); given, the default
        scheduler is the local cluster.
    page : bool
        Write ``fleet.html``.
    progress : callable, optional
        ``progress(done, total, file)`` after each file.
    flags : dict, optional
        How error messages spell a setting (``{"unit": "--unit"}``; default ``unit=``).

    Returns
    -------
    BatchResult

    Raises
    ------
    ConfigError
        Unknown command, invalid settings, no inputs, a bad output folder, or a scheduler that cannot
        be reached.
    fogdrift.interrupt.Interrupted
        An interruption was requested (see the module docstring for what is left on disk).
    """
    t0 = time.perf_counter()
    spec = command_spec(command)
    settings = json.loads(json.dumps(settings or {}, default=str))     # plain, picklable, hashable
    _validate(settings)
    paths = find_inputs(inputs, pattern)
    own = active(out_dir)
    if own is not None and own.path == Path(out_dir).expanduser().absolute():
        frame = contextlib.nullcontext(own)      # the caller's frame (the CLI) already holds the folder
    else:
        frame = BatchOutputDir(out_dir, command=f"batch {spec.name}", create_parents=False, protect=paths)
    with frame as od:
        return _run(od, paths, spec, settings, scheduler, workers, page, progress, flags, t0)


def _run(od, paths, spec, settings, scheduler, workers, page, progress, flags, t0) -> BatchResult:
    out = od.path
    digest = settings_sha256(spec.name, settings)
    names = _names(paths)
    seen: dict[str, str] = {}
    for n in names:  # distinct inputs, distinct folders: never one file's results over another's
        key = _folder(n).lower()
        if key in seen:
            raise ConfigError(f"{seen[key]!r} and {n!r} would share the output folder {_folder(n)!r} in "
                              f"{out}; rename one of them or run them in two batches")
        seen[key] = n
    tasks = [FileTask(path=str(p), file=n, out_dir=str(out / _folder(n)), rel_out=_folder(n), command=spec.name,
                      settings=settings, settings_sha256=digest, flags=flags) for p, n in zip(paths, names)]
    results: dict[int, list] = {}
    if isinstance(od, BatchOutputDir):
        od.start(tasks)
    od.expect(SUMMARY, *((PAGE,) if page else ()))

    def done(i, rows):
        results[i] = rows
        if isinstance(od, BatchOutputDir) and (Path(tasks[i].out_dir) / MANIFEST).exists():
            od.finished_file(tasks[i].rel_out)
        if progress is not None:
            progress(len(results), len(tasks), tasks[i].file)
        interrupt.check()

    interrupt.check()
    choice = choose(len(tasks), work_bytes(paths), usable_cores()) if scheduler is None and workers is None else None
    if scheduler == "serial" or (choice is not None and not choice.dask):
        used = "serial (in-process loop" + (f"; chosen: {choice.reason})" if choice else ")")
        interrupt.checkpoint(f"{len(tasks)} files, serial")
        for i, task in enumerate(tasks):
            done(i, run_file(task))
    else:
        used = _run_dask(tasks, None if scheduler == "local" else scheduler,
                         workers or (choice.workers if choice else None), done)
    interrupt.checkpoint("writing " + " and ".join((SUMMARY,) + ((PAGE,) if page else ())))
    rows = [{name: row.get(name) for name, _, _ in COLUMNS} for i in range(len(tasks)) for row in results[i]]
    summary = write_summary(rows, out / SUMMARY)
    page_path = None
    if page:
        from .page import write_fleet_page

        page_path = write_fleet_page(rows, out / PAGE, command=spec.name, settings=settings)
    status = [r.get("status") for i in range(len(tasks)) for r in results[i][:1]]
    return BatchResult(rows=rows, summary_path=summary, page_path=page_path, n_files=len(tasks),
                       n_ok=status.count("ok"), n_cached=status.count("cached"), n_error=status.count("error"),
                       wall_s=time.perf_counter() - t0, scheduler=used)


def _validate(settings: dict) -> None:
    unknown = set(settings) - {"load", "gaps", "analysis", "gmwm", "spec"}
    if unknown:
        raise ConfigError(f"unknown batch settings {sorted(unknown)}; expected load, gaps, analysis, gmwm, spec")
    spec_from_settings(settings)  # a bad spec: one line before any work
    gmwm = settings.get("gmwm", {})
    if set(gmwm) - {"model", "levels", "robust"}:
        raise ConfigError(f"unknown gmwm settings {sorted(set(gmwm) - {'model', 'levels', 'robust'})}; "
                          "expected some of ['levels', 'model', 'robust']")
    if gmwm:
        from ..gmwm.analysis import candidates_for

        candidates_for(gmwm.get("model", "auto"))
        levels = gmwm.get("levels")
        if levels is not None and (not isinstance(levels, int) or levels < 1):
            raise ConfigError(f"{{opt:scales}} must be an integer >= 1; got {levels!r}")
    if settings.get("gaps", "error") not in ("error", "longest"):
        raise ConfigError(f"gaps must be 'error' or 'longest'; got {settings.get('gaps')!r} in {{opt:gaps}}")
    from ..pipeline import AnalysisConfig

    load = dict(settings.get("load", {}))
    import inspect

    allowed = set(inspect.signature(load_fn).parameters) - {"path", "gaps"}
    if set(load) - allowed:
        raise ConfigError(f"unknown load settings {sorted(set(load) - allowed)}; expected some of {sorted(allowed)}")
    try:
        check_load_options(load.get("columns"), load.get("time_column", "auto"), load.get("dt_s"), load.get("rate_hz"),
                 load.get("unit"), load.get("time_unit"), load.get("delimiter"), "error", load.get("min_samples", 2),
                 load.get("format"), load.get("reader_options"), load.get("temperature"))
    except TypeError as exc:
        raise ConfigError(f"invalid load settings {load!r}: {exc}") from None
    try:
        AnalysisConfig(**settings.get("analysis", {})).validate()
    except TypeError as exc:
        raise ConfigError(f"unknown analysis setting: {exc}") from None


def _quiet_resource_tracker() -> None:
    """Start multiprocessing's resource tracker (if this process has none yet) with its leak warning off.

    The local cluster's process handles hold semaphores; when a Ctrl-C ends this process before the cluster
    has closed, the tracker removes them, as it should, and would print a ``UserWarning`` about "leaked
    semaphore objects" to the terminal after the one ``interrupted:`` line.  The tracker takes its warning
    filters from this process's ``sys.warnoptions`` when it starts.
    """
    import sys
    from multiprocessing import resource_tracker

    if getattr(resource_tracker._resource_tracker, "_fd", None) is not None:  # already running: leave it
        return
    saved = list(sys.warnoptions)
    sys.warnoptions.append("ignore:resource_tracker:UserWarning")
    try:
        resource_tracker.ensure_running()
    finally:
        sys.warnoptions[:] = saved


def _ignore_sigint() -> bool:
    """In a local worker process: ignore SIGINT (the batch process alone handles Ctrl-C; see the module docstring)."""
    import signal
    import threading

    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        return True
    return False


def _run_dask(tasks, scheduler, workers, done) -> str:
    distributed = require("distributed", "fleet", "running a batch on Dask")
    cluster = client = watch = None
    before = None                                # local cluster: this process's children before it started
    interrupted = lost = False
    dead = []                                    # tasks whose worker died: their folders' locks to remove
    muted = {}
    try:
        if scheduler:
            interrupt.checkpoint(f"connecting to the Dask scheduler {scheduler}")
            try:
                client = distributed.Client(scheduler, timeout=f"{CONNECT_TIMEOUT_S:g}s")
            except (OSError, TimeoutError, ValueError) as exc:
                raise ConfigError(f"cannot reach the Dask scheduler {scheduler!r}: {exc}; check {{opt:scheduler}}") \
                    from None
            used = f"Dask cluster at {scheduler}"
        else:
            n = int(workers or min(usable_cores(), len(tasks)) or 1)
            if n < 1:
                raise ConfigError(f"workers must be >= 1; got {workers!r} in {{opt:workers}}")
            interrupt.checkpoint(f"starting a local Dask cluster of {n} worker processes")
            # shielded: a Ctrl-C cut into the cluster's start would leave its loop starting workers after the batch
            # had gone; the flag raises at the checkpoint below, with the cluster there to be stopped
            with _sigint_blocked_for_children(), interrupt.shielded():
                _quiet_resource_tracker()
                before = set(_children())
                cluster = distributed.LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                                   host="127.0.0.1", dashboard_address=HTTP_ADDRESS,
                                                   silence_logs=logging.CRITICAL, env=_worker_env(n),
                                                   scheduler_kwargs={"allowed_failures": ALLOWED_FAILURES})
                client = distributed.Client(cluster)
                client.run(_ignore_sigint)               # each worker process's main thread
            used = f"local Dask cluster, {n} worker processes"
        interrupt.checkpoint(f"{len(tasks)} files on the {used}")  # stops after a Ctrl-C while the cluster started
        # no more tasks in the cluster than threads to run them: a worker then holds only the file it runs, and a
        # worker that dies fails that file alone (distributed counts every task sent to a dead worker as one it ran)
        futures: dict = {}
        queue = iter(enumerate(tasks))

        def submit() -> list:
            new = []
            while not lost and len(futures) - finished[0] < _slots(client):
                i, t = next(queue, (None, None))
                if t is None:
                    break
                new.append(client.submit(run_file, t, pure=False, key=f"fogdrift-{i}-{t.settings_sha256[:8]}"))
                futures[new[-1]] = i
            return new

        finished = [0]
        watch = _Watch(client, futures, f"Dask cluster at {scheduler}" if scheduler else "local Dask cluster")
        running = distributed.as_completed(submit())
        why = None
        for fut in running:
            i = futures[fut]
            finished[0] += 1
            try:
                rows = fut.result()
            except Exception as exc:  # noqa: BLE001 -- a killed worker, a lost task: an error row
                why = _lost(exc, scheduler, watch) or why
                lost = lost or why is not None
                if lost and not muted:   # the client's reconnection attempts would log ERRORs: the rows say it
                    muted = _mute_dask_logs()
                if type(exc).__name__ == "KilledWorker":
                    dead.append(tasks[i])
                rows = _error_rows(tasks[i], exc, why)
            done(i, rows)
            for new in submit():
                running.add(new)
        for i, t in queue:       # never sent: the cluster was lost first
            done(i, _error_rows(t, RuntimeError("not started"), why))
    except KeyboardInterrupt:
        interrupted = True
        raise
    finally:
        if watch is not None:
            watch.stop()
        if interrupted and not muted:
            # the in-process scheduler would log the gather the interruption cut short ("Couldn't gather keys"), a
            # client that lost its scheduler its reconnection cut short, as an ERROR with a traceback after the
            # batch's own lines; the batch is over, say nothing more
            muted = _mute_dask_logs()
        with interrupt.shielded() if interrupted else contextlib.nullcontext():
            _shut_down(client, cluster, before, tasks, interrupted, dead, quick=interrupted or lost)
        for name, level in muted.items():          # closed: a library caller's logging as it was
            logging.getLogger(name).setLevel(level)
    return used


def _slots(client) -> int:
    """Tasks the cluster can run at once: its workers' threads (at least 1), asked at each result (a cluster may
    grow or shrink while the batch runs)."""
    try:
        return max(1, sum(client.nthreads().values()))
    except Exception:  # noqa: BLE001 -- a scheduler being lost: the futures say so
        return 1


def _mute_dask_logs() -> dict:
    """Silence distributed's and tornado's loggers (each one: distributed's logging configuration gives some, like
    ``distributed.client``, levels of their own); returns their levels as they were."""
    manager = logging.Logger.manager
    names = [n for n in list(manager.loggerDict) if n.split(".")[0] in ("distributed", "tornado")]
    muted = {}
    for name in names + ["distributed", "tornado"]:
        log = logging.getLogger(name)
        muted.setdefault(name, log.level)
        log.setLevel(logging.CRITICAL + 1)
    return muted


def _lost(exc: BaseException, scheduler, watch) -> str | None:
    """Why a task's future was cancelled under it (the scheduler lost, no worker left), or None."""
    if watch.reason:
        return watch.reason
    if "scheduler-connection-lost" in str(exc) or type(exc).__name__ == "CommClosedError":
        return f"the Dask scheduler {scheduler or '(local)'} was lost (its connection closed) before it finished"
    return None


def _copy(futures: dict) -> list:
    """The keys of a dict another thread adds to (a copy taken while it grows is taken again)."""
    for _ in range(100):
        try:
            return list(futures)
        except RuntimeError:
            continue
    return []


class _Watch:
    """A thread that looks at the cluster's workers every :data:`WATCH_INTERVAL_S` while the files run; after
    :data:`NO_WORKERS_TIMEOUT_S` without any, once it has had one, it cancels the futures not done (each becomes an error row saying
    so), so that a cluster whose workers all died cannot keep the batch waiting for ever."""

    def __init__(self, client, futures, where: str):
        import threading

        self.client, self.futures, self.where = client, futures, where
        self.reason = None
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="fogdrift-batch-watch", daemon=True)
        self._thread.start()

    def _run(self) -> None:
        idle = None
        seen = False    # a cluster that has had no worker yet may be starting them (an adaptive one): waited for
        while not self._stop.wait(WATCH_INTERVAL_S):
            try:
                n = len(self.client.nthreads())
            except Exception:  # noqa: BLE001 -- a scheduler lost: its futures are cancelled by the client
                return
            if n or not seen:
                seen, idle = seen or bool(n), None
                continue
            idle = idle if idle is not None else time.monotonic()
            if time.monotonic() - idle >= NO_WORKERS_TIMEOUT_S:
                self.reason = (f"the {self.where} had no worker for {NO_WORKERS_TIMEOUT_S:g} s "
                               "(all died, none restarted)")
                with contextlib.suppress(Exception):
                    self.client.cancel([f for f in _copy(self.futures) if not f.done()], reason="no-workers")
                return

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(timeout=5)


def _shut_down(client, cluster, before, tasks, interrupted: bool, dead=(), quick: bool = False) -> None:
    """Close the client and the cluster; a local cluster leaves no process and no lock file behind.

    After an interruption its workers are killed first (their tasks cannot be stopped any other way), the
    cluster is closed without waiting, and the worker processes still there (a nanny may have started another)
    are killed too.  Every process the local cluster started (``before``: this process's children before it
    started; None for a ``tcp://`` scheduler, whose workers are not ours) has ended when this returns; then
    the lock and temporary files the killed ones, and the workers that died running ``dead`` (tasks), left in the
    files' folders are removed.  ``quick``: close without waiting (an interruption, a lost scheduler).  The watchdog of the
    CLI waits for this (:func:`fogdrift.interrupt.shielded`), so a loaded machine does not cut it short.
    """
    killed = []
    if interrupted and before is not None:
        if cluster is not None:
            _stop_restarts(cluster)
        killed += _end_processes(_children(exclude=before))
    _close(client, cluster, quick=quick)
    if before is not None:
        killed += _end_processes(_children(exclude=before))  # a graceful close leaves none; a quick one may
    if killed:
        _remove_temporaries(tasks, killed=killed)
    elif dead:
        _remove_temporaries(list(dead))


@contextlib.contextmanager
def _sigint_blocked_for_children():
    """Block SIGINT in this thread while the local cluster starts, so that the threads it creates, and the
    processes they spawn, start with SIGINT blocked: a Ctrl-C in the terminal (sent to the whole process
    group) then never reaches a worker that is still importing (it would print a traceback).  This process
    still gets the signal (another thread takes it; the interruption flag is checked right after)."""
    import signal
    import threading

    if not hasattr(signal, "pthread_sigmask") or threading.current_thread() is not threading.main_thread():
        yield
        return
    old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


#: Seconds to wait for a killed worker process to end (SIGKILL: at once, unless the machine is very busy).
WORKER_EXIT_WAIT_S = 60.0


def _children(exclude=()) -> list:
    """This process's descendants (psutil processes) that are not in ``exclude``, but multiprocessing's resource
    tracker (it ends by itself when this process does, after removing what the workers left registered)."""
    import psutil
    from multiprocessing import resource_tracker

    tracker = getattr(resource_tracker._resource_tracker, "_pid", None)
    try:
        kids = psutil.Process().children(recursive=True)
    except psutil.Error:
        return []
    return [p for p in kids if p not in exclude and p.pid != tracker]


def _stop_restarts(cluster) -> None:
    """Tell the local cluster's nannies not to start another worker when theirs dies: they close instead."""
    from distributed.core import Status

    for nanny in list(getattr(cluster, "workers", {}).values()):
        with contextlib.suppress(Exception):
            nanny.status = Status.closing_gracefully


def _end_processes(procs) -> list[int]:
    """SIGKILL the processes (psutil's, which checks that a pid is still the same process) and wait until each
    has ended (at most WORKER_EXIT_WAIT_S; a zombie has ended, its parent reaps it); return their ids."""
    import psutil

    killed = []
    for p in procs:
        with contextlib.suppress(psutil.Error):
            p.kill()
            killed.append(p.pid)
    deadline = time.monotonic() + WORKER_EXIT_WAIT_S
    while procs and time.monotonic() < deadline:
        procs = [p for p in procs if _running(p)]
        if procs:
            time.sleep(0.01)
    return killed


def _running(proc) -> bool:
    import psutil

    try:
        return proc.status() != psutil.STATUS_ZOMBIE
    except psutil.Error:
        return False


def _remove_temporaries(tasks, killed=()) -> None:
    """Remove the temporary files killed workers left in the files' folders (never a complete file), and their
    lock files: a worker killed between its folder's last file and the end of its run leaves the (dead) lock
    file of :class:`fogdrift.output.OutputDir`.  Also the folders above them up to the batch's folder: a worker
    checking a file's folder that does not exist yet probes the nearest existing one for writability
    (:func:`fogdrift.output.check_out_dir`), and a worker killed during that probe leaves its file there
    (``killed``: the workers' process ids; there, only their files and dead processes' are removed).  A killed
    worker that was re-running a finished folder is taken back (:func:`fogdrift.output.recover`)."""
    deadline = time.monotonic() + STALE_LOCK_WAIT_S
    above = {Path(t.out_dir).parents[k] for t in tasks for k in range(len(Path(t.rel_out).parts))}
    for folder in sorted(above):
        remove_stale_temporaries(folder, killed)
    for task in tasks:
        folder = Path(task.out_dir)
        for tmp in (folder.rglob(TMP_PREFIX + "*") if folder.is_dir() else ()):
            if tmp.is_file() and not tmp.name.startswith(f"{TMP_PREFIX}{os.getpid()}-"):
                with contextlib.suppress(OSError):
                    tmp.unlink()
        while (folder / LOCK).exists():
            lock = FolderLock(folder, f"fogdrift batch (process {os.getpid()}) removing a killed worker's lock")
            try:
                lock.acquire()  # free once the worker's process has exited
            except (ConfigError, OSError):
                if time.monotonic() > deadline:  # still held: not ours to remove
                    break
                time.sleep(0.02)
                continue
            lock.release()  # unlinks the file
            break
        with contextlib.suppress(OSError, ConfigError):
            recover(folder, killed)  # a killed worker's re-run of a finished folder: the earlier files come back


def _close(client, cluster, *, quick: bool) -> None:
    """Close the client and the local cluster; after an interruption, without waiting for running tasks."""
    kwargs = {"timeout": 2} if quick else {}
    if client is not None:
        with contextlib.suppress(Exception):
            if quick and client.futures:
                client.cancel(list(client.futures.values()), force=True)
            client.close(**kwargs)
    if cluster is not None:
        with contextlib.suppress(Exception):
            cluster.close(**kwargs)
