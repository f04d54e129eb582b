"""The reader interface: :class:`Table`, what every format module hands to :func:`fogdrift.io.load`.

A reader module defines one function::

    def open_table(path: Path, **options) -> Table

``options`` are the reader options its registry line declares (``delimiter`` for text; later
``dataset``, ``topic``, ``layout``...).  ``open_table`` reads as little as it needs to name the
columns (a header, an array header); :meth:`Table.read` delivers the numbers.  Everything
else (choosing columns, time checks, gaps, units, the record) is :mod:`fogdrift.io.load`'s job
and the same for every format.
"""

from __future__ import annotations

import importlib
import re
import zipfile
import zlib
from pathlib import Path

import numpy as np

from ...errors import ConfigError, DataFormatError, ResourceError
from .limits import check_columns

__all__ = ["Table", "split_unit_label", "numeric_column", "describe_exception", "PARSER_ERRORS",
           "require", "MissingDependencyError"]

#: What third-party parsers (numpy.load, zipfile, gzip) raise on corrupt bytes; readers turn
#: these into a DataFormatError naming the file.  RuntimeError covers zipfile's "encrypted"
#: and NotImplementedError ("compression method not supported"); OverflowError and
#: MemoryError come from absurd shapes in array headers.
PARSER_ERRORS = (ValueError, TypeError, KeyError, OSError, EOFError, OverflowError, MemoryError, RuntimeError,
                 zlib.error, zipfile.BadZipFile)

_UNIT_LABEL = re.compile(r"^(?P<name>.*?)\s*\[\s*(?P<unit>[^\[\]]*?)\s*\]$")


class MissingDependencyError(ConfigError):
    """A reader's optional dependency is not installed; the message names the extra to install."""


def require(module: str, extra: str, what: str):
    """Import ``module`` for a reader, or raise :class:`MissingDependencyError` naming the extra.

    Parameters
    ----------
    module : str
        Module to import (``"h5py"``, ``"rosbags.highlevel"``).
    extra : str
        The fogdrift extra that installs it (``"hdf5"``, ``"ros"``, ``"seismo"``, ``"fleet"``).
    what : str
        What needs it, for the message (``"reading HDF5 files"``).

    Examples
    --------
    >>> require("math", "none", "arithmetic").sqrt(4.0)
    2.0
    >>> require("no_such_module_xyz", "hdf5", "reading HDF5 files")
    Traceback (most recent call last):
    ...
    fogdrift.io.readers.base.MissingDependencyError: reading HDF5 files needs the Python package 'no_such_module_xyz', which is not installed; install it with: pip install 'fogdrift[hdf5]'
    """
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        if "failed to map segment" in str(exc) or isinstance(exc.__cause__ or exc.__context__, MemoryError):
            raise ResourceError(  # installed, but its shared library does not fit under a memory limit
                f"{what} needs the Python package {module.split('.')[0]!r}, which is installed but could not be "
                f"loaded: out of memory ({describe_exception(exc)}); run it with more memory (a process limit: "
                "ulimit -v)") from exc
        raise MissingDependencyError(
            f"{what} needs the Python package {module.split('.')[0]!r}, which is not installed; "
            f"install it with: pip install 'fogdrift[{extra}]'"
        ) from exc


def split_unit_label(label: str) -> tuple[str, str | None]:
    """Split a column label ``name[unit]`` into ``(name, unit)``; ``(label, None)`` without brackets.

    The convention for files that carry units in their column names (text headers):
    ``gz[deg/s]``, ``t[ms]``, ``gyro x [rad/s]``.  Spaces around the brackets are dropped;
    empty brackets declare no unit.

    Examples
    --------
    >>> split_unit_label("gz[deg/s]")
    ('gz', 'deg/s')
    >>> split_unit_label("gyro x [inc:arcsec]")
    ('gyro x', 'inc:arcsec')
    >>> split_unit_label("time_s")
    ('time_s', None)
    """
    label = label.strip()
    m = _UNIT_LABEL.match(label)
    if m is None:
        return label, None
    return m.group("name"), (m.group("unit") or None)


def describe_exception(exc: BaseException) -> str:
    """``"<Type>: <message>"`` of a parser's exception on one line (for ``got ...`` in messages)."""
    return " ".join(f"{type(exc).__name__}: {exc}".split())


def numeric_column(arr: np.ndarray, path, what: str, column=None) -> np.ndarray:
    """``arr`` as float64 (a copy only if it is not float64 already); DataFormatError for non-numeric dtypes."""
    if arr.dtype.kind not in "biuf":
        raise DataFormatError(
            f"{what} has dtype {arr.dtype}; expected a real numeric dtype, got {arr.dtype}", path=path, column=column
        )
    if arr.dtype != np.float64:
        arr = np.asarray(arr, dtype=np.float64)
    return arr


class Table:
    """Named numeric columns read from one file, and how to locate a sample in it.

    Parameters
    ----------
    path : Path
        The file (or directory, for directory formats).
    names : sequence of str
        One unique name per column.
    named : bool
        True if the names come from the file (header, array keys); False for generated
        names ``col0, col1, ...``.
    units : sequence of (str or None), optional
        Unit each column declares in the file, as written (None: not declared).  Rate units
        are checked by :func:`fogdrift.io.load` only for the columns it uses.
    data : ndarray, shape (n_rows, n_columns), optional
        The numbers, if the reader has them at open time (arrays).  Keep it a view of a
        memory map when the file allows: :func:`fogdrift.io.load` copies only the columns
        it converts.
    time_s : ndarray, shape (n_rows,), optional
        Time in s that the format itself provides (message stamps, start time + rate), when
        time is not one of the columns.  ``time_column="auto"`` uses it.
    sha256 : str, optional
        Hex SHA-256 of the file bytes, set by the reader once it has read them all.
    format : str, optional
        Format name for messages and notes (default: the class attribute, ``"table"``).

    Notes
    -----
    Subclasses override :meth:`read` (parse on demand, e.g. only the used columns of a text
    file), :meth:`line_of` (text: physical line of a data row), :meth:`label` and
    :meth:`describe`.  ``row_kind`` names a row in messages ("sample"; "message" for a bag,
    "record" for raw binary).

    Optional attributes a reader may set after construction:

    ``time_ticks`` : ndarray of int64, shape (n_rows,)
        Sample counts from a sequence counter (raw binary): the time of row ``i`` is
        ``time_ticks[i] * dt_s`` once the sample interval is known, so a counter jump is a gap
        handled like a time gap.  Used when there is no time column and no ``time_s``;
        ``tick_column`` (the counter's column index) locates time errors found on it.
    ``non_rate`` : set of str
        Columns never taken as rate data by default (a sequence counter).
    ``unit_hint`` : str or None
        How to supply the rate unit in this format when neither the caller nor the file gives
        one: :func:`fogdrift.io.load` never guesses it and raises a ConfigError with this text
        (instead of the text reader's "declare it in the header" advice).
    ``extra_notes`` : list of str
        Provenance for the record's notes (absolute start time, gain used, ...).
    """

    format = "table"
    row_kind = "sample"
    #: Physical line of a header that names the columns (text), 0 if none: locates unit errors.
    header_line = 0

    def __init__(self, path, *, names, named=True, units=None, data=None, time_s=None, sha256=None, format=None):
        if format is not None:
            self.format = str(format)
        self.path = Path(path)
        names = list(names)
        check_columns(len(names), self.path, n_rows=None if data is None or np.ndim(data) != 2 else data.shape[0])
        self.names = [str(n) for n in names]
        self.named = bool(named)
        self.units = list(units) if units is not None else [None] * len(self.names)
        self.data = data
        self.time_s = time_s
        self.sha256 = sha256
        self.time_ticks = None
        self.tick_column = None
        self.non_rate = set()
        self.unit_hint = None
        self.extra_notes = []
        if len(self.units) != len(self.names):
            raise ValueError(f"reader bug: {len(self.units)} units for {len(self.names)} columns")
        if len(set(self.names)) != len(self.names):
            seen: set = set()
            dup = next(a for a in self.names if a in seen or seen.add(a))
            raise DataFormatError(
                f"duplicate column name; expected unique names, got {dup!r} twice", path=self.path, column=dup
            )

    # -- the numbers ---------------------------------------------------------------------------
    def read(self, used) -> np.ndarray:
        """All rows as a 2-D array ``(n_rows, n_columns)``; the columns in ``used`` are valid numbers.

        Parameters
        ----------
        used : sequence of int
            Columns the caller will use (time and rate columns).  Cells of other columns
            may be NaN if they do not parse.  NaN/inf in used columns are returned as they
            are (the caller locates them).

        Raises
        ------
        DataFormatError
            If a used cell is not a number (located by line/column or sample index).
        """
        return self.data

    # -- locating ------------------------------------------------------------------------------
    def line_of(self, row: int) -> int | None:
        """Physical line of data row ``row`` (text formats), else None."""
        return None

    def label(self, col: int):
        """Column label for error locations (the name; header-less text: the 1-based field number)."""
        return self.names[col]

    def at(self, row: int) -> str:
        """Phrase that locates ``row`` inside a message: ``" at sample 12"``, or "" where a line number does."""
        return "" if self.line_of(row) is not None else f" at {self.row_kind} {row}"

    def row_ref(self, row: int) -> str:
        """``"line 7"`` or ``"sample 6"``: a row named in the middle of a message."""
        line = self.line_of(row)
        return f"line {line}" if line is not None else f"{self.row_kind} {row}"

    def error(self, message: str, row: int | None = None, col: int | None = None) -> DataFormatError:
        """DataFormatError at ``row`` (data row index) and ``col`` (column index) of this table."""
        return DataFormatError(
            message, path=self.path,
            line=None if row is None else self.line_of(row),
            column=None if col is None else self.label(col),
        )

    def describe(self, n_rows: int) -> str:
        """One line for the record's notes, e.g. ``"npy array, 1000 samples x 3 columns"``."""
        return f"{self.format} array, {n_rows} {self.row_kind}s x {len(self.names)} columns"
