"""Exception and warning hierarchy of fogdrift.

Every error a user can cause (bad file, bad parameter, too little data) is a
:class:`FogdriftError`; the CLI prints its message as one line and exits 1.
Messages follow ``<path>:<line>:<column>: <what is wrong>; expected <rule>, got <value>``
where a location applies.  This module imports nothing from fogdrift.

Options in messages.  A message that tells the user which setting to change names it as
``{opt:NAME}`` where ``NAME`` is the library parameter (``{opt:unit}``, ``{opt:gaps}``).
``str(error)`` renders it as ``NAME=`` (the library spelling); the CLI renders the same error
with :meth:`FogdriftError.render` and its table of flags, so the user reads ``--unit``.  One
message, two audiences, no CLI knowledge in the library.
"""

from __future__ import annotations

import re

__all__ = [
    "FogdriftError",
    "DataFormatError",
    "InsufficientDataError",
    "ConfigError",
    "NotFittedError",
    "ModelFileError",
    "ResourceLimitError",
    "ResourceError",
    "FogdriftWarning",
]


_OPT = re.compile(r"\{opt:([A-Za-z_][A-Za-z0-9_]*)\}")


def render_options(text: str, flags: dict | None = None) -> str:
    """Replace ``{opt:NAME}`` markers by ``flags[NAME]`` (or ``NAME=`` when not in ``flags``).

    Examples
    --------
    >>> render_options("no unit given; pass {opt:unit}")
    'no unit given; pass unit='
    >>> render_options("no unit given; pass {opt:unit}", {"unit": "--unit"})
    'no unit given; pass --unit'
    """
    flags = flags or {}
    return _OPT.sub(lambda m: flags.get(m.group(1), m.group(1) + "="), text)


class FogdriftError(Exception):
    """Root of every error fogdrift raises on purpose.

    The message may name settings as ``{opt:NAME}`` (see the module docstring).
    """

    def __str__(self) -> str:
        return render_options(super().__str__())

    def render(self, flags: dict | None = None) -> str:
        """The message with ``{opt:NAME}`` markers rendered through ``flags`` (e.g. CLI flags)."""
        return render_options(super().__str__(), flags)


def _location(path, line, column) -> str:
    parts = [str(p) for p in (path, line, column) if p is not None]
    return ":".join(parts)


class DataFormatError(FogdriftError, ValueError):
    """Input data are malformed (empty, non-numeric, NaN, unsorted time, gaps, bad unit).

    Parameters
    ----------
    message : str
        What is wrong, ideally ``"<problem>; expected <rule>, got <value>"``.
    path, line, column : optional
        Where it is wrong. ``line`` is 1-based and counts every physical line of the
        file (header included); ``column`` is 1-based or a column name.
    """

    def __init__(self, message: str, *, path=None, line=None, column=None):
        self.path = None if path is None else str(path)
        self.line = line
        self.column = column
        self.reason = message
        where = _location(self.path, line, column)
        super().__init__(f"{where}: {message}" if where else message)


class InsufficientDataError(FogdriftError, ValueError):
    """The record is too short for the requested analysis."""

    def __init__(self, message: str, *, needed=None, got=None, path=None):
        self.needed = needed
        self.got = got
        self.path = None if path is None else str(path)
        prefix = f"{self.path}: " if self.path else ""
        super().__init__(prefix + message)


class ConfigError(FogdriftError, ValueError):
    """A parameter value is invalid (names the parameter, the rule and the value)."""


class NotFittedError(FogdriftError, AttributeError):
    """A model method that needs ``fit`` was called before ``fit``."""


class ModelFileError(FogdriftError, ValueError):
    """A saved model file is missing, corrupt, of another format version or another class."""


class ResourceLimitError(DataFormatError):
    """An input exceeds a reading limit (rows, line length, decompressed size, memory budget).

    The message names the file, the limit, its value and how to raise it (an environment
    variable, see :mod:`fogdrift.io.readers.limits`).  A :class:`DataFormatError`: the file is
    refused before it can exhaust memory or time.

    Parameters
    ----------
    message : str
        What exceeded which limit, and how to raise it.
    limit : str, optional
        Name of the environment variable that sets the limit (``"FOGDRIFT_MAX_ROWS"``).
    path, line, column : optional
        Where (as :class:`DataFormatError`).
    """

    def __init__(self, message: str, *, limit=None, path=None, line=None, column=None):
        self.limit = limit
        super().__init__(message, path=path, line=line, column=column)


class ResourceError(FogdriftError, RuntimeError):
    """The machine ran out of a resource during a run (memory, disk space): not the input's fault.

    Never cached as a result (a re-run with more memory or space may succeed).
    """


class FogdriftWarning(UserWarning):
    """Base class of fogdrift's warnings."""
