"""GMWM against the Allan fit of the same record: do their N and B readings agree, and if not, why.

:func:`compare_with_allan` takes a :class:`~fogdrift.gmwm.analysis.GmwmAxis` and the
:class:`~fogdrift.noise.NoiseFit` of the same axis (``fogdrift.noise.fit_noise`` on its Allan result) and
returns one line per quantity, in words, with the numbers of both sides.  Only the NoiseFit's public fields
are read (``terms["N"]``, ``b_min``, ``tau_max_s``, ``selected``), each with a fallback, so a
fit with more terms or fields compares the same.

Rules (95 % intervals; a bound ``B < x`` is the interval ``[0, x]``):

* **N**: GMWM's white-noise N and the Allan fit's N agree when their intervals overlap.
* **Q, K, R**: one line per term that either model holds: both hold it and the intervals overlap (agree), or
  one holds it and the other's 95 % bound admits its lower limit (agree in value), else they differ, with why;
  the terms neither holds are named together.
* **S, M**: the Allan fit's periodic term against GMWM's treatment of the line's scales; the Allan fit's
  exponentially correlated term against GMWM's GM correlation times.
* **B**: GMWM's headline B (:attr:`fogdrift.gmwm.ieee.IEEEResult.b_headline`: the flicker term, else the
  minimum of the model's ADEV) against the Allan fit's IEEE reading ``b_min`` (the minimum of its ADEV,
  or a bound where the curve still falls).  Two bounds agree (neither finds a minimum within the record).
  A GM hump's reading, when GMWM makes one, gets its own line: it is a reading of the hump, not of a floor.

Units: N in deg/sqrt(h), B in deg/h, tau in s.
"""

from __future__ import annotations

from .._util import fmt_number
from ..noise.terms import DISPLAY_UNITS, TERM_TABLE

__all__ = ["compare_with_allan"]


def _g(x, d=3):
    return fmt_number(x, d, nonfinite=None)


def _t(tau):
    """A time in s: four significant digits, no exponent below 10^4 s."""
    return "?" if tau is None else f"{tau:.4g}"


def _iv(lo, hi):
    return "" if lo is None or hi is None else f" [{_g(lo)}, {_g(hi)}]"


def _no_result_n_line(axis, fit):
    """The N line when either side has no result (no GMWM candidate passed / no Allan model fits): their bounds,
    and whether the other side's value lies inside them."""
    sel = axis.selection
    a = (getattr(fit, "terms", None) or {}).get("N")
    g_pass = not getattr(sel, "no_result", False)
    a_fit = getattr(a, "status", None) != "no_fit"
    gb = axis.data_bounds().get("N") if not g_pass else None
    g = sel.ieee.terms.get("N_dprh")
    g_txt = (f"GMWM: no candidate passed its checks (N < {_g(gb, 4)} deg/√h, the WV's own bound)" if not g_pass else
             f"GMWM {_g(g.value, 4)}{_iv(g.lo95, g.hi95)} deg/√h" if g is not None else "GMWM has no N")
    a_txt = (f"the Allan fit: no model fits (N < {_g(a.hi95, 4)} deg/√h, the curve's own bound)" if not a_fit else
             f"the Allan fit {_g(a.value, 4)}{_iv(a.lo95, a.hi95)} deg/√h" if a is not None and a.value is not None
             else "the Allan fit has no N")
    if not g_pass and not a_fit:
        return None, f"N: neither estimator has a result: {g_txt}; {a_txt}"
    a_est = a is not None and a.value is not None
    if (not g_pass and not a_est) or (not a_fit and g is None):  # two bounds (or one and nothing): no estimate
        if a is not None and not a_est and a_fit and a.hi95 is not None:
            a_txt = f"the Allan fit has no N (< {_g(a.hi95, 4)} deg/√h, its 95 % bound)"
        return None, f"N: no estimate on either side: {g_txt}; {a_txt}"
    if not g_pass:
        ok = gb is not None and (a.lo95 or a.value) <= gb
    else:
        ok = a.hi95 is not None and g.lo95 <= a.hi95
    return (ok, f"N {'is consistent' if ok else 'differs'}: {g_txt}; {a_txt}"
            + ("" if ok else "; the estimate lies above the other side's bound"))


def _n_line(axis, fit) -> tuple:
    sel = axis.selection
    g = sel.ieee.terms.get("N_dprh")
    a = (getattr(fit, "terms", None) or {}).get("N")
    if getattr(sel, "no_result", False) or getattr(a, "status", None) == "no_fit":
        return _no_result_n_line(axis, fit)
    a_val = getattr(a, "value", None)
    if g is None and a_val is None:
        return None, "N cannot be compared: neither GMWM nor the Allan fit has a white-noise term"
    if g is None:
        return False, (f"N differs: the GMWM model {sel.selected} has no white-noise term; the Allan fit finds N "
                       f"{_g(a_val, 4)}{_iv(a.lo95, a.hi95)} deg/√h")
    if a_val is None:
        why = getattr(a, "reason", "") or "not in its model"
        return False, (f"N differs: GMWM {_g(g.value, 4)}{_iv(g.lo95, g.hi95)} deg/√h; the Allan fit gives no N "
                       f"({why})")
    a_lo = a.lo95 if a.lo95 is not None else a_val
    a_hi = a.hi95 if a.hi95 is not None else a_val
    both = (f"GMWM {_g(g.value, 4)}{_iv(g.lo95, g.hi95)} deg/√h, the Allan fit {_g(a_val, 4)}"
            f"{_iv(a.lo95, a.hi95)} deg/√h")
    if g.lo95 <= a_hi and a_lo <= g.hi95:
        return True, f"N agrees: {both} (the 95 % intervals overlap)"
    scales = sel.fit.scale_s
    why = (f"GMWM {sel.selected} is fitted to wavelet scales {_t(scales[0])}-{_t(scales[-1])} s "
           f"({len(sel.excluded)} short excluded), the Allan fit {'+'.join(getattr(fit, 'selected', ())) or '?'} "
           f"to τ {_t(getattr(fit, 'tau_min_s', None))}-{_t(getattr(fit, 'tau_max_s', None))} s: "
           "the two models give the short-τ slope to different terms")
    if getattr(axis.wvar, "robust", False):
        why = ("GMWM used the robust (Huber) wavelet variance, which discounts the outlying samples the Allan "
               "variance keeps; " + why)
    return False, f"N differs by {_g(g.value / a_val)}x: {both}; {why}"


def _b_interval(value, lo, hi, bound):
    """``(lo, hi)`` of a reading (a bound is ``[0, bound]``); None when nothing is read."""
    if value is not None:
        return (lo if lo is not None else value, hi if hi is not None else value)
    if bound is not None:
        return (0.0, bound)
    return None


def _allan_b_text(ab, tau_max, *, interval) -> str:
    """The Allan fit's B_min reading in words (a value, a bound and why, or none)."""
    a_val = ab.get("value")
    if a_val is None:
        return "the Allan fit has no ADEV-minimum reading"
    if ab.get("bound_only"):
        if "measured curve" in str(ab.get("rule", "")):
            return f"the Allan fit gives B_min < {_g(a_val)} deg/h (its fitted floor lies above the measured curve)"
        return (f"the Allan fit finds no ADEV minimum within τ ≤ {_t(tau_max)} s (B_min < {_g(a_val)} deg/h)"
                if tau_max is not None else f"the Allan fit gives only B_min < {_g(a_val)} deg/h")
    iv = _iv(ab.get("lo95"), ab.get("hi95")) if interval else ""
    return f"the Allan fit's B_min is {_g(a_val)}{iv} deg/h at τ = {_t(ab.get('tau_s'))} s"


def _allan_b(fit) -> dict:
    """The Allan fit's B reading in ``b_min``'s shape: ``b_min`` (the fitted ADEV's minimum), or -- when no model
    fits -- the measured ADEV's minimum read-out, with no interval (the table shows the same)."""
    if getattr(fit, "no_fit", None):
        ro = (getattr(fit, "readouts", None) or {}).get("B")
        if ro is not None and ro.value is not None:
            return {"value": ro.value, "tau_s": ro.tau_s, "bound_only": False, "lo95": None, "hi95": None,
                    "rule": "measured ADEV minimum / 0.664 (no model fits)"}
        return {}
    return getattr(fit, "b_min", None) or {}


def _b_line(axis, fit) -> tuple:
    ie = axis.selection.ieee
    gb = ie.b_headline
    ab = _allan_b(fit)
    if getattr(axis.selection, "no_result", False):
        a_txt = _allan_b_text(ab, getattr(fit, "tau_max_s", None), interval=True)
        return None, f"B: GMWM has no result (no candidate passed its checks); {a_txt}"
    tau_max = getattr(fit, "tau_max_s", None)
    g_iv = _b_interval(gb.value_dph, gb.lo95_dph, gb.hi95_dph, gb.bound_dph)
    a_bound = bool(ab.get("bound_only"))
    a_val = ab.get("value")
    a_iv = None if a_val is None else (
        (0.0, a_val) if a_bound else (ab.get("lo95") if ab.get("lo95") is not None else a_val,
                                      ab.get("hi95") if ab.get("hi95") is not None else a_val))
    if gb.value_dph is not None:
        g_text = (f"GMWM B {_g(gb.value_dph)}{_iv(gb.lo95_dph, gb.hi95_dph)} deg/h"
                  + ("" if gb.tau_s is None else f" at τ = {_t(gb.tau_s)} s") + f" ({gb.label})")
    elif gb.bound_dph is not None:
        lo, hi = ie.tau_range_s
        g_text = f"GMWM B < {_g(gb.bound_dph)} deg/h (its model's ADEV has no minimum within τ {_t(lo)}-{_t(hi)} s)"
    else:
        g_text = f"GMWM reads no B ({gb.reason})"
    a_text = _allan_b_text(ab, tau_max, interval=True)
    if g_iv is None or a_iv is None:
        return None, f"B cannot be compared: {g_text}; {a_text}"
    agree = g_iv[0] <= a_iv[1] and a_iv[0] <= g_iv[1]
    if agree and gb.value_dph is None and a_bound:
        return True, f"B agrees, both only as upper bounds: {g_text}; {a_text}"
    if agree:
        return True, f"B agrees: {g_text}; {a_text} (the 95 % ranges overlap)"
    if gb.value_dph is None or a_bound:
        why = ("one of them reaches an ADEV minimum inside the record and the other does not: the models bend "
               "the longest τ differently")
    else:
        why = "the GMWM model and the Allan fit put the ADEV minimum at different heights"
    return False, f"B differs: {g_text}; {a_text}; {why}"


def _hump_line(axis, fit):
    b = axis.selection.ieee.b_gm
    if b is None or b.value_dph is None:
        return None
    ab = _allan_b(fit)
    tail = _allan_b_text(ab, getattr(fit, "tau_max_s", None), interval=False)
    return (f"GMWM B {_g(b.value_dph, 4)} deg/h at τ = {_t(b.tau_s)} s is read from a GM hump ({b.label.split('(')[-1]}:"
            f" a detail, not a bias-instability floor; {tail}")


def compare_with_allan(axis, noise_fit) -> dict:
    """N and B of a GMWM axis against the Allan fit of the same record.

    Parameters
    ----------
    axis : GmwmAxis
    noise_fit : fogdrift.noise.NoiseFit
        The Allan fit of the same axis (``fogdrift.noise.fit_noise(allan_variance(...))``).

    Returns
    -------
    dict
        ``{"agree": bool or None, "n_agree", "b_agree": bool or None, "lines": [str, ...]}``; ``agree`` is
        True when every comparable quantity agrees, None when nothing could be compared.  Each line is one
        sentence with the numbers and units of both sides and, when they differ, why.

    Examples
    --------
    >>> from fogdrift.gmwm import simulate_latent
    >>> from fogdrift.gmwm.analysis import analyse_gmwm
    >>> from fogdrift.allan import allan_variance
    >>> from fogdrift.noise import fit_noise
    >>> x = simulate_latent("WN", [1.0], 2**15, seed=1)               # deg/h at dt = 0.01 s
    >>> c = compare_with_allan(analyse_gmwm("x", x, 0.01, model="WN"), fit_noise(allan_variance(x, 0.01)))
    >>> c["n_agree"], c["lines"][0].startswith("N agrees")
    (True, True)
    """
    n_ok, n_line = _n_line(axis, noise_fit)
    b_ok, b_line = _b_line(axis, noise_fit)
    lines = [n_line, b_line]
    hump = _hump_line(axis, noise_fit)
    if hump:
        lines.append(hump)
    term_ok = {}
    quiet = []
    for name in ("Q", "K", "R"):
        ok, line = _power_line(axis, noise_fit, name)
        term_ok[name] = ok
        if line is None:
            quiet.append(name)
        else:
            lines.append(line)
    if quiet:
        lines.append(f"{', '.join(quiet)} agree{'s' if len(quiet) == 1 else ''}: neither estimator claims "
                     f"{'it' if len(quiet) == 1 else 'them'}")
    for name, fn in (("S", _s_line), ("M", _m_line)):
        ok, line = fn(axis, noise_fit)
        term_ok[name] = ok
        if line:
            lines.append(line)
    known = [v for v in (n_ok, b_ok, *term_ok.values()) if v is not None]
    return {"agree": (all(known) if known else None), "n_agree": n_ok, "b_agree": b_ok,
            "term_agree": term_ok, "lines": lines}


def _power_line(axis, fit, name) -> tuple:
    """Q, K or R of both estimators, in the Allan fit's unit (GMWM's K unit deg/h/sqrt(h) is deg/h^1.5).

    ``(None, None)`` when neither model holds the term; ``(True, line)`` when both do and their 95 % intervals
    overlap, or when only one does but the other's 95 % bound admits its lower limit (the data allow both
    readings); ``(False, line)`` otherwise, with the numbers of both sides."""
    spec = TERM_TABLE[name]
    g = axis.selection.ieee.terms.get(name + spec.suffix)
    if getattr(axis.selection, "no_result", False):
        g = None  # no candidate passed: the fallback's terms are no claim
    a = (getattr(fit, "terms", None) or {}).get(name)
    a_in = a is not None and a.value is not None and a.status in ("resolved", "unresolved")
    unit = DISPLAY_UNITS[name]
    if g is None and not a_in:
        return None, None
    g_txt = "GMWM " + (f"{_g(g.value, 4)}{_iv(g.lo95, g.hi95)} {unit}" if g is not None else
                       f"has no {spec.long_name} in {axis.selection.selected}")
    if a_in:
        a_txt = f"the Allan fit {_g(a.value, 4)}{_iv(a.lo95, a.hi95)} {unit} ({a.status})"
    else:
        why = "no model fits its curve" if getattr(a, "status", "") == "no_fit" else "not in its model"
        a_txt = (f"the Allan fit {why}" + (f" (95 % bound < {_g(a.hi95)} {unit})" if a is not None
                                          and a.hi95 is not None else ""))
    if g is not None and a_in:
        lo_a = a.lo95 if a.lo95 is not None else a.value
        hi_a = a.hi95 if a.hi95 is not None else a.value
        ok = g.lo95 <= hi_a and lo_a <= g.hi95
        return ok, (f"{name} {'agrees' if ok else 'differs'}: {g_txt}, {a_txt}"
                    + ("" if ok else " (the 95 % intervals do not overlap)"))
    if g is not None:  # only GMWM holds it
        bound = None if a is None else a.hi95
        ok = bound is not None and g.lo95 <= bound
        why = (f"the Allan bound admits GMWM's lower limit {_g(g.lo95)} {unit}: the data allow both readings"
               if ok else "GMWM's 95 % interval lies above the Allan fit's bound: the two models give the curve's "
               "shape to different terms (see each estimator's notes)")
        return ok, f"{name} {'agrees in value' if ok else 'differs'}: {g_txt}; {a_txt}; {why}"
    lo_a = a.lo95 if a.lo95 is not None else 0.0
    ok = lo_a <= 0.0
    why = ("its interval reaches 0, so GMWM's model without it is consistent" if ok else
           "GMWM's model has no such process (its notes say which candidates held one and why they failed)")
    return ok, f"{name} {'agrees in value' if ok else 'differs'}: {a_txt}; {g_txt}; {why}"


def _s_line(axis, fit) -> tuple:
    """The periodic term S: the Allan fit models spectral lines as S; GMWM has no sinusoid process and leaves the
    scales a line dominates out of its fit."""
    a = (getattr(fit, "terms", None) or {}).get("S")
    if a is None or a.value is None or "S" not in (getattr(fit, "selected", ()) or ()):
        return None, None
    sh = (getattr(fit, "shaped", None) or {}).get("S") or {}
    f = sh.get("freq_hz")
    excl = [x for x in axis.selection.excluded if "spectral line" in (getattr(x, "reason", "") or "")]
    how = (f"GMWM leaves out the {len(excl)} scale(s) it dominates" if excl else
           "GMWM has no sinusoid process (its WV at the line's scales is part of its fit)")
    return True, (f"S: the Allan fit models the periodic error as S {_g(a.value)}{_iv(a.lo95, a.hi95)} deg/h at "
                  f"{_g(f, 4)} Hz; {how}: both keep it out of the noise terms")


def _gm_times(axis) -> list:
    """``[(label, T_c [s]), ...]`` of the GM components of the selected GMWM model (none when it has no fit)."""
    fit = getattr(axis.selection, "fit", None)
    if not hasattr(fit, "latent_model"):
        return []
    mdl = fit.latent_model
    return [(lab, fit.dt_s / fit.theta[sl.start]) for lab, sl, key in zip(mdl.labels, mdl.slices, mdl.components)
            if key == "GM"]


def _m_line(axis, fit) -> tuple:
    """The exponentially correlated term: Allan's M against GMWM's GM components, by correlation time."""
    a = (getattr(fit, "terms", None) or {}).get("M")
    a_in = a is not None and a.value is not None and "M" in (getattr(fit, "selected", ()) or ())
    gms = _gm_times(axis)
    if not a_in and not gms:
        return None, None
    g_txt = ("GMWM " + ", ".join(f"{lab} T_c {_g(tc)} s" for lab, tc in gms)) if gms else "GMWM has no GM"
    if not a_in:
        return None, (f"M: {g_txt}; the Allan fit has no M (its flicker/power-law terms describe the same part of "
                      "the curve; a GM is how GMWM and a Kalman filter express bias instability)")
    sh = (getattr(fit, "shaped", None) or {}).get("M") or {}
    tc, lo, hi = sh.get("tc_s"), sh.get("tc_lo95_s"), sh.get("tc_hi95_s")
    a_txt = f"the Allan fit M T_c {_g(tc)} s" + (f" [{_g(lo)}, {_g(hi)}]" if lo and hi else "")
    if not gms:
        return False, f"M differs: {a_txt}; {g_txt} (it reads the same part of the curve with other processes)"
    ok = any((lo or 0.0) <= t <= (hi or float('inf')) for _, t in gms) if tc else None
    return ok, (f"M {'agrees' if ok else 'differs'}: {a_txt}; {g_txt}"
                + ("" if ok else " (no GM correlation time inside the Allan fit's T_c interval)"))
