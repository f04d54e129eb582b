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
from scipy.optimize import brentq

from .huber import HUBER_K

__all__ = ["ScoreProblem", "projected_gauss_newton", "fit_subsets", "profile_interval", "ic_within", "IC_ROUNDING"]

_KERNEL = {}


_NO_START = np.zeros(0)  # the kernel's "no start given: take the NNLS fit"


def _wh_kernel():
    """One compiled fit on a set of design columns (:func:`._kernels.fit_columns`: the start, then
    :func:`projected_gauss_newton` specialised to the whitened Wilson-Hilferty residual), compiled on first use
    and cached on disk."""
    if "fit" not in _KERNEL:
        from ._kernels import fit_columns

        _KERNEL["fit"] = fit_columns
    return _KERNEL["fit"]


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
    extra_var : float
        The part of each diagonal element of ``C`` that is no chi-squared sampling error (the model-discrepancy
        allowance, :mod:`fogdrift.noise.discrepancy`): it widens the scores but does not shift their centre,
        ``1 - 2 / (9 nu)`` with ``nu`` the sampling EDF ``2 / (C_ii - extra_var)``.
    """

    def __init__(self, X, y, C, upper, extra_var=0.0):
        self.X = np.asarray(X, dtype=np.float64)
        self.y = np.asarray(y, dtype=np.float64)
        self.extra_var = float(extra_var)
        sd = np.sqrt(np.diag(C))
        self.nu = 2.0 / np.diag(C)
        nu_sampling = 2.0 / np.maximum(np.diag(C) - self.extra_var, 1e-12)
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
        self.c = 1.0 - 2.0 / (9.0 * nu_sampling)
        self.s = np.sqrt(2.0 / (9.0 * self.nu))
        self.y3 = np.cbrt(self.y)
        self._memo = {}
        self.upper = np.asarray(upper, dtype=np.float64)
        # coefficient scale at which a column alone reaches the data somewhere (conditioning of the solver)
        with np.errstate(divide="ignore"):
            self.scale = np.array([np.min(self.y / self.X[:, j]) for j in range(self.X.shape[1])])
        # the compiled fit's per-column and per-point rows, packed once; the zero model a free fit adds to
        self._per_column = np.stack([self.scale, self.upper])
        self._per_point = np.stack([self.y, self.y3, self.c, self.s])
        self._zero = np.zeros(self.y.size)

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

        The same problem asked again (``cols``, ``a0``, ``fixed`` and the design ``X``, which a
        :class:`~fogdrift.noise.context.FitContext` may change between calls, all equal) returns the remembered
        answer: the fit is deterministic, and a profile interval or a model selection asks about a fifth of its
        fits twice.
        """
        cols = list(cols)
        design = self.X.tobytes()
        key = (tuple(cols), None if a0 is None else np.asarray(a0, dtype=np.float64).tobytes(),
               None if fixed is None else (fixed[0], float(fixed[1]).hex()), design)
        hit = self._memo.get(key)
        if hit is None:
            hit = self._memo[key] = self._fit(cols, a0, fixed)
        return hit[0].copy(), hit[1]

    def _fit(self, cols, a0, fixed):
        free = [c for c in cols if fixed is None or c != fixed[0]]
        add = self._zero if fixed is None else self.X[:, fixed[0]] * fixed[1]
        if not free:
            if not np.all(add > 0):
                return np.array([]), math.inf
            w = _huber_py(self.W @ self.scores(add))
            return np.array([]), float(w @ w)
        start = _NO_START if a0 is None else np.asarray(a0, dtype=np.float64)
        a = np.empty(len(free))
        q = _wh_kernel()(self.X, np.asarray(free, dtype=np.int64), self._per_column, self._per_point, add, self.W,
                         start, 100, 1e-10, a)
        return a, float(q)

    def profile(self, cols, col, a0=None):
        """``v -> Q`` of ``fit(cols, a0, fixed=(col, v))`` (the same numbers), for the many values of one profile's
        root search: the parts that do not depend on ``v`` are formed once, and each value asked again is
        remembered (the design must not change while the function is used)."""
        free = [c for c in cols if c != col]
        if not free:
            return lambda v: self.fit(cols, a0, (col, v))[1]
        kernel, free_idx, column = _wh_kernel(), np.asarray(free, dtype=np.int64), self.X[:, col]
        start = _NO_START if a0 is None else np.asarray(a0, dtype=np.float64)
        out, seen = np.empty(len(free)), {}

        def q_at(v):
            q = seen.get(v)
            if q is None:
                q = seen[v] = float(kernel(self.X, free_idx, self._per_column, self._per_point, column * v, self.W,
                                           start, 100, 1e-10, out))
            return q

        return q_at


#: Relative difference below which two information-criterion values count as the same number.  A superset whose
#: extra terms all come out 0 has its subset's Q, so its IC lies a whole number of penalties away, often exactly on
#: the edge of the plausible window; rounding (the order of a sum) must not decide on which side.
IC_ROUNDING = 1e-9


def ic_within(ic: float, ic_ref: float, delta: float) -> bool:
    """``ic <= ic_ref + delta``, an IC equal to the edge up to rounding (:data:`IC_ROUNDING`) counted inside.

    Examples
    --------
    >>> ic_within(16.000000000001, 10.0, 6.0), ic_within(16.001, 10.0, 6.0)
    (True, False)
    """
    return ic <= ic_ref + delta + IC_ROUNDING * max(1.0, abs(ic_ref))


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
    q_fixed = problem.profile(cols, col, a0)

    def g(v):
        return q_fixed(v) - target

    ub = float(problem.upper[col])
    lo = 0.0
    if lower and v_hat > 0 and g(0.0) > 0:
        # tolerances relative to the bracket, not to the value: a ramp or a white-noise level can be known to
        # 1e-4 of itself, and a relative tolerance of 1e-3 would then miss the interval entirely
        lo = brentq(g, 0.0, v_hat, xtol=1e-7 * v_hat, rtol=1e-12, maxiter=100) if g(v_hat) < 0 else v_hat
    x0 = min(v_hat if v_hat > 0 else 1e-12 * ub, ub)
    x1 = min(ub, max(2.0 * x0, x0 + 1e-9 * ub))  # never past the upper bound (the fit is not defined there)
    g1 = g(x1)
    while x1 < ub and g1 <= 0:
        x0, x1 = x1, min(ub, 4.0 * x1)
        g1 = g(x1)
    if g1 <= 0:  # still inside at the upper bound
        hi = x1
    elif x1 > x0 and g(x0) <= 0:
        hi = brentq(g, x0, x1, xtol=1e-7 * (x1 - x0), rtol=1e-12, maxiter=100)
    else:
        hi = x0
    return lo, hi


def all_subsets(cols):
    """Every non-empty subset of ``cols``, smallest first."""
    cols = tuple(cols)
    return [s for r in range(1, len(cols) + 1) for s in itertools.combinations(cols, r)]
