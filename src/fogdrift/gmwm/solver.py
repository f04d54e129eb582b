"""Compiled trust-region-reflective least squares for the small GMWM problems (at most a dozen parameters).

:meth:`fogdrift.gmwm.estimator._Problem.solve` minimises ``||W (nu_hat - nu(exp z))||^2`` over box bounds on ``z``
some 500 times per ``fogdrift noise`` of a 3-axis log, each run a few dozen iterations on ~18 scales and <= 6
parameters.  ``scipy.optimize.least_squares`` (method ``"trf"``, ``x_scale="jac"``, exact trust-region solver)
spends almost all of such a run in per-call Python overhead (small NumPy calls, argument checks, the function
wrappers), not in arithmetic.  :func:`trf_solve` runs the same algorithm, step for step, in one compiled call with
the model's WV kernel (:func:`fogdrift.gmwm.processes._wv_kernel`) inside:

* the iteration of SciPy's ``trf_bounds`` (Coleman-Li scaling, the Jacobian scaling ``x_scale="jac"`` with its
  running maximum, the SVD-based More trust-region solution with the same root-finding of the Levenberg-Marquardt
  parameter, the reflective / projected / gradient step choice of ``select_step``, the strictly feasible update,
  the radius update and the termination tests on ``ftol``, ``xtol``, ``gtol``, the evaluation budget);
* the same reductions as NumPy's where the order is visible: BLAS ``ddot`` / ``dgemv`` (``np.dot``) for the dot
  products and matrix-vector products, LAPACK ``gesdd`` for the SVD, row-sequential column sums of squares.

The results are not equal bit for bit: NumPy's vectorised ``exp`` and ``expm1`` (the parameters ``exp z`` and the GM
terms of the WV) differ from libm's in the last bit for a few per cent of arguments, and an iteration amplifies that
like any rounding.  The optima agree to the optimiser's tolerance (tested against ``least_squares``).

Whatever the compiled run cannot decide the way SciPy would (a non-finite residual at the start, a non-finite scaled
Jacobian, a degenerate trust-region intersection, where SciPy raises) it reports as not done
(``status == FALLBACK``); the caller then runs ``least_squares`` itself, which decides as before.

Compilation: numba compiles the solver on its first use (about half a minute on a busy 2-core machine) and caches
it beside this file; later processes load it in a fraction of a second.  The cache holds the WV kernel as it was
when the solver was compiled (numba does not follow a callee into another module): after editing the kernel in
:mod:`fogdrift.gmwm.processes`, touch this file so that the solver is compiled again
(``tests/gmwm/test_gmwm_solver.py``, which compares with ``least_squares`` on the live kernel, fails on a stale copy).
"""

from __future__ import annotations

import math

import numpy as np

from .processes import _EXP_H, _EXP_MH, _wv_kernel

__all__ = ["trf_solve", "FALLBACK"]

#: ``status`` of a run the compiled solver hands back undecided (the caller runs ``least_squares``).
FALLBACK = -100
_NONE = -99  # termination status not set yet (SciPy's None)
_EPS = float(np.finfo(float).eps)


# ----------------------------------------------------------------------------------------
# Model, residuals and Jacobian (as _Problem._fun / _jac)
# ----------------------------------------------------------------------------------------
def _model_py(codes, starts, z, t, half, flick, gm_beta, dr, theta, vv, comps, total, jac, want_jac):
    """``theta = exp(z)`` and the kernel's WV (``total``) or Jacobian (``jac``), as :class:`WvEvaluator`."""
    for i in range(z.shape[0]):
        theta[i] = math.exp(z[i])
    n = t.shape[0]
    for g in range(gm_beta.shape[0]):
        b = theta[gm_beta[g]]
        if want_jac:
            b3 = (b * 1.0, b * _EXP_H, b * _EXP_MH)
            for r in range(3):
                for k in range(n):
                    vv[3 * g + r, k] = -math.expm1(-(b3[r] * half[k]))
        else:
            for k in range(n):
                vv[g, k] = -math.expm1(-(b * half[k]))
    dr_p2 = theta[dr] * theta[dr] if dr >= 0 else 0.0
    _kernel(codes, starts, theta, t, flick, vv, dr_p2, comps, total, jac, want_jac)


def _resid_py(nu_hat, total, w, cinv, f):
    """``f = W (nu_hat - nu)``, or 1e10 everywhere when the WV is not finite."""
    m = nu_hat.shape[0]
    for k in range(m):
        if not math.isfinite(total[k]):
            for i in range(m):
                f[i] = 1e10
            return
    if cinv.shape[0] == 0:
        for k in range(m):
            f[k] = w[k] * (nu_hat[k] - total[k])
    else:
        d = np.empty(m)
        for k in range(m):
            d[k] = nu_hat[k] - total[k]
        for i in range(m):
            s = 0.0
            for j in range(m):
                s += cinv[i, j] * d[j]
            f[i] = s


def _jacw_py(a, w, cinv, out):
    """``out = -W a`` with non-finite entries of ``a`` set to 0."""
    m, n = a.shape
    for i in range(m):
        for k in range(n):
            if not math.isfinite(a[i, k]):
                a[i, k] = 0.0
    if cinv.shape[0] == 0:
        for i in range(m):
            for k in range(n):
                out[i, k] = -(w[i] * a[i, k])
    else:
        for i in range(m):
            for k in range(n):
                s = 0.0
                for j in range(m):
                    s += cinv[i, j] * a[j, k]
                out[i, k] = -s


# ----------------------------------------------------------------------------------------
# The pieces of SciPy's trf_bounds (scipy/optimize/_lsq/common.py, trf.py)
# ----------------------------------------------------------------------------------------
def _norm_py(x):
    return math.sqrt(np.dot(x, x))


def _mvt_py(a, b):
    """``a.T.dot(b)`` of a C-ordered ``a`` as NumPy computes it (``ddot`` for one column, else ``dgemv``)."""
    if a.shape[1] == 1:
        return np.array([np.dot(np.ascontiguousarray(a[:, 0]), b)])
    return np.dot(b, a)


def _col_sumsq_py(a):
    """``np.sum(a**2, axis=0)`` in NumPy's order (rows accumulated in turn; one column: pairwise)."""
    m, n = a.shape
    out = np.empty(n)
    if n == 1:
        c = np.empty(m)
        for i in range(m):
            c[i] = a[i, 0] * a[i, 0]
        out[0] = _pairwise(c)
        return out
    for k in range(n):
        out[k] = a[0, k] * a[0, k]
    for i in range(1, m):
        for k in range(n):
            out[k] = out[k] + a[i, k] * a[i, k]
    return out


def _pairwise_py(a):
    """NumPy's pairwise sum of a short contiguous vector (blocks of 8 accumulators up to 128 terms)."""
    n = a.shape[0]
    if n < 8:
        res = 0.0
        for i in range(n):
            res += a[i]
        return res
    r = np.empty(8)
    for j in range(8):
        r[j] = a[j]
    i = 8
    while i < n - n % 8:
        for j in range(8):
            r[j] += a[i + j]
        i += 8
    res = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]))
    while i < n:
        res += a[i]
        i += 1
    return res


def _sum_py(a):
    """``np.sum`` of a short 1-D array (sequential below 8 terms, as NumPy)."""
    return _pairwise(a)


def _pmax_py(a, b):
    """``np.maximum`` of two floats (NaN propagates)."""
    if a != a or b != b:
        return math.nan
    return a if a >= b else b


def _step_size_to_bound_py(x, s, lb, ub, hits):
    """Step to the first bound along ``s`` and which bounds it hits (``hits``: -1, 0, 1)."""
    n = x.shape[0]
    steps = np.full(n, np.inf)
    for i in range(n):
        if s[i] != 0.0:
            steps[i] = _pmax((lb[i] - x[i]) / s[i], (ub[i] - x[i]) / s[i])
    mn = steps[0]
    for i in range(1, n):
        if mn != mn:
            break
        if steps[i] != steps[i] or steps[i] < mn:
            mn = steps[i]
    for i in range(n):
        sg = 0 if s[i] == 0.0 else (1 if s[i] > 0.0 else -1)
        hits[i] = sg if steps[i] == mn else 0
    return mn


def _in_bounds_py(x, lb, ub):
    for i in range(x.shape[0]):
        if not (x[i] >= lb[i] and x[i] <= ub[i]):
            return False
    return True


def _make_strictly_feasible_py(x, lb, ub, rstep):
    """SciPy's ``make_strictly_feasible`` (``rstep == 0``: the next float inside)."""
    n = x.shape[0]
    out = x.copy()
    for i in range(n):
        ld = x[i] - lb[i]
        ud = ub[i] - x[i]
        if rstep == 0.0:
            lower = x[i] <= lb[i]
            upper = x[i] >= ub[i]
        else:
            lower = math.isfinite(lb[i]) and ld <= min(ud, rstep * max(1.0, abs(lb[i])))
            upper = math.isfinite(ub[i]) and ud <= min(ld, rstep * max(1.0, abs(ub[i])))
        if upper:
            out[i] = np.nextafter(ub[i], lb[i]) if rstep == 0.0 else ub[i] - rstep * max(1.0, abs(ub[i]))
        elif lower:
            out[i] = np.nextafter(lb[i], ub[i]) if rstep == 0.0 else lb[i] + rstep * max(1.0, abs(lb[i]))
        if out[i] < lb[i] or out[i] > ub[i]:
            out[i] = 0.5 * (lb[i] + ub[i])
    return out


def _cl_scaling_py(x, g, lb, ub, v, dv):
    """Coleman-Li scaling vector ``v`` and its derivative ``dv``."""
    for i in range(x.shape[0]):
        v[i] = 1.0
        dv[i] = 0.0
        if g[i] < 0 and math.isfinite(ub[i]):
            v[i] = ub[i] - x[i]
            dv[i] = -1.0
        if g[i] > 0 and math.isfinite(lb[i]):
            v[i] = x[i] - lb[i]
            dv[i] = 1.0


def _evaluate_quadratic_py(jh, g, s, diag):
    js = np.dot(jh, s)
    q = np.dot(js, js) + np.dot(s * diag, s)
    return 0.5 * q + np.dot(s, g)


def _minimize_quadratic_1d_py(a, b, lo, hi, c):
    """Minimum of ``a t^2 + b t + c`` on ``[lo, hi]``: (t, value), first minimum as ``np.argmin``."""
    ts = np.empty(3)
    ts[0] = lo
    ts[1] = hi
    k = 2
    if a != 0:
        ext = -0.5 * b / a
        if lo < ext < hi:
            ts[2] = ext
            k = 3
    best_t = ts[0]
    best_y = ts[0] * (a * ts[0] + b) + c
    if best_y != best_y:
        return best_t, best_y
    for i in range(1, k):
        y = ts[i] * (a * ts[i] + b) + c
        if y != y or y < best_y:
            best_t, best_y = ts[i], y
            if y != y:
                break
    return best_t, best_y


def _solve_tr_py(n, m, uf, s, V, delta, initial_alpha):
    """SciPy's ``solve_lsq_trust_region`` (rtol 0.01, 10 iterations): (p, alpha)."""
    suf = s * uf
    full_rank = s[n - 1] > _EPS * m * s[0] if m >= n else False
    if full_rank:
        p = -np.dot(V, uf / s)
        if _norm(p) <= delta:
            return p, 0.0
    alpha_upper = _norm(suf) / delta
    if full_rank:
        phi, phi_prime = _phi(0.0, suf, s, delta)
        alpha_lower = -phi / phi_prime
    else:
        alpha_lower = 0.0
    if not full_rank and initial_alpha == 0:
        alpha = _pymax(0.001 * alpha_upper, math.sqrt(alpha_lower * alpha_upper))
    else:
        alpha = initial_alpha
    for _ in range(10):
        if alpha < alpha_lower or alpha > alpha_upper:
            alpha = _pymax(0.001 * alpha_upper, math.sqrt(alpha_lower * alpha_upper))
        phi, phi_prime = _phi(alpha, suf, s, delta)
        if phi < 0:
            alpha_upper = alpha
        ratio = phi / phi_prime
        alpha_lower = _pymax(alpha_lower, alpha - ratio)
        alpha -= (phi + delta) * ratio / delta
        if abs(phi) < 0.01 * delta:
            break
    p = -np.dot(V, suf / (s * s + alpha))
    p *= delta / _norm(p)
    return p, alpha


def _pymax_py(a, b):
    """Python's ``max(a, b)`` (``a`` unless ``b > a``)."""
    return b if b > a else a


def _phi_py(alpha, suf, s, delta):
    denom = s * s + alpha
    p_norm = _norm(suf / denom)
    d3 = np.empty(denom.shape[0])
    for i in range(denom.shape[0]):
        d3[i] = suf[i] * suf[i] / math.pow(denom[i], 3.0)
    return p_norm - delta, -_sum(d3) / p_norm


def _select_step_py(x, jh, diag_h, g_h, p, p_h, d, delta, lb, ub, theta, hits):
    """SciPy's ``select_step``: (step, step_h, predicted reduction, ok); ``ok`` False where SciPy raises."""
    if _in_bounds(x + p, lb, ub):
        return p, p_h, -_evaluate_quadratic(jh, g_h, p_h, diag_h), True
    p_stride = _step_size_to_bound(x, p, lb, ub, hits)
    r_h = p_h.copy()
    for i in range(r_h.shape[0]):
        if hits[i] != 0:
            r_h[i] *= -1
    r = d * r_h
    p = p * p_stride
    p_h = p_h * p_stride
    x_on_bound = x + p
    # intersect_trust_region(p_h, r_h, delta): the positive root
    a = np.dot(r_h, r_h)
    if a == 0:
        return p, p_h, 0.0, False
    b = np.dot(p_h, r_h)
    c = np.dot(p_h, p_h) - delta ** 2
    if c > 0:
        return p, p_h, 0.0, False
    dd = math.sqrt(b * b - a * c)
    q = -(b + math.copysign(dd, b))
    t1 = q / a
    t2 = c / q
    to_tr = t2 if t1 < t2 else t1
    to_bound = _step_size_to_bound(x_on_bound, r, lb, ub, hits)
    r_stride = to_tr if to_tr < to_bound else to_bound
    if r_stride > 0:
        r_stride_l = (1 - theta) * p_stride / r_stride
        r_stride_u = theta * to_bound if r_stride == to_bound else to_tr
    else:
        r_stride_l = 0.0
        r_stride_u = -1.0
    if r_stride_l <= r_stride_u:
        # build_quadratic_1d(J_h, g_h, r_h, s0=p_h, diag=diag_h)
        v = np.dot(jh, r_h)
        qa = np.dot(v, v)
        qa += np.dot(r_h * diag_h, r_h)
        qa *= 0.5
        qb = np.dot(g_h, r_h)
        u = np.dot(jh, p_h)
        qb += np.dot(u, v)
        qc = 0.5 * np.dot(u, u) + np.dot(g_h, p_h)
        qb += np.dot(p_h * diag_h, r_h)
        qc += 0.5 * np.dot(p_h * diag_h, p_h)
        r_stride, r_value = _minimize_quadratic_1d(qa, qb, r_stride_l, r_stride_u, qc)
        r_h = r_h * r_stride
        r_h += p_h
        r = r_h * d
    else:
        r_value = np.inf
    p = p * theta
    p_h = p_h * theta
    p_value = _evaluate_quadratic(jh, g_h, p_h, diag_h)
    ag_h = -g_h
    ag = d * ag_h
    to_tr = delta / _norm(ag_h)
    to_bound = _step_size_to_bound(x, ag, lb, ub, hits)
    ag_stride = theta * to_bound if to_bound < to_tr else to_tr
    # build_quadratic_1d(J_h, g_h, ag_h, diag=diag_h)
    v = np.dot(jh, ag_h)
    qa = np.dot(v, v)
    qa += np.dot(ag_h * diag_h, ag_h)
    qa *= 0.5
    qb = np.dot(g_h, ag_h)
    ag_stride, ag_value = _minimize_quadratic_1d(qa, qb, 0.0, ag_stride, 0.0)
    ag_h = ag_h * ag_stride
    ag = ag * ag_stride
    if p_value < r_value and p_value < ag_value:
        return p, p_h, -p_value, True
    if r_value < p_value and r_value < ag_value:
        return r, r_h, -r_value, True
    return ag, ag_h, -ag_value, True


# ----------------------------------------------------------------------------------------
# The solver
# ----------------------------------------------------------------------------------------
def _trf_py(codes, starts, t, half, flick, gm_beta, dr, n_comp, w, cinv, nu_hat, lb, ub, x0, max_nfev, ftol, xtol,
            gtol):
    """SciPy's ``least_squares(method="trf", x_scale="jac")`` on the GMWM residuals: (x, cost, status, nfev)."""
    m = t.shape[0]
    n = x0.shape[0]
    theta = np.empty(n)
    vv = np.empty((3 * gm_beta.shape[0], m))
    comps = np.empty((n_comp, m))
    total = np.empty(m)
    a = np.empty((m, n))
    none = np.empty((0, 0))

    def fun(z, f):
        _model(codes, starts, z, t, half, flick, gm_beta, dr, theta, vv, comps, total, none, False)
        _resid(nu_hat, total, w, cinv, f)

    def jacobian(z, out):
        _model(codes, starts, z, t, half, flick, gm_beta, dr, theta, vv, comps, total, a, True)
        _jacw(a, w, cinv, out)

    x = _make_strictly_feasible(x0, lb, ub, 1e-10)
    f = np.empty(m)
    fun(x, f)
    for k in range(m):
        if not math.isfinite(f[k]):
            return x, 0.0, FALLBACK, 1
    J = np.empty((m, n))
    jacobian(x, J)
    nfev = 1
    cost = 0.5 * np.dot(f, f)
    g = _mvt(J, f)
    scale_inv = np.sqrt(_col_sumsq(J))
    for i in range(n):
        if scale_inv[i] == 0:
            scale_inv[i] = 1.0
    scale = 1 / scale_inv
    v = np.empty(n)
    dv = np.empty(n)
    _cl_scaling(x, g, lb, ub, v, dv)
    for i in range(n):
        if dv[i] != 0:
            v[i] *= scale_inv[i]
    delta = _norm(x * scale_inv / np.sqrt(v))
    if delta == 0:
        delta = 1.0
    j_aug = np.zeros((m + n, n))
    f_aug = np.zeros(m + n)
    hits = np.empty(n, dtype=np.int64)
    f_new = np.empty(m)
    x_new = x
    cost_new = cost
    alpha = 0.0
    status = _NONE
    while True:
        _cl_scaling(x, g, lb, ub, v, dv)
        g_norm = 0.0
        for i in range(n):
            gv = abs(g[i] * v[i])
            if gv != gv or g_norm != g_norm:
                g_norm = math.nan
            elif gv > g_norm:
                g_norm = gv
        if g_norm < gtol:
            status = 1
        if status != _NONE or nfev == max_nfev:
            break
        for i in range(n):
            if dv[i] != 0:
                v[i] *= scale_inv[i]
        d = np.sqrt(v) * scale
        diag_h = g * dv * scale
        g_h = d * g
        f_aug[:m] = f
        for i in range(m):
            for k in range(n):
                j_aug[i, k] = J[i, k] * d[k]
        for i in range(n):
            for k in range(n):
                j_aug[m + i, k] = math.sqrt(diag_h[i]) if i == k else 0.0
        for i in range(m + n):
            for k in range(n):
                if not math.isfinite(j_aug[i, k]):
                    return x, cost, FALLBACK, nfev  # SciPy's SVD refuses a non-finite matrix
        jh = j_aug[:m]
        U, s, VT = np.linalg.svd(j_aug, full_matrices=False)
        V = VT.T
        if n == 1:
            uf = np.array([np.dot(np.ascontiguousarray(U[:, 0]), f_aug)])
        else:
            uf = np.dot(U.T, f_aug)
        th = 1 - g_norm
        theta_step = th if th > 0.995 else 0.995
        actual_reduction = -1.0
        while actual_reduction <= 0 and nfev < max_nfev:
            p_h, alpha = _solve_tr(n, m, uf, s, V, delta, alpha)
            p = d * p_h
            step, step_h, predicted_reduction, ok = _select_step(x, jh, diag_h, g_h, p, p_h, d, delta, lb, ub,
                                                                 theta_step, hits)
            if not ok:
                return x, cost, FALLBACK, nfev
            x_new = _make_strictly_feasible(x + step, lb, ub, 0.0)
            fun(x_new, f_new)
            nfev += 1
            step_h_norm = _norm(step_h)
            finite = True
            for k in range(m):
                if not math.isfinite(f_new[k]):
                    finite = False
            if not finite:
                delta = 0.25 * step_h_norm
                continue
            cost_new = 0.5 * np.dot(f_new, f_new)
            actual_reduction = cost - cost_new
            # update_tr_radius
            if predicted_reduction > 0:
                ratio = actual_reduction / predicted_reduction
            elif predicted_reduction == actual_reduction == 0:
                ratio = 1.0
            else:
                ratio = 0.0
            delta_new = delta
            if ratio < 0.25:
                delta_new = 0.25 * step_h_norm
            elif ratio > 0.75 and step_h_norm > 0.95 * delta:
                delta_new *= 2.0
            # check_termination
            ftol_ok = actual_reduction < ftol * cost and ratio > 0.25
            xtol_ok = _norm(step) < xtol * (xtol + _norm(x))
            if ftol_ok and xtol_ok:
                status = 4
            elif ftol_ok:
                status = 2
            elif xtol_ok:
                status = 3
            if status != _NONE:
                break
            alpha *= delta / delta_new
            delta = delta_new
        if actual_reduction > 0:
            x = x_new
            f[:] = f_new
            cost = cost_new
            jacobian(x, J)
            g = _mvt(J, f)
            scale_inv = np.maximum(np.sqrt(_col_sumsq(J)), scale_inv)
            scale = 1 / scale_inv
    if status == _NONE:
        status = 0
    return x, cost, status, nfev


# ----------------------------------------------------------------------------------------
# Compilation and the entry point
# ----------------------------------------------------------------------------------------
_HELPERS = ("pmax", "pymax", "model", "resid", "jacw", "norm", "mvt", "col_sumsq", "pairwise", "sum", "step_size_to_bound",
            "in_bounds", "make_strictly_feasible", "cl_scaling", "evaluate_quadratic", "minimize_quadratic_1d",
            "solve_tr", "phi", "select_step")
_SOLVER = []


def _compiled():
    """The compiled solver (numba, cached on disk), compiled on first use."""
    if not _SOLVER:
        import numba

        g = globals()
        g["_kernel"] = _wv_kernel()
        jit = numba.njit(cache=True, error_model="numpy")
        for name in _HELPERS:  # callees first: numba resolves a global dispatcher when it compiles its caller
            g["_" + name] = jit(g[f"_{name}_py"])
        _SOLVER.append(jit(_trf_py))
    return _SOLVER[0]


def trf_solve(ev, w, cinv, nu_hat, lb, ub, x0, max_nfev, ftol=1e-12, xtol=1e-12, gtol=1e-12):
    """Minimise ``||W (nu_hat - ev.wv(exp z))||^2`` over ``lb <= z <= ub`` as ``least_squares`` (trf, x_scale jac).

    Parameters
    ----------
    ev : fogdrift.gmwm.processes.WvEvaluator
        The model at the fitted scales (a model of built-in processes only).
    w : ndarray (J,)
        Diagonal whitening ``sqrt(Omega)``; an empty array when ``cinv`` is given.
    cinv : ndarray (J, J)
        Whitening matrix ``C^-1`` (``V = C C^T``); an empty ``(0, 0)`` array for diagonal weights.
    nu_hat : ndarray (J,)
        Observed WV.
    lb, ub : ndarray (p,)
        Bounds of the free parameters ``z = log theta``.
    x0 : ndarray (p,)
        Start, within the bounds.
    max_nfev : int
        Budget of residual evaluations.
    ftol, xtol, gtol : float
        ``least_squares``' tolerances.

    Returns
    -------
    x : ndarray (p,)
    cost : float
        ``0.5 ||r||^2`` at ``x``.
    status : int
        ``least_squares``' status (> 0 converged, 0 budget spent), or :data:`FALLBACK` (run ``least_squares``).
    nfev : int
        Residual evaluations made.
    """
    codes, starts, t, half, flick, gm_beta, dr, n_comp = ev.kernel_args()
    return _compiled()(codes, starts, t, half, flick, gm_beta, dr, n_comp, w, cinv, nu_hat, lb, ub,
                       np.ascontiguousarray(x0, dtype=np.float64), int(max_nfev), float(ftol), float(xtol),
                       float(gtol))
