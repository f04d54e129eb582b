"""Windows of one axis of a large file, in deg/h, for out-of-core analysis (:mod:`fogdrift.allan.chunked`).

:func:`open_source` opens ``.npy``, raw binary or HDF5 without loading it: :meth:`ChunkSource.read` returns
samples ``[start, stop)`` of one column as float64 deg/h, read with plain file reads (``np.fromfile`` at an
offset) or an h5py hyperslab, so memory is bounded by the window asked for, never by the file (a memory
map would count every page it ever touched in the process's resident set).

This path takes the sample rate as given (``rate_hz``/``dt_s``): it has no time column and no gap
splitting.  A raw binary sequence counter is checked for gaps while the first pass streams the file (an
error names the record).  Load smaller files with :func:`fogdrift.io.load`, which checks everything.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from ..errors import ConfigError, DataFormatError
from ._checks import check_path, parse_unit, unit_scale, valid_units
from .readers._columns import unit_list
from .readers.base import require
from .readers.hdf5 import UNIT_ATTRS

__all__ = ["ChunkSource", "open_source"]


@dataclass
class ChunkSource:
    """One column of a file as a series of rate samples in deg/h, read window by window.

    Attributes
    ----------
    path : Path
    n_samples : int
    dt_s : float
        Sample interval in s.
    name : str
        Column (axis) name.
    scale_to_dph : float
        Factor applied to the stored numbers (raw binary scale times the unit's factor).
    describe : str
        Format and layout, for notes.
    """

    path: Path
    n_samples: int
    dt_s: float
    name: str
    scale_to_dph: float
    describe: str
    _read: Callable = field(repr=False, default=None)
    check: Callable | None = field(repr=False, default=None)   # check(start, stop) on the streaming pass

    def raw(self, start: int, stop: int) -> np.ndarray:
        """Samples ``start .. stop-1`` as stored (after a raw binary scale factor), before ``scale_to_dph``.

        ``raw(a, b) * scale_to_dph`` (in float64) is :meth:`read`; compiled consumers multiply as they go
        and save the float64 copy.
        """
        start, stop = int(start), int(stop)
        if not 0 <= start <= stop <= self.n_samples:
            raise ConfigError(f"window [{start}, {stop}) outside 0..{self.n_samples}")
        if stop == start:
            return np.empty(0)
        return np.ascontiguousarray(self._read(start, stop))

    def read(self, start: int, stop: int) -> np.ndarray:
        """Samples ``start .. stop-1`` in deg/h (float64, a new array)."""
        x = np.asarray(self.raw(start, stop), dtype=np.float64)
        if self.scale_to_dph != 1.0:
            x = np.multiply(x, self.scale_to_dph, dtype=np.float64)
        return x


def _npy(p: Path, column):
    with open(p, "rb") as fh:
        try:
            version = np.lib.format.read_magic(fh)
            header = np.lib.format.read_array_header_1_0 if version == (1, 0) else np.lib.format.read_array_header_2_0
            shape, fortran, dtype = header(fh)
        except (ValueError, OSError) as exc:
            raise DataFormatError(f"unreadable .npy header; expected a NumPy array, got {exc}", path=p) from exc
        offset = fh.tell()
    if dtype.kind not in "biuf" or len(shape) not in (1, 2):
        raise DataFormatError(f"array {dtype} {shape}; expected a 1-D or 2-D numeric array", path=p)
    n = shape[0]
    ncol = 1 if len(shape) == 1 else shape[1]
    j = _column_index(column, [f"col{k}" for k in range(ncol)], p)
    isz = dtype.itemsize
    if p.stat().st_size < offset + n * ncol * isz:
        raise DataFormatError(f"file holds {p.stat().st_size - offset} data bytes; expected {n * ncol * isz} for "
                              f"shape {shape} (truncated?)", path=p)

    def read(a, b):
        with open(p, "rb") as fh:
            if ncol == 1 or fortran:
                return np.fromfile(fh, dtype=dtype, count=b - a, offset=offset + (j * n + a) * isz)
            rows = np.fromfile(fh, dtype=dtype, count=(b - a) * ncol, offset=offset + a * ncol * isz)
            return rows.reshape(b - a, ncol)[:, j]

    return n, f"col{j}", read, f"npy {dtype} {shape}", None, None


def _binary(p: Path, column, layout, scale, header_bytes, sequence):
    from .readers.binary import SEQUENCE_NAMES, parse_layout, parse_scale

    dtype = parse_layout(layout)
    fields = [f for f in dtype.names if dtype.fields[f][0].kind in "biuf"]
    seq = None if (isinstance(sequence, str) and sequence.lower() == "none") else sequence
    if seq is None and sequence is None:
        seq = next((f for f in fields if f.lower() in SEQUENCE_NAMES and dtype.fields[f][0].kind in "iu"), None)
    candidates = [f for f in fields if f != seq]
    name = _column_name(column, candidates, p)
    factor = parse_scale(scale, candidates).get(name, 1.0)
    hb = int(header_bytes or 0)
    n, rest = divmod(p.stat().st_size - hb, dtype.itemsize)
    if rest or n <= 0:
        raise DataFormatError(f"file size {p.stat().st_size} is not the {hb}-byte header plus whole "
                              f"{dtype.itemsize}-byte records", path=p)

    def read(a, b):
        with open(p, "rb") as fh:
            rec = np.fromfile(fh, dtype=dtype, count=b - a, offset=hb + a * dtype.itemsize)
        return rec[name] * factor if factor != 1.0 else rec[name]

    check = None
    if seq is not None:
        bits = dtype.fields[seq][0].itemsize * 8
        state = {"last": None}

        def check(a, b):
            with open(p, "rb") as fh:
                s = np.fromfile(fh, dtype=dtype, count=b - a, offset=hb + a * dtype.itemsize)[seq].astype(np.int64)
            prev = np.concatenate([[state["last"]], s[:-1]]) if state["last"] is not None else s[:-1]
            cur = s if state["last"] is not None else s[1:]
            steps = (cur - prev) % (1 << bits) if bits < 64 else cur - prev
            bad = steps != 1
            if bad.any():
                i = int(np.argmax(bad)) + (a if state["last"] is not None else a + 1)
                raise DataFormatError(
                    f"sequence counter jumps from {int(prev[np.argmax(bad)])} to {int(cur[np.argmax(bad)])} at record "
                    f"{i}; expected a gap-free record for the out-of-core path (load it with fogdrift.io.load and "
                    "gaps='split', or cut it at the gap)", path=p, column=seq,
                )
            state["last"] = int(s[-1])

    return n, name, read, f"raw binary {dtype.itemsize}-byte records, field {name!r} x {factor:g}", check, None


def _hdf5(p: Path, column, dataset):
    h5py = require("h5py", "hdf5", "reading HDF5 files")
    with h5py.File(p, "r") as fh:
        if dataset is None:
            found = []
            fh.visititems(lambda k, o: found.append(o.name) if isinstance(o, h5py.Dataset) and o.ndim in (1, 2)
                          else None)
            if len(found) != 1:
                raise DataFormatError(f"{len(found)} datasets; pass {{opt:dataset}} (one of {found})", path=p)
            dataset = found[0]
        if dataset not in fh or not isinstance(fh[dataset], h5py.Dataset):
            raise DataFormatError(f"no dataset {dataset!r}; expected a 1-D, 2-D or compound dataset", path=p,
                                  column=dataset)
        ds = fh[dataset]
        n = ds.shape[0]
        attr = next((ds.attrs[k] for k in UNIT_ATTRS if k in ds.attrs), None)
        if ds.dtype.names:
            names = [f for f in ds.dtype.names if ds.dtype.fields[f][0].kind in "biuf"]
            key = _column_name(column, names, p)
            declared = unit_list(attr, len(ds.dtype.names), dataset, p)
            declared = None if declared is None else declared[ds.dtype.names.index(key)]
        else:
            ncol = 1 if ds.ndim == 1 else ds.shape[1]
            key = _column_index(column, [f"col{k}" for k in range(ncol)], p)
            declared = unit_list(attr, ncol, dataset, p)
            declared = None if declared is None else declared[key]
        compound, ndim = bool(ds.dtype.names), ds.ndim

    def read(a, b):
        with h5py.File(p, "r") as fh:
            ds = fh[dataset]
            if compound:
                return ds.fields(key)[a:b]
            return ds[a:b] if ndim == 1 else ds[a:b, key]

    return n, (key if compound else f"col{key}"), read, f"HDF5 dataset {dataset}", None, declared


def _column_index(column, names, p) -> int:
    if column is None:
        if len(names) != 1:
            raise ConfigError(f"{p}: {len(names)} columns; choose one with {{opt:columns}} ({names} or an index)")
        return 0
    if isinstance(column, str) and column in names:
        return names.index(column)
    try:
        j = int(column)
    except (TypeError, ValueError):
        j = -1
    if not 0 <= j < len(names):
        raise DataFormatError(f"unknown column {column!r}; expected one of {names} or an index", path=p, column=column)
    return j


def _column_name(column, names, p) -> str:
    if column is None:
        if len(names) != 1:
            raise ConfigError(f"{p}: {len(names)} columns; choose one with {{opt:columns}} (one of {names})")
        return names[0]
    if column in names:
        return column
    return names[_column_index(column, names, p)]


def open_source(path, *, column=None, unit=None, rate_hz=None, dt_s=None, layout=None, scale=None,
                header_bytes=0, sequence=None, dataset=None) -> ChunkSource:
    """Open one column of a ``.npy``, raw binary (``layout`` given) or HDF5 file for windowed reads.

    Parameters
    ----------
    path : str or Path
    column : int or str, optional
        Column (name or 0-based index); required when there are several.
    unit : str, optional
        Unit of the stored numbers after ``scale`` (a rate unit or ``inc:<angle>``).  Required
        unless an HDF5 dataset declares it in a ``units``/``unit`` attribute: units are never
        guessed.
    rate_hz, dt_s : float
        Sample rate or interval (one of them is required).
    layout, scale, header_bytes, sequence
        Raw binary, as for :mod:`fogdrift.io.readers.binary`.
    dataset : str, optional
        HDF5 dataset path (default: the only 1-D/2-D dataset).

    Returns
    -------
    ChunkSource

    Raises
    ------
    ConfigError
        Missing rate or unit, bad unit, ambiguous column, a format other than npy/binary/HDF5.
    DataFormatError
        Unreadable header, truncated file, unknown column or dataset.
    """
    p = check_path(path)
    from .load import _interval_option

    dt = _interval_option(dt_s, rate_hz)
    if dt is None:
        raise ConfigError(f"{p}: the out-of-core path needs the sample rate; pass {{opt:rate_hz}} (or dt_s)")
    if unit is not None:
        parse_unit(unit)
    if layout is not None:
        n, name, read, what, check, declared = _binary(p, column, layout, scale, header_bytes, sequence)
    else:
        from .registry import select_reader

        fmt = select_reader(p).name
        if fmt == "npy":
            n, name, read, what, check, declared = _npy(p, column)
        elif fmt == "hdf5":
            n, name, read, what, check, declared = _hdf5(p, column, dataset)
        else:
            raise ConfigError(f"{p}: out-of-core reading supports .npy, raw binary (pass {{opt:layout}}) and HDF5; "
                              f"got a {fmt} file (load it with fogdrift.io.load)")
    if unit is None:
        if declared is None:
            raise ConfigError(f"{p}: no rate unit: {what} declares none; pass {{opt:unit}} ({', '.join(valid_units())}; "
                              "units are never guessed)")
        try:
            parse_unit(declared)
        except ConfigError:
            raise DataFormatError(f"unknown unit {declared!r} declared in the file; expected one of {valid_units()} "
                                  "(or pass {opt:unit})", path=p, column=str(name)) from None
        unit = declared
    kind, base = parse_unit(unit)
    factor = unit_scale(kind, base, dt)
    return ChunkSource(path=p, n_samples=int(n), dt_s=dt, name=str(name), scale_to_dph=factor,
                       describe=f"{what}, unit {unit}", _read=read, check=check)
