"""Null distribution of the spectral line search's local-median statistic (:mod:`fogdrift.noise.spectral`).

A line at Welch bin ``k`` is tested with ``r = P_k / max(med_left, med_right)`` (the PSD over the larger of its
two one-sided local medians, dimensionless); this module gives the survival function of ``r`` under "no line"
and its critical value, cached per (EDF, half-window, bin correlation, level).
"""

from __future__ import annotations

import functools
import math

import numpy as np


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


@functools.lru_cache(maxsize=512)
def _null_and_critical(nu: float, w: int, corr: float, p_target: float):
    """The :class:`_MedianNull` and its critical ratio for ``p_target`` (cached: a batch of equal-length records
    needs them once)."""
    null = _MedianNull(nu, w, corr)
    return null, null.critical(p_target)
