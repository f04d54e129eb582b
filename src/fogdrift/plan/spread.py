"""Record-to-record spread of a term's Allan-fit width: the fit's own rules on the linearised record.

The width the median record reaches is :func:`fogdrift.plan.analytic.analytic_widths`'s.  How much wider a record
may come out (the length for four records in five, ``share_s``) depends on what varies from record to record:
the estimate the width is relative to, the selected model (its degrees of freedom), its ``max(1, chi2_red)``
widening, and which models are plausible and so enter the union.  All four are taken here from the fit's rules
applied to Gaussian records of the linearised problem: in the fit's whitened metric (``V``: the estimators'
covariance plus the 2 % allowance, :func:`~fogdrift.plan.analytic.whitened`) a record's curve is the expected
one plus ``e ~ N(0, S)``, ``S = L^-1 V_s L^-T`` with ``V_s`` the sampling covariance alone, summed over the record's
finite number of Allan terms (:func:`~fogdrift.noise.covariance.finite_record_covariance`; a record that follows
the model departs from it by its sampling error, not by the allowance: its ``chi2_red`` averages about 0.5).
Per record: every subset of the planned terms is fitted by non-negative least squares, then the fit's Markov
stage (every subset plus a first-order Gauss-Markov term at the fit's grid of correlation times, kept only when it
beats the best model without it by the fit's IC gain; :func:`_record_fit`), the model of least IC
(``Q + 2 k``) is selected, the plausible models are those within the window (6), the threshold is
``t_{0.975, dof}^2 max(1, chi2_red)`` with the selected model's ``dof``, and the term's interval is the union of
its profile intervals (``A >= 0``) over the plausible models that hold it (any without it: not resolved).  The
ratio of the ``p``-quantile of the widths to their median is the spread (:func:`share_ratio`).

:func:`fit_rule_widths` checks the linearisation: the fit itself (:func:`fogdrift.noise.identify.identify`, every
rule of ``fogdrift allan`` but the automatic fit range and the Markov candidates) on Allan curves drawn from the
same sampling covariance (Wilson-Hilferty: ``cbrt(y / mu)`` Gaussian with the estimators' EDF and correlation).
It costs about 0.1 s per record, so the plan does not use it (docs/plan.md, "80 % of records").
"""

from __future__ import annotations

import itertools
import math

import numpy as np
from scipy.optimize import brentq, nnls
from scipy.stats import chi2
from scipy.stats import t as student_t

from ..allan.grid import tau_grid
from ..noise.context import FitContext
from ..noise.identify import MARKOV_IC_GAIN, MARKOV_TC_GRID, identify
from ..noise.terms import all_terms, markov_shape
from .analytic import IC_PENALTY, PLAUSIBLE_DELTA, whitened
from .model import PLANNED_TERMS as PLANNED

__all__ = ["share_ratio", "fit_rule_widths", "model_curves", "SPREAD_DRAWS"]

#: Gaussian records drawn per length (fixed seed): the 80 % / median ratio to about +-1 % (400 draws: +-2 %, i.e.
#: +-7 % in the 80 % length of a B, whose width falls as about n^-0.3; docs/plan.md "80 % of records").
SPREAD_DRAWS = 1600

_M = all_terms().index("M")  # the Gauss-Markov column of the whitened design


def _fit_m(model, n: int) -> np.ndarray:
    """The averaging factors the fit uses on ``n`` samples: the octave grid from the model's ``tau_min_s`` (a pilot's
    fitted range) on, as float."""
    dt = float(model.dt_s)
    m = tau_grid(n, dt, "octave").astype(np.float64)
    tau_min = getattr(model, "tau_min_s", None)
    if tau_min is not None:
        m = m[m * dt >= float(tau_min) * (1.0 - 1e-9)]
    return m


def share_ratio(model, n_samples, term, share, draws=SPREAD_DRAWS, seed=0) -> float:
    """``q_share / median`` of ``term``'s relative half-width (relative to each record's estimate) over ``draws``
    Gaussian records of the linearised fit of ``n_samples`` samples (module docstring); inf when fewer than
    ``share`` of them resolve the term, nan when the record is too short for the model."""
    names, A, dt = model.terms, model.law_coefficients(), float(model.dt_s)
    n = int(n_samples)
    m = _fit_m(model, n)
    if m.size <= len(names) + 1:
        return math.nan
    tau = m * dt
    ctx, L, Xall, yw0 = whitened(names, A, tau, m, n, dt)
    mu = ctx.X @ A
    Vs = ctx.relcov(A, exact_ramp=True, allowance=False, finite_record=True) * np.outer(mu, mu)
    S = np.linalg.solve(L, np.linalg.solve(L, Vs).T).T
    Ls = np.linalg.cholesky(0.5 * (S + S.T) + 1e-12 * np.trace(S) / len(S) * np.eye(len(S)))
    cols = [all_terms().index(u) for u in PLANNED if u in ctx.laws]
    ct = all_terms().index(term)
    subsets = [s for r in range(1, len(cols) + 1) for s in itertools.combinations(cols, r)]
    mcols = _markov_columns(L, tau, dt)
    rng = np.random.default_rng(seed)
    widths = [_record_width(Xall, yw0 + Ls @ rng.standard_normal(yw0.size), subsets, ct, m.size, mcols)
              for _ in range(int(draws))]
    w = np.asarray(widths)
    med, q = float(np.median(w)), float(np.quantile(w, share))
    return q / med if math.isfinite(q) and med > 0 else math.inf


def _markov_columns(L, tau, dt) -> list:
    """The whitened Gauss-Markov columns (:func:`~fogdrift.noise.terms.markov_shape`) at the fit's correlation
    times: :data:`~fogdrift.noise.identify.MARKOV_TC_GRID` log-spaced values of ``T_c`` [s] from ``2 tau[0]`` to
    ``tau[-1] / 2`` (the fit's Markov stage, :func:`fogdrift.noise.identify.identify`: the hump must lie inside the
    fitted range); none when the range holds fewer than 6 taus or no such ``T_c`` (the fit then tries no M
    either).  ``L``: the Cholesky factor of the fit's covariance of the Allan variances [(deg/h)^2]; ``tau``,
    ``dt`` [s]."""
    lo, hi = math.log(2.0 * tau[0]), math.log(tau[-1] / 2.0)
    if tau.size < 6 or hi <= lo:
        return []
    return [np.linalg.solve(L, markov_shape(tau, math.exp(x), "adev", dt))
            for x in np.linspace(lo, hi, MARKOV_TC_GRID)]


def _record_width(Xall, yw, subsets, ct, n_taus, mcols=()) -> float:
    """One linearised record's relative half-width of column ``ct`` (relative to its estimate; inf when not
    resolved) under the Allan fit's rules: :func:`_record_fit`'s ``width``."""
    return _record_fit(Xall, yw, subsets, ct, n_taus, mcols)["width"]


def _record_fit(Xall, yw, subsets, ct, n_taus, mcols=()) -> dict:
    """One linearised record under the Allan fit's rules: its candidate fits, selection and the relative
    half-width of column ``ct``.

    Parameters
    ----------
    Xall : ndarray, shape (n_taus, 7)
        Whitened design, a column per term of :func:`~fogdrift.noise.terms.all_terms` (the M column unused).
    yw : ndarray, shape (n_taus,)
        The record's whitened Allan curve.
    subsets : list of tuple
        The candidate models (column subsets of the planned terms).
    ct : int
        The term's column.
    n_taus : int
        Fitted taus (the degrees of freedom are ``n_taus`` less the selected model's parameters).
    mcols : sequence of ndarray
        Whitened Gauss-Markov columns over the fit's ``T_c`` grid (:func:`_markov_columns`).  The fit's Markov
        stage: every model plus M at each ``T_c`` (IC counts ``q_c`` and ``T_c``); when the best of them beats the
        best model without M by more than :data:`~fogdrift.noise.identify.MARKOV_IC_GAIN`, the models plus M at
        that ``T_c`` join the candidates (M may then stand in for the term: a model without it is plausible and
        the term is not resolved); otherwise none does.  ``T_c`` is not refined between grid points, and a K or
        R read from the hump (the fit's slope rule) is not refused.

    Returns
    -------
    dict
        ``fits`` (model -> ``(coefficients, Q, IC)``), ``best`` (the selected model), ``plausible``, ``dof`` (None
        when the term is not resolved by the selection) and ``width``: ``(sqrt(hi) - sqrt(lo)) / (2 sqrt(a_hat))``
        of the union of the plausible models' profile intervals (inf when not resolved).
    """
    fits = {}
    for s in subsets:
        coef, r = nnls(Xall[:, list(s)], yw)
        fits[s] = (coef, r * r, r * r + IC_PENALTY * len(s))
    best = min(fits, key=lambda s: fits[s][2])
    X = Xall
    if len(mcols):
        scan = []
        for g, col in enumerate(mcols):
            Xm = Xall.copy()
            Xm[:, _M] = col
            for s in [()] + list(subsets):
                coef, r = nnls(Xm[:, list(s) + [_M]], yw)
                scan.append((r * r + IC_PENALTY * (len(s) + 2), g))
        ic_m, g = min(scan)
        if ic_m < fits[best][2] - MARKOV_IC_GAIN:
            X = Xall.copy()
            X[:, _M] = mcols[g]
            for s in [()] + list(subsets):
                sm = s + (_M,)
                coef, r = nnls(X[:, list(sm)], yw)
                fits[sm] = (coef, r * r, r * r + IC_PENALTY * (len(sm) + 1))
            best = min(fits, key=lambda s: fits[s][2])
    plaus = [s for s in fits if fits[s][2] <= fits[best][2] + PLAUSIBLE_DELTA]
    out = {"fits": fits, "best": best, "plausible": plaus, "dof": None, "width": math.inf}
    if ct not in best or any(ct not in s for s in plaus):
        return out
    dof = out["dof"] = max(1, n_taus - len(best) - (1 if _M in best else 0))
    d2 = float(student_t.ppf(0.975, dof)) ** 2 * max(1.0, fits[best][1] / dof)
    lo, hi = math.inf, 0.0
    for s in plaus:
        l_, h_ = _profile(X[:, list(s)], yw, s.index(ct), fits[s][0], fits[s][1], d2)
        lo, hi = min(lo, l_), max(hi, h_)
    a_hat = float(fits[best][0][best.index(ct)])
    if lo > 0 and a_hat > 0:
        out["width"] = (math.sqrt(hi) - math.sqrt(lo)) / (2.0 * math.sqrt(a_hat))
    return out


def fit_rule_widths(model, n_samples, term, draws=100, seed=0) -> np.ndarray:
    """``term``'s relative half-width (relative to each record's estimate; inf where not resolved) from the Allan
    fit's own :func:`~fogdrift.noise.identify.identify` on ``draws`` Allan curves of ``n_samples`` samples drawn
    from the model: on the fit's octave taus (from ``model.tau_min_s``), ``cbrt(y_i / mu_i) = c_i + s_i z_i`` with
    ``c = 1 - 2 / (9 nu)``, ``s = sqrt(2 / (9 nu))``, ``nu_i`` the sampling EDF and ``z`` Gaussian with the
    sampling correlation of the estimators (``FitContext.relcov(A, exact_ramp=True, allowance=False,
    finite_record=True)``).  The fit
    range is fixed to those taus and the Markov candidates are off (on seeds 1-24 of each class of docs/plan.md
    neither changed a width; over 600 MEMS B records the Markov candidate enters about 6 % of them, docs/plan.md
    "The Gauss-Markov candidate")."""
    n, dt = int(n_samples), float(model.dt_s)
    m, mu, nu, curves = model_curves(model, n, draws, seed)
    if m.size <= len(model.terms) + 1:
        return np.full(int(draws), math.inf)
    tau = m * dt
    out = []
    for y in curves:
        fit = identify(tau, y, n, dt, var_hi95=y * nu / chi2.ppf(0.025, nu), m=m,
                       tau_range_s=(float(tau[0]), math.inf), markov=False)
        r = fit.terms[term]
        ok = r.status == "resolved" and r.value and r.lo95 is not None and r.hi95 is not None
        out.append((r.hi95 - r.lo95) / (2.0 * r.value) if ok else math.inf)
    return np.asarray(out)


def model_curves(model, n_samples, draws, seed=0):
    """``(m, mu, nu, curves)``: the fit's octave averaging factors (from ``model.tau_min_s``), the model's expected
    Allan variance and the estimators' sampling EDF there, and ``draws`` Allan curves drawn from it (rows):
    ``cbrt(y / mu) = 1 - 2 / (9 nu) + sqrt(2 / (9 nu)) z``, ``z`` Gaussian with the estimators' sampling correlation
    (Wilson-Hilferty: each ``y / mu`` about ``chi2_nu / nu``, mean 1)."""
    names, A, dt = model.terms, model.law_coefficients(), float(model.dt_s)
    n = int(n_samples)
    m = _fit_m(model, n)
    if m.size <= len(names) + 1:
        return m, None, None, None
    tau = m * dt
    probe = FitContext(tau, m, np.ones_like(tau), np.full_like(tau, 2.0), n, dt, "adev", names)
    mu = probe.X @ A
    C = FitContext(tau, m, mu, mu * 2.0, n, dt, "adev", names).relcov(A, exact_ramp=True, allowance=False,
                                                                     finite_record=True)
    nu = 2.0 / np.diag(C)
    sd = np.sqrt(np.diag(C))
    Lc = np.linalg.cholesky(C / np.outer(sd, sd) + 1e-10 * np.eye(tau.size))
    c, s = 1.0 - 2.0 / (9.0 * nu), np.sqrt(2.0 / (9.0 * nu))
    z = np.random.default_rng(seed).standard_normal((int(draws), tau.size)) @ Lc.T
    return m, mu, nu, mu * np.maximum(c + s * z, 1e-3) ** 3


def _profile(Xw, yw, j, coef, q0, d2):
    """Profile interval ``{a : min_{others >= 0} Q(A_j = a) <= q0 + d2}`` of column ``j`` (``coef``: the fit)."""
    others = [i for i in range(Xw.shape[1]) if i != j]
    a0 = float(coef[j])

    def g(a):
        r = yw - a * Xw[:, j]
        q = float(nnls(Xw[:, others], r)[1] ** 2) if others else float(r @ r)
        return q - q0 - d2

    scale = a0 if a0 > 0 else 1.0 / max(float(np.linalg.norm(Xw[:, j])), 1e-300)
    lo = 0.0
    if a0 > 0 and g(0.0) > 0:
        lo = brentq(g, 0.0, a0, xtol=1e-9 * a0)
    x1 = max(2.0 * a0, scale)
    while g(x1) <= 0:
        x1 *= 2.0
    hi = brentq(g, a0, x1, xtol=1e-9 * scale)
    return lo, hi
