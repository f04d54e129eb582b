"""The drift operator ``W^-1(cA_J, 0, ..., 0)`` of a clean 1-D signal: reference and fused paths.

:func:`_drift_1d` is what :func:`~fogdrift.lifting.separate`,
:func:`~fogdrift.lifting.causal_drift` and :func:`~fogdrift.lifting.level_scan` call.  It
runs either

* the step-by-step path (:func:`_drift_ref`): ``J`` forward levels that keep only the
  approximation, then ``J`` inverse levels with zero detail bands, through the generic step
  applier of the selected backend; or
* the fused path (:func:`_fused_drift`, numba backend and ``n >= _FUSED_MIN``): the same
  arithmetic, block by block with a halo, in parallel (serially below ``_PARALLEL_MIN_BLOCKS``
  blocks, where starting the threads costs more than the work).  Tests check it against
  :func:`_drift_ref` for every registered wavelet, both modes, odd and even lengths.
"""

from __future__ import annotations

import numpy as np

from . import _kernels
from ._kernels import (
    _fused_tables,
    _fused_tables_full_reach,
    _numba_kernels,
    _step,
    _step_arrays,
)
from .transform import _band_lengths, _forward, _inverse, _raw_forward

_FUSED_MIN = 2048  # records shorter than this use the step-by-step kernels
_BLOCK = 2048  # channel samples per block of the fused kernels (buffers stay in L1/L2)
_PARALLEL_MIN_BLOCKS = 8  # fewer blocks run serially: starting the threads costs more than the work


def _drift_1d(x, scheme, level, periodic, out=None, noise=None):
    """Drift of a clean 1-D signal: W^-1(cA_J, 0, ..., 0) with padding/trimming per level.

    Uses the fused block kernels (numba backend, long enough records) or the step-by-step
    reference path; ``noise`` (optional, same length) receives ``x - drift``.
    """
    if _kernels._get_backend() == "numba" and x.shape[0] >= _FUSED_MIN:
        return _fused_drift(x, scheme, level, periodic, out, noise)
    d = _drift_ref(x, scheme, level, periodic, out)
    if noise is not None:
        np.subtract(x, d, out=noise)
    return d


def _drift_ref(x, scheme, level, periodic, out=None):
    """Step-by-step reference implementation of :func:`_drift_1d`."""
    lens = _band_lengths(x.shape[0], level, periodic)
    a = x
    for _ in range(level):
        a, _unused = _forward(a, scheme, periodic, need_detail=False)
    for j in range(level, 0, -1):
        n = lens[j - 1]
        a = _inverse(a, None, scheme, periodic, n, out=out if j == 1 else None)
    return a


def _sym_edges_forward(x, scheme, M, hE, hO):
    """Symmetric mode: exact approximation values on the head [0, 2M) and tail [hO-2M, hE)."""
    T = 4 * M
    s_head, _ = _raw_forward_channels(x[0 : 2 * T : 2].copy(), x[1 : 2 * T : 2].copy(), scheme)
    g0 = hO - T
    s_tail, _ = _raw_forward_channels(x[2 * g0 :: 2].copy(), x[2 * g0 + 1 :: 2].copy(), scheme)
    return s_head[: 2 * M], s_tail[T - 2 * M :]


def _raw_forward_channels(e, o, scheme):
    for is_predict, offs, coefs in _step_arrays(scheme):
        if is_predict:
            _step(o, e, offs, coefs, False)
        else:
            _step(e, o, offs, coefs, False)
    return e * scheme.scale_approx, o


def _sym_edges_inverse(s, n, scheme, M, out):
    """Symmetric mode: exact inverse (zero details) on the head and tail channel ranges."""
    hE, hO = (n + 1) // 2, n // 2
    T = 4 * M
    for g0, keep_from in ((0, 0), (hO - T, T - 2 * M)):
        e = s[g0 : g0 + T if g0 == 0 else hE] / scheme.scale_approx
        o = np.zeros(T if g0 == 0 else hO - g0)
        for is_predict, offs, coefs in reversed(_step_arrays(scheme)):
            if is_predict:
                _step(o, e, offs, -coefs, False)
            else:
                _step(e, o, offs, -coefs, False)
        if g0 == 0:
            out[0 : 4 * M : 2] = e[: 2 * M]
            out[1 : 4 * M : 2] = o[: 2 * M]
        else:
            g1 = g0 + keep_from
            out[2 * g1 :: 2] = e[keep_from:]
            out[2 * g1 + 1 :: 2] = o[keep_from:]


def _run_blocks(parallel, serial, *args):
    """Run a fused block kernel whose last arguments are ``g_lo, g_hi, B`` (channel samples [g_lo, g_hi)).

    The parallel kernel for at least ``_PARALLEL_MIN_BLOCKS`` blocks, otherwise its serial twin (the same
    blocks and arithmetic, bit-identical output): on a few blocks, starting the threads costs more than
    the work (``causal_drift`` separates ``window`` unit vectors one after the other).
    """
    g_lo, g_hi = args[-3], args[-2]
    return (parallel if g_hi - g_lo >= _PARALLEL_MIN_BLOCKS * _BLOCK else serial)(*args)


def _fused_drift(x, scheme, level, periodic, out=None, noise=None):
    """Drift (and optionally noise) with the fused numba block kernels.

    Periodization: every block gathers its halo with periodic indexing, which is exact
    because the steps are shift-invariant on the circle.  Symmetric: interior blocks need
    no boundary rule; the head and tail (2M channel samples each, M = total step reach)
    are computed step by step on 4M-sample segments, whose truncation error reaches at
    most M samples inwards, so they are exact.
    """
    kern = _numba_kernels()

    def fwd_blocks(*args):
        return _run_blocks(kern[3], kern[5], *args)

    def inv_blocks(*args):
        return _run_blocks(kern[4], kern[6], *args)

    kf, pf, of, cf, rf, mf = _fused_tables(scheme, reverse=False)
    ki, pi, oi, ci, ri, mi = _fused_tables(scheme, reverse=True)
    M = max(mf, mi, _fused_tables_full_reach(scheme))
    lens = _band_lengths(x.shape[0], level, periodic)
    empty = np.empty(0)
    a = x
    for j in range(level):
        n = a.shape[0]
        if periodic:
            n_pad = n + (n & 1)
            h = n_pad // 2
            s = np.empty(h)
            fwd_blocks(a, n_pad, scheme.input_shift % n_pad, kf, pf, of, cf, rf, M,
                       scheme.scale_approx, s, 0, h, _BLOCK)
        else:
            hE, hO = (n + 1) // 2, n // 2
            if hO < 8 * M + 2:
                s, _ = _raw_forward(a, scheme, False)
            else:
                s = np.empty(hE)
                fwd_blocks(a, n, 0, kf, pf, of, cf, rf, M, scheme.scale_approx, s,
                           2 * M, hO - 2 * M, _BLOCK)
                head, tail = _sym_edges_forward(a, scheme, M, hE, hO)
                s[: 2 * M] = head
                s[hO - 2 * M :] = tail
        a = s
    for j in range(level, 0, -1):
        n = lens[j - 1]
        last = j == 1
        dst = out if (last and out is not None) else np.empty(n)
        nz = noise if (last and noise is not None) else empty
        if periodic:
            h = a.shape[0]
            inv_blocks(a, n, scheme.input_shift % (2 * h), ki, pi, oi, ci, ri, M,
                       scheme.scale_approx, dst, x, nz, 0, h, _BLOCK)
        else:
            hO = n // 2
            if hO < 8 * M + 2:
                _inverse(a, None, scheme, False, n, out=dst)
                if nz.shape[0]:
                    np.subtract(x, dst, out=nz)
            else:
                inv_blocks(a, n, 0, ki, pi, oi, ci, ri, M, scheme.scale_approx, dst, x, nz,
                           2 * M, hO - 2 * M, _BLOCK)
                _sym_edges_inverse(a, n, scheme, M, dst)
                if nz.shape[0]:
                    nz[: 4 * M] = x[: 4 * M] - dst[: 4 * M]
                    k0 = 2 * (hO - 2 * M)
                    nz[k0:] = x[k0:] - dst[k0:]
        a = dst
    return a
