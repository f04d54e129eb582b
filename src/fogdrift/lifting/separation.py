"""Drift/noise separation by separate reconstruction: :func:`separate` and the causal
(real-time) drift :func:`causal_drift`.

``drift = W^-1(cA_J, 0, ..., 0)`` and ``noise = W^-1(0, cD_J, ..., cD_1)`` with ``W`` the
J-level lifting transform (:mod:`fogdrift.lifting.transform`).  The level is an integer
here; :func:`~fogdrift.lifting.level_scan` and :func:`~fogdrift.lifting.choose_level`
(:mod:`fogdrift.lifting.levels`) resolve an automatic choice.
"""

from __future__ import annotations

import numbers

import numpy as np

from ..errors import ConfigError, InsufficientDataError
from ._drift import _drift_1d
from .schemes import get_wavelet
from .transform import _as_signal, _check_level, _check_mode

__all__ = ["separate", "causal_drift"]


def _symmetric_extension(arr: np.ndarray, level: int) -> np.ndarray:
    """Extend ``arr`` (axis 0) at its end by whole-sample reflection to a multiple of ``2**level`` samples.

    In symmetric mode a level of odd length amplifies the last drift samples (up to 9.3x the white-noise gain for
    db2 at J = 4, n = 16k + 1; :mod:`fogdrift.lifting.transform`); a record whose length is a multiple of
    ``2**level`` has even lengths at every level.  Reflecting ``x[n-2], x[n-3], ...`` keeps the extension as
    smooth as the record's end, and the drift is trimmed back to ``n`` samples afterwards.
    """
    n = arr.shape[0]
    pad = (-n) % (1 << level)
    if pad == 0:
        return arr
    idx = (n - 1) - (np.arange(1, pad + 1) % (2 * (n - 1)) if n > 1 else np.zeros(pad, int))
    idx = np.abs(idx)
    return np.concatenate([arr, arr[idx]], axis=0)


def separate(x, wavelet="db2", level=4, mode="periodization"):
    """Split a signal into a slow drift and a fast noise part by separate reconstruction.

    Parameters
    ----------
    x : array_like, shape (n,) or (n, n_axes)
        Signal (e.g. rate in deg/h); 2-D input is processed column by column along axis 0.
    wavelet : str or LiftingScheme
        A name from :func:`~fogdrift.lifting.wavelist` or a custom scheme.
    level : int
        Decomposition depth J (1 <= J <= :func:`~fogdrift.lifting.max_level`).  To choose it
        from the data, run ``choose_level(level_scan(x, dt_s, wavelet, mode=mode))`` first.
    mode : {"periodization", "symmetric"}
        Boundary rule (:mod:`fogdrift.lifting.transform`).

    Returns
    -------
    drift, noise : ndarray, same shape and unit as ``x``
        ``drift = W^-1(cA_J, 0, ..., 0)``, ``noise = W^-1(0, cD_J, ..., cD_1) = x - drift``.

    Raises
    ------
    ConfigError
        Level not an integer (``"auto"`` included: resolve it with
        :func:`~fogdrift.lifting.choose_level`), level too high (the message names the
        maximum), unknown wavelet or mode.
    DataFormatError
        Non-finite input (the message gives the index).

    Notes
    -----
    ``W^-1`` and the per-level padding/trimming are linear, so the noise is computed as
    ``x - drift`` (one inverse transform instead of two); the tests check it against the
    separate reconstruction ``W^-1(0, cD_J, ..., cD_1)`` in both modes and against
    PyWavelets' ``waverec`` on zeroed bands (periodization).  In periodization mode with
    ``n`` a multiple of ``2**J`` the drift is the orthogonal projection onto the level-J
    approximation space, so ``<drift, noise> = 0``.  The drift is non-causal (at J = 4,
    db2, it depends on up to 45 samples on either side); see :func:`causal_drift` for the
    real-time version.  About ``1/2**J`` of the variance of white noise stays in the drift
    (the approximation band keeps 1/2**J of the coefficients of an orthogonal transform).

    Examples
    --------
    >>> drift, noise = separate(np.full(64, 2.5), "db2", level=4)
    >>> bool(np.allclose(drift, 2.5) and np.allclose(noise, 0.0))
    True
    """
    scheme = get_wavelet(wavelet)
    mode = _check_mode(mode)
    if isinstance(level, str):
        raise ConfigError(
            f"separate() takes an integer level, got {level!r}; resolve it first with "
            "choose_level(level_scan(x, dt_s, wavelet, mode=mode)) and pass the result as {opt:level}"
        )
    arr = _as_signal(x, allow_2d=True)
    periodic = mode == "periodization"
    n = arr.shape[0]
    level = _check_level(level, n, scheme, mode)
    drift = np.empty(arr.shape)
    noise = np.empty(arr.shape)
    if not periodic and n % (1 << level):
        ext = _symmetric_extension(arr, level)
        cols = [ext] if ext.ndim == 1 else [np.ascontiguousarray(ext[:, k]) for k in range(ext.shape[1])]
        for k, c in enumerate(cols):
            d = _drift_1d(c, scheme, level, periodic)[:n]
            if arr.ndim == 1:
                drift[:] = d
            else:
                drift[:, k] = d
        np.subtract(arr, drift, out=noise)
    elif arr.ndim == 1:
        _drift_1d(arr, scheme, level, periodic, out=drift, noise=noise)
    else:
        for k in range(arr.shape[1]):
            c = np.ascontiguousarray(arr[:, k])
            d = _drift_1d(c, scheme, level, periodic)
            drift[:, k] = d
            noise[:, k] = c - d
    return drift, noise


def _drift_row_last(window: int, scheme, level: int, periodic: bool, block: int = 256) -> np.ndarray:
    """Weights g with ``drift(v)[-1] == g @ v`` for every v of length ``window``.

    Column i of the drift operator is the drift of the unit vector e_i; its last entry is
    g[i].  Computed on blocks of unit vectors (memory ``window * block``).
    """
    g = np.empty(window)
    for start in range(0, window, block):
        stop = min(window, start + block)
        for i in range(start, stop):
            e = np.zeros(window)
            e[i] = 1.0
            if not periodic:
                e = _symmetric_extension(e, level)
            g[i] = _drift_1d(e, scheme, level, periodic)[window - 1]
    return g


def causal_drift(x, window, wavelet="db2", level=4, mode="symmetric") -> np.ndarray:
    """Real-time (causal) drift: the last sample of the drift of a sliding window.

    ``drift[k]`` is the last sample of ``separate(x[k-window+1 : k+1], ...)[0]``, so it uses
    no sample later than k.  ``NaN`` for ``k < window - 1``.

    Parameters
    ----------
    x : array_like, shape (n,) or (n, n_axes)
    window : int
        Window length in samples; ``level`` must be allowed for it (see
        :func:`~fogdrift.lifting.max_level`).
    wavelet, level, mode
        As in :func:`separate`; the default ``"symmetric"`` avoids wrapping the window's
        start onto its end.

    Returns
    -------
    ndarray, same shape and unit as ``x``

    Raises
    ------
    ConfigError
        Bad window or level.
    InsufficientDataError
        ``window > n``.

    Notes
    -----
    The drift of a window is linear in the window, so its last sample is ``g @ window``
    with ``g`` the last row of the drift operator; ``g`` is computed once (``window``
    unit-vector separations) and then applied as a sliding dot product, which is exact to
    round-off and equal to the naive per-window separation.  ``||g||`` is the white-noise
    gain of the real-time drift; in symmetric mode choose a window that is a multiple of
    ``2**level``: db2, level 4, gives 0.41 with window 128 but 9.3 with window 129 (the
    symmetric-mode caveat of :mod:`fogdrift.lifting.transform`).

    Examples
    --------
    >>> x = np.full(300, 3.0)
    >>> d = causal_drift(x, 128, "db2", level=4)
    >>> bool(np.isnan(d[:127]).all() and np.allclose(d[127:], 3.0))
    True
    """
    scheme = get_wavelet(wavelet)
    mode = _check_mode(mode)
    arr = _as_signal(x, allow_2d=True)
    if isinstance(window, bool) or not isinstance(window, numbers.Integral) or window < 2:
        raise ConfigError(f"window must be an integer >= 2, got {window!r}")
    window = int(window)
    n = arr.shape[0]
    if window > n:
        raise InsufficientDataError(
            f"window {window} is longer than the record ({n} samples)", needed=window, got=n
        )
    level = _check_level(level, window, scheme, mode)
    g = _drift_row_last(window, scheme, level, mode == "periodization")
    out = np.full(arr.shape, np.nan)
    views = np.lib.stride_tricks.sliding_window_view(arr, window, axis=0)
    out[window - 1 :] = views @ g  # 2-D: views has shape (n - window + 1, n_axes, window)
    return out

