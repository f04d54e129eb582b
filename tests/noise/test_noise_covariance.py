"""The model covariance of Allan-family estimates (``fogdrift.noise.covariance``) against an exact reference.

For Gaussian white rate noise of unit variance every overlapping estimate is a quadratic form
``q = y^T A y`` with ``A = C^T C / (norm M)`` (``C`` stacks the ``M`` filter rows), so the exact finite-``N``
covariance is ``Cov(q_i, q_j) = 2 tr(A_i A_j) = 2 ||C_i C_j^T||_F^2 / (norm^2 M_i M_j)`` (Isserlis). The
filter rows are written here from the definitions (SP 1065 eqs. 11, 14, 20), not taken from the package. The
module's frequency-domain formula is a large-``M`` approximation: with ``m <= N/128`` it must agree within 2 %.
"""

from __future__ import annotations

import numpy as np
import pytest

from fogdrift.noise.covariance import estimator_covariance, expected_variance

N = 2048
MS = [1, 2, 4, 8, 16]


def _kernel(m: int, stat: str) -> tuple[np.ndarray, float]:
    """One filter row of the overlapping estimator (weights on consecutive rate samples) and its normaliser."""
    mean = np.ones(m) / m
    if stat == "adev":  # (ybar_{k+m} - ybar_k)^2 / 2
        return np.concatenate([-mean, mean]), 2.0
    if stat == "hdev":  # (ybar_{k+2m} - 2 ybar_{k+m} + ybar_k)^2 / 6
        return np.concatenate([mean, -2 * mean, mean]), 6.0
    return np.convolve(np.concatenate([-mean, mean]), mean), 2.0  # mdev: m-mean of the Allan differences


def _frobenius_cross(ki: np.ndarray, kj: np.ndarray) -> float:
    """||C_i C_j^T||_F^2 for the banded row stacks C of N samples: sum over row offsets d = l - k of
    (number of row pairs at offset d) x (inner product of the two rows at that offset)^2."""
    Mi, Mj = N - ki.size + 1, N - kj.size + 1
    total = 0.0
    for d in range(-(kj.size - 1), ki.size):
        a = np.zeros(N)
        b = np.zeros(N)
        a[: ki.size] = ki
        b[max(d, 0): max(d, 0) + kj.size] = kj if d >= 0 else 0.0
        if d < 0:
            a[:] = 0.0
            a[-d: -d + ki.size] = ki
            b[: kj.size] = kj
        pairs = min(Mi, Mj - d) - max(0, -d)
        total += pairs * float(a @ b) ** 2
    return total


@pytest.mark.parametrize("stat", ["adev", "hdev", "mdev"])
def test_white_noise_covariance_matches_the_exact_quadratic_form(stat):
    rows = {m: _kernel(m, stat) for m in MS}
    exact = np.empty((len(MS), len(MS)))
    for i, mi in enumerate(MS):
        (ki, ni), Mi = rows[mi], N - rows[mi][0].size + 1
        for j, mj in enumerate(MS):
            (kj, nj), Mj = rows[mj], N - rows[mj][0].size + 1
            exact[i, j] = 2.0 * _frobenius_cross(ki, kj) / (ni * nj * Mi * Mj)
    model = estimator_covariance(MS, N, lambda f: np.ones_like(f), statistic=stat)
    # standard deviations and correlations, each within 2 % / 0.02 of the exact finite-N values
    np.testing.assert_allclose(np.sqrt(np.diag(model)), np.sqrt(np.diag(exact)), rtol=0.02)
    corr = lambda c: c / np.sqrt(np.outer(np.diag(c), np.diag(c)))  # noqa: E731
    np.testing.assert_allclose(corr(model), corr(exact), atol=0.02)
    # the expectation: trace(A) = |kernel|^2 / norm for unit white noise
    exp_exact = [np.sum(rows[m][0] ** 2) / rows[m][1] for m in MS]
    np.testing.assert_allclose(expected_variance(MS, lambda f: np.ones_like(f), statistic=stat), exp_exact,
                               rtol=1e-3)


def test_quadrature_density_converges():
    # 16 cells per octave (the default) against 48: the documented < 4e-4 relative change of the std
    spectrum = lambda f: 1.0 + 1e-3 / np.sin(np.pi * f) ** 2  # noqa: E731  white + random walk
    m = [1, 3, 10, 40, 160, 640]
    coarse = np.sqrt(np.diag(estimator_covariance(m, 100_000, spectrum, per_octave=16)))
    fine = np.sqrt(np.diag(estimator_covariance(m, 100_000, spectrum, per_octave=48)))
    np.testing.assert_allclose(coarse, fine, rtol=4e-4)
