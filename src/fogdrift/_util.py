"""Small validation and serialisation helpers shared across layers (imports only numpy and errors)."""

from __future__ import annotations

import numpy as np

from .errors import ConfigError, DataFormatError


def check_series(y, name: str = "y", *, min_length: int = 1) -> np.ndarray:
    """Return ``y`` as a 1-D float64 array, or raise a clear error.

    Raises
    ------
    DataFormatError
        If ``y`` is not numeric, not 1-D, or holds NaN/inf (the message gives the first bad index).
    ConfigError
        If ``y`` is shorter than ``min_length``.
    """
    try:
        arr = np.asarray(y, dtype=np.float64)
    except (TypeError, ValueError):
        raise DataFormatError(f"{name} must be a numeric 1-D array, got {type(y).__name__}") from None
    if arr.ndim != 1:
        raise DataFormatError(f"{name} must be a 1-D series; expected shape (n_samples,), got {arr.shape}")
    bad = ~np.isfinite(arr)
    if bad.any():
        i = int(np.argmax(bad))
        raise DataFormatError(f"{name}[{i}] is {arr[i]!r}; expected finite values")
    if arr.size < min_length:
        raise ConfigError(f"{name} has {arr.size} samples; this model needs at least {min_length}")
    return arr


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
