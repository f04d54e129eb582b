"""Self-noise of co-located channels of one sensing axis (redundant gyros, a reference sensor) from their coherence.

Under a disturbance that all channels see (platform vibration, ground rotation), the noise of one channel is the
disturbance plus its own noise, and no single-channel analysis can tell them apart.  Channels that sense the same
axis at the same place share the disturbance and differ only by their own (independent) noise, so their cross
spectra separate the two.

Model
-----
Channel i records ``x_i = h_i * s + n_i``: a common signal s (the real rate: disturbance and platform motion)
seen through a response ``h_i`` (a gain; complex for a relative delay), and a self-noise ``n_i`` independent of s
and of the other channels' noise.  With one-sided (cross) spectral densities ``P_ij = E[X_i X_j^*]`` (Welch:
Hann windows, half overlap, each segment's mean removed) and ``N_ii`` the self-noise PSD of channel i:

* **two channels, identical responses** (``h_1 = h_2``; after Holcomb 1989): ``P_12 = S`` (the common signal's
  PSD), so

      N_ii = P_ii - Re P_12,     in expectation  N_ii = P_ii (1 - gamma sqrt(P_jj / P_ii)),

  with ``gamma = |P_12| / sqrt(P_11 P_22)`` the coherence magnitude; for equal self-noises this is Holcomb's
  ``N = P_11 (1 - gamma)``.  The real part is used because ``P_12 = S`` is real in expectation: the magnitude of an
  estimated ``P_12`` is biased upwards by about ``sqrt(N_11 N_22 / K)`` where the noise dominates.  A gain mismatch ``h_2 = (1 + e) h_1`` leaves about ``e S`` of the common signal in
  each estimate: use three channels where the signal dominates;
* **three channels, any responses** (Sleeman, van Wettum & Trampert 2006): the relative responses cancel in

      N_ii = P_ii - P_ji P_ik / P_jk     ({i, j, k} = {1, 2, 3}),

  exact in expectation for any gains ``h_i`` (Sleeman et al. 2006, eq. 10); the real part is taken (the
  imaginary part is estimation scatter).

Uncertainty
-----------
Welch over K half-overlapping Hann segments gives each spectral estimate about ``K_eff ~ 0.95 K`` degrees of
freedom (relative standard deviation ``1/sqrt(K_eff)``, Percival & Walden 1993, sec. 6.17).  In a self-noise
estimate (a difference of such estimates) the common signal's own scatter cancels; what remains is each noise's
scatter and the cross terms, first order ``sd(N_ii) ~ sqrt(N_ii^2 + sum_{a<b} N_aa N_bb / 2 + S_i Nbar) /
sqrt(K_eff)`` (``S_i`` the common signal's PSD in channel i, ``Nbar`` the mean self-noise, the N's a running median over 65
frequencies of the estimates; exact for two channels with equal gains).  The error thus grows as the square
root of the signal-to-self-noise ratio.  :attr:`SelfNoise.rel_sd` gives this value relative to ``N_ii`` per
frequency (measured on the seeded simulations of ``tests/test_selfnoise.py``: within 2.5 of it at 84-98 % of the
frequencies; it is too small where the common signal dominates the quieter of two channels); averaging over a band of B frequencies reduces it by about ``sqrt(B / 2)``.

References
----------
Holcomb, L. G. (1989). A direct method for calculating instrument noise levels in side-by-side seismometer
evaluations. U.S. Geological Survey Open-File Report 89-214.

Sleeman, R., van Wettum, A. & Trampert, J. (2006). Three-channel correlation analysis: a new technique to measure
instrumental noise of digitizers and seismic sensors. Bull. Seismol. Soc. Am. 96(1), 258-271.

Ringler, A. T., Hutt, C. R., Evans, J. R. & Sandoval, L. D. (2011). A comparison of seismic instrument noise
coherence analysis techniques. Bull. Seismol. Soc. Am. 101(2), 558-567.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ._util import check_series
from .errors import ConfigError, InsufficientDataError
from .units import check_dt_s

__all__ = ["SelfNoise", "self_noise", "cross_spectra"]


@dataclass(frozen=True)
class SelfNoise:
    """Self-noise PSD of each of two or three co-located channels.

    Attributes
    ----------
    method : str
        ``"two-channel"`` (identical responses, after Holcomb 1989) or ``"three-channel"`` (Sleeman et al. 2006).
    freq_hz : ndarray, shape (n_freq,)
        Frequencies in Hz (0 Hz left out).
    psd : ndarray, shape (n_channels, n_freq)
        Each channel's total one-sided PSD ``P_ii`` in (rate unit)^2/Hz.
    noise_psd : ndarray, shape (n_channels, n_freq)
        Each channel's self-noise PSD ``N_ii`` in (rate unit)^2/Hz (may be negative where the scatter exceeds it).
    coherence : ndarray, shape (n_pairs, n_freq)
        Magnitude-squared coherence ``|P_ij|^2 / (P_ii P_jj)`` of each pair (1-2; or 1-2, 1-3, 2-3).
    segments : int
        Welch segments averaged (K).
    rel_sd : ndarray, shape (n_channels, n_freq)
        First-order relative standard deviation of ``noise_psd`` (module docstring).
    """

    method: str
    freq_hz: np.ndarray = field(repr=False)
    psd: np.ndarray = field(repr=False)
    noise_psd: np.ndarray = field(repr=False)
    coherence: np.ndarray = field(repr=False)
    segments: int
    rel_sd: np.ndarray = field(repr=False)

    def band_noise(self, f_lo_hz: float, f_hi_hz: float) -> np.ndarray:
        """Mean self-noise PSD of each channel over ``f_lo_hz <= f <= f_hi_hz``, in (rate unit)^2/Hz."""
        sel = (self.freq_hz >= f_lo_hz) & (self.freq_hz <= f_hi_hz)
        if not sel.any():
            raise ConfigError(f"no frequency of the self-noise estimate lies in {f_lo_hz:g}-{f_hi_hz:g} Hz")
        return self.noise_psd[:, sel].mean(axis=1)


def cross_spectra(channels, dt_s: float, nperseg: int) -> tuple[np.ndarray, np.ndarray, int]:
    """Welch (cross) spectral densities of the channels: ``(freq_hz, P, K)`` with ``P[i, j]`` the one-sided
    ``E[X_i X_j^*]`` in (unit)^2/Hz (Hann windows, half overlap, each segment's mean removed) and K the segments."""
    from scipy.signal import csd

    fs = 1.0 / dt_s
    c = len(channels)
    n = len(channels[0])
    K = 1 + (n - nperseg) // (nperseg // 2)
    P = None
    for i in range(c):
        for j in range(i, c):
            f, p = csd(channels[i], channels[j], fs=fs, window="hann", nperseg=nperseg, noverlap=nperseg // 2,
                       detrend="constant", scaling="density")
            if P is None:
                P = np.zeros((c, c, f.size), dtype=np.complex128)
            P[i, j] = p
            P[j, i] = np.conj(p)
    return f, P, K


def self_noise(*channels, dt_s: float, nperseg: int | None = None) -> SelfNoise:
    """Self-noise PSD of each of two or three co-located channels of one sensing axis.

    Parameters
    ----------
    *channels : array_like, shape (n_samples,)
        Two (identical responses: after Holcomb 1989) or three (any gains: Sleeman et al. 2006) rate series of
        the same axis, sampled together, in one unit.
    dt_s : float, keyword-only
        Sample interval in s.
    nperseg : int or None, keyword-only
        Welch segment length in samples; None: the power of two nearest N/32 (K ~ 63 segments), at least 64.

    Returns
    -------
    SelfNoise

    Raises
    ------
    ConfigError
        Not two or three channels, channels of different lengths, or a bad ``nperseg``/``dt_s``.
    InsufficientDataError
        Fewer than 4 Welch segments.

    Notes
    -----
    Two channels: ``N_ii = P_ii - Re P_12``.  Three: ``N_ii = Re(P_ji P_ik / P_jk)`` subtracted from ``P_ii``.
    Equations, assumptions and references in the module docstring.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> s = np.cumsum(rng.normal(size=2**15)) * 0.05          # a common red signal
    >>> x = [s + rng.normal(scale=sd, size=s.size) for sd in (1.0, 2.0, 0.5)]
    >>> r = self_noise(*x, dt_s=0.1)
    >>> np.round(r.band_noise(1.0, 5.0) / (2 * 0.1 * np.array([1.0, 4.0, 0.25])), 1)  # truth: 2 sd^2 dt
    array([1., 1., 1.])
    """
    if len(channels) not in (2, 3):
        raise ConfigError(f"self-noise needs two or three co-located channels of one axis, got {len(channels)}")
    xs = [np.asarray(check_series(c, f"channel {i + 1}"), dtype=np.float64) for i, c in enumerate(channels)]
    if len({x.size for x in xs}) != 1:
        raise ConfigError("self-noise channels must have the same number of samples (recorded together); got "
                          + ", ".join(str(x.size) for x in xs))
    dt = check_dt_s(dt_s)
    n = xs[0].size
    if nperseg is None:
        nperseg = max(64, 2 ** int(round(math.log2(max(n, 2) / 32.0))))
    if int(nperseg) != nperseg or nperseg < 8:
        raise ConfigError(f"nperseg must be an integer >= 8 samples, got {nperseg!r}")
    nperseg = int(nperseg)
    if n < nperseg or 1 + (n - nperseg) // (nperseg // 2) < 4:
        raise InsufficientDataError(f"self-noise needs at least 4 Welch segments of {nperseg} samples "
                                    f"({2.5 * nperseg:g} samples), got {n}", needed=int(2.5 * nperseg), got=n)
    f, P, K = cross_spectra(xs, dt, nperseg)
    f, P = f[1:], P[:, :, 1:]
    c = len(xs)
    auto = np.real(np.stack([P[i, i] for i in range(c)]))
    pairs = [(0, 1)] if c == 2 else [(0, 1), (0, 2), (1, 2)]
    with np.errstate(divide="ignore", invalid="ignore"):
        coh = np.stack([np.abs(P[i, j]) ** 2 / (auto[i] * auto[j]) for i, j in pairs])
        if c == 2:
            common = np.real(P[0, 1])
            noise = auto - common[None, :]
            signal = np.stack([common, common])
            method = "two-channel"
        else:
            signal = np.stack([np.real(P[j, i] * P[i, k] / P[j, k])
                               for i, j, k in ((0, 1, 2), (1, 0, 2), (2, 0, 1))])
            noise = auto - signal
            method = "three-channel"
        k_eff = 0.95 * K
        # the common signal's own scatter cancels in the differences; what stays is each noise's scatter and the
        # signal x noise cross terms: var ~ (N_i^2 + S_i mean_j N_j) / K_eff
        # the noise level in the variance: a running median over 65 frequencies (a single estimate where the
        # signal dominates scatters far below zero), floored at a thousandth of the channel's median level
        from scipy.ndimage import median_filter

        nn = median_filter(noise, size=(1, 65), mode="nearest")
        floor = 1e-3 * np.abs(np.median(noise, axis=1, keepdims=True))
        nn = np.maximum(nn, floor)
        cross = sum(nn[a] * nn[b] for a, b in pairs) / 2.0  # the noise x noise terms of the cross spectra
        var = nn**2 + cross[None, :] + np.abs(signal) * nn.mean(axis=0)[None, :]
        rel = np.sqrt(var) / np.abs(noise) / math.sqrt(k_eff)
    return SelfNoise(method=method, freq_hz=f, psd=auto, noise_psd=noise, coherence=coh, segments=int(K),
                     rel_sd=rel)
