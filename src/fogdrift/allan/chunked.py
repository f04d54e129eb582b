"""Out-of-core Allan variance (and the Haar wavelet variance) of records larger than memory.

:func:`allan_variance_chunked` gives the same :class:`~fogdrift.allan.AllanResult` as
:func:`fogdrift.allan.allan_variance` on the whole series in memory, bit for bit, while holding only a few
windows of ``chunk_samples`` samples (at most about ``12 * chunk_samples * 8`` bytes: 200 MB at the default
2^21),
whatever the length of the record.  It reads a :class:`fogdrift.io.chunked.ChunkSource` (``.npy``, raw
binary, HDF5) in three streaming passes:

1. the mean ``mu``, by NumPy's own pairwise summation split across windows (the same additions as
   ``np.mean`` of the whole array);
2. the block totals of ``y - mu`` (blocks of 65536 samples, four interleaved accumulators) and their
   Neumaier-compensated running offsets, as the in-memory angle kernel computes them;
3. for each chunk of start indices ``k``, the angle ``theta`` of the windows the cluster sizes need,
   rebuilt by a compiled kernel from the block offsets and a running sum inside each block (so every
   ``theta_k`` equals the in-memory value), and the sums of ``(theta_{k+2m} - 2 theta_{k+m} + theta_k)^2`` per block of 65536
   start indices, added in block order as the in-memory estimator adds them.

Small cluster sizes (``2m <= chunk_samples``) are served from one window per chunk; each larger ``m``
reads two more windows (at ``k + m`` and ``k + 2m``; on an octave grid the window at ``k + 2m`` is the next
tau's window at ``k + m`` and is reused), so the file is read about ``4 + n_large`` times (``n_large`` taus
above ``chunk_samples / 2``), sequentially.  Non-overlapping sums with strides above
1.5 blocks read only the points they need.  The sums become the result (EDF, alpha, chi-squared bounds,
every field) in :func:`fogdrift.allan.core.result_from_sums`, the function the in-memory
:func:`fogdrift.allan.allan_variance` ends in.

The Haar wavelet variance of the MODWT at scale ``tau_j = 2^(j-1) dt`` is half the overlapping Allan
variance at ``m = 2^(j-1)`` (the same second differences over the same ``N - 2m + 1`` positions;
Percival & Walden 2000, sec. 8.6): :func:`haar_wavelet_variance_chunked` reuses the chunked phase.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ConfigError, DataFormatError, InsufficientDataError
from ._kernels import block_sums2
from .ci import resolve_alpha
from .core import IEEE952_ALPHAS, result_from_sums
from .grid import tau_grid
from .statistics import get_statistic

__all__ = ["allan_variance_chunked", "haar_wavelet_variance_chunked", "HaarWaveletVariance", "BLOCK",
           "DEFAULT_CHUNK"]

#: Samples per block of the angle offsets and of the partial sums (the in-memory kernel's block).
BLOCK = 65536
#: Default chunk of start indices (a multiple of BLOCK).
DEFAULT_CHUNK = 1 << 21
_PW_BLOCK = 128     # NumPy's pairwise-summation leaf size: recursion splits only above it


# ----------------------------------------------------------------------------------------
# numba kernels (compiled lazily, cached on disk)
# ----------------------------------------------------------------------------------------
def _theta_py(y, scale, mu, offsets, blk0, out, block):  # pragma: no cover - runs compiled
    """out[i + 1] = theta at sample i + 1 of the window: block offset + running sum of y * scale - mu in the block.

    ``y`` starts at block ``blk0``; the same additions in the same order as the in-memory phase kernel.
    """
    n = y.size
    nb = (n + block - 1) // block
    for ib in prange(nb):
        lo = ib * block
        hi = min(n, lo + block)
        base = offsets[blk0 + ib]
        run = 0.0
        for i in range(lo, hi):
            run += y[i] * scale - mu
            out[i + 1] = base + run


def _totals_py(y, scale, mu, out, block):  # pragma: no cover - runs compiled
    """out[ib] = sum of y * scale - mu over block ib, four interleaved accumulators (as the in-memory kernel)."""
    n = y.size
    nb = (n + block - 1) // block
    for ib in prange(nb):
        lo = ib * block
        hi = min(n, lo + block)
        a0 = 0.0
        a1 = 0.0
        a2 = 0.0
        a3 = 0.0
        i = lo
        while i + 3 < hi:
            a0 += y[i] * scale - mu
            a1 += y[i + 1] * scale - mu
            a2 += y[i + 2] * scale - mu
            a3 += y[i + 3] * scale - mu
            i += 4
        while i < hi:
            a0 += y[i] * scale - mu
            i += 1
        out[ib] = (a0 + a1) + (a2 + a3)


_KERNELS: dict = {}
prange = range


def _kernels():
    if not _KERNELS:
        import numba

        globals()["prange"] = numba.prange
        _KERNELS["totals"] = numba.njit(cache=True, parallel=True)(_totals_py)
        _KERNELS["theta"] = numba.njit(cache=True, parallel=True)(_theta_py)
    return _KERNELS


# ----------------------------------------------------------------------------------------
# passes 1 and 2
# ----------------------------------------------------------------------------------------
def _pairwise_sum(source, lo: int, n: int, leaf: int) -> float:
    """sum(y[lo:lo+n]) with NumPy's pairwise recursion (split at n/2 rounded down to a multiple of 8)."""
    if n <= leaf:
        return float(np.add.reduce(source.read(lo, lo + n)))
    n2 = n // 2
    n2 -= n2 % 8
    return _pairwise_sum(source, lo, n2, leaf) + _pairwise_sum(source, lo + n2, n - n2, leaf)


class _Phase:
    """theta windows of a source: theta_0 = 0, theta_{i+1} = offsets[i // BLOCK] + cumsum within the block."""

    def __init__(self, source, mu: float, offsets: np.ndarray):
        self.source, self.mu, self.offsets = source, mu, offsets
        self.n = source.n_samples

    def window(self, a: int, b: int) -> np.ndarray:
        """theta[a:b] (indices of the N + 1 phase points)."""
        lo_i, hi_i = max(a - 1, 0), b - 1           # theta_{i+1} needs y[block start .. i]
        ya = (lo_i // BLOCK) * BLOCK
        y = self.source.raw(ya, hi_i)
        buf = np.empty(y.size + 1)
        buf[0] = 0.0                                 # theta_0, used when a == 0
        _kernels()["theta"](y, self.source.scale_to_internal, self.mu, self.offsets, ya // BLOCK, buf, BLOCK)
        return buf[a - ya: b - ya]                   # buf[t + 1] = theta[ya + t + 1]

    def points(self, idx) -> np.ndarray:
        return np.array([self.window(int(p), int(p) + 1)[0] for p in idx])


def _mean_and_offsets(source, leaf: int, progress):
    n = source.n_samples
    if source.check is not None:                     # raw binary: sequence counter, streamed once
        for a in range(0, n, leaf):
            source.check(a, min(n, a + leaf))
    mu = _pairwise_sum(source, 0, n, leaf) / n
    if not math.isfinite(mu):
        for a in range(0, n, leaf):
            y = source.read(a, min(n, a + leaf))
            bad = ~np.isfinite(y)
            if bad.any():
                i = a + int(np.argmax(bad))
                raise DataFormatError(f"non-finite value at sample {i}; expected a finite number, got "
                                      f"{float(y[i - a])!r}", path=source.path, column=source.name)
    if progress is not None:
        progress("mean", 1, 1)
    nb = -(-n // BLOCK)
    totals = np.empty(nb)
    kern = _kernels()["totals"]
    step = max(BLOCK, (leaf // BLOCK) * BLOCK)
    for a in range(0, n, step):
        y = source.raw(a, min(n, a + step))
        part = np.empty(-(-y.size // BLOCK))
        kern(y, source.scale_to_internal, mu, part, BLOCK)
        totals[a // BLOCK: a // BLOCK + part.size] = part
    offsets = np.empty(nb + 1)
    s = c = 0.0
    for ib in range(nb):                             # Neumaier, as the in-memory kernel
        offsets[ib] = s + c
        x = float(totals[ib])
        t = s + x
        if abs(s) >= abs(x):
            c += (s - t) + x
        else:
            c += (x - t) + s
        s = t
    offsets[nb] = s + c
    if progress is not None:
        progress("offsets", 1, 1)
    return mu, offsets


# ----------------------------------------------------------------------------------------
# pass 3
# ----------------------------------------------------------------------------------------
def _second_difference_sums(phase: _Phase, m: np.ndarray, strides: np.ndarray, chunk: int, progress) -> np.ndarray:
    n_phase = phase.n + 1
    parts = [[] for _ in m]
    k_end_all = n_phase - 2 * int(m.min())           # start indices k < k_end_all for the smallest m
    n_chunks = -(-k_end_all // chunk)
    small = 2 * m <= chunk
    ext = int(2 * m[small].max()) if small.any() else 0
    for ci, k0 in enumerate(range(0, k_end_all, chunk)):
        k1 = min(k0 + chunk, k_end_all)
        base = phase.window(k0, min(n_phase, k1 + ext))      # theta for every small m of this chunk
        cache = {}                                   # window start -> theta window (octave grids: 2 m_j = m_j+1)
        for j in range(m.size):
            mj, s = int(m[j]), int(strides[j])
            kmax = min(k1, n_phase - 2 * mj)
            kstart = -(-k0 // s) * s
            if kstart >= kmax:
                continue
            nblk = (kmax - 1) // BLOCK - kstart // BLOCK + 1
            out = np.empty(nblk)
            if s > 1.5 * BLOCK:                      # a few terms: read the points only
                ks = np.arange(kstart, kmax, s)
                c = phase.points(ks)
                bb = phase.points(ks + mj)
                a = phase.points(ks + 2 * mj)
                for q, k in enumerate(ks):
                    d = a[q] - 2.0 * bb[q] + c[q]
                    parts[j].append((k // BLOCK, d * d))
                continue
            L = kmax - kstart
            c = base[kstart - k0: kstart - k0 + L]
            if small[j]:
                bb = base[kstart - k0 + mj: kstart - k0 + mj + L]
                a = base[kstart - k0 + 2 * mj: kstart - k0 + 2 * mj + L]
            else:
                start_b, start_a = kstart + mj, kstart + 2 * mj
                hit = cache.get(start_b)
                bb = hit[:L] if hit is not None and hit.size >= L else phase.window(start_b, start_b + L)
                cache.clear()                        # keep at most the window the next m can reuse
                a = phase.window(start_a, start_a + L)
                cache[start_a] = a
            block_sums2(a, bb, c, kstart, s, BLOCK, out)
            del a, bb, c                             # free the windows before the next m reads its own
            first = kstart // BLOCK
            parts[j] += [(first + q, float(v)) for q, v in enumerate(out)]
        del base, cache
        if progress is not None:
            progress("sums", ci + 1, n_chunks)
    sums = np.empty(m.size)
    for j in range(m.size):
        acc = {}
        for blk, v in parts[j]:                      # a block split across two chunks: its halves in k order
            acc[blk] = acc[blk] + v if blk in acc else v
        total = 0.0
        for blk in sorted(acc):                      # blocks added in order, as numpy adds the partial rows
            total += acc[blk]
        sums[j] = total
    return sums


_ESTIMATORS = ("overlapping", "non-overlapping")


def _prepare(source, taus, estimator, max_fraction, chunk_samples, noise_alpha=None):
    if estimator not in _ESTIMATORS:
        raise ConfigError(f"estimator must be one of {list(_ESTIMATORS)} out of core; got {estimator!r}")
    n = int(source.n_samples)
    if n < 2:
        raise InsufficientDataError(f"an Allan variance needs at least 2 rate samples, got {n}", needed=2, got=n)
    if isinstance(chunk_samples, bool) or not isinstance(chunk_samples, (int, np.integer)) or chunk_samples < 1:
        raise ConfigError(f"chunk_samples must be an integer >= 1; got {chunk_samples!r}")
    chunk = max(BLOCK, -(-int(chunk_samples) // BLOCK) * BLOCK)
    m = tau_grid(n, source.dt_s, taus, max_fraction=max_fraction)
    if noise_alpha is not None:  # refused before the file is read (the real choice needs the variances)
        resolve_alpha(noise_alpha, m * source.dt_s, np.ones(m.size), slopes=get_statistic("adev").dev_slopes,
                      candidates=IEEE952_ALPHAS)
    strides = m.copy() if estimator == "non-overlapping" else np.ones_like(m)
    return n, chunk, m, strides


def allan_variance_chunked(source, *, taus="octave", estimator="overlapping", noise_alpha="auto",
                           max_fraction=0.25, chunk_samples=DEFAULT_CHUNK, progress=None):
    """Allan variance of a record read window by window: the in-memory result with bounded memory.

    Parameters
    ----------
    source : fogdrift.io.chunked.ChunkSource
        One axis of a file (:func:`fogdrift.io.chunked.open_source`), in deg/h.
    taus : str, int or array_like
        Tau grid as for :func:`fogdrift.allan.allan_variance` (``"octave"``, ``"decade"``, an int, taus in s).
    estimator : {"overlapping", "non-overlapping"}
        The fast estimator is in-memory only.
    noise_alpha : "auto", "conservative", int or array_like
        Power-law alpha of the EDF, as for :func:`fogdrift.allan.allan_variance`.
    max_fraction : float
        Largest m of named grids as a fraction of N.
    chunk_samples : int
        Start indices per chunk, rounded up to a multiple of 65536; memory is at most about
        ``12 * chunk_samples * 8`` bytes.
    progress : callable, optional
        ``progress(stage, done, total)`` with stage ``"mean"``, ``"offsets"``, ``"sums"`` (chunks).

    Returns
    -------
    AllanResult
        Equal, bit for bit, to ``allan_variance(whole_series, dt_s, ...)`` with the same options.

    Raises
    ------
    ConfigError, InsufficientDataError
        Bad options or fewer than 2 samples.
    DataFormatError
        A non-finite sample (located) or a sequence-counter gap (raw binary).

    Examples
    --------
    >>> import numpy as np, tempfile, os
    >>> from fogdrift.io.chunked import open_source
    >>> from fogdrift.allan import allan_variance
    >>> p = os.path.join(tempfile.mkdtemp(), "x.npy")
    >>> y = np.random.default_rng(1).normal(size=200_000).astype(np.float32)
    >>> np.save(p, y)
    >>> src = open_source(p, rate_hz=100.0, unit="deg/h")
    >>> r = allan_variance_chunked(src, chunk_samples=65536)
    >>> bool(np.array_equal(r.avar_dph2, allan_variance(y, 0.01).avar_dph2))
    True
    """
    n, chunk, m, strides = _prepare(source, taus, estimator, max_fraction, chunk_samples, noise_alpha)
    mu, offsets = _mean_and_offsets(source, chunk, progress)
    sums = _second_difference_sums(_Phase(source, mu, offsets), m, strides, chunk, progress)
    return result_from_sums(sums, n, m, strides, source.dt_s, statistic="adev", estimator=estimator,
                            noise_alpha=noise_alpha)


@dataclass(frozen=True)
class HaarWaveletVariance:
    """Haar MODWT wavelet variance per level (unbiased estimator, boundary coefficients excluded).

    Attributes
    ----------
    level : ndarray of int
        Levels j = 1, 2, ...
    tau_s : ndarray
        Scales ``tau_j = 2^(j-1) dt_s`` in s.
    wv_dph2 : ndarray
        Wavelet variance in (deg/h)^2: mean of the squared level-j coefficients
        ``W_j,t = (mean of y over the last tau_j samples - mean over the tau_j before) / 2``.
    n_coefficients : ndarray of int
        Coefficients averaged, ``N - 2^j + 1``.
    """

    level: np.ndarray
    tau_s: np.ndarray
    wv_dph2: np.ndarray
    n_coefficients: np.ndarray


def haar_wavelet_variance_chunked(source, *, levels=None, chunk_samples=DEFAULT_CHUNK,
                                  progress=None) -> HaarWaveletVariance:
    """Haar wavelet variance at levels 1..J of a record read window by window (half the overlapping AVAR).

    Parameters
    ----------
    source : fogdrift.io.chunked.ChunkSource
    levels : int, optional
        Highest level J (default: the largest with ``2^J <= N``).
    chunk_samples : int
        As for :func:`allan_variance_chunked`.

    Returns
    -------
    HaarWaveletVariance
    """
    n = int(source.n_samples)
    j_max = int(math.floor(math.log2(n))) if n >= 2 else 0
    if n < 2:
        raise InsufficientDataError(f"a wavelet variance needs at least 2 samples, got {n}", needed=2, got=n)
    if levels is not None:
        if isinstance(levels, bool) or not isinstance(levels, (int, np.integer)) or not 1 <= levels <= j_max:
            raise ConfigError(f"levels must be an integer in 1..{j_max} for {n} samples; got {levels!r}")
        j_max = int(levels)
    tau_m = 2 ** np.arange(j_max, dtype=np.int64)
    _, chunk, _, _ = _prepare(source, [1], "overlapping", 0.25, chunk_samples)
    mu, offsets = _mean_and_offsets(source, chunk, progress)
    sums = _second_difference_sums(_Phase(source, mu, offsets), tau_m, np.ones_like(tau_m), chunk, progress)
    n_terms = n - 2 * tau_m + 1
    avar = sums / (2.0 * tau_m.astype(np.float64) ** 2 * n_terms)
    return HaarWaveletVariance(level=np.arange(1, j_max + 1), tau_s=tau_m * source.dt_s, wv_dph2=avar / 2.0,
                               n_coefficients=n_terms)
