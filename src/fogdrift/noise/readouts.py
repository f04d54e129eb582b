"""The classic IEEE-952 slope read-outs, as a labelled cross-check of the fit.

IEEE Std 952-1997 Annex C reads each coefficient off a straight line of its slope on the log-log ADEV plot:
Q = sigma(sqrt 3 s) on the -1 line, N = sigma(1 h) on the -1/2 line, K = sigma(3 h) on the +1/2 line,
R = sigma(sqrt 2 h) on the +1 line, and B = min sigma / 0.664.  Each read-out here takes the measured point whose
local slope is nearest the term's slope (within 0.2, on the side of the ADEV minimum where the term can live) and
says whether the fitted model has that term dominating there.  A read-out taken where another term dominates is a
transition, not a measurement of its term, and is labelled so; a read-out that disagrees with the fit beyond the
fit's interval says why.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..units import B_FACTOR, S_PER_H, URAD_PER_ARCSEC
from .terms import ALL_TERMS, DISPLAY_UNITS, TERM_UNITS, TERMS

__all__ = ["Readout", "slope_readouts"]

#: term -> (slope of sigma, tau [s] at which the line is read, factor to the reported unit, unit)
_READ = {
    "Q": (-1.0, math.sqrt(3.0), URAD_PER_ARCSEC, TERM_UNITS["Q"]),
    "N": (-0.5, S_PER_H, 1.0, TERM_UNITS["N"]),
    "K": (0.5, 3.0 * S_PER_H, 1.0, TERM_UNITS["K"]),
    "R": (1.0, math.sqrt(2.0) * S_PER_H, 1.0, TERM_UNITS["R"]),
}


@dataclass(frozen=True)
class Readout:
    """One slope read-out: ``value`` [``unit``] read at the measured ``tau_s`` (None when the curve shows no such
    slope); ``dominated`` is True when the fitted model's own term makes up at least half of the variance there;
    ``note`` explains a disagreement with the fit."""

    term: str
    value: float | None
    unit: str
    tau_s: float | None
    slope: float | None
    dominated: bool | None
    note: str
    tau_range_s: tuple | None = None

    def to_dict(self) -> dict:
        out = dict(self.__dict__)
        out["tau_range_s"] = None if self.tau_range_s is None else [float(t) for t in self.tau_range_s]
        return out

    def text(self) -> str:
        if self.value is None:
            return f"{self.term}: no {self.term}-slope in the curve"
        where = "its term dominates" if self.dominated else "another term dominates"
        unit = DISPLAY_UNITS.get(self.term, self.unit) if self.unit == TERM_UNITS.get(self.term) else self.unit
        if self.tau_range_s is not None:
            at = (f"median over the {self.slope:+.2f} slope at tau = {self.tau_range_s[0]:.3g}-"
                  f"{self.tau_range_s[1]:.3g} s")
        else:
            at = f"read at tau = {self.tau_s:.3g} s"
        out = f"{self.term} {self.value:.3g} {unit} ({at}, {where})"
        return out + (f"; {self.note}" if self.note else "")


def slope_readouts(tau_s, adev_dph, fit=None) -> dict:
    """Read-outs of Q, N, B, K, R from a measured ADEV curve, checked against ``fit`` (a CurveFit) when given.

    Returns
    -------
    dict
        Term -> :class:`Readout`.
    """
    tau = np.asarray(tau_s, dtype=np.float64)
    s = np.asarray(adev_dph, dtype=np.float64)
    ok = s > 0
    tau, s = tau[ok], s[ok]
    out = {}
    if tau.size < 3:
        return {t: Readout(t, None, u, None, None, None, "too few taus") for t, (_, _, _, u) in _READ.items()}
    slope = np.gradient(np.log(s), np.log(tau))
    i_min = int(np.argmin(s))
    for term, (mu, tau_read, fac, unit) in _READ.items():
        side = np.arange(tau.size) <= i_min if mu < 0 else np.arange(tau.size) >= i_min
        inside = side
        if fit is not None and len(getattr(fit, "fit_tau_s", ())):  # a run is read where the fit looked
            inside = side & (tau >= fit.tau_min_s * (1 - 1e-9)) & (tau <= fit.tau_max_s * (1 + 1e-9))
        run = _slope_run(tau, s, mu, inside)
        if run is not None:  # the term's own line, held over at least an octave: read it along the whole run
            a, b = run
            vals = s[a:b + 1] * (tau_read / tau[a:b + 1]) ** mu * fac
            k = a + int(np.argsort(vals)[vals.size // 2])  # the median point (an actual measured point)
            seg = float(np.polyfit(np.log(tau[a:b + 1]), np.log(s[a:b + 1]), 1)[0])
            ro = _judge(term, float(np.median(vals)), unit, float(tau[k]), seg, fit)
            out[term] = Readout(**{**ro.__dict__, "tau_range_s": (float(tau[a]), float(tau[b]))})
            continue
        dist = np.where(side, np.abs(slope - mu), np.inf)
        i = int(np.argmin(dist))
        if dist[i] > 0.2:
            out[term] = Readout(term, None, unit, None, None, None, "the curve shows no such slope")
            continue
        value = float(s[i] * (tau_read / tau[i]) ** mu * fac)
        out[term] = _judge(term, value, unit, float(tau[i]), float(slope[i]), fit)
    if 0 < i_min < s.size - 1:
        out["B"] = _judge("B", float(s[i_min] / B_FACTOR), TERM_UNITS["B"], float(tau[i_min]), float(slope[i_min]), fit)
    else:
        out["B"] = Readout("B", None, "deg/h", None, None, None,
                           "the ADEV has no interior minimum (still falling or rising at the record's end)")
    return {t: out[t] for t in TERMS}


#: A slope run holds when every chord between neighbouring points is within this of the term's slope.
RUN_SLOPE_TOLERANCE = 0.1


def _slope_run(tau, s, mu, side):
    """``(first, last)`` index of the longest run of at least three points (on ``side``) whose every
    neighbour-to-neighbour chord has the slope ``mu`` within :data:`RUN_SLOPE_TOLERANCE` and that spans at least
    an octave of tau; None when there is none.

    Examples
    --------
    >>> tau = np.array([1.0, 2, 4, 8, 16, 32])
    >>> _slope_run(tau, np.array([9.0, 3, 2.1, 1.5, 1.06, 1.1]), -0.5, np.ones(6, bool))
    (1, 4)
    """
    lt, ls = np.log(tau), np.log(s)
    chord = np.diff(ls) / np.diff(lt)
    good = (np.abs(chord - mu) <= RUN_SLOPE_TOLERANCE) & side[:-1] & side[1:]
    best, k = None, 0
    while k < good.size:
        if not good[k]:
            k += 1
            continue
        j = k
        while j + 1 < good.size and good[j + 1]:
            j += 1
        a, b = k, j + 1  # points a..b
        if b - a >= 2 and tau[b] >= 2.0 * tau[a] * (1 - 1e-9) and (best is None or lt[b] - lt[a] > lt[best[1]] - lt[best[0]]):
            best = (a, b)
        k = j + 1
    return best


def _judge(term, value, unit, tau, slope, fit) -> Readout:
    if fit is None or fit.statistic != "adev":
        return Readout(term, value, unit, tau, slope, None, "")
    parts = {n: float(fit.term_dev_dph(n, [tau])[0]) ** 2 for n in ALL_TERMS}
    total = sum(parts.values())
    share = parts[term] / total if total > 0 else 0.0
    dominated = share >= 0.5
    t = fit.terms[term]
    note = ""
    lo, hi = (t.lo95 or 0.0), t.hi95
    if hi is not None and not (lo <= value <= hi):
        if not dominated and total > 0:
            top = max(parts, key=parts.get)
            note = f"differs from the fit: {top} makes up {100 * parts[top] / total:.0f} % of the model there"
        elif fit.fit_tau_s[0] > tau or tau > fit.fit_tau_s[-1]:
            note = "differs from the fit: read outside the fitted tau range"
        else:
            note = "differs from the fit: one point of a curve that is not a single straight line there"
    return Readout(term, value, unit, tau, slope, dominated, note)
