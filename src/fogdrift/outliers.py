"""Outliers and heavy tails in a rate record: detection, and the two explicit treatments.

A gyro record with spikes (bad frames, EMI, a logger glitch) has an inflated Allan variance at every tau: a few
per cent of samples beyond six sigma can raise the short-tau ADEV by tens of per cent (the MTi-G log of the test
data: 5 % of samples beyond 6 robust sigma inflate its ADEV 1.44x).  Nothing is changed silently:
:func:`find_outliers` only reports, :func:`treat_outliers` clips or replaces, and both say how many samples and
where.

Robust scale.  The record is cut into blocks of ``block`` samples; each sample's deviation from its block median
removes the slow drift (and any bias), and ``sigma = 1.4826 MAD`` of those deviations is the scale a Gaussian core
would have.  A sample is an outlier when its deviation exceeds ``threshold`` robust sigmas (default 6: a Gaussian
record of 10^9 samples has about two such samples by chance).

Memory and speed.  The block medians are computed by a compiled quickselect (one block-sized buffer per
thread), the median of the absolute deviations by an exact radix selection over their float64 bit patterns
for records above :data:`SELECT_ABOVE` samples (four counting passes, no array of deviations), and the
flags by one compiled pass: besides the record (float32 or float64, not copied) the detector holds the block
medians (n / block values), a bool mask (n bytes) and the indices of the flagged samples.  The results are
those of the plain NumPy algorithm above, equal to the bit (``tests/test_outliers.py``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ._util import check_series
from .allan._kernels import threads_for
from .constraints import Choice, Setting
from .errors import ConfigError

__all__ = ["OutlierReport", "find_outliers", "treat_outliers", "OUTLIER_ACTIONS", "OUTLIERS_SETTING"]

#: Treatments accepted by :func:`treat_outliers` (``"warn"`` only reports).
OUTLIER_ACTIONS = ("warn", "clip", "replace")

#: The analyses' setting of what happens to outliers before them (:mod:`fogdrift.constraints`): the
#: ``AnalysisConfig.outliers`` default and rule, and the ``--outliers`` option.
OUTLIERS_SETTING = Setting("outliers", "warn", Choice(OUTLIER_ACTIONS), "--outliers",
                           "Samples beyond 6 robust sigma: warn (default), clip (to 6 sigma) or replace (by the "
                           "local median).")

_MAD_TO_SIGMA = 1.482602218505602  # 1 / Phi^-1(3/4)


@dataclass(frozen=True)
class OutlierReport:
    """What :func:`find_outliers` / :func:`treat_outliers` found and did.

    Attributes
    ----------
    n_samples, count : int
        Record length and number of samples beyond the threshold.
    fraction : float
        ``count / n_samples``.
    threshold_sigma : float
        Threshold in robust sigmas.
    robust_sigma_dph : float
        Robust scale of the deviations from the block medians [deg/h].
    max_abs_deviation_dph : float
        Largest deviation [deg/h].
    per_tenth : tuple of int
        Outlier counts in each tenth of the record (where they are).
    first_index : tuple of int
        Up to ten sample indices of the first outliers.
    action : str
        ``"none"`` (reported only), ``"clip"`` or ``"replace"``.
    """

    n_samples: int
    count: int
    fraction: float
    threshold_sigma: float
    robust_sigma_dph: float
    max_abs_deviation_dph: float
    per_tenth: tuple
    first_index: tuple
    action: str

    def spread(self) -> str:
        """'spread over the whole record' or 'concentrated in tenth(s) ...' (for messages)."""
        if self.count == 0:
            return "none"
        tenths = np.asarray(self.per_tenth, dtype=float)
        share = tenths / tenths.sum()
        if np.count_nonzero(share >= 0.05) >= 8:
            return "spread over the whole record"
        busy = [str(k + 1) for k in np.argsort(share)[::-1][:3] if share[k] > 0]
        return "concentrated in tenth(s) " + ", ".join(busy) + " of the record"

    def summary(self, dt_s: float | None = None) -> str:
        """One line: count, fraction, threshold, where, and what was done."""
        if self.count == 0:
            return f"no samples beyond {self.threshold_sigma:g} robust sigma ({self.robust_sigma_dph:.3g} deg/h)"
        first = self.first_index[0]
        at = f"first at sample {first}" + (f" (t = {first * dt_s:.6g} s)" if dt_s else "")
        done = {"none": "not changed (use --outliers clip|replace to treat them)",
                "clip": f"clipped to +-{self.threshold_sigma:g} sigma around the local median",
                "replace": "replaced by the local median"}[self.action]
        return (f"{self.count} samples ({100 * self.fraction:.3g} %) beyond {self.threshold_sigma:g} robust sigma "
                f"({self.robust_sigma_dph:.3g} deg/h; largest deviation {self.max_abs_deviation_dph:.3g} deg/h), "
                f"{self.spread()}, {at}; {done}")

    def to_dict(self) -> dict:
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in self.__dict__.items()}


#: Records longer than this [samples] take the median of |deviation| by an exact radix selection over the
#: float64 bit patterns (four counting passes, no array of deviations); shorter ones by ``np.median``.
SELECT_ABOVE = 1 << 22

#: Samples per chunk of the finiteness check of a float array (bounded extra memory: one bool chunk).
_CHECK_CHUNK = 1 << 22

_KERNELS: dict = {}
prange = range  # replaced by numba.prange in _compiled()
_select = None  # replaced by the compiled quickselect in _compiled()


def _select_py(buf, n, k):  # pragma: no cover - runs compiled
    """Partially order buf[:n] in place so that buf[k] is its k-th smallest value (Hoare's quickselect)."""
    lo = 0
    hi = n - 1
    while hi > lo:
        pivot = buf[(lo + hi) // 2]
        i = lo
        j = hi
        while i <= j:
            while buf[i] < pivot:
                i += 1
            while buf[j] > pivot:
                j -= 1
            if i <= j:
                t = buf[i]
                buf[i] = buf[j]
                buf[j] = t
                i += 1
                j -= 1
        if k <= j:
            hi = j
        elif k >= i:
            lo = i
        else:
            break
    return buf[k]


def _block_medians_py(x, block, out):  # pragma: no cover - runs compiled
    """out[ib] = median of x[ib*block : (ib+1)*block] in float64 (the last block may be shorter); the mean of
    the two middle values for an even count, as ``np.median``."""
    n = x.size
    nb = out.size
    nthr = 64
    per = (nb + nthr - 1) // nthr
    for t in prange(nthr):
        buf = np.empty(block)
        for ib in range(t * per, min(nb, (t + 1) * per)):
            lo = ib * block
            hi = min(n, lo + block)
            m = hi - lo
            for i in range(lo, hi):
                buf[i - lo] = x[i]
            upper = _select(buf, m, m // 2)
            if m % 2:
                out[ib] = upper
            else:  # the lower middle value is the largest of buf[:m // 2]
                lower = buf[0]
                for i in range(1, m // 2):
                    if buf[i] > lower:
                        lower = buf[i]
                out[ib] = (lower + upper) / 2.0


def _scan_py(x, med, block, limit, mask):  # pragma: no cover - runs compiled
    """mask[i] = |x[i] - med[i // block]| > limit; returns (count, max |deviation|)."""
    n = x.size
    count = 0
    top = 0.0
    for i in range(n):
        d = abs(float(x[i]) - med[i // block])
        if d > top:
            top = d
        if d > limit:
            mask[i] = True
            count += 1
    return count, top


def _radix_hist_py(x, med, block, shift, prefix, pshift, hist):  # pragma: no cover - runs compiled
    """Histogram of the 16 bits above ``shift`` of the bit patterns of |x - med| whose bits from ``pshift`` up
    equal ``prefix`` (every value when ``pshift`` < 0); a non-negative double's bit pattern orders like its
    value.  Rows of ``hist`` are per-thread partial histograms."""
    n = x.size
    nchunk = hist.shape[0]
    step = (n + nchunk - 1) // nchunk
    for c in prange(nchunk):
        lo = c * step
        hi = min(n, lo + step)
        buf = np.empty(4096)
        bits = buf.view(np.int64)
        for a in range(lo, hi, 4096):
            b = min(hi, a + 4096)
            for i in range(a, b):
                buf[i - a] = abs(float(x[i]) - med[i // block])
            for i in range(b - a):
                u = bits[i]
                if pshift < 0 or (u >> pshift) == prefix:
                    hist[c, (u >> shift) & 0xFFFF] += 1


def _moments_py(x, med, block):  # pragma: no cover - runs compiled
    """Mean and mean squared deviation of d = x - med (two passes, compensated sums)."""
    n = x.size
    s = 0.0
    c = 0.0
    for i in range(n):
        v = float(x[i]) - med[i // block] - c
        t = s + v
        c = (t - s) - v
        s = t
    mean = s / n
    s = 0.0
    c = 0.0
    for i in range(n):
        e = float(x[i]) - med[i // block] - mean
        v = e * e - c
        t = s + v
        c = (t - s) - v
        s = t
    return mean, s / n


def _compiled():
    if not _KERNELS:
        import numba

        globals()["prange"] = numba.prange
        globals()["_select"] = numba.njit(cache=True)(_select_py)
        _KERNELS["medians"] = numba.njit(cache=True, parallel=True)(_block_medians_py)
        _KERNELS["scan"] = numba.njit(cache=True)(_scan_py)
        _KERNELS["hist"] = numba.njit(cache=True, parallel=True)(_radix_hist_py)
        _KERNELS["moments"] = numba.njit(cache=True)(_moments_py)
    return _KERNELS


def _as_rate(y) -> np.ndarray:
    """A 1-D float32/float64 array of the rate, checked finite, without a float64 copy of a float array.

    Anything else goes through :func:`fogdrift._util.check_series` (its messages)."""
    x = y
    if isinstance(x, np.ndarray) and x.ndim == 1 and x.dtype in (np.float32, np.float64) and x.size >= 2:
        for a in range(0, x.size, _CHECK_CHUNK):
            if not np.isfinite(x[a:a + _CHECK_CHUNK]).all():
                return check_series(x, "y", min_length=2)  # raises, naming the first bad sample
        return x
    return check_series(y, "y", min_length=2)


def block_medians(x: np.ndarray, block: int) -> np.ndarray:
    """Median [deg/h, float64] of each block of ``block`` samples of ``x`` (the last block may be shorter)."""
    out = np.empty(-(-x.size // block))
    kern = _compiled()["medians"]
    with threads_for(10 * x.size):  # a quickselect touches each sample a few times
        kern(x, int(block), out)
    return out


def _select_abs_dev(x, med, block, ranks) -> list:
    """The values of rank ``ranks`` (0-based) among |x[i] - med[i // block]|, exactly, in four counting passes.

    Radix selection on the float64 bit pattern, 16 bits per pass from the top: the bit pattern of a
    non-negative double orders like its value, so each pass narrows every rank to one 16-bit digit.
    Extra memory: one (chunks, 65536) int64 histogram, whatever the record length.
    """
    import numba

    kern = _compiled()["hist"]
    out = []
    nchunk = max(1, numba.get_num_threads())  # per-thread histograms; the counts do not depend on it
    for rank in ranks:
        prefix, r = 0, int(rank)
        for shift in (48, 32, 16, 0):
            hist = np.zeros((nchunk, 1 << 16), dtype=np.int64)
            with threads_for(x.size):
                kern(x, med, int(block), shift, prefix, shift + 16 if shift < 48 else -1, hist)
            cum = np.cumsum(hist.sum(axis=0))
            digit = int(np.searchsorted(cum, r, side="right"))
            r -= int(cum[digit - 1]) if digit else 0
            prefix = (prefix << 16) | digit
        out.append(float(np.int64(prefix).view(np.float64)))
    return out


def _robust_sigma(x, med, block) -> float:
    """1.4826 x the median of |x - local median| [deg/h] (``np.median`` semantics: mean of the two middle
    values for an even count)."""
    n = x.size
    if n <= SELECT_ABOVE:
        local = np.repeat(med, block)[:n]
        return _MAD_TO_SIGMA * float(np.median(np.abs(x - local)))
    lo_hi = _select_abs_dev(x, med, block, sorted({(n - 1) // 2, n // 2}))
    mid = lo_hi[0] if len(lo_hi) == 1 else (lo_hi[0] + lo_hi[1]) / 2.0
    return _MAD_TO_SIGMA * float(mid)


def find_outliers(y, *, threshold=6.0, block=100):
    """Flag samples beyond ``threshold`` robust sigmas of their block median.

    Parameters
    ----------
    y : array_like, shape (n_samples,)
        The series in its channel's internal unit (deg/h, m/s^2).
    threshold : float
        Threshold in robust sigmas (> 0).
    block : int
        Block length [samples] of the local median (>= 5).

    Returns
    -------
    mask : ndarray of bool, shape (n_samples,)
    report : OutlierReport

    Examples
    --------
    >>> import numpy as np
    >>> x = np.random.default_rng(0).standard_normal(10_000)
    >>> x[[10, 5000]] = 50.0
    >>> mask, rep = find_outliers(x)
    >>> rep.count, np.flatnonzero(mask).tolist()
    (2, [10, 5000])
    """
    x = _as_rate(y)
    thr = float(threshold)
    if not (thr > 0 and math.isfinite(thr)):
        raise ConfigError(f"outlier threshold must be a finite number of sigmas > 0, got {threshold!r}")
    block = int(block)
    if block < 5:
        raise ConfigError(f"outlier block must be >= 5 samples, got {block}")
    block = min(block, x.size)
    med = block_medians(x, block)
    sigma = _robust_sigma(x, med, block)
    if sigma == 0.0:  # quantised or constant record: fall back to the standard deviation of the deviations
        sigma = math.sqrt(_compiled()["moments"](x, med, block)[1])
    mask = np.zeros(x.size, dtype=bool)
    count, top = _compiled()["scan"](x, med, block, thr * sigma if sigma > 0 else math.inf, mask)
    idx = np.flatnonzero(mask) if count else np.zeros(0, dtype=np.int64)
    tenths = np.bincount((idx * 10) // x.size, minlength=10)[:10] if idx.size else np.zeros(10, int)
    report = OutlierReport(
        n_samples=int(x.size), count=int(idx.size), fraction=float(idx.size / x.size), threshold_sigma=thr,
        robust_sigma_dph=sigma, max_abs_deviation_dph=float(top),
        per_tenth=tuple(int(v) for v in tenths), first_index=tuple(int(i) for i in idx[:10]), action="none",
    )
    return mask, report


def treat_outliers(y, action="clip", *, threshold=6.0, block=100):
    """Return a treated copy of the rate and the report.

    ``action="clip"`` limits each outlier's deviation to ``+-threshold`` robust sigmas around its block median
    (the sample keeps its sign and part of its size); ``"replace"`` sets it to the block median; ``"warn"``
    returns the input unchanged.  The record keeps its length and sampling, so Allan and wavelet variances stay
    defined.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.random.default_rng(1).standard_normal(1000); x[500] = 1e6
    >>> y, rep = treat_outliers(x, "replace")
    >>> rep.count, rep.action, abs(float(y[500])) < 1.0
    (1, 'replace', True)
    """
    if action not in OUTLIER_ACTIONS:
        raise ConfigError(f"outlier action must be one of {OUTLIER_ACTIONS}, got {action!r} (option {{opt:outliers}})")
    x = _as_rate(y)
    mask, report = find_outliers(x, threshold=threshold, block=block)
    if action == "warn" or report.count == 0:
        return x, report
    blk = min(int(block), x.size)
    idx = np.flatnonzero(mask)
    local = block_medians(x, blk)[idx // blk]
    y = np.array(x, dtype=np.float64)
    if action == "clip":
        lim = report.threshold_sigma * report.robust_sigma_dph
        y[idx] = local + np.clip(y[idx] - local, -lim, lim)
    else:
        y[idx] = local
    return y, OutlierReport(**{**report.__dict__, "action": action})
