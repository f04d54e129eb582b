"""Periodic content of a rate series, as the noise fit needs it: the spectral lines of the S term, the taus at
whole multiples of each period, and the words that name a line by its real frequency.

The spectrum itself is :func:`fogdrift.noise.spectral.analyse_spectrum` (a ``SpectrumSummary``); this module only
reads it (duck-typed: ``lines`` with ``freq_hz``/``amplitude_dph``/``harmonic_of``, ``components`` with
``fundamental_hz``/``period_s``/``lines``, ``rolloff_hz``).  Units: Hz, s, deg/h.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

__all__ = ["PeriodicContent", "periodic_content", "null_taus"]

#: A tau counts as a whole multiple of a period when ``f tau`` is within this of an integer (the sinusoid's Allan
#: variance there is below ``sin^4(pi 0.05) / (pi f tau)^2 ~ 6e-4`` of its envelope).
NULL_TOLERANCE = 0.05


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
