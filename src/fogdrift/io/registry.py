"""Which reader opens a file: a table of formats, selected by magic bytes, then extension, then content.

:data:`READERS` is data: one :class:`ReaderSpec` line per format.  :func:`select_reader`
picks the first line whose magic bytes start the file; failing that, the line with the
longest matching extension; failing that, a line whose ``sniff`` accepts the first bytes
(plain text has no magic bytes: any file without NUL bytes in its first 8000 bytes is text,
git's rule).  Directories are accepted only by a format with a ``directory_marker``.
An unknown format is a DataFormatError that names the file and lists the known formats.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from ..errors import ConfigError, DataFormatError

__all__ = ["ReaderSpec", "READERS", "select_reader", "reader_by_name"]

#: Bytes read from the start of a file to match magic numbers and sniff content.
HEAD_BYTES = 8000


def _looks_like_text(head: bytes) -> bool:
    """No NUL byte in the first 8000 bytes (git's binary test); UTF-16 text fails it, on purpose."""
    return b"\x00" not in head


@dataclass(frozen=True)
class ReaderSpec:
    """One format: how to recognise it and where its reader lives.

    Parameters
    ----------
    name : str
        Format name (``load(..., format=name)`` forces it).
    module : str
        Reader module, relative to :mod:`fogdrift.io.readers` (``"text"``) or absolute
        (``"mypkg.reader"``); imported on first use, so a reader's own dependencies (h5py,
        rosbags...) load only when such a file is read.  It defines
        ``open_table(path, **options) -> Table``.
    magic : tuple of bytes
        The file starts with one of these.
    extensions : tuple of str
        Lower-case name endings (``".csv"``, ``".csv.gz"``).
    options : tuple of str
        Reader options ``open_table`` accepts (``load(..., reader_options={...})``).
    sniff : callable, optional
        ``sniff(head_bytes) -> bool``, the last resort for formats without magic bytes.
    directory_marker : str, optional
        A directory holding a file of this name is in this format (ROS 2 bags:
        ``"metadata.yaml"``).
    description : str
        What the format is, for the unknown-format message.
    """

    name: str
    module: str
    magic: tuple[bytes, ...] = ()
    extensions: tuple[str, ...] = ()
    options: tuple[str, ...] = ()
    sniff: Callable[[bytes], bool] | None = None
    directory_marker: str | None = None
    description: str = ""

    def open_table(self, path: Path, options: dict):
        """Import the reader module and call its ``open_table(path, **options)``."""
        unknown = sorted(set(options) - set(self.options))
        if unknown:
            raise ConfigError(
                f"{path}: unknown reader option(s) {unknown} for {self.name} files; expected some of "
                f"{list(self.options)}"
            )
        name = self.module if "." in self.module else f"{__package__}.readers.{self.module}"
        return importlib.import_module(name).open_table(path, **options)


def _looks_like_mseed(head: bytes) -> bool:
    """miniSEED 2 fixed header (see :func:`fogdrift.io.readers.mseed.looks_like_mseed`; no import of ObsPy)."""
    return (len(head) >= 48 and all(c in b"0123456789 " for c in head[:6]) and head[6:7] in (b"D", b"R", b"Q", b"M")
            and head[7:8] in (b" ", b"\x00"))


_BAG_OPTIONS = ("topic", "stamp", "temperature")

#: The formats fogdrift reads, in the order magic bytes (then sniffers) are tried; text is last.
READERS: tuple[ReaderSpec, ...] = (
    ReaderSpec("npy", "npy", magic=(b"\x93NUMPY",), extensions=(".npy",),
               description="NumPy .npy array"),
    ReaderSpec("npz", "npz", magic=(b"PK\x03\x04", b"PK\x05\x06"), extensions=(".npz",),
               description="NumPy .npz archive"),
    ReaderSpec("hdf5", "hdf5", magic=(b"\x89HDF\r\n\x1a\n",), extensions=(".h5", ".hdf5", ".hdf", ".he5"),
               options=("dataset",), description="HDF5 file (h5py, extra [hdf5])"),
    ReaderSpec("mat", "matlab", magic=(b"MATLAB",), extensions=(".mat",), options=("variable",),
               description="MATLAB .mat v4/v5/v7 (scipy) or v7.3 (h5py)"),
    ReaderSpec("rosbag1", "rosbag", magic=(b"#ROSBAG V2.0",), extensions=(".bag",), options=_BAG_OPTIONS,
               description="ROS 1 bag (rosbags, extra [ros])"),
    ReaderSpec("rosbag2", "rosbag", magic=(b"\x89MCAP0\r\n", b"SQLite format 3\x00"), extensions=(".db3", ".mcap"),
               options=_BAG_OPTIONS, directory_marker="metadata.yaml",
               description="ROS 2 bag directory (rosbags, extra [ros])"),
    ReaderSpec("mseed", "mseed", extensions=(".mseed", ".miniseed", ".msd"), options=("gain", "temperature"),
               sniff=_looks_like_mseed, description="miniSEED (ObsPy, extra [seismo])"),
    ReaderSpec("binary", "binary", options=("layout", "scale", "header_bytes", "sequence"),
               description="raw binary records, chosen by giving their layout= (or format='binary')"),
    ReaderSpec("text", "text", magic=(b"\x1f\x8b",),
               extensions=(".csv", ".txt", ".tsv", ".dat", ".log", ".gz"), options=("delimiter",),
               sniff=_looks_like_text, description="CSV/TXT text, optionally gzip"),
)


def reader_by_name(name: str) -> ReaderSpec:
    """The :data:`READERS` line of format ``name``; ConfigError listing the formats otherwise."""
    for spec in READERS:
        if spec.name == name:
            return spec
    raise ConfigError(f"unknown format {name!r}; expected one of {[s.name for s in READERS]}")


def select_reader(path: Path) -> ReaderSpec:
    """The reader for ``path``: magic bytes first, then extension, then content sniffing.

    Raises
    ------
    DataFormatError
        If the file cannot be read or no format matches (the message lists the known ones).
    """
    p = Path(path)
    if p.is_dir():
        for spec in READERS:
            if spec.directory_marker and (p / spec.directory_marker).is_file():
                return spec
        raise DataFormatError(
            "not a regular file; expected a data file or a directory in a known format, got a directory", path=p
        )
    try:
        with open(p, "rb") as fh:
            head = fh.read(HEAD_BYTES)
    except OSError as exc:
        raise DataFormatError(
            f"cannot read file; expected a readable file, got {exc.strerror or exc}", path=p
        ) from exc
    for spec in READERS:
        if any(head.startswith(m) for m in spec.magic):
            return spec
    lower = p.name.lower()
    by_ext = [(len(e), spec) for spec in READERS for e in spec.extensions if lower.endswith(e)]
    if by_ext:
        return max(by_ext, key=lambda x: x[0])[1]
    for spec in READERS:
        if spec.sniff is not None and spec.sniff(head):
            return spec
    known = "; ".join(f"{s.name} ({s.description}: {', '.join(s.extensions) or 'no extension'})" for s in READERS)
    raise DataFormatError(
        f"unknown file format; expected one of {known}, got first bytes {head[:8].hex(' ') or 'none'}", path=p
    )
