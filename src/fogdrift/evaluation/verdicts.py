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


#: Fewest origins on which a horizon's verdict says which model reduces the heading error.
MIN_ORIGINS = 10


def heading_verdict(result, *, material: float = MATERIAL, min_origins: int = MIN_ORIGINS) -> Verdict:
    """Per horizon: constant bias's RMS angle error, each model's change, and which models reduce it.

    A model *reduces* the heading error when its RMS is at least ``material`` (5 %) below constant bias's,
    *worsens* it when at least 5 % above; in between the difference is not material.  With fewer than
    ``min_origins`` origins the numbers are shown but no model is said to reduce or worsen anything.

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
        if base.n_origins < min_origins:
            lines.append(f"{result.axis}, {h:g} s: {base.n_origins} origin(s) are too few to judge (need "
                         f"{min_origins}; use a longer held-out record or a smaller origin step).")
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
