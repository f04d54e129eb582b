"""A user's JSON or YAML document (a spec, a result, a bundle manifest, a model file, ``--components``) read within
limits: its size, the nesting depth of its lists and mappings, and the length of its numbers.

``json.loads`` recurses once per level (100 000 nested ``[`` end in a RecursionError) and Python refuses to
convert an integer of more than 4300 digits (a ValueError of its own); a YAML parser does both too.  No
fogdrift document is more than a few levels deep or holds a number of more than about 20 digits, so
:func:`loads` checks the text first and refuses with one line that names the line and what is wrong
(:class:`DocumentError`, a ValueError: the readers' one-line errors wrap it).

=============================  ===================================================  ===========================
Limit                          What                                                 Value
=============================  ===================================================  ===========================
``FOGDRIFT_MAX_DOCUMENT``      bytes of one JSON/YAML document (environment         64 MiB
                               variable; ``0``: no limit)
:data:`MAX_DEPTH`              lists/mappings inside each other                     64
:data:`MAX_DIGITS`             digits in one number                                 100
=============================  ===================================================  ===========================
"""

from __future__ import annotations

import json
import os
import re
from pathlib import Path

import numpy as np

from .errors import ConfigError

__all__ = ["DocumentError", "loads", "read", "MAX_DEPTH", "MAX_DIGITS", "ENV_DOCUMENT", "max_document_bytes"]

ENV_DOCUMENT = "FOGDRIFT_MAX_DOCUMENT"
DEFAULT_DOCUMENT = 64 << 20
#: Lists and mappings nested in each other, at most.
MAX_DEPTH = 64
#: Digits in one number, at most.
MAX_DIGITS = 100

#: Quoted strings (JSON's double quotes, YAML's single quotes too): brackets and digits inside them are text.
_STRINGS = re.compile(r'"(?:[^"\\\n]|\\.)*"|\'(?:[^\'\n]|\'\')*\'')
_LONG_NUMBER = re.compile(r"\d{%d,}" % (MAX_DIGITS + 1))


class DocumentError(ValueError):
    """A document over a limit, or unparsable: ``str()`` is one line, ``PATH:LINE: what is wrong``."""

    def __init__(self, message: str, path=None, line: int | None = None):
        self.reason = message
        self.path = path
        self.line = line
        where = f"{path}" if path is not None else ""
        where += f":{line}" if line is not None and where else (f"line {line}" if line is not None else "")
        super().__init__(f"{where}: {message}" if where else message)


_SIZE = re.compile(r"^\s*([0-9]*\.?[0-9]+(?:[eE][+-]?[0-9]+)?)\s*([kKmMgG]?)(?:i?[bB])?\s*$")


def max_document_bytes() -> int | None:
    """Bytes of one document, at most (``FOGDRIFT_MAX_DOCUMENT``, e.g. ``64M``; None: no limit)."""
    text = os.environ.get(ENV_DOCUMENT, "").strip()
    if not text:
        return DEFAULT_DOCUMENT
    m = _SIZE.match(text)
    if m is None:
        raise ConfigError(f"environment variable {ENV_DOCUMENT}={text!r}: expected a number >= 0 (bytes, or with K, "
                          "M, G: 64M)")
    value = float(m.group(1)) * {"": 1, "k": 1 << 10, "m": 1 << 20, "g": 1 << 30}[m.group(2).lower()]
    return None if value == 0 else int(min(value, 1 << 62))


def _line(text: str, pos: int) -> int:
    return text.count("\n", 0, pos) + 1


def check(text: str, path=None) -> None:
    """DocumentError when ``text`` nests deeper than :data:`MAX_DEPTH` or holds a number longer than
    :data:`MAX_DIGITS` digits (quoted strings are not looked into)."""
    bare = _STRINGS.sub(lambda m: " " * (m.end() - m.start()), text)  # same length: positions stay
    m = _LONG_NUMBER.search(bare)
    if m is not None:
        n = len(m.group(0))
        raise DocumentError(f"a number of {n} digits; expected at most {MAX_DIGITS} digits in a number (no fogdrift "
                            "setting needs more than about 20)", path, _line(text, m.start()))
    b = np.frombuffer(bare.encode("utf-32-le", "surrogatepass"), dtype="<u4")
    step = np.isin(b, (91, 123)).astype(np.int32) - np.isin(b, (93, 125)).astype(np.int32)
    if step.size:
        depth = np.cumsum(step)
        k = int(np.argmax(depth > MAX_DEPTH)) if depth.max(initial=0) > MAX_DEPTH else -1
        if k >= 0:
            raise DocumentError(f"lists/mappings nested more than {MAX_DEPTH} levels deep; expected a fogdrift "
                                "document (a few levels)", path, _line(text, k))


def loads(text: str, path=None, *, yaml: bool = False):
    """Parse JSON (or YAML with ``yaml=True``) text after :func:`check`; DocumentError on any failure of the
    limits (RecursionError, an integer too long to convert) -- syntax errors stay the parser's own."""
    check(text, path)
    try:
        if yaml:
            import yaml as _yaml

            return _yaml.safe_load(text)
        return json.loads(text)
    except RecursionError:
        raise DocumentError("nested too deeply to parse", path) from None
    except ValueError as exc:
        if "digits" in str(exc) and not isinstance(exc, json.JSONDecodeError):
            raise DocumentError(f"a number too long to read ({exc})", path) from None
        raise


def read(path, *, yaml: bool | None = None):
    """Read and parse the document at ``path`` (YAML when ``yaml``, by default for a ``.yaml``/``.yml`` name)
    within the limits (size first: refused before it is read)."""
    p = Path(path)
    limit = max_document_bytes()
    size = os.stat(p).st_size
    if limit is not None and size > limit:
        raise DocumentError(f"{size} bytes; expected a JSON/YAML document of at most {limit} bytes ({ENV_DOCUMENT}; "
                            "raise it with that environment variable, 0: no limit)", p)
    text = p.read_text(encoding="utf-8")
    return loads(text, p, yaml=p.suffix.lower() in (".yaml", ".yml") if yaml is None else yaml)
