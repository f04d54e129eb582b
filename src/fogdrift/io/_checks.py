"""Small validators and array helpers shared by the modules of :mod:`fogdrift.io`.

Private: the public entry points (:func:`~fogdrift.io.load`, :func:`~fogdrift.io.from_array`,
:class:`~fogdrift.io.GyroRecord`) call these to validate their arguments; nothing here reads files.
"""

from __future__ import annotations

import mmap
from pathlib import Path

import numpy as np

from .. import units
from ..errors import ConfigError, DataFormatError

#: Rows per chunk when scanning large (memory-mapped) arrays, keeps temporaries small.
CHUNK_ROWS = 1 << 16


def check_path(path, *, allow_dir: bool = False) -> Path:
    """``path`` as a Path to an existing regular file (or directory if ``allow_dir``), else an error."""
    if not isinstance(path, (str, Path)) and not hasattr(path, "__fspath__"):
        raise ConfigError(f"path must be a str or Path; got {type(path).__name__}")
    p = Path(path)
    if not p.exists():
        raise DataFormatError("file not found; expected an existing file, got no such path", path=p)
    if not p.is_file() and not (allow_dir and p.is_dir()):
        raise DataFormatError("not a regular file; expected a data file, got a directory or device", path=p)
    return p


def int_arg(value, name: str) -> int:
    """``value`` as an int (bools and floats refused), or ConfigError naming ``name``."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise ConfigError(f"{name} must be an integer; got {value!r}")
    return int(value)


def valid_units() -> list[str]:
    """Every angular-rate unit string :func:`fogdrift.units.parse_unit` (the one unit parser) accepts."""
    return units.valid_units("angular_rate")


def split_keys(keys, name: str) -> list:
    """Column/axis keys as a list: a comma-separated string, one int, or a sequence of them."""
    if isinstance(keys, str):
        out = [k.strip() for k in keys.split(",")]
    elif isinstance(keys, (int, np.integer)) and not isinstance(keys, bool):
        out = [keys]
    else:
        try:
            out = list(keys)
        except TypeError:
            raise ConfigError(f"{name} must be a name, an index or a sequence of them; got {keys!r}") from None
        out = [k.strip() if isinstance(k, str) else k for k in out]
    if not out or any(isinstance(k, str) and k == "" for k in out):
        raise ConfigError(f"{name} must list at least one non-empty name or index; got {keys!r}")
    return out


def take_columns(a: np.ndarray, idx) -> np.ndarray:
    """Columns ``idx`` of 2-D ``a``: a view when they are consecutive, else a copy."""
    idx = list(idx)
    if idx == list(range(idx[0], idx[0] + len(idx))):
        return a[:, idx[0]: idx[0] + len(idx)]
    return a[:, idx]


def drop_mapped_pages(block: np.ndarray) -> None:
    """Let the kernel drop the resident pages of a read-only memory map under ``block`` (a row range).

    For a view of a :class:`numpy.memmap` (the ``.npy`` and HDF5 readers), once a chunked scan is done with it:
    a file-backed page dropped is read again from the page cache if touched later, so values never change, but
    the scanned pages stop counting in the process's resident set (a 10^8-sample float32 file: 0.4 GB less at
    the peak of :func:`fogdrift.io.load`).  Anything else (a plain array, a platform without ``madvise``): no-op.
    """
    mm = getattr(block, "_mmap", None)
    advice = getattr(mmap, "MADV_DONTNEED", None)
    if mm is None or advice is None or not hasattr(mm, "madvise") or block.size == 0 or block.ndim < 1:
        return
    try:
        base = np.frombuffer(mm, dtype=np.uint8)
        lo = block.__array_interface__["data"][0] - base.__array_interface__["data"][0]
        hi = lo + (block.shape[0] - 1) * abs(block.strides[0]) + block.itemsize * (block[0].size or 1)
        del base
        page = mmap.PAGESIZE
        lo = max(0, lo // page * page)
        hi = min(len(mm), hi)
        if hi > lo:
            mm.madvise(advice, lo, hi - lo)
    except (ValueError, OSError, TypeError, BufferError):
        return


def to_dph(a: np.ndarray, scale: float) -> np.ndarray:
    """float64 rates in deg/h: no copy when ``a`` is float64 already and ``scale == 1``.

    Otherwise one float64 array ``a * scale`` (``a`` cast to float64 first, then multiplied: NumPy's buffered
    cast, no full-size intermediate).  A memory-mapped ``a`` is converted in row chunks, each chunk's mapped
    pages dropped once converted (:func:`drop_mapped_pages`), so the peak is the output plus one chunk.
    """
    if np.ndim(scale) == 0 and scale == 1.0 and a.dtype == np.float64:  # scale: one factor, or one per column
        return a
    with np.errstate(over="ignore"):  # an overflow becomes inf, which the callers locate
        if getattr(a, "_mmap", None) is None or a.ndim != 2:
            return np.multiply(a, scale, dtype=np.float64)
        out = np.empty(a.shape, dtype=np.float64)
        step = CHUNK_ROWS * 16
        for start in range(0, a.shape[0], step):
            block = a[start: start + step]
            np.multiply(block, scale, out=out[start: start + step], dtype=np.float64)
            drop_mapped_pages(block)
        return out


def first_nonfinite(a: np.ndarray, cols=None):
    """(row, col) of the first NaN/inf in ``a[:, cols]`` (row-major order), or None.

    Scans in chunks of rows so that memory-mapped arrays need no full-size temporary.
    """
    cols = list(range(a.shape[1])) if cols is None else list(cols)
    if not cols:
        return None
    contiguous = cols == list(range(cols[0], cols[0] + len(cols)))
    for start in range(0, a.shape[0], CHUNK_ROWS):
        block = a[start: start + CHUNK_ROWS]
        block = block[:, cols[0]: cols[0] + len(cols)] if contiguous else block[:, cols]
        ok = np.isfinite(block)
        if not ok.all():
            r, c = np.argwhere(~ok)[0]
            return start + int(r), cols[int(c)]
        drop_mapped_pages(a[start: start + CHUNK_ROWS])
    return None
