"""The report's first screen, as data: the recording, the headline noise coefficients, one compensation verdict
per axis, and what the record cannot support.

Every function returns plain rows of strings (units in the labels) or dicts, so the same content goes into
``report.html`` and into ``analysis.json`` (key ``report_summary``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..evaluation.verdicts import MIN_ORIGINS, independent_origins
from ..noise import TERM_TABLE
from ..noise.terms import DISPLAY_UNITS, TERMS
from ..signal import record_sampling, record_units
from ..spec import B_COMPARED, judgement_line
from ..units import S_PER_H
from .screen import screen_summary
from .tables import _fmt, noise_row, shaped_cell, term_text

__all__ = ["HEADLINE_TERMS", "OUTCOME_LABELS", "SPEC_LABELS", "SPEC_OUTCOMES", "recording_rows", "noise_headline",
           "verdict_items", "cannot_support", "summary_dict", "spec_summary"]

#: Terms of the headline table, in the order an engineer reads them (white noise first, quantization last).
HEADLINE_TERMS = ("N", "B", "K", "R", "Q")

#: Outcome of a headline verdict -> badge text (the colour is never the only signal).
OUTCOME_LABELS = {"reduces": "REDUCES", "mixed": "MIXED", "none": "NO GAIN", "undetermined": "CANNOT JUDGE"}


#: Datasheet verdict (:func:`fogdrift.spec.judge`) -> badge text, and the outcome class whose colour it borrows
#: (pass green, fail red, cannot tell grey; the badge text says it, the colour is never the only signal).
SPEC_LABELS = {"pass": "PASS", "fail": "FAIL", "cannot tell": "CANNOT TELL"}
SPEC_OUTCOMES = {"pass": "reduces", "fail": "none", "cannot tell": "undetermined"}


def _duration(seconds) -> str:
    """``1847 s (30.8 min)``, ``10000 s (2.78 h)``."""
    if seconds is None:
        return "–"
    s = float(seconds)
    if s >= 7200:
        return f"{s:.6g} s ({s / S_PER_H:.3g} h)"
    if s >= 120:
        return f"{s:.6g} s ({s / 60:.3g} min)"
    return f"{s:.6g} s"


def _effective_rate(result) -> str:
    """The modelling rate actually used: the averaged record's rate and its block-average factor."""
    smp = record_sampling(getattr(result, "model_record", None), "the model_record")
    if smp is None:
        return "native rate"
    fs, k, native = smp.rate_hz, smp.block_average_factor, smp.native_rate_hz
    return f"{fs:.6g} Hz (native {native:.6g} Hz averaged in blocks of {k})" if k > 1 else f"{fs:.6g} Hz (native)"


def _unit_text(rec: dict) -> str:
    units = record_units(rec, "the record")
    unit = units.input_unit if units is not None else "?"
    declared = [u for u in units.declared_units if u] if units is not None else []
    how = "declared in the file's header" if declared else "given by the user (--unit)"
    return f"{unit} ({how}); converted to deg/h" if unit != "deg/h" else f"deg/h ({how})"


def recording_rows(result, sensor: str | None = None) -> list:
    """``[label, value]`` rows describing the recording: file, sensor, duration, rate, axes, units."""
    rec = result.record
    smp = record_sampling(rec, "the record")
    return [
        ["file", Path(str(result.source)).name],
        ["sensor", sensor or "not stated (the log does not carry it; analyze --sensor names it)"],
        ["duration", f"{_duration(rec.get('duration_s'))}, {rec.get('n_samples')} samples"],
        ["sample rate", f"{smp.native_rate_hz:.6g} Hz (dt {smp.dt_s:.6g} s)" if smp else "–"],
        ["axes", ", ".join(rec.get("axis_names", []))],
        ["rate unit", _unit_text(rec)],
        ["modelling rate", _effective_rate(result)],
    ]


def noise_headline(result) -> tuple:
    """``(headers, rows)``: one column per axis; rows N, B (one reading per axis, named by its rule), K, R, Q
    (value [95 % interval]), the periodic / Markov terms, the selected model (or "no model fits" with the best
    candidate), chi2_red with the fit quality, and the fitted tau range.

    The cells are the allan table's (:func:`~fogdrift.report.tables.noise_row`): when no model fits, every
    coefficient is an upper bound, never a value."""

    axes = list(result.axes)
    if axes and all(getattr(ax, "gmwm", None) is not None for ax in axes):
        return _gmwm_headline(axes)
    cut = [ax.name for ax in axes if (getattr(ax.original, "screen", None) or {}).get("segments_used")]
    headers = [("native rate (Allan fit); the quiet segments of " + ", ".join(cut) + " (see the screen)") if cut else
               "whole record, native rate (Allan fit)"] + [f"axis {ax.name}" for ax in axes]
    fits = [ax.original.noise for ax in axes]
    cells = [dict(zip(TERMS, noise_row(f))) for f in fits]
    rows = []
    for name in HEADLINE_TERMS:
        label = ("B bias instability: the IEEE reading min ADEV/0.664 [deg/h]"
                 if name == "B" else _term_label(name))
        rows.append([label] + [c[name] for c in cells])
    rows.append(["periodic / Markov terms (IEEE-952 Annex C)"] + [shaped_cell(f) for f in fits])
    rows.append(["selected noise model"] + [
        (f"no model fits (best candidate {'+'.join(f.selected) or 'none'})" if getattr(f, "no_fit", None)
         else "+".join(f.selected) or "(none)") for f in fits])
    rows.append(["χ²_red (fit quality, p)"] + [
        f"{_fmt(f.chi2_red, 3)} ({'no model fits' if getattr(f, 'no_fit', None) else f.quality}, p = {f.p_value:.2g})"
        for f in fits])
    rows.append(["fitted τ range [s]"] + [f"{_fmt(f.tau_min_s, 3)} – {_fmt(f.tau_max_s, 3)}" for f in fits])
    return headers, rows


def _term_label(name) -> str:
    """``"N angle random walk [deg/√h]"``: symbol, long name and displayed unit of a term."""

    spec = TERM_TABLE[name]
    return f"{spec.header.split(' [')[0]} {spec.long_name} [{spec.header.split('[')[1]}"


def _gmwm_headline(axes) -> tuple:
    """The headline table of ``analyze --noise-method gmwm``: the terms the selected GMWM model implies, its
    checks and J test, the scales it used, and the Allan fit's N beside it as a cross-check."""
    headers = ["whole record, native rate (GMWM)"] + [f"axis {ax.name}" for ax in axes]
    terms = [ax.gmwm.ieee_terms() for ax in axes]
    rows = []
    for name in HEADLINE_TERMS:
        if name == "B":  # one B per axis, named by its rule; a bound or nothing beyond the scales used (gmwm.ieee)
            rows.append(["B bias instability [deg/h]"] + [
                "no result (no candidate passed its checks)" if ax.gmwm.selection.no_result else
                f"{ax.gmwm.selection.ieee.b_headline.text(3)}; {ax.gmwm.selection.ieee.b_headline.label}"
                for ax in axes])
            continue
        rows.append([_term_label(name)] + [term_text(t[name]) for t in terms])
    rows.append(["selected noise model (WIC)"] + [f"{ax.gmwm.selection.selected} ("
                                                   + ("checks passed" if ax.gmwm.selection.passed_checks
                                                      else "checks failed: see the axis section") + ")"
                                                   for ax in axes])
    rows.append(["J test (J, dof, p)"] + [f"{_fmt(ax.gmwm.selection.fit.j_stat, 3)}, {int(ax.gmwm.selection.fit.df)}, "
                                           f"p = {ax.gmwm.selection.fit.j_pvalue:.2g}" for ax in axes])
    rows.append(["wavelet scales used [s]"] + [_scales_used(ax.gmwm) for ax in axes])
    rows.append(["cross-check: GMWM vs Allan fit"] + [" ".join(_allan_check(ax)["lines"]) for ax in axes])
    return headers, rows


def _allan_check(ax) -> dict:
    """The GMWM axis's comparison with the Allan fit of the same record, as the workflow made it."""

    return ax.gmwm.allan_check or {"lines": ["–"]}


def _scales_used(g) -> str:

    excluded = {e.level for e in g.selection.excluded}
    used = [s for lv, s in zip(np.asarray(g.wvar.level), np.asarray(g.wvar.scale_s)) if int(lv) not in excluded]
    if not used:
        return "–"
    text = f"{_fmt(min(used), 3)} – {_fmt(max(used), 3)} ({len(used)} scales)"
    return text + (f", {len(excluded)} short excluded" if excluded else "")


def verdict_items(result, *, evaluated: bool = True) -> list:
    """One dict per axis: ``axis``, ``outcome`` (reduces|mixed|none|undetermined), ``sentence``.

    Axes without an evaluation (``analyze --no-heading``) get the *undetermined* outcome with a sentence that
    says so.
    """
    items = []
    for ax in result.axes:
        ev = getattr(ax, "evaluation", None)
        if ev is None:
            why = "--no-heading" if not evaluated else "not run"
            items.append({"axis": ax.name, "outcome": "undetermined",
                          "sentence": f"{ax.name}: heading error not evaluated ({why}); no compensation verdict."})
        else:
            items.append({"axis": ax.name, "outcome": ev.outcome, "sentence": ev.headline.lines[0]})
    return items


def _term_limits(result) -> list:
    """Rows ``[axis, term, status, 95 % bound, reason]`` of every term that is not resolved."""

    rows = []
    for ax in result.axes:
        for name in HEADLINE_TERMS:
            t = ax.original.noise.terms[name]
            if t.status == "resolved":
                continue
            status = {"not_estimable": "not estimable (n/e)", "absent": "not in the model",
                      "unresolved": "in the model, interval reaches 0"}.get(t.status, t.status)
            bound = "–" if t.hi95 is None else f"< {_fmt(t.hi95, 3)} {DISPLAY_UNITS.get(name, t.unit)}"
            rows.append([ax.name, f"{name} ({TERM_TABLE[name].long_name})", status, bound, t.reason or "–"])
    return rows


def _grouped(items: list) -> list:
    """Identical statements of several axes once, prefixed by the axes: ``gx, gy: ...``."""
    order, axes_of = [], {}
    for axis, text in items:
        if text not in axes_of:
            order.append(text)
            axes_of[text] = []
        if axis not in axes_of[text]:
            axes_of[text].append(axis)
    return [f"{', '.join(axes_of[t])}: {t}" if axes_of[t] else t for t in order]


def _strip_axis(text: str, axis: str) -> str:
    return text[len(axis) + 2:] if text.startswith(f"{axis}: ") else text


def cannot_support(result) -> dict:
    """What the record cannot support: ``terms`` (rows of :func:`_term_limits`, with their headers) and
    ``items`` (sentences: horizons too long or with too few origins, evaluations skipped, the longest tau,
    metrics that are NaN by design)."""

    items = []
    for ax in result.axes:
        r = ax.original.allan
        items.append((ax.name, f"the Allan curve reaches τ = {_fmt(float(r.tau_s[-1]), 3)} s of a "
                               f"{_fmt(result.record.get('duration_s'), 4)}-s record: noise that shows only at longer τ "
                               "(slow rate random walk, ramp) is not observed"))
        ev = getattr(ax, "evaluation", None)
        ma = ax.models
        e, f = ma.split["test"]
        block = f"the held-out test block ({_fmt((f - e) * ma.dt_s, 4)} s)"
        if ev is not None:
            for note in ev.notes:
                items.append((ax.name, _strip_axis(note, ax.name)))
            h = ev.heading
            if h is not None:
                for note in h.notes:
                    items.append((ax.name, f"heading error: {note}"))
                base = {r.horizon_s: r for r in h.rows if r.model == "constant bias"}
                for hz in h.horizons_s:
                    n = base[hz].n_origins
                    k = independent_origins(n, h.step_s, hz)
                    if k < MIN_ORIGINS:
                        items.append((ax.name, f"heading error at {hz:g} s: {block} gives {n} origin(s), {k} with "
                                               f"non-overlapping horizons; a verdict needs {MIN_ORIGINS} (the numbers "
                                               "are shown, not judged)"))
            if ev.artefacts is not None:
                for note in ev.artefacts.notes:
                    if note.startswith("frequencies"):
                        items.append((ax.name, f"artefact check: {note}"))
        for note in ma.notes:
            if note.startswith("p0 is unstable near zero"):
                items.append((ax.name, "p0 [%] is NaN (the drift crosses zero in the test block; see the glossary: "
                                       "read p0_w, RMSE and MASE instead)"))
            else:
                items.append((ax.name, f"one-step metrics: {note}"))
    return {"term_headers": ["axis", "term", "status", "95 % bound", "why"], "terms": _term_limits(result),
            "items": _grouped(items)}


def spec_summary(limits: dict, judgements, source: str = "") -> dict:
    """The first screen's datasheet comparison as JSON-able data: ``title``, one ``items`` dict per judgement
    (``verdict``, ``outcome`` for its colour, ``line``: :func:`fogdrift.spec.judgement_line`, and the judgement's
    fields), ``b_compared`` (which B reading was compared, :data:`fogdrift.spec.B_COMPARED`) and ``note`` when no
    limit applies."""
    title = f"{limits['sensor'] or source}" + (f" ({source})" if limits["sensor"] and source else "")
    items = [{**j.to_dict(), "outcome": SPEC_OUTCOMES[j.verdict], "line": judgement_line(j)} for j in judgements]
    note = None if items else ("no limit applies to these channels (the spec has "
                               f"{', '.join(sorted({l.kind for l in limits['limits']}))} limits only)")
    return {"title": title, "items": items, "b_compared": B_COMPARED, "note": note}


def summary_dict(result, sensor: str | None = None, *, evaluated: bool = True, spec: dict | None = None) -> dict:
    """The first screen as JSON-able data (stored in ``analysis.json`` as ``report_summary``); ``spec``: the
    datasheet comparison (:func:`spec_summary`), under ``spec`` only when given."""
    headers, rows = noise_headline(result)
    out = {"recording": dict(recording_rows(result, sensor)), "noise": {"headers": headers, "rows": rows},
           "verdicts": verdict_items(result, evaluated=evaluated), "cannot_support": cannot_support(result)}
    screen = screen_summary(result)
    if screen is not None:
        out["screen"] = screen
    if spec is not None:
        out["spec"] = spec
    if getattr(result, "apply_to", None) is not None:
        out["apply_to_verdicts"] = verdict_items(result.apply_to, evaluated=evaluated)
    return out
