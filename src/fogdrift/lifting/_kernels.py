"""Lifting kernels: the NumPy reference step applier, the compiled numba kernels, the switch.

One generic step applier runs any :class:`~fogdrift.lifting.schemes.LiftingScheme`:
``target[l] += sum_t coefs[t] * other[map(l + offs[t])]`` where ``map`` wraps the index
(periodization) or reflects it about the channel's end samples (whole-sample symmetric:
``i -> -i``, ``i -> 2(m-1) - i``, repeated with period ``2(m-1)``; a channel of one sample
repeats it).  Two implementations of the same arithmetic:

* NumPy (:func:`_np_step`, ``_np_split``, ``_np_merge``): the reference, vectorised over the
  interior and looped over the few boundary samples;
* numba (module-level functions in :mod:`fogdrift.lifting._numba`, returned by
  :func:`_numba_kernels`; compiled on first use and cached on disk for every later process):
  the same step applier, plus fused block kernels ``fwd_blocks``/``inv_blocks`` that run
  split, all steps and scaling of the approximation path on cache-sized blocks with a halo
  (used by :mod:`fogdrift.lifting._drift` for long records).  The scheme's steps reach them
  as arrays, never closed over.

``_set_backend("numpy")`` selects the reference (tests, benchmark); the default is numba.
The step tables of a scheme are converted to arrays once (``_step_arrays``,
``_fused_tables``; cached per scheme object).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..errors import ConfigError

if TYPE_CHECKING:
    from .schemes import LiftingScheme

_BACKEND = "numba"
_NUMBA = None


def _set_backend(name: str) -> None:
    """Select the kernel backend, ``"numba"`` (default) or ``"numpy"`` (reference).

    Examples
    --------
    >>> old = _get_backend()
    >>> _set_backend("numpy"); _get_backend()
    'numpy'
    >>> _set_backend(old)
    """
    global _BACKEND
    if name not in ("numba", "numpy"):
        raise ConfigError(f"backend must be 'numba' or 'numpy', got {name!r}")
    _BACKEND = name


def _get_backend() -> str:
    """The selected kernel backend, ``"numba"`` or ``"numpy"``."""
    return _BACKEND


def _bmap_scalar(j: int, m: int, periodic: bool) -> int:
    if periodic:
        return j % m
    if m == 1:
        return 0
    p = 2 * (m - 1)
    j = j % p
    return p - j if j > m - 1 else j


def _np_step(target, other, offs, coefs, periodic):
    """``target[l] += sum_t coefs[t] * other[map(l + offs[t])]`` (NumPy reference)."""
    n_t, m = target.shape[0], other.shape[0]
    for off, c in zip(offs.tolist(), coefs.tolist()):
        lo = max(0, -off)
        hi = min(n_t, m - off)
        if hi > lo:
            target[lo:hi] += c * other[lo + off : hi + off]
            edges = list(range(0, lo)) + list(range(hi, n_t))
        else:
            edges = range(n_t)
        for l in edges:
            target[l] += c * other[_bmap_scalar(l + off, m, periodic)]


def _np_split(x, n_pad, shift, e, o):
    n = x.shape[0]
    if n_pad != n:
        x = np.append(x, x[-1])
    if shift:
        x = np.roll(x, shift)
    e[:] = x[0::2]
    o[:] = x[1::2]


def _np_merge(e, o, shift, out):
    n = out.shape[0]
    h = e.shape[0]
    n_pad = 2 * h
    buf = np.empty(n_pad)
    buf[0::2] = e
    buf[1::2] = o
    if shift:
        buf = np.roll(buf, -shift)
    out[:] = buf[:n]


def _numba_kernels():
    """The compiled kernels ``(step, split, merge, fwd_blocks, inv_blocks, fwd_blocks_serial, inv_blocks_serial)``.

    They live at module level in :mod:`fogdrift.lifting._numba` (imported here on first use, so that
    importing :mod:`fogdrift.lifting` does not import numba), where numba's on-disk cache serves
    every new process.
    """
    global _NUMBA
    if _NUMBA is None:
        from . import _numba

        _NUMBA = (_numba.step, _numba.split, _numba.merge, _numba.fwd_blocks, _numba.inv_blocks,
                  _numba.fwd_blocks_serial, _numba.inv_blocks_serial)
    return _NUMBA


def _step(target, other, offs, coefs, periodic):
    if _BACKEND == "numba":
        _numba_kernels()[0](target, other, offs, coefs, periodic)
    else:
        _np_step(target, other, offs, coefs, periodic)


def _split(x, n_pad, shift, e, o):
    if _BACKEND == "numba":
        _numba_kernels()[1](x, n_pad, shift, e, o)
    else:
        if n_pad == x.shape[0] and shift == 0:
            e[:] = x[0::2]
            o[:] = x[1::2]
        else:
            _np_split(x, n_pad, shift, e, o)


def _merge(e, o, shift, out):
    if _BACKEND == "numba":
        _numba_kernels()[2](e, o, shift, out)
    else:
        if shift == 0 and e.shape[0] + o.shape[0] >= out.shape[0]:
            k = out[0::2].shape[0]
            out[0::2] = e[:k]
            out[1::2] = o[: out[1::2].shape[0]]
        else:
            _np_merge(e, o, shift, out)


_STEP_ARRAYS: dict = {}


def _step_arrays(scheme: LiftingScheme):
    """Offsets/coefficients of every step as arrays (cached per scheme)."""
    key = id(scheme)
    hit = _STEP_ARRAYS.get(key)
    if hit is not None and hit[0] is scheme:
        return hit[1]
    arrs = [
        (
            s.kind == "predict",
            np.array([o for o, _ in s.taps], dtype=np.int64),
            np.array([c for _, c in s.taps], dtype=np.float64),
        )
        for s in scheme.steps
    ]
    _STEP_ARRAYS[key] = (scheme, arrs)
    return arrs


def _fused_tables(scheme, reverse):
    key = (id(scheme), reverse)
    hit = _STEP_ARRAYS.get(key)
    if hit is not None and hit[0] is scheme:
        return hit[1]
    steps = list(scheme.steps)[::-1] if reverse else list(scheme.steps)
    # Only the approximation path is needed: the forward pass may drop trailing predict
    # steps (they only change the detail channel), and the inverse pass, whose detail
    # channel starts at zero, may drop leading update steps (they add 0 to the even channel).
    drop = "update" if reverse else "predict"
    if reverse:
        while len(steps) > 1 and steps[0].kind == drop:
            steps = steps[1:]
    else:
        while len(steps) > 1 and steps[-1].kind == drop:
            steps = steps[:-1]
    kinds = np.array([1 if st.kind == "predict" else 0 for st in steps], dtype=np.int64)
    ptr = np.zeros(len(steps) + 1, dtype=np.int64)
    ptr[1:] = np.cumsum([len(st.taps) for st in steps])
    offs = np.array([o for st in steps for o, _ in st.taps], dtype=np.int64)
    coefs = np.array([c for st in steps for _, c in st.taps], dtype=np.float64)
    reach = np.cumsum([max(abs(o) for o, _ in st.taps) for st in steps]).astype(np.int64)
    tables = (kinds, ptr, offs, coefs, reach, max(int(reach[-1]), 1))  # halo >= 1 keeps edge segments non-empty
    _STEP_ARRAYS[key] = (scheme, tables)
    return tables


def _fused_tables_full_reach(scheme) -> int:
    """Halo for the symmetric head/tail segments: total reach of all steps (>= 1)."""
    return max(sum(max(abs(o) for o, _ in st.taps) for st in scheme.steps), 1)

