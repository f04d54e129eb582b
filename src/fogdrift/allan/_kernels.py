"""Compiled kernels of the Allan family (numba; compiled lazily on first use, cached on disk).

These kernels serve every statistic of :data:`fogdrift.allan.statistics.STATISTICS`:

``phase``
    the mean-removed angle ``p_0 = 0, p_k = sum_{i<k} (y_i - mean)`` by blocked, compensated
    summation (rounding grows with the block length, not with N).
``diff2``, ``diff3``
    per-block sums of ``(sum_l c_l p_{k + l m})^2`` over start indices ``k = 0, s, 2s, ...``
    for the second (Allan) and third (Hadamard) difference.  Unit-stride slices let LLVM
    vectorise the loop; blocks of start indices run in parallel.
``window2``
    the second difference of m-point window sums ``W_k = sum_{i=k}^{k+m-1} p_i`` (modified
    Allan), stepped along the record by its third-difference increment and restarted at every
    block from a local reference point, so that rounding stays at the level of one block.
``fused2``
    the overlapping Allan block sums of ``diff2`` straight from the rate, for grids with few lags
    of at least one block (octave, decade): the angle is rebuilt block by block, by the additions
    of ``phase``, only where the operator reads it (the current block and one block-long window
    per long lag), so the (N + 1)-point angle array is never stored or page-faulted in, and the
    sums are those of ``phase`` + ``diff2`` bit for bit.

The operators themselves (coefficients, averaging) are data in ``statistics.py``; these
functions only evaluate them.  All kernels assume clean input (checked by the caller).
"""

from __future__ import annotations

import numpy as np

__all__ = ["phase_dph_samples", "operator_sums", "block_sums2", "allan_sums_fused", "fused_lags", "fused_part",
           "threads_for", "OPERATORS", "BLOCK", "PARALLEL_MIN", "FUSED_MIN", "FUSED_MAX_LAGS"]

#: Start indices per block of the ``diff`` kernel (also the unit of pairwise summation).
BLOCK = 65536

#: Smallest block of the ``window`` kernel; a block is at least 4 m start indices long so that
#: re-initialising the m-point windows at each block costs at most 3/4 of the block's work.
WINDOW_BLOCK = 4096

#: numba fast-math flags of the sum-of-squares helpers: reassociation lets LLVM vectorise the reduction,
#: contraction fuses d*d + acc into one FMA.  Results differ from a sequential sum by rounding only
#: (< 1e-14 relative at 10^7 samples; tests compare with allantools to 1e-12).
SUM_FASTMATH = frozenset({"reassoc", "contract"})

prange = range  # replaced by numba.prange in _compiled()
_sq2 = _sq3 = _fill = _run_before = None  # replaced by the compiled helpers in _compiled()
_KERNELS: dict = {}


def _offsets_py(y, mu, block):  # pragma: no cover - runs compiled
    """Angle at the start of every block of ``block`` samples: ``offsets[b] = sum_{i < b block} (y[i] - mu)``.

    Each block's total is summed with 4 interleaved accumulators (blocks in parallel), the totals are
    accumulated serially with Neumaier compensation.  Shared by :func:`_phase_py` and :func:`_fused2_py`, so
    both reconstruct the same angle bit for bit.
    """
    n = y.size
    nb = (n + block - 1) // block
    totals = np.zeros(nb)
    for ib in prange(nb):
        lo = ib * block
        hi = min(n, lo + block)
        a0 = 0.0
        a1 = 0.0
        a2 = 0.0
        a3 = 0.0
        i = lo
        while i + 3 < hi:
            a0 += y[i] - mu
            a1 += y[i + 1] - mu
            a2 += y[i + 2] - mu
            a3 += y[i + 3] - mu
            i += 4
        while i < hi:
            a0 += y[i] - mu
            i += 1
        totals[ib] = (a0 + a1) + (a2 + a3)
    offsets = np.zeros(nb)
    s = 0.0
    c = 0.0
    for ib in range(nb):
        offsets[ib] = s + c
        x = totals[ib]
        t = s + x
        if abs(s) >= abs(x):
            c += (s - t) + x
        else:
            c += (x - t) + s
        s = t
    return offsets


def _phase_py(y, mu, offsets, out, block):  # pragma: no cover - runs compiled
    """out[0] = 0, out[k] = sum_{i<k} (y[i] - mu). Clean input assumed.

    Blocked summation, parallel over blocks: each block runs its own cumulative sum from its offset
    (:func:`_offsets_py`).  The rounding error of any out[k] is bounded by about ``block * eps`` times the
    (mean-removed) magnitudes, not ``N * eps``: no cancellation at 10^8 samples.
    """
    n = y.size
    nb = (n + block - 1) // block
    out[0] = 0.0
    for ib in prange(nb):
        lo = ib * block
        hi = min(n, lo + block)
        run = 0.0
        base = offsets[ib]
        for i in range(lo, hi):
            run += y[i] - mu
            out[i + 1] = base + run


def _sq2_py(a, b, c):  # pragma: no cover - runs compiled
    """sum_k (a[k] - 2 b[k] + c[k])^2 over three contiguous arrays of one length.

    Compiled with :data:`SUM_FASTMATH` (reassociation and FMA contraction): LLVM then vectorises the reduction
    (8 doubles per AVX-512 instruction, several accumulators), 4-5x the speed of the strictly sequential sum
    whose every addition waits for the previous one.  The order of the additions is fixed by the compiled code
    and the block start, so the in-memory kernel (:func:`_diff2_py`) and the out-of-core one
    (:func:`block_sums2`, same helper on the same blocks) give the same bits.
    """
    acc = 0.0
    for k in range(c.size):
        d = a[k] - 2.0 * b[k] + c[k]
        acc += d * d
    return acc


def _sq3_py(a, b, e, f):  # pragma: no cover - runs compiled
    """sum_k ((f[k] - a[k]) + 3 (b[k] - e[k]))^2 over four contiguous arrays (as :func:`_sq2_py`)."""
    acc = 0.0
    for k in range(a.size):
        d = (f[k] - a[k]) + 3.0 * (b[k] - e[k])
        acc += d * d
    return acc


def _diff2_py(p, ms, strides, block):  # pragma: no cover - runs compiled
    """Per-block sums of (p[k+2m] - 2 p[k+m] + p[k])^2 over k = 0, s, 2s, ... < len(p) - 2m.

    Operator (1, -2, 1) (Allan).  Returns an array (n_blocks, n_tau); blocks of ``block`` start
    indices run in parallel.  Stride 1 (overlapping): contiguous slices summed by the vectorised
    :func:`_sq2_py`; other strides: a sequential sum over strided slices.
    """
    n_phase = p.size
    ntau = ms.size
    m_min = ms.min()
    nblocks = (n_phase - 2 * m_min + block - 1) // block
    part = np.zeros((nblocks, ntau))
    for ib in prange(nblocks):
        k0 = ib * block
        for j in range(ntau):
            m = ms[j]
            s = strides[j]
            kend = min(k0 + block, n_phase - 2 * m)
            if kend <= k0:
                continue
            if s == 1:
                part[ib, j] = _sq2(p[k0 + 2 * m : kend + 2 * m], p[k0 + m : kend + m], p[k0:kend])
                continue
            kstart = ((k0 + s - 1) // s) * s
            a = p[kstart + 2 * m : kend + 2 * m : s]
            b = p[kstart + m : kend + m : s]
            c = p[kstart:kend:s]
            acc = 0.0
            for k in range(c.size):
                d = a[k] - 2.0 * b[k] + c[k]
                acc += d * d
            part[ib, j] = acc
    return part


def _block_sums2_py(a, b, c, k_first, s, block, out):  # pragma: no cover - runs compiled
    """The out-of-core form of :func:`_diff2_py`: per-block sums of (a[q] - 2 b[q] + c[q])^2, k = k_first + q.

    ``a, b, c`` hold the angle at k + 2m, k + m and k for k = k_first .. k_first + len - 1; ``out[j]``
    receives the sum over the k (on the stride-s lattice) of block ``k_first // block + j``: the same
    additions in the same order as :func:`_diff2_py`, so the two engines agree bit for bit.
    """
    n = c.size
    b0 = k_first // block
    nb = out.size
    for j in prange(nb):
        lo = max((b0 + j) * block, k_first)
        hi = min((b0 + j + 1) * block, k_first + n)
        if s == 1:
            out[j] = _sq2(a[lo - k_first : hi - k_first], b[lo - k_first : hi - k_first],
                          c[lo - k_first : hi - k_first])
            continue
        kstart = ((lo + s - 1) // s) * s
        acc = 0.0
        for k in range(kstart, hi, s):
            q = k - k_first
            d = a[q] - 2.0 * b[q] + c[q]
            acc += d * d
        out[j] = acc


def _run_before_py(y, mu, block, x):  # pragma: no cover - runs compiled
    """The running block sum of :func:`_phase_py` just before it adds ``y[x - 1]``: ``sum (y[i] - mu)`` over
    ``i = b block .. x - 2``, ``b = (x - 1) // block`` (0 where x - 1 starts a block or x = 0)."""
    run = 0.0
    if x >= 1:
        for i in range(((x - 1) // block) * block, x - 1):
            run += y[i] - mu
    return run


def _fill_py(y, mu, offsets, block, x0, x1, out, o0, run):  # pragma: no cover - runs compiled
    """Angle points ``p[x0 .. x1)`` into ``out[o0 ...]``, continuing the running block sum ``run``.

    ``p[0] = 0`` and ``p[x] = offsets[b] + sum_{i = b block}^{x - 1} (y[i] - mu)``, ``b = (x - 1) // block``:
    the additions of :func:`_phase_py` in its order, so every point equals its output bit for bit.  ``run`` is
    the block sum before ``y[x0 - 1]`` (:func:`_run_before_py`); returns the one after ``y[x1 - 2]``, the
    ``run`` of a call that continues at ``x1``.
    """
    x = x0
    if x == 0:
        out[o0] = 0.0
        x = 1
    while x < x1:
        b = (x - 1) // block
        if x - 1 == b * block:
            run = 0.0
        hi = min(x1, (b + 1) * block + 1)
        base = offsets[b]
        for i in range(x - 1, hi - 1):
            run += y[i] - mu
            out[o0 + i + 1 - x0] = base + run
        x = hi
    return run


def _fused2_py(y, mu, offsets, ms, lags, slot_m, slot_2m, nblocks, block, nchunks):  # pragma: no cover
    """The per-block sums of :func:`_diff2_py` (stride 1) computed from the rate, without the whole angle array.

    For every block of start indices ``k0 = ib block .. k0 + block`` the angle is rebuilt where the Allan
    operator ``(p[k+2m] - 2 p[k+m] + p[k])^2`` reads it: ``near`` holds ``p[k0 .. k0 + 2 block)`` (lags below
    ``block``, slid by one block per step) and row ``l`` of ``far`` holds ``p[k0 + lags[l] .. + block)`` (one
    stream over the rate per distinct lag of at least ``block``).  Each row is produced from the rate by
    :func:`_fill_py` just before the taus whose lag 2m it is (``slot_2m[j] == l``; ``slot_m[j]`` is the row
    of lag m or -1 for ``near``) consume it, so the row is still in cache.  The slices passed to the
    vectorised :func:`_sq2_py` hold the same values and have the same lengths as in :func:`_diff2_py`,
    so ``part`` is the same bit for bit.  The blocks are cut into ``nchunks`` contiguous runs in parallel;
    each restarts its streams from the block offsets.  Reads the rate ``2 + len(lags)`` times, writes only
    cache-sized buffers.
    """
    n_phase = y.size + 1
    ntau = ms.size
    nl = lags.size
    part = np.zeros((nblocks, ntau))
    per = (nblocks + nchunks - 1) // nchunks
    for ic in prange(nchunks):
        b0 = ic * per
        b1 = min(nblocks, b0 + per)
        if b0 >= b1:
            continue
        near = np.empty(2 * block)
        far = np.empty(max(nl, 1) * block)
        runs = np.zeros(max(nl, 1))
        k0 = b0 * block
        run_near = _fill(y, mu, offsets, block, k0, min(k0 + 2 * block, n_phase), near, 0,
                         _run_before(y, mu, block, k0))
        for l in range(nl):
            runs[l] = _run_before(y, mu, block, min(k0 + lags[l], n_phase))
        for ib in range(b0, b1):
            k0 = ib * block
            if ib > b0:
                near[:block] = near[block:]
                if k0 + block < n_phase:
                    run_near = _fill(y, mu, offsets, block, k0 + block, min(k0 + 2 * block, n_phase), near,
                                     block, run_near)
            for j in range(ntau):
                if slot_2m[j] >= 0:
                    continue
                m = ms[j]
                kend = min(k0 + block, n_phase - 2 * m)
                if kend > k0:
                    ln = kend - k0
                    part[ib, j] = _sq2(near[2 * m : 2 * m + ln], near[m : m + ln], near[0:ln])
            for l in range(nl):
                x0 = k0 + lags[l]
                if x0 >= n_phase:
                    continue
                runs[l] = _fill(y, mu, offsets, block, x0, min(x0 + block, n_phase), far, l * block, runs[l])
                for j in range(ntau):
                    if slot_2m[j] != l:
                        continue
                    m = ms[j]
                    kend = min(k0 + block, n_phase - 2 * m)
                    if kend <= k0:
                        continue
                    ln = kend - k0
                    sm = slot_m[j]
                    if sm < 0:
                        mid = near[m : m + ln]
                    else:
                        mid = far[sm * block : sm * block + ln]
                    part[ib, j] = _sq2(far[l * block : l * block + ln], mid, near[0:ln])
    return part


def _diff3_py(p, ms, strides, block):  # pragma: no cover - runs compiled
    """As ``_diff2_py`` for the operator (-1, 3, -3, 1) (Hadamard):
    (p[k+3m] - 3 p[k+2m] + 3 p[k+m] - p[k])^2 over k < len(p) - 3m."""
    n_phase = p.size
    ntau = ms.size
    m_min = ms.min()
    nblocks = (n_phase - 3 * m_min + block - 1) // block
    part = np.zeros((nblocks, ntau))
    for ib in prange(nblocks):
        k0 = ib * block
        for j in range(ntau):
            m = ms[j]
            s = strides[j]
            kend = min(k0 + block, n_phase - 3 * m)
            if kend <= k0:
                continue
            if s == 1:
                part[ib, j] = _sq3(p[k0:kend], p[k0 + m : kend + m], p[k0 + 2 * m : kend + 2 * m],
                                   p[k0 + 3 * m : kend + 3 * m])
                continue
            kstart = ((k0 + s - 1) // s) * s
            a = p[kstart:kend:s]
            b = p[kstart + m : kend + m : s]
            e = p[kstart + 2 * m : kend + 2 * m : s]
            f = p[kstart + 3 * m : kend + 3 * m : s]
            acc = 0.0
            for k in range(a.size):
                d = (f[k] - a[k]) + 3.0 * (b[k] - e[k])
                acc += d * d
            part[ib, j] = acc
    return part


def _window2_py(p, item_m, item_k0, item_k1):  # pragma: no cover - runs compiled
    """Per-item sums of S_k^2, S_k = W[k] - 2 W[k+m] + W[k+2m] with W[k] = sum_{i=k}^{k+m-1} p[i],
    over start indices k0 <= k < k1 of each work item (m, k0, k1).

    Operator (1, -2, 1) on m-point window sums (modified Allan).  The items (blocks of start
    indices of every tau) run in parallel in one region.  Each computes its first S directly from
    its first phase point as reference (3 m additions; the operator sums to zero, so the reference
    cancels) and then steps S_{k+1} = S_k + (p[k+3m] - 3 p[k+2m] + 3 p[k+m] - p[k]): the increment
    is the third difference of p, so the running value carries rounding of its own size only.
    """
    nitems = item_m.size
    part = np.zeros(nitems)
    for it in prange(nitems):
        m = item_m[it]
        k0 = item_k0[it]
        k1 = item_k1[it]
        ref = p[k0]
        w0 = 0.0
        w1 = 0.0
        w2 = 0.0
        for i in range(m):
            w0 += p[k0 + i] - ref
            w1 += p[k0 + m + i] - ref
            w2 += p[k0 + 2 * m + i] - ref
        s = w0 - 2.0 * w1 + w2
        acc = s * s
        a = p[k0 : k1 - 1]
        b = p[k0 + m : k1 - 1 + m]
        c = p[k0 + 2 * m : k1 - 1 + 2 * m]
        d = p[k0 + 3 * m : k1 - 1 + 3 * m]
        for k in range(a.size):
            s += (d[k] - a[k]) + 3.0 * (b[k] - c[k])
            acc += s * s
        part[it] = acc
    return part


def _window_items(n_phase: int, m: np.ndarray, min_block: int):
    """Work items (m, k0, k1) of the window kernel: blocks of max(min_block, 4 m) start indices."""
    ims, k0s, k1s, owner = [], [], [], []
    for j, mm in enumerate(np.asarray(m, dtype=np.int64)):
        n_terms = n_phase - 3 * int(mm) + 1
        block = max(min_block, 4 * int(mm))
        starts = np.arange(0, n_terms, block, dtype=np.int64)
        ims.append(np.full(starts.size, mm, dtype=np.int64))
        k0s.append(starts)
        k1s.append(np.minimum(starts + block, n_terms))
        owner.append(np.full(starts.size, j, dtype=np.int64))
    return np.concatenate(ims), np.concatenate(k0s), np.concatenate(k1s), np.concatenate(owner)


def _compiled():
    """Compile (or load from the numba cache) the kernels on first use."""
    if not _KERNELS:
        import numba

        # ``prange`` is a module global (plain ``range`` until here) that numba reads at compile time
        globals()["prange"] = numba.prange
        # the helpers are module globals (None until here) that the kernels below call compiled
        globals()["_sq2"] = numba.njit(cache=True, fastmath=set(SUM_FASTMATH))(_sq2_py)
        globals()["_sq3"] = numba.njit(cache=True, fastmath=set(SUM_FASTMATH))(_sq3_py)
        globals()["_fill"] = numba.njit(cache=True)(_fill_py)
        globals()["_run_before"] = numba.njit(cache=True)(_run_before_py)
        _KERNELS["offsets"] = numba.njit(cache=True, parallel=True)(_offsets_py)
        _KERNELS["phase"] = numba.njit(cache=True, parallel=True)(_phase_py)
        _KERNELS["diff2"] = numba.njit(cache=True, parallel=True)(_diff2_py)
        _KERNELS["diff3"] = numba.njit(cache=True, parallel=True)(_diff3_py)
        _KERNELS["window2"] = numba.njit(cache=True, parallel=True)(_window2_py)
        _KERNELS["block_sums2"] = numba.njit(cache=True, parallel=True)(_block_sums2_py)
        _KERNELS["fused2"] = numba.njit(cache=True, parallel=True)(_fused2_py)
    return _KERNELS


#: Below this many array elements of work (about 10 ms on one core) a kernel runs on one thread: a parallel
#: region's barrier costs a scheduler time slice when the cores are busy (185 000 samples, octave ADEV, load
#: 15 on 2 cores: 140 ms with 2 threads, 9 ms with 1), while a short serial run loses at most a few ms on an
#: idle machine.  The
#: blocks and their order are the same either way, so the results are identical.
PARALLEL_MIN = 1 << 24


class threads_for:
    """Context: numba runs on one thread while it is entered with less than :data:`PARALLEL_MIN` work."""

    def __init__(self, work: int):
        self.serial = work < PARALLEL_MIN

    def __enter__(self):
        if self.serial:
            import numba

            self.before = numba.get_num_threads()
            numba.set_num_threads(1)
        return self

    def __exit__(self, *exc):
        if self.serial:
            import numba

            numba.set_num_threads(self.before)
        return False


def phase_dph_samples(y: np.ndarray) -> np.ndarray:
    """Angle in units of (deg/h) * dt with the mean removed: shape (N + 1,)."""
    mu = float(np.mean(y))
    p = np.empty(y.size + 1)
    kern = _compiled()
    with threads_for(y.size):
        kern["phase"](y, mu, kern["offsets"](y, mu, BLOCK), p, BLOCK)
    return p


#: Compiled implementations of the difference operators of ``statistics.py``, keyed by
#: (operator coefficients by lag, m-point window averaging).  Each is a hand-written kernel of
#: one operator (a generic coefficient loop costs ~17 % of the Allan speed); ``test_allan``
#: checks every entry against a plain numpy evaluation of its coefficients.
OPERATORS = {
    ((1, -2, 1), False): "diff2",
    ((-1, 3, -3, 1), False): "diff3",
    ((1, -2, 1), True): "window2",
}


def operator_sums(p: np.ndarray, m: np.ndarray, strides: np.ndarray, coefficients, window: bool) -> np.ndarray:
    """Sum over start indices of the squared operator, one value per m.

    Without ``window``: ``sum_k (sum_l c_l p[k + l m])^2`` over ``k = 0, s, 2s, ...`` with
    ``k + (len(c) - 1) m < len(p)``.  With ``window`` (every start index; ``strides`` must be 1):
    the same with ``p[i]`` replaced by the m-point window sum ``sum_{r<m} p[i + r]``.
    Block partial sums are added pairwise (``np.sum``).

    Raises
    ------
    KeyError
        No compiled kernel for this operator (see :data:`OPERATORS`).
    """
    key = (tuple(int(v) for v in coefficients), bool(window))
    name = OPERATORS[key]
    kern = _compiled()[name]
    if window:
        if np.any(strides != 1):
            raise ValueError("the window kernel runs over every start index (stride 1)")
        item_m, k0, k1, owner = _window_items(p.size, m, WINDOW_BLOCK)
        with threads_for(p.size * np.asarray(m).size):
            part = kern(p, item_m, k0, k1)
        return np.array([part[owner == j].sum() for j in range(np.asarray(m).size)], dtype=np.float64)
    with threads_for(int(np.sum(p.size // np.maximum(strides, 1)))):
        return kern(p, m, strides, BLOCK).sum(axis=0)


def block_sums2(a: np.ndarray, b: np.ndarray, c: np.ndarray, k_first: int, s: int, block: int,
                out: np.ndarray) -> None:
    """Per-block sums of the squared Allan second difference for the out-of-core engine, into ``out``.

    ``a``, ``b``, ``c``: float64 angle [(deg/h) x samples] at start index k + 2m, k + m and k for
    k = ``k_first`` .. ``k_first + len(c) - 1``; ``out[j]`` [(deg/h)^2 x samples^2] receives the sum over
    the k on the stride-``s`` lattice of block ``k_first // block + j``.  The same compiled additions as the
    in-memory kernel, block for block, so :mod:`fogdrift.allan.chunked` stays equal to
    :func:`fogdrift.allan.allan_variance` bit for bit.
    """
    kern = _compiled()["block_sums2"]
    with threads_for(c.size // max(int(s), 1)):
        kern(a, b, c, k_first, s, block, out)


#: Smallest record (samples) for which :func:`allan_sums_fused` is used: below it the angle array fits in cache
#: and the per-tau kernel is as fast.
FUSED_MIN = 1 << 21

#: Most distinct lags of at least :data:`BLOCK` (m or 2m) the fused kernel takes: each is one more read of the
#: rate per pass and one block buffer (512 kB) per thread.  The octave grid has ``log2(N) - 15`` of them (10 at
#: 10^8), the decade grid about 4 per decade; dense grids fall back to :func:`operator_sums`.
FUSED_MAX_LAGS = 32

#: Runs of blocks per thread in the fused kernel.  Each run restarts its streams (about ``(2 + lags) x BLOCK``
#: extra additions, 0.1 % of a 10^8 record at 4 runs per thread); more runs than threads let the threads
#: share the work when one of them is slowed by other processes.
FUSED_CHUNKS = 4


def fused_lags(n: int, m: np.ndarray):
    """The distinct lags (m and 2m, at least :data:`BLOCK`) of the fused kernel, or None where it does not apply.

    None: fewer than :data:`FUSED_MIN` samples or more than :data:`FUSED_MAX_LAGS` such lags.
    """
    m = np.asarray(m, dtype=np.int64)
    if n < FUSED_MIN or m.size == 0 or int(m.min()) < 1 or 2 * int(m.max()) > n:
        return None
    lags = np.unique(np.concatenate([m, 2 * m]))
    lags = lags[lags >= BLOCK]
    return lags if lags.size <= FUSED_MAX_LAGS else None


def fused_part(y: np.ndarray, m: np.ndarray, block: int, chunks: int) -> np.ndarray:
    """The per-block sums of :func:`_fused2_py`, shape (n_blocks, n_tau), for any ``block`` and number of runs.

    ``m`` (int64, ``1 <= m``, ``2 m <= len(y)``) may have any number of long lags here; :func:`allan_sums_fused`
    calls it with :data:`BLOCK`.  Tests call it with short blocks, which give the same bits as :func:`_phase_py`
    and :func:`_diff2_py` with that block.
    """
    import numba

    m = np.ascontiguousarray(m, dtype=np.int64)
    lags = np.unique(np.concatenate([m, 2 * m]))
    lags = lags[lags >= block]
    slot = {int(v): i for i, v in enumerate(lags)}
    slot_m = np.array([slot.get(int(v), -1) for v in m], dtype=np.int64)
    slot_2m = np.array([slot.get(int(2 * v), -1) for v in m], dtype=np.int64)
    nblocks = (y.size + 1 - 2 * int(m.min()) + block - 1) // block
    mu = float(np.mean(y))
    kern = _compiled()
    offsets = kern["offsets"](y, mu, block)
    chunks = max(1, min(int(chunks), nblocks))
    with numba.parallel_chunksize(1):
        return kern["fused2"](y, mu, offsets, m, lags, slot_m, slot_2m, nblocks, block, chunks)


def allan_sums_fused(y: np.ndarray, m: np.ndarray) -> np.ndarray:
    """Overlapping Allan sums ``sum_{k=0}^{N-2m} (p[k+2m] - 2 p[k+m] + p[k])^2`` straight from the rate.

    Parameters
    ----------
    y : ndarray of float64, shape (N,)
        Rate [deg/h], finite (checked by the caller), contiguous.
    m : ndarray of int64, shape (n_tau,)
        Averaging factors with ``2 m <= N`` and :func:`fused_lags` not None.

    Returns
    -------
    ndarray of float64, shape (n_tau,)
        [(deg/h)^2 x samples^2], with ``p`` the mean-removed angle of :func:`phase_dph_samples`.  Equal bit
        for bit to ``operator_sums(phase_dph_samples(y), m, 1, (1, -2, 1), False)``: the same angle points,
        the same per-block sums (:func:`_fused2_py`), added the same way; the angle array (8 (N + 1) bytes)
        is never stored.
    """
    import numba

    m = np.ascontiguousarray(m, dtype=np.int64)
    if fused_lags(y.size, m) is None:
        raise ValueError("the fused Allan kernel needs at least FUSED_MIN samples and at most "
                         "FUSED_MAX_LAGS long lags")
    with threads_for((y.size + 1) * m.size):
        threads = numba.get_num_threads()
        # FUSED_CHUNKS runs per thread, handed out one at a time: a thread slowed by other work takes fewer
        part = fused_part(y, m, BLOCK, FUSED_CHUNKS * threads if threads > 1 else 1)
    return part.sum(axis=0)
