"""Large files read in pieces: windows of one axis for out-of-core analysis (:mod:`fogdrift.allan.chunked`), and
row chunks of several axes for ``fogdrift compensate``.

:func:`open_source` opens ``.npy``, raw binary or HDF5 without loading it: :meth:`ChunkSource.read` returns
samples ``[start, stop)`` of one column as float64 deg/h, read with plain file reads (``np.fromfile`` at an
offset) or an h5py hyperslab, so memory is bounded by the window asked for, never by the file (a memory
map would count every page it ever touched in the process's resident set).

:func:`open_rows` streams the rate columns of a ``.npy`` in row chunks, each converted once to deg/h by the
factor it records in its :class:`~fogdrift.signal.SignalDescription` (``fogdrift compensate`` reads ``.npy`` logs
through it); a named time column's steps, scatter and span are checked as the rows stream, by the rules of
:func:`fogdrift.io.load`.

:func:`open_source` takes the sample rate as given (``rate_hz``/``dt_s``): it has no time column and no gap
splitting.  A raw binary sequence counter is checked for gaps while the first pass streams the file (an
error names the record).  Load smaller files with :func:`fogdrift.io.load`, which checks everything.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from ..errors import ConfigError, DataFormatError
from ..signal import Channel, Sampling, SignalDescription, channel_unit
from ..units import TIME_UNITS, check_dt_s, valid_units
from ._checks import check_path
from .hashing import file_sha256
from .load import _interval_option
from .timebase import (DT_TOLERANCE, GAP_FACTOR, GRID_DRIFT_FRACTION, GRID_DRIFT_INTERVALS, JITTER_TOLERANCE,
                       SHORT_STEP_FACTOR)
from .readers._columns import unit_list
from .readers.base import require
from .readers.hdf5 import UNIT_ATTRS

__all__ = ["ChunkSource", "open_source", "RowSource", "open_rows"]


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
    scale_to_internal : float
        Factor from the stored numbers to the internal unit (raw binary scale times the unit's factor; 1 for a
        series already in it).
    describe : str
        Format and layout, for notes.
    """

    path: Path
    n_samples: int
    dt_s: float
    name: str
    scale_to_internal: float
    describe: str
    _read: Callable = field(repr=False, default=None)
    check: Callable | None = field(repr=False, default=None)   # check(start, stop) on the streaming pass

    def raw(self, start: int, stop: int) -> np.ndarray:
        """Samples ``start .. stop-1`` as stored (after a raw binary scale factor), before ``scale_to_internal``.

        ``raw(a, b) * scale_to_internal`` (in float64) is :meth:`read`; compiled consumers multiply as they go
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
        if self.scale_to_internal != 1.0:
            x = np.multiply(x, self.scale_to_internal, dtype=np.float64)
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
    dt = _interval_option(dt_s, rate_hz)
    if dt is None:
        raise ConfigError(f"{p}: the out-of-core path needs the sample rate; pass {{opt:rate_hz}} (or dt_s)")
    if unit is not None:
        channel_unit(unit, "angular_rate")
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
            channel_unit(declared, "angular_rate")
        except ConfigError:
            raise DataFormatError(f"unknown unit {declared!r} declared in the file; expected one of {valid_units()} "
                                  "(or pass {opt:unit})", path=p, column=str(name)) from None
        unit = declared
    factor = channel_unit(unit, "angular_rate").scale_to_internal(dt)
    return ChunkSource(path=p, n_samples=int(n), dt_s=dt, name=str(name), scale_to_internal=factor,
                       describe=f"{what}, unit {unit}", _read=read, check=check)


# ----------------------------------------------------------------------------------------------------------
# several columns of a .npy, row chunk by row chunk, with the time base checked as it streams
# ----------------------------------------------------------------------------------------------------------
#: Rows per chunk when a caller gives none.
DEFAULT_ROWS = 1 << 20
#: Time steps the sample interval (their median) and their scatter are taken from.
HEAD_STEPS = 1 << 16


@dataclass
class RowSource:
    """Rate columns of a ``.npy`` file read in row chunks, in the internal unit (:func:`open_rows`).

    Attributes
    ----------
    path : Path
    axis_names : tuple of str
        ``col<j>`` of each rate column.
    n_samples : int
    dt_s, t0_s : float
        Sample interval and time of the first sample [s].
    unit : str
        Unit of the stored numbers (given: a ``.npy`` declares none).
    declared_units : tuple of None
        What the file declares per rate column (nothing).
    scale_to_dph : float
        Factor from ``unit`` to deg/h, applied once by :meth:`chunks`.
    sha256 : str
        SHA-256 of the file's bytes.
    signal : fogdrift.signal.SignalDescription
        The sampling (interval and where it came from) and the channels (unit as given, its factor), made here
        once.
    notes : list of str
    """

    path: Path
    axis_names: tuple
    n_samples: int
    dt_s: float
    t0_s: float
    unit: str
    declared_units: tuple
    scale_to_dph: float
    sha256: str
    signal: SignalDescription
    notes: list = field(default_factory=list)
    _reader: Callable = field(repr=False, default=None)

    def chunks(self, chunk_samples: int = DEFAULT_ROWS):
        """Yield ``(t_s (n,), rate_dph (n, n_axes))`` in order, ``chunk_samples`` rows at a time.

        The time base (a time column's steps and span) and the finiteness of every value are checked as the rows
        stream: an error names the sample.
        """
        if isinstance(chunk_samples, bool) or not isinstance(chunk_samples, (int, np.integer)) or chunk_samples < 1:
            raise ConfigError(f"{{opt:chunk_samples}} must be an integer >= 1 (rows read at a time); got "
                              f"{chunk_samples!r}")
        yield from self._reader(int(chunk_samples))


def _npy_layout(p: Path):
    """(rows, columns, dtype, Fortran order, data offset) of a real numeric 1-D or 2-D ``.npy``."""
    try:
        with open(p, "rb") as fh:
            version = np.lib.format.read_magic(fh)
            header = np.lib.format.read_array_header_1_0 if version == (1, 0) else np.lib.format.read_array_header_2_0
            shape, fortran, dtype = header(fh)
            offset = fh.tell()
    except (ValueError, OSError, EOFError) as exc:
        raise DataFormatError(f"unreadable .npy header; expected a NumPy array file, got {exc}", path=p) from None
    if dtype.kind not in "biuf" or dtype.hasobject or len(shape) not in (1, 2):
        raise DataFormatError(f"array of dtype {dtype} and shape {shape}; expected a real numeric 1-D or 2-D array",
                              path=p)
    rows = int(shape[0])
    cols = 1 if len(shape) == 1 else int(shape[1])
    if p.stat().st_size < offset + rows * cols * dtype.itemsize:
        raise DataFormatError(f"file holds {p.stat().st_size - offset} data bytes; expected "
                              f"{rows * cols * dtype.itemsize} for shape {shape} (truncated?)", path=p)
    return rows, cols, dtype, bool(fortran) and cols > 1, offset


def _row_column(key, cols: int, option: str, p: Path) -> int:
    if isinstance(key, (int, np.integer)) and not isinstance(key, bool) and -cols <= int(key) < cols:
        return int(key) % cols
    if isinstance(key, str):
        k = key.strip()
        if k.isdigit() and int(k) < cols:
            return int(k)
        if k.startswith("col") and k[3:].isdigit() and int(k[3:]) < cols:
            return int(k[3:])
    raise DataFormatError(f"unknown column {key!r}; expected one of col0..col{cols - 1} or an index in "
                          f"{{opt:{option}}}", path=p, column=key)


def open_rows(path, *, columns=None, time_column="auto", rate_hz=None, dt_s=None, time_unit=None,
              unit=None) -> RowSource:
    """Open the rate columns of a ``.npy`` file for streaming in row chunks (memory bounded by the chunk).

    The columns are ``col0, col1, ...`` as for :func:`fogdrift.io.load`.  A time column is used only when named
    (``time_column``; ``"auto"`` finds none in an array); its steps are checked as the rows stream by the rules
    of :func:`fogdrift.io.load` (:data:`~fogdrift.io.timebase.SHORT_STEP_FACTOR`,
    :data:`~fogdrift.io.timebase.GAP_FACTOR`, :data:`~fogdrift.io.timebase.JITTER_TOLERANCE` on the first
    :data:`HEAD_STEPS` steps, the span against ``(n - 1) dt`` within :data:`~fogdrift.io.timebase.DT_TOLERANCE` at
    opening, every stamp near the straight line from the first to the last, :data:`~fogdrift.io.timebase.GRID_DRIFT_INTERVALS`).

    Parameters
    ----------
    path : str or Path
    columns : None, int, str or sequence
        Rate columns (``"col0,col2"``, ``"1"``, ``[0, 2]``); default every column but the time column.
    time_column : "auto", None, int or str
    rate_hz, dt_s : float, optional
        Sample rate [Hz] or interval [s]; required without a time column, else checked against it (1 %).
    time_unit : {"s", "ms", "us", "ns"}, optional
        Unit of the time column (default s).
    unit : str
        Unit of the numbers (:func:`fogdrift.units.parse_unit`); required: a ``.npy`` declares none and units
        are never guessed.

    Returns
    -------
    RowSource

    Raises
    ------
    ConfigError
        No unit, unknown unit or time unit, no way to know the sample interval, the same column twice.
    DataFormatError
        Not a real numeric 1-D/2-D array, truncated file, unknown column, a time column that contradicts the
        rate; while streaming: a non-finite value, a time step out of the rules, a span that does not match.

    Examples
    --------
    >>> import tempfile, os
    >>> p = os.path.join(tempfile.mkdtemp(), "g.npy")
    >>> np.save(p, np.array([[0.0, 1.0], [0.5, 2.0], [1.0, 3.0]]))
    >>> src = open_rows(p, time_column="col0", unit="deg/s")
    >>> src.axis_names, src.dt_s, src.scale_to_dph
    (('col1',), 0.5, 3600.0)
    >>> [x[:, 0].tolist() for _, x in src.chunks(2)]
    [[3600.0, 7200.0], [10800.0]]
    """
    p = check_path(path)
    rows, cols, dtype, fortran, offset = _npy_layout(p)
    t_idx = None
    if time_column is not None and not (isinstance(time_column, str) and time_column.strip().lower() in ("auto",
                                                                                                          "none")):
        t_idx = _row_column(time_column, cols, "time_column", p)
    if columns is None:
        r_idx = [j for j in range(cols) if j != t_idx]
    else:
        keys = [c.strip() for c in columns.split(",") if c.strip()] if isinstance(columns, str) else list(columns)
        r_idx = [_row_column(k, cols, "columns", p) for k in keys]
    if not r_idx or len(set(r_idx)) != len(r_idx) or t_idx in r_idx:
        raise ConfigError(f"{p}: choose distinct rate columns other than the time column with {{opt:columns}}; got "
                          f"columns={columns!r}")
    if unit is None:
        raise ConfigError(f"{p}: no rate unit: a .npy array declares none; pass {{opt:unit}} "
                          f"({', '.join(valid_units())}; units are never guessed)")
    spec = channel_unit(unit, "angular_rate")
    if time_unit is not None and time_unit not in TIME_UNITS:
        raise ConfigError(f"unknown time unit {time_unit!r}; expected one of {list(TIME_UNITS)} ({{opt:time_unit}})")
    t_scale = TIME_UNITS[time_unit] if time_unit else 1.0
    dt_user = _interval_option(dt_s, rate_hz)

    def read(lo, hi):
        if fortran:
            mm = np.load(p, mmap_mode="r")
            return np.array(mm[lo:hi], dtype=np.float64).reshape(hi - lo, cols)
        with open(p, "rb") as fh:
            a = np.fromfile(fh, dtype=dtype, count=(hi - lo) * cols, offset=offset + lo * cols * dtype.itemsize)
        return a.reshape(hi - lo, cols)

    notes = [f"npy array, {rows} samples x {cols} columns, read in chunks"]
    tcol = f"col{t_idx}"
    if t_idx is None:
        if dt_user is None:
            raise ConfigError(f"{p}: cannot tell the sample interval: a .npy file has no time column unless one is "
                              "named with {opt:time_column}; pass the sample rate in Hz as {opt:rate_hz}")
        dt, t0 = dt_user, 0.0
        notes.append(f"sample interval {dt:.10g} s from the given rate (no time column)")
    else:
        head = np.asarray(read(0, min(rows, HEAD_STEPS + 1))[:, t_idx], dtype=np.float64) * t_scale
        if head.size < 2:
            raise DataFormatError("fewer than 2 samples; expected at least 2 to take the sample interval", path=p)
        steps = np.diff(head)
        dt = float(f"{float(np.median(steps)):.10g}")
        t0 = float(head[0])
        if not (np.isfinite(dt) and dt > 0):
            raise DataFormatError(f"time steps' median {dt!r} s; expected strictly increasing time", path=p,
                                  column=tcol)
        if dt_user is not None:
            if abs(dt - dt_user) > DT_TOLERANCE * dt_user:
                raise DataFormatError(f"time column disagrees with the given sample interval; expected steps of "
                                      f"{dt_user:.10g} s within 1 %, got {dt:.10g} s", path=p, column=tcol)
            dt = dt_user
        spread = float(np.median(np.abs(steps - dt))) / dt
        if steps.size >= 8 and spread > JITTER_TOLERANCE:
            raise DataFormatError(f"time steps scatter by {100 * spread:.3g} % of the sample interval {dt:.10g} s "
                                  f"(median absolute deviation of the first {steps.size} steps); expected a uniform "
                                  f"grid within {100 * JITTER_TOLERANCE:g} %", path=p, column=tcol)
        notes.append(f"sample interval {dt:.10g} s from the time column {tcol} (median of the first steps)")
        # the last stamp, read now: the span is checked before any work and gives the straight line from the first
        # to the last stamp that every chunk's stamps must stay near (fogdrift.io.timebase, the same rules)
        t_last = float(np.asarray(read(rows - 1, rows)[:, t_idx], dtype=np.float64)[0]) * t_scale
        span, grid = t_last - t0, (rows - 1) * dt
        if rows > 2 and abs(span - grid) > DT_TOLERANCE * grid:
            raise DataFormatError(
                f"time column spans {span:.6g} s, but its {rows} samples at {dt:.10g} s span "
                f"{grid:.6g} s ({100 * (span / grid - 1):+.3g} %); expected agreement within "
                f"{100 * DT_TOLERANCE:g} %", path=p, column=tcol)
        slope = span / (rows - 1)
        drift_limit = max(GRID_DRIFT_INTERVALS * dt, GRID_DRIFT_FRACTION * span)
    check_dt_s(dt, "the sample interval")
    scale = float(spec.scale_to_internal(dt))

    def reader(chunk):
        prev_t = None
        for lo in range(0, rows, chunk):
            hi = min(rows, lo + chunk)
            a = read(lo, hi)
            with np.errstate(over="ignore", invalid="ignore"):
                x = np.multiply(a[:, r_idx], scale, dtype=np.float64)
            bad = ~np.isfinite(x)
            if bad.any():
                i, j = np.argwhere(bad)[0]
                raise DataFormatError(f"non-finite value at sample {lo + i} (in deg/h); expected a finite number, "
                                      f"got {float(a[i, r_idx[j]])!r} {spec.text}", path=p, column=f"col{r_idx[j]}")
            if t_idx is None:
                t = t0 + np.arange(lo, hi) * dt
            else:
                t = np.asarray(a[:, t_idx], dtype=np.float64) * t_scale
                with np.errstate(over="ignore", invalid="ignore"):
                    steps = np.diff(t if prev_t is None else np.concatenate([[prev_t], t]))
                first = lo + 1 if prev_t is None else lo
                bad = ~(steps >= SHORT_STEP_FACTOR * dt) | (steps > GAP_FACTOR * dt)
                if bad.any():
                    k = int(np.argmax(bad))
                    raise DataFormatError(
                        f"time step at sample {first + k} is {float(steps[k])!r} s ({float(steps[k]) / dt:.3g} sample "
                        f"intervals); expected increasing time in steps of {dt:.10g} s (between "
                        f"{SHORT_STEP_FACTOR} and {GAP_FACTOR} intervals: no gap, no rate change)", path=p,
                        column=tcol)
                prev_t = float(t[-1])
                dev = t - (t0 + np.arange(lo, hi, dtype=np.float64) * slope)
                off = np.abs(dev) > drift_limit
                if off.any():
                    k = int(np.argmax(off))
                    raise DataFormatError(
                        f"time stamps run {abs(float(dev[k])):.6g} s ({abs(float(dev[k])) / dt:.3g} sample intervals) "
                        f"{'ahead of' if dev[k] > 0 else 'behind'} a uniform grid at sample {lo + k} (the straight line "
                        f"from the first to the last stamp); expected within {drift_limit:.3g} s: the sample rate "
                        "changes within the log", path=p, column=tcol)
            yield t, x

    names = tuple(f"col{j}" for j in r_idx)
    sampling = Sampling(dt_s=dt, dt_source="rate option" if t_idx is None else "time column",
                        time_column=None if t_idx is None else tcol,
                        time_unit=None if t_idx is None else (time_unit or "s"),
                        time_unit_source=None if t_idx is None else ("option" if time_unit else None))
    signal = SignalDescription(sampling=sampling, channels=tuple(
        Channel(name=n, unit=spec, unit_source="option", declared_unit=None, scale_to_internal=scale) for n in names))
    return RowSource(path=p, axis_names=names, n_samples=rows, dt_s=dt, t0_s=t0, unit=spec.text,
                     declared_units=(None,) * len(r_idx), scale_to_dph=scale, sha256=file_sha256(p), signal=signal,
                     notes=notes, _reader=reader)
