"""When a rising power-law term may be claimed from a measured curve (rate random walk K, rate ramp R).

A rate random walk K adds ``K^2 tau / 3`` to the Allan variance, a rate ramp R adds ``R^2 tau^2 / 2``: on a
log-log plot of the variance against tau they are straight lines of slope ``p = +1`` (K) and ``p = +2`` (R),
``+1/2`` and ``+1`` in deviation.  The Haar wavelet variance of the GMWM is ``AVAR / 2`` at the same scale, so
its slopes are the same.  A *hump* -- the curve rising for an octave or two and falling back, the signature of
an exponentially correlated (Gauss-Markov) process with correlation time ``T_c`` (ADEV maximum near
``1.9 T_c``) -- has no sustained slope, and a K or R fitted to it predicts a curve that keeps rising where the
measured one falls.  Both estimators (:func:`fogdrift.noise.identify`, :func:`fogdrift.gmwm.select_model`) ask
:func:`slope_claim` before they keep a model that holds such a term.

The rule (all three must hold):

(a) **Dominance over an octave.**  The term holds at least :data:`DOMINANCE` of the model variance at a run of
    consecutive measured points spanning at least one octave (``tau_last / tau_first >= 2``).  Elsewhere the
    curve is described by other terms whatever the term's coefficient, so the term is read from its own
    stretch only.
(b) **A sustained rise.**  Over that run the measured curve does not rise significantly slower than the model
    says it should.  Each point's degrees of freedom ``nu_i`` come from its own 95 % interval (the ratio
    ``hi / lo = chi2_nu(0.975) / chi2_nu(0.025)``), which gives the exact mean and variance of its logarithm,

    .. math:: E[\\ln \\hat\\sigma^2] = \\ln \\sigma^2 + \\psi(\\nu/2) - \\ln(\\nu/2), \\qquad
              \\mathrm{Var}[\\ln \\hat\\sigma^2] = \\psi_1(\\nu/2),

    (``psi`` the digamma, ``psi_1`` the trigamma function).  The weighted least-squares slope ``b`` of the
    bias-corrected ``ln sigma^2`` against ``ln tau`` is compared with the model's own slope ``b_model`` fitted the
    same way (the term's slope ``p`` diluted by the other terms' share; ``= p`` where the term alone is the model):
    the claim fails when ``z = (b - b_model) / se(b) < -`` :data:`Z_SLOPE` (one-sided, 5 %) *and* the curve rises
    by less than :data:`RISE_FRACTION` of the model's slope (a flat or falling stretch, not a slight bend).  The points are
    treated as independent; neighbouring Allan/Haar estimates are positively correlated, which makes the true
    standard error of a slope smaller, so the test is conservative towards a true term.
(c) **The longest taus.**  The model lies inside the measured interval (at :data:`LAST_LEVEL`, from the
    EDF of the point's 95 % interval) at each of the last :data:`N_LAST` points: a term that dominates the end of the record predicts the end of the curve.

A true K with few degrees of freedom at the longest tau passes in >= 90 % of seeded simulations, a
Gauss-Markov hump read as K fails in >= 95 % (``tests/noise/test_noise_rules.py``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.optimize import brentq
from scipy.special import polygamma, psi

from .distributions import chi2_ppf
from .processes import processes as _processes

__all__ = ["SlopeClaim", "slope_claim", "DOMINANCE", "Z_SLOPE", "N_LAST", "SLOPES"]

#: Share of the model variance a term must hold at every point of its stretch (criterion (a)).
DOMINANCE = 0.5
#: One-sided 5 % normal quantile: a measured rise this many standard errors below the model's fails (b).
Z_SLOPE = 1.645
#: ... and rises by less than this fraction of the model's slope there: a long stretch of many well-measured points
#: makes the slope's standard error tiny, and a real sensor's curve bends a little (the model-discrepancy
#: allowance); what (b) must refuse is a curve that bends over or stays flat, not one that rises a little slower (0.7: measured on 20-seed NK, NBK and GM-hump simulations, tests/noise/test_noise_rules.py).
RISE_FRACTION = 0.7
#: Criterion (c) looks at this many points at the longest taus.
N_LAST = 2
#: ... and judges each against its interval at this level: a right model misses one of two 95 % intervals one
#: time in ten, which refused true K's; a K read from a hump misses by far more.
LAST_LEVEL = 0.99
#: Variance slope against tau of the rising terms claimed only from a sustained slope (the rows of
#: :mod:`fogdrift.noise.processes` with ``slope_rule``): Allan fit names and GMWM process keys.
SLOPES = {name: float(p.term.avar_power) for p in _processes() if p.slope_rule
          for name in (p.name, p.latent.name if p.latent is not None else p.name)}

_WORDS = {1.0: "a rate random walk (variance slope +1, deviation slope +1/2)",
          2.0: "a rate ramp (variance slope +2, deviation slope +1)"}


@dataclass(frozen=True)
class SlopeClaim:
    """The verdict of :func:`slope_claim`.

    Attributes
    ----------
    ok : bool
        True when the term may be claimed.
    reason : str
        Why not (empty when ``ok``), in words with taus in s.
    tau_lo_s, tau_hi_s : float or None
        The stretch where the term dominates the model [s] (None when there is none).
    slope, slope_model, z : float
        Measured and model variance slopes over that stretch and the score ``(slope - slope_model) / se``
        (NaN without a stretch).
    """

    ok: bool
    reason: str
    tau_lo_s: float | None = None
    tau_hi_s: float | None = None
    slope: float = math.nan
    slope_model: float = math.nan
    z: float = math.nan

    def __bool__(self) -> bool:
        return self.ok


@lru_cache(maxsize=4096)
def _edf_from_interval(ratio: float) -> float:
    """Degrees of freedom ``nu`` of a chi-squared interval with ``hi / lo = ratio`` (clipped to 0.2-1e6; cached:
    a model selection asks the rule about many candidates on the same measured points)."""
    def f(lnu):
        nu = math.exp(lnu)
        return math.log(chi2_ppf(0.975, nu) / chi2_ppf(0.025, nu)) - math.log(ratio)

    if not math.isfinite(ratio) or ratio <= 1.0:
        return 1e6 if ratio <= 1.0 else 0.2
    lo, hi = math.log(0.2), math.log(1e6)
    if f(lo) <= 0:
        return 0.2
    if f(hi) >= 0:
        return 1e6
    return math.exp(brentq(f, lo, hi, xtol=1e-6))


def _wls_slope(x, y, w):
    """Weighted least-squares slope of ``y`` on ``x`` and its standard error (weights ``1 / var``)."""
    xm = np.sum(w * x) / np.sum(w)
    sxx = np.sum(w * (x - xm) ** 2)
    b = np.sum(w * (x - xm) * y) / sxx
    return float(b), float(1.0 / math.sqrt(sxx))


def slope_claim(tau_s, var, lo95, hi95, model_var, term_var, slope, *, name="K", curve="ADEV") -> SlopeClaim:
    """May a rising power-law term of variance slope ``slope`` be claimed from this measured curve?

    Parameters
    ----------
    tau_s : array_like, shape (n,)
        Measured taus or scales [s], increasing.
    var : array_like, shape (n,)
        Measured variances (Allan variance or Haar wavelet variance) [(deg/h)^2].
    lo95, hi95 : array_like, shape (n,)
        Their 95 % intervals [(deg/h)^2].
    model_var : array_like, shape (n,)
        The model's total variance at ``tau_s`` [(deg/h)^2].
    term_var : array_like, shape (n,)
        The term's own variance at ``tau_s`` [(deg/h)^2].
    slope : float
        The term's variance slope against tau: +1 (K, GMWM ``RW``) or +2 (R, GMWM ``DR``).
    name : str, keyword-only
        The term's name in the words (``K``, ``R``, ``RW``, ``DR``).
    curve : str, keyword-only
        The curve's name in the words (``ADEV`` or ``WV``; with ``WV`` the abscissa is called "scale").

    Returns
    -------
    SlopeClaim
        ``ok`` and, when not, the reason in words (module docstring: criteria (a)-(c)).

    Examples
    --------
    A curve rising like ``tau`` over three octaves carries a K; the same K fitted to a hump does not:

    >>> tau = np.array([100.0, 200, 400, 800, 1600])
    >>> rising = 1.0 + tau / 100
    >>> lo, hi = rising / 2, rising * 3
    >>> slope_claim(tau, rising, lo, hi, rising, tau / 100, 1.0).ok
    True
    >>> hump = np.array([2.0, 3.0, 3.5, 2.5, 2.0])
    >>> r = slope_claim(tau, hump, hump / 1.6, hump * 1.9, rising, tau / 100, 1.0)
    >>> r.ok, r.reason.split(":")[0]
    (False, 'K not claimed')
    """
    tau = np.asarray(tau_s, dtype=np.float64)
    y = np.asarray(var, dtype=np.float64)
    lo = np.asarray(lo95, dtype=np.float64)
    hi = np.asarray(hi95, dtype=np.float64)
    mu = np.asarray(model_var, dtype=np.float64)
    tv = np.asarray(term_var, dtype=np.float64)
    slope = float(slope)
    what = _WORDS.get(slope, f"a term of variance slope {slope:+g}")
    head = f"{name} not claimed"
    at = "scale" if curve.upper() == "WV" else "tau"  # the abscissa's name in the words

    # (a) the longest run of consecutive points where the term holds >= DOMINANCE of the model
    dom = (mu > 0) & (tv >= DOMINANCE * mu)
    runs, k = [], 0
    while k < tau.size:
        if dom[k]:
            j = k
            while j + 1 < tau.size and dom[j + 1]:
                j += 1
            runs.append((k, j))
            k = j + 1
        else:
            k += 1
    if not runs:
        return SlopeClaim(False, f"{head}: it holds less than {DOMINANCE:.0%} of the model variance at every "
                                 f"measured {at}, so no stretch of the {curve} is its own")
    i0, i1 = max(runs, key=lambda r: tau[r[1]] / tau[r[0]])
    span = tau[i1] / tau[i0]
    if span < 2.0 * (1 - 1e-9):
        where = f"{at} = {tau[i0]:.3g} s" if i0 == i1 else f"{at} = {tau[i0]:.3g}-{tau[i1]:.3g} s"
        return SlopeClaim(False, f"{head}: it holds >= {DOMINANCE:.0%} of the model variance only at {where}, "
                                 f"less than an octave of measured points, so the {curve} does not show "
                                 f"{what} over an octave", float(tau[i0]), float(tau[i1]))

    # (b) the measured rise over the run against the model's, with each point's EDF from its own interval
    sl = slice(i0, i1 + 1)
    nu = np.array([_edf_from_interval(float(h / l)) if l > 0 else 0.2 for l, h in zip(lo[sl], hi[sl])])
    ln_y = np.log(y[sl]) - (psi(nu / 2.0) - np.log(nu / 2.0))  # unbiased log of each estimate
    w = 1.0 / polygamma(1, nu / 2.0)
    x = np.log(tau[sl])
    b, se = _wls_slope(x, ln_y, w)
    b_model, _ = _wls_slope(x, np.log(mu[sl]), w)
    z = (b - b_model) / se
    span_txt = f"{at} = {tau[i0]:.3g}-{tau[i1]:.3g} s"
    if z < -Z_SLOPE and b < RISE_FRACTION * b_model:
        verb = "falls" if b < 0 else "stays flat" if b < 0.25 * slope else "rises too slowly"
        return SlopeClaim(
            False,
            f"{head}: the {curve} does not rise over an octave where {name} would dominate ({span_txt}): the "
            f"measured variance slope is {b:+.2f} +- {se:.2f} against the model's {b_model:+.2f} ({slope:+g} for "
            f"{name} alone), z = {z:.2f}; the curve {verb} there.  {name} is {what}, which needs a sustained "
            f"slope; a hump that rises and falls back is a Gauss-Markov (exponentially correlated) term",
            float(tau[i0]), float(tau[i1]), b, b_model, z)

    # (c) the model inside the measured 95 % interval at the longest taus
    bad = []
    for j in range(max(0, tau.size - N_LAST), tau.size):
        if lo[j] > 0 and y[j] > 0:  # the point's interval at LAST_LEVEL, from the EDF of its own 95 % interval
            nu_j = _edf_from_interval(float(hi[j] / lo[j]))
            a = (1.0 - LAST_LEVEL) / 2.0
            lo_j, hi_j = y[j] * nu_j / chi2_ppf(1.0 - a, nu_j), y[j] * nu_j / chi2_ppf(a, nu_j)
        else:
            lo_j, hi_j = lo[j], hi[j]
        if not lo_j <= mu[j] <= hi_j:
            bad.append(j)
    if bad:
        j = bad[-1]
        side = "above" if mu[j] > y[j] else "below"
        return SlopeClaim(
            False,
            f"{head}: with {name} the model lies {side} the measured {LAST_LEVEL:.0%} interval at {at} = {tau[j]:.3g} s "
            f"({math.sqrt(mu[j] / y[j]):.3g}x the measured deviation), so the longest taus do not carry "
            f"{what}; a hump that rises and falls back is a Gauss-Markov (exponentially correlated) term",
            float(tau[i0]), float(tau[i1]), b, b_model, z)
    return SlopeClaim(True, "", float(tau[i0]), float(tau[i1]), b, b_model, z)
