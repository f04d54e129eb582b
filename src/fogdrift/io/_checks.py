"""Small validators and array helpers shared by the modules of :mod:`fogdrift.io`.

Private: the public entry points (:func:`~fogdrift.io.load`, :func:`~fogdrift.io.from_array`,
:class:`~fogdrift.io.GyroRecord`) call these to validate their arguments; nothing here reads files.
"""

from __future__ import annotations

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


def to_dph(a: np.ndarray, scale: float) -> np.ndarray:
    """float64 rates in deg/h: no copy when ``a`` is float64 already and ``scale == 1``."""
    if np.ndim(scale) == 0 and scale == 1.0 and a.dtype == np.float64:  # scale: one factor, or one per column
        return a
    with np.errstate(over="ignore"):  # an overflow becomes inf, which the callers locate
        return np.multiply(a, scale, dtype=np.float64)


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
    return None
