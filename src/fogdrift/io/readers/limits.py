"""Reading limits: what a small hostile file may cost before it is refused (rows, line length, decompression, memory).

A 2 MB ``.csv.gz`` can hold 2 GB of NUL bytes, one 2 GiB line or 300 million rows; a 4 MB ``.npz`` can declare
a 4 GiB member.  The readers check these limits *while* they stream (text) or *before* they decompress (zip
members, HDF5/MATLAB arrays), and refuse the file with one :class:`~fogdrift.errors.ResourceLimitError` that names
the file, the limit and the environment variable that raises it:

===========================  ==============================================================  ======================
Environment variable         Limit                                                           Default
===========================  ==============================================================  ======================
``FOGDRIFT_MAX_LINE_BYTES``  bytes in one line of a text file                                1048576 (1 MiB)
``FOGDRIFT_MAX_ROWS``        lines of a text file, rows of an array, raw binary records      1000000000
``FOGDRIFT_MAX_EXPANSION``   decompressed bytes per stored byte (gzip text, ``.npz``           50
                             members, HDF5/MATLAB arrays), beyond the first 16 MiB
``FOGDRIFT_MAX_MEMORY``      bytes of the float64 table a reader builds (``2G``, ``512M``);    half the machine's
                             and a command's estimated peak for the record it read             memory (or of the
                             (:mod:`fogdrift.io.readers.command_memory`)                       process's RLIMIT_AS)
``FOGDRIFT_MAX_COLUMNS``     columns of a table: text fields, array columns, ``.npz``          1024
                             members, datasets (each a possible axis)
``FOGDRIFT_MAX_PREAMBLE``    bytes of comment or blank lines before a text file's header       16 MiB
                             and first data row
===========================  ==============================================================  ======================

A memory-mapped float64 ``.npy`` costs no memory and is not held to the budget (another dtype's float64 copy is;
so is the float64 copy of a raw binary file's used fields).  Real gyro logs compress 2-10 times (the bundled RLG
log: 5.5); set a variable to ``0`` to switch that limit off.
"""

from __future__ import annotations

import io
import math
import os
import re

import numpy as np

from ...errors import ConfigError, DataFormatError, ResourceLimitError

__all__ = ["ENV_LINE", "ENV_ROWS", "ENV_EXPANSION", "ENV_MEMORY", "EXPANSION_FLOOR", "max_line_bytes", "max_rows",
           "max_expansion", "memory_budget", "check_rows", "check_memory", "check_expansion", "format_bytes",
           "GuardedStream", "ENV_COLUMNS", "ENV_PREAMBLE", "max_columns", "max_preamble_bytes", "check_columns"]

ENV_LINE = "FOGDRIFT_MAX_LINE_BYTES"
ENV_ROWS = "FOGDRIFT_MAX_ROWS"
ENV_EXPANSION = "FOGDRIFT_MAX_EXPANSION"
ENV_MEMORY = "FOGDRIFT_MAX_MEMORY"
ENV_COLUMNS = "FOGDRIFT_MAX_COLUMNS"
ENV_PREAMBLE = "FOGDRIFT_MAX_PREAMBLE"

DEFAULT_LINE_BYTES = 1 << 20
DEFAULT_ROWS = 1_000_000_000
DEFAULT_EXPANSION = 50.0
DEFAULT_COLUMNS = 1024
DEFAULT_PREAMBLE = 16 << 20
#: Decompressed bytes always allowed, whatever the ratio (a small, very compressible file is harmless).
EXPANSION_FLOOR = 16 << 20

_SIZE = re.compile(r"^\s*([0-9]*\.?[0-9]+(?:[eE][+-]?[0-9]+)?)\s*([kKmMgGtT]?)(i?[bB])?\s*$")
_SCALE = {"": 1, "k": 1 << 10, "m": 1 << 20, "g": 1 << 30, "t": 1 << 40}


def _env(name: str, default, *, sizes: bool = False):
    """The limit set by environment variable ``name`` (None: switched off with 0), else ``default``."""
    text = os.environ.get(name, "").strip()
    if not text:
        return default
    m = _SIZE.match(text) if sizes else re.match(r"^\s*([0-9]*\.?[0-9]+(?:[eE][+-]?[0-9]+)?)\s*()()$", text)
    if m is None:
        unit = " (bytes, or with K, M, G, T: 512M, 2G)" if sizes else ""
        raise ConfigError(f"environment variable {name}={text!r}: expected a number >= 0{unit}")
    value = float(m.group(1)) * _SCALE[m.group(2).lower()]
    if not math.isfinite(value):  # 1e400: a float overflow, not a limit
        raise ConfigError(f"environment variable {name}={text!r}: expected a finite number >= 0 (0 switches the "
                          "limit off)")
    return None if value == 0 else value


def max_line_bytes() -> int | None:
    """Most bytes in one line of a text file (``FOGDRIFT_MAX_LINE_BYTES``; None: no limit)."""
    v = _env(ENV_LINE, DEFAULT_LINE_BYTES, sizes=True)
    return None if v is None else int(v)


def max_rows() -> int | None:
    """Most lines of a text file / rows of an array (``FOGDRIFT_MAX_ROWS``; None: no limit)."""
    v = _env(ENV_ROWS, DEFAULT_ROWS)
    return None if v is None else int(v)


def max_expansion() -> float | None:
    """Most decompressed bytes per stored byte beyond :data:`EXPANSION_FLOOR` (``FOGDRIFT_MAX_EXPANSION``)."""
    return _env(ENV_EXPANSION, DEFAULT_EXPANSION)


def max_columns() -> int | None:
    """Most columns of a table (``FOGDRIFT_MAX_COLUMNS``; None: no limit)."""
    v = _env(ENV_COLUMNS, DEFAULT_COLUMNS)
    return None if v is None else int(v)


def max_preamble_bytes() -> int | None:
    """Most bytes of comment/blank lines before a text file's content (``FOGDRIFT_MAX_PREAMBLE``)."""
    v = _env(ENV_PREAMBLE, DEFAULT_PREAMBLE, sizes=True)
    return None if v is None else int(v)


def check_columns(n_columns: int, path, what: str = "columns", n_rows: int | None = None) -> None:
    """ResourceLimitError if a table has more than ``FOGDRIFT_MAX_COLUMNS`` columns (each a possible axis: a
    file of thousands is no gyro log, or an array stored transposed)."""
    limit = max_columns()
    if limit is not None and n_columns > limit:
        turned = (f"; {n_rows} rows x {n_columns} columns: stored transposed? (samples go down the rows, one "
                  "column per axis)" if n_rows is not None and n_rows < n_columns else "")
        raise ResourceLimitError(f"{n_columns} {what}; expected at most {limit} ({ENV_COLUMNS}: each column is a "
                                 f"possible axis){turned}; {_raise_it(ENV_COLUMNS)}", limit=ENV_COLUMNS, path=path)


def _machine_memory() -> int:
    total = 8 << 30
    try:
        total = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):  # pragma: no cover - not POSIX
        pass
    try:
        import resource

        soft = resource.getrlimit(resource.RLIMIT_AS)[0]
        if soft != resource.RLIM_INFINITY and soft > 0:
            total = min(total, soft)
    except (ImportError, ValueError, OSError):  # pragma: no cover - not POSIX
        pass
    return int(total)


def memory_budget() -> int | None:
    """Bytes a reader may allocate for one table (``FOGDRIFT_MAX_MEMORY``; default half the memory, None: off)."""
    v = _env(ENV_MEMORY, _machine_memory() // 2, sizes=True)
    return None if v is None else int(v)


def format_bytes(n: float) -> str:
    """``"4 GiB"``, ``"1.5 MiB"``, ``"512 bytes"``.

    Examples
    --------
    >>> format_bytes(4 << 30), format_bytes(1536 << 10), format_bytes(512)
    ('4 GiB', '1.5 MiB', '512 bytes')
    """
    for unit, scale in (("TiB", 1 << 40), ("GiB", 1 << 30), ("MiB", 1 << 20), ("KiB", 1 << 10)):
        if n >= scale:
            return f"{n / scale:.3g} {unit}"
    return f"{int(n)} bytes"


def _raise_it(env: str) -> str:
    return f"raise it with the environment variable {env} (0: no limit) if the file is genuine"


def check_rows(n_rows: int, path, what: str = "rows") -> None:
    """ResourceLimitError if ``n_rows`` exceeds ``FOGDRIFT_MAX_ROWS``."""
    limit = max_rows()
    if limit is not None and n_rows > limit:
        raise ResourceLimitError(f"{n_rows} {what}; expected at most {limit} ({ENV_ROWS}); {_raise_it(ENV_ROWS)}",
                                 limit=ENV_ROWS, path=path)


def check_memory(n_bytes: float, path, what: str) -> None:
    """ResourceLimitError if reading ``what`` needs more than the memory budget (``FOGDRIFT_MAX_MEMORY``)."""
    budget = memory_budget()
    if budget is not None and n_bytes > budget:
        raise ResourceLimitError(
            f"{what} needs {format_bytes(n_bytes)} of memory; expected at most the memory budget "
            f"{format_bytes(budget)} ({ENV_MEMORY}); {_raise_it(ENV_MEMORY)}", limit=ENV_MEMORY, path=path)


def expansion_allowed(stored_bytes: int) -> float | None:
    """Decompressed bytes allowed for ``stored_bytes`` of a file (None: no limit)."""
    ratio = max_expansion()
    return None if ratio is None else max(ratio * stored_bytes, EXPANSION_FLOOR)


def check_expansion(declared: float, stored_bytes: int, path, what: str) -> None:
    """ResourceLimitError if ``declared`` bytes from a ``stored_bytes`` file exceed the expansion limit.

    Parameters
    ----------
    declared : float
        Bytes the file says it will decompress to (zip members' sizes, an array's shape x item size).
    stored_bytes : int
        Size of the file on disk in bytes.
    path : Path
        The file, for the message.
    what : str
        What declares it (``"member 'gx.npy'"``).
    """
    allowed = expansion_allowed(stored_bytes)
    if allowed is not None and declared > allowed:
        raise ResourceLimitError(
            f"{what}: {format_bytes(declared)} declared in a {format_bytes(stored_bytes)} file "
            f"({declared / max(stored_bytes, 1):.3g} times its size); expected at most {max_expansion():g} times "
            f"({ENV_EXPANSION}, beyond the first {format_bytes(EXPANSION_FLOOR)}); refused before decompressing "
            f"(a decompression bomb?); {_raise_it(ENV_EXPANSION)}", limit=ENV_EXPANSION, path=path)


def _count_breaks(chunk: bytes) -> int:
    """Line breaks in ``chunk``: ``\n``, ``\r\n`` and a lone ``\r`` count one each (numpy: bytes.count is ~10x
    slower on a chunk full of matches)."""
    a = np.frombuffer(chunk, dtype=np.uint8)
    n = int(np.count_nonzero(a == 10))
    if b"\r" in chunk:
        cr = a == 13
        n += int(np.count_nonzero(cr)) - int(np.count_nonzero(cr[:-1] & (a[1:] == 10)))
    return n


class GuardedStream(io.RawIOBase):
    """A binary stream of text bytes that stops at the reading limits while it is read.

    Counts physical lines (``\\n``, ``\\r\\n`` or ``\\r``) and the length of the current one in C-speed
    byte operations per chunk; raises :class:`~fogdrift.errors.ResourceLimitError` as soon as a line is longer
    than ``FOGDRIFT_MAX_LINE_BYTES``, the lines exceed ``FOGDRIFT_MAX_ROWS`` or ``rows x bytes_per_row`` the
    memory budget, or (``stored_bytes`` given: compressed input) the bytes decompressed so far exceed the
    expansion limit.  ``binary_check`` refuses NUL bytes in the first 8000 bytes (decompressed gzip content
    that is not text).

    Parameters
    ----------
    inner : binary stream with ``readinto``
        The decoded bytes (a ``GzipFile``, a buffered file).
    path : Path
        The file, for messages.
    stored_bytes : int, optional
        Size on disk of a compressed file (enables the expansion limit).
    bytes_per_row : int
        Memory one line will cost once parsed (8 x columns; 0: no memory check).
    binary_check : bool
        Refuse NUL bytes at the start.
    closing : sequence
        Other streams to close with this one (the file under a ``GzipFile``).
    """

    def __init__(self, inner, path, *, stored_bytes=None, bytes_per_row: int = 0, binary_check: bool = False,
                 closing=()):
        self._inner = inner
        self._closing = list(closing)
        self.path = path
        self.total = 0
        self.lines = 0          # line breaks seen
        self.current = 0        # bytes of the line being read
        self._prev_cr = False
        self._head = b"" if binary_check else None
        self.max_line = max_line_bytes()
        rows = max_rows()
        budget = memory_budget() if bytes_per_row else None
        by_memory = None if budget is None else budget // max(int(bytes_per_row), 1)
        self.max_lines = min((x for x in (rows, by_memory) if x is not None), default=None)
        self._by_memory = by_memory is not None and (rows is None or by_memory < rows)
        self.bytes_per_row = int(bytes_per_row)
        self.budget = budget
        self.max_total = None if stored_bytes is None else expansion_allowed(int(stored_bytes))
        self.stored = stored_bytes

    def readable(self) -> bool:
        return True

    def readinto(self, b) -> int:
        n = self._inner.readinto(b)
        if n:
            self._account(bytes(memoryview(b)[:n]))
        return n

    def close(self) -> None:
        if not self.closed:
            for s in [self._inner, *self._closing]:
                try:
                    s.close()
                except (OSError, ValueError):  # a corrupt gzip trailer at close: the read already said so
                    pass
        super().close()

    # -- the limits ----------------------------------------------------------------------------------
    def _account(self, chunk: bytes) -> None:
        n = len(chunk)
        self.total += n
        if self._head is not None:
            self._check_binary(chunk)
        breaks = _count_breaks(chunk) - (1 if self._prev_cr and chunk[:1] == b"\n" else 0)
        first = min((k for k in (chunk.find(b"\n"), chunk.find(b"\r") if b"\r" in chunk else -1) if k >= 0),
                    default=-1)
        if first < 0:
            self.current += n
            self._line_check(self.current, self.lines + 1)
        else:
            self._line_check(self.current + first, self.lines + 1)
            if self.max_line is not None and n > self.max_line:
                self._inner_lines(chunk)
            last = max(chunk.rfind(b"\n"), chunk.rfind(b"\r") if b"\r" in chunk else -1)
            self.current = n - last - 1
            self.lines += breaks
            self._line_check(self.current, self.lines + 1)  # the part after the last break (a chunk > the limit)
        self._prev_cr = chunk[-1:] == b"\r"
        if self.max_lines is not None and self.lines > self.max_lines:
            self._too_many()
        if self.max_total is not None and self.total > self.max_total:
            raise ResourceLimitError(
                f"gzip content exceeds {format_bytes(self.max_total)} after {self.lines} lines (more than "
                f"{max_expansion():g} times the file's {format_bytes(self.stored)}); expected at most "
                f"{max_expansion():g} times ({ENV_EXPANSION}, beyond the first {format_bytes(EXPANSION_FLOOR)}): "
                f"stopped while decompressing (a decompression bomb?); {_raise_it(ENV_EXPANSION)}",
                limit=ENV_EXPANSION, path=self.path)

    def _inner_lines(self, chunk: bytes) -> None:
        """Lines wholly inside a chunk longer than the line limit (rare: chunks are 1 MiB, the limit too)."""
        a = np.frombuffer(chunk, dtype=np.uint8)
        pos = np.flatnonzero((a == 10) | (a == 13))
        if pos.size > 1:
            gaps = np.diff(pos) - 1
            k = int(np.argmax(gaps > self.max_line))  # the first line over the limit (the one a small chunk finds)
            before = chunk[:int(pos[k]) + 1]
            line = self.lines + 1 + _count_breaks(before)
            self._line_check(int(gaps[k]), line)

    def _line_check(self, length: int, line: int) -> None:
        if self.max_line is not None and length > self.max_line:
            raise ResourceLimitError(
                f"line longer than {format_bytes(self.max_line)} (more than {self.max_line} bytes without a line "
                f"break); expected at most {self.max_line} bytes per line ({ENV_LINE}); {_raise_it(ENV_LINE)}",
                limit=ENV_LINE, path=self.path, line=line)

    def _too_many(self) -> None:
        if self._by_memory:
            raise ResourceLimitError(
                f"more than {self.max_lines} lines of {self.bytes_per_row // 8} columns: the table would need more "
                f"than {format_bytes(self.budget)} of memory; expected at most the memory budget "
                f"{format_bytes(self.budget)} ({ENV_MEMORY}); stopped while reading; {_raise_it(ENV_MEMORY)}",
                limit=ENV_MEMORY, path=self.path)
        raise ResourceLimitError(
            f"more than {self.max_lines} lines; expected at most {self.max_lines} ({ENV_ROWS}); stopped while "
            f"reading; {_raise_it(ENV_ROWS)}", limit=ENV_ROWS, path=self.path)

    def _check_binary(self, chunk: bytes) -> None:
        head = self._head + chunk[:8000 - len(self._head)]
        k = head.find(b"\x00")
        if k >= 0:
            before = head[:k]
            line = 1 + before.count(b"\n") + before.count(b"\r") - before.count(b"\r\n")
            raise DataFormatError(
                f"NUL byte at byte {k + 1} of the decompressed content; expected text (gzip holds binary data, "
                "not a CSV/TXT log)", path=self.path, line=line)
        self._head = head if len(head) < 8000 else None
