"""Periodic content and output filters of a rate record, read from its spectrum, with a stated false-alarm rate.

A sinusoid ``Omega0 sin(2 pi f0 t)`` in the rate has the Allan variance ``Omega0^2 sin^4(pi f0 tau) / (pi f0 tau)^2``
(IEEE Std 952-1997 Annex C.5), whose envelope falls as ``tau^-2`` exactly like quantization noise: a tone, a
vibration or a phase-ramp (sawtooth) error in the short-tau region is easily read as Q with a tight interval.  The
spectrum tells them apart: this module finds the lines, groups harmonics into periodic components and says whether
the spectrum shows an output low-pass / anti-alias roll-off.  Rates are in deg/h, frequencies in Hz.

Method (:func:`analyse_spectrum`)

1. Welch PSD, one-sided density [(deg/h)^2/Hz], periodic Hann window, 50 % overlap, segment length ``2^k`` giving
   at least 32 segments (64 to 65536 samples), computed chunk by chunk (memory bounded by the chunk, not ``n``).
2. Each bin ``P_k`` is tested against a local floor: the geometric mean of the medians of the ``w`` bins left and
   the ``w`` bins right of it (``w <= 16``), leaving out the bin and its two neighbours on each side (the Hann main
   lobe), corrected by the median of ``chi^2_nu / nu``.  The two one-sided medians make the floor unbiased on a
   locally straight log-spectrum and robust to other lines.  Under no line, ``P_k / S ~ chi^2_nu / nu`` with the
   Welch EDF ``nu = 2K / (1 + 2 sum_j (1 - j/K) rho_j^2)`` (Percival & Walden 1993, eq. 292b; ``rho_j`` the window's
   overlap correlation, 1/6 for Hann at 50 %, so ``nu = 36 K^2 / (19 K - 1)``), and the floor has an equivalent
   ``nu_f = 16 w_eff g(q)^2 q^2`` (asymptotic variance of a sample median, ``w_eff`` = ``w`` over the Hann
   neighbour-bin correlation ``1 + 2 sum_d |W_d|^2``), so ``P_k / floor ~ F(nu, nu_f)``.  The per-bin p-values are
   Sidak-corrected over the searched bins: the family-wise false-alarm rate under no line is at most
   ``false_alarm`` on any smooth noise spectrum (white, random walk, flicker, quantization, low-passed white).
3. Contiguous significant bins (gaps of up to 2 bins) are one line: frequency by Gaussian (log-parabolic)
   interpolation of the peak, power = sum over the cluster and its main lobe of ``(P - floor) df`` (the density
   scaling already accounts for the window's ENBW), amplitude ``sqrt(2 power)``.
4. Lines whose frequencies are whole multiples of a lower line (within 1.5 bins, harmonics taken in order with at
   most two missing) form a :class:`PeriodicComponent`; its fundamental is the least-squares ``f0`` of the lines.
5. Roll-off: on the line-free spectrum (running median) in 1/6-octave bands, a flat white-noise plateau (slope
   within 1.5 dB/octave over an octave) followed by a monotone fall to at least 6 dB below it at Nyquist; the corner
   is where the level first falls 3 dB below the plateau.

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

__all__ = ["SpectralLine", "PeriodicComponent", "SpectrumSummary", "analyse_spectrum", "sinusoid_avar",
           "MIN_SAMPLES"]

#: Fewest samples analysed; a shorter record gets an empty summary with the reason.
MIN_SAMPLES = 256
_MIN_SEGMENTS = 32  # target number of Welch segments (EDF ~ 60)
_NPERSEG_MIN, _NPERSEG_MAX = 64, 65536
_GUARD = 2  # bins either side of the tested bin left out of its floor (the Hann main lobe)
_W_MAX, _W_MIN = 15, 7  # floor half-window [bins], odd
_MERGE_GAP = 2  # significant bins at most this far apart are one line
_ROLLOFF_DB = 6.0  # a roll-off is reported when Nyquist is at least this far below the white plateau
_PLATEAU_DB_PER_OCT = 1.5  # |slope| of a white plateau
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
        Variance the line contributes [(deg/h)^2], ``amplitude_dph^2 / 2``.
    snr_db : float
        Line power against the local noise floor in one bin's noise bandwidth (floor x ENBW) [dB].
    p_value : float
        False-alarm probability of the line under the no-line hypothesis, after the Sidak correction over the
        searched bins.
    harmonic_of : float or None
        Fundamental frequency [Hz] when this line is a harmonic of another line found; None otherwise.
    """

    freq_hz: float
    amplitude_dph: float
    power_dph2: float
    snr_db: float
    p_value: float
    harmonic_of: float | None = None

    def to_dict(self) -> dict:
        return {k: _finite_or_none(v) for k, v in self.__dict__.items()}


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
                out.append(f"spectral line at {_freq_text(ln.freq_hz, df)}, amplitude {ln.amplitude_dph:#.2g} deg/h "
                           f"({_p_text(ln.p_value)}, {rate})")
            else:
                share = 100.0 * c.power_dph2 / self.variance_dph2 if self.variance_dph2 > 0 else float("nan")
                n_h = c.n_harmonics
                out.append(f"periodic error with period {c.period_s:.3g} s ({_freq_text(c.fundamental_hz, df)} and "
                           f"{n_h} harmonic{'s' if n_h != 1 else ''}), {share:#.2g} % of the variance")
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


def _welch(x: np.ndarray, fs_hz: float, nperseg: int):
    """One-sided Welch PSD [(unit)^2/Hz] (Hann, 50 % overlap, mean removed per segment), chunk by chunk.

    Returns (f_hz, psd, n_segments).  Identical to one ``scipy.signal.welch`` call on the whole record; memory is
    bounded by the chunk (about 2^21 samples), not by ``n``.
    """
    from scipy.signal import welch

    step = nperseg // 2
    n_seg = (x.size - nperseg) // step + 1
    per_chunk = max(1, (1 << 21) // nperseg)
    acc = None
    f = None
    done = 0
    while done < n_seg:
        j = min(per_chunk, n_seg - done)
        a = done * step
        b = a + (j - 1) * step + nperseg
        f, p = welch(x[a:b], fs=fs_hz, window="hann", nperseg=nperseg, noverlap=step, detrend="constant",
                     scaling="density")
        acc = p * j if acc is None else acc + p * j
        done += j
    return f, acc / n_seg, n_seg


def _window(nperseg: int) -> np.ndarray:
    from scipy.signal import get_window

    return get_window("hann", nperseg)


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


def _bin_correlation(nperseg: int, max_lag: int = 4) -> float:
    """``1 + 2 sum_d |rho_d|^2``: how many neighbouring bins one independent bin is worth (white noise, window h).

    ``rho_d = sum_t h_t^2 exp(-2 pi i d t / N) / sum_t h_t^2`` is the correlation of two DFT values ``d`` bins apart;
    for Hann ``|rho_1|^2 = 4/9``, ``|rho_2|^2 = 1/36``.
    """
    h2 = _window(nperseg) ** 2
    t = np.arange(nperseg)
    s = float(h2.sum())
    out = 1.0
    for d in range(1, max_lag + 1):
        r = abs(np.sum(h2 * np.exp(-2j * np.pi * d * t / nperseg))) / s
        out += 2.0 * r * r
    return out


class _MedianNull:
    """Null distribution of ``r = P_k / max(med_left, med_right)`` for one half-window ``w`` (odd).

    Under no line and a locally smooth spectrum ``S``: ``P_k / S ~ X = chi^2_nu / nu`` (Welch EDF ``nu``), and each
    one-sided median is the median of ``w`` variates distributed as ``X`` that are correlated as neighbouring Hann
    bins are, modelled as the median of ``n_eff = w / (1 + 2 sum_d |rho_d|^2)`` independent ones: the order
    statistic ``CDF I_{F_X(m)}(a, a)``, ``a = (n_eff + 1) / 2`` (regularized incomplete beta).  The larger of two
    independent medians has CDF ``F_A(m)^2``, so ``p(r) = int sf_X(r m) dF_A(m)^2``, integrated on a geometric grid
    that covers ``F_A`` from 1e-14 to 1 - 1e-14 (the lower tail of the floor matters at small p).
    """

    def __init__(self, nu: float, w: int, bin_corr: float, n_grid: int = 600):
        from scipy.special import betainc, betaincinv, chdtr, chdtri

        self.nu = float(nu)
        a = 0.5 * (max(float(w) / bin_corr, 1.0) + 1.0)
        lo, hi = chdtri(nu, 1.0 - betaincinv(a, a, np.array([1e-14, 1.0 - 1e-14]))) / nu
        m = np.geomspace(lo, hi, n_grid)
        cdf = betainc(a, a, chdtr(nu, m * nu)) ** 2
        self.m = 0.5 * (m[1:] + m[:-1])
        self.wt = np.diff(cdf)
        self.wt /= self.wt.sum()

    def sf(self, r) -> np.ndarray:
        """P(statistic >= r) under the null, for an array ``r``."""
        from scipy.special import chdtrc

        r = np.atleast_1d(np.asarray(r, dtype=np.float64))
        out = np.empty(r.shape)
        for i0 in range(0, r.size, 256):
            rr = r[i0:i0 + 256]
            out[i0:i0 + 256] = chdtrc(self.nu, rr[:, None] * self.m[None, :] * self.nu) @ self.wt
        return out

    def critical(self, p_target: float) -> float:
        """The ratio ``r`` with ``sf(r) = p_target``."""
        from scipy.optimize import brentq

        lt = math.log(p_target)
        return math.exp(brentq(lambda lr: math.log(max(float(self.sf(math.exp(lr))[0]), 1e-300)) - lt, 0.0,
                               math.log(1e4), xtol=1e-5))


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
        comps.append((f0, members))
    return comps


def _rolloff(f: np.ndarray, p: np.ndarray, df: float):
    """(corner_hz, fall_db, plateau_top_hz) when the line-free spectrum shows a low-pass roll-off, else None."""
    from scipy.ndimage import median_filter

    nb = p.size
    nyq = f[-1]
    smooth = median_filter(p, size=2 * _W_MAX + 1, mode="nearest")
    f_a = max(2 * _W_MAX * df, nyq / 32.0)
    top = nyq - 2.0 * df
    if top <= 4.0 * f_a:
        return None
    n_band = int(math.floor(6.0 * math.log2(top / f_a)))
    edges = f_a * 2.0 ** (np.arange(n_band + 1) / 6.0)
    edges[-1] = top
    lev, cen = [], []
    for lo, hi in zip(edges[:-1], edges[1:]):
        sel = (f >= lo) & (f < hi)
        if not sel.any():
            continue
        v = float(np.mean(smooth[sel]))
        if v <= 0:
            return None
        lev.append(10.0 * math.log10(v))
        cen.append(math.sqrt(lo * hi))
    lev, cen = np.asarray(lev), np.asarray(cen)
    if lev.size < 10:
        return None
    oct_ = np.log2(cen)
    l_top = lev[-1]
    best = None
    for i in range(lev.size - 2, 5, -1):  # highest plateau first
        sel = (oct_ >= oct_[i] - 1.0) & (oct_ <= oct_[i])
        if sel.sum() < 5:
            break
        slope, icpt = np.polyfit(oct_[sel], lev[sel], 1)
        if abs(slope) > _PLATEAU_DB_PER_OCT:
            continue
        white = float(np.mean(lev[sel]))
        after = lev[i + 1:]
        if white - l_top < _ROLLOFF_DB:
            continue
        if np.any(after > np.minimum.accumulate(np.concatenate([[white], after]))[:-1] + _MONOTONE_TOL_DB):
            continue
        best = (i, white)
        break
    if best is None:
        return None
    i, white = best
    # corner: first frequency above the plateau where the smoothed PSD falls 3 dB below it
    k0 = int(np.searchsorted(f, cen[i]))
    sl = 10.0 * np.log10(np.maximum(smooth, 1e-300))
    below = np.nonzero(sl[k0:nb - 1] <= white - 3.0)[0]
    if below.size == 0:
        return None
    k = k0 + int(below[0])
    if k > k0:
        y0, y1 = sl[k - 1] - (white - 3.0), sl[k] - (white - 3.0)
        corner = f[k - 1] + (f[k] - f[k - 1]) * (y0 / (y0 - y1) if y0 != y1 else 0.0)
    else:
        corner = f[k]
    return float(corner), float(white - l_top), float(cen[i])


# ----------------------------------------------------------------------------------------------------------------
# Public functions


def analyse_spectrum(rate_dph, dt_s, *, false_alarm=0.01, max_lines=16) -> SpectrumSummary:
    """Find the spectral lines, periodic components and output roll-off of a rate record.

    Parameters
    ----------
    rate_dph : array_like, shape (n_samples,)
        Rate [deg/h] (float32 or float64, finite).
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
        ``rate_dph`` not a finite 1-D numeric series.
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
    x = check_series(rate_dph, "rate_dph", min_length=0)
    n = int(x.size)
    fs = 1.0 / dt
    if n < MIN_SAMPLES:
        return SpectrumSummary(dt, n, fa, float("nan"), note=f"no spectrum: the record has {n} samples; the line "
                                                             f"search needs at least {MIN_SAMPLES}")
    var = float(np.var(x))
    if not var > 0:
        return SpectrumSummary(dt, n, fa, float("nan"), note="no spectrum: the record is constant")
    nperseg = _nperseg(n)
    f, p, n_seg = _welch(x - x.mean(), fs, nperseg)
    df = fs / nperseg
    nb = p.size
    nu = welch_edf(nperseg, n_seg)
    left, right, w = _local_medians(p)
    searched = w > 0
    m = int(searched.sum())
    if m == 0:
        return SpectrumSummary(dt, n, fa, df, variance_dph2=var, note="no spectrum: too few frequency bins")
    from scipy.stats import chi2

    q = chi2.median(nu) / nu
    ref = np.where(searched, np.maximum(left, right), np.nan)
    ratio = np.zeros(nb)
    ok = searched & (ref > 0)
    ratio[ok] = p[ok] / ref[ok]
    p_target = -math.expm1(math.log1p(-fa) / m)  # per-bin level of the Sidak correction
    bin_corr = _bin_correlation(nperseg)
    p_fw = np.ones(nb)
    for ww in np.unique(w[ok]):
        null = _MedianNull(nu, int(ww), bin_corr)
        cand = np.nonzero(ok & (w == ww) & (ratio >= null.critical(p_target)))[0]
        if cand.size:
            pb = null.sf(ratio[cand])
            p_fw[cand] = np.where(pb < 1e-12, m * pb, -np.expm1(m * np.log1p(-np.minimum(pb, 1.0 - 1e-16))))
    # the floor under a line: median-unbiased on a locally straight log-spectrum
    floor_c = np.zeros(nb)
    floor_c[ok] = np.sqrt(left[ok] * right[ok]) / q
    sig = np.nonzero(ok & (p_fw <= fa))[0]
    band = (float(f[searched][0]), float(f[searched][-1]))
    enbw = nperseg * float(np.sum(_window(nperseg) ** 2)) / float(np.sum(_window(nperseg))) ** 2

    raw = []
    if sig.size:
        splits = np.nonzero(np.diff(sig) > _MERGE_GAP + 1)[0] + 1
        for run in np.split(sig, splits):
            a, b = int(run[0]), int(run[-1])
            k = a + int(np.argmax(p[a: b + 1]))
            fl_k = floor_c[k]
            lo, hi = max(1, a - _GUARD), min(nb - 2, b + _GUARD)
            power = float(np.sum(p[lo: hi + 1] - fl_k) * df)
            if not power > 0:
                power = float((p[k] - fl_k) * df * enbw)
            raw.append({"f": _refine_freq(p, k, df), "power": power,
                        "snr": 10.0 * math.log10(power / (fl_k * enbw * df)) if fl_k > 0 else float("inf"),
                        "p": float(np.min(p_fw[a: b + 1]))})
    raw.sort(key=lambda r: -r["power"])
    raw = raw[:n_max]

    comps = []
    for f0, members in _group_harmonics(raw, df):
        lines = []
        for h, i in members:
            r = raw[i]
            lines.append(SpectralLine(freq_hz=r["f"], amplitude_dph=math.sqrt(2.0 * r["power"]),
                                      power_dph2=r["power"], snr_db=r["snr"], p_value=min(1.0, r["p"]),
                                      harmonic_of=None if h == 1 else f0))
            r["line"] = lines[-1]
        comps.append(PeriodicComponent(fundamental_hz=f0, period_s=1.0 / f0, lines=tuple(lines),
                                       power_dph2=float(sum(ln.power_dph2 for ln in lines))))
    comps.sort(key=lambda c: -c.power_dph2)
    lines = tuple(sorted((r["line"] for r in raw), key=lambda ln: -ln.power_dph2))

    ro = _rolloff(f, p, df)
    return SpectrumSummary(dt, n, fa, df, lines=lines, components=tuple(comps),
                           rolloff_hz=None if ro is None else ro[0], rolloff_db=None if ro is None else ro[1],
                           variance_dph2=var, searched_bins=m, band_hz=band)


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
