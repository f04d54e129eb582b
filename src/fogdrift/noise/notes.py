"""The words of a noise fit (:func:`fogdrift.noise.identify`): why short taus were left out, where and how the model
misses the curve, the "no model fits" note, the largest model/data gap, terms at their data bound, and the reason
for every term that is not resolved or not in the model.

These functions only describe a fit the procedure in :mod:`.identify` has made; they change no number of it.
"""

from __future__ import annotations

import math

import numpy as np

from .context import FitContext, point_limits
from .checks import _points_outside
from .distributions import chi2_ppf
from .spectral import sinusoid_avar
from .terms import DISPLAY_UNITS, all_terms

_names = all_terms  # the fit's columns: Q N B K R (then any registered power-law term), S, M


def _tau_span(lo: float, hi: float) -> str:
    """``"0.64"`` for one point, ``"0.64-5.12"`` for a range (3 significant digits)."""
    a, b = f"{lo:.3g}", f"{hi:.3g}"
    return a if a == b else f"{a}-{b}"


def _slope(tau, var):
    lt, ls = np.log(tau), 0.5 * np.log(var)
    if tau.size < 2:
        return math.nan
    return float(np.polyfit(lt, ls, 1)[0])


#: A spectral line is named as the reason for left-out taus only where its own Allan variance reaches this
#: fraction of the measured one at one of them (a 0.56-Hz line does not shape the curve at tau <= 0.08 s).
LINE_SHARE = 0.1


def _lines_that_matter(periodic, tau, y) -> list:
    """Phrases for the spectral lines of ``periodic`` whose sinusoid Allan variance (IEEE-952 C.5 law, the line's
    amplitude) is at least :data:`LINE_SHARE` of the measured variance ``y`` at some tau of ``tau``."""
    if periodic is None or len(tau) == 0:
        return []

    out = []
    for f, rel in periodic.lines:
        amp = periodic.ref_amplitude_dph * math.sqrt(rel)
        share = sinusoid_avar(np.asarray(tau, dtype=float), amp, f) / np.asarray(y, dtype=float)
        if np.nanmax(share) >= LINE_SHARE:
            out.append(f"spectral line at {f:.4g} Hz, {amp:.3g} deg/h")
    return out


def _describe_excluded(ctx: FitContext, start: int, sel, periodic=None, spectrum_given=False, rolloff_hz=None) -> str:
    """Why the short taus [0, start) were left out, in words.

    An oscillation is named by the real frequency of the spectral lines when the spectrum found any (the tau of a
    bump is no frequency estimate: a line at 72 Hz in a 100-Hz log puts it anywhere); a curve below the model is
    called an output filter only where the spectrum shows a roll-off (``rolloff_hz``)."""
    tau, y = ctx.tau[: start + 1], ctx.y[: start + 1]
    model = (ctx.X[: start + 1] @ sel["res"][sel["best"]]["a"])
    ratio = np.sqrt(y / model)  # ADEV data / model
    slope = _slope(tau[:-1], y[:-1]) if start >= 2 else _slope(tau, y)
    g = np.sqrt(y * tau)  # ADEV * sqrt(tau): flat for white noise
    sd = np.log(ctx.y_hi[: start + 1] / y) / (2 * 1.96)  # ~ relative sd of the ADEV
    # a bump: an interior maximum of ADEV*sqrt(tau) clearly (2 sd) above where the fit starts
    interior = [k for k in range(1, start) if g[k] > g[k - 1] and g[k] >= g[k + 1]
                and g[k] > g[start] * (1 + 2 * max(sd[k], 0.01))]
    i_max = max(interior, key=lambda k: g[k]) if interior else -1
    named = _lines_that_matter(periodic, tau[:-1] if start >= 1 else tau, y[:-1] if start >= 1 else y)
    if named:
        return f"{'; '.join(named)} (periodic content the fitted terms do not describe there), not a noise term"
    if i_max > 0:
        what = ("an oscillation, but the spectrum shows no line: not a noise term" if spectrum_given else
                "an oscillation or vibration; its frequency needs the spectrum of the series, not the tau of the "
                "bump")
        return f"a bump in the curve near tau = {tau[i_max]:.3g} s ({what})"
    if np.all(ratio[:-1] < 1.0) and slope > -0.5:
        if rolloff_hz is not None:
            why = f"an output low-pass / anti-alias filter (the spectrum rolls off above {rolloff_hz:.3g} Hz)"
        elif spectrum_given:
            why = "correlated samples (the spectrum shows no roll-off)"
        else:
            why = "correlated samples (no spectrum of the series was given to say more)"
        kind = (f"ADEV below the model with a slope of {slope:+.2f} (flatter than white noise's -0.5): {why}, "
                "not a noise term")
    elif slope < -1.0:
        kind = f"a slope of {slope:+.2f}, steeper than quantization's -1: not an IEEE-952 term"
    else:
        dev = ratio[:-1] - 1.0 if start >= 1 else ratio - 1.0
        k = int(np.argmax(np.abs(dev)))
        kind = (f"a shape no IEEE-952 term describes: the ADEV is {'above' if dev[k] > 0 else 'below'} the model by up "
                f"to {100 * abs(dev[k]):.2g} %, many times its statistical error there")
    return kind


def _worst_region(tau, z):
    """Contiguous run of |z| > 2 with the largest sum of z^2: (i0, i1) inclusive, or None."""
    best, cur = None, None
    for i, v in enumerate(z):
        if abs(v) > 2.0:
            if cur is None:
                cur = [i, i, 0.0]
            cur[1] = i
            cur[2] += v * v
        else:
            if cur is not None and (best is None or cur[2] > best[2]):
                best = cur
            cur = None
    if cur is not None and (best is None or cur[2] > best[2]):
        best = cur
    if best is None and z.size:
        i = int(np.argmax(np.abs(z)))
        best = [i, i, float(z[i] ** 2)]
    return None if best is None else (best[0], best[1])


def _misfit_note(tau, y, mu, z, quality, chi2_red, p) -> list:
    """The fit-quality note of a fit that is not good: where the model misses the curve most (the worst run of
    scores, :func:`_worst_region`), on which side and by how much, with a hint at the shape there."""
    i01 = _worst_region(tau, z)
    if i01 is None:
        return []
    i0, i1 = i01
    dev = np.sqrt(y[i0:i1 + 1] / mu[i0:i1 + 1]) - 1.0
    k = int(np.argmax(np.abs(dev)))
    side = "above" if dev[k] > 0 else "below"
    return [f"fit {quality}: chi2_red = {chi2_red:.3g} (p = {p:.2g}); the model misses the curve most at "
            f"tau = {_tau_span(tau[i0], tau[i1])} s, where the measured deviation is {side} the model by up to "
            f"{100 * abs(dev[k]):.0f} %" + _shape_hint(tau[i0:i1 + 1], y[i0:i1 + 1], dev)]


def _no_fit(tau, y, mu, nu, best, chi2_red):
    """The "no model fits" record and note: the points whose own 95 % interval misses the best candidate's value
    (:func:`~fogdrift.noise.checks._points_outside`).  Returns ``(no_fit, note)``, or ``(None, None)`` when every
    point holds the model."""
    miss = _points_outside(y, mu, nu)
    if not miss.size:
        return None, None
    no_fit = {"tau_min_s": float(tau[0]), "tau_max_s": float(tau[-1]),
              "miss_tau_s": [float(t) for t in tau[miss]],
              "best_candidate": "+".join(_names()[i] for i in best)}
    note = (f"no model fits tau {tau[0]:.3g}-{tau[-1]:.3g} s: the best candidate "
            f"({no_fit['best_candidate']}, chi2_red {chi2_red:.3g}) misses the measured curve outside "
            f"its 95 % intervals at tau = {', '.join(f'{t:.3g}' for t in tau[miss])} s; the "
            "coefficients are not a result (the table shows their upper bounds only)")
    return no_fit, note


#: A model deviation at least this many times the measured one (or below 1/this) at one point is named in the
#: notes whatever the fit statistic says.
GAP_NOTE_RATIO = 2.0


def _largest_gap_note(tau, y, mu, nu) -> list:
    """The point where the model's deviation is farthest, as a ratio, from the measured one, when that ratio is
    at least :data:`GAP_NOTE_RATIO` either way.  Chi-squared weighs each point by its EDF, so a long-tau point
    with few averaging intervals can sit 2x off and count little; a reader of the plot sees it at once, and the
    note says whether the gap is inside that point's own 95 % interval (chance) or not."""
    ratio = np.sqrt(mu / y)
    k = int(np.argmax(np.abs(np.log(ratio))))
    r, v = float(ratio[k]), float(nu[k])
    if max(r, 1.0 / r) < GAP_NOTE_RATIO or not np.isfinite(v) or v <= 0:
        return []
    lo, hi = chi2_ppf(0.025, v) / v, chi2_ppf(0.975, v) / v  # measured/true variance, 95 %
    inside = lo <= 1.0 / r**2 <= hi
    side = "above" if r > 1 else "below"
    verdict = ("inside that point's own 95 % interval: with so few averaging intervals the data cannot tell, so "
               "terms acting there rest on little" if inside else
               "outside that point's own 95 % interval: the model's shape is wrong there")
    return [f"largest gap: at tau = {tau[k]:.3g} s the model's deviation is {r:.2f}x the measured one ({side} it; "
            f"~{v:.2g} degrees of freedom), {verdict}"]


def _at_bound_notes(prob, A, best, tau, out_terms) -> list:
    """A selected term whose estimate sits at its upper bound (:meth:`FitContext._upper`): the value is set by one
    point of the curve (the term alone would exceed that point's ~4-sigma upper limit), not by the fit."""
    notes = []
    ub_pt = point_limits(prob.y, prob.nu)
    for i in best:
        u = float(prob.upper[i])
        if not (u > 0 and A[i] >= (1.0 - 1e-3) * u):
            continue
        name = _names()[i]
        t = out_terms[name]
        if t.value is None:  # refused afterwards (a floor above the measured curve): its reason says why
            continue
        k = int(np.nanargmin(ub_pt / prob.X[:, i]))
        notes.append(
            f"{name} = {t.value:.4g} {DISPLAY_UNITS.get(name, t.unit)} sits at its data bound: a larger {name} alone would "
            f"exceed the measured curve's ~4-sigma upper limit at tau = {tau[k]:.3g} s, so that one point sets the "
            f"value, not the fit as a whole; read it as the largest {name} the data allow")
    return notes


def _shape_hint(tau, y, dev) -> str:
    if tau.size >= 2 and np.any(dev < 0) and np.all(dev <= 0.05):
        return ("; the curve falls faster than the fitted terms allow (a correlated/Gauss-Markov component or "
                "bounded platform motion; `fogdrift noise` models Gauss-Markov terms)")
    if tau.size >= 2:
        return f"; local ADEV slope there {_slope(tau, y):+.2f}"
    return ""


def _unresolved_reason(name, lacking, plaus, res, ic_best) -> str:
    if lacking:
        alt = "+".join(_names()[i] for i in lacking[0])
        return (f"not resolved from zero: the model {alt} without {name} describes the curve about as well "
                f"(IC {res[lacking[0]]['ic'] - ic_best:+.1f})")
    return "not resolved from zero: its 95 % interval reaches 0"


def _absent_reason(c: FitContext, name, A, hi_a) -> str:
    """Why a term is not in the model: where would it show at its upper bound?"""
    law = c.laws[name]
    i = _names().index(name)
    grid = np.logspace(math.log10(c.tau[0]) - 4, math.log10(c.tau[-1]) + 4, 801)
    rest = sum(A[j] * c.laws[n].shape(grid, c.dt) for j, n in enumerate(_names()) if n in c.laws and j != i)
    dom = grid[hi_a * law.shape(grid, c.dt) >= rest]
    if law.power >= 0 and (dom.size == 0 or dom.min() > c.tau[-1]):
        where = "beyond the record" if dom.size == 0 else f"only beyond tau = {dom.min():.3g} s"
        return f"not in the model: at its upper bound it would dominate {where} (longest fitted tau {c.tau[-1]:.3g} s); a longer record can resolve it"
    if law.power < 0 and (dom.size == 0 or dom.max() < c.tau[0]):
        return f"not in the model: at its upper bound it would dominate only below the fitted range (tau < {c.tau[0]:.3g} s)"
    return "not in the model: the curve shows no sign of it in the fitted range"
