"""``fogdrift.noise.distributions`` answers what ``scipy.stats.chi2`` / ``scipy.stats.t`` answer, bit for bit.

The noise fit takes its chi-squared and t quantiles from :mod:`scipy.special` so that no command imports
``scipy.stats`` (0.3-0.6 s of start-up, issue 35).  Here the replacements are checked against SciPy's own
distributions on a grid of the arguments the fit uses (and edge cases: df <= 0, NaN, inf, integers, arrays).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.stats import chi2, t

from fogdrift.noise.distributions import chi2_median, chi2_ppf, chi2_sf, t_ppf

DFS = [0.3, 0.5, 1, 1.5, 2, 2.7, 3, 5, 7.5, 10, 17, 18, 33.3, 100, 1e3, 1e5, 1e7, np.inf, 0, -1.0, np.nan]
PS = [3.17e-5, 0.025, 0.05, 0.5, 0.95, 0.975, 1 - 3.17e-5]
XS = [0.0, -1.0, 1e-9, 0.3, 1.0, 5.0, 17.2, 100.0, 1e4, np.inf, np.nan]


def _same(a, b):
    assert type(a) is type(b), (type(a), type(b))
    assert np.array_equal(a, b, equal_nan=True), (a, b)
    if isinstance(a, np.ndarray):
        assert a.dtype == b.dtype


@pytest.mark.parametrize("df", DFS)
def test_scalar_quantiles_and_tails_are_scipy_stats_bit_for_bit(df):
    for p in PS:
        _same(chi2.ppf(p, df), chi2_ppf(p, df))
        _same(t.ppf(p, df), t_ppf(p, df))
    for x in XS:
        _same(chi2.sf(x, df), chi2_sf(x, df))
    _same(chi2.median(df), chi2_median(df))


def test_integer_and_array_arguments():
    for d in (1, 2, 5, 18):
        _same(chi2.ppf(0.975, d), chi2_ppf(0.975, d))
        _same(chi2.sf(13.5, d), chi2_sf(13.5, d))
        _same(t.ppf(0.95, d), t_ppf(0.95, d))
    nu = np.array([0.4, 1.0, 3.0, 7.7, 100.0, np.inf, 0.0])
    for p in PS:
        _same(chi2.ppf(p, nu), chi2_ppf(p, nu))
        _same(t.ppf(p, nu), t_ppf(p, nu))
    _same(chi2.ppf(1.0 - np.array([0.01, 0.2]), np.array([3.0, 9.0])),
          chi2_ppf(1.0 - np.array([0.01, 0.2]), np.array([3.0, 9.0])))
    _same(chi2.sf(np.array([0.0, 1.0, 3.0]), nu[:3]), chi2_sf(np.array([0.0, 1.0, 3.0]), nu[:3]))
    _same(chi2.median(nu), chi2_median(nu))
