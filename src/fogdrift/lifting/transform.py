"""Lifting wavelet transform: one level (:func:`lift`, :func:`unlift`) and multilevel
(:func:`wavedec`, :func:`waverec`), both boundary modes, and the level rule :func:`max_level`.

Boundary modes
--------------
``"periodization"``
    Channel indices wrap around.  Every level works on an even length: an odd length is
    made even by repeating its last sample, exactly like :func:`pywt.dwt`; the inverse
    trims back to the stored length.  Coefficients equal
    ``pywt.wavedec(x, name, mode="periodization", level=J)`` band by band (PyWavelets
    documentation, "Signal extension modes").
``"symmetric"``
    A step that needs a neighbour outside the other channel reflects the index
    (whole-sample symmetric, ``i -> -i``, ``i -> 2(m-1) - i``).  Nothing is padded, there are
    exactly N coefficients and there is no wrap-around from the end of the record to its
    start.  Not equal to PyWavelets' ``mode="symmetric"`` (an expansive convolution).  The
    periodization alignment (input shift, detail shift) is not applied; the detail sign is.
    Each step is inverted exactly with the same reflection, so reconstruction is perfect
    for any length (Daubechies & Sweldens 1998), but the transform is not orthogonal.

    Caveat (measured, ``tests/lifting/test_lifting_symmetric.py``): when a level has an odd length,
    the reflected steps amplify the last samples of the drift.  White-noise gain of the
    last drift sample (norm of the last row of the drift operator) at J = 4, over the 16
    residues of n mod 16 (the same for n = 256..271 and 1024..1039): db2 0.41 for n a
    multiple of 16 but up to 9.3 (n = 16k + 1); db4 0.20 .. 1.38; haar 0.25 .. 1.39;
    periodization: db2 0.33 .. 0.48, db4 0.21 .. 0.26.  Records (and causal windows)
    whose length is a multiple of ``2**J`` have even lengths at every level and do not show
    it, so :func:`~fogdrift.lifting.separate` and :func:`~fogdrift.lifting.causal_drift`
    extend a record by whole-sample reflection to such a length before separating it and
    trim the result (last-sample gain then 0.26 .. 0.43 for db2, 0.22 .. 0.40 for db4).

Units: the transform is unit-agnostic (coefficients carry the unit of ``x``).
"""

from __future__ import annotations

import math
import numbers

import numpy as np

from ..errors import ConfigError, DataFormatError
from .._util import check_series
from ._kernels import _merge, _split, _step, _step_arrays
from .schemes import LiftingScheme, get_wavelet

__all__ = ["MODES", "max_level", "lift", "unlift", "wavedec", "waverec"]

MODES = ("periodization", "symmetric")


def _check_mode(mode) -> str:
    if mode not in MODES:
        raise ConfigError(f"unknown boundary mode {mode!r}; expected one of {list(MODES)}")
    return mode


def max_level(n: int, wavelet="db2", mode="periodization") -> int:
    """Largest decomposition level allowed for ``n`` samples.

    The rule is PyWavelets' ``dwt_max_level`` in both modes:
    ``J_max = floor(log2(n / (L - 1)))`` with ``L`` the filter length (haar 2, db2 4, db4 8),
    i.e. level J needs ``n >= (L - 1) * 2**J`` samples (db2: ``3 * 2**J``; level 4 needs 48).
    ``0`` when ``n < L - 1``.

    Examples
    --------
    >>> max_level(47), max_level(48)
    (3, 4)
    >>> max_level(112, "db4")
    4
    """
    scheme = get_wavelet(wavelet)
    _check_mode(mode)
    return _max_level(int(n), scheme)


def _max_level(n: int, scheme: LiftingScheme) -> int:
    lm1 = int(scheme.filter_length) - 1
    if n < lm1 or n < 1:
        return 0
    j = int(math.floor(math.log2(n / lm1)))
    # guard against floating-point error in log2 at exact powers of two
    while (j + 1) >= 0 and lm1 * 2 ** (j + 1) <= n:
        j += 1
    while j > 0 and lm1 * 2**j > n:
        j -= 1
    return max(j, 0)


# --------------------------------------------------------------------------------------
# One level, private (inputs already validated, 1-D float64 contiguous)
# --------------------------------------------------------------------------------------


def _raw_forward(x, scheme, periodic):
    """Split and lift: returns the scaled (s, d) channels before the detail alignment.

    Periodization applies the padding and the input shift; symmetric applies neither.
    """
    n = x.shape[0]
    if periodic:
        n_pad = n + (n & 1)
        h = n_pad // 2
        e = np.empty(h)
        o = np.empty(h)
        _split(x, n_pad, scheme.input_shift % n_pad, e, o)
    else:
        e = np.empty((n + 1) // 2)
        o = np.empty(n // 2)
        _split(x, n, 0, e, o)
    for is_predict, offs, coefs in _step_arrays(scheme):
        if is_predict:
            _step(o, e, offs, coefs, periodic)
        else:
            _step(e, o, offs, coefs, periodic)
    e *= scheme.scale_approx
    o *= scheme.scale_detail
    return e, o


def _forward(x, scheme, periodic, need_detail=True):
    s, d = _raw_forward(x, scheme, periodic)
    if not need_detail:
        return s, None
    if periodic and scheme.detail_shift % d.shape[0]:
        d = np.roll(d, -scheme.detail_shift)
    if scheme.detail_sign < 0:
        np.negative(d, out=d)
    return s, d


def _inverse(ca, cd, scheme, periodic, n, out=None):
    """Inverse of one level; ``cd=None`` means an all-zero detail band; output length n."""
    e = ca / scheme.scale_approx
    h_o = ca.shape[0] if periodic else n // 2
    if cd is None:
        o = np.zeros(h_o)
    else:
        o = cd * (scheme.detail_sign / scheme.scale_detail)
        if periodic and scheme.detail_shift % h_o:
            o = np.roll(o, scheme.detail_shift)
    for is_predict, offs, coefs in reversed(_step_arrays(scheme)):
        if is_predict:
            _step(o, e, offs, -coefs, periodic)
        else:
            _step(e, o, offs, -coefs, periodic)
    if out is None:
        out = np.empty(n)
    shift = (scheme.input_shift % (2 * e.shape[0])) if periodic else 0
    _merge(e, o, shift, out)
    return out


def _band_lengths(n: int, level: int, periodic: bool) -> list[int]:
    """Signal length entering each level: [n, n_1, ..., n_{level-1}] and the final cA length."""
    lens = [n]
    for _ in range(level):
        lens.append((lens[-1] + 1) // 2)
    return lens


# --------------------------------------------------------------------------------------
# Validation helpers
# --------------------------------------------------------------------------------------


def _as_signal(x, name="x", allow_2d=False) -> np.ndarray:
    """The lifting transform's input check: the package's one series validator, at least 2 samples."""
    return check_series(x, name, min_length=2, allow_2d=allow_2d, needed_by="a wavelet level")


def _check_level(level, n, scheme, mode) -> int:
    if isinstance(level, bool) or not isinstance(level, numbers.Integral):
        raise ConfigError(f"level must be a positive integer, got {level!r}")
    level = int(level)
    jmax = _max_level(n, scheme)
    if level < 1:
        raise ConfigError(f"level must be >= 1, got {level}")
    if level > jmax:
        fix = f"pass {{opt:level}} {jmax} or lower" if jmax >= 1 else "use a longer record"
        raise ConfigError(
            f"level {level} is too high for {n} samples with {scheme.name!r}; the maximum is "
            f"{jmax} (rule: level J needs n >= (L-1)*2**J = {scheme.filter_length - 1}*2**J); {fix}"
        )
    return level


# --------------------------------------------------------------------------------------
# Public transform
# --------------------------------------------------------------------------------------


def lift(x, wavelet="db2", mode="periodization") -> tuple[np.ndarray, np.ndarray]:
    """One level of the forward lifting wavelet transform.

    Parameters
    ----------
    x : array_like, shape (n,)
        Signal, n >= 2, finite.
    wavelet : str or LiftingScheme
        A name from :func:`~fogdrift.lifting.wavelist` or a custom scheme.
    mode : {"periodization", "symmetric"}
        Boundary rule (module docstring).

    Returns
    -------
    approx, detail : ndarray
        Periodization: both of length ``ceil(n/2)``, equal to
        ``pywt.dwt(x, wavelet, mode="periodization")``.  Symmetric: lengths ``ceil(n/2)``
        and ``floor(n/2)``.

    Raises
    ------
    DataFormatError
        Not 1-D or non-finite values (the message gives the index).
    ConfigError
        Unknown wavelet or mode.

    Notes
    -----
    db2 uses the Daubechies–Sweldens (1998) update-first factorisation with PyWavelets'
    periodization alignment: ``x' = roll(x, 1)``, lift, then ``cA = s`` and
    ``cD = -roll(d, -1)`` (the scheme table, :mod:`fogdrift.lifting.schemes`, gives each
    wavelet's alignment).

    Examples
    --------
    >>> a, d = lift([1.0, 2.0, 3.0, 4.0], "haar")
    >>> np.round(a, 10).tolist(), np.round(d, 10).tolist()
    ([2.1213203436, 4.9497474683], [-0.7071067812, -0.7071067812])
    """
    scheme = get_wavelet(wavelet)
    mode = _check_mode(mode)
    x = _as_signal(x)
    return _forward(x, scheme, mode == "periodization")


def unlift(approx, detail, wavelet="db2", mode="periodization", length=None) -> np.ndarray:
    """Inverse of :func:`lift`.

    Parameters
    ----------
    approx, detail : array_like, shape (h,) and (h,) or (h - 1,)
        Coefficient bands.  Periodization needs equal lengths; symmetric needs
        ``len(approx) - len(detail)`` in {0, 1}.
    wavelet, mode
        As in :func:`lift`.
    length : int, optional
        Output length.  Periodization: default ``2*len(detail)``; pass ``2h - 1`` to undo
        the padding of an odd-length input.  Symmetric: must be ``len(approx) + len(detail)``.

    Returns
    -------
    ndarray, shape (length,)

    Raises
    ------
    ConfigError
        Inconsistent band lengths or ``length``.
    """
    scheme = get_wavelet(wavelet)
    mode = _check_mode(mode)
    a = _as_signal(approx, "approx") if np.size(approx) > 1 else np.asarray(approx, float).ravel()
    d = _as_signal(detail, "detail") if np.size(detail) > 1 else np.asarray(detail, float).ravel()
    if not (np.isfinite(a).all() and np.isfinite(d).all()):
        raise DataFormatError("approx/detail hold non-finite values")
    periodic = mode == "periodization"
    h = a.shape[0]
    if periodic:
        if d.shape[0] != h:
            raise ConfigError(
                f"periodization needs len(approx) == len(detail); got {h} and {d.shape[0]}"
            )
        n = 2 * h if length is None else int(length)
        if n not in (2 * h, 2 * h - 1):
            raise ConfigError(f"length must be {2 * h} or {2 * h - 1} for {h} coefficients, got {length}")
    else:
        if h - d.shape[0] not in (0, 1):
            raise ConfigError(
                f"symmetric needs len(approx) - len(detail) in {{0, 1}}; got {h} and {d.shape[0]}"
            )
        n = h + d.shape[0]
        if length is not None and int(length) != n:
            raise ConfigError(f"symmetric: length must be len(approx)+len(detail)={n}, got {length}")
    return _inverse(a, d, scheme, periodic, n)


def wavedec(x, wavelet="db2", level=4, mode="periodization") -> list[np.ndarray]:
    """Multilevel forward lifting transform.

    Parameters
    ----------
    x : array_like, shape (n,)
        Finite signal.
    wavelet : str or LiftingScheme
    level : int
        1 <= level <= :func:`max_level` ``(n)``.
    mode : {"periodization", "symmetric"}

    Returns
    -------
    list of ndarray
        ``[cA_J, cD_J, cD_{J-1}, ..., cD_1]`` (PyWavelets order).  Periodization: equal to
        ``pywt.wavedec(x, wavelet, mode="periodization", level=J)``; every level pads an odd
        length with its last sample, so band lengths are ``ceil(n_j / 2)``.

    Raises
    ------
    ConfigError
        Level out of range (the message names the maximum), unknown wavelet or mode.
    DataFormatError
        Non-finite input (the message gives the index).

    Examples
    --------
    >>> [len(c) for c in wavedec(np.arange(101.0), "db2", level=4)]
    [7, 7, 13, 26, 51]
    """
    scheme = get_wavelet(wavelet)
    mode = _check_mode(mode)
    x = _as_signal(x)
    level = _check_level(level, x.shape[0], scheme, mode)
    periodic = mode == "periodization"
    a = x
    details = []
    for _ in range(level):
        a, d = _forward(a, scheme, periodic)
        details.append(d)
    return [a] + details[::-1]


def waverec(coeffs, wavelet="db2", mode="periodization", length=None) -> np.ndarray:
    """Multilevel inverse of :func:`wavedec`.

    Parameters
    ----------
    coeffs : list of array_like
        ``[cA_J, cD_J, ..., cD_1]``.
    wavelet, mode
        As used by :func:`wavedec`.
    length : int, optional
        Length of the original signal.  Periodization: the output has ``2*len(cD_1)``
        samples unless ``length`` trims it (``length = n`` undoes the padding of an odd n,
        like trimming ``pywt.waverec``); symmetric lengths are implied by the bands.

    Returns
    -------
    ndarray, shape (length,)

    Raises
    ------
    ConfigError
        Fewer than two bands or band lengths that do not chain.
    """
    scheme = get_wavelet(wavelet)
    mode = _check_mode(mode)
    periodic = mode == "periodization"
    if not isinstance(coeffs, (list, tuple)) or len(coeffs) < 2:
        raise ConfigError("coeffs must be a list [cA_J, cD_J, ..., cD_1] with at least two bands")
    bands = [np.ascontiguousarray(np.asarray(c, dtype=np.float64)).ravel() for c in coeffs]
    for i, b in enumerate(bands):
        if not np.isfinite(b).all():
            raise DataFormatError(f"coeffs[{i}] holds non-finite values")
    a = bands[0]
    details = bands[1:]
    for k, d in enumerate(details):
        last = k == len(details) - 1
        if periodic:
            if a.shape[0] == d.shape[0] + 1:
                a = a[:-1]  # undo the padding of the odd length at this level (pywt rule)
            if a.shape[0] != d.shape[0]:
                raise ConfigError(
                    f"band {k + 1}: cA has {a.shape[0]} coefficients but cD has {d.shape[0]}"
                )
            n = 2 * d.shape[0]
            if last and length is not None:
                if int(length) not in (n, n - 1):
                    raise ConfigError(f"length must be {n} or {n - 1}, got {length}")
                n = int(length)
        else:
            if a.shape[0] - d.shape[0] not in (0, 1):
                raise ConfigError(
                    f"band {k + 1}: cA has {a.shape[0]} coefficients and cD {d.shape[0]}; "
                    "symmetric needs a difference of 0 or 1"
                )
            n = a.shape[0] + d.shape[0]
            if last and length is not None and int(length) != n:
                raise ConfigError(f"symmetric: length must be {n}, got {length}")
        a = _inverse(a, d, scheme, periodic, n)
    return a

