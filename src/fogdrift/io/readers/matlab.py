"""MATLAB ``.mat`` reader: v4/v5/v7 through :func:`scipy.io.loadmat`, v7.3 (HDF5) through h5py (extra ``[hdf5]``).

What becomes the table (``variable`` option, a top-level variable name):

* a numeric matrix: its columns (``col0 ..``); samples run along the longer dimension, so a
  ``3 x n`` matrix of row vectors is read as ``n x 3`` (a note says so); a vector: one column
  named after the variable;
* a struct (``imu.t``, ``imu.gx`` ...): its numeric fields of the longest length as named
  columns (:mod:`._columns`); an ``n x k`` field gives ``k`` columns.

Without ``variable``: the only numeric or struct variable, else every numeric top-level vector of
the longest length as a named column (``save log.mat t gx gy gz``); otherwise an error lists the
variables.  MATLAB files carry no units: pass ``unit`` (a name such as ``gz_dps`` is not read as
a unit).  MATLAB ``table``/``timeseries`` objects are opaque outside MATLAB: save their contents
as a matrix or a struct.  The SHA-256 is of the file's bytes.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ...errors import DataFormatError
from ..hashing import file_sha256
from ._columns import ArrayItem, check_layout, layout_columns, read_layout
from .base import PARSER_ERRORS, Table, describe_exception, require
from .limits import check_expansion, check_memory

__all__ = ["open_table", "MatTable", "mat_version"]

#: Bytes 0..18 of a v7.3 file (an HDF5 file with a 512-byte MATLAB user block).
_V73 = b"MATLAB 7.3 MAT-file"


def mat_version(head: bytes) -> str:
    """``"7.3"`` (HDF5-based), ``"5"`` (v5/v7, text header) or ``"4"`` (no text header) from the first bytes.

    Examples
    --------
    >>> mat_version(b"MATLAB 7.3 MAT-file, Platform: GLNXA64"), mat_version(b"MATLAB 5.0 MAT-file")
    ('7.3', '5')
    """
    if head.startswith(_V73):
        return "7.3"
    return "5" if head.startswith(b"MATLAB") else "4"


class MatTable(Table):
    """Columns of one MATLAB variable (or of several vectors); numbers converted in :meth:`read`."""

    format = "mat"

    def __init__(self, path, *, layout, named, sha256, what, notes):
        super().__init__(path, names=layout.names, named=named, units=layout.units, sha256=sha256)
        self.layout = layout
        self.what = what
        self.extra_notes = list(notes)
        self.unit_hint = "MATLAB files carry no units; pass {opt:unit}"

    def read(self, used) -> np.ndarray:
        if self.data is None:
            check_layout(self.layout, used, self.path)
            self.data = read_layout(self.layout, used)
        return self.data

    def describe(self, n_rows: int) -> str:
        left = f"; left out {', '.join(self.layout.left_out)}" if self.layout.left_out else ""
        return f"MATLAB {self.what}, {n_rows} samples x {len(self.names)} columns{left}"


#: Bytes per element of MATLAB's numeric classes (as :func:`scipy.io.whosmat` names them).
_CLASS_BYTES = {"double": 8, "single": 4, "int8": 1, "uint8": 1, "int16": 2, "uint16": 2, "int32": 4, "uint32": 4,
                "int64": 8, "uint64": 8, "logical": 1, "char": 2}


def _unreadable(p: Path, exc: BaseException) -> DataFormatError:
    return DataFormatError(
        f"unreadable MATLAB file; expected a v4/v5/v7 .mat file, got {describe_exception(exc)}", path=p)


def _check_sizes(p: Path) -> None:
    """Refuse variables whose declared shapes exceed the expansion limit or the memory budget, before loading.

    :func:`scipy.io.whosmat` reads only the variables' headers (a compressed variable's first bytes); struct and
    cell contents are not listed there and are not checked.
    """
    from scipy.io import whosmat

    try:
        listing = whosmat(p)
    except Exception as exc:  # noqa: BLE001 -- scipy's parser raises MatReadError, IndexError, struct.error...
        raise _unreadable(p, exc) from exc
    declared = 0
    for name, shape, cls in listing:
        n = math.prod(int(s) for s in shape) * _CLASS_BYTES.get(cls, 0)
        check_memory(n / _CLASS_BYTES.get(cls, 1) * 8, p, f"variable {name!r} {tuple(shape)} as float64")
        declared += n
    check_expansion(declared, p.stat().st_size, p, f"the MATLAB file's {len(listing)} variable(s)")


def _load_v5(p: Path) -> dict:
    from scipy.io import loadmat

    _check_sizes(p)
    try:
        raw = loadmat(p, simplify_cells=True)
    except Exception as exc:  # noqa: BLE001 -- scipy's parser raises MatReadError, IndexError, struct.error...
        raise _unreadable(p, exc) from exc
    return {k: v for k, v in raw.items() if not k.startswith("__")}


def _load_v73(p: Path) -> dict:
    h5py = require("h5py", "hdf5", "reading MATLAB v7.3 (.mat, HDF5-based) files")
    size, declared = p.stat().st_size, [0]

    def convert(obj):
        if isinstance(obj, h5py.Group):
            return {k: convert(obj[k]) for k in obj if not k.startswith("#")}
        cls = obj.attrs.get("MATLAB_class", b"")
        cls = cls.decode() if isinstance(cls, bytes) else str(cls)
        if cls in ("char", "cell", "function_handle") or obj.dtype.kind not in "biuf" or obj.attrs.get(
                "MATLAB_empty", 0):
            return np.asarray([], dtype=object)  # left out by the layout rule
        # every variable is read at open: its declared size is checked first (a compressed dataset can claim GBs)
        check_memory(obj.size * 8.0, p, f"variable {obj.name!r} {tuple(obj.shape)[::-1]} as float64")
        declared[0] += obj.size * obj.dtype.itemsize
        check_expansion(declared[0], size, p, "the MATLAB v7.3 file's variables")
        arr = np.asarray(obj[()]).T            # MATLAB is column-major: HDF5 holds the transpose
        return arr.reshape(-1) if arr.ndim == 2 and 1 in arr.shape else arr

    try:
        with h5py.File(p, "r") as fh:
            return {k: convert(fh[k]) for k in fh if not k.startswith("#")}
    except DataFormatError:  # a reading limit (a ValueError too): as it is
        raise
    except PARSER_ERRORS as exc:
        raise DataFormatError(
            f"unreadable MATLAB v7.3 file; expected HDF5 data after the MATLAB header, got {describe_exception(exc)}",
            path=p,
        ) from exc


def _as_item(name: str, value, source: str, notes: list) -> ArrayItem | None:
    arr = np.asarray(value) if not isinstance(value, dict) else None
    if arr is None or arr.dtype.kind not in "biuf" or arr.ndim not in (1, 2) or arr.size <= 1:
        return None
    if arr.ndim == 2 and 1 in arr.shape:
        arr = arr.reshape(-1)
    if arr.ndim == 2 and arr.shape[0] < arr.shape[1]:
        notes.append(f"{source} is {arr.shape[0]} x {arr.shape[1]}: read as {arr.shape[1]} samples of "
                     f"{arr.shape[0]} channels (samples along the longer dimension)")
        arr = arr.T
    return ArrayItem(name, arr.shape, arr.dtype, source, loader=lambda _c, a=arr: np.asarray(a, dtype=np.float64))


def _describe_vars(variables: dict) -> str:
    parts = []
    for k, v in variables.items():
        if isinstance(v, dict):
            parts.append(f"{k} (struct: {', '.join(v) or 'no fields'})")
        else:
            a = np.asarray(v)
            parts.append(f"{k} {a.dtype} {a.shape}")
    return ", ".join(parts) or "none"


def open_table(path: Path, *, variable=None) -> Table:
    """Open a ``.mat`` file and lay out the chosen variable as columns (see the module docstring).

    Raises
    ------
    DataFormatError
        Unreadable or corrupt file, ``variable`` not in the file (the message lists the
        variables), several candidates and no ``variable``, nothing numeric.
    MissingDependencyError
        A v7.3 file and h5py not installed (``pip install 'fogdrift[hdf5]'``).
    """
    p = Path(path)
    try:
        with open(p, "rb") as fh:
            head = fh.read(128)
    except OSError as exc:
        raise DataFormatError(f"cannot read file; expected a readable file, got {exc.strerror or exc}",
                              path=p) from exc
    version = mat_version(head)
    variables = _load_v73(p) if version == "7.3" else _load_v5(p)
    notes = [f"MATLAB v{version} file"]
    if variable is not None:
        key = str(variable).strip()
        if key not in variables:
            raise DataFormatError(
                f"no variable {key!r} in the file; expected one of: {_describe_vars(variables)} "
                "(pass {opt:variable})", path=p, column=key,
            )
        chosen = {key: variables[key]}
    else:
        chosen = {k: v for k, v in variables.items()
                  if isinstance(v, dict) or _as_item(k, v, k, []) is not None}
    structs = [k for k, v in chosen.items() if isinstance(v, dict)]
    if len(chosen) == 1 and structs:
        name = structs[0]
        items = [it for f, v in chosen[name].items() if (it := _as_item(f, v, f"{name}.{f}", notes)) is not None]
        what, named = f"struct {name!r}", True
    elif len(chosen) == 1:
        (name, value), = chosen.items()
        item = _as_item(name, value, name, notes)
        if item is None:
            raise DataFormatError(
                f"variable {name!r} holds no samples; expected a numeric vector, matrix or struct, got "
                f"{_describe_vars({name: value})}", path=p, column=name,
            )
        items = [item]
        named = item.shape.__len__() == 1
        if not named:
            item.names = [f"col{j}" for j in range(item.shape[1])]
        what = f"variable {name!r}"
    elif not structs and chosen:
        items = [_as_item(k, v, k, notes) for k, v in chosen.items()]
        what, named = "variables " + ", ".join(chosen), True
    else:
        raise DataFormatError(
            f"{'no numeric variable' if not chosen else 'several variables'}; expected one matrix, one struct or "
            f"vectors of samples, got {_describe_vars(variables)}; choose one with {{opt:variable}}", path=p,
        )
    layout = layout_columns(items, p, what)
    return MatTable(p, layout=layout, named=named, sha256=file_sha256(p), what=what, notes=notes)
