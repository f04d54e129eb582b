"""Verdicts: what the evaluation says, as data plus plain sentences, in the order a reader needs them.

1. :func:`heading_verdict` -- heading error after a static calibration (the headline: what an engineer gains);
2. :func:`artefact_verdict` -- which "improvements" are removal of real signal;
3. :func:`causal_verdict` -- one-step skill against the **causal** drift (what a real-time compensator sees);
4. :func:`paper_measure_verdict` -- the paper's one-step figures against the non-causal wavelet drift,
   labelled "paper's measure", never the headline.

:func:`compensation_verdicts` returns them in that order; :func:`heading_table` / :func:`artefact_table`
give formatted rows (strings with units) for consoles and reports.  Nothing here prints.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

__all__ = [
    "Verdict",
    "heading_verdict",
    "artefact_verdict",
    "causal_verdict",
    "paper_measure_verdict",
    "compensation_verdicts",
    "heading_table",
    "artefact_table",
    "table2_marks",
    "headline_verdict",
    "independent_origins",
    "OUTCOMES",
]

#: Relative change of the RMS heading error that counts as a real difference (5 %).
MATERIAL = 0.05


@dataclass
class Verdict:
    """``kind`` (heading / artefacts / causal / paper), sentences, and the numbers behind them."""

    kind: str
    lines: list
    data: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        return {"kind": self.kind, "lines": list(self.lines), "data": self.data}


def _f(x, digits=3) -> str:
    if x is None or not math.isfinite(x):
        return "n/a"
    if x == 0:
        return "0"
    if abs(x) >= 1e4 or abs(x) < 1e-3:
        return f"{x:.{digits - 1}e}"
    return f"{x:.{digits}g}"


def _pct(ratio) -> str:
    """Change of a ratio in per cent; ``x12`` style beyond 10 (a diverging forecast)."""
    if ratio is None or not math.isfinite(ratio):
        return "n/a"
    if ratio >= 10:
        return f"x{ratio:.3g}"
    pct = round(100.0 * (ratio - 1.0))
    return "±0 %" if pct == 0 else f"{pct:+d} %"


#: Label of the reference compensator (as in :mod:`.heading`).
CONSTANT_BIAS_LABEL = "constant bias"

#: Fewest origins on which a horizon's verdict says which model reduces the heading error.
MIN_ORIGINS = 10


def independent_origins(n_origins: int, step_s, horizon_s: float) -> int:
    """Origins whose horizon windows do not overlap: ``1 + floor((n - 1) step / max(step, H))``.

    Errors of origins closer than the horizon share most of their integration window, so they are not
    independent evidence; a verdict counts only these.  ``step_s`` None: all origins count.

    Examples
    --------
    >>> independent_origins(31, 300.0, 60.0), independent_origins(31, 300.0, 600.0), independent_origins(21, 300.0, 3600.0)
    (31, 16, 2)
    """
    n = int(n_origins)
    if n <= 1 or step_s is None or step_s >= horizon_s:
        return max(n, 0)
    return 1 + int((n - 1) * float(step_s) / float(horizon_s) + 1e-9)


def heading_verdict(result, *, material: float = MATERIAL, min_origins: int = MIN_ORIGINS) -> Verdict:
    """Per horizon: constant bias's RMS angle error, each model's change, and which models reduce it.

    A model *reduces* the heading error when its RMS is at least ``material`` (5 %) below constant bias's,
    *worsens* it when at least 5 % above; in between the difference is not material.  With fewer than
    ``min_origins`` independent origins (:func:`independent_origins`: horizon windows that do not overlap) the
    numbers are shown but no model is said to reduce or worsen anything.

    Examples
    --------
    >>> from types import SimpleNamespace as NS
    >>> rows = [NS(model="constant bias", horizon_s=600.0, n_origins=20, rms_deg=0.5, ratio_to_bias=1.0,
    ...            wins_vs_bias=0.0, predicted_sigma_deg=None, inside_sigma=None),
    ...         NS(model="AR(p)", horizon_s=600.0, n_origins=20, rms_deg=0.6, ratio_to_bias=1.2,
    ...            wins_vs_bias=0.3, predicted_sigma_deg=None, inside_sigma=None)]
    >>> v = heading_verdict(NS(axis="gz", calib_s=300.0, horizons_s=(600.0,), rows=rows))
    >>> print(v.lines[-1])
    gz, 600 s: no model reduces the heading error by 5 % or more (worse: AR(p) +20 %).
    """
    lines, data = [], {}
    for h in result.horizons_s:
        rows = {r.model: r for r in result.rows if r.horizon_s == h}
        base = rows.get("constant bias")
        if base is None:
            continue
        parts = []
        better, worse = [], []
        for label, r in rows.items():
            if label == "constant bias":
                continue
            text = f"{label} {_f(r.rms_deg)} deg ({_pct(r.ratio_to_bias)}, better at {100 * r.wins_vs_bias:.0f} % of origins)"
            if r.predicted_sigma_deg is not None:
                text += (f" [predicted 1-sigma {_f(r.predicted_sigma_deg)} deg, {100 * r.inside_sigma:.0f} % of "
                         "origins inside; ~68 % if calibrated]")
            parts.append(text)
            if math.isfinite(r.ratio_to_bias) and r.ratio_to_bias <= 1.0 - material:
                better.append((r.ratio_to_bias, label))
            elif not math.isfinite(r.ratio_to_bias) or r.ratio_to_bias >= 1.0 + material:
                worse.append(label)
        lines.append(f"{result.axis}, {h:g} s after a {result.calib_s:g}-s calibration ({base.n_origins} origins): "
                     f"constant bias leaves {_f(base.rms_deg)} deg RMS; " + "; ".join(parts) + ".")
        n_ind = independent_origins(base.n_origins, getattr(result, "step_s", None), h)
        if n_ind < min_origins:
            count = (f"{base.n_origins} origin(s)" if n_ind == base.n_origins else
                     f"{base.n_origins} origin(s), {n_ind} of them with non-overlapping horizons,")
            lines.append(f"{result.axis}, {h:g} s: {count} are too few to judge (need {min_origins}; use a longer "
                         "held-out record" + (" or a smaller origin step" if n_ind == base.n_origins else "") + ").")
            data[str(h)] = {"reduces": [], "worsens": [], "constant_bias_rms_deg": base.rms_deg,
                            "too_few_origins": True}
            continue
        if better:
            best = ", ".join(f"{label} by {100 * (1 - ratio):.0f} %" for ratio, label in sorted(better))
            lines.append(f"{result.axis}, {h:g} s: reduces the heading error: {best}.")
        else:
            tail = f" (worse: {', '.join(f'{w} {_pct(rows[w].ratio_to_bias)}' for w in worse)})" if worse else ""
            lines.append(f"{result.axis}, {h:g} s: no model reduces the heading error by {100 * material:.0f} % or "
                         f"more{tail}.")
        data[str(h)] = {"reduces": [label for _, label in sorted(better)], "worsens": worse,
                        "constant_bias_rms_deg": base.rms_deg}
    return Verdict("heading", lines, data)


def artefact_verdict(result) -> Verdict:
    """Which compensators remove injected real rate where they claim an Allan improvement."""
    lines, data = [], {}
    for row in result.rows:
        if row.model == "constant bias":
            continue
        low = [f for f in result.frequencies_hz if row.gains.get(f, 1.0) < 0.9]
        data[row.model] = {"flagged_hz": list(row.flagged_hz), "removes_over_10pct_hz": low}
        if row.flagged_hz:
            lines.append(f"{result.axis}: {row.model} FLAGGED: its Allan 'improvement' near "
                         f"{', '.join(f'{f:g}' for f in row.flagged_hz)} Hz is removal of real rate (an injected "
                         f"sinusoid keeps only {', '.join(_f(row.gains[f], 2) for f in row.flagged_hz)} of its "
                         "amplitude).")
        elif low:
            lines.append(f"{result.axis}: {row.model} removes > 10 % of injected rate at "
                         f"{', '.join(f'{f:g}' for f in low)} Hz (no Allan improvement claimed there).")
    if not lines:
        lines.append(f"{result.axis}: no compensator removes more than 10 % of an injected signal.")
    return Verdict("artefacts", lines, data)


def causal_verdict(model_axis) -> Verdict:
    """One-step skill against the causal drift target (``ModelAxis.causal_metrics``)."""
    metrics = {k: m for k, m in model_axis.causal_metrics.items() if k != "persistence"}
    lines, data = [], {}
    for label, m in metrics.items():
        data[label] = {"skill": m.skill, "rmse_dph": m.rmse_dph, "rmse_persistence_dph": m.rmse_persistence_dph}
    if not metrics:
        return Verdict("causal", ["Only persistence was run."], data)
    beat = [k for k, m in metrics.items() if math.isfinite(m.skill) and m.skill > 0]
    detail = "; ".join(f"{k} {_f(m.skill, 2)}" for k, m in metrics.items())
    lines.append(f"{model_axis.name}: against the causal drift (what a real-time compensator sees), one-step skill "
                 f"vs persistence: {detail}.")
    lines.append(f"{model_axis.name}: " + (f"{', '.join(beat)} beat persistence on the causal target." if beat else
                                           "no model beats persistence on the causal target."))
    return Verdict("causal", lines, data)


def paper_measure_verdict(model_axis) -> Verdict:
    """The paper's one-step comparison (target: non-causal wavelet drift of the test block), labelled as such."""
    metrics = {k: m for k, m in model_axis.metrics.items() if k != "persistence"}
    parts = [f"{k} RMSE {_pct(m.rmse_dph / m.rmse_persistence_dph if m.rmse_persistence_dph else math.nan)} "
             f"vs persistence" for k, m in metrics.items()]
    line = (f"{model_axis.name}: paper's measure (one step ahead, target = non-causal wavelet drift; not a "
            f"compensation result): " + ("; ".join(parts) if parts else "persistence only") + ".")
    return Verdict("paper", [line], {k: m.to_dict() for k, m in metrics.items()})


def compensation_verdicts(*, heading=None, artefacts=None, model_axis=None) -> list:
    """The verdicts that exist, in reading order: heading, artefacts, causal target, paper's measure."""
    out = []
    if heading is not None:
        out.append(heading_verdict(heading))
    if artefacts is not None:
        out.append(artefact_verdict(artefacts))
    if model_axis is not None:
        out.append(causal_verdict(model_axis))
        out.append(paper_measure_verdict(model_axis))
    return out


def heading_table(result) -> tuple:
    """``(headers, rows)`` of the heading-error table: one row per model, per horizon RMS [deg] and ratio."""
    headers = ["model"]
    for h in result.horizons_s:
        headers += [f"RMS {h:g} s [deg]", f"/ bias {h:g} s"]
    headers += ["origins", "Kalman 1σ / inside"]
    models = list(dict.fromkeys(r.model for r in result.rows))
    rows = []
    for label in models:
        cells = [label]
        extra = []
        for h in result.horizons_s:
            r = next(x for x in result.rows if x.model == label and x.horizon_s == h)
            cells += [_f(r.rms_deg), _f(r.ratio_to_bias)]
            if r.predicted_sigma_deg is not None:
                extra.append(f"{_f(r.predicted_sigma_deg)} / {100 * r.inside_sigma:.0f} %")
        n = "/".join(str(x.n_origins) for x in result.rows if x.model == label)
        rows.append(cells + [n, ", ".join(extra) or "–"])
    return headers, rows


def artefact_table(result) -> tuple:
    """``(headers, rows)``: gain per injected frequency, step survival, ramp survival, flags."""
    headers = (["model"] + [f"{f:g} Hz" for f in result.frequencies_hz]
               + [f"step +{d:g} s" for d in result.step_delays_s] + ["ramp", "flagged [Hz]"])
    rows = []
    for r in result.rows:
        rows.append([r.model] + [_f(r.gains[f], 2) for f in result.frequencies_hz]
                    + [_f(r.step_survival[d], 2) for d in result.step_delays_s]
                    + [_f(r.ramp_survival, 2), ", ".join(f"{f:g}" for f in r.flagged_hz) or "–"])
    return headers, rows


def table2_marks(table2_rows, artefacts) -> dict:
    """Label -> mark for Table 2 rows whose model is flagged by the artefact check ("removes signal at ... Hz")."""
    flagged = {r.model: r.flagged_hz for r in artefacts.rows if r.flagged_hz}
    out = {}
    for row in table2_rows:
        model = getattr(row, "model", None)
        if model in flagged and getattr(row, "kind", "") == "practical":
            out[row.label] = f"improvement partly removes real rate (artefact check: {', '.join(f'{f:g}' for f in flagged[model])} Hz)"
    return out


#: Outcome of :func:`headline_verdict` -> what it means (the report colours it: green, amber, red, grey).
OUTCOMES = {
    "reduces": "a model reduces the heading error at a judged horizon, worsens it at none and passes the artefact "
               "check",
    "mixed": "a model reduces the heading error at a judged horizon but worsens it at another, or removes real "
             "rate (artefact check)",
    "none": "no model reduces the heading error by 5 % or more at any judged horizon",
    "undetermined": "too few calibration origins (or no heading evaluation): nothing can be judged",
}


def _horizon_list(hs) -> str:
    hs = [f"{h:g}" for h in hs]
    return hs[0] if len(hs) == 1 else ", ".join(hs[:-1]) + " or " + hs[-1]


def headline_verdict(heading=None, artefacts=None, *, axis: str = "", reason: str = "", material: float = MATERIAL,
                     min_origins: int = MIN_ORIGINS) -> Verdict:
    """ONE sentence per axis: did any compensator reduce the heading error, judged against constant bias.

    Only horizons with at least ``min_origins`` independent calibration origins (:func:`independent_origins`)
    are judged.  The best model is the one
    that reduces the error (by ``material`` or more) at the most judged horizons, then by the largest factor.
    ``data["outcome"]`` is one of :data:`OUTCOMES`: *reduces* only when that model worsens the error at no
    judged horizon and the artefact check (when it ran) flags nothing for it; *mixed* when it does either;
    *none* when no model reduces it; *undetermined* when no horizon can be judged.

    Parameters
    ----------
    heading : HeadingResult or None
        None: the heading evaluation did not run (``reason`` says why).
    artefacts : ArtefactResult or None
    axis : str
        Axis name (default: the heading result's).

    Examples
    --------
    >>> from types import SimpleNamespace as NS
    >>> def row(m, h, rms, ratio):
    ...     return NS(model=m, horizon_s=h, n_origins=30, rms_deg=rms, ratio_to_bias=ratio)
    >>> h = NS(axis="gx", calib_s=300.0, horizons_s=(60.0, 600.0),
    ...        rows=[row("constant bias", 60.0, 1.0, 1.0), row("Kalman", 60.0, 0.8, 0.8),
    ...              row("constant bias", 600.0, 8.0, 1.0), row("Kalman", 600.0, 8.1, 1.0125)])
    >>> v = headline_verdict(h)
    >>> v.data["outcome"], v.data["model"]
    ('reduces', 'Kalman')
    >>> print(v.lines[0])
    gx: Kalman reduces the heading error by 20 % at 60 s after a 300-s calibration (0.8 vs 1 deg RMS, 30 origins) and worsens it at no judged horizon (60, 600 s); artefact check not run.
    """
    axis = axis or getattr(heading, "axis", "")
    if heading is None:
        why = reason or "not run"
        return Verdict("headline", [f"{axis}: heading error not evaluated ({why}); no compensation verdict."],
                       {"outcome": "undetermined", "model": None, "reason": why})
    by_h = {h: {r.model: r for r in heading.rows if r.horizon_s == h} for h in heading.horizons_s}
    step = getattr(heading, "step_s", None)
    judged = [h for h, rows in by_h.items() if CONSTANT_BIAS_LABEL in rows
              and independent_origins(rows[CONSTANT_BIAS_LABEL].n_origins, step, h) >= min_origins]
    if not judged:
        h0 = heading.horizons_s[0]
        n0 = by_h[h0][CONSTANT_BIAS_LABEL].n_origins if CONSTANT_BIAS_LABEL in by_h[h0] else 0
        line = (f"{axis}: cannot judge whether any model reduces the heading error: the held-out block gives "
                f"{n0} calibration origin(s) at {h0:g} s ({heading.calib_s:g}-s calibrations every "
                f"{heading.step_s:g} s; need {min_origins}).")
        return Verdict("headline", [line], {"outcome": "undetermined", "model": None, "judged_horizons_s": []})
    better, worse = {}, {}
    for h in judged:
        for label, r in by_h[h].items():
            if label == CONSTANT_BIAS_LABEL:
                continue
            if math.isfinite(r.ratio_to_bias) and r.ratio_to_bias <= 1.0 - material:
                better.setdefault(label, []).append(h)
            elif not math.isfinite(r.ratio_to_bias) or r.ratio_to_bias >= 1.0 + material:
                worse.setdefault(label, []).append(h)
    flagged = {}
    if artefacts is not None:
        flagged = {r.model: list(r.flagged_hz) for r in artefacts.rows if r.flagged_hz}
    base = {h: by_h[h][CONSTANT_BIAS_LABEL] for h in judged}
    data = {"judged_horizons_s": judged, "reduces": {k: v for k, v in better.items()},
            "worsens": {k: v for k, v in worse.items()}, "flagged_hz": flagged}
    if not better:
        rms = " / ".join(_f(base[h].rms_deg) for h in judged)
        line = (f"{axis}: no model reduces the heading error by {100 * material:.0f} % or more at "
                f"{_horizon_list(judged)} s after a {heading.calib_s:g}-s calibration (constant bias leaves {rms} deg "
                f"RMS" + (f"; worse: {', '.join(sorted(worse))}" if worse else "") + ").")
        return Verdict("headline", [line], {"outcome": "none", "model": None, **data})

    def gain(label):
        return min(by_h[h][label].ratio_to_bias for h in better[label])

    best = sorted(better, key=lambda k: (-len(better[k]), gain(k)))[0]
    h = min(better[best], key=lambda x: by_h[x][best].ratio_to_bias)
    r = by_h[h][best]
    what = (f"{axis}: {best} reduces the heading error by {100 * (1 - r.ratio_to_bias):.0f} % at {h:g} s after a "
            f"{heading.calib_s:g}-s calibration ({_f(r.rms_deg)} vs {_f(base[h].rms_deg)} deg RMS, {r.n_origins} "
            "origins)")
    buts = []
    if best in worse:
        buts.append("worsens it by " + ", ".join(f"{_pct(by_h[x][best].ratio_to_bias)} at {x:g} s"
                                                 for x in worse[best]))
    if best in flagged:
        buts.append(f"removes real rate near {', '.join(f'{f:g}' for f in flagged[best])} Hz (artefact check)")
    if buts:
        line = what + " but " + " and ".join(buts) + "."
        outcome = "mixed"
    else:
        check = "artefact check not run" if artefacts is None else "artefact check clean"
        line = what + f" and worsens it at no judged horizon ({', '.join(f'{x:g}' for x in judged)} s); {check}."
        outcome = "reduces"
    return Verdict("headline", [line], {"outcome": outcome, "model": best, "horizon_s": h,
                                        "ratio_to_bias": r.ratio_to_bias, **data})
