"""Which scheduler runs a batch by default: a local Dask cluster only where the work pays for its start-up.

A local cluster costs a start-up before the first file (worker processes that import the analysis stack and
load the compiled kernels, each on its own) and gains less than its worker count: the serial loop is not
single-core (numba's threads parallelise the Allan kernel inside each file).  On a 2-core VM the five ADIS16405
sessions (5 x 10^6 samples x 3 axes of gzip CSV, 115 MB of text) ran 1.6-2.3x slower on the local cluster than
in the serial loop, and 20 CSV logs of 10^6 x 3 samples (880 MB) 1.45x faster (bench/RESULTS.md).

The rule (:func:`choose`), for ``scheduler=None``:

* fewer than 2 usable cores (:func:`usable_cores`: the CPU affinity, not the machine's count) -> serial;
* fewer than 2 files -> serial (nothing to run side by side);
* less input than :data:`DASK_MIN_BYTES` (:func:`work_bytes`: the files' sizes, a gzip file's uncompressed
  size) -> serial;
* else a local cluster of ``min(usable cores, files)`` worker processes.

``scheduler="local"`` or an explicit ``workers`` asks for the local cluster whatever the size.
"""

from __future__ import annotations

import os
import struct
from pathlib import Path

__all__ = ["DASK_MIN_BYTES", "Choice", "choose", "usable_cores", "work_bytes"]

#: Input (bytes, uncompressed) below which the default scheduler is the serial loop: about 11 of the ADIS16405
#: sessions, some 50 s of serial work on the 2-core VM, where two workers start to save more than they cost.
DASK_MIN_BYTES = 256 * 2**20


def usable_cores() -> int:
    """Cores this process may run on (its CPU affinity where the system has one, else the machine's count)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return max(1, os.cpu_count() or 1)


def _file_bytes(path: Path) -> int:
    """Bytes of one input as a reader sees them: a gzip file's uncompressed size (its trailer's ISIZE, modulo
    2**32, never taken below the compressed size), a folder's (ROS 2 bag) files summed."""
    try:
        if path.is_dir():
            return sum(q.stat().st_size for q in path.rglob("*") if q.is_file())
        size = path.stat().st_size
        if path.name.lower().endswith(".gz") and size >= 18:
            with open(path, "rb") as f:
                f.seek(-4, os.SEEK_END)
                return max(size, struct.unpack("<I", f.read(4))[0])
        return size
    except OSError:
        return 0


def work_bytes(paths) -> int:
    """The batch's input in bytes (:func:`_file_bytes` summed): the work-size estimate of :func:`choose`."""
    return sum(_file_bytes(Path(p)) for p in paths)


class Choice:
    """The default scheduler for a batch: ``dask`` (a local cluster of ``workers``) or not, and why (``reason``)."""

    def __init__(self, dask: bool, workers: int, reason: str):
        self.dask, self.workers, self.reason = dask, workers, reason

    def __repr__(self) -> str:
        return f"Choice(dask={self.dask}, workers={self.workers}, reason={self.reason!r})"


def choose(n_files: int, n_bytes: int, cores: int) -> Choice:
    """The scheduler of a batch of ``n_files`` holding ``n_bytes`` of input on ``cores`` usable cores.

    Examples
    --------
    >>> choose(5, 115 * 2**20, 2).dask
    False
    >>> choose(20, 880 * 2**20, 2).workers
    2
    """
    size = f"{n_bytes / 1e6:.0f} MB of input"
    if cores < 2:
        return Choice(False, 1, f"{cores} usable core")
    if n_files < 2:
        return Choice(False, 1, f"{n_files} file")
    if n_bytes < DASK_MIN_BYTES:
        return Choice(False, 1, f"{size}, less than the {DASK_MIN_BYTES / 1e6:.0f} MB a local Dask cluster's "
                                "start-up pays for")
    return Choice(True, min(cores, n_files), f"{n_files} files, {size}, {cores} usable cores")
