"""Compiled lifting kernels (numba; imported on first use, cached on disk).

Module-level functions, so that numba's on-disk cache is reused by every new process: as closures
inside a factory they referred to each other as free variables, the cache index key (which hashes
the closure cells) changed in every process, so every ``fogdrift`` run (and every Dask worker of
``fogdrift batch``) compiled them again (~4 s) and wrote a new cache file.  A scheme's steps reach
the kernels as arrays (``_kernels._step_arrays``, ``_kernels._fused_tables``), never closed over.

``step``, ``split``, ``merge``
    the generic step applier ``target[l] += sum_t coefs[t] * other[map(l + offs[t])]`` (``map``
    wraps the index or reflects it whole-sample about the channel's end samples) and the
    even/odd split and merge with padding and input shift;
``fwd_blocks``, ``inv_blocks``
    fused split + all steps + scaling of the approximation path (and its inverse with a zero
    detail band) on cache-sized blocks with a halo (``fwd_block``, ``inv_block``), blocks in
    parallel (used by :mod:`fogdrift.lifting._drift` for long records); ``*_serial``: the same
    blocks one after the other, for records of a few blocks.

The NumPy reference of the same arithmetic is in :mod:`fogdrift.lifting._kernels`.
"""

import numba
import numpy as np
from numba import prange

__all__ = ["step", "split", "merge", "fwd_blocks", "inv_blocks", "fwd_blocks_serial", "inv_blocks_serial"]


@numba.njit(cache=True, inline="always")
def bmap(j, m, periodic):  # pragma: no cover - compiled
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
def step(target, other, offs, coefs, periodic):  # pragma: no cover - compiled
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
def split(x, n_pad, shift, e, o):  # pragma: no cover - compiled
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
def merge(e, o, shift, out):  # pragma: no cover - compiled
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
def step_local(T, S, lo, hi, t0, t1, offs, coefs, sign):  # pragma: no cover - compiled
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
def apply_steps_local(E, O, w, kinds, ptr, offs, coefs, reach, sign):  # pragma: no cover - compiled
    # steps on cache-resident buffers; after step k values are valid on [reach[k], w - reach[k])
    for k in range(kinds.shape[0]):
        r = reach[k]
        if kinds[k] == 1:
            step_local(O, E, r, w - r, ptr[k], ptr[k + 1], offs, coefs, sign)
        else:
            step_local(E, O, r, w - r, ptr[k], ptr[k + 1], offs, coefs, sign)


@numba.njit(cache=True)
def fwd_block(x, n_pad, shift, kinds, ptr, offs, coefs, reach, M, scale_a, s_out, g_lo, g_hi, B, ib):  # pragma: no cover
    # block ib of the fused split + lifting + scaling of the approximation (halo M), with its own buffers
    n = x.shape[0]
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


@numba.njit(cache=True)
def inv_block(s, n_out, shift, kinds, ptr, offs, coefs, reach, M, scale_a, out, x, noise,
              g_lo, g_hi, B, ib):  # pragma: no cover - compiled
    # block ib of the fused unscaling + inverse lifting (zero detail band) + merge; kinds/ptr/offs/
    # coefs/reach describe the reversed step list; writes noise = x - out when noise has the length of out
    h = s.shape[0]
    n_pad = 2 * h
    do_noise = noise.shape[0] == out.shape[0]
    inv_a = 1.0 / scale_a
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


# The drivers: blocks are independent, so they run in parallel; the serial twins (same blocks, same
# arithmetic, bit-identical output) serve records of a few blocks, where starting the threads costs more
# than the work (causal_drift separates `window` unit vectors one by one).

@numba.njit(cache=True, parallel=True)
def fwd_blocks(x, n_pad, shift, kinds, ptr, offs, coefs, reach, M, scale_a, s_out, g_lo, g_hi, B):  # pragma: no cover
    for ib in prange((g_hi - g_lo + B - 1) // B):
        fwd_block(x, n_pad, shift, kinds, ptr, offs, coefs, reach, M, scale_a, s_out, g_lo, g_hi, B, ib)


@numba.njit(cache=True)
def fwd_blocks_serial(x, n_pad, shift, kinds, ptr, offs, coefs, reach, M, scale_a, s_out, g_lo, g_hi,
                      B):  # pragma: no cover - compiled
    for ib in range((g_hi - g_lo + B - 1) // B):
        fwd_block(x, n_pad, shift, kinds, ptr, offs, coefs, reach, M, scale_a, s_out, g_lo, g_hi, B, ib)


@numba.njit(cache=True, parallel=True)
def inv_blocks(s, n_out, shift, kinds, ptr, offs, coefs, reach, M, scale_a, out, x, noise,
               g_lo, g_hi, B):  # pragma: no cover - compiled
    for ib in prange((g_hi - g_lo + B - 1) // B):
        inv_block(s, n_out, shift, kinds, ptr, offs, coefs, reach, M, scale_a, out, x, noise, g_lo, g_hi, B, ib)


@numba.njit(cache=True)
def inv_blocks_serial(s, n_out, shift, kinds, ptr, offs, coefs, reach, M, scale_a, out, x, noise,
                      g_lo, g_hi, B):  # pragma: no cover - compiled
    for ib in range((g_hi - g_lo + B - 1) // B):
        inv_block(s, n_out, shift, kinds, ptr, offs, coefs, reach, M, scale_a, out, x, noise, g_lo, g_hi, B, ib)
