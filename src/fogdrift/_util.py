"""Small validation and serialisation helpers shared across layers (imports only numpy and errors, so that every
module, :mod:`fogdrift.output` included, can use them)."""

from __future__ import annotations

import json
import math
import re
import secrets

import numpy as np

from .errors import ConfigError, DataFormatError, InsufficientDataError


def check_series(y, name: str = "y", *, min_length: int = 1, allow_2d: bool = False, needed_by: str = "",
                 hint: str = "") -> np.ndarray:
    """Return ``y`` as a C-contiguous float64 array of samples, or raise a clear error.

    The one series validator of the package (models, metrics and the lifting transform call it), so that
    the same fault gives the same message everywhere.

    Parameters
    ----------
    y : array_like
        The series, shape ``(n_samples,)`` (or ``(n_samples, n_axes)`` with ``allow_2d``).
    name : str
        Name used in the messages (the argument name the caller documents).
    min_length : int
        Fewest samples accepted (``0`` accepts an empty series).
    allow_2d : bool
        Accept ``(n_samples, n_axes)`` as well.
    needed_by : str
        What needs ``min_length`` samples, e.g. ``"this model"``; named in the too-short message.
    hint : str
        Appended to the non-finite message, e.g. how to drop warm-up NaN.

    Returns
    -------
    numpy.ndarray
        float64, C-contiguous, same shape.

    Raises
    ------
    DataFormatError
        Not numeric, wrong number of dimensions, or NaN/inf (the message gives the first bad index).
    InsufficientDataError
        Fewer than ``min_length`` samples.

    Examples
    --------
    >>> check_series([1, 2, 3]).tolist()
    [1.0, 2.0, 3.0]
    >>> check_series([[1.0, 2.0]], "x")
    Traceback (most recent call last):
    ...
    fogdrift.errors.DataFormatError: x must be a 1-D series of shape (n_samples,); got shape (1, 2)
    >>> check_series([0.0, float("nan")], "y_test")
    Traceback (most recent call last):
    ...
    fogdrift.errors.DataFormatError: y_test[1] is nan; expected finite values
    >>> check_series([1.0], "y_train", min_length=3, needed_by="this model")
    Traceback (most recent call last):
    ...
    fogdrift.errors.InsufficientDataError: y_train has 1 samples; this model needs at least 3
    """
    try:
        arr = np.asarray(y, dtype=np.float64)
    except (TypeError, ValueError):
        raise DataFormatError(f"{name} must be a numeric series; got {type(y).__name__}") from None
    if arr.ndim == 0 or arr.ndim > (2 if allow_2d else 1):
        want = "1-D (n_samples,) or 2-D (n_samples, n_axes)" if allow_2d else "a 1-D series of shape (n_samples,)"
        raise DataFormatError(f"{name} must be {want}; got shape {arr.shape}")
    bad = ~np.isfinite(arr)
    if bad.any():
        idx = np.unravel_index(int(np.argmax(bad)), arr.shape)
        where = ", ".join(str(int(i)) for i in idx)
        raise DataFormatError(f"{name}[{where}] is {float(arr[idx])!r}; expected finite values{hint}")
    n = int(arr.shape[0])
    if n < min_length:
        who = f"{needed_by} needs" if needed_by else "expected"
        raise InsufficientDataError(f"{name} has {n} samples; {who} at least {min_length}", needed=min_length, got=n)
    return np.ascontiguousarray(arr)


def check_count(value, name: str = "n_samples", minimum: int = 2) -> int:
    """``value`` as an int ``>= minimum`` (an integral float is accepted), or a ConfigError naming ``name``.

    >>> check_count(4.0), check_count(10, "levels", 1)
    (4, 10)
    """
    try:
        n = int(value)
    except (TypeError, ValueError):
        raise ConfigError(f"{name} must be an integer >= {minimum}, got {value!r}") from None
    if n != value or n < minimum:
        raise ConfigError(f"{name} must be an integer >= {minimum}, got {value!r}")
    return n


def json_default(obj):
    """``json.dumps(default=...)`` hook: numpy scalars and arrays, objects with ``to_dict()``."""
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if hasattr(obj, "to_dict"):
        return obj.to_dict()
    raise TypeError(f"not JSON-serialisable: {type(obj).__name__}")


def fmt_number(x, digits: int = 4, *, missing: str = "–", nonfinite: str | None = "–", sci_outside=None,
               whole_below: float | None = None, zero: str | None = "0", float_literal: bool = False) -> str:
    """A number as a table or text cell: the one number formatter of the reports, the console and the fleet page.

    Parameters
    ----------
    x : float, int, str or None
        The number (a text cell, such as a bound ``"< 7.06"``, comes back as it is).
    digits : int
        Significant digits (``f"{x:.{digits}g}"``).
    missing : str
        Cell of None.
    nonfinite : str or None
        Cell of NaN and infinity; None formats them as Python does (``nan``, ``inf``).
    sci_outside : (float, float), optional
        ``(lo, hi)``: values with ``|x| < lo`` or ``|x| >= hi`` (except 0) in scientific notation with ``digits``
        significant digits, ``0`` as ``"0"``.
    whole_below : float, optional
        Whole numbers with ``1e4 <= |x| < whole_below`` written without decimals (counts, sample numbers).
    zero : str or None
        Cell of ``0`` under ``sci_outside``; None writes it by the ``g`` rule (``-0.0`` as ``"-0"``).
    float_literal : bool
        Put a dot in a mantissa that has none (``1e-05`` as ``1.0e-05``, ``2`` as ``2.0``), so that every YAML
        parser reads the text as a float; ``nan`` and ``inf`` stay as they are.

    Examples
    --------
    >>> fmt_number(2.41234), fmt_number(None), fmt_number(float("nan")), fmt_number("< 7.1")
    ('2.412', '–', '–', '< 7.1')
    >>> fmt_number(12345.0, sci_outside=(1e-3, 1e4)), fmt_number(0.0, sci_outside=(1e-3, 1e4))
    ('1.234e+04', '0')
    >>> fmt_number(360000.0, whole_below=1e9), fmt_number(0.5, 3)
    ('360000', '0.5')
    >>> fmt_number(1e-5, 6, float_literal=True), fmt_number(-0.0, 3, sci_outside=(1e-3, 1e4), zero=None)
    ('1.0e-05', '-0')
    """
    if x is None:
        return missing
    if isinstance(x, str):
        return x
    x = float(x)
    if not math.isfinite(x) and nonfinite is not None:
        return nonfinite
    if sci_outside is not None and math.isfinite(x):
        if x == 0:
            if zero is not None:
                return zero
        elif abs(x) < sci_outside[0] or abs(x) >= sci_outside[1]:
            return f"{x:.{digits - 1}e}"
    if whole_below is not None and 1e4 <= abs(x) < whole_below and x == round(x):
        return f"{x:.0f}"
    s = f"{x:.{digits}g}"
    if float_literal and math.isfinite(x):
        mant, _, exp = s.partition("e")
        if "." not in mant:
            s = mant + ".0" + ("e" + exp if exp else "")
    return s


def strict_json(obj, *, indent: int | None = 2, sort_keys: bool = False) -> str:
    """``obj`` as strict JSON text (RFC 8259): numpy values and ``to_dict()`` objects converted
    (:func:`json_default`), NaN and infinity written as ``null``, never as the non-standard ``NaN``/``Infinity``.

    The one strict-JSON serialiser: :func:`fogdrift.report.files.write_json` writes its text atomically (every
    result file), :mod:`fogdrift.output` its manifest.

    With ``indent``, objects and lists of objects are indented and a list of numbers (a curve, a table column)
    is written on one line: the same JSON value, a file a person can read (a 25 000-tau curve is not 25 000 lines),
    written by the C encoder instead of Python's indenting one.

    >>> import numpy as np
    >>> strict_json({"tau_s": np.float64(2.0), "edf": float("nan"), "m": np.arange(2)}, indent=None)
    '{"tau_s": 2.0, "edf": null, "m": [0, 1]}'
    >>> print(strict_json({"m": [1, 2, None], "axes": [{"name": "gx"}]}, indent=1))
    {
     "m": [1, 2, null],
     "axes": [
      {
       "name": "gx"
      }
     ]
    }
    """
    rows: list[str] | None = None if indent is None else []
    mark = f"@{secrets.token_hex(8)}:"  # a placeholder no value of the document can hold by chance
    text = json.dumps(_plain(obj, rows, mark), indent=indent, sort_keys=sort_keys, allow_nan=False)
    if not rows:
        return text
    return re.sub(f'"{re.escape(mark)}(\\d+)"', lambda m: rows[int(m.group(1))], text)


class RawJson:
    """A JSON value already encoded: :func:`strict_json` writes ``text`` as it is (with ``indent``, on one line, where a
    list of numbers goes), or its decoded value without ``indent``.  The writer that made ``text`` vouches for it
    (strict JSON, no NaN)."""

    __slots__ = ("text",)

    def __init__(self, text: str):
        self.text = text


#: The element types of a list that :func:`_plain` takes as a list of plain numbers (bool is not one: ``True`` is
#: written as ``true``).
_PLAIN_NUMBERS = frozenset({float, int, type(None)})


def _plain(x, rows, mark):
    """``x`` as plain JSON values (dict with str keys, list, str, int, float, bool, None), NaN and infinity as
    None, in one walk: what ``json.loads(json.dumps(x, default=json_default))`` gives with non-finite numbers
    read as null.  With ``rows`` (a list), a non-empty list of numbers and nulls is encoded into ``rows`` and
    replaced by ``mark`` + its index (written on one line by :func:`strict_json`)."""
    if isinstance(x, np.ndarray) and x.dtype.kind in "fiub" and x.ndim == 1:
        vals = x.tolist()
        if x.dtype.kind == "f" and not np.isfinite(x).all():
            for i in np.flatnonzero(~np.isfinite(x)).tolist():
                vals[i] = None
        if rows is None or not vals or x.dtype.kind == "b":
            return vals
        rows.append(json.dumps(vals, allow_nan=False))
        return f"{mark}{len(rows) - 1}"
    if isinstance(x, dict):
        return {k if isinstance(k, str) else _key(k): _plain(v, rows, mark) for k, v in x.items()}
    if isinstance(x, RawJson):
        if rows is None:
            return json.loads(x.text)
        rows.append(x.text)
        return f"{mark}{len(rows) - 1}"
    if isinstance(x, (list, tuple)):
        kinds = set(map(type, x))
        if x and kinds <= _PLAIN_NUMBERS:
            # a list of plain numbers (a curve as a list): the walk below, without a Python call per number
            if kinds == {int} or (kinds == {float} and all(map(math.isfinite, x))):
                vals = list(x)
            else:
                vals = [None if type(v) is float and not math.isfinite(v) else v for v in x]
        else:
            vals = [_plain(v, rows, mark) for v in x]
        if rows is not None and vals and set(map(type, vals)) <= _PLAIN_NUMBERS:
            rows.append(json.dumps(vals, allow_nan=False))
            return f"{mark}{len(rows) - 1}"
        return vals
    if isinstance(x, np.generic):
        x = x.item()
    if isinstance(x, float):
        return float(x) if math.isfinite(x) else None
    if x is None or isinstance(x, (str, int)):
        return int(x) if type(x) not in (int, bool) and isinstance(x, int) else x
    if isinstance(x, np.ndarray):
        return _plain(x.tolist(), rows, mark)
    return _plain(json_default(x), rows, mark)


def _key(k) -> str:
    """A non-str dict key as JSON writes it (``1`` -> ``"1"``, ``True`` -> ``"true"``, ``None`` -> ``"null"``)."""
    if not (k is None or isinstance(k, (int, float))):
        raise TypeError(f"keys must be str, int, float, bool or None, not {type(k).__name__}")
    return json.dumps(k)


def safe_name(name) -> str:
    """An axis, model or file name as a file-name part: runs of characters other than ASCII letters, digits,
    ``.``, ``_`` and ``-`` become one ``_`` (deterministic; no path separator), ``"_"`` if nothing is left.

    The one sanitiser of output names (figures, bundle, compensated files, fleet folders); two names that map to
    the same part are refused where they are made (:func:`check_distinct_names`), never silently overwritten.

    Examples
    --------
    >>> safe_name("g x"), safe_name("gyro/z"), safe_name("../x"), safe_name("")
    ('g_x', 'gyro_z', 'x', '_')
    """
    return re.sub(r"[^A-Za-z0-9._-]+", "_", str(name)).strip("._") or "_"


def check_distinct_names(names, what: str = "axis names", hint: str = "") -> None:
    """Refuse names that :func:`safe_name` maps to one output name (``g x`` and ``g_x``; ``a b.csv``, ``a_b.csv``).

    Examples
    --------
    >>> check_distinct_names(["gx", "gy"])
    >>> check_distinct_names(["g x", "g_x"])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    fogdrift.errors.ConfigError: axis names 'g x' and 'g_x' would share the output name 'g_x'...
    """
    seen: dict[str, str] = {}
    for n in names:
        key = safe_name(n).lower()  # also distinct on a case-insensitive file system
        if key in seen and seen[key] != str(n):
            raise ConfigError(f"{what} {seen[key]!r} and {str(n)!r} would share the output name "
                              f"{safe_name(n)!r}; their files would overwrite each other" + (f"; {hint}" if hint else ""))
        seen.setdefault(key, str(n))
