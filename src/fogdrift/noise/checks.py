"""Checks of a fitted noise model against the measured curve, and the classical bias-instability reading
(:func:`fogdrift.noise.identify`, step 7).

Each point's ~4-sigma upper limit and the points whose 95 % interval misses the model; the refusal of a flat
bias-instability floor above the measured curve; the re-selection without every term those checks reject (a
refused floor, a term at its data bound); whether quantization is still resolved at whole periods of a periodic
error; and B read the IEEE-952 way, min ADEV / 0.664.
"""

from __future__ import annotations

import math

import numpy as np

from ..units import B_FACTOR
from .context import FitContext, point_limits
from .distributions import chi2_ppf
from .engine import ScoreProblem, ic_within, profile_interval
from .periodic import Q_OVER_ENVELOPE, q_stands_above_lines
from .result import NoiseTerm
from .terms import DISPLAY_UNITS, TERM_TABLE, all_terms, markov_shape, periodic_shape


_names = all_terms  # the fit's columns: Q N B K R (then any registered power-law term), S, M



def _points_outside(y, mu, nu) -> np.ndarray:
    """Indices of the points whose own 95 % chi-squared interval (EDF ``nu``) does not hold the model value."""
    nu = np.maximum(np.asarray(nu, dtype=np.float64), 1e-6)
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        lo = y * nu / chi2_ppf(0.975, nu)
        hi = y * nu / chi2_ppf(0.025, nu)  # inf where nu << 1: such a point bounds nothing above
    return np.flatnonzero((mu < lo) | (mu > hi))


def _check_floor(terms, c: FitContext, A) -> None:
    """Refuse a flat B floor above the measured curve's minimum (its 95 % upper bound): the data fall below it."""
    i = _names().index("B")
    floor_var = A[i]
    k = int(np.argmin(c.y))
    if floor_var > c.y_hi[k]:
        scale = c.laws["B"].scale(c.dt)
        bound = math.sqrt(c.y[k] / scale) * TERM_TABLE["B"].to_unit
        name = {"adev": "ADEV", "hdev": "HDEV", "mdev": "MDEV"}.get(c.statistic, c.statistic)
        terms["B"] = NoiseTerm(
            "B", None, TERM_TABLE["B"].unit, None, bound, "not_estimable",
            f"a flat floor of {math.sqrt(floor_var / scale):.3g} deg/h is contradicted by the measured curve, which "
            f"falls to {math.sqrt(c.y[k]):.3g} deg/h at tau = {c.tau[k]:.3g} s: no bias-instability floor within the "
            f"record; classical bound B <= min {name} / {math.sqrt(scale):.4g} = {bound:.3g} deg/h")


def _classical_b(c: FitContext, A, floor_refused: bool = False) -> dict:
    """IEEE-952 practice: bias instability read at the minimum of the (fitted) Allan deviation, B = min ADEV / 0.664.

    The minimum is searched on the fitted curve inside the fitted tau range.  When it sits at the longest tau the
    curve is still falling there and the value is only an upper bound, never above the one the measured curve
    gives (min measured ADEV / 0.664).  When the fitted flat floor was refused (it lies above the measured curve)
    the measured minimum is the only reading.  The interval is the measured point's 95 % interval at the tau
    nearest the minimum.
    """
    if floor_refused:
        j = int(np.argmin(c.y))
        return {"value": math.sqrt(c.y[j]) / B_FACTOR, "unit": "deg/h", "tau_s": float(c.tau[j]), "bound_only": True,
                "lo95": None, "hi95": math.sqrt(c.y_hi[j]) / B_FACTOR,
                "rule": "min of the measured ADEV / 0.664 (IEEE Std 952-1997 C.2), an upper bound: the fitted flat "
                        "floor lies above the measured curve"}
    grid = np.logspace(math.log10(c.tau[0]), math.log10(c.tau[-1]), 400)
    var = sum(A[i] * c.laws[n].shape(grid, c.dt) for i, n in enumerate(_names()) if n in c.laws)
    iS, iM = _names().index("S"), _names().index("M")
    if A[iM] > 0 and c.tc_s is not None:  # the printed model: its shaped terms too
        var = var + A[iM] * markov_shape(grid, c.tc_s, c.statistic, c.dt)
    if A[iS] > 0 and c.lines:
        var = var + A[iS] * periodic_shape(grid, c.lines, c.dt, c.statistic)
    k = int(np.argmin(var))
    j = int(np.argmin(np.abs(np.log(c.tau / grid[k]))))
    value = math.sqrt(var[k]) / B_FACTOR
    at_edge = k >= grid.size - 2
    lo = math.sqrt(c.y[j] * (c.y[j] / c.y_hi[j])) / B_FACTOR  # symmetric-in-log guess of the lower bound
    rule = ("min of the fitted ADEV / 0.664 (IEEE Std 952-1997 C.2); an upper bound when the curve still falls at "
            "the longest fitted tau")
    jm = int(np.argmin(c.y))
    if at_edge:  # two valid upper bounds: the fitted curve's end and the measured minimum; keep the tighter
        if math.sqrt(c.y[jm]) / B_FACTOR < value:
            value, j, k = math.sqrt(c.y[jm]) / B_FACTOR, jm, None
    elif not lo <= value <= math.sqrt(c.y_hi[j]) / B_FACTOR:
        # the fitted curve misses the measured points at its minimum (a poor fit): read the measured curve
        value, j, k = math.sqrt(c.y[jm]) / B_FACTOR, jm, None
        lo = math.sqrt(c.y[j] * (c.y[j] / c.y_hi[j])) / B_FACTOR
        rule = ("min of the measured ADEV / 0.664 (IEEE Std 952-1997 C.2): the fitted curve misses the measured "
                "points at its minimum")
    return {
        "value": value, "unit": "deg/h", "tau_s": float(grid[k] if k is not None else c.tau[j]),
        "bound_only": bool(at_edge),
        "lo95": None if at_edge else lo, "hi95": math.sqrt(c.y_hi[j]) / B_FACTOR, "rule": rule,
    }


def _drop_rejected(c: FitContext, prob, res, best, plausible_delta=6.0):
    """Re-select without every selected term its own checks reject.  Returns ``(best, {index: NoiseTerm})`` with
    the dropped terms' entries (status ``not_estimable``, the bound and the reason).

    * A flat B floor above the measured curve's minimum (:func:`_check_floor`) is always dropped: the data
      contradict it.
    * A term at its ~4-sigma data bound (one point sets it) is dropped when a model without it is plausible (IC
      within ``plausible_delta`` of the current one): then nothing but that one point asks for the value.  When
      every model without it is far worse the term stays, named in the notes (:func:`_at_bound_notes`): the data
      need it, and its value is the largest they allow.
    """
    dropped = {}
    ic_now = res[best]["ic"]
    for _ in range(len(_names())):
        a = res[best]["a"]
        bad = None
        iB = _names().index("B")
        if iB in best and "B" in c.laws:
            tmp = {}
            _check_floor(tmp, c, a)
            if "B" in tmp:
                bad = (iB, tmp["B"])
        if bad is None:
            for i in best:
                u = float(prob.upper[i])
                if u > 0 and a[i] >= (1.0 - 1e-3) * u and len(best) > 1:
                    name = _names()[i]
                    ub_pt = point_limits(prob.y, prob.nu)
                    k = int(np.nanargmin(np.where(prob.X[:, i] > 0, ub_pt / np.where(prob.X[:, i] > 0, prob.X[:, i], 1),
                                                  np.inf)))
                    if name in c.laws:
                        conv = TERM_TABLE[name].to_unit / math.sqrt(c.laws[name].scale(c.dt))
                        bound, unit = conv * math.sqrt(u), DISPLAY_UNITS[name]
                    elif name == "S":
                        bound, unit = math.sqrt(u), "deg/h"
                    else:
                        bound, unit = math.sqrt(u) / max(c.tc_s or 1.0, 1e-300), "deg/h/√s"
                    bad = (i, NoiseTerm(
                        name, None, TERM_TABLE[name].unit if name in TERM_TABLE else unit, None, bound,
                        "not_estimable",
                        f"left out of the model: its fit ran into its data bound ({bound:.4g} {unit}, set by the "
                        f"point at tau = {c.tau[k]:.3g} s alone), so the data bound it but do not measure it; "
                        f"the model was re-selected without it"))
                    break
        if bad is None:
            break
        i, term = bad
        keep = [k for k in res if not any(j in k for j in dropped) and i not in k]
        if not keep:
            break
        alt = min(keep, key=lambda k: res[k]["ic"])
        if _names()[i] != "B" and not ic_within(res[alt]["ic"], ic_now, plausible_delta):
            break  # the data need the term: it stays at its bound (noted)
        dropped[i] = term
        best = alt
        nz = tuple(j for j in best if res[best]["a"][j] > 0)
        if nz and nz != best and nz in res:
            best = nz
    return best, dropped


def _q_at_whole_periods(c: FitContext, prob, best, A, d2, periodic, out_terms) -> None:
    """Quantization and a periodic error both fall like tau^-2 below the period, and lines the spectrum did not
    detect (the weak harmonics of a sawtooth) add exactly such a tail; only the taus from the shortest period on
    (where every line of a component vanishes at its whole periods) tell them apart.  A Q the fit resolves is kept
    resolved only if it is still resolved from zero on those taus alone; otherwise it is reported unresolved with
    that reason (lower bound 0)."""
    iQ, iS = _names().index("Q"), _names().index("S")
    p_min = min(periodic.periods_s) if periodic is not None and periodic.periods_s else None
    if p_min is None:
        return
    # a real line is no perfect sinusoid (its amplitude and frequency wander, which fills its nulls): a Q that does
    # not stand clearly above the lines' envelope at some fitted tau is not told apart from them at any tau (the one
    # rule of both noise fits, noise.periodic.q_stands_above_lines)
    q_var = A[iQ] * c.laws["Q"].shape(c.tau, c.dt)
    env = A[iS] * periodic_shape(c.tau, c.lines, c.dt, c.statistic, envelope=True)
    above, ratio = q_stands_above_lines(q_var, env)
    if not above:
        t = out_terms["Q"]  # not claimed at all (no value): beside a line, a Q below its envelope is no Q
        out_terms["Q"] = NoiseTerm(
            "Q", None, t.unit, 0.0, t.hi95, "absent",
            f"not claimed beside the periodic error: its variance is at most {ratio:.3g}x the lines' own envelope "
            f"(each line's law with sin^4 replaced by 1) at the fitted taus, not the {Q_OVER_ENVELOPE:g}x it must "
            "stand above it, and a real line's wandering amplitude and frequency fill its nulls; notch the line to "
            "read Q")
        return
    k0 = int(np.searchsorted(c.tau, p_min * (1 - 1e-9)))
    if c.tau.size - k0 < len(best) + 1:
        lo = 0.0
    else:
        sub = ScoreProblem(prob.X[k0:], prob.y[k0:], _sub_cov(prob, k0), prob.upper, prob.extra_var)
        a, q_sub = sub.fit(best)
        full = np.zeros(len(_names()))
        full[list(best)] = a
        lo = profile_interval(sub, best, full, iQ, q_sub, d2)[0] if full[iQ] > 0 else 0.0
    if lo > 0:
        return
    t = out_terms["Q"]
    out_terms["Q"] = NoiseTerm("Q", t.value, t.unit, 0.0, t.hi95, "unresolved",
                               f"not resolved from zero at whole periods of the periodic error (tau >= {p_min:.3g} s), "
                               "where a line adds nothing: below the period quantization and the periodic error "
                               "(with its undetected weak lines) are not told apart")


def _sub_cov(prob, k0):
    """The relative covariance of the points from ``k0`` on, rebuilt from the problem's EDF and whitening."""
    L = np.linalg.inv(prob.W)
    R = L @ L.T
    sd = np.sqrt(2.0 / prob.nu)
    C = R * np.outer(sd, sd)
    return C[k0:, k0:]
