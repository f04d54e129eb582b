"""Characters of the disturbed intervals the record screen finds (:mod:`fogdrift.screen`): vibration bursts and warm-ups.

These rules only *name* what the screen's detectors (window levels, window-mean steps) already found; they add no
detection, so the screen's false-alarm rate on stationary noise is unchanged by them.

``vibration burst``
    A level interval (a ``transient``) whose excess power is band-limited and steady: at least
    :data:`BAND_FRACTION` of the interval's excess spectrum (its Welch spectrum over windows of L samples minus the
    quiet windows' one) lies within one octave centred on its peak frequency, and it is steady: no window's excess
    level (``s_j / s_ref - 1``) above :data:`STEADY_RATIO` times the interval's median one (an engine, a pump, a
    platform resonance switched on and off).  A band-limited wave train whose envelope rises and decays (an earthquake's surface waves) stays a
    ``transient``; so does a burst of broadband noise.
``warm-up``
    Disturbances found at the record start (an interval or a window-mean step beginning in the first 5 % of the
    record or its first four windows)
    that an exponential settling of the window means ``mu_j = c + A exp(-t_j / T)`` explains better than one level
    step: ``|A|`` beyond the screen's step threshold ``z sigma_D`` (lag 1), ``T`` from one window to a quarter of
    the record (a log grid), and the exponential's residual sum of squares below the best single step's.  The
    warm-up interval runs from the first sample to where ``|A| exp(-t/T)`` falls to the scatter of one window mean
    (``sigma_D / sqrt 2``), and takes in the start disturbances it explains.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["BAND_FRACTION", "STEADY_RATIO", "welch_windows", "is_vibration_burst", "warm_up_end"]

#: Share of an interval's excess power inside one octave around its peak for a vibration burst.
BAND_FRACTION = 0.6
#: ... and at least this many times the octave's share of the frequency bins (broadband excess fills its share).
CONCENTRATION = 2.0

#: Largest ratio of a window's excess level to the interval's median excess level for a steady (vibration) burst.
STEADY_RATIO = 3.0


def welch_windows(y: np.ndarray, starts, L: int) -> np.ndarray:
    """Mean Hann-windowed periodogram (rfft bins of L samples, each window's line removed) over the windows starting
    at ``starts``; arbitrary scale (only ratios of such spectra are used)."""
    w = np.hanning(L)
    t = np.arange(L) - (L - 1) / 2.0
    acc = np.zeros(L // 2 + 1)
    k = 0
    for a in starts:
        x = np.asarray(y[a:a + L], dtype=np.float64)
        if x.size < L:
            continue
        x = x - x.mean()
        x = x - (np.dot(t, x) / np.dot(t, t)) * t
        acc += np.abs(np.fft.rfft(x * w)) ** 2
        k += 1
    return acc / max(k, 1)


def is_vibration_burst(y: np.ndarray, a: int, b: int, L: int, quiet_psd: np.ndarray, window_ratios) -> bool:
    """True when the interval ``y[a:b]`` is a steady band-limited burst (module docstring).

    ``quiet_psd``: :func:`welch_windows` over the quiet windows; ``window_ratios``: the interval's window levels
    over the quiet level (variance ratios ``s_j / s_ref``), whose excesses ``s_j / s_ref - 1`` must stay within
    :data:`STEADY_RATIO` of their median (a steady burst).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> y = rng.normal(size=4096)
    >>> y[1024:2048] += 4 * np.sin(2 * np.pi * 0.1 * np.arange(1024))
    >>> q = welch_windows(y, range(2048, 4096 - 64, 64), 64)
    >>> steady = np.full(16, 9.0)
    >>> is_vibration_burst(y, 1024, 2048, 64, q, steady), is_vibration_burst(rng.normal(size=4096) * 3, 1024, 2048,
    ...                                                                      64, q, steady)
    (True, False)
    >>> is_vibration_burst(y, 1024, 2048, 64, q, np.geomspace(30.0, 1.5, 16))  # decaying: a transient
    False
    """
    n = b - a
    if n < 2 * L:
        return False
    step = max(1, L // 2)
    p = welch_windows(y, range(a, b - L + 1, step), L)
    excess = np.clip(p - quiet_psd, 0.0, None)
    excess[0] = 0.0
    total = float(excess.sum())
    if not total > 0:
        return False
    k = int(np.argmax(excess))
    lo, hi = int(math.floor(k / math.sqrt(2.0))), int(math.ceil(k * math.sqrt(2.0)))
    hi = min(hi, excess.size - 1)
    # concentrated: the octave holds BAND_FRACTION of the excess AND at least CONCENTRATION times its share of the
    # frequency bins (an octave near the Nyquist frequency spans half of them: broadband noise fills it by chance)
    share = (hi - lo + 1) / max(1, excess.size - 1)
    if float(excess[lo:hi + 1].sum()) < max(BAND_FRACTION, CONCENTRATION * share) * total:
        return False
    excess_w = np.asarray(window_ratios, dtype=np.float64) - 1.0  # each window's excess over the quiet level
    med = float(np.median(excess_w))
    return med > 0 and float(excess_w.max()) <= STEADY_RATIO * med


def warm_up_end(mu: np.ndarray, centres_s: np.ndarray, use: np.ndarray, sigma_d: float, z: float,
                window_s: float) -> tuple[float, float] | None:
    """``(end_s, change)`` of a warm-up explaining the window means at the record start, or None (module docstring).

    ``mu``: window means; ``centres_s``: their centres in s; ``use``: windows the fit may use (not inside a later
    disturbance); ``sigma_d``: the scatter of adjacent-window mean differences; ``z``: the step threshold in units
    of ``sigma_d``; ``window_s``: the window length in s.  ``change``: the fitted settling ``-A`` (final level minus
    initial, in the rate's unit).

    Examples
    --------
    >>> t = (np.arange(64) + 0.5) * 10.0
    >>> mu = 5.0 * np.exp(-t / 60.0) + np.random.default_rng(1).normal(scale=0.05, size=64)
    >>> end, change = warm_up_end(mu, t, np.ones(64, bool), 0.07, 4.0, 10.0)
    >>> round(change, 1), 250 < end < 400
    (-5.0, True)
    """
    if not sigma_d > 0:
        return None
    t, m = centres_s[use], mu[use]
    if t.size < 8:
        return None
    span = float(centres_s[-1] + window_s / 2.0)
    best = None
    for T in np.geomspace(window_s, span / 4.0, 60):
        X = np.column_stack([np.ones_like(t), np.exp(-t / T)])
        coef, *_ = np.linalg.lstsq(X, m, rcond=None)
        rss = float(np.sum((m - X @ coef) ** 2))
        if best is None or rss < best[0]:
            best = (rss, float(T), float(coef[1]))
    rss_exp, T, A = best
    # the best single level step in the first half of the record
    rss_step = math.inf
    for p in range(1, max(2, t.size // 2)):
        r = float(np.sum((m[:p] - m[:p].mean()) ** 2) + np.sum((m[p:] - m[p:].mean()) ** 2))
        rss_step = min(rss_step, r)
    if abs(A) <= z * sigma_d or not rss_exp < rss_step:
        return None
    sigma_1 = sigma_d / math.sqrt(2.0)
    end = T * math.log(abs(A) / sigma_1)
    if not 0 < end <= span / 2.0:
        return None
    return end, -A
