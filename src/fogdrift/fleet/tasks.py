"""One file of a batch: hash it, skip it if unchanged, load it, run the command, write its manifest.

:func:`run_file` is what each Dask task (or the serial loop) calls; it never raises for a bad file: a
:class:`~fogdrift.errors.FogdriftError` or any other exception becomes one row with ``status = "error"``.
Each file's folder holds the command's outputs and ``batch.json`` (SHA-256 of the file, SHA-256 of the
settings, the rows), which lets a re-run skip the file when both are unchanged.  Unexpected exceptions
(a bug, memory) are not cached and write ``error.txt`` with the traceback.
"""

from __future__ import annotations

import json
import time
import traceback
import warnings
from dataclasses import dataclass
from pathlib import Path

from ..errors import FogdriftError

__all__ = ["FileTask", "run_file", "load_record", "MANIFEST"]

#: Name of the per-file manifest.
MANIFEST = "batch.json"


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


def load_record(path, settings: dict):
    """Load a record with the batch's load settings; ``gaps="longest"`` keeps the longest gap-free segment."""
    from ..io import load, load_segments

    kwargs = dict(settings.get("load", {}))
    gaps = settings.get("gaps", "error")
    if gaps == "longest":
        return max(load_segments(path, **kwargs), key=lambda r: r.n_samples)
    return load(path, **kwargs)


def _base(task: FileTask, sha256) -> dict:
    return {"file": task.file, "path": task.path, "sha256": sha256, "command": task.command,
            "out_dir": task.rel_out, "settings_sha256": task.settings_sha256}


def _cached(task: FileTask, sha256: str):
    man = Path(task.out_dir) / MANIFEST
    try:
        doc = json.loads(man.read_text())
    except (OSError, ValueError):
        return None
    if doc.get("sha256") != sha256 or doc.get("settings_sha256") != task.settings_sha256:
        return None
    rows = doc.get("rows") or []
    for row in rows:
        if row.get("status") == "ok":
            row["status"] = "cached"
        row["wall_s"] = 0.0
        row.update(file=task.file, path=task.path, out_dir=task.rel_out)
    return rows


def run_file(task: FileTask) -> list[dict]:
    """Process one input; returns its summary rows (one per axis, or one error row). Never raises."""
    from ..io.hashing import path_sha256
    from .commands import command_spec

    t0 = time.perf_counter()
    out = Path(task.out_dir)
    sha256 = None
    caught = []
    try:
        sha256 = path_sha256(task.path)
        cached = _cached(task, sha256)
        if cached is not None:
            return cached
        out.mkdir(parents=True, exist_ok=True)
        (out / "error.txt").unlink(missing_ok=True)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            record = load_record(task.path, task.settings)
            rows = command_spec(task.command).run(record, task.settings, out)
        status, error, cache = "ok", None, True
    except FogdriftError as exc:             # bad input or settings: deterministic, cached like a result
        rows, status, error, cache = [{}], "error", f"{type(exc).__name__}: {exc}", True
    except Exception as exc:  # noqa: BLE001 -- one file must never crash the batch
        rows, status, error, cache = [{}], "error", f"{type(exc).__name__}: {exc}", False
        try:
            out.mkdir(parents=True, exist_ok=True)
            (out / "error.txt").write_text(traceback.format_exc())
        except OSError:
            pass
    seen = list(dict.fromkeys(f"{w.category.__name__}: {w.message}" for w in caught))
    wall = time.perf_counter() - t0
    rows = [{**_base(task, sha256), **row, "status": status, "error": error,
             "warnings": "; ".join(seen) or None, "wall_s": wall} for row in rows]
    if cache and sha256 is not None:
        try:
            out.mkdir(parents=True, exist_ok=True)
            (out / MANIFEST).write_text(json.dumps({"sha256": sha256, "settings_sha256": task.settings_sha256,
                                                    "command": task.command, "settings": task.settings,
                                                    "rows": rows}, indent=1, default=str))
        except OSError:
            pass
    return rows
