"""Run one command over many logs on Dask: inputs, settings hash, scheduling, the summary and the fleet page.

Scheduling (``scheduler``):

* ``None`` (default): a local Dask cluster of worker *processes*, one per core (``workers`` to change it),
  one thread each; numeric libraries inside a worker get ``cores // workers`` threads so that workers do
  not oversubscribe the machine.  The cluster listens on 127.0.0.1 only and has no dashboard.
* ``"tcp://HOST:8786"``: an existing cluster (``dask scheduler`` + ``dask worker`` on other machines); the
  workers need fogdrift installed and must see the input and output paths (a shared file system).
* ``"serial"``: no Dask, a loop in this process (debugging; the benchmark's reference).

Each file is one task (:func:`fogdrift.fleet.tasks.run_file`); a task that fails, or a worker that dies,
becomes an error row, never a crashed batch.  Results are collected as they finish (``progress``).
"""

from __future__ import annotations

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

from ..errors import ConfigError
from ..io.readers.base import require
from .commands import command_spec
from .summary import COLUMNS, write_summary
from .tasks import FileTask, run_file

__all__ = ["BatchResult", "run_batch", "find_inputs", "settings_sha256", "SUMMARY", "PAGE"]

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
    threads = str(max(1, (os.cpu_count() or 1) // max(1, n_workers)))
    return {k: threads for k in ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")}


def _error_rows(task: FileTask, exc: BaseException) -> list[dict]:
    return [{"file": task.file, "path": task.path, "command": task.command, "out_dir": task.rel_out,
             "settings_sha256": task.settings_sha256, "status": "error",
             "error": f"{type(exc).__name__}: {exc} (the task or its worker failed)", "wall_s": 0.0}]


def run_batch(inputs, out_dir, *, command: str = "allan", settings: dict | None = None, pattern: str | None = None,
              scheduler: str | None = None, workers: int | None = None, page: bool = True,
              progress: Callable | None = None) -> BatchResult:
    """Run ``command`` over every input; write per-file folders, ``summary.parquet`` and ``fleet.html``.

    Parameters
    ----------
    inputs : sequence of str or Path
        Files, folders (with ``pattern``), ROS 2 bag directories or wildcards.
    out_dir : str or Path
        Batch folder: ``<out_dir>/<file>/`` per input (as the single command writes it, plus
        ``batch.json``), ``summary.parquet`` and ``fleet.html``.
    command : str
        A name of :data:`fogdrift.fleet.commands.COMMANDS` (``"allan"``, ``"analyze"``).
    settings : dict, optional
        ``{"load": {...keywords of fogdrift.io.load...}, "gaps": "error"|"longest", "analysis":
        {...fields of fogdrift.pipeline.AnalysisConfig...}}``; validated before any work.
    pattern : str, optional
        Glob for the files inside folders (``"*.csv.gz"``); also filters explicit files.
    scheduler : None, "serial" or str
        See the module docstring: local process cluster, in-process loop, or a scheduler address.
    workers : int, optional
        Workers of the local cluster (default: the machine's cores).
    page : bool
        Write ``fleet.html``.
    progress : callable, optional
        ``progress(done, total, file)`` after each file.

    Returns
    -------
    BatchResult

    Raises
    ------
    ConfigError
        Unknown command, invalid settings, no inputs, or a scheduler that cannot be reached.
    """
    t0 = time.perf_counter()
    spec = command_spec(command)
    settings = json.loads(json.dumps(settings or {}, default=str))     # plain, picklable, hashable
    _validate(settings)
    paths = find_inputs(inputs, pattern)
    out = Path(out_dir).resolve()
    out.mkdir(parents=True, exist_ok=True)
    digest = settings_sha256(spec.name, settings)
    names = _names(paths)
    tasks = [FileTask(path=str(p), file=n, out_dir=str(out / _folder(n)), rel_out=_folder(n), command=spec.name,
                      settings=settings, settings_sha256=digest) for p, n in zip(paths, names)]
    results: dict[int, list] = {}

    def done(i, rows):
        results[i] = rows
        if progress is not None:
            progress(len(results), len(tasks), tasks[i].file)

    if scheduler == "serial":
        used = "serial (in-process loop)"
        for i, task in enumerate(tasks):
            done(i, run_file(task))
    else:
        used = _run_dask(tasks, scheduler, workers, done)
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
    unknown = set(settings) - {"load", "gaps", "analysis"}
    if unknown:
        raise ConfigError(f"unknown batch settings {sorted(unknown)}; expected load, gaps, analysis")
    if settings.get("gaps", "error") not in ("error", "longest"):
        raise ConfigError(f"gaps must be 'error' or 'longest'; got {settings.get('gaps')!r} in {{opt:gaps}}")
    from ..io.load import _options
    from ..pipeline import AnalysisConfig

    load = dict(settings.get("load", {}))
    import inspect

    from ..io import load as load_fn

    allowed = set(inspect.signature(load_fn).parameters) - {"path", "gaps"}
    if set(load) - allowed:
        raise ConfigError(f"unknown load settings {sorted(set(load) - allowed)}; expected some of {sorted(allowed)}")
    try:
        _options(load.get("columns"), load.get("time_column", "auto"), load.get("dt_s"), load.get("rate_hz"),
                 load.get("unit"), load.get("time_unit"), load.get("delimiter"), "error", load.get("min_samples", 2),
                 load.get("format"), load.get("reader_options"), load.get("temperature"))
    except TypeError as exc:
        raise ConfigError(f"invalid load settings {load!r}: {exc}") from None
    try:
        AnalysisConfig(**settings.get("analysis", {})).validate()
    except TypeError as exc:
        raise ConfigError(f"unknown analysis setting: {exc}") from None


def _run_dask(tasks, scheduler, workers, done) -> str:
    distributed = require("distributed", "fleet", "running a batch on Dask")
    cluster = None
    if scheduler:
        try:
            client = distributed.Client(scheduler, timeout="20s")
        except (OSError, TimeoutError, ValueError) as exc:
            raise ConfigError(f"cannot reach the Dask scheduler {scheduler!r}: {exc}; check {{opt:scheduler}}") \
                from None
        used = f"Dask cluster at {scheduler}"
    else:
        n = int(workers or os.cpu_count() or 1)
        if n < 1:
            raise ConfigError(f"workers must be >= 1; got {workers!r} in {{opt:workers}}")
        cluster = distributed.LocalCluster(n_workers=n, threads_per_worker=1, processes=True, host="127.0.0.1",
                                           dashboard_address=None, silence_logs=logging.ERROR, env=_worker_env(n))
        client = distributed.Client(cluster)
        used = f"local Dask cluster, {n} worker processes"
    try:
        futures = {client.submit(run_file, t, pure=False, key=f"fogdrift-{i}-{t.settings_sha256[:8]}"): i
                   for i, t in enumerate(tasks)}
        for fut in distributed.as_completed(futures):
            i = futures[fut]
            try:
                rows = fut.result()
            except Exception as exc:  # noqa: BLE001 -- a killed worker, a lost task: an error row
                rows = _error_rows(tasks[i], exc)
            done(i, rows)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    return used
