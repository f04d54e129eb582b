"""SHA-256 of input files: a utility for whole files and a stream wrapper that hashes while a reader reads.

Readers record the hash of the bytes they stream through :func:`hashing_stream` (text, gzip)
or of the bytes they read once anyway (``.npz``); a memory-mapped ``.npy`` is hashed by
:func:`file_sha256` in chunks, its only full read.  The hash is always of the file's bytes as
stored (a ``.csv.gz`` is hashed compressed), so it equals ``sha256sum <file>``.
"""

from __future__ import annotations

import hashlib
import io
from pathlib import Path
from typing import Callable

from ..errors import DataFormatError
from ._checks import check_path

__all__ = ["file_sha256", "hashing_stream", "path_sha256"]

#: Bytes per read when hashing a whole file (a reused buffer: no large temporaries).
_CHUNK = 1 << 18


def file_sha256(path) -> str:
    """Hex SHA-256 of a file's bytes (read in 256 KiB chunks into one reused buffer).

    :func:`fogdrift.io.load` records the hash while reading (``GyroRecord.sha256``); use
    this only for files that are not loaded.

    Raises
    ------
    DataFormatError
        If the file does not exist or cannot be read.

    Examples
    --------
    >>> import os, tempfile
    >>> p = os.path.join(tempfile.mkdtemp(), "x.txt")
    >>> with open(p, "wb") as fh:
    ...     _ = fh.write(b"abc")
    >>> file_sha256(p)[:16]
    'ba7816bf8f01cfea'
    """
    p = check_path(path)
    h = hashlib.sha256()
    buf = bytearray(_CHUNK)
    view = memoryview(buf)
    try:
        with open(p, "rb", buffering=0) as fh:
            while n := fh.readinto(buf):
                h.update(view[:n])
    except OSError as exc:
        raise DataFormatError(
            f"cannot read file; expected a readable file, got {exc.strerror or exc}", path=p
        ) from exc
    return h.hexdigest()


def path_sha256(path) -> str:
    """SHA-256 of a file (as :func:`file_sha256`), or of a directory in a directory format (ROS 2 bag).

    A directory's hash is the SHA-256 of the text ``"<relative path> <file sha256>\n"`` for every
    file below it, in sorted path order: it changes when any file's name or bytes change.

    Raises
    ------
    DataFormatError
        If the path does not exist or cannot be read.
    """
    p = Path(path)
    if not p.is_dir():
        return file_sha256(p)
    lines = []
    for f in sorted(q for q in p.rglob("*") if q.is_file()):
        lines.append(f"{f.relative_to(p).as_posix()} {file_sha256(f)}\n")
    return hashlib.sha256("".join(lines).encode("utf-8")).hexdigest()


class _HashingRaw(io.RawIOBase):
    """Raw binary stream over a file that feeds every byte read to SHA-256.

    When a read returns no bytes (end of file) ``on_eof(hexdigest)`` is called once: only a
    stream read to its end from the start has seen every byte.
    """

    def __init__(self, path: Path, on_eof: Callable[[str], None]):
        self._fh = open(path, "rb", buffering=0)
        self._hash = hashlib.sha256()
        self._on_eof = on_eof
        self._done = False

    def readable(self) -> bool:
        return True

    def readinto(self, b) -> int:
        n = self._fh.readinto(b)
        if n:
            self._hash.update(memoryview(b)[:n])
        elif n == 0 and not self._done:
            self._done = True
            self._on_eof(self._hash.hexdigest())
        return n

    def close(self) -> None:
        if not self.closed:
            self._fh.close()
        super().close()


def hashing_stream(path: Path, on_eof: Callable[[str], None], buffer_size: int = 1 << 20) -> io.BufferedReader:
    """Buffered binary stream over ``path`` that calls ``on_eof(sha256 hex)`` when read to the end.

    Wrap it (``gzip.GzipFile(fileobj=...)``, ``io.TextIOWrapper``) to decode; the hash is of
    the raw file bytes underneath.
    """
    return io.BufferedReader(_HashingRaw(path, on_eof), buffer_size)
