"""The finite-record covariance of the overlapping Allan variance (``noise.covariance.finite_record_covariance``),
which the planner's simulated records use (``plan.spread``), against an exact reference and against simulation.

1. White rate noise: each estimate is a quadratic form ``y^T A_m y`` with ``A_m = D_m^T D_m / (2 M)`` (``D_m``
   stacks the ``M`` rows of the adjacent-mean difference), so ``Cov = 2 tr(A_i A_j)`` exactly (Isserlis).  The
   matrices are built here from the definition, row by row: no lag counting shared with the module.
2. White plus random-walk rate (a spectrum the quadratic form above does not cover), 4 000 seeded records of
   4 096 samples: the records' standard deviations and correlations against the formula, with tolerances from
   the records' own sampling error; the large-``M`` formula of ``estimator_covariance`` must fail the same check
   at the long taus (else the test could not tell the two apart).
"""

from __future__ import annotations

import numpy as np
import pytest

from fogdrift.noise.covariance import estimator_covariance, finite_record_covariance


def _white_exact(ms, n):
    """``Cov(sigma2_i, sigma2_j)`` of unit white rate noise from the explicit quadratic forms."""
    mats = []
    for m in ms:
        rows = n - 2 * m + 1
        D = np.zeros((rows, n))
        for k in range(rows):
            D[k, k:k + m] = -1.0 / m
            D[k, k + m:k + 2 * m] = 1.0 / m
        mats.append(D.T @ D / (2.0 * rows))
    return np.array([[2.0 * np.sum(a * b.T) for b in mats] for a in mats])


def _corr(c):
    s = np.sqrt(np.diag(c))
    return c / np.outer(s, s)


@pytest.mark.parametrize("exact_from", [0.0, 1 / 64])
def test_white_noise_matches_the_quadratic_form(exact_from):
    # up to m = N/4, where the large-M formula's standard deviation is 15 % high; exact_from = 0 sums every
    # pair lag by lag, the default only the long ones (the rest: large-M value with the M correction)
    n, ms = 512, [1, 2, 4, 8, 16, 32, 64, 128]
    ref = _white_exact(ms, n)
    got = finite_record_covariance(ms, n, lambda f: np.ones_like(f), exact_from=exact_from)
    # every covariance, the small ones between far-apart taus too (the M-corrected pairs: within 0.6 %, the
    # large-M cells' quadrature; summed: within 1e-3)
    np.testing.assert_allclose(got, ref, rtol=2e-3 if exact_from == 0.0 else 1e-2)
    np.testing.assert_allclose(_corr(got), _corr(ref), atol=1e-3)
    large = estimator_covariance(ms, n, lambda f: np.ones_like(f))
    assert np.sqrt(large[-1, -1] / ref[-1, -1]) > 1.1


def _simulated(n, ms, q, records, seed):
    """Overlapping Allan variances at ``ms`` of ``records`` records of unit white plus random-walk rate
    (increment variance ``q``)."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(records // 500):
        x = rng.standard_normal((500, n)) + np.cumsum(rng.standard_normal((500, n)) * np.sqrt(q), axis=1)
        th = np.concatenate([np.zeros((500, 1)), np.cumsum(x, axis=1)], axis=1)
        out.append(np.stack([np.mean(((th[:, 2 * m:] - 2 * th[:, m:-m] + th[:, :-2 * m]) / m) ** 2, axis=1) / 2
                             for m in ms], axis=1))
    return np.concatenate(out)


def test_random_walk_records_follow_the_finite_record_covariance():
    n, q, records = 4096, 1e-4, 4000
    ms = [2**k for k in range(11)]  # up to N/4
    y = _simulated(n, ms, q, records, seed=20261129)
    emp = np.cov(y.T)
    spec = lambda f: 1.0 + q / (4.0 * np.sin(np.pi * f) ** 2)  # noqa: E731
    fin = finite_record_covariance(ms, n, spec)
    large = estimator_covariance(ms, n, spec)
    # standard error of each record-to-record s.d. from the records' own fourth moment, of each correlation
    # (1 - rho^2) / sqrt(R) widened by 1.5 for the estimates' skew (chi-square with 3-9 degrees of freedom)
    d = y - y.mean(axis=0)
    se_sd = np.sqrt((np.mean(d**4, axis=0) - np.var(d, axis=0) ** 2) / records) / (2.0 * np.var(d, axis=0))
    sd_err = lambda c: np.abs(np.sqrt(np.diag(emp) / np.diag(c)) - 1.0) / se_sd  # noqa: E731
    rho = _corr(emp)
    se_rho = 1.5 * (1.0 - rho**2) / np.sqrt(records)
    np.fill_diagonal(se_rho, np.inf)  # the diagonal is 1 on both sides
    rho_err = lambda c: np.abs(_corr(c) - rho) / se_rho  # noqa: E731
    # measured (seed 20261129): the formula within 1.2 standard errors (s.d.) and 1.7 (correlations)
    assert sd_err(fin).max() < 3.5, sd_err(fin)
    assert rho_err(fin).max() < 3.5, rho_err(fin)
    # the large-M formula: the correlation of the two longest octaves 0.865 against the records' 0.776 (9 standard
    # errors; its s.d. at m = N/4 is 9 % high, 3.1 standard errors of these records: the white test pins that)
    assert rho_err(large).max() > 3.5
