"""Chi-squared and Student-t quantiles through :mod:`scipy.special`, without importing :mod:`scipy.stats`.

``import scipy.stats`` costs 0.3-0.6 s of start-up (its docstring machinery and ~300 modules) on every command
that fits noise terms, ``fogdrift allan`` included, while the noise fit needs only four functions of two
distributions.  These are the very special functions ``scipy.stats.chi2`` and ``scipy.stats.t``
evaluate (SciPy 1.17: ``chi2._ppf = 2 gammaincinv(df/2, p)``, ``chi2._sf = chdtrc``, ``t._ppf = stdtrit``), with the
same answers outside the support: NaN for ``df <= 0`` or NaN.  ``tests/noise/test_noise_distributions.py`` checks them
bit for bit against ``scipy.stats`` on a grid of arguments.
"""

from __future__ import annotations

import numpy as np
from scipy.special import chdtrc, gammaincinv, stdtrit

__all__ = ["chi2_ppf", "chi2_median", "chi2_sf", "t_ppf"]


def _out(v):
    """A 0-d result as a NumPy scalar (what ``scipy.stats`` returns), an array as is."""
    return v[()] if isinstance(v, np.ndarray) and v.ndim == 0 else v


def _valid(df) -> np.ndarray:
    return np.asarray(df) > 0  # False for NaN too


def chi2_ppf(p, df):
    """``scipy.stats.chi2.ppf(p, df)`` for ``0 < p < 1`` (the callers' probabilities are constants in (0, 1))."""
    df = np.asarray(df)
    with np.errstate(invalid="ignore"):
        v = np.where(_valid(df), 2.0 * gammaincinv(df / 2.0, p), np.nan)
    return _out(v)


def chi2_median(df):
    """``scipy.stats.chi2.median(df)``."""
    return chi2_ppf(0.5, df)


def chi2_sf(x, df):
    """``scipy.stats.chi2.sf(x, df)``: 1 at and below 0, 0 at +inf."""
    x, df = np.asarray(x, dtype=np.float64), np.asarray(df)
    with np.errstate(invalid="ignore"):
        v = np.where(x <= 0.0, 1.0, np.where(x == np.inf, 0.0, chdtrc(df, np.where(x <= 0.0, 1.0, x))))
        v = np.where(_valid(df) & ~np.isnan(x), v, np.nan)
    return _out(v)


def t_ppf(p, df):
    """``scipy.stats.t.ppf(p, df)`` for ``0 < p < 1``."""
    df = np.asarray(df)
    with np.errstate(invalid="ignore"):
        v = np.where(_valid(df), stdtrit(df, p), np.nan)
    return _out(v)
