"""NumPy ``.npz`` reader: several 1-D arrays (named columns) or a single 2-D array.

The archive is read into memory once; the SHA-256 is taken from those bytes (no second read).
"""

from __future__ import annotations

import hashlib
import io
from pathlib import Path

import numpy as np

from ...errors import DataFormatError
from .base import PARSER_ERRORS, Table, describe_exception, numeric_column

__all__ = ["open_table"]


def open_table(path: Path) -> Table:
    """Read a ``.npz`` archive: one column per 1-D array (named by its key), or the columns of one 2-D array.

    Raises
    ------
    DataFormatError
        Unreadable archive, no arrays, arrays of different lengths or of other shapes,
        non-numeric dtypes.
    """
    p = Path(path)
    try:
        raw = p.read_bytes()
    except OSError as exc:
        raise DataFormatError(f"cannot read file; expected a readable file, got {exc.strerror or exc}",
                              path=p) from exc
    sha256 = hashlib.sha256(raw).hexdigest()
    try:
        with np.load(io.BytesIO(raw), allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
    except PARSER_ERRORS as exc:
        raise DataFormatError(
            f"unreadable .npz file; expected NumPy arrays, got {describe_exception(exc)}", path=p
        ) from exc
    del raw
    if not arrays:
        raise DataFormatError("no arrays in .npz file; expected at least one, got none", path=p)
    if len(arrays) == 1:
        (key, arr), = arrays.items()
        if arr.ndim == 2:
            arr = numeric_column(arr, p, f"array {key!r}", column=key)
            return Table(p, names=[f"col{j}" for j in range(arr.shape[1])], named=False, data=arr,
                         sha256=sha256, format="npz")
    n = None
    cols = []
    for key, arr in arrays.items():
        if arr.ndim != 1:
            raise DataFormatError(
                f"array {key!r} has shape {arr.shape}; expected 1-D arrays (one per column) "
                "or a single 2-D array", path=p, column=key,
            )
        if n is None:
            n, first = arr.shape[0], key
        elif arr.shape[0] != n:
            raise DataFormatError(
                f"array {key!r} has {arr.shape[0]} samples; expected {n} (as {first!r}), got {arr.shape[0]}",
                path=p, column=key,
            )
        cols.append(numeric_column(arr, p, f"array {key!r}", column=key))
    return Table(p, names=list(arrays), named=True, data=np.column_stack(cols), sha256=sha256, format="npz")
