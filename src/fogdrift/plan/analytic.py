"""Interval width of each term of the Allan fit against record length, from the estimator's own covariance laws.

For a record of ``n`` samples the fit works on the octave taus ``m = 1, 2, 4, ... <= n/4`` (:func:`fogdrift.allan.
tau_grid`, as ``fogdrift allan``).  At the true model the fit's objective is, to first order, the generalised
least-squares form ``(y - X A)' V^-1 (y - X A)`` with ``V`` the model covariance the fit itself uses (the
estimators' covariance of :mod:`fogdrift.noise.covariance` and the model-discrepancy allowance, built by the
fit's own context, :class:`fogdrift.noise.context.FitContext`).  Hence (the "Asimov" record: the expected curve
fitted, the median record's interval):

* ``Cov(A) = (X' V^-1 X)^-1`` over the model's terms;
* the 95 % interval of ``A_k`` is ``A_k +- d sd_k`` with ``d^2 = t_{0.975, dof}^2 E[max(1, chi2_red)]`` (the
  fit's profile threshold and its expected widening for misfit; ``dof`` that of the model the fit selects, the
  subset of least IC at the expected curve: a term the length cannot yet show is left out of it), widened to the union over the models one absent
  term larger (always plausible at the expected curve: the information criterion ``IC = Q + 2 k`` rises by at most
  2, inside the plausible window of 6): the absent term may only grow from zero, so one side widens, the side of
  the sign of its correlation with ``A_k``, and to the union over the models one term *smaller* (another term of
  the model dropped) that are plausible at the expected curve (a term the length cannot yet tell from zero): their
  ``A_k`` is fitted by non-negative least squares on the expected curve (biased: it takes up part of the dropped
  term) and gets its own ``+- d sd_k``, widened on one side by the absent terms as above;
* the coefficient is ``sqrt(A)``-like, so its interval relative to the value is ``[sqrt(A_lo), sqrt(A_hi)] /
  sqrt(A)`` and the reported relative width is the half-width ``(hi - lo) / 2``;
* the term is **resolved** when its interval excludes zero and no model without it is plausible: the model
  without it, or with it replaced by one absent term, fitted to the expected curve (non-negative least squares
  in the whitened metric), is more than the plausible window (6) above in IC.

A model from a pilot (:func:`fogdrift.plan.model.model_from_fit`) adds two things: the fit starts at the pilot's
first fitted tau (``model.tau_min_s``: the short taus its fit left out, an output filter or correlated samples,
stay out), and each long-tau term the pilot only bounded (``model.bounds``: B, K or R absent from its model) is
a plausible alternative at :data:`BOUND_FRACTION` of its 95 % bound: every term's interval is the union over the
model and the model plus that term, and resolved only in both.

The allowance (2 % on every deviation, :mod:`fogdrift.noise.discrepancy`) puts a floor under every width: a term
may never reach a target below it at any length, which the plan says.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
from scipy.optimize import nnls
from scipy.stats import chi2, ncx2, t as student_t

from ..allan.grid import tau_grid
from ..noise.context import FitContext
from ..noise.terms import TERM_TABLE, all_terms, laws_of
from .model import PLANNED_TERMS as PLANNED

__all__ = ["analytic_widths", "expected_inflation", "whitened", "PLAUSIBLE_DELTA", "IC_PENALTY",
           "BOUND_FRACTION"]

#: The Allan fit's plausible-model window and IC penalty per term (:func:`fogdrift.noise.fit_noise` defaults).
PLAUSIBLE_DELTA = 6.0
IC_PENALTY = 2.0

#: A term the pilot could only bound enters the plan's union of models at this fraction of its 95 % upper bound
#: (in the coefficient): the middle of what the pilot allows (docs/plan.md, "From a pilot").
BOUND_FRACTION = 0.5


def expected_inflation(dof: int) -> float:
    """``E[max(1, X / dof)]`` for ``X ~ chi2_dof``: the mean widening of the fit's profile threshold.

    ``E[X 1{X > c}] = dof (1 - F_{dof+2}(c))``, so the mean is ``F_dof(dof) + 1 - F_{dof+2}(dof)``.

    Examples
    --------
    >>> round(expected_inflation(10), 4), round(expected_inflation(1000), 4)
    (1.1755, 1.0178)
    """
    k = max(int(dof), 1)
    return float(chi2.cdf(k, k) + 1.0 - chi2.cdf(k, k + 2))


def analytic_widths(model, n_samples, share=None) -> dict:
    """Expected 95 % interval of every model term for a record of ``n_samples`` samples at ``model.dt_s``.

    Parameters
    ----------
    model : PlanModel
        The model (its ``tau_min_s``: the first fitted tau [s]; its ``bounds``: terms the pilot only bounded).
    n_samples : int
        Record length [samples].
    share : float, optional
        None: the median record.  A share ``p`` (e.g. 0.8): a model one term smaller joins the union when at least
        ``1 - p`` of the records find it plausible (its IC gap is then random: ``Q ~ chi2_1(lambda)``, noncentral,
        with ``lambda`` its ``Q`` at the expected curve), the union of the ``p``-th record.

    Returns
    -------
    dict
        ``{term: {"rel_lo", "rel_hi", "rel_width", "z", "delta_ic", "resolved"}}`` (interval ends relative to the
        true value, relative half-width, ``A / sd``) and ``"_fit"``: ``{"tau_min_s", "tau_max_s", "n_taus",
        "dof"}``.  With ``bounds``, every term's interval is the union over the model and the model plus each
        bounded term at :data:`BOUND_FRACTION` of its bound, and resolved only if resolved in all of them.  A
        record too short for ``len(terms) + 1`` taus gives every term ``rel_width = inf``.
    """
    names = model.terms
    A = model.law_coefficients()
    tau_min = getattr(model, "tau_min_s", None)
    out = _widths(names, A, int(n_samples), float(model.dt_s), tau_min, share)
    for e, bound in (getattr(model, "bounds", None) or {}).items():
        if e in names or e not in PLANNED or not bound > 0:
            continue
        Ae = A.copy()
        Ae[all_terms().index(e)] = (BOUND_FRACTION * bound / TERM_TABLE[e].to_unit) ** 2 * \
            laws_of("adev")[e].scale(float(model.dt_s))
        alt = _widths(tuple(t for t in PLANNED if t in names or t == e), Ae, int(n_samples), float(model.dt_s),
                      tau_min, share)
        for t in names:
            o, a = out[t], alt[t]
            o["rel_lo"], o["rel_hi"] = min(o["rel_lo"], a["rel_lo"]), max(o["rel_hi"], a["rel_hi"])
            o["resolved"] = bool(o["resolved"] and a["resolved"])
            o["z"] = min(o["z"], a["z"])
            o["delta_ic"] = min(o.get("delta_ic", math.inf), a.get("delta_ic", math.inf))
            o["rel_width"] = (o["rel_hi"] - o["rel_lo"]) / 2.0 if o["resolved"] else math.inf
    return out


def _widths(names, A, n, dt, tau_min_s=None, share=None) -> dict:
    """:func:`analytic_widths` of the model ``names`` with Allan-law coefficients ``A`` (all columns)."""
    m = tau_grid(n, dt, "octave").astype(np.float64)
    if tau_min_s is not None:
        m = m[m * dt >= float(tau_min_s) * (1.0 - 1e-9)]
    tau = m * dt
    k = len(names)
    out = {"_fit": {"tau_min_s": float(tau[0]) if tau.size else math.nan,
                    "tau_max_s": float(tau[-1]) if tau.size else math.nan, "n_taus": int(m.size),
                    "dof": int(m.size - k)}}
    if m.size <= k:
        for t in names:
            out[t] = {"rel_lo": 0.0, "rel_hi": math.inf, "rel_width": math.inf, "z": 0.0, "delta_ic": 0.0,
                      "resolved": False}
        return out
    ctx, L, Xall, yw = whitened(names, A, tau, m, n, dt)
    col = {t: all_terms().index(t) for t in PLANNED}
    extras = [e for e in PLANNED if e not in names]
    # the fit's threshold uses the degrees of freedom of the model it selects: at the expected curve the one of
    # least IC (a term the length cannot yet tell from zero is left out, as the real fit leaves it out)
    sel = _selected(Xall, yw, [col[t] for t in PLANNED if t in ctx.laws], IC_PENALTY * k)
    dof = int(m.size - len(sel))
    out["_fit"]["dof"] = dof
    out["_fit"]["selected"] = "+".join(t for t in PLANNED if col[t] in sel)
    d = float(student_t.ppf(0.975, dof)) * math.sqrt(expected_inflation(dof))
    cov = _cov(Xall[:, [col[t] for t in names]])
    # the models one extra term away (always plausible at the true curve: IC rises by at most 2)
    cov_ext = {e: _cov(Xall[:, [col[t] for t in names] + [col[e]]]) for e in extras}
    for j, t in enumerate(names):
        a = float(A[col[t]])
        sd = math.sqrt(max(float(cov[j, j]), 0.0))
        z = a / sd if sd > 0 else math.inf
        lo_a, hi_a = a - d * sd, a + d * sd
        for e, ce in cov_ext.items():  # the extra term may only grow from 0: one side of the interval widens
            sd_e = math.sqrt(max(float(ce[j, j]), 0.0))
            if ce[j, -1] < 0:
                lo_a = min(lo_a, a - d * sd_e)
            else:
                hi_a = max(hi_a, a + d * sd_e)
        # the plausible models that lack a term of the model (a K the length cannot yet tell from 0): t fitted
        # there (non-negative least squares on the expected curve) is biased, and the fit's union holds it
        for lo_s, hi_s in _smaller_plausible(Xall, yw, [col[u] for u in names], col[t], [col[e] for e in extras],
                                             IC_PENALTY * k, d, share):
            lo_a, hi_a = min(lo_a, lo_s), max(hi_a, hi_s)
        # resolved: every plausible model needs t -- the model without t, or with t replaced by an absent term,
        # is out of the plausible window at the expected curve
        rest = [col[u] for u in names if u != t]
        dq = min(_q(Xall[:, rest + ([col[e]] if e else [])], yw) + IC_PENALTY * (0 if e else -1)
                 for e in [None] + extras)
        resolved = bool(lo_a > 0 and dq > PLAUSIBLE_DELTA)
        lo = math.sqrt(max(lo_a, 0.0) / a)
        hi = math.sqrt(hi_a / a)
        out[t] = {"rel_lo": lo, "rel_hi": hi, "rel_width": (hi - lo) / 2.0 if resolved else math.inf, "z": z,
                  "delta_ic": float(dq), "resolved": resolved}
    return out


def whitened(names, A, tau, m, n, dt):
    """The fit's view of the expected curve of the model ``names`` (Allan-law coefficients ``A``) on the taus
    ``tau`` (averaging factors ``m``) of an ``n``-sample record: ``(ctx, L, Xall, yw)``, the fit context of the model,
    the Cholesky factor of its covariance ``V`` (estimators' covariance and allowance, exact ramp), and the
    whitened design of every planned column and the whitened expected curve."""
    probe = FitContext(tau, m, np.ones_like(tau), np.full_like(tau, 2.0), n, dt, "adev", names)
    mu = probe.X @ A
    ctx = FitContext(tau, m, mu, mu * 2.0, n, dt, "adev", names)
    V = ctx.relcov(A, exact_ramp=True) * np.outer(mu, mu)
    L = np.linalg.cholesky(V)
    full = FitContext(tau, m, mu, mu * 2.0, n, dt, "adev", tuple(t for t in PLANNED if t in ctx.laws))
    return ctx, L, np.linalg.solve(L, full.X), np.linalg.solve(L, mu)


def _smaller_plausible(Xall, yw, cols, ct, extras, ic_true, d, share=None):
    """95 % intervals ``(lo, hi)`` of column ``ct`` in the models one term smaller than the true one (columns
    ``cols``) that keep it and are plausible at the expected curve (IC ``Q + 2 k`` within :data:`PLAUSIBLE_DELTA`
    of the true model's ``ic_true``).  Each is fitted by non-negative least squares in the whitened metric (its
    ``A_t`` is biased: it takes up part of the dropped term); its interval is ``A_t +- d sd_t``, widened on one
    side by the models one absent column (of ``extras``) larger, as the true model's.  ``share``: see
    :func:`analytic_widths`."""
    out = []
    for u in cols:
        if u == ct:
            continue
        sub = [c for c in cols if c != u]
        coef, res = nnls(Xall[:, sub], yw)
        if not np.all(coef > 0):
            continue
        gap = IC_PENALTY * len(sub) - ic_true  # the IC the smaller model saves in penalty (-2)
        if share is None:
            if res**2 + gap > PLAUSIBLE_DELTA:
                continue
        elif ncx2.cdf(PLAUSIBLE_DELTA - gap, 1, res**2) < 1.0 - share:
            continue
        j = sub.index(ct)
        c_t = float(coef[j])
        sd = math.sqrt(max(float(_cov(Xall[:, sub])[j, j]), 0.0))
        lo, hi = c_t - d * sd, c_t + d * sd
        for e in extras:
            ce = _cov(Xall[:, sub + [e]])
            sd_e = math.sqrt(max(float(ce[j, j]), 0.0))
            if ce[j, -1] < 0:
                lo = min(lo, c_t - d * sd_e)
            else:
                hi = max(hi, c_t + d * sd_e)
        out.append((lo, hi))
    return out


def _selected(Xall, yw, cols, ic_true):
    """Columns of the model of least IC (``Q + 2 k``, :data:`IC_PENALTY`) at the expected curve among every subset
    of ``cols`` holding at most the true model's number of terms (its IC is ``ic_true``, ``Q = 0``; a larger model
    cannot have less); a tie keeps the larger model."""
    best, best_ic = None, math.inf
    for r in range(min(len(cols), int(round(ic_true / IC_PENALTY))), 0, -1):
        for sub in itertools.combinations(cols, r):
            ic = _q(Xall[:, list(sub)], yw) + IC_PENALTY * r
            if ic < best_ic - 1e-9:
                best, best_ic = list(sub), ic
    return best


def _cov(Xw):
    F = Xw.T @ Xw
    try:
        return np.linalg.inv(F)
    except np.linalg.LinAlgError:
        return np.linalg.pinv(F)


def _q(Xw, yw) -> float:
    """Smallest whitened residual ``||yw - Xw A||^2`` over ``A >= 0`` (0 columns: ``||yw||^2``)."""
    if Xw.shape[1] == 0:
        return float(yw @ yw)
    return float(nnls(Xw, yw)[1] ** 2)
