"""Tables of strings with units: noise coefficients, one-step metrics and the paper-measure sentences.

Nothing here prints or writes; the console (:mod:`fogdrift.cli`) and the HTML report use the same rows.
"""

from __future__ import annotations

from .._util import fmt_number
from ..noise.terms import TERM_HEADERS, TERMS

NOISE_HEADERS = tuple(TERM_HEADERS[name] for name in TERMS)

METRICS_HEADERS = (
    "model",
    "RMSE [deg/h]",
    "MAE [deg/h]",
    "max|e| [deg/h]",
    "MASE",
    "skill vs persistence",
    "p0 [%]",
    "p0_w [%]",
    "p0 as measured [%] (persistence)",
)


def _fmt(x, digits=4) -> str:
    """A table cell: :func:`fogdrift._util.fmt_number`, scientific below 1e-3 and from 1e4, NaN as ``NaN``."""
    return fmt_number(x, digits, nonfinite="NaN", sci_outside=(1e-3, 1e4))


def term_text(term) -> str:
    """``value [lo95, hi95]`` for a term in the model; ``- (< hi95)`` for one that is not; ``n/e`` when the data
    cannot support a number (the reason is in the notes)."""
    if term.value is None or term.status == "no_fit":  # a model that does not fit claims no value
        if term.status == "not_estimable":
            return "n/e" if term.hi95 is None else f"n/e (< {_fmt(term.hi95, 3)})"
        return "–" if term.hi95 is None else f"– (< {_fmt(term.hi95, 3)})"
    text = _fmt(term.value)
    if term.lo95 is not None and term.hi95 is not None:
        text += f" [{_fmt(term.lo95, 3)}, {_fmt(term.hi95, 3)}]"
    return text


def noise_row(noise) -> list[str]:
    """Five cells Q, N, B, K, R of a NoiseFit (95 % intervals in brackets; – = not in the model, with its upper
    bound; n/e = not estimable).

    One B per row, one definition: the IEEE reading min ADEV / 0.664 (:func:`b_headline`).  When no model fits
    (``noise.no_fit``) no coefficient of the best candidate is shown: a term whose own slope holds over at least an
    octave shows its labelled slope read-out (``≈ 2.33 read-out``), and every cell its true bound (the measured
    curve's own, ``< x``)."""
    no_fit = getattr(noise, "no_fit", None)
    cells = []
    for name in TERMS:
        t = noise.terms[name]
        if name == "B":
            cells.append(b_headline(noise))
        elif no_fit:
            cells.append(_no_fit_cell(noise, name, t))
        else:
            cells.append(term_text(t))
    return cells


def _readout(noise, name):
    """The slope read-out of a term held over at least an octave (a run), or None."""
    ro = (getattr(noise, "readouts", None) or {}).get(name)
    if ro is None or ro.value is None or getattr(ro, "tau_range_s", None) is None:
        return None
    return ro


def _no_fit_cell(noise, name, t) -> str:
    ro = _readout(noise, name)
    if ro is None:
        return "–" if t.hi95 is None else f"– (< {_fmt(t.hi95, 3)})"
    return f"≈ {_fmt(ro.value, 4)} read-out" + ("" if t.hi95 is None else f" (< {_fmt(t.hi95, 4)})")


def b_headline(noise) -> str:
    """The one bias-instability cell of a row: the IEEE reading min ADEV / 0.664 -- ``39.2 [35, 44] at τ 117 s``,
    ``< 28.3`` where the curve has no minimum (a bound) -- named by its rule in the table's caption.  When no
    model fits, the minimum of the *measured* ADEV (``≈ 43.9 read-out at τ 82 s``).  Where the statistic has no
    such reading, the B term's own cell (the flicker coefficient, labelled)."""
    t = noise.terms.get("B")
    if getattr(noise, "no_fit", None):
        ro = (getattr(noise, "readouts", None) or {}).get("B")
        if ro is not None and ro.value is not None:
            return f"≈ {_fmt(ro.value, 3)} read-out at τ {_fmt(ro.tau_s, 3)} s"
        return "–" if t is None or t.hi95 is None else f"– (< {_fmt(t.hi95, 3)})"
    b = noise.b_min or {}
    if b.get("value") is not None:
        if b.get("bound_only"):
            return f"< {_fmt(b['value'], 3)}"
        iv = (f" [{_fmt(b['lo95'], 3)}, {_fmt(b['hi95'], 3)}]" if b.get("lo95") is not None
              and b.get("hi95") is not None else "")
        return f"{_fmt(b['value'], 3)}{iv} at τ {_fmt(b.get('tau_s'), 3)} s"
    if t is not None and t.value is not None:
        return term_text(t) + " flicker"
    return term_text(t) if t is not None else "–"


def shaped_cell(noise) -> str:
    """The IEEE-952 Annex C terms that are no power law, when the selected model holds them:
    ``S 8.0 deg/h @ 20.02 Hz`` and ``M σ 3.1 deg/h, T_c 48 [35, 70] s`` (``–`` when neither, or when no model
    fits)."""
    parts = []
    sh = getattr(noise, "shaped", None) or {}
    ts = noise.terms.get("S")
    if ts is not None and ts.value is not None and "S" in noise.selected:
        parts.append(f"S {_fmt(ts.value, 3)} deg/h @ {sh['S']['freq_hz']:.4g} Hz")
    tm = noise.terms.get("M")
    if tm is not None and tm.value is not None and "M" in noise.selected and sh.get("M", {}).get("tc_s"):
        m = sh["M"]
        lo, hi = m.get("tc_lo95_s"), m.get("tc_hi95_s")
        if not (lo and hi) or not tm.lo95:  # a T_c or q_c the data do not bound is no number to print
            parts.append("M in the model, not resolved (T_c not bounded by the data)")
        else:
            parts.append(f"M σ {_fmt(m['sigma_dph'], 3)} deg/h, T_c {_fmt(m['tc_s'], 3)} [{_fmt(lo, 2)}, "
                         f"{_fmt(hi, 2)}] s")
    if getattr(noise, "no_fit", None):  # no headline value from a model that misses the curve (notes have them)
        return "–"
    return "; ".join(parts) if parts else "–"


def b_min_cell(noise) -> str:
    """The IEEE bias-instability reading (min of the fitted ADEV / 0.664) as a cell: ``39.2 at τ = 117 s``, or
    ``< x (why)`` when the value is only an upper bound; ``–`` when the statistic has no such reading."""
    b = noise.b_min or {}
    if b.get("value") is None:
        return "–"
    if b.get("bound_only"):
        why = "fitted floor above the measured curve" if "measured curve" in b.get("rule", "") else \
            "curve still falling"
        return f"< {_fmt(b['value'], 3)} ({why})"
    return f"{_fmt(b['value'], 3)} at τ = {_fmt(b.get('tau_s'), 3)} s"


def fit_cell(noise) -> str:
    """Short fit-quality cell of a table row: the fit verdict, chi2_red and the fitted tau range
    (the Table 2 rows are fitted on short blocks and smoothed signals: how well each fits is part of the row)."""
    if noise.chi2_red is None:
        return "–"
    if getattr(noise, "no_fit", None):
        return (f"no model fits (χ²ᵣ {_fmt(noise.chi2_red, 2)}, τ {_fmt(noise.tau_min_s, 2)}–"
                f"{_fmt(noise.tau_max_s, 2)} s)")
    return (f"{noise.quality} (χ²ᵣ {_fmt(noise.chi2_red, 2)}, τ {_fmt(noise.tau_min_s, 2)}–"
            f"{_fmt(noise.tau_max_s, 2)} s)")


def fit_summary(noise) -> str:
    """One line: the selected model, the fit statistic and p-value, the fitted tau range."""
    head = (f"no model fits; best candidate {'+'.join(noise.selected) or '(none)'} of {len(noise.candidates)}"
            if getattr(noise, "no_fit", None) else
            f"model {'+'.join(noise.selected) or '(none)'} selected from {len(noise.candidates)} candidates")
    return (f"{head}; "
            f"chi2_red {_fmt(noise.chi2_red, 3)} on {noise.dof} dof (p = {noise.p_value:.2g}, fit {noise.quality}); "
            f"fitted tau {_fmt(noise.tau_min_s, 3)} .. {_fmt(noise.tau_max_s, 3)} s")


def readout_text(noise) -> str:
    """The classic IEEE-952 slope read-outs, labelled as a cross-check (with where each was read)."""
    parts = [ro.text() for ro in noise.readouts.values() if ro.value is not None]
    return "; ".join(parts) if parts else "no term's slope is visible in the curve"


def noise_notes(noise) -> list[str]:
    """Everything a reader needs beside the table, in words: fit quality, what was left out and why, the
    classical bias instability, each term that is not resolved and why, outliers."""
    out = [fit_summary(noise)]
    for e in noise.excluded:
        out.append(f"left out tau {_fmt(e['tau_min_s'], 3)} .. {_fmt(e['tau_max_s'], 3)} s: {e['reason']}")
    out += list(noise.notes)
    sh = getattr(noise, "shaped", None) or {}
    m = sh.get("M") or {}
    tm = noise.terms.get("M")
    if m.get("tc_s") and tm is not None and tm.value is not None:
        lo, hi = m.get("tc_lo95_s"), m.get("tc_hi95_s")
        out.append(f"M (exponentially correlated, IEEE-952 C.6): q_c = {_fmt(tm.value, 3)} [{_fmt(tm.lo95, 3)}, "
                   f"{_fmt(tm.hi95, 3)}] deg/h/√s, T_c = {_fmt(m['tc_s'], 3)} s (95 %: "
                   f"{_fmt(lo, 3) + ' s' if lo else 'below the searched range'} .. "
                   f"{_fmt(hi, 3) + ' s' if hi else 'beyond the searched range'}), "
                   f"sigma = q_c sqrt(T_c/2) = {_fmt(m.get('sigma_dph'), 3)} deg/h")
    ts = noise.terms.get("S")
    if sh.get("S") and ts is not None and ts.value is not None:
        out.append(f"S (sinusoidal, IEEE-952 C.7): Omega0 = {_fmt(ts.value, 3)} [{_fmt(ts.lo95, 3)}, "
                   f"{_fmt(ts.hi95, 3)}] deg/h at {sh['S']['freq_hz']:.4g} Hz (the strongest line; the other lines "
                   "keep their spectral ratios)")
    b = noise.b_min or {}
    if b.get("value") is not None:
        if b.get("bound_only"):
            why = ("the fitted flat floor lies above the measured curve, so the measured minimum bounds it"
                   if "measured curve" in b.get("rule", "") else "the curve still falls at the longest tau")
            out.append(f"bias instability (IEEE reading at the ADEV minimum): B_min < {_fmt(b['value'], 3)} deg/h "
                       f"(min at tau = {_fmt(b['tau_s'], 3)} s; {why})")
        else:
            which = "measured" if "measured ADEV" in b.get("rule", "") else "fitted"
            out.append(f"bias instability (IEEE reading, min of the {which} ADEV / 0.664): B_min = {_fmt(b['value'], 3)} "
                       f"deg/h at tau = {_fmt(b['tau_s'], 3)} s")
    tb = noise.terms.get("B")
    if tb is not None and tb.value is not None and tb.status in ("resolved", "unresolved") and b.get("value") is not None:
        out.append(f"B detail (not the headline B): the fitted flicker coefficient is {term_text(tb)} deg/h; the "
                   "headline B is the IEEE reading min ADEV / 0.664")
    ros = [ro for n in TERMS if (ro := _readout(noise, n)) is not None]
    if getattr(noise, "no_fit", None) and ros:
        out.append("no model fits: the table's ≈ values are IEEE-952 read-outs along a term's own slope, held over "
                   "at least an octave (not a model): " + "; ".join(ro.text() for ro in ros))
    for t in noise.terms.values():
        if t.reason and t.status not in ("resolved", "no_fit"):
            out.append(f"{t.name}: {t.reason}")
    if noise.outliers and noise.outliers.get("count"):
        o = noise.outliers
        out.append(f"outliers: {o['count']} samples ({100 * o['fraction']:.3g} %) beyond {o['threshold_sigma']:g} "
                   f"robust sigma, action: {o['action']}")
    return out


def not_estimable_notes(noise) -> list[str]:
    """Kept for callers of the earlier API: the notes of :func:`noise_notes`."""
    return noise_notes(noise)


def metrics_rows(model_axis) -> list[list[str]]:
    """One row per model of the test-block metrics (paper target: the wavelet drift of the test block)."""
    rows = []
    for label, m in model_axis.metrics.items():
        p0m, p0p = model_axis.p0_as_measured.get(label, (float("nan"), float("nan")))
        rows.append([
            label, _fmt(m.rmse_dph), _fmt(m.mae_dph), _fmt(m.max_abs_dph), _fmt(m.mase), _fmt(m.skill),
            _fmt(m.p0_pct), _fmt(m.p0_weighted_pct), f"{_fmt(p0m, 5)} ({_fmt(p0p, 5)})",
        ])
    return rows


def causal_metrics_rows(model_axis) -> list[list[str]]:
    rows = []
    for label, m in model_axis.causal_metrics.items():
        rows.append([label, _fmt(m.rmse_dph), _fmt(m.mae_dph), _fmt(m.max_abs_dph), _fmt(m.mase), _fmt(m.skill),
                     _fmt(m.p0_pct), _fmt(m.p0_weighted_pct), "–"])
    return rows


