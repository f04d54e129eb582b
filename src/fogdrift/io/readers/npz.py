"""NumPy ``.npz`` reader: several 1-D arrays (named columns) or a single 2-D array.

The archive is opened with :mod:`zipfile` and checked *before* anything is decompressed: every member must be
a ``.npy`` array (a zip of CSV files is not an ``.npz``: the message names its members), the members' declared
sizes must fit the expansion limit against the file's size and the memory budget
(:mod:`fogdrift.io.readers.limits`), and each array's header (shape x item size) must agree with its member's
declared size.  Only then are the arrays read, one at a time.  The SHA-256 is of the file's bytes (read in
chunks, not held in memory).
"""

from __future__ import annotations

import ast
import math
import zipfile
from pathlib import Path

import numpy as np

from ...errors import DataFormatError
from ..hashing import file_sha256
from .base import PARSER_ERRORS, Table, describe_exception, numeric_column
from .limits import check_expansion, check_memory, check_rows, check_columns

__all__ = ["open_table"]

#: Most bytes of a ``.npy`` header read from a member (NumPy's own limit for untrusted headers is 10000).
_MAX_HEADER = 10000


def _member_header(z: zipfile.ZipFile, info: zipfile.ZipInfo, p: Path):
    """(shape, dtype, header bytes) of a ``.npy`` member, from its first bytes only."""
    key = info.filename[:-4]
    try:
        with z.open(info) as fh:
            head = fh.read(min(info.file_size, _MAX_HEADER + 16))
    except PARSER_ERRORS as exc:
        raise DataFormatError(f"unreadable member {info.filename!r} of the .npz file; expected a NumPy array, got "
                              f"{describe_exception(exc)}", path=p, column=key) from exc
    bad = f"member {info.filename!r} is not a valid .npy array"
    if not head.startswith(b"\x93NUMPY") or len(head) < 10:
        raise DataFormatError(f"{bad}; expected the .npy magic bytes 93 4e 55 4d 50 59, got "
                              f"{head[:6].hex(' ') or 'an empty member'}", path=p, column=key)
    major = head[6]
    if major == 1:
        hlen, start = int.from_bytes(head[8:10], "little"), 10
    elif major in (2, 3):
        hlen, start = int.from_bytes(head[8:12], "little"), 12
    else:
        raise DataFormatError(f"{bad}; expected .npy format version 1, 2 or 3, got {major}", path=p, column=key)
    if hlen > _MAX_HEADER or start + hlen > len(head):
        raise DataFormatError(f"{bad}; expected a header of at most {_MAX_HEADER} bytes inside the member, got "
                              f"{hlen} bytes", path=p, column=key)
    try:
        text = head[start:start + hlen].decode("utf-8" if major == 3 else "latin1")
        d = ast.literal_eval(text)
        shape = tuple(int(s) for s in d["shape"])
        dtype = np.dtype(d["descr"]) if isinstance(d["descr"], str) else None
        if any(s < 0 for s in shape):
            raise ValueError(f"negative dimension in {shape}")
    except (*PARSER_ERRORS, SyntaxError, MemoryError, RecursionError) as exc:
        raise DataFormatError(f"{bad}; expected a header dict with shape and descr, got "
                              f"{describe_exception(exc)}", path=p, column=key) from None
    if dtype is None or dtype.hasobject or dtype.kind not in "biufc":
        raise DataFormatError(f"array {key!r} has dtype {d['descr']}; expected a real numeric dtype, got "
                              f"{d['descr']}", path=p, column=key)
    n_bytes = math.prod(shape) * dtype.itemsize
    if n_bytes > info.file_size - start - hlen:
        raise DataFormatError(
            f"array {key!r} declares shape {shape} ({n_bytes} bytes) but its member holds "
            f"{max(info.file_size - start - hlen, 0)} bytes of data; expected a consistent .npy member",
            path=p, column=key)
    return shape, dtype, n_bytes


def open_table(path: Path) -> Table:
    """Read a ``.npz`` archive: one column per 1-D array (named by its key), or the columns of one 2-D array.

    Raises
    ------
    DataFormatError
        Unreadable archive, a member that is not a ``.npy`` array, no arrays, arrays of different lengths or of
        other shapes, non-numeric dtypes.
    ResourceLimitError
        Members that declare more bytes than the expansion limit allows for the file's size, or more than the
        memory budget (checked before decompressing).
    """
    p = Path(path)
    try:
        size = p.stat().st_size
        zf = zipfile.ZipFile(p)
    except (*PARSER_ERRORS, IndexError) as exc:
        raise DataFormatError(
            f"unreadable .npz file; expected NumPy arrays in a zip archive, got {describe_exception(exc)}", path=p
        ) from exc
    with zf as z:
        infos = [i for i in z.infolist() if not i.is_dir()]
        check_columns(len(infos), p, "members (arrays)")
        others = [i.filename for i in infos if not i.filename.endswith(".npy")]
        if others:
            listing = ", ".join(repr(n) for n in others[:5]) + (f" and {len(others) - 5} more" if len(others) > 5
                                                                else "")
            if len(others) == len(infos):
                raise DataFormatError(
                    f"a zip archive of {listing}, not a NumPy .npz file; expected .npy members (a zipped CSV or "
                    "text log: extract it and load that file)", path=p)
            raise DataFormatError(f"member {listing} of the .npz file is not a .npy array; expected only .npy "
                                  "members (one array per column)", path=p, column=others[0])
        declared = sum(i.file_size for i in infos)
        check_expansion(declared, size, p, f"the .npz file's {len(infos)} member(s)")
        check_memory(declared, p, f"the .npz file's {len(infos)} member(s)")
        headers = {}
        for info in infos:
            key = info.filename[:-4]
            shape, dtype, n_bytes = _member_header(z, info, p)
            if shape:
                check_rows(shape[0], p, f"rows in array {key!r}")
            width = math.prod(shape[1:]) if len(shape) > 1 else 1
            check_memory(n_bytes + (shape[0] if shape else 1) * width * 8, p, f"array {key!r} as float64")
            headers[key] = (info, shape)
        if not headers:
            raise DataFormatError("no arrays in .npz file; expected at least one, got none", path=p)
        arrays = {}
        for key, (info, shape) in headers.items():
            try:
                with z.open(info) as fh:
                    arrays[key] = np.lib.format.read_array(fh, allow_pickle=False)
            except PARSER_ERRORS as exc:
                raise DataFormatError(f"unreadable array {key!r} in the .npz file; expected NumPy array data, got "
                                      f"{describe_exception(exc)}", path=p, column=key) from exc
    sha256 = file_sha256(p)
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
