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

from .._util import fmt_number

__all__ = [
    "Verdict",
    "heading_verdict",
    "artefact_verdict",
    "causal_verdict",
    "paper_measure_verdict",
    "one_step_lines",
    "compensation_verdicts",
    "heading_table",
    "artefact_table",
    "table2_marks",
    "table2_verdict",
    "adev_caveat",
    "headline_verdict",
    "independent_origins",
    "independent_subset",
    "judge",
    "Judgement",
    "JUDGEMENTS",
    "diverges",
    "DIVERGE_RATIO",
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
    #: The same verdict in one short sentence for a console summary whose heading already states the protocol
    #: (held-out block, calibration, constant bias as reference); "" when the verdict has no short form.  Not
    #: stored: the JSON and the report keep the full sentences.
    short: str = ""

    def to_dict(self) -> dict:
        return {"kind": self.kind, "lines": list(self.lines), "data": self.data}


def _f(x, digits=3) -> str:
    """``digits`` significant digits, scientific below 1e-3 and from 1e4, ``n/a`` when missing or not finite."""
    return fmt_number(x, digits, missing="n/a", nonfinite="n/a", sci_outside=(1e-3, 1e4))


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


def _stride(step_s, horizon_s) -> int:
    """Every how many origins (``step_s`` apart) the horizon windows stop overlapping: ``ceil(H / step)``."""
    if step_s is None or step_s >= horizon_s:
        return 1
    return max(1, math.ceil(float(horizon_s) / float(step_s) - 1e-9))


def independent_subset(n_origins: int, step_s, horizon_s: float):
    """Indices of the origins whose horizon windows do not overlap: every ``ceil(H / step)``-th from the first.

    The origins are ``step_s`` apart; the first one is always kept and the next kept one is the first that starts
    at or after the end of the previous one's horizon window.  ``step_s`` None: all origins.

    Examples
    --------
    >>> independent_subset(7, 300.0, 600.0).tolist(), independent_subset(7, 300.0, 700.0).tolist()
    ([0, 2, 4, 6], [0, 3, 6])
    """
    import numpy as np

    return np.arange(0, max(int(n_origins), 0), _stride(step_s, horizon_s))


def independent_origins(n_origins: int, step_s, horizon_s: float) -> int:
    """How many origins have horizon windows that do not overlap (:func:`independent_subset`).

    Errors of origins closer than the horizon share most of their integration window, so they are not
    independent evidence; a verdict counts only these.  ``step_s`` None: all origins count.

    Examples
    --------
    >>> independent_origins(31, 300.0, 60.0), independent_origins(31, 300.0, 600.0), independent_origins(21, 300.0, 3600.0)
    (31, 16, 2)
    """
    n = int(n_origins)
    return 0 if n <= 0 else 1 + (n - 1) // _stride(step_s, horizon_s)


#: RMS heading error, as a multiple of constant bias's, beyond which a forecast has diverged: a forecast whose
#: angle error is a thousand times what subtracting nothing leaves has added a drift three orders of magnitude
#: larger than the gyro's own -- a runaway extrapolation (GM(1,1)'s exponential on real logs reaches 4.8e5 x at
#: 600 s), not a drift estimate; its figure is printed as "diverges", not as a number.
DIVERGE_RATIO = 1e3


def diverges(rms_deg, ratio_to_bias) -> bool:
    """True when a forecast diverged: its RMS heading error is not finite or above :data:`DIVERGE_RATIO` times
    constant bias's.

    Examples
    --------
    >>> diverges(3.38e34, 1.2e35), diverges(float("inf"), float("inf")), diverges(0.5, 0.88)
    (True, True, False)
    """
    if rms_deg is None or not math.isfinite(rms_deg):
        return True
    return ratio_to_bias is not None and (ratio_to_bias == math.inf or ratio_to_bias > DIVERGE_RATIO)


#: Outcomes of :func:`judge` -> meaning.
JUDGEMENTS = {
    "reduces": "RMS at least 5 % below constant bias's AND better at more than half of the non-overlapping origins",
    "worsens": "RMS at least 5 % above constant bias's AND worse at more than half of the non-overlapping origins",
    "diverges": "the forecast diverged (non-finite, or RMS above 1e3 x constant bias's)",
    "not material": "RMS within 5 % of constant bias's",
    "not at most origins": "RMS 5 % or more from constant bias's, but not better (worse) at more than half of the "
                           "non-overlapping origins",
    "too few": "fewer non-overlapping origins than a verdict needs",
    "n/a": "no ratio to constant bias (constant bias leaves no error)",
}


@dataclass(frozen=True)
class Judgement:
    """One model against constant bias at one horizon: the outcome of :func:`judge` and the counts behind it."""

    outcome: str
    ratio: float
    n: int | None  # non-overlapping origins
    better: int | None  # of them, where the model's |E| < constant bias's
    worse: int | None  # of them, where it is above (or not finite)

    @property
    def reduces(self) -> bool:
        return self.outcome == "reduces"

    @property
    def worsens(self) -> bool:
        """Worse than constant bias: materially at most origins, or diverged."""
        return self.outcome in ("worsens", "diverges")

    def counts(self, side: str = "better", only: bool = False) -> str:
        """``"better at 9 of 12 non-overlapping origins"`` (``side``: better or worse; ``only``: "at only")."""
        k = self.better if side == "better" else self.worse
        at = "at only" if only else "at"
        if k is None or self.n is None:
            return f"{side} {at} ? of {'?' if self.n is None else self.n} non-overlapping origins (not counted)"
        return f"{side} {at} {k} of {self.n} non-overlapping origins"

    def change(self) -> str:
        """The RMS change as text: ``-12 %``, or ``diverges``."""
        return "diverges" if self.outcome == "diverges" else _pct(self.ratio)


def judge(row, *, step_s=None, material: float = MATERIAL, min_origins: int = MIN_ORIGINS) -> Judgement:
    """THE rule: does a model reduce (worsen) the heading error against constant bias at one horizon?

    *reduces*: RMS ratio to constant bias <= 1 - ``material`` AND the model is better (smaller |E|) at MORE THAN
    HALF of the origins whose horizon windows do not overlap (:func:`independent_subset`); *worsens*: the mirror
    image (ratio >= 1 + ``material`` and worse at more than half).  A forecast that :func:`diverges` is
    *diverges* (a kind of worsening, never a reduction) whatever the counts.  With fewer than ``min_origins``
    non-overlapping origins nothing is judged (*too few*).  Every verdict sentence, table colour, report and
    fleet outcome of fogdrift decides "reduces / worse" here.

    Parameters
    ----------
    row : HeadingRow
        ``ratio_to_bias``, ``rms_deg`` and the counts ``n_independent``, ``better_independent``,
        ``worse_independent`` (:func:`~fogdrift.evaluation.heading.heading_errors`).  A row without the counts
        gets its ``n`` from ``n_origins`` and ``step_s`` and can then be neither *reduces* nor *worsens*.
    step_s : float, optional
        Origin spacing [s], only for a row without ``n_independent``.

    Examples
    --------
    >>> from types import SimpleNamespace as NS
    >>> def row(ratio, better, worse, n=12):
    ...     return NS(horizon_s=600.0, n_origins=2 * n - 1, rms_deg=ratio, ratio_to_bias=ratio, n_independent=n,
    ...               better_independent=better, worse_independent=worse)
    >>> j = judge(row(0.88, 9, 3)); j.outcome, j.counts()
    ('reduces', 'better at 9 of 12 non-overlapping origins')
    >>> judge(row(0.88, 6, 6)).outcome        # exactly half is not most
    'not at most origins'
    >>> judge(row(1.10, 2, 10)).outcome, judge(row(0.97, 12, 0)).outcome, judge(row(float("inf"), 0, 12)).outcome
    ('worsens', 'not material', 'diverges')
    """
    ratio = getattr(row, "ratio_to_bias", math.nan)
    ratio = math.nan if ratio is None else float(ratio)
    n = getattr(row, "n_independent", None)
    better = getattr(row, "better_independent", None)
    worse = getattr(row, "worse_independent", None)
    if n is None:
        n = independent_origins(row.n_origins, step_s, row.horizon_s)
        better = worse = None
    if diverges(row.rms_deg, ratio):
        outcome = "diverges"
    elif n < min_origins:
        outcome = "too few"
    elif not math.isfinite(ratio):
        outcome = "n/a"
    elif ratio <= 1.0 - material and better is not None and 2 * better > n:
        outcome = "reduces"
    elif ratio >= 1.0 + material and worse is not None and 2 * worse > n:
        outcome = "worsens"
    elif abs(ratio - 1.0) < material:
        outcome = "not material"
    else:
        outcome = "not at most origins"
    return Judgement(outcome, ratio, n, better, worse)


def heading_verdict(result, *, material: float = MATERIAL, min_origins: int = MIN_ORIGINS) -> Verdict:
    """Per horizon: constant bias's RMS angle error, each model's change, and which models reduce it.

    Which models *reduce* or *worsen* the heading error is decided by :func:`judge` (RMS 5 % or more below / above
    constant bias's AND better / worse at more than half of the non-overlapping origins); the sentence gives the
    count behind it.  With fewer than ``min_origins`` non-overlapping origins the numbers are shown but no model
    is said to reduce or worsen anything; a diverged forecast reads "diverges", not a number.

    Examples
    --------
    >>> from types import SimpleNamespace as NS
    >>> def row(model, rms, ratio, better, worse):
    ...     return NS(model=model, horizon_s=600.0, n_origins=20, rms_deg=rms, ratio_to_bias=ratio,
    ...               wins_vs_bias=0.0, predicted_sigma_deg=None, inside_sigma=None, n_independent=20,
    ...               better_independent=better, worse_independent=worse)
    >>> rows = [row("constant bias", 0.5, 1.0, 0, 0), row("AR(p)", 0.6, 1.2, 6, 14), row("Kalman", 0.44, 0.88, 9, 11)]
    >>> v = heading_verdict(NS(axis="gz", calib_s=300.0, horizons_s=(600.0,), rows=rows))
    >>> print(v.lines[-1])
    gz, 600 s: no model reduces the heading error (5 % or more lower RMS and better at most non-overlapping origins); Kalman -12 % but better at only 9 of 20 non-overlapping origins; worse: AR(p) (+20 %, worse at 14 of 20 non-overlapping origins).
    """
    lines, data = [], {}
    step = getattr(result, "step_s", None)
    for h in result.horizons_s:
        rows = {r.model: r for r in result.rows if r.horizon_s == h}
        base = rows.get(CONSTANT_BIAS_LABEL)
        if base is None:
            continue
        parts = []
        better, worse, unsure, diverged = [], [], [], []
        for label, r in rows.items():
            if label == CONSTANT_BIAS_LABEL:
                continue
            j = judge(r, step_s=step, material=material, min_origins=min_origins)
            if j.outcome == "diverges":
                text = f"{label} diverges"
            else:
                text = f"{label} {_f(r.rms_deg)} deg ({_pct(r.ratio_to_bias)}, {j.counts()})"
            if r.predicted_sigma_deg is not None and j.outcome != "diverges":
                text += (f" [predicted 1-sigma {_f(r.predicted_sigma_deg)} deg, {100 * r.inside_sigma:.0f} % of "
                         "origins inside; ~68 % if calibrated]")
            parts.append(text)
            if j.reduces:
                better.append((r.ratio_to_bias, label, j))
            elif j.outcome == "diverges":
                diverged.append(label)
            elif j.outcome == "worsens":
                worse.append((label, j))
            elif j.outcome == "not at most origins":
                unsure.append((label, j))
        lines.append(f"{result.axis}, {h:g} s after a {result.calib_s:g}-s calibration ({base.n_origins} origins): "
                     f"constant bias leaves {_f(base.rms_deg)} deg RMS; " + "; ".join(parts) + ".")
        n_ind = judge(base, step_s=step, material=material, min_origins=min_origins).n
        if n_ind < min_origins:
            count = (f"{base.n_origins} origin(s)" if n_ind == base.n_origins else
                     f"{base.n_origins} origin(s), {n_ind} of them with non-overlapping horizons,")
            lines.append(f"{result.axis}, {h:g} s: {count} are too few to judge (need {min_origins}; use a longer "
                         "held-out record" + (" or a smaller origin step" if n_ind == base.n_origins else "") + ")"
                         + (f"; {', '.join(diverged)} diverges" if diverged else "") + ".")
            data[str(h)] = {"reduces": [], "worsens": list(diverged), "diverges": list(diverged),
                            "constant_bias_rms_deg": base.rms_deg, "too_few_origins": True,
                            "n_independent": n_ind}
            continue
        if better:
            best = ", ".join(f"{label} by {100 * (1 - ratio):.0f} % ({j.counts()})"
                             for ratio, label, j in sorted(better, key=lambda x: x[0]))
            text = f"{result.axis}, {h:g} s: reduces the heading error: {best}"
        else:
            text = (f"{result.axis}, {h:g} s: no model reduces the heading error ({100 * material:.0f} % or more "
                    "lower RMS and better at most non-overlapping origins)")
        if unsure:
            text += "; " + "; ".join(f"{label} {_pct(j.ratio)} but {j.counts('better' if j.ratio < 1 else 'worse', True)}"
                                     for label, j in unsure)
        if worse or diverged:
            text += "; worse: " + ", ".join([f"{label} ({_pct(j.ratio)}, {j.counts('worse')})" for label, j in worse]
                                            + [f"{label} diverges" for label in diverged])
        lines.append(text + ".")
        data[str(h)] = {"reduces": [label for _, label, _ in sorted(better, key=lambda x: x[0])],
                        "worsens": [label for label, _ in worse] + diverged, "diverges": diverged,
                        "constant_bias_rms_deg": base.rms_deg, "n_independent": n_ind,
                        "counts": {label: {"better": j.better, "worse": j.worse, "n_independent": j.n,
                                           "outcome": j.outcome}
                                   for label, j in ([(lb, jj) for _, lb, jj in better] + worse + unsure)}}
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
    headers += ["origins", "better / non-overlapping", "Kalman 1σ / inside"]
    models = list(dict.fromkeys(r.model for r in result.rows))
    step = getattr(result, "step_s", None)
    rows = []
    for label in models:
        cells = [label]
        extra, wins = [], []
        for h in result.horizons_s:
            r = next(x for x in result.rows if x.model == label and x.horizon_s == h)
            j = judge(r, step_s=step)
            if j.outcome == "diverges":
                cells += ["diverges", "diverges"]
            else:
                cells += [_f(r.rms_deg), _f(r.ratio_to_bias)]
            if label != CONSTANT_BIAS_LABEL:
                wins.append(f"{'?' if j.better is None else j.better}/{j.n}")
            if r.predicted_sigma_deg is not None and j.outcome != "diverges":
                extra.append(f"{_f(r.predicted_sigma_deg)} / {100 * r.inside_sigma:.0f} %")
        n = "/".join(str(x.n_origins) for x in result.rows if x.model == label)
        rows.append(cells + [n, ", ".join(wins) or "–", ", ".join(extra) or "–"])
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


def adev_caveat(model_label: str, artefacts=None, *, axis: str = "", heading=None, why_not: str = "") -> str:
    """One sentence for a before/after ADEV figure: is the compensated curve's lower long-τ ADEV evidence?

    A causal drift subtraction lowers the long-τ ADEV of any static record (it is a high-pass), so the figure
    proves nothing by itself; the artefact check (``artefacts``: an ArtefactResult of the same axis, None when it
    did not run, ``why_not`` saying why) tells whether the model removes real rate, and the heading error at the
    longest judged horizon (``heading``: a HeadingResult) says what the compensation is worth.

    Examples
    --------
    >>> from types import SimpleNamespace as NS
    >>> a = NS(rows=[NS(model="Kalman", flagged_hz=(0.001, 0.002))])
    >>> print(adev_caveat("Kalman", a, axis="gx"))
    gx: the lower long-τ ADEV of Kalman is not evidence: the artefact check shows it removes real rate near 0.001, 0.002 Hz.
    >>> print(adev_caveat("Kalman", NS(rows=[NS(model="Kalman", flagged_hz=())]), axis="gx"))
    gx: artefact check clean: Kalman removes no injected real rate where its ADEV is lower.
    """
    pre = f"{axis}: " if axis else ""
    if artefacts is None:
        text = (f"{pre}the lower long-τ ADEV of {model_label} is not checked: the artefact check did not run"
                + (f" ({why_not})" if why_not else "") + "; a causal drift subtraction lowers it on any static log")
    else:
        row = next((r for r in artefacts.rows if r.model == model_label), None)
        if row is None:
            text = f"{pre}the artefact check has no row for {model_label}"
        elif row.flagged_hz:
            text = (f"{pre}the lower long-τ ADEV of {model_label} is not evidence: the artefact check shows it removes "
                    f"real rate near {', '.join(f'{f:g}' for f in row.flagged_hz)} Hz")
        else:
            text = f"{pre}artefact check clean: {model_label} removes no injected real rate where its ADEV is lower"
    if heading is not None:
        h = heading.horizons_s[-1]
        r = next((x for x in heading.rows if x.model == model_label and x.horizon_s == h), None)
        if r is not None:
            j = judge(r, step_s=getattr(heading, "step_s", None))
            worth = "diverges" if j.outcome == "diverges" else f"{_f(r.ratio_to_bias)} x constant bias's"
            why = {"too few": f"{j.n} non-overlapping origins: too few to judge",
                   "not at most origins": j.counts("better" if j.ratio < 1 else "worse", True)}.get(j.outcome,
                                                                                                   j.outcome)
            text += f"; what it is worth: heading error at {h:g} s {worth} ({why})"
    return text + "."


def table2_verdict(table2_rows, artefacts, *, axis: str = "") -> Verdict | None:
    """The flag of :func:`table2_marks` as console lines (the HTML marks the same rows): None when nothing is
    flagged or the artefact check did not run.

    Examples
    --------
    >>> from types import SimpleNamespace as NS
    >>> rows = [NS(label="Kalman: output - causal prediction (practical)", kind="practical", model="Kalman")]
    >>> v = table2_verdict(rows, NS(rows=[NS(model="Kalman", flagged_hz=(0.001,))]), axis="gx")
    >>> print(v.lines[0])
    gx: Table 2 row "Kalman: output - causal prediction (practical)" FLAGGED: improvement partly removes real rate (artefact check: 0.001 Hz); its lower noise figures are not evidence of a better gyro.
    """
    if artefacts is None:
        return None
    marks = table2_marks(table2_rows, artefacts)
    if not marks:
        return None
    pre = f"{axis}: " if axis else ""
    return Verdict("table2", [f'{pre}Table 2 row "{label}" FLAGGED: {mark}; its lower noise figures are not evidence '
                              "of a better gyro." for label, mark in marks.items()], {"marks": marks})


#: Outcome of :func:`headline_verdict` -> what it means (the report colours it: green, amber, red, grey).
OUTCOMES = {
    "reduces": "a model reduces the heading error at a judged horizon, worsens it at none and passes the artefact "
               "check",
    "mixed": "a model reduces the heading error at a judged horizon but worsens it at another, or removes real "
             "rate (artefact check)",
    "none": "no model reduces the heading error (5 % or more lower RMS and better at most non-overlapping origins) "
            "at any judged horizon",
    "undetermined": "too few calibration origins (or no heading evaluation): nothing can be judged",
}


def _horizon_list(hs) -> str:
    hs = [f"{h:g}" for h in hs]
    return hs[0] if len(hs) == 1 else ", ".join(hs[:-1]) + " or " + hs[-1]


def headline_verdict(heading=None, artefacts=None, *, axis: str = "", reason: str = "", material: float = MATERIAL,
                     min_origins: int = MIN_ORIGINS) -> Verdict:
    """ONE sentence per axis: did any compensator reduce the heading error, judged against constant bias.

    Only horizons with at least ``min_origins`` independent calibration origins (:func:`independent_origins`)
    are judged, each model by :func:`judge` (the one rule).  The best model is the one
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
    >>> def row(m, h, rms, ratio, better=0, worse=0):
    ...     return NS(model=m, horizon_s=h, n_origins=30, rms_deg=rms, ratio_to_bias=ratio, n_independent=30,
    ...               better_independent=better, worse_independent=worse)
    >>> h = NS(axis="gx", calib_s=300.0, horizons_s=(60.0, 600.0),
    ...        rows=[row("constant bias", 60.0, 1.0, 1.0), row("Kalman", 60.0, 0.8, 0.8, 21, 9),
    ...              row("constant bias", 600.0, 8.0, 1.0), row("Kalman", 600.0, 8.1, 1.0125, 14, 16)])
    >>> v = headline_verdict(h)
    >>> v.data["outcome"], v.data["model"]
    ('reduces', 'Kalman')
    >>> print(v.lines[0])
    gx: Kalman reduces the heading error by 20 % at 60 s after a 300-s calibration (0.8 vs 1 deg RMS, better at 21 of 30 non-overlapping origins) and worsens it at no judged horizon (60, 600 s); artefact check not run.
    """
    axis = axis or getattr(heading, "axis", "")
    if heading is None:
        why = reason or "not run"
        return Verdict("headline", [f"{axis}: heading error not evaluated ({why}); no compensation verdict."],
                       {"outcome": "undetermined", "model": None, "reason": why})
    by_h = {h: {r.model: r for r in heading.rows if r.horizon_s == h} for h in heading.horizons_s}
    step = getattr(heading, "step_s", None)
    judged = [h for h, rows in by_h.items() if CONSTANT_BIAS_LABEL in rows
              and judge(rows[CONSTANT_BIAS_LABEL], step_s=step, min_origins=min_origins).n >= min_origins]
    if not judged:
        h0 = heading.horizons_s[0]
        base0 = by_h[h0].get(CONSTANT_BIAS_LABEL)
        n0 = base0.n_origins if base0 is not None else 0
        # origins closer than the horizon overlap: say how many count, or "17 origins ... need 10" reads as enough
        n_ind0 = judge(base0, step_s=step, min_origins=min_origins).n if base0 is not None else 0
        count = f"{n0} calibration origin(s)" + ("" if n_ind0 == n0 else
                                                 f", {n_ind0} of them with non-overlapping horizons,")
        line = (f"{axis}: cannot judge whether any model reduces the heading error: the held-out block gives "
                f"{count} at {h0:g} s ({heading.calib_s:g}-s calibrations every "
                f"{heading.step_s:g} s; need {min_origins}).")
        short = (f"{axis}: cannot judge: {n_ind0} non-overlapping origin(s) at {h0:g} s, {min_origins} needed "
                 "(a longer held-out block or shorter horizons).")
        return Verdict("headline", [line], {"outcome": "undetermined", "model": None, "judged_horizons_s": []},
                       short)
    better, worse, judgements = {}, {}, {}
    for h in judged:
        for label, r in by_h[h].items():
            if label == CONSTANT_BIAS_LABEL:
                continue
            jd = judgements[(label, h)] = judge(r, step_s=step, material=material, min_origins=min_origins)
            if jd.reduces:
                better.setdefault(label, []).append(h)
            elif jd.worsens:
                worse.setdefault(label, []).append(h)
    flagged = {}
    if artefacts is not None:
        flagged = {r.model: list(r.flagged_hz) for r in artefacts.rows if r.flagged_hz}
    base = {h: by_h[h][CONSTANT_BIAS_LABEL] for h in judged}
    data = {"judged_horizons_s": judged, "reduces": {k: v for k, v in better.items()},
            "worsens": {k: v for k, v in worse.items()}, "flagged_hz": flagged,
            "diverges": {k: [h for h in v if judgements[(k, h)].outcome == "diverges"] for k, v in worse.items()
                         if any(judgements[(k, h)].outcome == "diverges" for h in v)}}
    if not better:
        rms = " / ".join(_f(base[h].rms_deg) for h in judged)
        line = (f"{axis}: no model reduces the heading error by {100 * material:.0f} % or more at most "
                f"non-overlapping origins at {_horizon_list(judged)} s after a {heading.calib_s:g}-s calibration "
                f"(constant bias leaves {rms} deg RMS" + (f"; worse: {', '.join(sorted(worse))}" if worse else "")
                + ").")
        short = (f"{axis}: no model gains {100 * material:.0f} % or more at {' / '.join(f'{h:g}' for h in judged)} s "
                 f"(constant bias: {rms} deg RMS)" + (f"; worse: {', '.join(sorted(worse))}" if worse else "") + ".")
        return Verdict("headline", [line], {"outcome": "none", "model": None, **data}, short)

    def gain(label):
        return min(by_h[h][label].ratio_to_bias for h in better[label])

    best = sorted(better, key=lambda k: (-len(better[k]), gain(k)))[0]
    h = min(better[best], key=lambda x: by_h[x][best].ratio_to_bias)
    r = by_h[h][best]
    what = (f"{axis}: {best} reduces the heading error by {100 * (1 - r.ratio_to_bias):.0f} % at {h:g} s after a "
            f"{heading.calib_s:g}-s calibration ({_f(r.rms_deg)} vs {_f(base[h].rms_deg)} deg RMS, "
            f"{judgements[(best, h)].counts()})")
    buts = []
    if best in worse:
        buts.append(", ".join(
            f"diverges at {x:g} s" if judgements[(best, x)].outcome == "diverges" else
            f"worsens it by {_pct(by_h[x][best].ratio_to_bias)} at {x:g} s ({judgements[(best, x)].counts('worse')})"
            for x in worse[best]))
    if best in flagged:
        buts.append(f"removes real rate near {', '.join(f'{f:g}' for f in flagged[best])} Hz (artefact check)")
    gained = (f"{axis}: {best} -{100 * (1 - r.ratio_to_bias):.0f} % at {h:g} s ({_f(r.rms_deg)} vs "
              f"{_f(base[h].rms_deg)} deg RMS, {judgements[(best, h)].counts()})")
    if buts:
        line = what + " but " + " and ".join(buts) + "."
        short = gained + " but " + " and ".join(buts) + "."
        outcome = "mixed"
    else:
        check = "artefact check not run" if artefacts is None else "artefact check clean"
        line = what + f" and worsens it at no judged horizon ({', '.join(f'{x:g}' for x in judged)} s); {check}."
        short = gained + f"; worse nowhere; {check}."
        outcome = "reduces"
    return Verdict("headline", [line], {"outcome": outcome, "model": best, "horizon_s": h,
                                        "ratio_to_bias": r.ratio_to_bias, **data}, short)


def _cell(x, digits=4) -> str:
    """A number as the report's tables print it (scientific below 1e-3 and from 1e4, NaN as ``NaN``)."""
    return fmt_number(x, digits, nonfinite="NaN", sci_outside=(1e-3, 1e4))


def one_step_lines(model_axis) -> list[str]:
    """Plain-language sentences: which model beat persistence on the test block, judged on RMSE and MAE.

    A model "beat" persistence only if both its RMSE and its MAE are lower; if one is lower and the other
    higher the verdict says "mixed" (RMSE is dominated by a few large errors, MAE by typical ones).  These are
    the paper's one-step measures (the report prints them under the causal and heading verdicts).

    Examples
    --------
    >>> from types import SimpleNamespace as NS
    >>> m = {"persistence": NS(rmse_dph=1.0, mae_dph=0.8, rmse_persistence_dph=1.0),
    ...      "Elman": NS(rmse_dph=0.9, mae_dph=0.6, rmse_persistence_dph=1.0)}
    >>> one_step_lines(NS(metrics=m))[0]
    'Elman beat persistence one step ahead: RMSE 0.9 vs 1 deg/h (-10.0 %), MAE 0.6 vs 0.8 deg/h (-25.0 %).'
    """
    learned = {k: v for k, v in model_axis.metrics.items() if k != "persistence"}
    if not learned:
        return ["Only the persistence baseline was run."]
    any_m = next(iter(model_axis.metrics.values()))
    p_rmse = any_m.rmse_persistence_dph
    p_mae = model_axis.metrics["persistence"].mae_dph if "persistence" in model_axis.metrics else None
    lines = []
    for label, m in learned.items():
        d_rmse = 100.0 * (m.rmse_dph / p_rmse - 1.0)
        text = f"RMSE {_cell(m.rmse_dph)} vs {_cell(p_rmse)} deg/h ({d_rmse:+.1f} %)"
        if p_mae is None:
            better = d_rmse < 0
            word = "beat" if better else "did NOT beat"
        else:
            d_mae = 100.0 * (m.mae_dph / p_mae - 1.0)
            text += f", MAE {_cell(m.mae_dph)} vs {_cell(p_mae)} deg/h ({d_mae:+.1f} %)"
            if d_rmse < 0 and d_mae < 0:
                word = "beat"
            elif d_rmse >= 0 and d_mae >= 0:
                word = "did NOT beat"
            else:
                word = "gave a MIXED result against"
        lines.append(f"{label} {word} persistence one step ahead: {text}.")
    best = min(learned, key=lambda k: learned[k].rmse_dph)
    lines.append(f"Lowest RMSE among learned models on the test block: {best}.")
    return lines
