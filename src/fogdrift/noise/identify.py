"""IEEE-952 noise identification on an Allan-family curve: model selection, honest intervals, visible fit quality.

Procedure (method notes §2.5 and §9; each step is a function below):

1. **Working points.**  The measured taus nearest the lattice ``tau_0 2^(k / max_per_octave)`` are fitted (points
   closer than that are almost perfectly correlated and only make the covariance ill-conditioned), so the result
   does not depend on whether the curve was computed on an octave, a 100-point or a 1,000-point grid.
2. **Covariance.**  The estimates' correlation and EDF come from the model itself
   (:func:`.covariance.estimator_covariance` with the spectrum of the current coefficients), so neighbouring taus
   are not counted as independent evidence.
3. **Objective.**  Whitened Wilson-Hilferty scores (:mod:`.engine`), no term above the data's ~4-sigma bound.
4. **Model selection.**  Every subset of the allowed terms is fitted with one common covariance (that of the
   full model) and scored by ``IC = Q + 2 k`` (an AIC/WIC analogue: ``Q`` is a chi-squared when the covariance
   is right).  All candidates and scores are kept.
5. **Fit range.**  Short taus that no candidate describes (an output low-pass filter, an anti-alias roll-off, a
   vibration bump) are left out automatically: the fit range grows from the long-tau half towards short taus one
   point at a time and stops at a point that costs more than a 4-sigma chi-squared increase, or that lies 2.5
   sigma below the white-noise line of the current model (no IEEE term can lower the curve: only a filter can).
   Never more than half of the octaves.  What was excluded, and why, is recorded.
6. **Intervals.**  Profile intervals (Brent) at the t-quantile of the residual degrees of freedom, widened by the
   reduced chi-squared when it exceeds 1, and taken as the union over every *plausible* model (IC within
   ``plausible_delta`` of the best): a term is "resolved" only if every plausible model needs it.  A term not in
   the best model gets a one-sided 95 % upper bound from the model plus that term.
7. **Checks and words.**  A flat bias-instability floor above the measured curve's minimum is refused (the
   classical bound min ADEV / 0.664 is reported instead); the fit quality (chi-squared, p-value, worst tau
   range with the sign and size of the misfit) is always returned, with the reason for every term that is not
   resolved.  The checks and the classical reading are in :mod:`.checks`, the words in :mod:`.notes`.

Simulation checks (tests): over 50 seeds each of white + random walk, white + flicker + random walk and
quantization + white + random walk + ramp, the 95 % intervals cover the true coefficient of every present term in
>= 90 % of seeds and claim an absent term (lower bound > 0) in <= 5 %.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

from ..errors import ConfigError, InsufficientDataError
from .checks import _check_floor, _classical_b, _drop_rejected, _q_at_whole_periods
from .context import FitContext
from .discrepancy import discrepancy_relcov
from .distributions import chi2_sf, t_ppf
from .covariance import estimator_covariance
from .engine import ScoreProblem, all_subsets, fit_subsets, ic_within, profile_interval
from .notes import (_absent_reason, _at_bound_notes, _describe_excluded, _largest_gap_note, _misfit_note, _no_fit,
                    _unresolved_reason)
from .result import NoiseFit, NoiseTerm
from .claims import (_CURVE, _best_claimable, _first_claimable, _measured_limits, _no_fit_terms, _rising_var,
                     _slope_refusals)
from .rules import SLOPES, slope_claim
from .terms import TERM_TABLE, UNESTIMABLE, all_terms, laws_of, power_terms


__all__ = ["identify", "thin_taus", "POOR_CHI2_RED"]

_names = all_terms  # the fit's columns: Q N B K R (then any registered power-law term), S, M

#: The diagonal of the model-discrepancy allowance's relative covariance (no chi-squared error: see ScoreProblem).
_ALLOW = float(discrepancy_relcov([1.0])[0, 0])
#: A fit whose reduced chi-squared exceeds this is "poor" (the misfit is several times the statistical error).
POOR_CHI2_RED = 4.0


# ---------------------------------------------------------------------------------------------------------
def thin_taus(tau_s, per_octave: int) -> np.ndarray:
    """Indices of the points of increasing ``tau_s`` nearest to the lattice ``tau_0 2^(k/per_octave)``.

    Each lattice node takes the measured tau closest to it (within half a lattice step), so an octave grid, a
    decade grid and dense log grids all give (nearly) the same working points: the fit does not depend on the
    display grid.

    Examples
    --------
    >>> thin_taus(np.array([1.0, 2, 3, 4, 5, 8, 9, 16]), 1).tolist()
    [0, 1, 3, 5, 7]
    """
    lt = np.log2(np.asarray(tau_s, dtype=np.float64))
    if lt.size == 0:
        return np.zeros(0, dtype=np.int64)
    nodes = lt[0] + np.arange(0.0, lt[-1] - lt[0] + 1e-9 + 1.0 / per_octave, 1.0 / per_octave)
    keep = []
    for v in nodes:
        k = int(np.argmin(np.abs(lt - v)))
        if abs(lt[k] - v) <= 0.5 / per_octave + 1e-9 and (not keep or k > keep[-1]):
            keep.append(k)
    return np.asarray(keep, dtype=np.int64)




def _select(ctx: FitContext, penalty: float, iters: int = 2, C=None, allowance=True):
    """Common-covariance model selection on the points of ``ctx`` (``C``: a fixed relative covariance;
    ``allowance``: include the model-discrepancy allowance in the model covariance)."""
    from scipy.optimize import nnls

    cols = ctx.cols
    if C is not None:
        prob = ScoreProblem(ctx.X, ctx.y, C, ctx._upper(C), _ALLOW if allowance else 0.0)
        res = fit_subsets(prob, all_subsets(cols), penalty)
        best = min(res, key=lambda s: res[s]["ic"])
        return {"best": best, "res": res, "prob": prob, "C": C, "A_full": res[tuple(cols)]["a"]}
    # pilot: relative-error NNLS on scaled columns (the powers of tau span many decades)
    w = 1.0 / ctx.y
    Xw = ctx.X[:, cols] * w[:, None]
    sc = np.linalg.norm(Xw, axis=0)
    sc[sc == 0] = 1.0
    try:
        a, _ = nnls(Xw / sc, ctx.y * w, maxiter=100 * len(cols))
    except RuntimeError:
        from scipy.optimize import lsq_linear

        a = lsq_linear(Xw / sc, ctx.y * w, bounds=(0.0, np.inf)).x
    A = np.zeros(len(_names()))
    A[list(cols)] = np.minimum(a / sc, ctx.upper[list(cols)])
    if not np.any(A > 0):
        A[list(cols)] = ctx.upper[list(cols)] * 1e-3
    for _ in range(iters):
        C = ctx.relcov(A, allowance=allowance)
        prob = ScoreProblem(ctx.X, ctx.y, C, ctx._upper(C), _ALLOW if allowance else 0.0)
        a, _q = prob.fit(cols)
        newA = np.zeros(len(_names()))
        newA[list(cols)] = a
        done = np.allclose(newA, A, rtol=2e-2, atol=0.0)
        A = newA
        if done:
            break
    res = fit_subsets(prob, all_subsets(cols), penalty)
    best = min(res, key=lambda s: res[s]["ic"])
    return {"best": best, "res": res, "prob": prob, "C": C, "A_full": A}


def _reduced(sel, n_points):
    r = sel["res"][sel["best"]]
    return r["q"] / max(1, n_points - len(sel["best"]))


def _choose_start(ctx: FitContext, penalty: float, max_fraction: float = 0.5, thresh: float = 16.0,
                  thresh_below: float = 6.25):
    """First fitted point: grow the fit range from where the curve is visibly white noise (else from the long-tau
    half) toward short taus, one point at a time, while
    adding the point raises the best model's chi-squared by at most ``thresh`` (a 4-sigma effect) times
    ``max(1, chi2_red)`` of the current range.  The model of the current range is re-selected at each step, so a
    term that only shows at short taus (quantization) can enter; a filter roll-off or a bump that no term
    explains stops the growth.  At most ``max_fraction`` of the octaves are left out.
    """
    tau = ctx.tau
    span = math.log2(tau[-1] / tau[0])
    cap = 0
    while cap + 1 < tau.size - 3 and math.log2(tau[-1] / tau[cap + 1]) >= (1 - max_fraction) * span:
        cap += 1
    # start where the curve is visibly white noise (the earliest run of >= 3 points with local ADEV slope within
    # 0.1 of -1/2): the model of a range that holds white noise knows N, so its white-noise line is a reliable
    # reference for the points below it.  Without such a run, start from the long-tau half.
    start0, from_white = cap, False
    ld, lt = 0.5 * np.log(ctx.y), np.log(tau)
    sd = np.log(ctx.y_hi / ctx.y) / (2.0 * 1.96)  # ~ s.d. of log ADEV of each point
    white = np.zeros(tau.size, dtype=bool)
    for k in range(1, tau.size - 1):  # central slope and its s.d. (neighbours treated as independent: generous)
        slope = (ld[k + 1] - ld[k - 1]) / (lt[k + 1] - lt[k - 1])
        sd_slope = math.hypot(sd[k + 1], sd[k - 1]) / (lt[k + 1] - lt[k - 1])
        white[k] = abs(slope + 0.5) <= max(0.02, 2.5 * sd_slope)
    for k in range(0, cap + 1):
        if white[k:k + 3].all() and k + 3 <= tau.size:
            start0, from_white = k, True
            break
    # one covariance for the whole scan: that of the full model fitted to every point, from the sampling error
    # alone -- a filter edge or a bump a few % off the white-noise line is where the fit range stops, whatever
    # the model-discrepancy allowance later grants the fit inside that range
    C_all = _select(ctx, penalty, allowance=False)["C"]
    cache = {}

    def get(k):
        if k not in cache:
            cache[k] = _select(ctx.sub(k), penalty, C=C_all[k:, k:], allowance=False)
        return cache[k]

    s = start0
    while s > 0:
        here = get(s)
        q_here = here["res"][here["best"]]["q"]
        q_more = get(s - 1)["res"][get(s - 1)["best"]]["q"]
        red = max(1.0, _reduced(here, tau.size - s))
        # IEEE-952 terms are additive and non-negative, so no term can put a point BELOW the white-noise line
        # N^2/tau of the current model: only noise or an output filter can, and refitting would let the terms
        # rebalance around it (N down, B up).  Such a point is judged by its score against that line, no refit.
        # (Only when the current fit is not poor: a poor fit's N is no reliable anchor.)
        a_here = here["res"][here["best"]]["a"]
        i_n = _names().index("N")
        if from_white and a_here[i_n] > 0 and _reduced(here, tau.size - s) <= POOR_CHI2_RED:
            white = np.zeros(len(_names()))
            white[i_n] = a_here[i_n]
            line = float(ctx.X[s - 1] @ white)
            if ctx.y[s - 1] < line:
                rel_var = float(C_all[s - 1, s - 1])
                nu = 2.0 / rel_var
                u = (math.cbrt(ctx.y[s - 1] / line) - 1.0 + 2.0 / (9.0 * nu)) / math.sqrt(2.0 / (9.0 * nu))
                if u < -math.sqrt(thresh_below * red):
                    break
        if q_more - q_here > thresh * red:
            break
        s -= 1
    return s, _select(ctx.sub(s), penalty), "grown"


def identify(tau_s, var, n_samples, dt_s, *, var_hi95, m=None, statistic="adev", terms=None, tau_range_s=None,
             max_per_octave=1, ic_penalty=2.0, plausible_delta=6.0, var_inflation=None, strides=None,
             periodic=None, keep_tau_s=None, markov=True, spectrum_given=False, rolloff_hz=None) -> NoiseFit:
    """Identify the IEEE-952 noise terms of one Allan-family curve (see the module docstring).

    Parameters
    ----------
    tau_s, var : array_like, shape (n_tau,)
        Averaging times [s] (increasing) and the statistic's variance [(deg/h)^2].
    n_samples : int
        Number of rate samples the curve was computed from.
    dt_s : float
        Sample interval [s].
    var_hi95 : array_like, shape (n_tau,)
        Upper 95 % bound of each variance (bounds the terms; from the EDF or a published CI).
    m : array_like of int, optional
        Averaging factors (default ``round(tau_s / dt_s)``).
    statistic : str
        Key of :data:`fogdrift.noise.VARIANCE_LAWS` (``adev``, ``hdev``, ``mdev``).
    terms : sequence of str, optional
        Fixed model (no selection), e.g. ``("N", "K")``.
    tau_range_s : (float or None, float or None), optional
        Fit range; without it, short taus no model describes are excluded automatically.
    max_per_octave : int
        Working points per octave.
    ic_penalty, plausible_delta : float
        Information-criterion penalty per term and the IC window of plausible models.
    var_inflation : array_like, shape (n_tau,), optional
        Factor by which each estimate's variance exceeds the overlapping estimator's (non-overlapping or strided
        sampling); the model covariance is scaled by ``sqrt(f_i f_j)``.
    strides : array_like, shape (n_tau,), optional
        Start-index stride of each estimate (1 overlapping, ``m`` non-overlapping, ``b`` fast).
    periodic : PeriodicContent or None
        Spectral lines of the same rate series (:func:`fogdrift.noise.periodic.periodic_content`): they become the
        candidate S term and name the real frequency wherever the notes speak of an oscillation.
    keep_tau_s : array_like, optional
        Taus [s] kept besides the thinned working points (whole multiples of a period: a sinusoid vanishes there).
    markov : bool
        Try the exponentially correlated term M (its correlation time profiled on the fitted range).
    spectrum_given : bool
        True when the spectrum of the series was examined.
    rolloff_hz : float or None
        Where that spectrum shows an output low-pass roll-off [Hz].  A short-tau shape below the white-noise line
        is called an output filter only with one; without a spectrum or without a roll-off it never is.

    Returns
    -------
    NoiseFit
        Without read-outs (:func:`fogdrift.noise.fit_noise` adds them from the whole curve).
    """
    laws = laws_of(statistic)
    tau = np.asarray(tau_s, dtype=np.float64)
    y = np.asarray(var, dtype=np.float64)
    y_hi = np.asarray(var_hi95, dtype=np.float64)
    mm = np.rint(tau / dt_s) if m is None else np.asarray(m, dtype=np.float64)
    # a degenerate interval (exact, noise-free curves) bounds nothing
    y_hi = np.where(np.isfinite(y_hi) & (y_hi > y * (1 + 1e-6)), y_hi, 1e6 * np.abs(y))
    ok = (y > 0) & np.isfinite(y)
    if tau_range_s is not None:
        lo, hi = tau_range_s
        ok &= (tau >= (lo if lo is not None else 0.0)) & (tau <= (hi if hi is not None else math.inf))
    infl_pt = np.ones(tau.size) if var_inflation is None else np.asarray(var_inflation, dtype=np.float64)
    strd = np.ones(tau.size) if strides is None else np.asarray(strides, dtype=np.float64)
    tau, y, y_hi, mm, infl_pt, strd = tau[ok], y[ok], y_hi[ok], mm[ok], infl_pt[ok], strd[ok]
    idx = thin_taus(tau, max_per_octave)
    if keep_tau_s is not None and len(keep_tau_s):  # whole multiples of a period: Q and S are told apart there
        kt = np.asarray(keep_tau_s, dtype=np.float64)
        near = np.any(np.abs(tau[:, None] / kt[None, :] - 1.0) < 1e-9, axis=1)
        idx = np.union1d(idx, np.flatnonzero(near)).astype(np.int64)
    tau, y, y_hi, mm, infl_pt, strd = tau[idx], y[idx], y_hi[idx], mm[idx], infl_pt[idx], strd[idx]
    allowed = tuple(t for t in power_terms() if t in laws) if terms is None else tuple(terms)
    bad = [t for t in allowed if t not in laws]
    if bad:
        why = "; ".join(UNESTIMABLE.get((statistic, t), f"{statistic} has no law for {t}") for t in bad)
        raise ConfigError(f"{statistic} cannot estimate term(s) {bad}: {why}; drop them from {{opt:terms}} "
                          f"or use another {{opt:statistic}}")
    if tau.size < len(allowed) + 2 if terms is not None else tau.size < 4:
        need = len(allowed) + 2 if terms is not None else 4
        raise InsufficientDataError(
            f"the noise fit needs at least {need} taus at least 1/{max_per_octave} octave apart in the fit range; "
            f"got {tau.size} (widen {{opt:fit_taus}} or fit fewer {{opt:terms}})", needed=need, got=int(tau.size))
    lines = tuple(periodic.lines) if periodic is not None else ()
    if lines and terms is None:
        allowed = allowed + ("S",)
    ctx = FitContext(tau, mm, y, y_hi, int(n_samples), float(dt_s), statistic, allowed, infl_pt, strd, lines=lines)

    excluded, notes = [], []
    if tau_range_s is None and terms is None:
        start, sel, how = _choose_start(ctx, ic_penalty)
    else:
        start, how = 0, "fixed"
        sel = _select(ctx, ic_penalty)
    if start > 0:
        excluded.append({"tau_min_s": float(tau[0]), "tau_max_s": float(tau[start - 1]),
                         "reason": _describe_excluded(ctx, start, sel, periodic, spectrum_given, rolloff_hz)})
    c = ctx.sub(start)
    if terms is not None:
        sel["best"] = tuple(_names().index(t) for t in allowed)
    prob, res = sel["prob"], sel["res"]
    best = sel["best"]
    refused = {}
    if terms is None:
        # a K or R without a sustained slope is not selectable (a hump goes to M, or to B/N without it)
        refused = _slope_refusals(c, prob, res)
        best = _best_claimable(res, refused, best)
        nz = tuple(i for i in best if res[best]["a"][i] > 0)  # a term at exactly zero is not in the model
        if nz and nz != best and nz in res and nz not in refused:
            best = nz
    # the exponentially correlated (Gauss-Markov) term: its correlation time is profiled on the fitted range
    markov_info = None
    if markov and terms is None and c.tau.size >= 6:
        mk = _markov_stage(c, sel["C"], res, best, ic_penalty)
        if mk is not None:
            prob, res, best, markov_info = mk
            if markov_info is not None:
                allowed = allowed + ("M",)
            refused = _slope_refusals(c, prob, res)
            best = _best_claimable(res, refused, best)
    sel_res = res  # the selection stage's fits (one common covariance): what the candidate table reports
    # every refusal ranked below the chosen model names why its K or R was not claimed
    slope_notes = {}
    for k in sorted(refused, key=lambda k: res[k]["ic"]):
        for name in ("K", "R"):
            if _names().index(name) in k and refused[k].reason.startswith(name) and name not in slope_notes:
                slope_notes[name] = (res[k]["ic"], refused[k].reason)
    # a selected model never holds a term its own checks reject: a flat floor above the measured curve or a term at
    # its ~4-sigma data bound is dropped and the model re-selected without it
    dropped = {}
    if terms is None:
        best, dropped = _drop_rejected(c, prob, {k: v for k, v in res.items() if k not in refused}, best,
                                       plausible_delta)
    ic_best = res[best]["ic"]

    def _ok(k):
        return not any(i in k for i in dropped) and k not in refused

    plaus = [best] if terms is not None else [k for k, v in res.items()
                                             if ic_within(v["ic"], ic_best, plausible_delta) and _ok(k)]
    # (problem, fits) pairs whose intervals are united: the selection's conservative covariance, and -- when the
    # selected model holds a ramp -- the ramp's real (much smaller) covariance, which gives the estimate.  A ramp
    # that really is a random walk in disguise keeps the wide interval; a real ramp gets an unbiased value.
    views = [(prob, res)]
    iR = _names().index("R")
    if res[best]["a"][iR] > 0:
        C_exact = c.relcov(res[best]["a"], exact_ramp=True)
        p_exact = ScoreProblem(c.X, c.y, C_exact, c._upper(C_exact), _ALLOW)
        r_exact = {**res, **fit_subsets(p_exact, plaus, ic_penalty)}
        no_r = tuple(i for i in best if i != iR)
        n_par_r = len(best) + (1 if _names().index("M") in best else 0)
        if (terms is None and r_exact[best]["q"] / max(1, c.tau.size - n_par_r) > POOR_CHI2_RED
                and no_r in res and no_r in plaus):
            # as a deterministic ramp (its real covariance) the model misses the curve, while the same curve
            # without R is a plausible fit: the "ramp" was a random walk's long-tau scatter, not a ramp
            best = no_r
            plaus = [k for k in plaus if iR not in k] or [best]
            ic_best = res[best]["ic"]
        else:
            prob, res = p_exact, r_exact
            views.append((prob, res))
    # a candidate refused only by the slope rule cannot be claimed, but the data do not exclude it: within the IC
    # window it still keeps the *other* terms from being resolved when it does without them (a true K whose rise
    # the record happens not to show must not turn into a resolved flicker floor)
    alt = [k for k in refused if k in views[0][1] and not any(i in k for i in dropped)
           and ic_within(views[0][1][k]["ic"], ic_best, plausible_delta) and k not in plaus] if terms is None else []
    A = res[best]["a"]
    q = res[best]["q"]
    n_par = len(best) + (1 if _names().index("M") in best else 0)
    dof = max(1, c.tau.size - n_par)
    chi2_red = q / dof
    p = float(chi2_sf(q, dof))
    quality = "good" if p >= 0.01 else "acceptable" if chi2_red <= POOR_CHI2_RED else "poor"
    infl = max(1.0, chi2_red)
    d2 = float(t_ppf(0.975, dof) ** 2) * infl
    d1 = float(t_ppf(0.95, dof) ** 2) * infl
    mu = c.X @ A
    z = prob.scores(mu)

    candidates = [{"terms": [_names()[i] for i in k], "chi2": float(v["q"]), "ic": float(v["ic"]),
                   "delta_ic": float(v["ic"] - sel_res[best]["ic"]), "plausible": k in plaus}
                  for k, v in sorted(sel_res.items(), key=lambda kv: kv[1]["ic"])]

    out_terms = {}
    shaped = {}
    for i, name in enumerate(_names()):
        if name in ("S", "M"):
            if name not in allowed:
                continue
            spec_unit = "deg/h" if name == "S" else "deg/h/sqrt(s)"
        else:
            spec = TERM_TABLE[name]
            spec_unit = spec.unit
            if name not in laws:
                out_terms[name] = NoiseTerm(name, None, spec.unit, None, None, "not_estimable",
                                            UNESTIMABLE.get((statistic, name), f"{statistic} has no law for {name}"))
                continue
        if name == "S":
            conv = 1.0
        elif name == "M":
            conv = 1.0 / markov_info["tc_s"]
        else:
            conv = spec.to_unit / math.sqrt(laws[name].scale(dt_s))
        if name not in allowed:
            out_terms[name] = NoiseTerm(name, None, spec_unit, None, None, "absent",
                                        f"not fitted (terms={'+'.join(allowed)})")
            continue
        if i in dropped:
            out_terms[name] = dropped[i]
            continue
        los, his, lacking = [], [], []
        for mod in plaus + alt:
            if i not in mod:
                lacking.append(mod)
            for v_prob, v_res in (views if mod in plaus else views[:1]):
                r = v_res[mod]
                if i in mod:
                    lo, hi = profile_interval(v_prob, mod, r["a"], i, r["q"], d2)
                else:
                    big = tuple(sorted(mod + (i,)))
                    rb = v_res.get(big) or fit_subsets(v_prob, [big], ic_penalty)[big]
                    lo, (_, hi) = 0.0, profile_interval(v_prob, big, rb["a"], i, rb["q"], d1, lower=False)
                los.append(lo)
                his.append(hi)
        lo_v, hi_v = conv * math.sqrt(min(los)), conv * math.sqrt(max(his))
        if name == "M" and i in best:  # q_c = sqrt(A_M) / T_c over the T_c interval too
            lo_v, hi_v = _markov_qc_interval(c, prob, best, markov_info, q, d2, lo_v, hi_v)
        if i in best:
            val = conv * math.sqrt(A[i])
            if min(los) > 0:
                status, reason = "resolved", ""
            else:
                status = "unresolved"
                reason = _unresolved_reason(name, lacking, plaus, res, ic_best)
            if name in SLOPES:
                # never resolved without a sustained slope (a fixed model keeps the term, with the reason)
                lo_m, hi_m = _measured_limits(c, prob.nu)
                claim = slope_claim(c.tau, c.y, lo_m, hi_m, c.X @ A, _rising_var(c, A, name), SLOPES[name],
                                    name=name, curve=_CURVE.get(statistic, statistic.upper()))
                if not claim.ok:
                    status, reason, lo_v = "unresolved", claim.reason, 0.0
            out_terms[name] = NoiseTerm(name, val, spec_unit, lo_v, hi_v, status, reason)
        else:
            why = (_absent_reason(c, name, A, max(his)) if name in laws else
                   "not in the model: the curve is described as well without it")
            if name in slope_notes and ic_within(slope_notes[name][0], ic_best, plausible_delta):
                why = (f"{why}; {slope_notes[name][1]}; the model {'+'.join(_names()[j] for j in best)} describes "
                       "the curve instead")
            out_terms[name] = NoiseTerm(name, None, spec_unit, 0.0, hi_v, "absent", why)
    if terms is not None and "B" in laws and out_terms.get("B") is not None and out_terms["B"].value is not None:
        _check_floor(out_terms, c, A)  # a fixed model keeps its terms; a floor above the curve is still refused
    iQ, iS = _names().index("Q"), _names().index("S")
    if iQ in best and iS in best and out_terms["Q"].status in ("resolved", "unresolved"):
        _q_at_whole_periods(c, prob, best, A, d2, periodic, out_terms)
    if "S" in allowed:
        shaped["S"] = {"A": float(A[_names().index("S")]), "lines": [list(x) for x in lines],
                       "freq_hz": float(periodic.ref_freq_hz), "spectrum_amplitude_dph": periodic.ref_amplitude_dph,
                       "description": periodic.text()}
        t_s = out_terms["S"]
        notes.append(f"{periodic.text()}: " + (
            f"modelled as S, amplitude {t_s.value:.3g} deg/h at {periodic.ref_freq_hz:.4g} Hz" if t_s.value else
            "not needed by the model in the fitted range (S absent)"))
    if markov_info is not None:
        iM = _names().index("M")
        tc = markov_info["tc_s"]
        shaped["M"] = {"A": float(A[iM]), "tc_s": tc, "tc_lo95_s": markov_info["tc_lo95_s"],
                       "tc_hi95_s": markov_info["tc_hi95_s"],
                       "sigma_dph": (math.sqrt(A[iM]) / tc) * math.sqrt(tc / 2.0) if A[iM] > 0 else None,
                       "q_unit": "deg/h/sqrt(s)"}
        if iM not in best:
            shaped["M"].update(tc_s=None, tc_lo95_s=None, tc_hi95_s=None, sigma_dph=None)
    notes.extend(_at_bound_notes(prob, A, best, c.tau, out_terms))
    if quality != "good":
        notes.extend(_misfit_note(c.tau, c.y, mu, z, quality, chi2_red, p))
        if infl > 1:
            notes.append(f"intervals widened by sqrt(chi2_red) = {math.sqrt(infl):.3g} for the misfit")
    notes.extend(_largest_gap_note(c.tau, c.y, mu, prob.nu))
    no_fit = None
    if chi2_red > POOR_CHI2_RED:
        no_fit, note = _no_fit(c.tau, c.y, mu, prob.nu, best, chi2_red)
        if no_fit is not None:
            notes.insert(0, note)
            _no_fit_terms(c, out_terms, laws, dt_s)
    b_min = _classical_b(c, A, floor_refused=out_terms.get("B") is not None and out_terms["B"].status ==
                         "not_estimable" and "contradicted" in (out_terms["B"].reason or "")) \
        if statistic == "adev" else {}
    A5 = np.asarray(A[:len(power_terms())], dtype=np.float64)
    return NoiseFit(
        statistic=statistic, dt_s=float(dt_s), terms=out_terms, selected=tuple(_names()[i] for i in best), A=A5,
        candidates=candidates, plausible=["+".join(_names()[i] for i in k) for k in plaus], fit_tau_s=c.tau,
        fit_var=c.y, model_var=mu, z=z, chi2=float(q), dof=int(dof), chi2_red=float(chi2_red), p_value=p,
        quality=quality, inflation=float(infl), excluded=excluded, notes=notes, b_min=b_min,
        n_samples=int(n_samples), shaped=shaped, no_fit=no_fit,
    )


def _markov_fits(c: FitContext, C, base_cols, tc, penalty):
    """Fits of every model ``subset + M`` at one correlation time ``tc`` [s] under the fixed relative covariance C."""
    c.set_tc(tc)
    prob = ScoreProblem(c.X, c.y, C, c._upper(C), _ALLOW)
    iM = _names().index("M")
    subs = [()] + all_subsets(base_cols)
    out = fit_subsets(prob, [tuple(sorted(s + (iM,))) for s in subs], penalty)
    for v in out.values():
        v["ic"] += penalty  # T_c is a parameter too
    return prob, out


#: IC gain (beyond the penalty of q_c and T_c) the best Gauss-Markov model needs over the best model without M.
MARKOV_IC_GAIN = 2.0
#: Correlation times the Markov stage scans first (log-spaced over the fitted range), before refining the best.
MARKOV_TC_GRID = 12


def _markov_stage(c: FitContext, C, res, best, penalty):
    """Try the exponentially correlated term M: profile ``T_c`` on a log grid over the fitted tau range (refined by
    a bounded search), with ``(q_c T_c)^2`` linear given ``T_c``; M enters the model only if its best model's IC
    (``T_c`` counted as a parameter) beats the best model without it.  Returns ``(prob, res, best, info)`` or None.

    ``info``: ``tc_s`` and the profile-likelihood 95 % interval ``tc_lo95_s``/``tc_hi95_s`` (None where it reaches
    the edge of the searched range: the data bound T_c only on one side).
    """
    from scipy.optimize import minimize_scalar

    if "M" in _names() and c.statistic not in ("adev", "hdev", "mdev"):
        return None
    iM = _names().index("M")
    base_cols = tuple(i for i in c.cols if i != iM)
    # T_c inside the fitted range (2 tau_min .. tau_max / 2): the Gauss-Markov hump (ADEV maximum at ~1.9 T_c)
    # must lie within it, or the term only imitates a filter edge (short T_c) or a random walk (long T_c)
    lo_t, hi_t = math.log(2.0 * c.tau[0]), math.log(c.tau[-1] / 2.0)
    if hi_t <= lo_t:
        return None
    grid = np.linspace(lo_t, hi_t, MARKOV_TC_GRID)
    ic0 = res[best]["ic"]
    scan = []
    for g, lt in enumerate(grid):
        pr, fits = _markov_fits(c, C, base_cols, math.exp(lt), penalty)
        k = _first_claimable(c, pr, fits)  # a K or R read from the hump is no candidate
        if k is not None:
            scan.append((fits[k]["ic"], lt, k, g))
    if not scan:
        c.X[:, iM] = 0.0
        c.tc_s = None
        return None
    ic_m, lt_m, sub, j = min(scan, key=lambda e: e[0])
    # the correlation time is searched, not given: ask for more than its one-parameter penalty (look-elsewhere)
    if not ic_m < ic0 - MARKOV_IC_GAIN:
        c.set_tc(math.exp(lt_m))
        c.X[:, iM] = 0.0
        c.tc_s = None
        return None
    a, b = grid[max(j - 1, 0)], grid[min(j + 1, grid.size - 1)]

    def q_at(lt, sub=sub):
        c.set_tc(math.exp(lt))
        prob = ScoreProblem(c.X, c.y, C, c._upper(C), _ALLOW)
        return prob.fit(sub)[1]

    r = minimize_scalar(q_at, bounds=(a, b), method="bounded", options={"xatol": 1e-3})
    lt_best = float(r.x) if r.fun <= q_at(lt_m) else lt_m
    tc = math.exp(lt_best)
    # the final covariance: that of the selected M model
    c.set_tc(tc)
    prob0 = ScoreProblem(c.X, c.y, C, c._upper(C), _ALLOW)
    a_sel, _ = prob0.fit(sub)
    A = np.zeros(len(_names()))
    A[list(sub)] = a_sel
    C2 = c.relcov(A)
    prob = ScoreProblem(c.X, c.y, C2, c._upper(C2), _ALLOW)
    non_m = fit_subsets(prob, all_subsets(base_cols), penalty)
    _, with_m = _markov_fits(c, C2, base_cols, tc, penalty)
    prob = ScoreProblem(c.X, c.y, C2, c._upper(C2), _ALLOW)
    res2 = {**non_m, **with_m}
    refused = _slope_refusals(c, prob, res2)
    best_non = _best_claimable(non_m, refused, min(non_m, key=lambda s: non_m[s]["ic"]))
    best2 = _best_claimable(res2, refused, best_non)
    if iM in best2 and not res2[best2]["ic"] < non_m[best_non]["ic"] - MARKOV_IC_GAIN:
        best2 = best_non
    if iM in best2 and res2[best2]["q"] / max(1, c.tau.size - len(best2) - 1) > POOR_CHI2_RED:
        # an M that still leaves a poor fit describes no hump: it only bends the model somewhere; no M
        c.X[:, iM] = 0.0
        c.tc_s = None
        return None
    if iM not in best2:  # under its own covariance M is no longer needed
        c.X[:, iM] = 0.0
        c.tc_s = None
        prob = ScoreProblem(c.X, c.y, C2, c._upper(C2), _ALLOW)
        return prob, non_m, best2, None
    # profile-likelihood interval of T_c: {T : min_q(T) <= q_min + t^2 chi2_red}
    q_min = res2[best2]["q"]
    dof = max(1, c.tau.size - len(best2) - 1)
    d2 = float(t_ppf(0.975, dof) ** 2) * max(1.0, q_min / dof)
    lt_lo, lt_hi = lo_t - math.log(8.0), hi_t + math.log(16.0)  # the interval's range: tau_min/8 .. 8 tau_max
    cache = {}

    def q_prof(lt):
        if lt not in cache:
            c.set_tc(math.exp(lt))
            pr = ScoreProblem(c.X, c.y, C2, c._upper(C2), _ALLOW)
            cache[lt] = pr.fit(best2)[1]
        return cache[lt]

    lt0 = math.log(tc)
    target = q_min + d2

    def edge(direction):
        """The T_c where the profile crosses the threshold on one side (None: not within the searched range)."""
        step = math.log(2.0) / 2.0
        a_, b_ = lt0, lt0
        while True:
            b_ = a_ + direction * step
            if not lt_lo <= b_ <= lt_hi:
                return None
            if q_prof(b_) > target:
                break
            a_ = b_
        lo_, hi_ = sorted((a_, b_))
        return math.exp(brentq(lambda x: q_prof(x) - target, lo_, hi_, xtol=1e-3))

    tc_lo, tc_hi = edge(-1), edge(+1)
    fine = np.array(sorted(cache))
    qs = np.array([cache[k] for k in fine])
    c.set_tc(tc)
    return prob, res2, best2, {"tc_s": tc, "tc_lo95_s": tc_lo, "tc_hi95_s": tc_hi, "grid_log_tc": fine, "q": qs,
                               "C": C2, "q_min": q_min, "d2": d2}


def _markov_qc_interval(c: FitContext, prob, best, info, q_min, d2, lo_v, hi_v):
    """``q_c = sqrt(A_M) / T_c`` 95 % interval: the union over the T_c values inside the T_c interval of the
    profile interval of ``A_M`` at each (threshold: the global minimum plus the same ``d2``)."""
    iM = _names().index("M")
    C2 = info["C"]
    tc0 = c.tc_s
    los, his = [lo_v], [hi_v]
    ok = np.flatnonzero(info["q"] <= info["q_min"] + info["d2"])
    for j in ok[:: max(1, ok.size // 6)]:
        tc = float(np.exp(info["grid_log_tc"][j]))
        c.set_tc(tc)
        pr = ScoreProblem(c.X, c.y, C2, c._upper(C2), _ALLOW)
        a, qq = pr.fit(best)
        full = np.zeros(len(_names()))
        full[list(best)] = a
        if full[iM] <= 0:
            continue
        lo, hi = profile_interval(pr, best, full, iM, q_min, d2)
        los.append(math.sqrt(lo) / tc)
        his.append(math.sqrt(hi) / tc)
    c.set_tc(tc0)
    return min(los), max(his)
