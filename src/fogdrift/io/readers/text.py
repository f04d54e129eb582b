"""Text reader: CSV/TXT, optionally gzip-compressed.

Comma, tab, semicolon or whitespace separated, with or without one header row; lines (or line
tails) starting with ``#`` or ``%`` are comments; UTF-8 with or without a byte-order mark.
Header cells may declare units as ``name[unit]`` (``gz[deg/s]``, ``t[ms]``).  Numbers use a
decimal point, or a decimal comma when the separator is not a comma and the first data row
shows it (``0,01;1,5``).  The file's SHA-256 is computed from the bytes the parser streams.
"""

from __future__ import annotations

import gzip
import io
from array import array
import math
import re
import warnings
import zlib
from pathlib import Path

import numpy as np

from ...errors import ConfigError, DataFormatError, ResourceLimitError
from ..hashing import hashing_stream
from .base import Table, describe_exception, split_unit_label
from .limits import ENV_PREAMBLE, GuardedStream, check_columns, format_bytes, max_preamble_bytes

__all__ = ["open_table", "TextTable", "delimiter_option"]

_COMMENT_CHARS = ("#", "%")
_DELIMITERS = {
    ",": ",", "comma": ",",
    ";": ";", "semicolon": ";",
    "\t": "\t", "\\t": "\t", "tab": "\t",
    " ": None, "whitespace": None, "space": None,
}
_DELIM_NAMES = {",": "comma", ";": "semicolon", "\t": "tab", None: "whitespace"}
#: A cell written with a decimal comma: "1,5", "-0,25e-3".
_DECIMAL_COMMA = re.compile(r"^[+-]?\d*,\d+([eE][+-]?\d+)?$|^[+-]?\d+,\d*([eE][+-]?\d+)?$")
#: A number written with thousands separators: "1,137", "-12,345,678" (a first group of 1-3 digits, not 0).  Such a
#: cell reads as a decimal comma too: where every comma cell of the first data row has this shape, the file is
#: refused rather than read as 1.137 or 1137 by guess.
_GROUPED = re.compile(r"^[+-]?[1-9]\d{0,2}(,\d{3})+$")
#: Errors of the text layers while streaming (decoding never fails: errors="replace").
_STREAM_ERRORS = (OSError, EOFError, zlib.error)
#: Rows the line-by-line scan collects as Python floats before packing them into a float64 block.
_BLOCK = 1 << 16


#: Use the fast CSV path (:meth:`TextTable._read_fast`) when pyarrow is installed; False: numpy.loadtxt always.
FAST_CSV = True


def _arrow_csv():
    """``pyarrow.csv`` if pyarrow is installed (found without importing it when it is not), else None."""
    import importlib.util

    try:
        if importlib.util.find_spec("pyarrow") is None:
            return None
        import pyarrow.csv as pc
    except Exception:  # noqa: BLE001 - a broken optional install: the numpy path reads the file
        return None
    return pc


def delimiter_option(delimiter):
    """Normalise the ``delimiter`` option: "auto", a delimiter string, or None (whitespace)."""
    if delimiter is None:
        return "auto"
    if isinstance(delimiter, str) and delimiter.lower() in _DELIMITERS:
        return _DELIMITERS[delimiter.lower()]
    raise ConfigError(
        f"delimiter must be None (auto) or one of {sorted(repr(k) for k in _DELIMITERS)}; got {delimiter!r}"
    )


class TextTable(Table):
    """A text file: layout found by :func:`open_table`, numbers parsed by :meth:`read`."""

    format = "text"

    def __init__(self, path, *, names, named, units, header_line, delimiter, n_fields, is_gz, decimal_comma):
        super().__init__(path, names=names, named=named, units=units)
        self.header_line = header_line      # physical line of the header (0 = none)
        self.delimiter = delimiter          # str, or None for whitespace
        self.n_fields = n_fields
        self.is_gz = is_gz
        self.decimal_comma = decimal_comma
        self.line_numbers = None            # physical line of each data row (computed lazily)

    # -- streaming -----------------------------------------------------------------------------
    def _record_hash(self, digest: str) -> None:
        if self.sha256 is None:
            self.sha256 = digest

    def stream(self) -> io.TextIOWrapper:
        """Decoded text of the file; reading it to the end records ``sha256``.

        The bytes pass through a :class:`~fogdrift.io.readers.limits.GuardedStream`: a line longer than the
        line limit, more lines than the row limit or the memory budget allow (``8 x n_fields`` bytes per
        line), or gzip content beyond the expansion limit stop the read with a ResourceLimitError.
        """
        raw = hashing_stream(self.path, self._record_hash)
        try:
            if self.is_gz:
                stored = self.path.stat().st_size
                inner = gzip.GzipFile(fileobj=raw, mode="rb")
                guard = GuardedStream(inner, self.path, stored_bytes=stored, bytes_per_row=8 * self.n_fields,
                                      binary_check=True, closing=[raw])
            else:
                guard = GuardedStream(raw, self.path, bytes_per_row=8 * self.n_fields)
        except BaseException:
            raw.close()
            raise
        return io.TextIOWrapper(io.BufferedReader(guard, 1 << 20), encoding="utf-8-sig", errors="replace")

    def delimiter_name(self) -> str:
        return _DELIM_NAMES.get(self.delimiter, repr(self.delimiter))

    # -- Table interface -----------------------------------------------------------------------
    def read(self, used) -> np.ndarray:
        """Parse all rows: the fast path (:meth:`_read_fast`), else :func:`numpy.loadtxt`, else a line-by-line scan
        that locates the first bad cell.

        loadtxt runs first with the single comment character ``#`` (handled in C); only if that
        fails is it retried with ``#`` and ``%`` (handled per line in Python, ~4x slower).
        """
        if self.data is not None:
            return self.data
        data = self._read_fast()
        if data is not None:
            self.data = data
            return data
        for comments in ("#", list(_COMMENT_CHARS)):
            try:
                with self.stream() as fh, warnings.catch_warnings():
                    warnings.simplefilter("ignore", UserWarning)  # "input contained no data"
                    lines = (ln.replace(",", ".") for ln in fh) if self.decimal_comma else fh
                    data = np.loadtxt(
                        lines, dtype=np.float64, delimiter=self.delimiter, comments=comments,
                        skiprows=self.header_line, ndmin=2,
                    )
            except DataFormatError:  # a reading limit, binary content: the same on a second pass
                raise
            except (ValueError, *_STREAM_ERRORS):
                continue
            if data.shape[0] == 0 or data.shape[1] == self.n_fields:
                self.data = data if data.shape[0] else np.empty((0, self.n_fields))
                return self.data
        self.data, self.line_numbers = self._scan(set(used))
        return self.data

    def _read_fast(self):
        """A plain numeric delimited file through pyarrow's CSV reader, or None (then loadtxt and the scan decide).

        Measured: ``np.loadtxt`` took 2.6-3.8 s on ADIS16405 session 1 (10^6 rows x 4), pyarrow on one thread
        ~0.5 s.  Used only when pyarrow is installed (the ``fleet`` extra; :data:`FAST_CSV` switches it off), for a
        comma/tab/semicolon file with decimal points, and only if every cell of every row parses as a finite
        number with exactly ``n_fields`` fields per row: each cell is parsed straight to float64 (no quoting, no
        null values, no type inference), and both parsers round correctly, so the array is loadtxt's bit for bit
        (``tests/io/test_io_fast_csv.py``).  Anything else (comments, blank cells, NaN/inf, quotes, ragged rows, a
        decimal comma, whitespace-separated) returns None and is read, and reported, exactly as before.  The bytes
        come through the same guarded, hashing stream (limits, binary check, ``sha256``), the header lines are
        skipped as physical lines, like loadtxt's ``skiprows``.
        """
        if not FAST_CSV or self.delimiter is None or self.decimal_comma or self.n_fields < 1:
            return None
        pc = _arrow_csv()
        if pc is None:
            return None
        import pyarrow as pa

        names = [f"f{j}" for j in range(self.n_fields)]
        try:
            with self.stream() as fh:
                raw = fh.buffer
                for _ in range(self.header_line):
                    line = raw.readline()
                    if b"\r" in line.rstrip(b"\r\n"):  # a lone CR ends a line for loadtxt's text stream
                        return None
                table = pc.read_csv(
                    raw,
                    read_options=pc.ReadOptions(column_names=names, use_threads=False, block_size=1 << 22),
                    parse_options=pc.ParseOptions(delimiter=self.delimiter, quote_char=False, double_quote=False,
                                                  escape_char=False, newlines_in_values=False,
                                                  ignore_empty_lines=True),
                    convert_options=pc.ConvertOptions(column_types={n: pa.float64() for n in names}, null_values=[],
                                                      strings_can_be_null=False, quoted_strings_can_be_null=False),
                )
        except DataFormatError:  # a reading limit, binary content: the same on the slow paths
            raise
        except Exception:  # noqa: BLE001 - anything pyarrow refuses is for loadtxt and the scan to read or locate
            return None
        if table.num_rows == 0 or table.num_columns != self.n_fields:
            return None
        data = np.empty((table.num_rows, self.n_fields), dtype=np.float64)
        for j, col in enumerate(table.columns):
            if col.null_count or col.type != pa.float64():
                return None
            a = 0
            for chunk in col.chunks:  # the values buffer itself (pyarrow's to_numpy imports pandas: +0.5 s)
                n = len(chunk)
                data[a: a + n, j] = np.frombuffer(chunk.buffers()[1], dtype=np.float64, count=n,
                                                  offset=8 * chunk.offset)
                a += n
        del table
        if not np.isfinite(data).all():  # NaN/inf spellings and overflow: loadtxt's reading is the reference
            return None
        return data

    def line_of(self, row: int) -> int:
        if self.line_numbers is None:
            self.line_numbers = self._data_lines()
        return int(self.line_numbers[row])

    def label(self, col: int):
        return self.names[col] if self.named else col + 1

    def at(self, row: int) -> str:
        return ""  # the line number locates it

    def describe(self, n_rows: int) -> str:
        head = f"header on line {self.header_line}" if self.header_line else "no header"
        gz = "gzip " if self.is_gz else ""
        dec = ", decimal comma" if self.decimal_comma else ""
        return f"{gz}text, {self.delimiter_name()}-separated{dec}, {head}, {n_rows} data rows"

    # -- slow paths ----------------------------------------------------------------------------
    def _scan(self, used: set):
        """Parse line by line and raise at the first bad line/column.

        Cells that are not numbers are an error only in used columns; elsewhere they become NaN.
        """
        rows, lines = [], array("q")
        blocks = []  # rows as float64 arrays of _BLOCK rows each: 8 bytes per cell, not a Python float's 24+
        nf = self.n_fields
        try:
            with self.stream() as fh:
                for lineno, raw in enumerate(fh, start=1):
                    if lineno <= self.header_line:
                        continue
                    s = _strip_comment(raw)
                    if not s:
                        continue
                    fields = _split(s, self.delimiter)
                    if len(fields) != nf:
                        raise self._ragged(lineno, len(fields), lines)
                    row = []
                    for j, f in enumerate(fields):
                        try:
                            row.append(float(f.replace(",", ".") if self.decimal_comma else f))
                        except ValueError:
                            if j in used:
                                raise self._non_numeric(f.strip(), lineno, j) from None
                            row.append(math.nan)
                    rows.append(row)
                    lines.append(lineno)
                    if len(rows) == _BLOCK:
                        blocks.append(np.array(rows, dtype=np.float64))
                        rows = []
        except _STREAM_ERRORS as exc:
            raise DataFormatError(f"unreadable file; expected text or gzip text, got {describe_exception(exc)}",
                                  path=self.path) from exc
        blocks.append(np.array(rows, dtype=np.float64).reshape(len(rows), nf))
        data = np.concatenate(blocks) if len(blocks) > 1 else blocks[0]
        return data, np.frombuffer(lines, dtype=np.int64) if len(lines) else np.zeros(0, dtype=np.int64)

    def _ragged(self, lineno: int, got: int, lines: list) -> DataFormatError:
        nf = self.n_fields
        if self.named:
            rule = f"{nf} fields as in the header on line {self.header_line}"
        else:
            rule = f"{nf} fields as in the first data row (line {lines[0] if lines else lineno})"
        j = min(got, nf)
        col = self.label(j) if j < nf else j + 1
        return DataFormatError(
            f"wrong number of fields ({self.delimiter_name()}-separated); expected {rule}, got {got}",
            path=self.path, line=lineno, column=col,
        )

    def _non_numeric(self, cell: str, lineno: int, j: int) -> DataFormatError:
        hint = ""
        if not self.decimal_comma and _GROUPED.match(cell):
            hint = " (a thousands separator: write the number without it)"
        elif not self.decimal_comma and _DECIMAL_COMMA.match(cell):
            hint = (" (a decimal comma: read only when the separator is not a comma and the first data row "
                    "has one; write decimal points)")
        return DataFormatError(f"non-numeric value{hint}; expected a number, got {cell!r}",
                               path=self.path, line=lineno, column=self.label(j))

    def _data_lines(self) -> np.ndarray:
        """Physical line number of every data row (used only to locate errors and segments)."""
        lines = array("q")
        with self.stream() as fh:
            for lineno, raw in enumerate(fh, start=1):
                if lineno > self.header_line and _strip_comment(raw):
                    lines.append(lineno)
        return np.frombuffer(lines, dtype=np.int64) if len(lines) else np.zeros(0, dtype=np.int64)


def open_table(path: Path, *, delimiter=None) -> TextTable:
    """Read the first two non-comment lines: delimiter, header (names, declared units), field count.

    Parameters
    ----------
    path : Path
        Text file, plain or gzip (detected from the magic bytes ``1f 8b``).
    delimiter : None or str
        ``None`` detects it (tab, comma, semicolon, else whitespace); or ``","``, ``";"``,
        ``"\\t"``, ``" "`` (whitespace) or the words comma, semicolon, tab, whitespace.

    Raises
    ------
    ConfigError
        Unknown ``delimiter``.
    DataFormatError
        Unreadable/empty file, duplicate header names.
    """
    delim = delimiter_option(delimiter)
    p = Path(path)
    try:
        with open(p, "rb") as fh:
            head = fh.read(8)
    except OSError as exc:
        raise DataFormatError(f"cannot read file; expected a readable file, got {exc.strerror or exc}",
                              path=p) from exc
    gzip_magic = head[:2] == b"\x1f\x8b"
    refuse_foreign(head, p)
    probe = TextTable(p, names=[], named=False, units=[], header_line=0, delimiter=None, n_fields=0,
                      is_gz=gzip_magic, decimal_comma=False)
    content, lines_of, first_lineno, lineno, skipped = [], [], 0, 0, 0
    preamble = max_preamble_bytes()
    try:
        with probe.stream() as fh:
            for lineno, raw in enumerate(fh, start=1):
                s = _strip_comment(raw)
                if s:
                    content.append(s)
                    lines_of.append(lineno)
                    first_lineno = first_lineno or lineno
                    if len(content) == 2:
                        break
                else:
                    skipped += len(raw)
                    if preamble is not None and skipped > preamble:
                        raise ResourceLimitError(
                            f"no header or data row in the first {lineno} lines ({format_bytes(skipped)} of comment "
                            f"or blank lines); expected the table within the first {format_bytes(preamble)} "
                            f"({ENV_PREAMBLE}); raise it with the environment variable {ENV_PREAMBLE} (0: no limit) "
                            "if the file is genuine", limit=ENV_PREAMBLE, path=p, line=lineno)
    except _STREAM_ERRORS as exc:
        raise DataFormatError(f"unreadable file; expected text or gzip text, got {describe_exception(exc)}",
                              path=p) from exc
    if not content:
        raise DataFormatError(
            "empty file; expected a header and/or numeric data rows, got no content "
            "(only blank or comment lines)" if lineno else "empty file; expected data, got 0 bytes", path=p,
        )
    first, second = content[0], (content[1] if len(content) > 1 else None)
    if delim == "auto":
        delim, is_header = _detect_layout(first, second)
    else:
        is_header = not (_fits(first, delim, False) or (delim != "," and _fits(first, delim, True)))
    data_line = second if is_header else first
    cells = [] if data_line is None else [f.strip() for f in _split(data_line, delim)]
    commas = [c for c in cells if _DECIMAL_COMMA.match(c)]
    # a decimal comma only where no cell of the row has a decimal point ("0.01<TAB>1,137" holds a thousands
    # separator, not two decimal marks)
    decimal_comma = delim != "," and bool(commas) and not any("." in c for c in cells)
    if decimal_comma and all(_GROUPED.match(c) for c in commas):
        raise DataFormatError(
            f"cells such as {commas[0]!r} read as a decimal comma ({commas[0].replace(',', '.')}) or as a thousands "
            f"separator ({commas[0].replace(',', '')}); expected numbers with one meaning: write decimal points and "
            "no thousands separators", path=p, line=lines_of[1] if is_header else lines_of[0])
    fields = [f.strip() for f in _split(first, delim)]
    check_columns(len(fields), p, "columns (fields in the first line)")
    common = dict(delimiter=delim, n_fields=len(fields), is_gz=gzip_magic, decimal_comma=decimal_comma)
    if not is_header:
        table = TextTable(p, names=[f"col{j}" for j in range(len(fields))], named=False,
                          units=[None] * len(fields), header_line=0, **common)
        table.sha256 = probe.sha256  # set if the probe read a tiny file to its end
        return table
    names, units = [], []
    for j, f in enumerate(fields):
        name, unit = split_unit_label(f.strip("\"'").strip())
        names.append(name or f"col{j}")
        units.append(unit)
    dup = next((a for j, a in enumerate(names) if a in names[:j]), None)
    if dup is not None:
        raise DataFormatError(
            f"duplicate column name in header; expected unique names, got {dup!r} twice",
            path=p, line=first_lineno, column=dup,
        )
    table = TextTable(p, names=names, named=True, units=units, header_line=first_lineno, **common)
    table.sha256 = probe.sha256
    return table


#: Encodings (byte-order marks, longest first) and compressions (magic bytes) a text log is refused in, by name.
FOREIGN = (
    (b"\xff\xfe\x00\x00", "UTF-32 text (little-endian byte-order mark FF FE 00 00)", "iconv -f UTF-32 -t UTF-8"),
    (b"\x00\x00\xfe\xff", "UTF-32 text (big-endian byte-order mark 00 00 FE FF)", "iconv -f UTF-32 -t UTF-8"),
    (b"\xff\xfe", "UTF-16 text (little-endian byte-order mark FF FE)", "iconv -f UTF-16 -t UTF-8"),
    (b"\xfe\xff", "UTF-16 text (big-endian byte-order mark FE FF)", "iconv -f UTF-16 -t UTF-8"),
    (b"BZh", "bzip2-compressed (magic bytes 42 5A 68)", "bunzip2 -k, or recompress with gzip"),
    (b"\xfd7zXZ\x00", "xz-compressed (magic bytes FD 37 7A 58 5A 00)", "unxz -k, or recompress with gzip"),
    (b"\x28\xb5\x2f\xfd", "Zstandard-compressed (magic bytes 28 B5 2F FD)", "unzstd, or recompress with gzip"),
    (b"\x04\x22\x4d\x18", "LZ4-compressed (magic bytes 04 22 4D 18)", "unlz4, or recompress with gzip"),
    (b"7z\xbc\xaf\x27\x1c", "a 7-Zip archive (magic bytes 37 7A BC AF 27 1C)", "extract the log from it"),
)


def refuse_foreign(head: bytes, path) -> None:
    """DataFormatError naming the encoding or compression when ``head`` (a file's first bytes) is one that the
    text reader does not read (UTF-16/UTF-32, bzip2, xz, zstd, lz4, 7z): plain or gzip UTF-8 text only."""
    for magic, what, fix in FOREIGN:
        if head.startswith(magic) and not (magic == b"BZh" and not head[3:4].isdigit()):  # BZh1..BZh9
            raise DataFormatError(f"the file is {what}; expected UTF-8 (or ASCII) text, plain or gzip: convert it "
                                  f"({fix})", path=path, line=1)


def _detect_layout(first: str, second):
    """(delimiter, first line is a header) from the first two content lines.

    A delimiter fits a data line when it splits it into numbers only; candidates are tab,
    comma and semicolon (if present), then whitespace; a delimiter other than comma also
    fits with decimal commas.  If the first line fits no candidate it is a header, and the
    delimiter is the one that fits the second line with as many fields as the header;
    failing that, the most frequent of tab/comma/semicolon.
    """
    def candidates(line):
        return [d for d in ("\t", ",", ";") if d in line] + [None]

    for dc in (False, True):
        for d in candidates(first):
            if not (dc and d == ",") and _fits(first, d, dc):
                return d, False
    if second is not None:
        for dc in (False, True):
            for d in candidates(second):
                if not (dc and d == ",") and _fits(second, d, dc) and len(_split(first, d)) == len(_split(second, d)):
                    return d, True
    counts = {c: first.count(c) for c in ("\t", ",", ";")}
    best = max(counts, key=counts.get)
    return (best if counts[best] else None), True


def _fits(line: str, delim, decimal_comma: bool) -> bool:
    """All fields of ``line`` are numbers (with "," read as "." if ``decimal_comma``)."""
    fields = _split(line, delim)
    if decimal_comma:
        return any("," in f for f in fields) and all(_is_number(f.replace(",", ".")) for f in fields)
    return all(_is_number(f) for f in fields)


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
