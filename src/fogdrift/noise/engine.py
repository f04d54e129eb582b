"""Fitting engine of the IEEE-952 noise model to an Allan-family curve (arrays in, arrays out).

The model is ``sigma^2(tau) = sum_n A_n tau^p_n`` with ``A_n >= 0`` (columns of a design matrix ``X``).  Each
estimate is treated as ``mu_i chi2_{nu_i} / nu_i``; the Wilson-Hilferty transform ([WH1931]_)

    u_i = ((y_i / mu_i)^(1/3) - 1 + 2/(9 nu_i)) / sqrt(2/(9 nu_i))

is close to a standard normal score even for ``nu ~ 1`` (the long-tau end), so the deviations are neither
measured on the self-justifying scale of the model (a model far above the data would get a huge variance) nor on
the data's (a model far below the data would be cheap).  The scores are whitened with the correlation matrix of
the estimates (model based, :mod:`.covariance`) and ``Q = ||L^-1 u||^2`` is minimised subject to
``0 <= A_n <= U_n`` where ``U_n`` keeps every single term below the ~4-sigma upper bound of the measured curve
at every fitted tau (no term may claim more variance than the data hold anywhere).

Everything here is deterministic numerics on small arrays; the public wrapper is :func:`fogdrift.noise.fit_noise`.

References
----------
.. [WH1931] E. B. Wilson, M. M. Hilferty, "The distribution of chi-square", PNAS 17(12):684-688 (1931).
"""

from __future__ import annotations

import itertools
import math

import numpy as np
from scipy.optimize import brentq, nnls

__all__ = ["ScoreProblem", "projected_gauss_newton", "fit_subsets", "profile_interval"]

_KERNEL = {}

#: Huber constant of the objective: a whitened residual beyond HUBER_K standard deviations counts linearly, not
#: quadratically, so one extreme innovation (typically the last, 1-3 EDF octave, whose distribution is far from
#: normal) cannot drag the whole fit.  Normal residuals exceed it with probability 0.27 %.
HUBER_K = 3.0


def _wh_kernel():
    """numba version of :func:`projected_gauss_newton` specialised to the whitened Wilson-Hilferty residual."""
    if "pgn" not in _KERNEL:
        import numba

        @numba.njit(cache=True)
        def residual(Xs, add, W, y3, c, s, u):  # pragma: no cover - compiled
            n = Xs.shape[0]
            z = np.empty(n)
            for i in range(n):
                mu = add[i]
                for k in range(Xs.shape[1]):
                    mu += Xs[i, k] * u[k]
                if mu < 1e-300:
                    mu = 1e-300
                z[i] = (y3[i] / np.cbrt(mu) - c[i]) / s[i]
            w = W @ z
            return huber(w)

        @numba.njit(cache=True)
        def huber(w):  # pragma: no cover - compiled
            # sign(w) sqrt(2 rho(w)) with Huber's rho (k = HUBER_K): quadratic inside, linear outside
            out = np.empty(w.size)
            for i in range(w.size):
                a = abs(w[i])
                if a <= HUBER_K:
                    out[i] = w[i]
                else:
                    out[i] = np.sign(w[i]) * np.sqrt(2.0 * HUBER_K * a - HUBER_K * HUBER_K)
            return out

        @numba.njit(cache=True)
        def dhuber(w):  # pragma: no cover - compiled
            out = np.empty(w.size)
            for i in range(w.size):
                a = abs(w[i])
                out[i] = 1.0 if a <= HUBER_K else HUBER_K / np.sqrt(2.0 * HUBER_K * a - HUBER_K * HUBER_K)
            return out

        @numba.njit(cache=True)
        def pgn(Xs, add, W, y3, c, s, u0, ub, max_iter, tol):  # pragma: no cover - compiled
            n, p = Xs.shape
            x = np.minimum(np.maximum(u0, 0.0), ub)
            r = residual(Xs, add, W, y3, c, s, x)
            q = r @ r
            for _ in range(max_iter):
                d = np.empty(n)
                for i in range(n):
                    mu = add[i]
                    for k in range(p):
                        mu += Xs[i, k] * x[k]
                    if mu < 1e-300:
                        mu = 1e-300
                    d[i] = -(y3[i] / np.cbrt(mu)) / (3.0 * mu * s[i])
                zz = np.empty(n)
                for i in range(n):
                    mu = add[i]
                    for k in range(p):
                        mu += Xs[i, k] * x[k]
                    if mu < 1e-300:
                        mu = 1e-300
                    zz[i] = (y3[i] / np.cbrt(mu) - c[i]) / s[i]
                J = (W @ (Xs * d.reshape(-1, 1))) * dhuber(W @ zz).reshape(-1, 1)
                g = J.T @ r
                free = np.ones(p, dtype=np.bool_)
                nf = 0
                for k in range(p):
                    if (x[k] <= 0.0 and g[k] > 0.0) or (x[k] >= ub[k] and g[k] < 0.0):
                        free[k] = False
                    else:
                        nf += 1
                if nf == 0:
                    break
                idx = np.where(free)[0]
                Jf = J[:, idx]
                H = Jf.T @ Jf
                for k in range(nf):
                    H[k, k] *= 1.0 + 1e-12
                    H[k, k] += 1e-300
                stepf = -np.linalg.solve(H, Jf.T @ r)
                step = np.zeros(p)
                for k in range(nf):
                    step[idx[k]] = stepf[k]
                t = 1.0
                improved = False
                xn = x.copy()
                rn = r
                qn = q
                for _ls in range(40):
                    for k in range(p):
                        v = x[k] + t * step[k]
                        xn[k] = min(max(v, 0.0), ub[k])
                    rn = residual(Xs, add, W, y3, c, s, xn)
                    qn = rn @ rn
                    if qn < q - 1e-13 * max(1.0, q):
                        improved = True
                        break
                    t *= 0.5
                if not improved:
                    break
                dq = q - qn
                x = xn.copy()
                r = rn
                q = qn
                if dq <= tol * max(1.0, q):
                    break
            return x, q

        _KERNEL["pgn"] = pgn
    return _KERNEL["pgn"]


def projected_gauss_newton(res, jac, x0, upper, *, max_iter=100, tol=1e-10):
    """Minimise ``||res(x)||^2`` over ``0 <= x <= upper`` (a few parameters): projected Gauss-Newton steps on the
    free set with backtracking.  Returns ``(x, Q)``."""
    x = np.clip(np.asarray(x0, dtype=np.float64), 0.0, upper)
    r = res(x)
    q = float(r @ r)
    for _ in range(max_iter):
        J = jac(x)
        g = J.T @ r
        free = ~(((x <= 0) & (g > 0)) | ((x >= upper) & (g < 0)))
        if not free.any():
            break
        step = np.zeros_like(x)
        Jf = J[:, free]
        H = Jf.T @ Jf
        H[np.diag_indices_from(H)] *= 1.0 + 1e-12
        try:
            step[free] = -np.linalg.solve(H, Jf.T @ r)
        except np.linalg.LinAlgError:
            step[free] = -np.linalg.lstsq(Jf, r, rcond=None)[0]
        t, improved = 1.0, False
        for _ls in range(40):
            xn = np.clip(x + t * step, 0.0, upper)
            rn = res(xn)
            qn = float(rn @ rn)
            if qn < q - 1e-13 * max(1.0, q):
                improved = True
                break
            t *= 0.5
        if not improved:
            break
        dq = q - qn
        x, r, q = xn, rn, qn
        if dq <= tol * max(1.0, q):
            break
    return x, q


def _huber_py(w):
    a = np.abs(w)
    return np.where(a <= HUBER_K, w, np.sign(w) * np.sqrt(np.maximum(2 * HUBER_K * a - HUBER_K**2, 0.0)))


class ScoreProblem:
    """Whitened Wilson-Hilferty scores of ``y ~ X a`` under a fixed relative covariance ``C``.

    Parameters
    ----------
    X : ndarray, shape (n, k)
        Design: ``X[i, j] = tau_i ** p_j``.
    y : ndarray, shape (n,)
        Measured variances (> 0).
    C : ndarray, shape (n, n)
        Relative covariance ``Cov(y_i, y_j) / (mu_i mu_j)`` of the estimates (model based); ``nu_i = 2 / C_ii``.
    upper : ndarray, shape (k,)
        Upper bounds of the coefficients.
    """

    def __init__(self, X, y, C, upper):
        self.X = np.asarray(X, dtype=np.float64)
        self.y = np.asarray(y, dtype=np.float64)
        sd = np.sqrt(np.diag(C))
        self.nu = 2.0 / np.diag(C)
        R = C / np.outer(sd, sd)
        try:
            L = np.linalg.cholesky(R + np.eye(self.y.size) * 1e-10)
        except np.linalg.LinAlgError:
            # quadrature noise made the correlation matrix slightly indefinite: clip its spectrum
            w, v = np.linalg.eigh(R)
            R = (v * np.maximum(w, 1e-8 * w.max())) @ v.T
            d = np.sqrt(np.diag(R))
            L = np.linalg.cholesky(R / np.outer(d, d) + np.eye(self.y.size) * 1e-10)
        self.W = np.linalg.inv(L)  # lower triangular; tiny (n_tau x n_tau)
        self.c = 1.0 - 2.0 / (9.0 * self.nu)
        self.s = np.sqrt(2.0 / (9.0 * self.nu))
        self.y3 = np.cbrt(self.y)
        self.upper = np.asarray(upper, dtype=np.float64)
        # coefficient scale at which a column alone reaches the data somewhere (conditioning of the solver)
        with np.errstate(divide="ignore"):
            self.scale = np.array([np.min(self.y / self.X[:, j]) for j in range(self.X.shape[1])])

    def scores(self, mu):
        """Standard-normal scores of the data under the model values ``mu`` (positive: data above model)."""
        return (self.y3 / np.cbrt(mu) - self.c) / self.s

    def q_of(self, a_full):
        """``Q`` of a full coefficient vector (shape (k,))."""
        mu = self.X @ a_full
        if not np.all(mu > 0):
            return math.inf
        w = _huber_py(self.W @ self.scores(mu))
        return float(w @ w)

    def fit(self, cols, a0=None, fixed=None):
        """Minimise ``Q`` over the coefficients in ``cols`` (others 0); ``fixed=(col, value)`` pins one of them.

        Returns ``(a, Q)`` with ``a`` the coefficients of the free columns (in ``cols`` order, minus the fixed one).
        """
        cols = list(cols)
        free = [c for c in cols if fixed is None or c != fixed[0]]
        add = np.zeros(self.y.size) if fixed is None else self.X[:, fixed[0]] * fixed[1]
        if not free:
            if not np.all(add > 0):
                return np.array([]), math.inf
            w = _huber_py(self.W @ self.scores(add))
            return np.array([]), float(w @ w)
        scale = self.scale[free]
        Xs = self.X[:, free] * scale
        ub = self.upper[free] / scale
        if a0 is None:
            wt = 1.0 / self.y
            u0, _ = nnls(Xs * wt[:, None], np.maximum(self.y - add, 0.0) * wt)
        else:
            u0 = np.asarray(a0, dtype=np.float64) / scale
        u0 = np.clip(u0, 1e-6, ub * (1 - 1e-9))
        u, q = _wh_kernel()(np.ascontiguousarray(Xs), add, self.W, self.y3, self.c, self.s, u0,
                            np.ascontiguousarray(ub, dtype=np.float64), 100, 1e-10)
        return u * scale, float(q)


def fit_subsets(problem: ScoreProblem, candidates, penalty: float):
    """Fit every candidate column subset; returns ``{subset: {"q", "ic", "a"}}`` with ``a`` full-length."""
    k = problem.X.shape[1]
    out = {}
    for cols in candidates:
        a, q = problem.fit(cols)
        full = np.zeros(k)
        full[list(cols)] = a
        out[tuple(cols)] = {"q": q, "ic": q + penalty * len(cols), "a": full}
    return out


def profile_interval(problem: ScoreProblem, cols, a_hat, col, q_min, delta, *, lower=True):
    """Profile interval ``{v : min_others Q(A_col = v) <= q_min + delta}`` of coefficient ``col``.

    ``a_hat`` is the full-length estimate.  Returns ``(lo, hi)``; ``lo`` is 0 when the term can vanish, ``hi`` is
    at most ``problem.upper[col]``.  Brent's method on each side ([Brent1973]_).
    """
    others = [c for c in cols if c != col]
    a0 = a_hat[others] if others and np.all(a_hat[others] > 0) else None
    v_hat = float(a_hat[col])
    q_at = problem.fit(cols, a0=a0, fixed=(col, v_hat))[1]
    target = min(q_min, q_at) + delta

    def g(v):
        return problem.fit(cols, a0=a0, fixed=(col, v))[1] - target

    ub = float(problem.upper[col])
    lo = 0.0
    if lower and v_hat > 0 and g(0.0) > 0:
        # tolerances relative to the bracket, not to the value: a ramp or a white-noise level can be known to
        # 1e-4 of itself, and a relative tolerance of 1e-3 would then miss the interval entirely
        lo = brentq(g, 0.0, v_hat, xtol=1e-7 * v_hat, rtol=1e-12, maxiter=100) if g(v_hat) < 0 else v_hat
    x0 = v_hat if v_hat > 0 else 1e-12 * ub
    x1 = max(2.0 * x0, x0 + 1e-9 * ub)
    while x1 < ub and g(x1) <= 0:
        x0, x1 = x1, min(ub, 4.0 * x1)
    if x1 >= ub and g(ub) <= 0:
        hi = ub
    elif g(x0) <= 0:
        hi = brentq(g, x0, x1, xtol=1e-7 * (x1 - x0), rtol=1e-12, maxiter=100)
    else:
        hi = x0
    return lo, hi


def all_subsets(cols):
    """Every non-empty subset of ``cols``, smallest first."""
    cols = tuple(cols)
    return [s for r in range(1, len(cols) + 1) for s in itertools.combinations(cols, r)]
