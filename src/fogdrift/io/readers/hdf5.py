"""HDF5 reader (h5py, extra ``[hdf5]``): a dataset or a group of datasets as named columns.

What becomes the table (``dataset`` option, an HDF5 path such as ``"/imu"`` or ``"/imu/gyro"``):

* a 2-D dataset ``(n, k)``: ``k`` columns, named by its ``columns`` (or ``column_names``)
  attribute, else ``col0 .. col{k-1}``; a 1-D dataset: one column named after it;
* a compound dataset (a table of records): one column per numeric field;
* a group: its datasets of the longest length as columns (:mod:`._columns`), e.g.
  ``/imu/t``, ``/imu/gyro (n, 3)``, ``/imu/temp``.

Without ``dataset``: the only numeric dataset of the file, else the only group that holds all
of them; otherwise an error lists the candidates.  Units: a ``units`` (or ``unit``) attribute,
one string for all columns of the dataset or one per column, is the declared unit of those
columns (``deg/s``, ``rad/s``, ``s``, ``degC`` ...; used when no unit is given).

A contiguous, uncompressed float64 dataset is memory-mapped (no copy, like ``.npy``); others are
read column by column, only the columns used.  The SHA-256 is of the file's bytes (one chunked
read).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...errors import DataFormatError
from ..hashing import file_sha256
from ._columns import ArrayItem, check_layout, layout_columns, read_layout, unit_list
from .base import PARSER_ERRORS, Table, describe_exception, require

__all__ = ["open_table", "HDF5Table", "UNIT_ATTRS", "NAME_ATTRS"]

#: Attributes read as the unit(s) of a dataset, in this order.
UNIT_ATTRS = ("units", "unit")
#: Attributes read as the column names of a 2-D dataset, in this order.
NAME_ATTRS = ("columns", "column_names")


def _h5py():
    return require("h5py", "hdf5", "reading HDF5 files")


def _attr(obj, keys):
    for k in keys:
        if k in obj.attrs:
            return obj.attrs[k]
    return None


def _names(value, k):
    if value is None:
        return None
    vals = [v.decode("utf-8", "replace") if isinstance(v, bytes) else str(v) for v in np.asarray(value).ravel()]
    return [v.strip() for v in vals] if len(vals) == k else None


class HDF5Table(Table):
    """Columns of one HDF5 dataset or group; numbers read in :meth:`read` (only the used columns)."""

    format = "hdf5"

    def __init__(self, path, *, layout, named, sha256, what):
        super().__init__(path, names=layout.names, named=named, units=layout.units, sha256=sha256)
        self.layout = layout
        self.what = what

    def read(self, used) -> np.ndarray:
        if self.data is None:
            check_layout(self.layout, used, self.path)
            try:
                self.data = read_layout(self.layout, used)
            except PARSER_ERRORS as exc:
                raise DataFormatError(
                    f"cannot read {self.what}; expected readable HDF5 data, got {describe_exception(exc)}",
                    path=self.path,
                ) from exc
        return self.data

    def describe(self, n_rows: int) -> str:
        left = f"; left out {', '.join(self.layout.left_out)}" if self.layout.left_out else ""
        return f"HDF5 {self.what}, {n_rows} samples x {len(self.names)} columns{left}"


def _check_storage(path: Path, ds) -> None:
    """Refuse a virtual dataset one of whose source files is missing: h5py reads the missing part as the fill value
    (zeros), a silent wrong record.  Data behind an external link or in another file is read through h5py (never
    memory-mapped from ``path``); the SHA-256 stays that of ``path``."""
    if not getattr(ds, "is_virtual", False):
        return
    base = Path(ds.file.filename).parent
    for vs in ds.virtual_sources():
        if vs.file_name in (".", ""):
            continue
        src = Path(vs.file_name)
        src = src if src.is_absolute() else base / src
        if not src.is_file():
            raise DataFormatError(f"virtual dataset {ds.name}: its source file {vs.file_name!r} (dataset "
                                  f"{vs.dset_name}) is missing; h5py would read that part as zeros; expected every "
                                  "source file beside the file", path=path, column=ds.name)


def _item(path: Path, ds, name: str) -> list[ArrayItem]:
    """ArrayItems of one dataset (a compound dataset gives one 1-D item per numeric field)."""
    _check_storage(path, ds)
    src = ds.name
    units_attr = _attr(ds, UNIT_ATTRS)
    if ds.dtype.names:
        fields = [f for f in ds.dtype.names if ds.dtype.fields[f][0].kind in "biuf"]
        units = unit_list(units_attr, len(ds.dtype.names), src, path) if units_attr is not None else None
        out = []
        for f in fields:
            u = None if units is None else [units[ds.dtype.names.index(f)]]
            out.append(ArrayItem(f, ds.shape, ds.dtype.fields[f][0], f"{src}.{f}", units=u,
                                 loader=lambda _c, ds=ds, f=f: np.asarray(ds.fields(f)[()], dtype=np.float64)))
        return out
    shape = tuple(ds.shape)
    k = shape[1] if len(shape) == 2 else 1
    units = unit_list(units_attr, k, src, path) if units_attr is not None else None
    return [ArrayItem(name, shape, ds.dtype, src, units=units, names=_names(_attr(ds, NAME_ATTRS), k),
                      loader=lambda _c, ds=ds: np.asarray(ds[()], dtype=np.float64))]


def _memmap(path: Path, ds):
    """A read-only memory map of a contiguous, unfiltered, native float64 dataset stored in ``path`` itself, else
    None (a dataset reached through an external link lives in another file; external raw storage and virtual
    datasets have no offset in ``path``)."""
    try:
        if (getattr(ds, "is_virtual", False) or ds.external
                or not Path(ds.file.filename).resolve().samefile(Path(path).resolve())):
            return None
        offset = ds.id.get_offset()
    except (*PARSER_ERRORS, OSError):
        return None
    if offset is None or ds.chunks is not None or ds.dtype != np.dtype("<f8") or ds.size == 0:
        return None
    return np.memmap(path, dtype="<f8", mode="r", offset=offset, shape=tuple(ds.shape))


def open_table(path: Path, *, dataset=None) -> Table:
    """Open an HDF5 file and lay out the chosen dataset or group as columns (see the module docstring).

    Raises
    ------
    DataFormatError
        Not HDF5 or corrupt, ``dataset`` not in the file (the message lists the datasets),
        several candidates and no ``dataset``, nothing numeric, units attribute of the wrong
        length.
    MissingDependencyError
        h5py is not installed (``pip install 'fogdrift[hdf5]'``).
    """
    h5py = _h5py()
    p = Path(path)
    try:
        fh = h5py.File(p, "r")
    except PARSER_ERRORS as exc:
        raise DataFormatError(
            f"unreadable HDF5 file; expected an HDF5 file, got {describe_exception(exc)}", path=p
        ) from exc
    try:
        return _open(h5py, p, fh, dataset)
    except DataFormatError:
        raise
    except PARSER_ERRORS as exc:
        raise DataFormatError(
            f"corrupt HDF5 file; expected readable groups and datasets, got {describe_exception(exc)}", path=p
        ) from exc


def _datasets(h5py, fh) -> list:
    found = []

    def visit(name, obj):
        if isinstance(obj, h5py.Dataset) and (obj.dtype.names or obj.dtype.kind in "biuf") and obj.ndim in (1, 2):
            found.append(obj)

    fh.visititems(visit)
    return found


def _open(h5py, p: Path, fh, dataset) -> Table:
    sha256 = file_sha256(p)
    if dataset is not None:
        key = str(dataset).strip()
        if key not in fh:
            listing = ", ".join(f"{d.name} {d.shape}" for d in _datasets(h5py, fh)) or "none"
            raise DataFormatError(
                f"no dataset or group {key!r} in the file; expected one of: {listing} (pass {{opt:dataset}})",
                path=p, column=key,
            )
        obj = fh[key]
    else:
        dsets = _datasets(h5py, fh)
        parents = {d.parent.name for d in dsets}
        if len(dsets) == 1:
            obj = dsets[0]
        elif len(parents) == 1 and dsets:
            obj = dsets[0].parent
        else:
            listing = ", ".join(f"{d.name} {d.shape}" for d in dsets) or "none"
            raise DataFormatError(
                f"{'no numeric dataset' if not dsets else 'several datasets in several groups'}; expected one "
                f"dataset or one group of columns, got {listing}; choose one with {{opt:dataset}}", path=p,
            )
    if isinstance(obj, h5py.Dataset):
        what = f"dataset {obj.name}"
        items = _item(p, obj, obj.name.rsplit("/", 1)[-1] or "col")
        named = bool(obj.dtype.names) or obj.ndim == 1 or items[0].names is not None
        if not obj.dtype.names and obj.ndim == 2 and items[0].names is None:
            items[0].names = [f"col{j}" for j in range(obj.shape[1])]
        mm = None if obj.dtype.names else _memmap(p, obj)
    else:
        what = f"group {obj.name}"
        items = []
        for name in obj:
            child = obj.get(name)
            if isinstance(child, h5py.Dataset) and (child.dtype.names or child.dtype.kind in "biuf"):
                items += _item(p, child, name)
        named, mm = True, None
    layout = layout_columns(items, p, what)
    table = HDF5Table(p, layout=layout, named=named, sha256=sha256, what=what)
    table.unit_hint = (f"{what} has no {UNIT_ATTRS[0]!r} attribute for its rate columns; pass {{opt:unit}}, or "
                       f"set the attribute on the dataset, e.g. {UNIT_ATTRS[0]}='deg/s'")
    if mm is not None and not layout.left_out:
        table.data = mm.reshape(mm.shape[0], -1)
    return table
