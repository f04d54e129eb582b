"""Periodic content and output filters of a rate record, read from its spectrum, with a stated false-alarm rate.

A sinusoid ``Omega0 sin(2 pi f0 t)`` in the rate has the Allan variance ``Omega0^2 sin^4(pi f0 tau) / (pi f0 tau)^2``
(IEEE Std 952-1997 Annex C.5), whose envelope falls as ``tau^-2`` exactly like quantization noise: a tone, a
vibration or a phase-ramp (sawtooth) error in the short-tau region is easily read as Q with a tight interval.  The
spectrum tells them apart: this module finds the lines, groups harmonics into periodic components and says whether
the spectrum shows an output low-pass / anti-alias roll-off.  Rates are in deg/h, frequencies in Hz.

Method (:func:`analyse_spectrum`)

1. Welch PSD, one-sided density [(deg/h)^2/Hz], periodic Hann window, 50 % overlap, segment length ``2^k`` giving
   at least 32 segments (64 to 65536 samples), computed chunk by chunk (memory bounded by the chunk, not ``n``).
2. Each bin ``P_k`` is tested against the larger of the medians of the ``w`` bins left and the ``w`` bins right of
   it (``w`` odd, 7 to 15), leaving out the bin and its two neighbours on each side (the Hann main lobe).  For any
   monotone smooth spectrum (white, random walk, flicker, quantization, low-passed white) the larger one-sided
   median is not below the local level, whatever the curvature, and a median is robust to other lines.  Under no
   line ``P_k / S ~ X = chi^2_nu / nu`` with the Welch EDF ``nu = 2K / (1 + 2 sum_j (1 - j/K) rho_j^2)`` (Percival &
   Walden 1993, eq. 292b; ``rho_j`` the window's overlap correlation, 1/6 for Hann at 50 %, so
   ``nu = 36 K^2 / (19 K - 1)``, eq. 292c), taken as ``0.9 nu`` (measured: the chi^2 tail is slightly light).  Each
   median is the order statistic of ``w_eff = w / (1 + 2 sum_d |rho_d|^2)`` independent ``X`` (the Hann neighbour-
   bin correlation), their maximum has CDF ``F_med^2``, and the p-value ``int sf_X(r m) dF_med(m)^2`` is exact for
   that model.  The p-values are Sidak-corrected over the searched bins.
3. The same test runs on the PSD averaged over 4, 16, 64 and 256 adjacent bins (while at least 64 such bins
   remain; the EDF of the average from the same correlations), so a broad vibration peak that is flat at the Welch
   resolution is found too; the family-wise rate is split equally over the resolutions (Bonferroni), so a record
   without lines gets any line with probability at most ``false_alarm``.  Contiguous significant bins (gaps of up
   to 2) are one line; a coarser cluster replaces the finer line inside it when it holds 1.5 times its power.  A
   tone's frequency comes from Gaussian (log-parabolic) interpolation of its peak, a broad line's from the centroid
   of its excess power; power = sum over the cluster and its main lobe of ``(P - floor) df`` (the density scaling
   already accounts for the window's ENBW; the floor is the geometric mean of the two medians over the median of
   ``X``, unbiased on a locally straight log-spectrum), amplitude ``sqrt(2 power)``.
4. Lines whose frequencies are whole multiples of a lower line (within 1.5 bins, harmonics taken in order with at
   most two missing; once three lines make a series, any higher multiple within 1 bin) form a
   :class:`PeriodicComponent`; its fundamental is the least-squares ``f0`` of the lines.
5. Roll-off: on the line-free spectrum (lines replaced by their floor) in 1/6-octave bands, a flat white-noise
   plateau (slope within 1.5 dB/octave over two octaves) followed by a monotone fall to at least 6 dB below it at
   Nyquist; the corner is where the level first falls 3 dB below the plateau.

References
----------
.. [1] D. B. Percival, A. T. Walden, *Spectral Analysis for Physical Applications*, Cambridge 1993, Sec. 6.17,
   eqs. (292b), (292c).
.. [2] P. D. Welch, "The use of fast Fourier transform for the estimation of power spectra", IEEE Trans. Audio
   Electroacoust. AU-15 (1967) 70-73.
.. [3] IEEE Std 952-1997, Annex C.5 (sinusoidal noise).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._util import check_count, check_series
from ..errors import ConfigError
from ..units import check_dt_s
from ._spectral_null import _null_and_critical
from .distributions import chi2_median

__all__ = ["SpectralLine", "PeriodicComponent", "SpectrumSummary", "analyse_spectrum", "welch_psd", "sinusoid_avar",
           "MIN_SAMPLES"]

#: Fewest samples analysed; a shorter record gets an empty summary with the reason.
MIN_SAMPLES = 256
_MIN_SEGMENTS = 32  # target number of Welch segments (EDF ~ 60)
_NPERSEG_MIN, _NPERSEG_MAX = 64, 65536
_GUARD = 2  # bins either side of the tested bin left out of its floor (the Hann main lobe)
_W_MAX, _W_MIN = 15, 7  # floor half-window [bins], odd
_MERGE_GAP = 2  # significant bins at most this far apart are one line
_LEVELS = (1, 4, 16, 64, 256)  # resolutions searched: the Welch bins averaged in groups of L (broad lines)
_MIN_COARSE_BINS = 64  # a coarser resolution is searched only when it keeps at least this many bins
_BROAD_POWER_RATIO = 1.5  # a coarse cluster replaces a finer line when it holds this much more power
#: The chi^2_nu law with the Welch EDF matches the variance of a (bin-averaged) Welch estimate but its tail is a
#: little light: on 600 white records of 2^16 samples the bins beyond its 1e-4 point were 1.13x (Welch bins),
#: 1.38x (4 bins averaged) and 1.32x (16) the nominal rate; the test uses 0.9 nu, which is conservative at all three.
_EDF_SAFETY = 0.9
_BROAD_WIDTH_BINS = 4.0  # a line wider than this many Welch bins is "broad"
_ROLLOFF_DB = 6.0  # a roll-off is reported when Nyquist is at least this far below the white plateau
_PLATEAU_DB_PER_OCT = 1.5  # |slope| of a white plateau
_PLATEAU_OCTAVES = 2.0  # span of the plateau fit
_MONOTONE_TOL_DB = 1.0  # a band may rise this much above the running minimum and still count as falling


def _finite_or_none(x):
    if x is None:
        return None
    x = float(x)
    return x if math.isfinite(x) else None


@dataclass(frozen=True)
class SpectralLine:
    """One spectral line (a sinusoid in the rate).

    Attributes
    ----------
    freq_hz : float
        Refined centre frequency [Hz] (log-parabolic interpolation of the Welch peak; within 0.5 % for a clean tone).
    amplitude_dph : float
        Peak amplitude ``Omega0`` [deg/h] of the equivalent sinusoid, from the line's power.
    power_dph2 : float
        Variance the line contributes [(deg/h)^2], ``amplitude_dph^2 / 2``: the power above the local floor over
        the significant bins and the main lobe (for a broad resonance, whose skirts merge into the floor, a lower
        bound: 70 % of a Q = 20 resonance's variance in the tests).
    snr_db : float
        Line power against the local noise floor in one bin's noise bandwidth (floor x ENBW) [dB].
    p_value : float
        False-alarm probability of the line under the no-line hypothesis, after the Sidak correction over the
        searched bins.
    harmonic_of : float or None
        Fundamental frequency [Hz] when this line is a harmonic of another line found; None otherwise.
    width_hz : float
        Twice the RMS spread [Hz] of the line's excess power about ``freq_hz`` (about one bin for a tone).
    broad : bool
        True when ``width_hz`` exceeds 4 Welch bins (a tone is about 1.2 bins wide): a vibration hump or a wandering
        line rather than a tone; its Allan variance has no clean nulls at whole periods.
    """

    freq_hz: float
    amplitude_dph: float
    power_dph2: float
    snr_db: float
    p_value: float
    harmonic_of: float | None = None
    width_hz: float = 0.0
    broad: bool = False

    def to_dict(self) -> dict:
        return {k: (v if isinstance(v, bool) else _finite_or_none(v)) for k, v in self.__dict__.items()}


@dataclass(frozen=True)
class PeriodicComponent:
    """A fundamental with its harmonics (a sawtooth / phase-ramp error, a vibration); a single line is a component
    of one line.

    Attributes
    ----------
    fundamental_hz : float
        Least-squares fundamental [Hz] over the component's lines.
    period_s : float
        ``1 / fundamental_hz`` [s].
    lines : tuple of SpectralLine
        The fundamental's line first, then the harmonics by frequency.
    power_dph2 : float
        Total variance of its lines [(deg/h)^2].
    """

    fundamental_hz: float
    period_s: float
    lines: tuple
    power_dph2: float

    @property
    def n_harmonics(self) -> int:
        """Number of lines beyond the fundamental."""
        return len(self.lines) - 1

    def to_dict(self) -> dict:
        return {"fundamental_hz": _finite_or_none(self.fundamental_hz), "period_s": _finite_or_none(self.period_s),
                "power_dph2": _finite_or_none(self.power_dph2), "lines": [ln.to_dict() for ln in self.lines]}


def _freq_text(f_hz: float, df_hz: float) -> str:
    """A frequency [Hz] with the decimals its resolution supports (one tenth of a bin)."""
    dec = int(min(6, max(0, math.ceil(-math.log10(df_hz / 10.0))))) if df_hz > 0 else 3
    return f"{f_hz:.{dec}f} Hz"


def _sig2(x: float) -> str:
    """Two significant digits, no trailing point: 24 -> '24', 5 -> '5.0', 0.0123 -> '0.012'."""
    return f"{x:#.2g}".rstrip(".") if abs(x) < 100 else f"{x:.0f}"


def _p_text(p: float) -> str:
    return "p < 1e-6" if p < 1e-6 else f"p = {p:.2g}"


@dataclass(frozen=True)
class SpectrumSummary:
    """What the spectrum of a rate record shows: lines, periodic components, an output low-pass.

    Attributes
    ----------
    dt_s : float
        Sample interval [s].
    n_samples : int
        Samples analysed.
    false_alarm : float
        Family-wise false-alarm rate of the line search (probability of any line on a line-free record).
    resolution_hz : float
        Welch bin spacing ``1 / (nperseg dt)`` [Hz] (the noise bandwidth of a bin is 1.5 times it, Hann).
    lines : tuple of SpectralLine
        Sorted by power, descending (at most ``max_lines``).
    components : tuple of PeriodicComponent
        Lines grouped by harmonic relation, by power, descending; every line is in exactly one.
    rolloff_hz : float or None
        Corner [Hz] of an output low-pass / anti-alias filter when the spectrum shows one; None otherwise.
    rolloff_db : float or None
        How far the top of the band lies below the white plateau [dB]; None without a roll-off.
    variance_dph2 : float
        Variance of the record about its mean [(deg/h)^2] (the lines' shares are of this).
    searched_bins : int
        Number of frequency bins tested (the multiple-test correction is over these).
    band_hz : (float, float) or None
        Lowest and highest searched frequency [Hz].
    note : str
        Why the summary is empty (record too short, constant), else "".
    """

    dt_s: float
    n_samples: int
    false_alarm: float
    resolution_hz: float
    lines: tuple = ()
    components: tuple = ()
    rolloff_hz: float | None = None
    rolloff_db: float | None = None
    variance_dph2: float = 0.0
    searched_bins: int = 0
    band_hz: tuple | None = None
    note: str = ""

    def periods_s(self) -> tuple:
        """Period [s] of each component (``1 / fundamental``), in the order of :attr:`components`."""
        return tuple(c.period_s for c in self.components)

    def describe(self) -> list:
        """Plain one-line sentences with units, one per component, then the roll-off (or why nothing was found)."""
        if self.note:
            return [self.note]
        df = self.resolution_hz
        rate = f"false-alarm rate {100.0 * self.false_alarm:.3g} % over {self.searched_bins} bins"
        out = []
        for c in self.components:
            if len(c.lines) == 1:
                ln = c.lines[0]
                kind = f"broad spectral peak ({ln.width_hz:.2g} Hz wide)" if ln.broad else "spectral line"
                out.append(f"{kind} at {_freq_text(ln.freq_hz, df)}, amplitude {_sig2(ln.amplitude_dph)} deg/h, "
                           f"{_sig2(100.0 * ln.power_dph2 / self.variance_dph2)} % of the variance "
                           f"({_p_text(ln.p_value)}, {rate})")
            else:
                share = 100.0 * c.power_dph2 / self.variance_dph2 if self.variance_dph2 > 0 else float("nan")
                n_h = c.n_harmonics
                out.append(f"periodic error with period {c.period_s:#.3g} s ({_freq_text(c.fundamental_hz, df)} and "
                           f"{n_h} harmonic{'s' if n_h != 1 else ''}), {_sig2(share)} % of the variance")
        if not self.lines and self.band_hz is not None:
            out.append(f"no spectral line from {_freq_text(self.band_hz[0], df)} to {_freq_text(self.band_hz[1], df)} "
                       f"({rate}, resolution {_freq_text(df, df)})")
        if self.rolloff_hz is not None:
            nyq = 0.5 / self.dt_s
            out.append(f"output low-pass: the rate PSD falls {self.rolloff_db:.0f} dB from "
                       f"{self.rolloff_hz:.3g} Hz to Nyquist ({nyq:.4g} Hz)")
        return out

    def to_dict(self) -> dict:
        """Strict-JSON-able dict (floats finite or None)."""
        return {
            "dt_s": _finite_or_none(self.dt_s), "n_samples": int(self.n_samples),
            "false_alarm": _finite_or_none(self.false_alarm), "resolution_hz": _finite_or_none(self.resolution_hz),
            "lines": [ln.to_dict() for ln in self.lines], "components": [c.to_dict() for c in self.components],
            "periods_s": [_finite_or_none(p) for p in self.periods_s()],
            "rolloff_hz": _finite_or_none(self.rolloff_hz), "rolloff_db": _finite_or_none(self.rolloff_db),
            "variance_dph2": _finite_or_none(self.variance_dph2), "searched_bins": int(self.searched_bins),
            "band_hz": None if self.band_hz is None else [_finite_or_none(b) for b in self.band_hz],
            "note": self.note, "describe": self.describe(),
        }


# ----------------------------------------------------------------------------------------------------------------
# Welch PSD and its statistics


def _nperseg(n: int) -> int:
    """Segment length: the largest power of two giving at least ``_MIN_SEGMENTS`` half-overlapped segments."""
    k = int(math.floor(math.log2(max(2.0 * n / (_MIN_SEGMENTS + 1), 1.0))))
    return int(min(_NPERSEG_MAX, max(_NPERSEG_MIN, 2**k)))


def _welch(x: np.ndarray, fs_hz: float, nperseg: int, chunk_samples: int = 1 << 21, offset: float = 0.0):
    """One-sided Welch PSD [(unit)^2/Hz] (Hann, 50 % overlap, mean removed per segment), chunk by chunk.

    Returns (f_hz, psd, n_segments).  The estimate of ``scipy.signal.welch(x - offset, fs_hz, "hann", nperseg,
    nperseg // 2, detrend="constant", scaling="density")`` (Welch 1967; the tests hold it to that call within
    1e-12 relative): each segment ``s`` of ``nperseg`` samples, step ``nperseg // 2``, gives ``|FFT(h (s -
    mean(s)))|^2 / (fs sum h^2)``, doubled away from 0 and Nyquist, and the segments are averaged.  Written here
    on :func:`scipy.fft.rfft` because ``import scipy.signal`` costs every command that reads a spectrum 0.9 s
    (it loads ``scipy.stats``; bench/bench_startup.py).  ``offset`` [unit] is subtracted chunk by chunk; memory
    is bounded by the chunk (about ``chunk_samples``), not by ``n``.
    """
    from numpy.lib.stride_tricks import sliding_window_view
    from scipy.fft import rfft

    step = nperseg - nperseg // 2  # noverlap = nperseg // 2
    n_seg = (x.size - nperseg) // step + 1
    per_chunk = max(1, int(chunk_samples) // nperseg)
    h = _window(nperseg)
    scale = 1.0 / (fs_hz * float(np.sum(h * h)))
    acc = np.zeros(nperseg // 2 + 1)
    done = 0
    while done < n_seg:
        j = min(per_chunk, n_seg - done)
        a = done * step
        seg = x[a: a + (j - 1) * step + nperseg]
        seg = sliding_window_view(seg if offset == 0.0 else seg - offset, nperseg)[::step]
        d = seg - seg.mean(axis=1, keepdims=True)
        d *= h
        F = rfft(d, axis=1)
        acc += np.sum(F.real * F.real + F.imag * F.imag, axis=0)
        done += j
    p = acc * (scale / n_seg)
    p[1: -1 if nperseg % 2 == 0 else None] *= 2.0  # the negative frequencies folded in; Nyquist is its own
    return np.arange(nperseg // 2 + 1) * (fs_hz / nperseg), p, n_seg


def welch_psd(x, dt_s) -> tuple[np.ndarray, np.ndarray]:
    """The one-sided Welch PSD of a record, as :func:`analyse_spectrum` takes it: ``(f_hz, psd)``, ``psd`` in
    (unit of ``x``)^2/Hz, the mean removed, Hann segments of :func:`_nperseg` samples (all of a record shorter
    than that) at 50 % overlap, computed chunk by chunk.

    >>> f, p = welch_psd(np.random.default_rng(0).standard_normal(2**14), 0.01)
    >>> f.size, float(f[-1]), round(float(p[1:].mean()) * 50.0, 1)  # white noise of variance 1 at 100 Hz
    (257, 50.0, 1.0)
    """
    dt = check_dt_s(dt_s)
    x = check_series(x, "x", min_length=2)
    return _welch(x, 1.0 / dt, min(_nperseg(x.size), x.size), offset=x.mean())[:2]


#: Samples per block of :func:`_variance`: a record up to this length is one block (the result is then
#: ``np.var``'s, bit for bit); longer ones hold one block-sized float64 temporary instead of a full-length one.
VAR_BLOCK = 1 << 20


def _variance(x: np.ndarray, mean: float, block: int | None = None) -> float:
    """Population variance [(unit)^2] of 1-D float64 ``x`` about its ``mean`` [unit], block by block.

    Two-pass like ``np.var(x)`` (``mean`` must be ``x.mean()``): the squared deviations are summed per block
    (NumPy's pairwise sum) and the block sums added in order, so memory is one block, not ``n`` samples.  Equal
    to ``np.var(x)`` bit for bit when ``x.size <= block``, else to within summation rounding (~1e-15 relative).
    """
    block = VAR_BLOCK if block is None else int(block)
    total = 0.0
    for a in range(0, x.size, block):
        d = x[a: a + block] - mean
        np.multiply(d, d, out=d)
        total += float(d.sum())
    return total / x.size


def _window(nperseg: int) -> np.ndarray:
    """The periodic Hann window ``h_t = sin^2(pi t / N)``, ``t = 0 .. N-1`` (``scipy.signal.get_window("hann",
    N)``, the window of spectral analysis; tested against it).

    >>> _window(4).round(12).tolist()
    [0.0, 0.5, 1.0, 0.5]
    """
    t = np.arange(int(nperseg)) * (math.pi / int(nperseg))
    return np.sin(t) ** 2


def welch_edf(nperseg: int, n_segments: int) -> float:
    """Equivalent degrees of freedom of a Welch estimate (Hann, 50 % overlap) at a frequency away from 0 and Nyquist.

    Percival & Walden (1993) eq. (292b): ``nu = 2 K / (1 + 2 sum_{j=1}^{K-1} (1 - j/K) |rho_j|^2)`` with
    ``rho_j = sum_t h_t h_{t+j s} / sum_t h_t^2`` (``s`` the segment step); for Hann at 50 % overlap only
    ``rho_1 = 1/6`` is non-zero, giving ``36 K^2 / (19 K - 1)`` (their eq. 292c).

    >>> round(welch_edf(1024, 31), 2), round(36 * 31**2 / (19 * 31 - 1), 2)
    (58.84, 58.84)
    """
    h = _window(nperseg)
    step = nperseg // 2
    den = float(np.sum(h * h))
    corr = 0.0
    k = int(n_segments)
    for j in range(1, k):
        lag = j * step
        if lag >= nperseg:
            break
        rho = float(np.sum(h[:-lag] * h[lag:])) / den
        corr += (1.0 - j / k) * rho * rho
    return 2.0 * k / (1.0 + 2.0 * corr)


def _local_medians(p: np.ndarray):
    """Left and right medians [PSD unit] and the odd half-window ``w`` of every bin (0: not searched).

    The left window is the ``w`` bins ending ``_GUARD + 1`` bins below ``k``, the right one the ``w`` bins starting
    ``_GUARD + 1`` above; both stay within bins 1 .. nb-2 (DC and Nyquist left out), ``_W_MIN <= w <= _W_MAX``.
    """
    from numpy.lib.stride_tricks import sliding_window_view

    nb = p.size
    k = np.arange(nb)
    w = np.minimum(_W_MAX, np.minimum(k - _GUARD - 1, nb - 2 - _GUARD - k))
    w = np.where(w % 2 == 0, w - 1, w)
    w = np.where(w >= _W_MIN, w, 0)
    left = np.full(nb, np.nan)
    right = np.full(nb, np.nan)
    if nb > _W_MAX:
        med = np.median(sliding_window_view(p, _W_MAX), axis=1)  # med[j] = median(p[j : j + W])
        full = np.nonzero(w == _W_MAX)[0]
        left[full] = med[full - _GUARD - _W_MAX]
        right[full] = med[full + _GUARD + 1]
    for kk in np.nonzero((w > 0) & (w < _W_MAX))[0]:
        ww = int(w[kk])
        left[kk] = np.median(p[kk - _GUARD - ww: kk - _GUARD])
        right[kk] = np.median(p[kk + _GUARD + 1: kk + _GUARD + 1 + ww])
    return left, right, w


def _fine_bin_r(nperseg: int) -> np.ndarray:
    """``|rho_d|^2``, d = 0..4: correlation of Welch PSD values ``d`` bins apart (white noise, Hann window ``h``).

    ``rho_d = sum_t h_t^2 exp(-2 pi i d t / N) / sum_t h_t^2`` (Percival & Walden 1993, Sec. 6.17); for Hann
    ``|rho_1|^2 = 4/9``, ``|rho_2|^2 = 1/36`` and 0 beyond.
    """
    h2 = _window(nperseg) ** 2
    t = np.arange(nperseg)
    s = float(h2.sum())
    return np.array([abs(np.sum(h2 * np.exp(-2j * np.pi * d * t / nperseg))) / s for d in range(5)]) ** 2


def _coarse_stats(nu: float, r: np.ndarray, L: int):
    """EDF of the mean of ``L`` adjacent Welch bins, and ``1 + 2 sum_k corr_k`` of neighbouring coarse bins."""
    rr = np.zeros(3 * L + 8)
    rr[: r.size] = r

    def pair_sum(k):  # sum over a in coarse bin 0, b in coarse bin k of r_|b - a|
        d = np.arange(k * L - (L - 1), k * L + L)
        return float(np.sum((L - np.abs(d - k * L)) * rr[np.abs(d)]))

    var = pair_sum(0)
    nu_l = nu * L * L / var
    corr = 1.0 + 2.0 * sum(pair_sum(k) / var for k in (1, 2))
    return nu_l, corr


def _search_level(p: np.ndarray, L: int, nu: float, r: np.ndarray, alpha: float, df: float):
    """Line search on the Welch PSD averaged over ``L`` adjacent bins, family-wise level ``alpha``.

    Returns (clusters, number of bins searched, (lowest, highest) searched frequency [Hz]) or None.  A cluster is a
    dict with fine-bin ``lo``/``hi`` (its extent, main lobe included), ``peak`` (fine bin of the maximum), ``p``
    (Sidak-corrected), ``power`` [(deg/h)^2], ``floor`` [(deg/h)^2/Hz] and ``L``.
    """
    if L == 1:
        pl = p
    else:
        nbl = (p.size - 1) // L
        pl = p[: nbl * L].reshape(nbl, L).mean(axis=1)
    nu_l, corr = (nu, 1.0 + 2.0 * float(np.sum(r[1:]))) if L == 1 else _coarse_stats(nu, r, L)
    nu_l *= _EDF_SAFETY
    left, right, w = _local_medians(pl)
    ok = (w > 0) & (np.fmax(left, right) > 0)
    m = int(ok.sum())
    if m == 0:
        return None
    ratio = np.zeros(pl.size)
    ratio[ok] = pl[ok] / np.maximum(left[ok], right[ok])
    p_target = -math.expm1(math.log1p(-alpha) / m)  # per-bin level of the Sidak correction
    p_fw = np.ones(pl.size)
    for ww in np.unique(w[ok]):
        null, r_crit = _null_and_critical(float(nu_l), int(ww), float(corr), float(p_target))
        cand = np.nonzero(ok & (w == ww) & (ratio >= r_crit))[0]
        if cand.size:
            pb = null.sf(ratio[cand])
            p_fw[cand] = np.where(pb < 1e-12, m * pb, -np.expm1(m * np.log1p(-np.minimum(pb, 1.0 - 1e-16))))
    q = chi2_median(nu_l) / nu_l
    idx = np.nonzero(ok)[0]
    band = (float((idx[0] * L + 0.5 * (L - 1)) * df), float((idx[-1] * L + 0.5 * (L - 1)) * df))  # bin centres
    sig = np.nonzero(ok & (p_fw <= alpha))[0]
    out = []
    if sig.size:
        g = _GUARD if L == 1 else 1
        for run in np.split(sig, np.nonzero(np.diff(sig) > _MERGE_GAP + 1)[0] + 1):
            a, b = int(run[0]), int(run[-1])
            k = a + int(np.argmax(pl[a: b + 1]))
            floor = float(math.sqrt(left[k] * right[k]) / q)  # median-unbiased on a locally straight log-spectrum
            lo, hi = max(1, a - g), min(pl.size - 2, b + g)
            power = float(np.sum(pl[lo: hi + 1] - floor) * df * L)
            if not power > 0:
                power = float((pl[k] - floor) * df * L)
            lo_f, hi_f = lo * L, (hi + 1) * L - 1
            peak = lo_f + int(np.argmax(p[lo_f: hi_f + 1]))
            out.append({"lo": lo_f, "hi": min(hi_f, p.size - 2), "peak": peak, "p": float(np.min(p_fw[a: b + 1])),
                        "power": power, "floor": floor, "L": L})
    return out, m, band


def _merge_levels(found: list) -> list:
    """One line per feature from the clusters of every resolution (finest first).

    A coarser cluster overlapping no accepted line is added; overlapping exactly one, it replaces it when it holds
    more than ``_BROAD_POWER_RATIO`` times its power (the finer resolution saw only the top of a broad line);
    overlapping two or more, it is dropped (the finer resolution separates them).
    """
    acc = []
    for c in sorted(found, key=lambda c: c["L"]):
        hit = [i for i, a in enumerate(acc) if c["lo"] <= a["hi"] and a["lo"] <= c["hi"]]
        if not hit:
            acc.append(c)
        elif len(hit) == 1 and c["power"] > _BROAD_POWER_RATIO * acc[hit[0]]["power"]:
            acc[hit[0]] = c
    return acc


def _refine_freq(p: np.ndarray, k: int, df: float) -> float:
    """Gaussian (log-parabolic) interpolation of the peak at bin ``k`` [Hz]."""
    if k <= 0 or k >= p.size - 1:
        return k * df
    a, b, c = (math.log(max(float(v), 1e-300)) for v in p[k - 1: k + 2])
    den = a - 2.0 * b + c
    delta = 0.5 * (a - c) / den if den < 0 else 0.0
    return (k + max(-0.5, min(0.5, delta))) * df


# ----------------------------------------------------------------------------------------------------------------
# Harmonic grouping and roll-off


def _group_harmonics(raw: list, df: float) -> list:
    """Group raw lines (dicts with 'f', 'power') into components: list of (f0, [line dicts with 'h'])."""
    order = sorted(range(len(raw)), key=lambda i: raw[i]["f"])
    free = set(order)
    comps = []
    for i0 in order:
        if i0 not in free:
            continue
        free.discard(i0)
        members = [(1, i0)]
        f0 = raw[i0]["f"]
        h, missing = 2, 0
        while missing <= 2 and free:
            target = h * f0
            best = min(free, key=lambda i: abs(raw[i]["f"] - target))
            if abs(raw[best]["f"] - target) <= 1.5 * df and raw[best]["f"] > raw[i0]["f"]:
                members.append((h, best))
                free.discard(best)
                hs = np.array([m[0] for m in members], dtype=np.float64)
                fs = np.array([raw[m[1]]["f"] for m in members])
                f0 = float(np.sum(hs * fs) / np.sum(hs * hs))
                missing = 0
            else:
                missing += 1
            h += 1
        if len(members) >= 3:  # an established series: its isolated higher harmonics too (tighter tolerance)
            for i in sorted(free, key=lambda i: raw[i]["f"]):
                hh = int(round(raw[i]["f"] / f0))
                if hh > max(m[0] for m in members) and abs(raw[i]["f"] - hh * f0) <= df:
                    members.append((hh, i))
                    free.discard(i)
        comps.append((f0, members))
    return comps


def _rolloff(f: np.ndarray, p_free: np.ndarray, df: float):
    """(corner_hz, fall_db) when the line-free spectrum ``p_free`` shows a low-pass roll-off, else None.

    Levels are band means in 1/6-octave bands from ``max(4 df, Nyquist / 64)`` to two bins below Nyquist.  A white
    plateau is two octaves of bands whose fitted slope is within ``_PLATEAU_DB_PER_OCT``; the highest plateau counts
    when every band above it stays within ``_MONOTONE_TOL_DB`` of the running minimum (a monotone fall) and the top
    band is at least ``_ROLLOFF_DB`` below both the plateau's mean level and its fitted trend carried to Nyquist
    (so a 1/f spectrum, which falls everywhere, shows no roll-off).  The corner is where the band levels first fall
    3 dB below that level (interpolated in log frequency).
    """
    nyq = float(f[-1])
    f_a = max(4.0 * df, nyq / 64.0)
    top = nyq - 2.0 * df
    if top <= 8.0 * f_a:
        return None
    n_band = int(math.floor(6.0 * math.log2(top / f_a)))
    edges = f_a * 2.0 ** (np.arange(n_band + 1) / 6.0)
    edges[-1] = top
    lev, cen = [], []
    for lo, hi in zip(edges[:-1], edges[1:]):
        sel = (f >= lo) & (f < hi)
        if not sel.any():
            continue
        v = float(np.mean(p_free[sel]))
        if not v > 0:
            return None
        lev.append(10.0 * math.log10(v))
        cen.append(math.sqrt(lo * hi))
    lev, cen = np.asarray(lev), np.asarray(cen)
    if lev.size < 12:
        return None
    oct_ = np.log2(cen)
    l_top = lev[-1]
    for i in range(lev.size - 2, 4, -1):  # the highest plateau first
        sel = (oct_ >= oct_[i] - _PLATEAU_OCTAVES) & (oct_ <= oct_[i])
        if oct_[i] - oct_[0] < _PLATEAU_OCTAVES - 1e-9:
            break
        slope, icpt = np.polyfit(oct_[sel], lev[sel], 1)
        if abs(slope) > _PLATEAU_DB_PER_OCT:
            continue
        white = float(np.mean(lev[sel]))
        trend_top = float(icpt + slope * oct_[-1])  # the plateau's own trend carried to Nyquist
        if min(white, trend_top) - l_top < _ROLLOFF_DB:
            return None  # the highest plateau reaches Nyquist, or the fall is only its own trend: no roll-off
        after = lev[i + 1:]
        run_min = np.minimum.accumulate(np.concatenate([[white], after]))[:-1]
        if np.any(after > run_min + _MONOTONE_TOL_DB):
            continue
        below = np.nonzero(after <= white - 3.0)[0]
        j = i + 1 + int(below[0])
        y0, y1 = lev[j - 1] - (white - 3.0), lev[j] - (white - 3.0)
        x = oct_[j - 1] + (oct_[j] - oct_[j - 1]) * (y0 / (y0 - y1) if y0 > 0 and y0 != y1 else 0.0)
        return float(2.0**x), float(white - l_top)
    return None


# ----------------------------------------------------------------------------------------------------------------
# Public functions


def analyse_spectrum(y, dt_s, *, false_alarm=0.01, max_lines=16) -> SpectrumSummary:
    """Find the spectral lines, periodic components and output roll-off of a rate record.

    Parameters
    ----------
    y : array_like, shape (n_samples,)
        The series in its channel's internal unit (deg/h, m/s^2), float32 or float64, finite.
    dt_s : float
        Sample interval [s].
    false_alarm : float, keyword-only
        Family-wise false-alarm rate of the line search, in (0, 0.5]: the probability that a record without lines
        gets any line (default 0.01).
    max_lines : int, keyword-only
        Most lines reported (the strongest), >= 1.

    Returns
    -------
    SpectrumSummary
        Empty, with the reason in ``note``, when the record has fewer than :data:`MIN_SAMPLES` samples or is
        constant.

    Raises
    ------
    DataFormatError
        ``y`` not a finite 1-D numeric series.
    ConfigError
        Bad ``dt_s``, ``false_alarm`` or ``max_lines``.

    Notes
    -----
    See the module docstring for the test, its distribution and references.  Frequencies are searched from
    about ``9 / (nperseg dt)`` (the DC region is left out) to about ``9`` bins below Nyquist.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> t = np.arange(2**15) * 0.01
    >>> y = 10.0 * rng.standard_normal(t.size) + 5.0 * np.sin(2 * np.pi * 20.0 * t)
    >>> s = analyse_spectrum(y, 0.01)
    >>> [round(ln.freq_hz, 1) for ln in s.lines], round(s.lines[0].amplitude_dph, 0)
    ([20.0], 5.0)
    >>> s.rolloff_hz is None
    True
    """
    dt = check_dt_s(dt_s)
    try:
        fa = float(false_alarm)
    except (TypeError, ValueError):
        raise ConfigError(f"false_alarm must be a probability in (0, 0.5], got {false_alarm!r}") from None
    if not (0.0 < fa <= 0.5):
        raise ConfigError(f"false_alarm must be a probability in (0, 0.5], got {false_alarm!r}")
    n_max = check_count(max_lines, "max_lines", 1)
    x = check_series(y, "y", min_length=0)
    n = int(x.size)
    fs = 1.0 / dt
    if n < MIN_SAMPLES:
        return SpectrumSummary(dt, n, fa, float("nan"), note=f"no spectrum: the record has {n} samples; the line "
                                                             f"search needs at least {MIN_SAMPLES}")
    mean = x.mean()  # a reduction: no full-length temporary
    var = _variance(x, mean)
    if not np.ptp(x) > 0:
        return SpectrumSummary(dt, n, fa, float("nan"), note="no spectrum: the record is constant")
    nperseg = _nperseg(n)
    f, p, n_seg = _welch(x, fs, nperseg, offset=mean)
    df = fs / nperseg
    nu = welch_edf(nperseg, n_seg)
    r_fine = _fine_bin_r(nperseg)
    levels = [L for L in _LEVELS if L == 1 or (p.size - 1) // L >= _MIN_COARSE_BINS]
    found, m_total, band = [], 0, None
    for L in levels:
        res = _search_level(p, L, nu, r_fine, fa / len(levels), df)
        if res is None:
            continue
        clusters, m_l, band_l = res
        m_total += m_l
        if L == 1:
            band = band_l
        for c in clusters:
            c["p"] = min(1.0, c["p"] * len(levels))  # Bonferroni over the resolutions
            found.append(c)
    if m_total == 0 or band is None:
        return SpectrumSummary(dt, n, fa, df, variance_dph2=var, note="no spectrum: too few frequency bins")
    raw = _merge_levels(found)
    p_free = p.copy()  # the spectrum with every significant line replaced by its floor (for the roll-off)
    for c in raw:
        p_free[c["lo"]: c["hi"] + 1] = c["floor"]
    enbw = nperseg * float(np.sum(_window(nperseg) ** 2)) / float(np.sum(_window(nperseg))) ** 2
    for c in raw:
        if c["L"] == 1:
            c["f"] = _refine_freq(p, c["peak"], df)
        else:  # a broad line: the centroid of its excess power
            ex = np.maximum(p[c["lo"]: c["hi"] + 1] - c["floor"], 0.0)
            c["f"] = float(np.sum(ex * f[c["lo"]: c["hi"] + 1]) / np.sum(ex)) if ex.sum() > 0 else float(f[c["peak"]])
        ex = np.maximum(p[c["lo"]: c["hi"] + 1] - c["floor"], 0.0)
        fr = f[c["lo"]: c["hi"] + 1]
        c["width"] = 2.0 * math.sqrt(float(np.sum(ex * (fr - c["f"]) ** 2) / np.sum(ex))) if ex.sum() > 0 else df
        c["snr"] = 10.0 * math.log10(c["power"] / (c["floor"] * enbw * df)) if c["floor"] > 0 else float("inf")
    raw.sort(key=lambda r: -r["power"])
    raw = raw[:n_max]

    comps = []
    for f0, members in _group_harmonics(raw, df):
        lines = []
        for h, i in members:
            r = raw[i]
            lines.append(SpectralLine(freq_hz=r["f"], amplitude_dph=math.sqrt(2.0 * r["power"]),
                                      power_dph2=r["power"], snr_db=r["snr"], p_value=min(1.0, r["p"]),
                                      harmonic_of=None if h == 1 else f0, width_hz=r["width"],
                                      broad=r["width"] > _BROAD_WIDTH_BINS * df))
            r["line"] = lines[-1]
        comps.append(PeriodicComponent(fundamental_hz=f0, period_s=1.0 / f0, lines=tuple(lines),
                                       power_dph2=float(sum(ln.power_dph2 for ln in lines))))
    comps.sort(key=lambda c: -c.power_dph2)
    lines = tuple(sorted((r["line"] for r in raw), key=lambda ln: -ln.power_dph2))

    ro = _rolloff(f, p_free, df)
    return SpectrumSummary(dt, n, fa, df, lines=lines, components=tuple(comps),
                           rolloff_hz=None if ro is None else ro[0], rolloff_db=None if ro is None else ro[1],
                           variance_dph2=var, searched_bins=m_total, band_hz=band)


def sinusoid_avar(tau_s, amplitude_dph, freq_hz, *, dt_s=None) -> np.ndarray:
    """Allan variance [(deg/h)^2] of a sinusoidal rate ``Omega0 sin(2 pi f0 t)``.

    ``sigma^2(tau) = Omega0^2 sin^4(pi f0 tau) / (pi f0 tau)^2`` (IEEE Std 952-1997 Annex C.5; continuous
    averaging).  With ``dt_s`` the cluster average of the sampled sinusoid is used instead (exact for a record of
    samples, ``tau`` a multiple of ``dt_s``): ``Omega0^2 sin^2(pi f0 tau) D^2`` with the Dirichlet factor
    ``D = sin(pi f0 tau) / (m sin(pi f0 dt))``, ``m = tau / dt``, which tends to the continuous law as ``f0 dt -> 0``.
    Both vanish at ``tau = k / f0``.

    Parameters
    ----------
    tau_s : array_like
        Cluster times [s], > 0.
    amplitude_dph : float
        Peak amplitude ``Omega0`` [deg/h].
    freq_hz : float
        Frequency ``f0`` [Hz], > 0.
    dt_s : float or None, keyword-only
        Sample interval [s] for the sampled (discrete-average) form; None for the continuous law.

    Returns
    -------
    numpy.ndarray
        Same shape as ``tau_s``, (deg/h)^2.

    Examples
    --------
    >>> sinusoid_avar([0.05, 0.1, 0.125], 1.0, 10.0).round(4).tolist()   # zero at 1/f0, envelope ~ tau^-2
    [0.4053, 0.0, 0.0162]
    """
    t = np.asarray(tau_s, dtype=np.float64)
    a = float(amplitude_dph)
    f0 = float(freq_hz)
    if not (np.all(np.isfinite(t)) and np.all(t > 0)):
        raise ConfigError("tau_s must be finite and > 0")
    if not (math.isfinite(f0) and f0 > 0 and math.isfinite(a)):
        raise ConfigError(f"freq_hz must be finite and > 0 and amplitude_dph finite, got {freq_hz!r}, "
                          f"{amplitude_dph!r}")
    x = math.pi * f0 * t
    s = np.sin(x)
    if dt_s is None:
        return a * a * s**4 / x**2
    dt = check_dt_s(dt_s)
    m = t / dt
    d = s / (m * math.sin(math.pi * f0 * dt))
    return a * a * s * s * d * d
