"""Raw binary reader: fixed-size records declared by a NumPy dtype layout, read through a memory map.

Options (``load(..., reader_options={...})``; CLI ``--layout``, ``--scale``, ``--header-bytes``,
``--sequence``):

``layout``
    The record, as ``"TYPE NAME"`` items separated by commas, each TYPE a NumPy dtype string
    with its byte order: ``"<u4 seq, <i4 gx, <i4 gy, <i4 gz, <i2 temp"``.  ``V<n>`` items are
    padding (skipped).  Every other field is a column.
``scale``
    Factor from the stored integers to the unit of the data (the LSB weight): one number for
    every field except the sequence counter (``"1e-4"``), or per field
    (``"gx=1e-4, gy=1e-4, gz=1e-4, temp=0.01"``; fields not named keep factor 1).  The unit of
    the scaled numbers is given as ``unit`` (``inc:arcsec`` for angle increments per record,
    ``deg/s`` for rates): raw binary declares none, so ``load`` refuses to guess.
``header_bytes``
    Bytes before the first record (a file header), default 0.
``sequence``
    The sequence-counter field, default the first integer field named seq, sequence, counter,
    cnt, count or frame; ``"none"`` for none.  The counter wraps at its width (2^16 for
    ``u2``): a step of 1 is the next record, a step of k > 1 means k - 1 records are missing
    (a gap, reported or split exactly like a gap in a time column, once the sample rate is
    given), a step of 0 is a repeated record and a step of more than half the counter range is
    a counter going backwards (both errors naming the record).  A counter that skips more than
    half its range cannot be told from one going backwards.

The file must hold ``header_bytes`` plus a whole number of records: a trailing partial record
(a truncated log) is an error naming its byte offset.  Rows are records: errors say "at
record 12 (byte 1032)".  The SHA-256 is of the file's bytes (one chunked read).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ...errors import ConfigError, DataFormatError
from ..hashing import file_sha256
from .limits import check_memory, check_rows
from .base import Table

__all__ = ["open_table", "BinaryTable", "parse_layout", "parse_scale", "SEQUENCE_NAMES"]

#: Field names taken as the sequence counter by default (case-insensitive), if of integer type.
SEQUENCE_NAMES = ("seq", "sequence", "counter", "cnt", "count", "frame")

_ITEM = re.compile(r"^\s*(?P<type>\S+)\s+(?P<name>[A-Za-z_][A-Za-z0-9_.]*)\s*$")


def parse_layout(layout) -> np.dtype:
    """A record dtype from ``"TYPE NAME, TYPE NAME, ..."`` (or a ``np.dtype`` / list of (name, type) pairs).

    Raises
    ------
    ConfigError
        An item that is not ``TYPE NAME``, an unknown dtype, a non-numeric field that is not
        padding (``V<n>``), a repeated name, or no numeric field.

    Examples
    --------
    >>> dt = parse_layout("<u4 seq, <i4 gx, V2 pad, >f4 temp")
    >>> dt.names, dt.itemsize
    (('seq', 'gx', 'pad', 'temp'), 14)
    """
    if isinstance(layout, np.dtype):
        dtype = layout
    elif isinstance(layout, str):
        fields = []
        for raw in layout.split(","):
            m = _ITEM.match(raw)
            if m is None:
                raise ConfigError(f"layout item {raw.strip()!r} is not 'TYPE NAME' (e.g. '<i4 gx'); "
                                  f"got layout {layout!r}; fix {{opt:layout}}")
            try:
                ft = np.dtype(m.group("type"))
            except TypeError:
                raise ConfigError(f"layout item {raw.strip()!r}: unknown NumPy dtype {m.group('type')!r} "
                                  "(e.g. '<i4', '>u2', '<f8', 'V4' for padding); fix {opt:layout}") from None
            fields.append((m.group("name"), ft))
        names = [n for n, _ in fields]
        dup = next((n for j, n in enumerate(names) if n in names[:j]), None)
        if dup is not None:
            raise ConfigError(f"layout names field {dup!r} twice; expected unique names in {{opt:layout}}")
        dtype = np.dtype(fields)
    else:
        try:
            dtype = np.dtype(list(layout))
        except (TypeError, ValueError) as exc:
            raise ConfigError(f"layout must be a string 'TYPE NAME, ...' or a dtype; got {layout!r}") from exc
    if not dtype.names:
        raise ConfigError(f"layout must declare named fields; got {dtype}")
    for name in dtype.names:
        kind = dtype.fields[name][0].kind
        if kind not in "biufV" or dtype.fields[name][0].shape:
            raise ConfigError(f"layout field {name!r} has type {dtype.fields[name][0]}; expected a scalar integer "
                              "or float type, or V<n> padding, in {opt:layout}")
    if not any(dtype.fields[n][0].kind in "biuf" for n in dtype.names):
        raise ConfigError(f"layout {layout!r} has no numeric field; expected at least one in {{opt:layout}}")
    return dtype


def parse_scale(scale, fields) -> dict:
    """Scale factor per field from ``1e-4`` / ``"1e-4"`` (every field) or ``"gx=1e-4, gy=1e-4"`` (those fields).

    Examples
    --------
    >>> parse_scale("gx=0.5, temp=0.01", ["seq", "gx", "temp"])
    {'gx': 0.5, 'temp': 0.01}
    >>> parse_scale(2, ["seq", "gx"])
    {'seq': 2.0, 'gx': 2.0}
    """
    if scale is None:
        return {}

    def number(text, what):
        try:
            v = float(text)
        except (TypeError, ValueError):
            v = float("nan")
        if not np.isfinite(v) or v == 0:
            raise ConfigError(f"scale {what} must be a finite non-zero number; got {text!r} in {{opt:scale}}")
        return v

    if isinstance(scale, (int, float, np.floating, np.integer)) and not isinstance(scale, bool):
        return {f: number(scale, "factor") for f in fields}
    if isinstance(scale, dict):
        items = list(scale.items())
    elif isinstance(scale, str) and "=" not in scale:
        return {f: number(scale.strip(), "factor") for f in fields}
    elif isinstance(scale, str):
        items = []
        for part in scale.split(","):
            name, sep, val = part.partition("=")
            if not sep:
                raise ConfigError(f"scale item {part.strip()!r} is not NAME=FACTOR; got {scale!r} in {{opt:scale}}")
            items.append((name.strip(), val.strip()))
    else:
        raise ConfigError(f"scale must be a number or 'NAME=FACTOR, ...'; got {scale!r} in {{opt:scale}}")
    out = {}
    for name, val in items:
        if name not in fields:
            raise ConfigError(f"scale names field {name!r}, not in the layout; expected one of {list(fields)} "
                              "in {opt:scale}")
        out[name] = number(val, f"of {name!r}")
    return out


class BinaryTable(Table):
    """Records of a raw binary file through a structured memory map; columns converted in :meth:`read`."""

    format = "binary"
    row_kind = "record"

    def __init__(self, path, *, records, fields, scales, header_bytes, sha256, sequence):
        super().__init__(path, names=fields, named=True, sha256=sha256)
        self.records = records
        self.scales = scales
        self.header_bytes = header_bytes
        self.sequence = sequence
        self.unit_hint = ("raw binary declares no unit; pass {opt:unit} for the scaled numbers (a rate such as "
                          "deg/s, or an angle increment per record such as inc:arcsec)")

    def read(self, used) -> np.ndarray:
        if self.data is None:
            n = self.records.shape[0]
            check_rows(n, self.path, "records")
            check_memory(n * 8.0 * max(len(set(used)), 1), self.path,
                         f"{n} records x {len(set(used))} used field(s) as float64")
            data = np.zeros((n, len(self.names)), dtype=np.float64, order="F")   # unused columns cost nothing
            for j in sorted(set(used)):
                name = self.names[j]
                col = self.records[name]
                s = self.scales.get(name, 1.0)
                if s == 1.0:
                    data[:, j] = col
                else:
                    np.multiply(col, s, out=data[:, j], casting="unsafe")
            self.data = data
        return self.data

    def at(self, row: int) -> str:
        return f" at record {row} (byte {self.header_bytes + row * self.records.dtype.itemsize})"

    def describe(self, n_rows: int) -> str:
        seq = f", sequence counter {self.sequence!r}" if self.sequence else ", no sequence counter"
        scaled = ", ".join(f"{k} x {v:g}" for k, v in self.scales.items()) or "none"
        return (f"raw binary, {n_rows} records of {self.records.dtype.itemsize} bytes after a "
                f"{self.header_bytes}-byte header{seq}; scale factors: {scaled}")


def _sequence_field(dtype: np.dtype, sequence) -> str | None:
    if isinstance(sequence, str) and sequence.strip().lower() == "none":
        return None
    if sequence is not None:
        name = str(sequence).strip()
        if name not in dtype.names:
            raise ConfigError(f"sequence field {name!r} is not in the layout; expected one of {list(dtype.names)} "
                              "or 'none' in {opt:sequence}")
        if dtype.fields[name][0].kind not in "iu":
            raise ConfigError(f"sequence field {name!r} has type {dtype.fields[name][0]}; expected an integer type "
                              "in {opt:sequence}")
        return name
    for name in dtype.names:
        if name.lower() in SEQUENCE_NAMES and dtype.fields[name][0].kind in "iu":
            return name
    return None


def _ticks(table: BinaryTable, seq: np.ndarray, name: str) -> np.ndarray:
    """Unwrapped sample counts from a wrapping counter; errors for repeats and backward steps."""
    bits = seq.dtype.itemsize * 8
    mod = np.int64(1) << np.int64(bits) if bits < 64 else None
    n = seq.shape[0]
    ticks = np.empty(n, dtype=np.int64)
    ticks[0] = 0
    step_chunk = 1 << 22
    total = np.int64(0)
    j = table.names.index(name)
    for a in range(1, n, step_chunk):
        b = min(n, a + step_chunk)
        cur = seq[a:b].astype(np.int64)
        prev = seq[a - 1:b - 1].astype(np.int64)
        steps = cur - prev
        if mod is not None:
            steps %= mod
        bad = (steps == 0) | (steps > (mod // 2 if mod is not None else np.iinfo(np.int64).max))
        if bad.any():
            i = a + int(np.argmax(bad))
            what = "repeats" if steps[i - a] == 0 else "goes backwards"
            raise table.error(
                f"sequence counter {what}{table.at(i)}; expected it to increase (modulo 2^{bits}), got "
                f"{int(seq[i])} after {int(seq[i - 1])}", row=i, col=j,
            )
        ticks[a:b] = total + np.cumsum(steps)
        total = ticks[b - 1]
    return ticks


def open_table(path: Path, *, layout=None, scale=None, header_bytes=0, sequence=None) -> Table:
    """Memory-map the records of a raw binary file (see the module docstring).

    Raises
    ------
    ConfigError
        No or invalid ``layout``, ``scale``, ``header_bytes`` or ``sequence``.
    DataFormatError
        File shorter than the header, a trailing partial record, no record, a repeated or
        backward sequence counter.
    """
    p = Path(path)
    if layout is None:
        raise ConfigError(f"{p}: raw binary needs its record layout; pass {{opt:layout}} as NumPy dtype items, "
                          "e.g. '<u4 seq, <i4 gx, <i4 gy, <i4 gz'")
    dtype = parse_layout(layout)
    try:
        hb = int(header_bytes)
    except (TypeError, ValueError):
        hb = -1
    if isinstance(header_bytes, bool) or hb < 0 or float(header_bytes) != hb:
        raise ConfigError(f"header_bytes must be an integer >= 0; got {header_bytes!r} in {{opt:header_bytes}}")
    fields = [n for n in dtype.names if dtype.fields[n][0].kind in "biuf"]
    seq = _sequence_field(dtype, sequence)
    scales = parse_scale(scale, [f for f in fields if f != seq])
    size = p.stat().st_size
    body = size - hb
    if body < 0:
        raise DataFormatError(f"file has {size} bytes; expected at least the {hb}-byte header", path=p)
    n, rest = divmod(body, dtype.itemsize)
    if rest:
        raise DataFormatError(
            f"trailing partial record at byte {hb + n * dtype.itemsize} (record {n}); expected the "
            f"{hb}-byte header plus whole {dtype.itemsize}-byte records, got {rest} extra bytes "
            "(a truncated log? check {opt:layout} and {opt:header_bytes})", path=p,
        )
    if n == 0:
        raise DataFormatError(f"no record after the {hb}-byte header; expected at least one "
                              f"{dtype.itemsize}-byte record, got {body} bytes", path=p)
    records = np.memmap(p, dtype=dtype, mode="r", offset=hb, shape=(n,))
    table = BinaryTable(p, records=records, fields=fields, scales=scales, header_bytes=hb, sha256=file_sha256(p),
                        sequence=seq)
    if seq is not None:
        table.non_rate = {seq}
        table.time_ticks = _ticks(table, records[seq], seq)
        table.tick_column = fields.index(seq)
    return table
