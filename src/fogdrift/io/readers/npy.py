"""NumPy ``.npy`` reader: 1-D (one axis) or 2-D (samples x columns), memory-mapped.

The array is opened with ``mmap_mode="r"`` and handed on as a view of the memory map, never copied here,
whatever its numeric dtype: :func:`fogdrift.io.load` converts the rate columns to float64 deg/h in one step
(``np.multiply(raw, scale, dtype=float64)``, one float64 array and no full-size intermediate), so a float32
file of n samples costs 8 n bytes beside its mapped pages, not 16 n.  The file's SHA-256 is
computed by reading it once in chunks (the memory map itself reads nothing up front).
"""

from __future__ import annotations

import errno
from pathlib import Path

import numpy as np

from ...errors import DataFormatError, ResourceError
from ..hashing import file_sha256
from .base import PARSER_ERRORS, Table, describe_exception, numeric_column
from .limits import check_memory

__all__ = ["open_table"]


def open_table(path: Path) -> Table:
    """Memory-map a ``.npy`` array; columns are named ``col0, col1, ...``.

    Raises
    ------
    DataFormatError
        Unreadable file, object/string/complex dtype, or more than 2 dimensions.
    ResourceLimitError
        A dtype other than float64 (converted in memory) whose float64 copy exceeds the memory budget.
    """
    p = Path(path)
    try:
        arr = np.load(p, mmap_mode="r", allow_pickle=False)
    except PARSER_ERRORS as exc:
        if isinstance(exc, MemoryError) or getattr(exc, "errno", None) == errno.ENOMEM:
            raise ResourceError(f"{p}: not enough memory to map the .npy file ({describe_exception(exc)}); run it "
                                "with more memory (a process limit: ulimit -v)") from exc
        raise DataFormatError(
            f"unreadable .npy file; expected a numeric NumPy array, got {describe_exception(exc)}", path=p
        ) from exc
    if arr.ndim not in (1, 2):
        raise DataFormatError(
            f"array has shape {arr.shape}; expected 1-D (one axis) or 2-D (samples x columns)", path=p
        )
    if arr.dtype != np.float64 and arr.dtype.kind in "biuf":  # converted in memory: held to the budget
        check_memory(arr.size * 8.0, p, f"the {arr.dtype} array {arr.shape} as float64")
    if arr.dtype.kind not in "biuf":
        numeric_column(arr, p, "array")  # raises: not a real numeric dtype
    if arr.ndim == 1:
        arr = arr.reshape(-1, 1)
    return Table(p, names=[f"col{j}" for j in range(arr.shape[1])], named=False, data=arr,
                 sha256=file_sha256(p), format="npy")
