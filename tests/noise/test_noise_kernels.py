"""The compiled kernels of the noise fit (``fogdrift.noise._kernels``) against independent references: SciPy's
``nnls`` for the start, the NumPy projected Gauss-Newton (``engine.projected_gauss_newton``) for the fit, both on
seeded problems shaped as the fit's (powers of tau over several decades, correlated estimates, outliers that the
Huber loss caps)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import nnls as scipy_nnls

from fogdrift.noise._kernels import fit_columns, nnls, pgn
from fogdrift.noise.engine import ScoreProblem, _huber_py, projected_gauss_newton
from fogdrift.noise.huber import HUBER_K

POWERS = (-2.0, -1.0, 0.0, 1.0, 2.0)


def _curve_problem(rng, outliers=0):
    """A ScoreProblem of a random sum of tau powers over 1e-2 .. 1e4 s, correlated neighbours, EDF 2 .. 1e4."""
    n = int(rng.integers(8, 25))
    tau = np.logspace(-2, 4, n)
    X = tau[:, None] ** np.array(POWERS)[None, :]
    a = np.where(rng.random(len(POWERS)) < 0.7, 10.0 ** rng.uniform(-6, 1, len(POWERS)), 0.0)
    a[1] = max(a[1], 1e-4)
    nu = np.logspace(4, 0.3, n)
    y = (X @ a) * rng.chisquare(nu) / nu
    for i in rng.choice(n, size=outliers, replace=False):
        y[i] *= 30.0  # far outside: the Huber part of the loss
    rho = 0.5
    R = rho ** np.abs(np.subtract.outer(np.arange(n), np.arange(n)))
    C = R * np.sqrt(np.outer(2.0 / nu, 2.0 / nu))
    upper = np.array([np.min(4 * y / X[:, j]) for j in range(len(POWERS))])
    return ScoreProblem(X, y, C, upper)


def _reference_fit(prob, free, a0=None):
    """The same fit from NumPy and SciPy parts: scaled columns, SciPy's NNLS start, the NumPy Gauss-Newton."""
    scale = prob.scale[free]
    Xs = prob.X[:, free] * scale
    ub = prob.upper[free] / scale
    wt = 1.0 / prob.y
    if a0 is None:
        u0, _ = scipy_nnls(Xs * wt[:, None], prob.y * wt)
    else:
        u0 = np.asarray(a0) / scale
    u0 = np.minimum(np.maximum(u0, 1e-6), ub * (1 - 1e-9))

    def res(u):
        mu = np.maximum(Xs @ u, 1e-300)
        return _huber_py(prob.W @ ((prob.y3 / np.cbrt(mu) - prob.c) / prob.s))

    def jac(u):
        mu = np.maximum(Xs @ u, 1e-300)
        ratio = prob.y3 / np.cbrt(mu)
        w = prob.W @ ((ratio - prob.c) / prob.s)
        dh = np.where(np.abs(w) <= HUBER_K, 1.0, HUBER_K / np.sqrt(np.maximum(2 * HUBER_K * np.abs(w) - HUBER_K**2,
                                                                                1e-300)))
        return (prob.W @ (Xs * (-ratio / (3.0 * mu * prob.s))[:, None])) * dh[:, None]

    u, q = projected_gauss_newton(res, jac, u0, ub)
    return u * scale, q


def test_nnls_matches_scipy_on_tau_power_designs():
    """Residual norm equal to SciPy's (1e-10 relative) on 400 seeded designs of 1-5 tau-power columns, full rank
    or not, right-hand sides inside and outside the cone; x >= 0 and the KKT sign conditions hold."""
    rng = np.random.default_rng(35)
    worse = 0
    for _ in range(400):
        m, k = int(rng.integers(5, 25)), int(rng.integers(1, 6))
        tau = np.logspace(-2, rng.uniform(0.5, 5), m)
        A = tau[:, None] ** rng.choice(POWERS, k)[None, :]
        A /= np.linalg.norm(A, axis=0)
        b = A @ np.maximum(rng.normal(size=k), 0.0) + rng.normal(size=m) * rng.uniform(0.0, 0.5)
        x = nnls(A, b, 3 * k)
        xs, rs = scipy_nnls(A, b, maxiter=100 * k)
        r = np.linalg.norm(A @ x - b)
        worse += r > rs * (1 + 1e-10) + 1e-12
        assert np.all(x >= 0)
        g = A.T @ (b - A @ x)  # gradient of -||r||^2 / 2
        assert np.all(g[x == 0] <= 1e-8 * max(1.0, np.abs(b).max()))
    assert worse == 0


@pytest.mark.parametrize("outliers", [0, 2])
def test_fit_columns_matches_the_numpy_reference(outliers):
    """Every column subset of 30 seeded problems: Q of the compiled fit equal to the NumPy/SciPy reference's
    to 1e-8 relative, from its own start and from a given one; the Huber cap is reached on the way."""
    rng = np.random.default_rng(952 + outliers)
    n_huber = 0
    for _ in range(30):
        prob = _curve_problem(rng, outliers)
        for free in ([1], [0, 1], [1, 3], [0, 1, 2, 3], [0, 1, 2, 3, 4], [2, 4]):
            f = np.asarray(free, dtype=np.int64)
            a = np.empty(len(free))
            q = fit_columns(prob.X, f, *_packed(prob), np.zeros(prob.y.size), prob.W, np.zeros(0), 100, 1e-10, a)
            a_ref, q_ref = _reference_fit(prob, free)
            assert q == pytest.approx(q_ref, rel=1e-8, abs=1e-12)
            assert q == pytest.approx(prob.q_of(_full(a, free)), rel=1e-12)
            start = a_ref * 1.3 + 1e-9
            q2 = fit_columns(prob.X, f, *_packed(prob), np.zeros(prob.y.size), prob.W, start, 100, 1e-10,
                             np.empty(len(free)))
            assert q2 == pytest.approx(_reference_fit(prob, free, start)[1], rel=1e-8, abs=1e-12)
            w = prob.W @ prob.scores(prob.X[:, free] @ a)
            n_huber += bool(np.any(np.abs(w) > HUBER_K))
    assert n_huber > 0  # the capped part of the loss was reached (misfitting subsets, outliers)


def test_pgn_stays_inside_the_bounds_and_lowers_q():
    """A start above the upper bounds is projected; the result is feasible and no worse than the start."""
    prob = _curve_problem(np.random.default_rng(3))
    free = [0, 1, 3]
    scale = prob.scale[free]
    Xs = np.ascontiguousarray(prob.X[:, free] * scale)
    ub = prob.upper[free] / scale
    u0 = ub * 5.0
    u, q = pgn(Xs, np.zeros(prob.y.size), prob.W, prob.y3, prob.c, prob.s, u0, ub, 100, 1e-10)
    assert np.all(u >= 0) and np.all(u <= ub)
    assert q <= prob.q_of(_full(np.minimum(u0, ub) * scale, free)) + 1e-12


def _packed(prob):
    """The kernel's per-column rows (scale, upper) and per-point rows (y, y^(1/3), c, s), built here from the
    problem's documented attributes."""
    return np.stack([prob.scale, prob.upper]), np.stack([prob.y, prob.y3, prob.c, prob.s])


def _full(a, free):
    out = np.zeros(len(POWERS))
    out[list(free)] = a
    return out
