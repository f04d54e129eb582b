"""Loading gyro logs into a :class:`GyroRecord` (rates in deg/h, time in s).

This is the only module where input units are converted (see :mod:`fogdrift.units`); it does
no analysis.  Supported inputs:

* text (CSV/TXT, optionally ``.gz``): comma, tab, semicolon or whitespace separated, with or
  without one header row; lines (or line tails) starting with ``#`` or ``%`` are comments;
* NumPy ``.npy`` (1-D = one axis, 2-D = columns), opened with ``mmap_mode="r"`` so that a
  float64 deg/h record is never copied;
* NumPy ``.npz`` (several 1-D arrays = named columns, or a single 2-D array).

The format is detected from the file's first bytes, not its name.  Every problem with the
input raises :class:`~fogdrift.errors.DataFormatError` located as
``<path>:<line>:<column>: <what>; expected <rule>, got <value>``; ``line`` is the 1-based
physical line (header and comments included), ``column`` the column name (files with a
header, arrays) or the 1-based field number (header-less text).  In arrays the location is
the sample index, given in the message ("at sample 12345").

Conventions: sample ``k`` of a record covers ``[t0_s + k dt_s, t0_s + (k+1) dt_s)``, so
``duration_s = n_samples * dt_s`` and block averages keep ``t0_s``.
"""

from __future__ import annotations

import dataclasses
import gzip
import hashlib
import io
import math
import warnings
import zipfile
import zlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import units
from .errors import ConfigError, DataFormatError, FogdriftWarning, InsufficientDataError

__all__ = [
    "GyroRecord",
    "load",
    "load_segments",
    "from_array",
    "block_average",
    "file_sha256",
    "TIME_COLUMN_NAMES",
    "GAP_FACTOR",
    "DT_TOLERANCE",
]

#: Column names (compared case-insensitively) that ``time_column="auto"`` takes as time in s.
TIME_COLUMN_NAMES = ("t", "t_s", "time", "time_s", "timestamp")
#: A time step larger than ``GAP_FACTOR`` sample intervals is a gap.
GAP_FACTOR = 1.5
#: Largest relative disagreement allowed between the time column and ``dt_s``/``rate_hz``.
DT_TOLERANCE = 0.01
#: Relative tolerance for "target interval is an integer multiple of dt_s" in block averaging.
_MULTIPLE_RTOL = 1e-6
#: Rows per chunk when scanning large (memory-mapped) arrays, keeps temporaries small.
_CHUNK_ROWS = 1 << 16
_COMMENT_CHARS = ("#", "%")
_DELIMITERS = {
    ",": ",", "comma": ",",
    ";": ";", "semicolon": ";",
    "\t": "\t", "\\t": "\t", "tab": "\t",
    " ": None, "whitespace": None, "space": None,
}
_DELIM_NAMES = {",": "comma", ";": "semicolon", "\t": "tab", None: "whitespace"}


# --------------------------------------------------------------------------------------------
# GyroRecord
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class GyroRecord:
    """A uniformly sampled multi-axis gyro record in deg/h.

    Parameters
    ----------
    rate_dph : ndarray, shape (n_samples, n_axes), float64
        Angular rate in deg/h.  Stored as a read-only view (possibly of a memory map): copy
        it before modifying.
    dt_s : float
        Sample interval in s (> 0).
    axis_names : tuple of str
        One unique name per column of ``rate_dph``.
    source : str
        File path, or ``"<array>"``.
    input_unit : str
        Unit of the input numbers as given (``"deg/s"``, ``"inc:arcsec"`` ...).
    scale_to_dph : float
        Factor that was applied to the input numbers to get deg/h.
    t0_s : float, optional
        Time of the first sample in s.
    notes : tuple of str, optional
        Provenance ("segment 2 of 3: samples ...", "block-averaged x100 ...").

    Notes
    -----
    Sample ``k`` covers ``[t0_s + k dt_s, t0_s + (k + 1) dt_s)``; ``duration_s`` is
    ``n_samples * dt_s``.  Records compare by identity (they hold arrays).
    """

    rate_dph: np.ndarray
    dt_s: float
    axis_names: tuple[str, ...]
    source: str
    input_unit: str
    scale_to_dph: float
    t0_s: float = 0.0
    notes: tuple[str, ...] = ()

    def __post_init__(self):
        r = self.rate_dph
        if not isinstance(r, np.ndarray) or r.ndim != 2 or r.dtype != np.float64:
            raise ConfigError(
                "rate_dph must be a float64 array of shape (n_samples, n_axes); got "
                f"{type(r).__name__} {getattr(r, 'dtype', '')} {getattr(r, 'shape', '')}".rstrip()
            )
        if r.flags.writeable:
            r = r.view()
            r.flags.writeable = False
            object.__setattr__(self, "rate_dph", r)
        names = tuple(str(a) for a in self.axis_names)
        if len(names) != r.shape[1]:
            raise ConfigError(f"axis_names must name the {r.shape[1]} columns of rate_dph; got {names!r}")
        if len(set(names)) != len(names):
            raise ConfigError(f"axis_names must be unique; got {names!r}")
        object.__setattr__(self, "axis_names", names)
        object.__setattr__(self, "dt_s", _positive_float(self.dt_s, "dt_s"))
        object.__setattr__(self, "t0_s", float(self.t0_s))
        object.__setattr__(self, "scale_to_dph", float(self.scale_to_dph))
        object.__setattr__(self, "source", str(self.source))
        object.__setattr__(self, "notes", tuple(str(n) for n in self.notes))

    # -- sizes ---------------------------------------------------------------------------------
    @property
    def n_samples(self) -> int:
        """Number of samples."""
        return int(self.rate_dph.shape[0])

    @property
    def n_axes(self) -> int:
        """Number of axes (columns)."""
        return int(self.rate_dph.shape[1])

    @property
    def fs_hz(self) -> float:
        """Sample rate in Hz (``1 / dt_s``)."""
        return 1.0 / self.dt_s

    @property
    def duration_s(self) -> float:
        """Record length in s, ``n_samples * dt_s``."""
        return self.n_samples * self.dt_s

    # -- axes and ranges -----------------------------------------------------------------------
    def _axis_index(self, key) -> int:
        n = self.n_axes
        if isinstance(key, (int, np.integer)) and not isinstance(key, bool):
            if -n <= int(key) < n:
                return int(key) % n
        elif isinstance(key, str):
            k = key.strip()
            if k in self.axis_names:
                return self.axis_names.index(k)
            if k.isdigit() and int(k) < n:
                return int(k)
            folded = [i for i, a in enumerate(self.axis_names) if a.lower() == k.lower()]
            if len(folded) == 1:
                return folded[0]
        raise ConfigError(
            f"unknown axis {key!r}; expected one of {list(self.axis_names)} or an index 0..{n - 1}"
        )

    def axis(self, key) -> np.ndarray:
        """Rate of one axis in deg/h, shape (n_samples,), a read-only view.

        Parameters
        ----------
        key : int or str
            Axis name, or 0-based index (negative counts from the end).

        Raises
        ------
        ConfigError
            If ``key`` names no axis.
        """
        return self.rate_dph[:, self._axis_index(key)]

    def select(self, keys) -> "GyroRecord":
        """Record with a subset of the axes, in the order given.

        Parameters
        ----------
        keys : int, str or sequence of int/str
            Axis names or 0-based indices; a string may list several separated by commas.

        Raises
        ------
        ConfigError
            If a key is unknown, repeated, or no key is given.
        """
        idx = [self._axis_index(k) for k in _split_keys(keys, "keys")]
        if len(set(idx)) != len(idx):
            raise ConfigError(f"keys select an axis twice; expected distinct axes, got {keys!r}")
        return dataclasses.replace(
            self, rate_dph=_take_columns(self.rate_dph, idx), axis_names=tuple(self.axis_names[i] for i in idx)
        )

    def slice(self, start: int, stop: int) -> "GyroRecord":
        """Record of samples ``start .. stop-1`` (Python semantics for negative values).

        ``t0_s`` becomes ``t0_s + start * dt_s``; a note records the range.

        Raises
        ------
        ConfigError
            If the range is empty or outside ``0 .. n_samples``.
        """
        n = self.n_samples
        lo, hi = _int_arg(start, "start"), _int_arg(stop, "stop")
        lo = lo + n if lo < 0 else lo
        hi = hi + n if hi < 0 else hi
        if not 0 <= lo < hi <= n:
            raise ConfigError(
                f"slice({start!r}, {stop!r}) is empty or out of range; expected 0 <= start < stop <= {n}"
            )
        note = f"slice: samples {lo}-{hi - 1} of {n}"
        return dataclasses.replace(
            self, rate_dph=self.rate_dph[lo:hi], t0_s=self.t0_s + lo * self.dt_s, notes=self.notes + (note,)
        )

    def block_average(self, dt_s: float) -> "GyroRecord":
        """Average non-overlapping blocks to the longer sample interval ``dt_s`` (s).

        Parameters
        ----------
        dt_s : float
            Target interval in s; must be an integer multiple ``m`` of ``self.dt_s`` within
            1e-6 relative.  The result has ``dt_s = m * self.dt_s``; the incomplete last
            block is dropped.

        Raises
        ------
        ConfigError
            If ``dt_s`` is not a positive integer multiple (the message suggests the nearest).
        InsufficientDataError
            If the record is shorter than one block.

        Notes
        -----
        ``y_j = (1/m) sum_{k=0}^{m-1} x_{jm+k}``: for rate samples that are averages over their
        interval (integrating gyros, angle increments) this is exactly the average rate over
        the longer interval, so ``t0_s`` is unchanged.
        """
        target = _positive_float(dt_s, "dt_s")
        ratio = target / self.dt_s
        m = int(round(ratio))
        if m < 1 or abs(m * self.dt_s - target) > _MULTIPLE_RTOL * target:
            near = sorted({max(1, math.floor(ratio)), max(1, math.ceil(ratio))})
            hint = " or ".join(f"{k * self.dt_s:.10g} s (x{k})" for k in near)
            raise ConfigError(
                f"block-average interval dt_s={dt_s!r} is not an integer multiple of the sample "
                f"interval {self.dt_s:.10g} s; expected e.g. {hint}, got {ratio:.6g} x dt_s"
            )
        if m == 1:
            return self
        n = self.n_samples
        if n < m:
            raise InsufficientDataError(
                f"block average to {m * self.dt_s:.10g} s needs {m} samples for one block; got {n}",
                needed=m, got=n, path=self.source,
            )
        avg = block_average(self.rate_dph, m)
        dropped = n - avg.shape[0] * m
        note = f"block-averaged x{m} ({self.dt_s:.10g} s -> {m * self.dt_s:.10g} s), dropped {dropped} trailing samples"
        return dataclasses.replace(self, rate_dph=avg, dt_s=m * self.dt_s, notes=self.notes + (note,))

    def metadata(self) -> dict:
        """JSON-serialisable description (no arrays): every field but the data, plus sizes.

        Returns
        -------
        dict
            ``source, input_unit, scale_to_dph, rate_unit ("deg/h"), dt_s, fs_hz, t0_s,
            n_samples, n_axes, duration_s, axis_names (list), notes (list)``.
        """
        return {
            "source": self.source,
            "input_unit": self.input_unit,
            "scale_to_dph": self.scale_to_dph,
            "rate_unit": "deg/h",
            "dt_s": self.dt_s,
            "fs_hz": self.fs_hz,
            "t0_s": self.t0_s,
            "n_samples": self.n_samples,
            "n_axes": self.n_axes,
            "duration_s": self.duration_s,
            "axis_names": list(self.axis_names),
            "notes": list(self.notes),
        }

    def __repr__(self) -> str:
        return (
            f"GyroRecord(n_samples={self.n_samples}, axes={list(self.axis_names)}, dt_s={self.dt_s:.10g}, "
            f"t0_s={self.t0_s:.10g}, input_unit={self.input_unit!r}, source={self.source!r})"
        )


# --------------------------------------------------------------------------------------------
# Public functions
# --------------------------------------------------------------------------------------------
def block_average(x, factor: int) -> np.ndarray:
    """Average non-overlapping blocks of ``factor`` samples along axis 0.

    Parameters
    ----------
    x : array_like, shape (n_samples, ...)
        Samples (any unit).
    factor : int
        Block length m >= 1.

    Returns
    -------
    ndarray, shape (n_samples // factor, ...), float64
        ``y_j = (1/m) sum_{k=0}^{m-1} x_{jm+k}``; the incomplete last block is dropped.

    Raises
    ------
    ConfigError
        If ``factor`` is not an integer >= 1 or ``x`` is 0-D.
    InsufficientDataError
        If ``x`` has fewer than ``factor`` samples.

    Notes
    -----
    Works on memory maps without a full copy: the kept rows are reshaped (a view) to
    ``(n_blocks, m, ...)`` and reduced along the block axis.

    Examples
    --------
    >>> block_average([1.0, 2.0, 3.0, 4.0, 5.0], 2)
    array([1.5, 3.5])
    """
    if isinstance(factor, bool) or not isinstance(factor, (int, np.integer)) or factor < 1:
        raise ConfigError(f"factor must be an integer >= 1; got {factor!r}")
    arr = np.asarray(x)
    if arr.ndim == 0:
        raise ConfigError("x must have at least one dimension (samples along axis 0); got a scalar")
    m = int(factor)
    n = arr.shape[0]
    nb = n // m
    if nb == 0:
        raise InsufficientDataError(
            f"block average needs {m} samples for one block; got {n}", needed=m, got=n
        )
    blocks = arr[: nb * m].reshape((nb, m) + arr.shape[1:])
    return blocks.mean(axis=1, dtype=np.float64)


def file_sha256(path) -> str:
    """Hex SHA-256 of a file's bytes (read in 1 MiB chunks).

    Raises
    ------
    DataFormatError
        If the file does not exist or cannot be read.
    """
    p = _check_path(path)
    h = hashlib.sha256()
    try:
        with open(p, "rb") as fh:
            for chunk in iter(lambda: fh.read(1 << 20), b""):
                h.update(chunk)
    except OSError as exc:
        raise DataFormatError(
            f"cannot read file; expected a readable file, got {exc.strerror or exc}", path=p
        ) from exc
    return h.hexdigest()


def from_array(rate, *, dt_s, unit="deg/h", axis_names=None, source="<array>") -> GyroRecord:
    """Wrap an array of rates (or angle increments) as a :class:`GyroRecord`.

    Parameters
    ----------
    rate : array_like, shape (n_samples,) or (n_samples, n_axes)
        Rates in ``unit``.  A float64 deg/h array is not copied (the record holds a
        read-only view of it).
    dt_s : float
        Sample interval in s (> 0).
    unit : str
        Rate unit from :data:`fogdrift.units.RATE_UNITS` or ``"inc:<angle>"`` for an angle
        increment per sample (``"inc:deg"``, ``"inc:rad"``, ``"inc:arcsec"``).
    axis_names : sequence of str, optional
        Default ``("axis0", "axis1", ...)``.
    source : str
        Where the numbers came from (used in messages).

    Returns
    -------
    GyroRecord

    Raises
    ------
    ConfigError
        Bad ``dt_s``, ``unit`` or ``axis_names``.
    DataFormatError
        Non-numeric data, wrong number of dimensions, or a NaN/inf value (the message gives
        the sample index; ``column`` is the axis name).
    InsufficientDataError
        Zero samples.

    Examples
    --------
    >>> rec = from_array([0.1, 0.1, 0.2], dt_s=0.01, unit="inc:arcsec")
    >>> rec.rate_dph[:, 0]
    array([10., 10., 20.])
    """
    dt = _positive_float(dt_s, "dt_s")
    kind, base = _parse_unit(unit)
    try:
        arr = np.asarray(rate)
        if arr.dtype.kind not in "biuf":
            arr = np.asarray(rate, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise DataFormatError(
            f"rate is not numeric; expected an array of numbers, got {type(rate).__name__}", path=source
        ) from exc
    if arr.ndim == 1:
        arr = arr.reshape(-1, 1)
    if arr.ndim != 2:
        raise DataFormatError(
            f"rate has shape {arr.shape}; expected (n_samples,) or (n_samples, n_axes)", path=source
        )
    if axis_names is None:
        names = [f"axis{j}" for j in range(arr.shape[1])]
    else:
        names = [axis_names] if isinstance(axis_names, str) else [str(a) for a in axis_names]
        if len(names) != arr.shape[1] or len(set(names)) != len(names):
            raise ConfigError(
                f"axis_names must be {arr.shape[1]} unique names (one per column); got {axis_names!r}"
            )
    n = arr.shape[0]
    if n == 0:
        raise InsufficientDataError("rate has 0 samples; expected at least 1", needed=1, got=0, path=source)
    bad = _first_nonfinite(arr)
    if bad is not None:
        i, j = bad
        raise DataFormatError(
            f"non-finite value at sample {i}; expected a finite number, got {float(arr[i, j])!r}",
            path=source, column=names[j],
        )
    scale = _unit_scale(kind, base, dt)
    return GyroRecord(
        rate_dph=_to_dph(arr, scale), dt_s=dt, axis_names=tuple(names), source=str(source),
        input_unit=unit, scale_to_dph=scale,
    )


def load(
    path,
    *,
    columns=None,
    time_column="auto",
    dt_s=None,
    rate_hz=None,
    unit="deg/h",
    delimiter=None,
    gaps="error",
    min_samples=2,
) -> GyroRecord:
    """Load a gyro log into a :class:`GyroRecord` in deg/h.

    Parameters
    ----------
    path : str or Path
        Text (CSV/TXT, optionally gzip), ``.npy`` or ``.npz`` file; the format is detected
        from the first bytes.
    columns : None, int, str or sequence of int/str
        Rate columns: names or 0-based indices (ints or digit strings; a string may list
        several separated by commas, e.g. ``"gx,gz"`` or ``"1,2"``).  Default: every column
        except the time column.  Header-less text and arrays name columns ``col0, col1, ...``.
    time_column : "auto", None, int or str
        ``"auto"`` uses a column named t, t_s, time, time_s or timestamp (any case) if there is
        one; ``None`` means no time column.  Time is in s.
    dt_s, rate_hz : float, optional
        Sample interval in s, or sample rate in Hz.  Required without a time column; with
        one, they must agree with its median step within 1 % and then take precedence.
    unit : str
        Unit of the numbers: a rate unit from :data:`fogdrift.units.RATE_UNITS`
        (``"deg/h"``, ``"deg/s"``, ``"rad/s"``, ``"rad/h"``, ``"arcsec/s"``) or an angle increment
        per sample ``"inc:deg"``, ``"inc:rad"``, ``"inc:arcsec"``.
    delimiter : None or str
        ``None`` detects it from the first non-comment line (tab, comma, semicolon, else
        whitespace); or one of ``","``, ``";"``, ``"\\t"``, ``" "`` (whitespace) or the words
        comma, semicolon, tab, whitespace.
    gaps : {"error", "split"}
        A time step > 1.5 sample intervals is a gap.  ``"error"`` raises, naming the line,
        time and size of the first gap; ``"split"`` returns the longest gap-free segment with
        a :class:`FogdriftWarning` (use :func:`load_segments` to get all of them).
    min_samples : int
        Fewest samples accepted (>= 1).

    Returns
    -------
    GyroRecord
        ``rate_dph`` is a read-only view; for a float64 ``.npy`` in deg/h it is a view of the
        memory map (no copy).

    Raises
    ------
    ConfigError
        Invalid option (unit, dt_s/rate_hz, delimiter, gaps, min_samples), a column selected
        twice, or no way to know the sample interval.
    DataFormatError
        Missing/empty file, header only, non-numeric cell, NaN/inf, ragged row, unsorted or
        duplicate time, gap, unknown column, time column contradicting dt_s/rate_hz.
    InsufficientDataError
        Fewer than ``min_samples`` samples.

    Notes
    -----
    Text is parsed by :func:`numpy.loadtxt`; only if that fails is the file re-read line by
    line to report the exact line and column.  The interval from a time column is the
    median step rounded to 10 significant digits (removes the float noise of decimal time
    stamps: steps of 0.01 s stay 0.01 s).

    Examples
    --------
    >>> import numpy as np, tempfile, os
    >>> d = tempfile.mkdtemp(); p = os.path.join(d, "g.csv")
    >>> with open(p, "w") as fh:
    ...     _ = fh.write("t_s,gx,gy\\n0.00,1,2\\n0.01,3,4\\n0.02,5,6\\n")
    >>> rec = load(p, columns="gy")
    >>> rec.dt_s, rec.axis_names, rec.rate_dph[:, 0].tolist()
    (0.01, ('gy',), [2.0, 4.0, 6.0])
    """
    if gaps not in ("error", "split"):
        raise ConfigError(f"gaps must be 'error' or 'split'; got {gaps!r}")
    records = _load_records(
        path, columns=columns, time_column=time_column, dt_s=dt_s, rate_hz=rate_hz, unit=unit,
        delimiter=delimiter, split=gaps == "split", min_samples=min_samples,
    )
    if len(records) == 1:
        return records[0]
    best = max(records, key=lambda r: r.n_samples)
    warnings.warn(
        f"{path}: data have {len(records)} gap-free segments; returning the longest "
        f"({best.n_samples} of {sum(r.n_samples for r in records)} samples, {best.notes[-1]}); "
        "use load_segments() to get all",
        FogdriftWarning,
        stacklevel=2,
    )
    return best


def load_segments(path, **kwargs) -> list[GyroRecord]:
    """Load a gyro log split at time gaps into gap-free :class:`GyroRecord` segments.

    Takes the keyword arguments of :func:`load`; ``gaps`` defaults to ``"split"`` here
    (``"error"`` raises at the first gap as in :func:`load`).  Each segment's ``t0_s`` is
    its first time stamp and its last note reads
    ``"segment k of m: samples a-b (lines c-d)"`` (sample indices are 0-based data rows of
    the file; lines are physical lines, text only).  Segments shorter than ``min_samples``
    are dropped with a :class:`FogdriftWarning`.

    Returns
    -------
    list of GyroRecord
        In time order; a single element when the data have no gap.

    Raises
    ------
    InsufficientDataError
        If no segment has ``min_samples`` samples.
    """
    gaps = kwargs.pop("gaps", "split")
    if gaps not in ("error", "split"):
        raise ConfigError(f"gaps must be 'error' or 'split'; got {gaps!r}")
    allowed = {"columns", "time_column", "dt_s", "rate_hz", "unit", "delimiter", "min_samples"}
    unknown = sorted(set(kwargs) - allowed)
    if unknown:
        raise ConfigError(f"unknown option(s) {unknown}; expected some of {sorted(allowed | {'gaps'})}")
    return _load_records(path, split=gaps == "split", **kwargs)


# --------------------------------------------------------------------------------------------
# Loading machinery
# --------------------------------------------------------------------------------------------
class _Table:
    """A parsed source: 2-D data (all columns) plus everything needed to locate errors."""

    def __init__(self, path, kind, names, named, data=None, header_line=0, delimiter=None, n_fields=0,
                 is_gz=False):
        self.path = path
        self.kind = kind            # "text", "npy", "npz"
        self.names = names          # list[str], one per column
        self.named = named          # True if names come from the file (header, npz keys)
        self.data = data            # ndarray (n_rows, n_cols) once parsed
        self.header_line = header_line  # physical line of the header (0 = none)
        self.delimiter = delimiter
        self.n_fields = n_fields
        self.is_gz = is_gz
        self.line_numbers = None    # physical line of each data row (text, computed lazily)

    def delimiter_name(self):
        return _DELIM_NAMES.get(self.delimiter, repr(self.delimiter))

    def label(self, j):
        """Column label for error locations: name, or 1-based field number in header-less text."""
        if self.kind == "text" and not self.named:
            return j + 1
        return self.names[j]

    def line_of(self, i):
        if self.kind != "text":
            return None
        if self.line_numbers is None:
            self.line_numbers = _text_line_numbers(self)
        return int(self.line_numbers[i])

    def at(self, i):
        """Phrase locating row ``i`` inside a message ("" for text: the line says it)."""
        return "" if self.kind == "text" else f" at sample {i}"

    def row_ref(self, i):
        return f"line {self.line_of(i)}" if self.kind == "text" else f"sample {i}"

    def error(self, message, row=None, col=None):
        return DataFormatError(
            message, path=self.path,
            line=None if row is None else self.line_of(row),
            column=None if col is None else self.label(col),
        )


def _load_records(path, *, columns=None, time_column="auto", dt_s=None, rate_hz=None, unit="deg/h",
                  delimiter=None, split=False, min_samples=2) -> list[GyroRecord]:
    # 1. options, before touching the file
    kind_u, base_u = _parse_unit(unit)
    dt_user = _interval_option(dt_s, rate_hz)
    delim = _delimiter_option(delimiter)
    if isinstance(min_samples, bool) or not isinstance(min_samples, (int, np.integer)) or min_samples < 1:
        raise ConfigError(f"min_samples must be an integer >= 1; got {min_samples!r}")
    min_samples = int(min_samples)

    # 2. open and describe the source, resolve columns (before parsing any data)
    p = _check_path(path)
    table = _open_source(p, delim)
    t_idx, r_idx = _resolve_columns(table, columns, time_column)
    if t_idx is None and dt_user is None:
        raise ConfigError(
            f"{p}: cannot tell the sample interval: no time column (none named "
            f"{' / '.join(TIME_COLUMN_NAMES)}; or pass time_column=) and neither dt_s nor rate_hz was given; "
            "expected dt_s=<seconds> or rate_hz=<hertz>"
        )
    if table.kind == "text":
        _parse_text(table, used=[j for j in [t_idx, *r_idx] if j is not None])
    data = table.data
    n = data.shape[0]
    if n == 0:
        if table.kind == "text" and table.header_line:
            raise DataFormatError(
                f"no data rows after the header on line {table.header_line}; expected at least one "
                "numeric row, got only the header", path=p,
            )
        raise DataFormatError("no data; expected at least one sample, got an empty table", path=p)

    # 3. values: finite in every used column
    used = [j for j in [t_idx, *r_idx] if j is not None]
    bad = _first_nonfinite(data, used)
    if bad is not None:
        i, j = bad
        raise table.error(
            f"non-finite value{table.at(i)}; expected a finite number, got {float(data[i, j])!r}", row=i, col=j
        )

    # 4. sample interval and segments
    notes = [_describe_source(table, n)]
    t = None
    if t_idx is not None:
        t = np.asarray(data[:, t_idx], dtype=np.float64)
        if n < 2 and dt_user is None:
            raise InsufficientDataError(
                f"{n} sample; expected at least 2 to take the sample interval from time column "
                f"{table.names[t_idx]!r}", needed=2, got=n, path=p,
            )
        dt, seg_bounds, gap_info = _check_time(table, t, t_idx, dt_user, split)
        tname = table.names[t_idx]
        if dt_user is None:
            notes.append(f"dt_s {dt:.10g} from the median step of time column {tname!r}")
        else:
            notes.append(f"dt_s {dt:.10g} from dt_s/rate_hz (time column {tname!r} agrees within 1 %)")
    else:
        dt, seg_bounds, gap_info = dt_user, [(0, n)], []
        notes.append(f"dt_s {dt:.10g} from dt_s/rate_hz (no time column)")
    scale = _unit_scale(kind_u, base_u, dt)
    if scale != 1.0:
        notes.append(f"input unit {unit!r} scaled by {scale:.10g} to deg/h")

    # 5. records
    m = len(seg_bounds)
    if m == 1 and n < min_samples:
        raise InsufficientDataError(
            f"{n} samples; expected at least min_samples={min_samples}", needed=min_samples, got=n, path=p
        )
    names = tuple(table.names[j] for j in r_idx)
    records, dropped = [], []
    for k, (a, b) in enumerate(seg_bounds, start=1):
        seg_notes = list(notes)
        if m > 1:
            where = f"samples {a}-{b - 1}"
            if table.kind == "text":
                where += f" (lines {table.line_of(a)}-{table.line_of(b - 1)})"
            if k > 1:
                where += f", after a gap of {gap_info[k - 2]:.6g} s"
            seg_notes.append(f"segment {k} of {m}: {where}")
            if b - a < min_samples:
                dropped.append(f"segment {k} ({where}, {b - a} samples)")
                continue
        rate = _to_dph(_take_columns(data[a:b], r_idx), scale)
        t0 = float(t[a]) if t is not None else 0.0
        records.append(GyroRecord(
            rate_dph=rate, dt_s=dt, axis_names=names, source=str(p), input_unit=unit,
            scale_to_dph=scale, t0_s=t0, notes=tuple(seg_notes),
        ))
    if dropped:
        if not records:
            longest = max(b - a for a, b in seg_bounds)
            raise InsufficientDataError(
                f"all {m} gap-free segments are shorter than min_samples={min_samples}; longest has {longest}",
                needed=min_samples, got=longest, path=p,
            )
        warnings.warn(
            f"{p}: dropped {len(dropped)} segment(s) shorter than min_samples={min_samples}: "
            + "; ".join(dropped), FogdriftWarning, stacklevel=3,
        )
    return records


def _check_path(path) -> Path:
    if not isinstance(path, (str, Path)) and not hasattr(path, "__fspath__"):
        raise ConfigError(f"path must be a str or Path; got {type(path).__name__}")
    p = Path(path)
    if not p.exists():
        raise DataFormatError("file not found; expected an existing file, got no such path", path=p)
    if not p.is_file():
        raise DataFormatError("not a regular file; expected a data file, got a directory or device", path=p)
    return p


def _open_source(p: Path, delim) -> _Table:
    try:
        with open(p, "rb") as fh:
            magic = fh.read(6)
    except OSError as exc:
        raise DataFormatError(
            f"cannot read file; expected a readable file, got {exc.strerror or exc}", path=p
        ) from exc
    if magic.startswith(b"\x93NUMPY"):
        return _open_npy(p)
    if magic.startswith(b"PK\x03\x04") or magic.startswith(b"PK\x05\x06"):
        return _open_npz(p)
    return _open_text(p, delim, is_gz=magic.startswith(b"\x1f\x8b"))


def _numeric_array(arr, p, what):
    if arr.dtype.kind not in "biuf":
        raise DataFormatError(
            f"{what} has dtype {arr.dtype}; expected a real numeric dtype, got {arr.dtype}", path=p
        )
    if arr.dtype != np.float64:
        arr = np.asarray(arr, dtype=np.float64)  # copy: only float64 arrays are used in place
    return arr


def _open_npy(p: Path) -> _Table:
    try:
        arr = np.load(p, mmap_mode="r", allow_pickle=False)
    except (ValueError, OSError, EOFError) as exc:
        raise DataFormatError(f"unreadable .npy file; expected a numeric NumPy array, got error: {exc}", path=p) from exc
    if arr.ndim not in (1, 2):
        raise DataFormatError(
            f"array has shape {arr.shape}; expected 1-D (one axis) or 2-D (samples x columns)", path=p
        )
    arr = _numeric_array(arr, p, "array")
    if arr.ndim == 1:
        arr = arr.reshape(-1, 1)
    return _Table(p, "npy", [f"col{j}" for j in range(arr.shape[1])], named=False, data=arr)


def _open_npz(p: Path) -> _Table:
    try:
        with np.load(p, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
    except (ValueError, OSError, EOFError, zlib.error, zipfile.BadZipFile) as exc:
        raise DataFormatError(f"unreadable .npz file; expected NumPy arrays, got error: {exc}", path=p) from exc
    if not arrays:
        raise DataFormatError("no arrays in .npz file; expected at least one, got none", path=p)
    if len(arrays) == 1:
        (key, arr), = arrays.items()
        if arr.ndim == 2:
            arr = _numeric_array(arr, p, f"array {key!r}")
            return _Table(p, "npz", [f"col{j}" for j in range(arr.shape[1])], named=False, data=arr)
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
        cols.append(_numeric_array(arr, p, f"array {key!r}"))
    return _Table(p, "npz", list(arrays), named=True, data=np.column_stack(cols))


def _text_stream(p: Path, is_gz: bool):
    raw = io.BufferedReader(gzip.open(p, "rb"), 1 << 20) if is_gz else open(p, "rb")
    return io.TextIOWrapper(raw, encoding="utf-8-sig", errors="replace")


def _strip_comment(line: str) -> str:
    cut = len(line)
    for c in _COMMENT_CHARS:
        k = line.find(c)
        if k != -1 and k < cut:
            cut = k
    return line[:cut].strip()


def _split(line: str, delim):
    return line.split() if delim is None else line.split(delim)


def _is_number(s: str) -> bool:
    try:
        float(s)
    except ValueError:
        return False
    return True


def _open_text(p: Path, delim, *, is_gz: bool) -> _Table:
    """Read the first two non-comment lines: delimiter, header and number of fields."""
    content, first_lineno, lineno = [], 0, 0
    try:
        with _text_stream(p, is_gz) as fh:
            for lineno, raw in enumerate(fh, start=1):
                s = _strip_comment(raw)
                if s:
                    content.append(s)
                    first_lineno = first_lineno or lineno
                    if len(content) == 2:
                        break
    except (OSError, EOFError, zlib.error) as exc:
        raise DataFormatError(f"unreadable file; expected text or gzip text, got error: {exc}", path=p) from exc
    if not content:
        raise DataFormatError(
            "empty file; expected a header and/or numeric data rows, got no content "
            "(only blank or comment lines)" if lineno else "empty file; expected data, got 0 bytes", path=p,
        )
    first = content[0]
    if delim == "auto":
        delim, is_header = _detect_layout(first, content[1] if len(content) > 1 else None)
    else:
        is_header = not all(_is_number(f) for f in _split(first, delim))
    fields = [f.strip() for f in _split(first, delim)]
    if is_header:
        names = [f.strip("\"'").strip() or f"col{j}" for j, f in enumerate(fields)]
        dup = next((a for j, a in enumerate(names) if a in names[:j]), None)
        if dup is not None:
            raise DataFormatError(
                f"duplicate column name in header; expected unique names, got {dup!r} twice",
                path=p, line=first_lineno, column=dup,
            )
        return _Table(p, "text", names, named=True, header_line=first_lineno, delimiter=delim,
                      n_fields=len(fields), is_gz=is_gz)
    return _Table(p, "text", [f"col{j}" for j in range(len(fields))], named=False, header_line=0,
                  delimiter=delim, n_fields=len(fields), is_gz=is_gz)


def _detect_layout(first: str, second):
    """(delimiter, first line is a header) from the first two content lines.

    A delimiter fits a data line when it splits it into numbers only; candidates are tab,
    comma and semicolon (if present), then whitespace.  If the first line fits no candidate
    it is a header, and the delimiter is the one that fits the second line with as many
    fields as the header; failing that, the most frequent of tab/comma/semicolon.
    """
    def candidates(line):
        return [d for d in ("\t", ",", ";") if d in line] + [None]

    for d in candidates(first):
        if all(_is_number(f) for f in _split(first, d)):
            return d, False
    if second is not None:
        for d in candidates(second):
            fields = _split(second, d)
            if all(_is_number(f) for f in fields) and len(_split(first, d)) == len(fields):
                return d, True
    counts = {c: first.count(c) for c in ("\t", ",", ";")}
    best = max(counts, key=counts.get)
    return (best if counts[best] else None), True


def _parse_text(table: _Table, used) -> None:
    """Fast path: numpy.loadtxt over all columns; on any failure re-scan line by line.

    loadtxt runs first with the single comment character ``#`` (handled in C); only if that
    fails is it retried with ``#`` and ``%`` (handled per line in Python, ~4x slower).
    """
    for comments in ("#", list(_COMMENT_CHARS)):
        try:
            with _text_stream(table.path, table.is_gz) as fh, warnings.catch_warnings():
                warnings.simplefilter("ignore", UserWarning)  # "input contained no data"
                data = np.loadtxt(
                    fh, dtype=np.float64, delimiter=table.delimiter, comments=comments,
                    skiprows=table.header_line, ndmin=2,
                )
        except (ValueError, OSError, EOFError, zlib.error):
            continue
        if data.shape[0] == 0 or data.shape[1] == table.n_fields:
            table.data = data if data.shape[0] else np.empty((0, table.n_fields))
            return
    table.data, table.line_numbers = _scan_text(table, set(used))


def _scan_text(table: _Table, used: set):
    """Slow path: parse line by line and raise at the first bad line/column.

    Cells that are not numbers are an error only in used columns; elsewhere they become NaN.
    """
    rows, lines = [], []
    nf = table.n_fields
    try:
        with _text_stream(table.path, table.is_gz) as fh:
            for lineno, raw in enumerate(fh, start=1):
                if lineno <= table.header_line:
                    continue
                s = _strip_comment(raw)
                if not s:
                    continue
                fields = _split(s, table.delimiter)
                if len(fields) != nf:
                    if table.named:
                        rule = f"{nf} fields as in the header on line {table.header_line}"
                    else:
                        rule = f"{nf} fields as in the first data row (line {lines[0] if lines else lineno})"
                    j = min(len(fields), nf)
                    col = table.label(j) if j < nf else j + 1
                    raise DataFormatError(
                        f"wrong number of fields ({table.delimiter_name()}-separated); expected {rule}, "
                        f"got {len(fields)}", path=table.path, line=lineno, column=col,
                    )
                row = []
                for j, f in enumerate(fields):
                    try:
                        row.append(float(f))
                    except ValueError:
                        if j in used:
                            raise DataFormatError(
                                f"non-numeric value; expected a number, got {f.strip()!r}",
                                path=table.path, line=lineno, column=table.label(j),
                            ) from None
                        row.append(math.nan)
                rows.append(row)
                lines.append(lineno)
    except (OSError, EOFError, zlib.error) as exc:
        raise DataFormatError(f"unreadable file; expected text or gzip text, got error: {exc}",
                              path=table.path) from exc
    data = np.array(rows, dtype=np.float64).reshape(len(rows), nf)
    return data, np.asarray(lines, dtype=np.int64)


def _text_line_numbers(table: _Table) -> np.ndarray:
    """Physical line number of every data row (used only to locate errors and segments)."""
    lines = []
    with _text_stream(table.path, table.is_gz) as fh:
        for lineno, raw in enumerate(fh, start=1):
            if lineno > table.header_line and _strip_comment(raw):
                lines.append(lineno)
    return np.asarray(lines, dtype=np.int64)


def _describe_source(table: _Table, n: int) -> str:
    if table.kind == "text":
        head = f"header on line {table.header_line}" if table.header_line else "no header"
        gz = "gzip " if table.is_gz else ""
        return f"{gz}text, {table.delimiter_name()}-separated, {head}, {n} data rows"
    return f"{table.kind} array, {n} samples x {len(table.names)} columns"


def _resolve_columns(table: _Table, columns, time_column):
    names = table.names
    ncol = len(names)

    def resolve(key):
        if isinstance(key, (int, np.integer)) and not isinstance(key, bool):
            if -ncol <= int(key) < ncol:
                return int(key) % ncol
        elif isinstance(key, str):
            k = key.strip()
            hits = [j for j, a in enumerate(names) if a == k]
            if not hits and k.isdigit() and int(k) < ncol:
                return int(k)
            if not hits:
                hits = [j for j, a in enumerate(names) if a.lower() == k.lower()]
            if len(hits) == 1:
                return hits[0]
            if len(hits) > 1:
                raise DataFormatError(
                    f"column name {key!r} is ambiguous; expected a unique name or an index, "
                    f"got columns {hits}", path=table.path, column=key,
                )
        raise DataFormatError(
            f"unknown column {key!r}; expected one of {names} or an index 0..{ncol - 1}, got {key!r}",
            path=table.path, column=key,
        )

    if time_column is None:
        t_idx = None
    elif isinstance(time_column, str) and time_column.strip().lower() == "auto":
        t_idx = None
        if table.named:
            for j, a in enumerate(names):
                if a.lower() in TIME_COLUMN_NAMES:
                    t_idx = j
                    break
    else:
        t_idx = resolve(time_column)

    if columns is None:
        r_idx = [j for j in range(ncol) if j != t_idx]
    else:
        keys = _split_keys(columns, "columns")
        r_idx = [resolve(k) for k in keys]
        if len(set(r_idx)) != len(r_idx):
            raise ConfigError(f"columns selects a column twice; expected distinct columns, got {columns!r}")
        if t_idx is not None and t_idx in r_idx:
            raise ConfigError(
                f"column {names[t_idx]!r} is the time column; expected rate columns only in columns=, "
                f"got {columns!r} (pass time_column=None to read it as data)"
            )
    if not r_idx:
        raise DataFormatError(
            f"no rate columns; expected at least one column besides the time column, got {names}",
            path=table.path,
        )
    return t_idx, r_idx


def _check_time(table: _Table, t: np.ndarray, t_idx: int, dt_user, split: bool):
    """Validate the time column; return (dt_s, [(start, stop) segments], [gap sizes in s])."""
    n = t.shape[0]
    if n < 2:
        return dt_user, [(0, n)], []
    steps = np.diff(t)
    nonpos = steps <= 0
    if nonpos.any():

        i = int(np.argmax(nonpos)) + 1
        if steps[i - 1] == 0:
            msg = (f"duplicate timestamp{table.at(i)}; expected strictly increasing time, "
                   f"got {float(t[i])!r} s again (as on {table.row_ref(i - 1)})")
        else:
            msg = (f"time goes backwards{table.at(i)}; expected strictly increasing time, "
                   f"got {float(t[i])!r} s after {float(t[i - 1])!r} s on {table.row_ref(i - 1)}")
        raise table.error(msg, row=i, col=t_idx)
    dt_time = float(f"{float(np.median(steps)):.10g}")
    if dt_user is None:
        dt = dt_time
    else:
        rel = abs(dt_time - dt_user) / dt_user
        if rel > DT_TOLERANCE:
            raise table.error(
                f"time column disagrees with dt_s/rate_hz; expected a median step within 1 % of "
                f"{dt_user:.10g} s ({1 / dt_user:.10g} Hz), got {dt_time:.10g} s ({rel:.1%} off)", col=t_idx,
            )
        dt = dt_user
    gap_rows = np.flatnonzero(steps > GAP_FACTOR * dt) + 1
    if gap_rows.size == 0:
        return dt, [(0, n)], []
    if not split:
        i = int(gap_rows[0])
        g = float(steps[i - 1])
        raise table.error(
            f"gap in time{table.at(i)} of {g:.6g} s ({g / dt:.4g} sample intervals) between t={float(t[i - 1])!r} s "
            f"and t={float(t[i])!r} s ({gap_rows.size} gap(s) in total; use load_segments() or gaps='split'); "
            f"expected steps of at most {GAP_FACTOR} x {dt:.10g} s, got {g:.6g} s",
            row=i, col=t_idx,
        )
    starts = [0, *gap_rows.tolist()]
    stops = [*gap_rows.tolist(), n]
    return dt, list(zip(starts, stops)), [float(steps[i - 1]) for i in gap_rows]


# --------------------------------------------------------------------------------------------
# Small helpers
# --------------------------------------------------------------------------------------------
def _positive_float(value, name: str) -> float:
    if isinstance(value, bool):
        raise ConfigError(f"{name} must be a number > 0; got {value!r}")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ConfigError(f"{name} must be a number > 0; got {value!r}") from None
    if not math.isfinite(v) or v <= 0:
        raise ConfigError(f"{name} must be a finite number > 0; got {value!r}")
    return v


def _int_arg(value, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise ConfigError(f"{name} must be an integer; got {value!r}")
    return int(value)


def _interval_option(dt_s, rate_hz):
    dt = None if dt_s is None else _positive_float(dt_s, "dt_s")
    fs = None if rate_hz is None else _positive_float(rate_hz, "rate_hz")
    if dt is not None and fs is not None and abs(dt * fs - 1.0) > 1e-6:
        raise ConfigError(
            f"dt_s and rate_hz disagree; expected dt_s = 1/rate_hz, got dt_s={dt_s!r}, rate_hz={rate_hz!r}"
        )
    if dt is not None:
        return dt
    return None if fs is None else 1.0 / fs


def _delimiter_option(delimiter):
    if delimiter is None:
        return "auto"
    if isinstance(delimiter, str) and delimiter.lower() in _DELIMITERS:
        return _DELIMITERS[delimiter.lower()]
    raise ConfigError(
        f"delimiter must be None (auto) or one of {sorted(repr(k) for k in _DELIMITERS)}; got {delimiter!r}"
    )


def _parse_unit(unit):
    """Return ("rate", name) or ("inc", angle unit); ConfigError listing the valid units."""
    if isinstance(unit, str):
        u = unit.strip()
        if u in units.RATE_UNITS:
            return "rate", u
        if u.startswith("inc:") and u[4:].strip() in units.INCREMENT_UNITS:
            return "inc", u[4:].strip()
    valid = list(units.RATE_UNITS) + [f"inc:{k}" for k in units.INCREMENT_UNITS]
    raise ConfigError(
        f"unknown unit {unit!r}; expected a rate unit or an angle increment per sample, one of {valid}"
    )


def _unit_scale(kind: str, base: str, dt_s: float) -> float:
    if kind == "rate":
        return units.rate_scale_to_dph(base)
    return units.increment_scale_to_dph(base, dt_s)


def _split_keys(keys, name: str) -> list:
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
    if not out or any(k == "" for k in out):
        raise ConfigError(f"{name} must list at least one non-empty name or index; got {keys!r}")
    return out


def _take_columns(a: np.ndarray, idx) -> np.ndarray:
    """Columns ``idx`` of 2-D ``a``: a view when they are consecutive, else a copy."""
    idx = list(idx)
    if idx == list(range(idx[0], idx[0] + len(idx))):
        return a[:, idx[0]: idx[0] + len(idx)]
    return a[:, idx]


def _to_dph(a: np.ndarray, scale: float) -> np.ndarray:
    """float64 rates in deg/h: no copy when ``a`` is float64 already and ``scale == 1``."""
    if scale == 1.0 and a.dtype == np.float64:
        return a
    return np.multiply(a, scale, dtype=np.float64)


def _first_nonfinite(a: np.ndarray, cols=None):
    """(row, col) of the first NaN/inf in ``a[:, cols]`` (row-major order), or None.

    Scans in chunks of rows so that memory-mapped arrays need no full-size temporary.
    """
    cols = list(range(a.shape[1])) if cols is None else list(cols)
    if not cols:
        return None
    contiguous = cols == list(range(cols[0], cols[0] + len(cols)))
    for start in range(0, a.shape[0], _CHUNK_ROWS):
        block = a[start: start + _CHUNK_ROWS]
        block = block[:, cols[0]: cols[0] + len(cols)] if contiguous else block[:, cols]
        ok = np.isfinite(block)
        if not ok.all():
            r, c = np.argwhere(~ok)[0]
            return start + int(r), cols[int(c)]
    return None
