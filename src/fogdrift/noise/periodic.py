"""Periodic content of a rate series, as the noise fit needs it: the spectral lines of the S term, the taus at
whole multiples of each period, and the words that name a line by its real frequency; the variance the lines add
at a given scale (Allan family and Haar wavelet variance, and their envelopes), and the one rule both noise fits
(the Allan fit and the GMWM) apply before they claim quantization beside lines (:func:`q_stands_above_lines`).

The spectrum itself is :func:`fogdrift.noise.spectral.analyse_spectrum` (a ``SpectrumSummary``); this module only
reads it (duck-typed: ``lines`` with ``freq_hz``/``amplitude_dph``/``harmonic_of``, ``components`` with
``fundamental_hz``/``period_s``/``lines``, ``rolloff_hz``).  Units: Hz, s, deg/h.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .terms import periodic_shape

__all__ = ["PeriodicContent", "periodic_content", "null_taus", "periodic_variance", "periodic_wvar",
           "q_stands_above_lines", "line_name", "Q_OVER_ENVELOPE", "LINE_SHARE_MAX"]

#: A tau counts as a whole multiple of a period when ``f tau`` is within this of an integer (the sinusoid's Allan
#: variance there is below ``sin^4(pi 0.05) / (pi f tau)^2 ~ 6e-4`` of its envelope).
NULL_TOLERANCE = 0.05

#: Quantization is claimed beside spectral lines only where its variance stands at least this many times above the
#: lines' envelope (:func:`periodic_variance` with ``envelope=True``) at some tau or scale used (``sqrt(10)`` = 3.2x
#: in deviation).  Q and a line's envelope both fall as ``tau^-2``, so the ratio is nearly the same at every tau.  A
#: fit that reads a line's tail as Q puts it at about the lines' mean level, ``3/8`` of the envelope (the mean of
#: ``sin^4``), up to the envelope itself (a wandering line fills its nulls); and where the GMWM has left out the
#: scales a line dominates, the QN it fits to the noise of the first kept scales came to 1-3.7x the envelope on
#: seeded records of white noise + a 20-Hz tone (2^16-2^17 samples, 20 seeds each): 10x stays clear of both, while a
#: quantization that stands out of the noise beside a line is usually tens of times above its envelope.
Q_OVER_ENVELOPE = 10.0

#: The GMWM leaves out the leading Haar scales up to the last one where the lines' wavelet variance
#: (:func:`periodic_wvar`) exceeds this share of the measured one: no latent process models a line.
LINE_SHARE_MAX = 0.05


@dataclass(frozen=True)
class PeriodicContent:
    """The spectral lines the noise fit models as one S term.

    Attributes
    ----------
    lines : tuple of (float, float)
        ``(freq_hz, relative_power)``: every detected line, its power relative to the reference line.
    ref_freq_hz, ref_amplitude_dph : float
        The strongest line (frequency [Hz], amplitude [deg/h]): S's ``Omega0`` is that line's fitted amplitude.
    periods_s : tuple of float
        Period [s] of each periodic component (fundamental) and of each line outside a component.
    descriptions : tuple of str
        One phrase per component or line: ``"spectral line at 20.02 Hz, 8.0 deg/h"``, ``"periodic error, period
        0.240 s (4.17 Hz and 5 harmonics)"``.
    rolloff_hz : float or None
        Where the spectrum shows an output low-pass roll-off; None when it shows none.
    """

    lines: tuple
    ref_freq_hz: float
    ref_amplitude_dph: float
    periods_s: tuple
    descriptions: tuple = field(default_factory=tuple)
    rolloff_hz: float | None = None

    def text(self) -> str:
        """All the descriptions, joined."""
        return "; ".join(self.descriptions)


def _g(x, k, default=None):
    return getattr(x, k, default) if not isinstance(x, dict) else x.get(k, default)


def periodic_content(spectrum) -> PeriodicContent | None:
    """The :class:`PeriodicContent` of a ``SpectrumSummary`` (None when it holds no line).

    Lines inside a periodic component keep their measured relative powers (harmonics of a sawtooth fall as
    ``1/k^2``); a line outside every component is its own component.
    """
    if spectrum is None:
        return None
    lines = list(_g(spectrum, "lines", ()) or ())
    comps = list(_g(spectrum, "components", ()) or ())
    seen = set()
    for c in comps:
        for ln in _g(c, "lines", ()) or ():
            seen.add(round(float(_g(ln, "freq_hz")), 9))
            if all(abs(float(_g(x, "freq_hz")) - float(_g(ln, "freq_hz"))) > 1e-9 for x in lines):
                lines.append(ln)
    lines = [ln for ln in lines if float(_g(ln, "freq_hz")) > 0 and float(_g(ln, "amplitude_dph")) > 0]
    if not lines:
        return None
    ref = max(lines, key=lambda ln: float(_g(ln, "amplitude_dph")))
    a_ref = float(_g(ref, "amplitude_dph"))
    out_lines = tuple((float(_g(ln, "freq_hz")), (float(_g(ln, "amplitude_dph")) / a_ref) ** 2) for ln in lines)
    periods, desc = [], []
    for c in sorted(comps, key=lambda c: -float(_g(c, "power_dph2", 0.0) or 0.0)):
        f0 = float(_g(c, "fundamental_hz"))
        p = float(_g(c, "period_s", 1.0 / f0 if f0 > 0 else math.nan))
        c_lines = list(_g(c, "lines", ()) or ())
        periods.append(p)
        if len(c_lines) <= 1:
            amp = float(_g(c_lines[0], "amplitude_dph")) if c_lines else math.nan
            desc.append(f"spectral line at {f0:.4g} Hz, {amp:.3g} deg/h")
        else:
            desc.append(f"periodic error, period {p:.3g} s ({f0:.4g} Hz and {len(c_lines) - 1} harmonic(s))")
    for ln in lines:
        f = float(_g(ln, "freq_hz"))
        if round(f, 9) in seen:
            continue
        periods.append(1.0 / f)
        desc.append(f"spectral line at {f:.4g} Hz, {float(_g(ln, 'amplitude_dph')):.3g} deg/h")
    roll = _g(spectrum, "rolloff_hz")
    return PeriodicContent(out_lines, float(_g(ref, "freq_hz")), a_ref, tuple(periods), tuple(desc),
                           None if roll is None else float(roll))


def null_taus(periods_s, dt_s, tau_min_s, tau_max_s, max_periods=16, max_components=2) -> np.ndarray:
    """Taus [s] (whole multiples of ``dt_s``) within ``[tau_min_s, tau_max_s]`` on a whole multiple of a period in
    ``periods_s`` (within :data:`NULL_TOLERANCE` of a cycle): where a sinusoid of that period adds nothing to the
    Allan variance, so quantization and a periodic error are told apart there.

    About one per octave of tau per period (``k`` = 1, 2, 4, ..., ``max_periods`` periods, the nearest sample
    multiple on a whole cycle), for the first ``max_components`` periods (the strongest components first): beyond 16
    periods a line's envelope ``1/(pi k)^2`` is below 4e-4 of its amplitude squared.

    Examples
    --------
    >>> null_taus([0.05], 0.01, 0.01, 0.5).tolist()
    [0.05, 0.1, 0.2, 0.4]
    """
    out = set()
    for p in list(periods_s)[:max_components]:
        p = float(p)
        if not (p > 0 and math.isfinite(p)):
            continue
        k = 1
        while k * p <= tau_max_s * (1 + 1e-9) and k <= max_periods:
            # the nearest sample count to k..2k periods whose tau is on a whole cycle
            for kk in range(k, 2 * k):
                m = max(1, int(round(kk * p / dt_s)))
                cyc = m * dt_s / p
                if abs(cyc - round(cyc)) <= NULL_TOLERANCE and tau_min_s <= m * dt_s <= tau_max_s:
                    out.add(m)
                    break
            k *= 2
    return np.array(sorted(m * dt_s for m in out), dtype=np.float64)


def _lines_of(content) -> tuple:
    """``(freq_hz, relative_power)`` of every line and ``Omega0^2`` [(deg/h)^2] of a :class:`PeriodicContent`."""
    return tuple(content.lines), float(content.ref_amplitude_dph) ** 2


def periodic_variance(content, tau_s, dt_s, statistic="adev", *, envelope=False, per_line=False) -> np.ndarray:
    """Variance [(deg/h)^2] the spectral lines of ``content`` add to an Allan-family statistic at ``tau_s`` [s].

    ``Omega0^2 sum_i r_i shape_i(tau)`` with the lines' amplitudes as the spectrum measured them
    (:func:`fogdrift.noise.terms.periodic_shape`; ``adev``: ``a_i^2 sin^4(pi f_i tau) / (m sin(pi f_i dt))^2``,
    ``m = tau / dt``).  ``envelope=True`` replaces ``sin(pi f_i tau)`` by 1: the level a wandering line can reach.
    ``per_line=True``: one row per line of ``content.lines`` (shape ``(n_lines,) + shape(tau_s)``), not their sum.

    Examples
    --------
    >>> pc = PeriodicContent(((20.0, 1.0),), 20.0, 8.0, (0.05,))
    >>> [round(float(v), 2) for v in periodic_variance(pc, [0.01, 0.05], 0.01)]  # 64 sin^2(0.2 pi); a whole period
    [22.11, 0.0]
    >>> round(float(periodic_variance(pc, 0.05, 0.01, envelope=True)[()]), 3)          # 64 / (5 sin(0.2 pi))^2
    7.41
    """
    lines, a2 = _lines_of(content)
    if per_line:
        return a2 * np.array([periodic_shape(tau_s, (ln,), float(dt_s), statistic, envelope=envelope) for ln in lines])
    return a2 * periodic_shape(tau_s, lines, float(dt_s), statistic, envelope=envelope)


def periodic_wvar(content, scale_samples, dt_s, *, envelope=False, per_line=False) -> np.ndarray:
    """Haar wavelet variance [(deg/h)^2] of the spectral lines of ``content`` at Haar scales ``scale_samples``
    (filter width ``tau_j = 2^j`` samples, as :attr:`fogdrift.gmwm.wvar.WvarResult.tau_samples`).

    A line of amplitude ``a`` [deg/h] has power ``P = a^2 / 2`` and Haar WV ``P |H(f dt, m)|^2`` with
    ``|H(f, m)|^2 = sin^4(pi f m) / (m^2 sin^2(pi f))`` the Haar filter's squared gain
    (:func:`fogdrift.gmwm.processes.haar_gain2`, ``f`` in cycles per sample, ``m = tau_j / 2``): half the Allan
    variance at ``tau = m dt`` (:func:`periodic_variance`), which is how it is computed.  ``envelope=True``
    replaces ``sin^4`` by 1; ``per_line=True`` gives one row per line.

    Examples
    --------
    >>> pc = PeriodicContent(((20.0, 1.0),), 20.0, 8.0, (0.05,))
    >>> [round(float(v), 3) for v in periodic_wvar(pc, [2, 4, 8], 0.01)]     # 32 sin^4(0.2 pi m) / (m sin(0.2 pi))^2
    [11.056, 18.944, 0.691]
    """
    m = 0.5 * np.asarray(scale_samples, dtype=np.float64)
    return 0.5 * periodic_variance(content, m * float(dt_s), dt_s, "adev", envelope=envelope, per_line=per_line)


def q_stands_above_lines(q_var, envelope_var, factor=Q_OVER_ENVELOPE) -> tuple[bool, float]:
    """The one rule for quantization beside spectral lines, in the Allan fit and in the GMWM alike: Q is told apart
    from the lines only where its variance stands at least ``factor`` times above the lines' envelope at some tau
    (scale) used.

    Parameters
    ----------
    q_var : array_like
        Q's variance at each tau (or Haar scale) used [(deg/h)^2], in the statistic of ``envelope_var``.
    envelope_var : array_like
        The lines' envelope there [(deg/h)^2] (:func:`periodic_variance` / :func:`periodic_wvar` with
        ``envelope=True``).
    factor : float
        :data:`Q_OVER_ENVELOPE`.

    Returns
    -------
    (bool, float)
        Whether Q stands above the lines, and the largest ratio ``q_var / envelope_var`` over the taus (inf where
        the envelope is 0: no line reaches there).

    Examples
    --------
    >>> q_stands_above_lines([1.0, 20.0], [1.0, 4.0])
    (False, 5.0)
    >>> q_stands_above_lines([1.0, 20.0], [1.0, 2.0])
    (True, 10.0)
    """
    q = np.asarray(q_var, dtype=np.float64).ravel()
    env = np.asarray(envelope_var, dtype=np.float64).ravel()
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(env > 0, q / np.where(env > 0, env, 1.0), np.where(q > 0, np.inf, 0.0))
    best = float(np.max(ratio)) if ratio.size else math.inf
    return bool(best >= factor), best


def line_name(content, freq_hz, df_hz=None) -> str:
    """Words naming the line of ``content`` at ``freq_hz`` [Hz] by its real frequency: ``"spectral line at 20.09 Hz"``,
    or for a harmonic of a periodic component ``"spectral line at 8.333 Hz (harmonic 2 of the periodic error with
    period 0.240 s, 4.167 Hz)"``.

    Examples
    --------
    >>> pc = PeriodicContent(((4.1667, 1.0), (8.3333, 0.25)), 4.1667, 8.0, (0.24,),
    ...                      ("periodic error, period 0.24 s (4.167 Hz and 1 harmonic(s))",))
    >>> line_name(pc, 8.3333)
    'spectral line at 8.333 Hz (harmonic 2 of the periodic error with period 0.240 s, 4.167 Hz)'
    >>> line_name(pc, 4.1667)
    'spectral line at 4.167 Hz (the fundamental of the periodic error with period 0.240 s)'
    """
    f = float(freq_hz)
    text = f"spectral line at {f:.4g} Hz"
    # a harmonic only of a component the spectrum grouped (its description says "periodic error")
    for p, d in zip(content.periods_s, content.descriptions):
        k = f * float(p)
        if d.startswith("periodic error") and k > 0.5 and abs(k - round(k)) <= 0.02 * round(k):
            if round(k) == 1:
                return text + f" (the fundamental of the periodic error with period {float(p):.3f} s)"
            return text + f" (harmonic {int(round(k))} of the periodic error with period {float(p):.3f} s, " \
                          f"{1.0 / float(p):.4g} Hz)"
    return text
