"""Compiled kernels of :mod:`fogdrift.noise.engine` (numba, imported on first use).

Module-level functions, so that numba's on-disk cache is reused by every new process: as closures inside a
factory they referred to each other as free variables, could not be cached, and every ``fogdrift`` run (and
every Dask worker of ``fogdrift batch``) compiled them again (~5 s).
"""

import numba
import numpy as np

from .huber import HUBER_K

__all__ = ["pgn"]


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
        zz = np.empty(n)
        for i in range(n):  # the model value and its cube root once for both (the same numbers as two passes)
            mu = add[i]
            for k in range(p):
                mu += Xs[i, k] * x[k]
            if mu < 1e-300:
                mu = 1e-300
            ratio = y3[i] / np.cbrt(mu)
            d[i] = -ratio / (3.0 * mu * s[i])
            zz[i] = (ratio - c[i]) / s[i]
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
