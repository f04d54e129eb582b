"""Which reader opens a file: a table of formats, selected by magic bytes, then extension, then content.

:data:`READERS` is data: one :class:`ReaderSpec` line per format.  :func:`select_reader`
picks the first line whose magic bytes start the file; failing that, the line with the
longest matching extension; failing that, a line whose ``sniff`` accepts the first bytes
(plain text has no magic bytes: any file without NUL bytes in its first 8000 bytes is text,
git's rule).  Directories are accepted only by a format with a ``directory_marker``.
An unknown format is a DataFormatError that names the file and lists the known formats.

Reader options live here too, each declared once: a :class:`ReaderOption` in a line's ``options``
gives the option's name, value type, help text and CLI flag.  The command line builds its flags
from this table (:func:`cli_options`; ``fogdrift.cli._app``), so a reader with options needs one
module and one line here, and no CLI edit, as ObsPy hands ``**kwargs`` on to its format plugins.
An option shared by several formats (``temperature``) is one object used in each line, one flag.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from ..errors import ConfigError, DataFormatError

__all__ = ["ReaderOption", "ReaderSpec", "READERS", "cli_options", "select_reader", "reader_by_name"]

#: Bytes read from the start of a file to match magic numbers and sniff content.
HEAD_BYTES = 8000


def _looks_like_text(head: bytes) -> bool:
    """No NUL byte in the first 8000 bytes (git's binary test); UTF-16 text fails it, on purpose."""
    return b"\x00" not in head


class ReaderOption(str):
    """One reader option, declared once: its name, value type, help text and CLI flag.

    The object *is* the option's name (a ``str``), so ``"topic" in spec.options``,
    ``reader_options={"topic": ...}`` and error messages read it as the plain name; the
    declaration rides along as attributes, which are read-only.

    Parameters
    ----------
    name : str
        Keyword of the reader's ``open_table`` (and of ``load(..., reader_options={name: ...})``).
    type : {str, int, float}
        Type of the value on the command line (the reader still validates it).
    help : str
        Help text of the CLI flag; say which format it is for (``"Bag: ..."``) and give units.
    flag : str, optional
        CLI flag; default ``--`` and the name with ``_`` written ``-`` (``header_bytes`` ->
        ``--header-bytes``).

    Notes
    -----
    A plain string in :attr:`ReaderSpec.options` is an option of the library alone (no flag),
    e.g. the text reader's ``delimiter``, which ``load(..., delimiter=...)`` also takes.
    """

    type: type
    help: str
    flag: str

    def __new__(cls, name: str, type: type = str, help: str = "", flag: str | None = None):  # noqa: A002
        if not (isinstance(name, str) and name.isidentifier()):
            raise ConfigError(f"reader option name must be a Python identifier; got {name!r}")
        if type not in (str, int, float):
            raise ConfigError(f"reader option {name!r}: type must be str, int or float; got {type!r}")
        if not (isinstance(help, str) and help.strip()):
            raise ConfigError(f"reader option {name!r}: a help text is required (it is the CLI flag's help)")
        flag = "--" + name.replace("_", "-") if flag is None else flag
        if not (isinstance(flag, str) and flag.startswith("--") and len(flag) > 2):
            raise ConfigError(f"reader option {name!r}: flag must start with '--'; got {flag!r}")
        self = super().__new__(cls, name)
        self.__dict__.update(type=type, help=help, flag=flag)
        return self

    def __setattr__(self, key, value):
        raise AttributeError(f"ReaderOption {str(self)!r} is read-only")

    @property
    def name(self) -> str:
        """The option's name as a plain ``str``."""
        return str(self)

    def declaration(self) -> tuple:
        """(name, type, help, flag): two declarations of one option must agree on all four."""
        return (str(self), self.type, self.help, self.flag)


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
    options : tuple of ReaderOption or str
        Reader options ``open_table`` accepts (``load(..., reader_options={...})``); each
        :class:`ReaderOption` is also a CLI flag of every command that reads a log.
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
    options: tuple[ReaderOption | str, ...] = ()
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


#: Shared by the bag and miniSEED lines (one option, one flag); ``load(..., temperature=...)`` takes it for
#: every format (a column), and passes it on to a reader that declares it.
TEMPERATURE = ReaderOption("temperature", str, "Temperature column [deg C] carried with the log (bag: a "
                                               "sensor_msgs/Temperature topic; miniSEED: a channel).")

_BAG_OPTIONS = (
    ReaderOption("topic", str, "Bag: the sensor_msgs/Imu topic."),
    ReaderOption("stamp", str, "Bag: time from 'header' stamps or 'receive' time."),
    TEMPERATURE,
    ReaderOption("fields", str, "Bag: channels analysed by default: gyro (default), accel or both."),
)

#: The formats fogdrift reads, in the order magic bytes (then sniffers) are tried; text is last.
READERS: tuple[ReaderSpec, ...] = (
    ReaderSpec("npy", "npy", magic=(b"\x93NUMPY",), extensions=(".npy",),
               description="NumPy .npy array"),
    ReaderSpec("npz", "npz", magic=(b"PK\x03\x04", b"PK\x05\x06"), extensions=(".npz",),
               description="NumPy .npz archive"),
    ReaderSpec("hdf5", "hdf5", magic=(b"\x89HDF\r\n\x1a\n",), extensions=(".h5", ".hdf5", ".hdf", ".he5"),
               options=(ReaderOption("dataset", str, "HDF5: dataset or group path, e.g. /imu."),),
               description="HDF5 file (h5py, extra [hdf5])"),
    ReaderSpec("mat", "matlab", magic=(b"MATLAB",), extensions=(".mat",),
               options=(ReaderOption("variable", str, "MATLAB .mat: variable name."),),
               description="MATLAB .mat v4/v5/v7 (scipy) or v7.3 (h5py)"),
    ReaderSpec("rosbag1", "rosbag", magic=(b"#ROSBAG V2.0",), extensions=(".bag",), options=_BAG_OPTIONS,
               description="ROS 1 bag (rosbags, extra [ros])"),
    ReaderSpec("rosbag2", "rosbag", magic=(b"\x89MCAP0\r\n", b"SQLite format 3\x00"), extensions=(".db3", ".mcap"),
               options=_BAG_OPTIONS, directory_marker="metadata.yaml",
               description="ROS 2 bag directory (rosbags, extra [ros])"),
    ReaderSpec("mseed", "mseed", extensions=(".mseed", ".miniseed", ".msd"),
               options=(ReaderOption("gain", str, "miniSEED: counts per unit, or a StationXML/dataless/RESP "
                                                  "response file."), TEMPERATURE),
               sniff=_looks_like_mseed, description="miniSEED (ObsPy, extra [seismo])"),
    ReaderSpec("binary", "binary",
               options=(ReaderOption("layout", str, "Raw binary record as NumPy dtype items, e.g. "
                                                    "'<u4 seq, <i4 gx, <i4 gy, <i4 gz'."),
                        ReaderOption("scale", str, "Raw binary: LSB factor for every field, or per field "
                                                   "'gx=1e-4,temp=0.01'."),
                        ReaderOption("header_bytes", int, "Raw binary: bytes before the first record."),
                        ReaderOption("sequence", str, "Raw binary: sequence-counter field (default "
                                                      "seq/counter/...; 'none').")),
               description="raw binary records, chosen by giving their layout= (or format='binary')"),
    ReaderSpec("text", "text", magic=(b"\x1f\x8b",),
               extensions=(".csv", ".txt", ".tsv", ".dat", ".log", ".gz"), options=("delimiter",),
               sniff=_looks_like_text, description="CSV/TXT text, optionally gzip"),
)


def cli_options(readers=None) -> tuple[ReaderOption, ...]:
    """Every :class:`ReaderOption` of the table, once each, in the order of first appearance.

    Parameters
    ----------
    readers : sequence of ReaderSpec, optional
        Default: :data:`READERS` as it is now (a plugged-in line counts).

    Raises
    ------
    ConfigError
        If two lines declare one option name differently (type, help or flag), or two options
        share a flag: an option shared by several formats is one declaration, one flag.
    """
    seen: dict[str, ReaderOption] = {}
    flags: dict[str, str] = {}
    for spec in READERS if readers is None else readers:
        for opt in spec.options:
            if not isinstance(opt, ReaderOption):
                continue  # a library-only option
            first = seen.setdefault(str(opt), opt)
            if first.declaration() != opt.declaration():
                raise ConfigError(f"reader option {str(opt)!r} is declared twice differently ({spec.name}: "
                                  f"{opt.declaration()[1:]}, before: {first.declaration()[1:]}); expected one "
                                  f"declaration shared by the formats")
            owner = flags.setdefault(opt.flag, str(opt))
            if owner != str(opt):
                raise ConfigError(f"reader options {owner!r} and {str(opt)!r} share the flag {opt.flag}; expected "
                                  f"one flag per option")
    return tuple(seen.values())


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
