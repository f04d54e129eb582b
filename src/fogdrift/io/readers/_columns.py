"""Named arrays -> table columns: the layout rule shared by the HDF5 and MATLAB readers.

A group of arrays (an HDF5 group, a MATLAB struct, the variables of a ``.mat`` file) becomes a
table by one rule: every numeric 1-D array of the longest length is one column named after it,
every 2-D array ``(n, k)`` of that length gives ``k`` columns (named by its ``columns``
attribute, else ``name0 .. name{k-1}``); arrays of other lengths (calibration matrices,
scalars) are left out and listed in a note.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ...errors import DataFormatError
from .limits import check_expansion, check_memory, check_rows

__all__ = ["ArrayItem", "Layout", "layout_columns", "unit_list"]


@dataclass
class ArrayItem:
    """One named array: ``source`` locates it in messages (``"/imu/gyro"``, ``"imu.gx"``)."""

    name: str
    shape: tuple
    dtype: np.dtype
    source: str
    units: list | None = None          # one per column, or None
    names: list | None = None          # column names of a 2-D array, or None
    loader: object = None              # callable(column index or None) -> 1-D/2-D ndarray


@dataclass
class Layout:
    """Columns of a table: for each column, which item and which of its columns (None: a 1-D item)."""

    names: list
    units: list
    parts: list                        # (ArrayItem, column index or None)
    n_rows: int
    left_out: list = field(default_factory=list)


def unit_list(value, n: int, source: str, path) -> list | None:
    """A ``units`` attribute as one unit per column: a string for all, or a sequence of ``n`` strings."""
    if value is None:
        return None
    if isinstance(value, bytes):
        value = value.decode("utf-8", "replace")
    if isinstance(value, str):
        return [value.strip() or None] * n
    vals = [v.decode("utf-8", "replace") if isinstance(v, bytes) else str(v) for v in np.asarray(value).ravel()]
    if len(vals) == 1:
        return [vals[0].strip() or None] * n
    if len(vals) != n:
        raise DataFormatError(
            f"units attribute lists {len(vals)} units; expected 1 or one per column ({n}), got {vals}",
            path=path, column=source,
        )
    return [v.strip() or None for v in vals]


def layout_columns(items: list[ArrayItem], path, what: str) -> Layout:
    """Lay out numeric 1-D/2-D arrays of the longest common length as columns (see the module docstring).

    Raises
    ------
    DataFormatError
        No numeric 1-D/2-D array, or two columns with the same name.
    """
    usable = [it for it in items if it.dtype.kind in "biuf" and len(it.shape) in (1, 2) and it.shape[0] > 0]
    if not usable:
        listing = ", ".join(f"{it.source} {it.dtype} {it.shape}" for it in items) or "nothing"
        raise DataFormatError(
            f"no numeric 1-D or 2-D array in {what}; expected vectors or matrices of samples, got {listing}", path=path
        )
    n = max(it.shape[0] for it in usable)
    names, units, parts, left_out = [], [], [], []
    for it in items:
        if it not in usable or it.shape[0] != n:
            left_out.append(f"{it.source} {it.dtype} {it.shape}")
            continue
        if len(it.shape) == 1:
            names.append(it.name)
            units.append(it.units[0] if it.units else None)
            parts.append((it, None))
            continue
        k = it.shape[1]
        col_names = it.names if it.names and len(it.names) == k else [f"{it.name}{j}" for j in range(k)]
        for j in range(k):
            names.append(col_names[j])
            units.append(it.units[j] if it.units else None)
            parts.append((it, j))
    dup = next((a for j, a in enumerate(names) if a in names[:j]), None)
    if dup is not None:
        raise DataFormatError(f"two columns named {dup!r} in {what}; expected unique names", path=path, column=dup)
    return Layout(names=names, units=units, parts=parts, n_rows=n, left_out=left_out)


def check_layout(layout: Layout, used, path) -> None:
    """Refuse a layout whose used columns exceed the row limit, the memory budget or (as stored) the expansion
    limit against the file's size, before anything is read (:mod:`fogdrift.io.readers.limits`)."""
    used = sorted(set(used))
    check_rows(layout.n_rows, path)
    check_memory(layout.n_rows * 8.0 * max(len(used), 1), path,
                 f"{layout.n_rows} rows x {len(used)} used column(s) as float64")
    items = {id(it): it for it, _ in (layout.parts[j] for j in used)}.values()
    declared = sum(math.prod(int(s) for s in it.shape) * np.dtype(it.dtype).itemsize for it in items)
    try:
        size = Path(path).stat().st_size
    except OSError:
        return
    check_expansion(declared, size, path, f"the arrays of {len(used)} used column(s)")


def read_layout(layout: Layout, used) -> np.ndarray:
    """The used columns of a layout as a ``(n_rows, n_columns)`` float64 array (Fortran order).

    Columns not in ``used`` are not read and hold 0 (their pages are never touched, so an
    unused column costs no memory).
    """
    data = np.zeros((layout.n_rows, len(layout.names)), dtype=np.float64, order="F")
    cache = {}
    for j in sorted(set(used)):
        item, col = layout.parts[j]
        if col is None:
            data[:, j] = item.loader(None)
        else:
            if id(item) not in cache:
                cache[id(item)] = item.loader(None)
            data[:, j] = cache[id(item)][:, col]
    return data
