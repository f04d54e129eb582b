"""One file of a batch: hash it, skip it if unchanged, load it, run the command, write its manifest.

:func:`run_file` is what each Dask task (or the serial loop) calls; it never raises for a bad file: a
:class:`~fogdrift.errors.FogdriftError` or any other exception becomes one row with ``status = "error"``.

Each file's folder is its own :class:`fogdrift.output.OutputDir`: every file in it is written under a
temporary name and renamed when complete, the previous run's files there are replaced at the first write,
and ``batch.json`` (SHA-256 of the input, SHA-256 of the settings, the rows) is written **last**.  So a
folder with ``batch.json`` is complete; a file interrupted or killed half-way has none, and the next run
recomputes it.  A re-run skips a file when ``batch.json`` names the same SHA-256 and settings.  Unexpected
exceptions (a bug, memory) are not cached and write ``error.txt`` with the traceback.
"""

from __future__ import annotations

import json
import os
import signal
import time
import traceback
import warnings
from dataclasses import dataclass
from pathlib import Path

from .._util import strict_json
from ..errors import FogdriftError, ResourceError, render_options
from ..io import load, load_segments
from ..io.hashing import path_sha256
from ..output import OutputDir, atomic_path
from ..plausibility import check_record
from .commands import TERMS, command_spec
from .summary import ACCEL_TERMS

__all__ = ["FileTask", "run_file", "load_record", "split_by_quantity", "MANIFEST"]

#: Name of the per-file manifest, written last.
MANIFEST = "batch.json"
#: Test hook, inert unless set: ``FILE:PID`` makes the task of the batch file ``FILE`` (its display name) send
#: SIGKILL to process ``PID`` (``self``: the worker process running it) once it holds its folder's lock, so that
#: tests kill a worker or a scheduler mid-batch at an event, not a time (tests/fleet/test_fleet_dying.py).
TEST_KILL_ENV = "FOGDRIFT_TEST_KILL"


@dataclass(frozen=True)
class FileTask:
    """One input of a batch: where it is, where its outputs go and how to process it."""

    path: str            # absolute input path
    file: str            # display name (relative to the common folder)
    out_dir: str         # absolute output folder of this file
    rel_out: str         # out_dir relative to the batch folder
    command: str
    settings: dict       # {"load": {...}, "gaps": "error"|"longest", "analysis": {...}}
    settings_sha256: str
    flags: dict | None = None   # {opt:NAME} -> how messages spell a setting (the CLI's flags), else NAME=


def load_record(path, settings: dict):
    """Load a record with the batch's load settings; ``gaps="longest"`` keeps the longest gap-free segment."""
    kwargs = dict(settings.get("load", {}))
    gaps = settings.get("gaps", "error")
    if gaps == "longest":
        return max(load_segments(path, **kwargs), key=lambda r: r.n_samples)
    return load(path, **kwargs)


def _base(task: FileTask, sha256) -> dict:
    return {"file": task.file, "path": task.path, "sha256": sha256, "command": task.command,
            "out_dir": task.rel_out, "settings_sha256": task.settings_sha256}


def cached_rows(task: FileTask, sha256: str):
    """The rows of the file's ``batch.json`` when it names ``sha256`` and the task's settings, else None."""
    man = Path(task.out_dir) / MANIFEST
    try:
        doc = json.loads(man.read_text())
    except (OSError, ValueError, RecursionError):
        return None
    if not isinstance(doc, dict) or doc.get("sha256") != sha256 or doc.get("settings_sha256") != task.settings_sha256:
        return None
    rows = doc.get("rows") or []
    for row in rows:
        if row.get("status") == "ok":
            row["status"] = "cached"
        row["wall_s"] = 0.0
        row.update(file=task.file, path=task.path, out_dir=task.rel_out)
    return rows


def split_by_quantity(record, rows: list[dict], b_in_mps2: bool = False) -> list[dict]:
    """Each row in the columns of its axis's quantity: an accelerometer axis's coefficients (already in the
    accelerometer's units, :func:`fogdrift.noise.quantity.express`) move from the gyro-named columns (``N_dprh``
    ...) to the accelerometer's (``N_mps_rh`` ...), ``b_min_dph`` to ``b_min_ug``; every row gets ``quantity``.
    A gyro row is unchanged but for ``quantity``.  So no accelerometer figure sits in a deg/h column.
    ``b_in_mps2``: the rows' B figures are in m/s^2 (a GMWM reading, :mod:`fogdrift.gmwm.quantity`), converted
    to ug here (1 ug = 9.80665e-6 m/s^2)."""
    out = []
    for row in rows:
        name = row.get("axis")
        try:
            quantity = record.signal.channel(name).quantity if name is not None else None
        except FogdriftError:
            quantity = None
        row = dict(row, quantity=quantity)
        if quantity == "specific_force":
            for (term, g), (_, a) in zip(TERMS, ACCEL_TERMS):
                for kind in ("", "lo95_", "hi95_"):
                    key = f"{term}_{kind}{g}"
                    if key in row:
                        row[f"{term}_{kind}{a}"] = row.pop(key)
            if "b_min_dph" in row:
                row["b_min_ug"] = row.pop("b_min_dph")
            if b_in_mps2:
                for key in ("B_ug", "B_lo95_ug", "B_hi95_ug", "b_min_ug"):
                    if row.get(key) is not None:
                        row[key] = row[key] / 9.80665e-6
        out.append(row)
    return out


def _plausibility(record, flags) -> list[str]:
    """The plausibility findings the single commands print as warnings (a likely wrong unit or time unit)."""
    return [f"implausible: {f.render(flags)}" for f in check_record(record)]


def _warning_text(w, flags) -> str:
    return f"{w.category.__name__}: {render_options(str(w.message), flags)}"


def _test_kill(task: FileTask) -> None:
    """The :data:`TEST_KILL_ENV` hook (nothing unless the variable is set and names this task's file)."""
    hook = os.environ.get(TEST_KILL_ENV)
    if hook:
        name, _, pid = hook.rpartition(":")
        if name == task.file:
            os.kill(os.getpid() if pid == "self" else int(pid), signal.SIGKILL)


def run_file(task: FileTask) -> list[dict]:
    """Process one input; returns its summary rows (one per axis, or one error row).

    Never raises for a bad file or a failing command; only an interruption (:mod:`fogdrift.interrupt`,
    a ``KeyboardInterrupt``) passes through, leaving the file's folder without ``batch.json``.
    """
    t0 = time.perf_counter()
    out = Path(task.out_dir)
    sha256 = None
    try:
        sha256 = path_sha256(task.path)
    except Exception as exc:  # noqa: BLE001 -- an unreadable input is a row
        rows = [{**_base(task, None), "status": "error", "error": f"{type(exc).__name__}: {exc}",
                 "wall_s": time.perf_counter() - t0}]
        return rows
    cached = cached_rows(task, sha256)
    if cached is not None:
        return cached
    caught = []
    notes = []
    with OutputDir(out, command=f"batch {task.command}", create_parents=True, protect=[task.path]) as od:
        _test_kill(task)
        try:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                record = load_record(task.path, task.settings)
                notes = _plausibility(record, task.flags)
                rows = split_by_quantity(record, command_spec(task.command).run(record, task.settings, od.path),
                                         b_in_mps2=task.command == "noise")
            status, error, cache = "ok", None, True
        except ResourceError as exc:         # out of memory / disk space: the machine's state, never cached
            rows, status, error, cache = [{}], "error", f"{type(exc).__name__}: {exc.render(task.flags)}", False
        except FogdriftError as exc:         # bad input or settings: deterministic, cached like a result
            rows, status, error, cache = [{}], "error", f"{type(exc).__name__}: {exc.render(task.flags)}", True
        except Exception as exc:  # noqa: BLE001 -- one file must never crash the batch
            rows, status, error, cache = [{}], "error", f"{type(exc).__name__}: {exc}", False
            with atomic_path(od.path / "error.txt") as tmp:
                tmp.write_text(traceback.format_exc())
        seen = list(dict.fromkeys(notes + [_warning_text(w, task.flags) for w in caught]))
        wall = time.perf_counter() - t0
        rows = [{**_base(task, sha256), **row, "status": status, "error": error,
                 "warnings": "; ".join(seen) or None, "wall_s": wall} for row in rows]
        if cache:
            doc = {"sha256": sha256, "settings_sha256": task.settings_sha256, "command": task.command,
                   "settings": task.settings, "rows": rows}
            with atomic_path(od.path / MANIFEST) as tmp:
                # strict JSON (NaN/inf as null: a row's unfitted interval); default=str keeps any odd cell a string
                tmp.write_text(strict_json(json.loads(json.dumps(doc, default=str)), indent=1))
    return rows
