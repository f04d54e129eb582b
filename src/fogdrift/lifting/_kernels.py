"""Lifting kernels: the NumPy reference step applier, the compiled numba kernels, the switch.

One generic step applier runs any :class:`~fogdrift.lifting.schemes.LiftingScheme`:
``target[l] += sum_t coefs[t] * other[map(l + offs[t])]`` where ``map`` wraps the index
(periodization) or reflects it about the channel's end samples (whole-sample symmetric:
``i -> -i``, ``i -> 2(m-1) - i``, repeated with period ``2(m-1)``; a channel of one sample
repeats it).  Two implementations of the same arithmetic:

* NumPy (:func:`_np_step`, ``_np_split``, ``_np_merge``): the reference, vectorised over the
  interior and looped over the few boundary samples;
* numba (:func:`_numba_kernels`, compiled on first use and cached on disk): the same step
  applier, plus fused block kernels ``fwd_blocks``/``inv_blocks`` that run split, all steps
  and scaling of the approximation path on cache-sized blocks with a halo (used by
  :mod:`fogdrift.lifting._drift` for long records).

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
    global _NUMBA
    if _NUMBA is not None:
        return _NUMBA
    import numba
    from numba import prange

    @numba.njit(cache=True, inline="always")
    def bmap(j, m, periodic):
        if periodic:
            j = j % m
            if j < 0:
                j += m
            return j
        if m == 1:
            return 0
        p = 2 * (m - 1)
        j = j % p
        if j < 0:
            j += p
        if j > m - 1:
            j = p - j
        return j

    @numba.njit(cache=True, fastmath=False)
    def step(target, other, offs, coefs, periodic):
        n_t = target.shape[0]
        m = other.shape[0]
        nt = offs.shape[0]
        lo = min(max(0, -offs.min()), n_t)
        hi = max(min(n_t, m - offs.max()), lo)
        for l in range(lo, hi):
            acc = 0.0
            for t in range(nt):
                acc += coefs[t] * other[l + offs[t]]
            target[l] += acc
        for l in range(0, lo):
            acc = 0.0
            for t in range(nt):
                acc += coefs[t] * other[bmap(l + offs[t], m, periodic)]
            target[l] += acc
        for l in range(hi, n_t):
            acc = 0.0
            for t in range(nt):
                acc += coefs[t] * other[bmap(l + offs[t], m, periodic)]
            target[l] += acc

    @numba.njit(cache=True)
    def split(x, n_pad, shift, e, o):
        n = x.shape[0]
        h = e.shape[0]
        if shift == 0 and n_pad == n:
            for i in range(o.shape[0]):
                e[i] = x[2 * i]
                o[i] = x[2 * i + 1]
            if h > o.shape[0]:
                e[h - 1] = x[2 * (h - 1)]
            return
        for i in range(h):
            j = (2 * i - shift) % n_pad
            if j < 0:
                j += n_pad
            e[i] = x[min(j, n - 1)]
            j = (2 * i + 1 - shift) % n_pad
            if j < 0:
                j += n_pad
            o[i] = x[min(j, n - 1)]

    @numba.njit(cache=True)
    def merge(e, o, shift, out):
        n = out.shape[0]
        h = e.shape[0]
        n_pad = 2 * h
        if shift == 0:
            for i in range(o.shape[0]):
                if 2 * i < n:
                    out[2 * i] = e[i]
                if 2 * i + 1 < n:
                    out[2 * i + 1] = o[i]
            if h > o.shape[0] and 2 * (h - 1) < n:
                out[2 * (h - 1)] = e[h - 1]
            return
        for i in range(h):
            j = (2 * i - shift) % n_pad
            if j < 0:
                j += n_pad
            if j < n:
                out[j] = e[i]
            j = (2 * i + 1 - shift) % n_pad
            if j < 0:
                j += n_pad
            if j < n:
                out[j] = o[i]

    @numba.njit(cache=True, inline="always")
    def step_local(T, S, lo, hi, t0, t1, offs, coefs, sign):
        # T[l] += sign * sum_t coefs[t] * S[l + offs[t]] for l in [lo, hi); 1 and 2 taps unrolled
        nt = t1 - t0
        if nt == 1:
            c0 = sign * coefs[t0]
            o0 = offs[t0]
            for l in range(lo, hi):
                T[l] += c0 * S[l + o0]
        elif nt == 2:
            c0 = sign * coefs[t0]
            o0 = offs[t0]
            c1 = sign * coefs[t0 + 1]
            o1 = offs[t0 + 1]
            for l in range(lo, hi):
                T[l] += c0 * S[l + o0] + c1 * S[l + o1]
        else:
            for t in range(t0, t1):
                c = sign * coefs[t]
                o = offs[t]
                for l in range(lo, hi):
                    T[l] += c * S[l + o]

    @numba.njit(cache=True)
    def apply_steps_local(E, O, w, kinds, ptr, offs, coefs, reach, sign):
        # steps on cache-resident buffers; after step k values are valid on [reach[k], w - reach[k])
        for k in range(kinds.shape[0]):
            r = reach[k]
            if kinds[k] == 1:
                step_local(O, E, r, w - r, ptr[k], ptr[k + 1], offs, coefs, sign)
            else:
                step_local(E, O, r, w - r, ptr[k], ptr[k + 1], offs, coefs, sign)

    @numba.njit(cache=True, parallel=True)
    def fwd_blocks(x, n_pad, shift, kinds, ptr, offs, coefs, reach, M, scale_a, s_out, g_lo, g_hi, B):
        # fused split + lifting + scaling of the approximation, block by block (halo M);
        # blocks are independent, so they run in parallel, each with its own buffers
        n = x.shape[0]
        for ib in prange((g_hi - g_lo + B - 1) // B):
            a = g_lo + ib * B
            E = np.empty(B + 2 * M)
            O = np.empty(B + 2 * M)
            b = min(a + B, g_hi)
            w = b - a + 2 * M
            base = a - M
            j0 = 2 * base - shift
            if j0 >= 0 and j0 + 2 * w - 1 < n:
                for i in range(w):
                    E[i] = x[j0 + 2 * i]
                    O[i] = x[j0 + 2 * i + 1]
            else:
                for i in range(w):
                    j = (j0 + 2 * i) % n_pad
                    if j < 0:
                        j += n_pad
                    E[i] = x[min(j, n - 1)]
                    j = (j0 + 2 * i + 1) % n_pad
                    if j < 0:
                        j += n_pad
                    O[i] = x[min(j, n - 1)]
            apply_steps_local(E, O, w, kinds, ptr, offs, coefs, reach, 1.0)
            for i in range(b - a):
                s_out[a + i] = E[M + i] * scale_a

    @numba.njit(cache=True, parallel=True)
    def inv_blocks(s, n_out, shift, kinds, ptr, offs, coefs, reach, M, scale_a, out, x, noise,
                   g_lo, g_hi, B):
        # fused unscaling + inverse lifting (zero detail band) + merge, block by block;
        # kinds/ptr/offs/coefs/reach describe the reversed step list; writes noise = x - out
        # when noise has the length of out.
        h = s.shape[0]
        n_pad = 2 * h
        do_noise = noise.shape[0] == out.shape[0]
        inv_a = 1.0 / scale_a
        for ib in prange((g_hi - g_lo + B - 1) // B):
            a = g_lo + ib * B
            E = np.empty(B + 2 * M)
            O = np.empty(B + 2 * M)
            b = min(a + B, g_hi)
            w = b - a + 2 * M
            base = a - M
            if base >= 0 and base + w <= h:
                for i in range(w):
                    E[i] = s[base + i] * inv_a
                    O[i] = 0.0
            else:
                for i in range(w):
                    g = (base + i) % h
                    if g < 0:
                        g += h
                    E[i] = s[g] * inv_a
                    O[i] = 0.0
            apply_steps_local(E, O, w, kinds, ptr, offs, coefs, reach, -1.0)
            j0 = 2 * a - shift
            if j0 >= 0 and j0 + 2 * (b - a) <= n_out:
                for i in range(b - a):
                    out[j0 + 2 * i] = E[M + i]
                    out[j0 + 2 * i + 1] = O[M + i]
                    if do_noise:
                        noise[j0 + 2 * i] = x[j0 + 2 * i] - E[M + i]
                        noise[j0 + 2 * i + 1] = x[j0 + 2 * i + 1] - O[M + i]
            else:
                for i in range(b - a):
                    for q in range(2):
                        j = (j0 + 2 * i + q) % n_pad
                        if j < 0:
                            j += n_pad
                        if j < n_out:
                            v = E[M + i] if q == 0 else O[M + i]
                            out[j] = v
                            if do_noise:
                                noise[j] = x[j] - v

    _NUMBA = (step, split, merge, fwd_blocks, inv_blocks)
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

