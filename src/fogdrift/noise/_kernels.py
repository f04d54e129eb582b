"""Compiled kernels of :mod:`fogdrift.noise.engine` (numba, imported on first use).

Module-level functions, so that numba's on-disk cache is reused by every new process: as closures inside a
factory they referred to each other as free variables, could not be cached, and every ``fogdrift`` run (and
every Dask worker of ``fogdrift batch``) compiled them again (~5 s).

:func:`pgn` is :func:`fogdrift.noise.engine.projected_gauss_newton` on the whitened Wilson-Hilferty residual,
written for problems of a few parameters and some tens of working points: every product, the Gauss-Newton
normal equations and their solve are plain loops over work arrays allocated once per call.  The same steps with
NumPy's operators (a BLAS call for each ``W @ z``, a LAPACK solve, about ten temporaries per iteration) took
19 us a fit on the fits of ``make demo``, these loops 11 us; the sums run in another order, so ``Q`` agrees to
about 1e-14 relative (``tests/noise/test_noise_kernels.py`` checks the kernel against the NumPy reference).

:func:`fit_columns` is one whole fit of :meth:`fogdrift.noise.engine.ScoreProblem.fit` on a set of design
columns: the scaled columns and bounds, the start (the non-negative least-squares fit of the relative errors,
:func:`nnls`, where none is given) and :func:`pgn`, in one call instead of some ten NumPy and SciPy calls
(``scipy.optimize.nnls`` alone: 6 us of argument checks around a 1.6 us solve).
"""

import numba
import numpy as np

from .huber import HUBER_K

__all__ = ["pgn", "nnls", "fit_columns"]


@numba.njit(cache=True)
def _scores(Xs, add, y3, c, s, x, z, dz):  # pragma: no cover - compiled
    """Scores ``z_i = (y_i^(1/3) / mu_i^(1/3) - c_i) / s_i`` of the model ``mu = add + Xs x`` (floored at 1e-300)
    and, where ``dz`` has room, their derivatives ``dz_i / dmu_i``."""
    n, p = Xs.shape
    for i in range(n):
        mu = add[i]
        for k in range(p):
            mu += Xs[i, k] * x[k]
        if mu < 1e-300:
            mu = 1e-300
        ratio = y3[i] / np.cbrt(mu)
        z[i] = (ratio - c[i]) / s[i]
        if dz.size:
            dz[i] = -ratio / (3.0 * mu * s[i])


@numba.njit(cache=True)
def _huber(w):  # pragma: no cover - compiled
    """``sign(w) sqrt(2 rho(w))`` with Huber's rho (``k = HUBER_K``): ``w`` inside, growing as ``sqrt(|w|)`` outside."""
    a = abs(w)
    if a <= HUBER_K:
        return w
    return np.sign(w) * np.sqrt(2.0 * HUBER_K * a - HUBER_K * HUBER_K)


@numba.njit(cache=True)
def _dhuber(w):  # pragma: no cover - compiled
    a = abs(w)
    return 1.0 if a <= HUBER_K else HUBER_K / np.sqrt(2.0 * HUBER_K * a - HUBER_K * HUBER_K)


@numba.njit(cache=True)
def _residual(Xs, add, W, y3, c, s, x, z, r):  # pragma: no cover - compiled
    """``r = huber(W z(x))`` into ``r``; returns ``Q = r . r``."""
    n = Xs.shape[0]
    _scores(Xs, add, y3, c, s, x, z, z[:0])
    q = 0.0
    for i in range(n):
        w = 0.0
        for j in range(n):
            w += W[i, j] * z[j]
        r[i] = _huber(w)
        q += r[i] * r[i]
    return q


@numba.njit(cache=True)
def _solve(H, b, nf, out):  # pragma: no cover - compiled
    """``out[:nf] = H[:nf, :nf]^-1 b[:nf]``: Gaussian elimination with partial pivoting (H is overwritten)."""
    for col in range(nf):
        piv = col
        for row in range(col + 1, nf):
            if abs(H[row, col]) > abs(H[piv, col]):
                piv = row
        if piv != col:
            for k in range(nf):
                H[col, k], H[piv, k] = H[piv, k], H[col, k]
            b[col], b[piv] = b[piv], b[col]
        for row in range(col + 1, nf):
            f = H[row, col] / H[col, col]
            for k in range(col, nf):
                H[row, k] -= f * H[col, k]
            b[row] -= f * b[col]
    for row in range(nf - 1, -1, -1):
        acc = b[row]
        for k in range(row + 1, nf):
            acc -= H[row, k] * out[k]
        out[row] = acc / H[row, row]


@numba.njit(cache=True)
def pgn(Xs, add, W, y3, c, s, u0, ub, max_iter, tol):  # pragma: no cover - compiled
    """Minimise ``Q(x) = ||huber(W z(x))||^2`` over ``0 <= x <= ub``: projected Gauss-Newton steps on the free set
    (the coordinates not held at a bound by the gradient), halving the step until ``Q`` falls.  Returns ``(x, Q)``."""
    n, p = Xs.shape
    x = np.empty(p)
    for k in range(p):
        x[k] = min(max(u0[k], 0.0), ub[k])
    z, r, rn, dz, e = np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    J = np.empty((n, p))
    g, xn, step, rhs, sol = np.empty(p), np.empty(p), np.empty(p), np.empty(p), np.empty(p)
    H = np.empty((p, p))
    free = np.empty(p, dtype=np.int64)
    q = _residual(Xs, add, W, y3, c, s, x, z, r)
    for _ in range(max_iter):
        # Jacobian of r: J = diag(huber'(W z)) W diag(dz/dmu) Xs
        _scores(Xs, add, y3, c, s, x, z, dz)
        for i in range(n):
            w = 0.0
            for j in range(n):
                w += W[i, j] * z[j]
            e[i] = _dhuber(w)
        for i in range(n):
            for k in range(p):
                acc = 0.0
                for j in range(n):
                    acc += W[i, j] * (Xs[j, k] * dz[j])
                J[i, k] = acc * e[i]
        nf = 0
        for k in range(p):
            gk = 0.0
            for i in range(n):
                gk += J[i, k] * r[i]
            g[k] = gk
            if not ((x[k] <= 0.0 and gk > 0.0) or (x[k] >= ub[k] and gk < 0.0)):
                free[nf] = k
                nf += 1
        if nf == 0:
            break
        for a in range(nf):  # normal equations on the free set, the diagonal nudged off singularity
            for b in range(a, nf):
                acc = 0.0
                for i in range(n):
                    acc += J[i, free[a]] * J[i, free[b]]
                H[a, b] = acc
                H[b, a] = acc
            H[a, a] = H[a, a] * (1.0 + 1e-12) + 1e-300
            rhs[a] = -g[free[a]]
        _solve(H, rhs, nf, sol)
        for k in range(p):
            step[k] = 0.0
        for a in range(nf):
            step[free[a]] = sol[a]
        t = 1.0
        improved = False
        qn = q
        for _ls in range(40):
            for k in range(p):
                xn[k] = min(max(x[k] + t * step[k], 0.0), ub[k])
            qn = _residual(Xs, add, W, y3, c, s, xn, z, rn)
            if qn < q - 1e-13 * max(1.0, q):
                improved = True
                break
            t *= 0.5
        if not improved:
            break
        dq = q - qn
        x[:] = xn
        r[:] = rn
        q = qn
        if dq <= tol * max(1.0, q):
            break
    return x, q


@numba.njit(cache=True)
def _lstsq(A, b, cols, k, out):  # pragma: no cover - compiled
    """``out[:k]``: least squares of ``b`` on the columns ``cols[:k]`` of ``A`` (Householder QR; a column that adds
    nothing beyond the previous ones, ``|R_jj| <= 1e-12 max|R|``, gets 0)."""
    m = A.shape[0]
    R = np.empty((m, k))
    for i in range(m):
        for j in range(k):
            R[i, j] = A[i, cols[j]]
    rhs = b.copy()
    v = np.empty(m)
    for j in range(k):
        norm = 0.0
        for i in range(j, m):
            norm += R[i, j] * R[i, j]
        norm = np.sqrt(norm)
        if norm == 0.0:
            continue
        alpha = -norm if R[j, j] >= 0.0 else norm
        vv = 0.0
        for i in range(j, m):
            v[i] = R[i, j]
        v[j] -= alpha
        for i in range(j, m):
            vv += v[i] * v[i]
        if vv == 0.0:
            continue
        for col in range(j, k):
            dot = 0.0
            for i in range(j, m):
                dot += v[i] * R[i, col]
            f = 2.0 * dot / vv
            for i in range(j, m):
                R[i, col] -= f * v[i]
        dot = 0.0
        for i in range(j, m):
            dot += v[i] * rhs[i]
        f = 2.0 * dot / vv
        for i in range(j, m):
            rhs[i] -= f * v[i]
    big = 0.0
    for j in range(k):
        big = max(big, abs(R[j, j]))
    for j in range(k - 1, -1, -1):
        if abs(R[j, j]) <= 1e-12 * big or big == 0.0:
            out[j] = 0.0
            continue
        acc = rhs[j]
        for col in range(j + 1, k):
            acc -= R[j, col] * out[col]
        out[j] = acc / R[j, j]


@numba.njit(cache=True)
def nnls(A, b, max_iter):  # pragma: no cover - compiled
    """``argmin ||A x - b||`` over ``x >= 0``: the active-set method of Lawson and Hanson (*Solving Least Squares
    Problems*, 1974, ch. 23, algorithm NNLS), the algorithm of ``scipy.optimize.nnls``, for a few columns.

    After ``max_iter`` inner steps the current feasible point is returned (the callers want a start point).
    """
    m, n = A.shape
    x = np.zeros(n)
    passive = np.zeros(n, dtype=np.bool_)
    skip = np.zeros(n, dtype=np.bool_)  # entered with a non-positive LS coefficient (rounding): not again this pass
    cols = np.empty(n, dtype=np.int64)
    z = np.empty(n)
    w = np.empty(n)
    res = np.empty(m)
    anorm = 0.0
    for i in range(m):
        for j in range(n):
            anorm = max(anorm, abs(A[i, j]))
    tol = 10.0 * 2.220446049250313e-16 * anorm * max(m, n)
    it = 0
    while it < max_iter:
        for i in range(m):
            acc = b[i]
            for j in range(n):
                acc -= A[i, j] * x[j]
            res[i] = acc
        t = -1
        best = tol
        for j in range(n):
            acc = 0.0
            for i in range(m):
                acc += A[i, j] * res[i]
            w[j] = acc
            if not passive[j] and not skip[j] and acc > best:
                best = acc
                t = j
        if t < 0:
            break
        passive[t] = True
        while it < max_iter:
            it += 1
            k = 0
            for j in range(n):
                if passive[j]:
                    cols[k] = j
                    k += 1
            _lstsq(A, b, cols, k, z)
            ok = True
            for a in range(k):
                if z[a] <= 0.0:
                    ok = False
            if ok:
                for j in range(n):
                    x[j] = 0.0
                for a in range(k):
                    x[cols[a]] = z[a]
                for j in range(n):
                    skip[j] = False
                break
            if x[t] == 0.0 and k > 0:
                # the column just entered cannot enter (its coefficient is not positive): leave it out this pass
                zt = 0.0
                for a in range(k):
                    if cols[a] == t:
                        zt = z[a]
                if zt <= 0.0:
                    passive[t] = False
                    skip[t] = True
                    break
            # step from x towards z until the first passive coefficient reaches zero; it leaves the passive set
            alpha = 1.0
            jmin = -1
            for a in range(k):
                j = cols[a]
                if z[a] <= 0.0:
                    d = x[j] - z[a]
                    ratio = x[j] / d if d > 0.0 else 0.0
                    if jmin < 0 or ratio < alpha:
                        alpha = ratio
                        jmin = j
            for a in range(k):
                j = cols[a]
                x[j] += alpha * (z[a] - x[j])
            if jmin >= 0:
                x[jmin] = 0.0
            for a in range(k):
                j = cols[a]
                if x[j] <= 0.0:
                    x[j] = 0.0
                    passive[j] = False
    return x


@numba.njit(cache=True)
def fit_columns(X, free, per_column, per_point, add, W, a0, max_iter, tol, out):  # pragma: no cover
    """One fit of :meth:`~fogdrift.noise.engine.ScoreProblem.fit` on the design columns ``free``.

    ``per_column`` holds the rows ``scale, upper`` of every design column, ``per_point`` the rows ``y, y^(1/3),
    c, s`` of every working point (packed: each argument costs the call its type check).  The columns are scaled
    by ``scale[free]``; the start is ``a0`` (unscaled coefficients) or, if ``a0`` is empty, the NNLS fit of the
    relative errors ``(y - add) / y``, moved inside ``[1e-6, ub (1 - 1e-9)]``; then :func:`pgn`.  Writes the
    coefficients of ``free`` (unscaled) into ``out`` and returns ``Q`` (an array made here would be boxed for
    Python at ~1.4 us a call)."""
    scale_all, upper_all = per_column[0], per_column[1]
    y, y3, c, s = per_point[0], per_point[1], per_point[2], per_point[3]
    n = X.shape[0]
    p = free.size
    Xs = np.empty((n, p))
    ub = np.empty(p)
    for k in range(p):
        sc = scale_all[free[k]]
        ub[k] = upper_all[free[k]] / sc
        for i in range(n):
            Xs[i, k] = X[i, free[k]] * sc
    if a0.size:
        u0 = np.empty(p)
        for k in range(p):
            u0[k] = a0[k] / scale_all[free[k]]
    else:
        Xw = np.empty((n, p))
        bw = np.empty(n)
        for i in range(n):
            wt = 1.0 / y[i]
            bw[i] = max(y[i] - add[i], 0.0) * wt
            for k in range(p):
                Xw[i, k] = Xs[i, k] * wt
        u0 = nnls(Xw, bw, 3 * p)
    for k in range(p):
        u0[k] = min(max(u0[k], 1e-6), ub[k] * (1 - 1e-9))
    u, q = pgn(Xs, add, W, y3, c, s, u0, ub, max_iter, tol)
    for k in range(p):
        out[k] = u[k] * scale_all[free[k]]
    return q
