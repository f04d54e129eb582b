"""What a noise fit may claim: the sustained-slope rule applied to a set of candidate models, and the true bounds
of a fit that does not hold.

:func:`_slope_refusals` asks :func:`fogdrift.noise.rules.slope_claim` (the one rule both estimators read) about
every candidate whose K or R is in the model, on the measured curve's own intervals (:func:`_measured_limits`);
:func:`_no_fit_terms` replaces the terms of a model that misses the curve by the bounds the curve itself sets.
Used by :mod:`fogdrift.noise.identify`; ``c`` is its fit context (working points ``tau``, ``y``, ``y_hi``, design
``X``, the statistic's ``laws``).
"""

from __future__ import annotations

import functools
import math

import numpy as np
from scipy.optimize import brentq

from .context import FitContext
from .distributions import chi2_ppf
from .result import NoiseTerm
from .rules import SLOPES, slope_claim
from .terms import TERM_TABLE, all_terms, power_terms

_names = all_terms  # the fit's columns: Q N B K R (then any registered power-law term), S, M


_CURVE = {"adev": "ADEV", "hdev": "HDEV", "mdev": "MDEV"}


def _measured_limits(c: FitContext, nu):
    """The 95 % chi-squared interval ``[y nu / chi2_nu(0.975), y nu / chi2_nu(0.025)]`` of each point: with the
    EDF of the measured curve's own interval (its ``var_hi95``), which the slope rule needs -- the model's EDF at
    a long tau is that of the model being judged (a K model lends the long taus its own, wider, scatter) --
    and the model's ``nu`` only where the curve brought no interval."""
    nu = np.maximum(np.asarray(nu, dtype=np.float64), 1e-3).copy()
    ratio = c.y_hi / c.y
    for i, r in enumerate(ratio):
        if np.isfinite(r) and 1.0 < r < 1e5:
            nu[i] = _edf_from_upper(float(r))
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        return c.y * nu / chi2_ppf(0.975, nu), c.y * nu / chi2_ppf(0.025, nu)


@functools.lru_cache(maxsize=4096)
def _edf_from_upper(ratio: float) -> float:
    """EDF ``nu`` of a chi-squared interval whose upper limit is ``ratio`` times the estimate
    (``nu / chi2_nu(0.025) = ratio``; 0.2-1e7)."""
    def f(lnu):
        nu = math.exp(lnu)
        return math.log(nu / chi2_ppf(0.025, nu)) - math.log(ratio)

    lo, hi = math.log(0.2), math.log(1e7)
    if f(hi) >= 0:
        return 1e7
    if f(lo) <= 0:
        return 0.2
    return math.exp(brentq(f, lo, hi, xtol=1e-6))


def _slope_refusals(c: FitContext, prob, res) -> dict:
    """``{subset: SlopeClaim}`` of the candidates of ``res`` whose K or R fails the sustained-slope rule
    (:func:`fogdrift.noise.rules.slope_claim`: it must dominate over an octave, the curve must rise there as the
    model says, and the model must meet the longest taus).  Such a candidate is not selectable: a hump is a
    Gauss-Markov term (M), not a random walk.  The model values use the current columns of ``c`` (the M column at
    the correlation time being tried)."""
    limits = _measured_limits(c, prob.nu)
    out = {}
    for k, v in res.items():
        claim = _refusal(c, limits, k, v["a"])
        if claim is not None:
            out[k] = claim
    return out


def _refusal(c: FitContext, limits, k, a):
    """The failed :func:`~fogdrift.noise.rules.slope_claim` of subset ``k`` (coefficients ``a``), or None: its K,
    then its R, judged against the measured curve's 95 % ``limits``."""
    lo, hi = limits
    mu = None
    for name in ("K", "R"):
        i = _names().index(name)
        if i in k and a[i] > 0:
            mu = c.X @ a if mu is None else mu
            claim = slope_claim(c.tau, c.y, lo, hi, mu, _rising_var(c, a, name), SLOPES[name], name=name,
                                curve=_CURVE.get(c.statistic, c.statistic.upper()))
            if not claim.ok:
                return claim
    return None


def _first_claimable(c: FitContext, prob, res, fallback=None):
    """``_best_claimable(res, _slope_refusals(c, prob, res), fallback)``, asking the slope rule only down the IC
    order until a candidate passes: the same subset (ties in ``res``'s order, as :func:`min` takes them) for a
    fraction of the rule's calls, where only the best claimable candidate is wanted."""
    limits = None
    for k in sorted(res, key=lambda k: res[k]["ic"]):
        if limits is None:
            limits = _measured_limits(c, prob.nu)
        if _refusal(c, limits, k, res[k]["a"]) is None:
            return k
    return fallback


def _rising_var(c: FitContext, a, name):
    """The variance the rule weighs for ``name``: K's stretch is the rise of K and R together (a K between a
    flicker floor and a ramp shapes a sustained rise without ever holding half the variance alone); R's is R's."""
    cols = ("K", "R") if name == "K" else (name,)
    return sum(c.X[:, _names().index(t)] * a[_names().index(t)] for t in cols)


def _best_claimable(res, refused, fallback=None):
    """The smallest-IC subset of ``res`` not in ``refused`` (``fallback`` when every one is)."""
    keep = [k for k in res if k not in refused]
    return min(keep, key=lambda k: res[k]["ic"]) if keep else fallback


def _no_fit_terms(c: FitContext, out_terms: dict, laws, dt_s) -> None:
    """The terms of a model that misses the curve are no result: every estimated or absent power-law term becomes
    status ``"no_fit"`` with, as its ``hi95``, the bound the measured curve itself sets.

    IEEE-952 terms add and none is negative, so each alone lies below the measured variance at every fitted tau:
    ``X <= min_tau sqrt(var_hi(tau) / shape_X(tau))``, with ``var_hi`` each point's ~4-sigma upper limit (the
    95 % limit stretched to 4 sigma, so the minimum over all the fitted taus still holds: a 95 % limit per point
    is missed by one of twenty points).  That bound needs no model, so it is a true bound even where every model
    fails -- unlike the profile limit of a model that does not fit (which lay below the measured read-out on a real
    MEMS axis).  The best candidate's value is kept, labelled by the status.
    """
    data_bound = c._upper()  # per term, in law units: the ~4-sigma limit of the curve alone, no model
    for i, name in enumerate(power_terms()):
        t = out_terms.get(name)
        if t is None or name not in laws or t.status not in ("resolved", "unresolved", "absent"):
            continue
        if not data_bound[i] > 0:
            continue
        conv = TERM_TABLE[name].to_unit / math.sqrt(laws[name].scale(dt_s))
        bound = conv * math.sqrt(float(data_bound[i]))
        why = ("no model fits the curve: the best candidate's value is no result; the bound is the measured "
               "curve's own (each term alone stays below its upper 95 % limit at every fitted tau)")
        out_terms[name] = NoiseTerm(name, t.value, t.unit, None, bound, "no_fit", why)
