"""The evaluation as part of an analysis result: heading error, artefact check and verdicts of every axis.

:func:`evaluated_analysis` runs :func:`evaluate_axis` on the test block of every axis of a
:class:`fogdrift.pipeline.AnalysisResult` (and of its ``apply_to`` result: the models applied unchanged to a
second recording) and returns a new result whose axes carry an :class:`AxisEvaluation` in ``axis.evaluation``,
so that ``AnalysisResult.to_dict()`` (``analysis.json``) and the report carry it; the given result is not
changed (results are complete when built).  :func:`evaluations` lists them.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

from ..errors import FogdriftError
from ..interrupt import checkpoint
from .artefacts import artefact_check
from .heading import HORIZONS_S, heading_errors
from .verdicts import compensation_verdicts, headline_verdict, table2_verdict

__all__ = ["AxisEvaluation", "evaluate_axis", "evaluated_analysis", "evaluations"]


@dataclass
class AxisEvaluation:
    """Heading-error and artefact evaluation of one axis's test block, with the verdicts.

    Attributes
    ----------
    axis : str
    heading : fogdrift.evaluation.HeadingResult or None
        None when not run or when the test block is too short (``notes`` says which).
    artefacts : fogdrift.evaluation.ArtefactResult or None
    verdicts : list of Verdict
        In reading order: heading, artefacts, causal target, paper's measure, and the Table 2 practical rows
        the artefact check flags (kind ``table2``, only when there are any).
    headline : Verdict
        One sentence (:func:`~fogdrift.evaluation.headline_verdict`); ``headline.data["outcome"]`` is
        ``reduces``, ``mixed``, ``none`` or ``undetermined``.
    notes : list of str
    settings : dict
        ``calibration_window_s``, ``origin_step_s``, ``horizons_s`` requested, ``artefacts`` (bool).
    wall_s : float
        Seconds the evaluation of this axis took.
    """

    axis: str
    heading: object
    artefacts: object
    verdicts: list
    headline: object
    notes: list = field(default_factory=list)
    settings: dict = field(default_factory=dict)
    wall_s: float = 0.0

    @property
    def outcome(self) -> str:
        return self.headline.data.get("outcome", "undetermined")

    def to_dict(self) -> dict:
        return {
            "axis": self.axis,
            "headline": self.headline.to_dict(),
            "heading": None if self.heading is None else self.heading.to_dict(),
            "artefacts": None if self.artefacts is None else self.artefacts.to_dict(),
            "verdicts": [v.to_dict() for v in self.verdicts],
            "notes": list(self.notes),
            "settings": dict(self.settings),
            "wall_s": self.wall_s,
        }


def evaluated_analysis(result, *, calib_s: float = 300.0, step_s: float = 60.0, horizons_s=HORIZONS_S,
                       artefacts: bool = True):
    """A copy of ``result`` whose every axis (and every axis of ``result.apply_to``) carries its evaluation.

    ``result`` is not changed: each axis is rebuilt with :func:`dataclasses.replace` (``evaluation`` set), and
    so is the result (``axes``, ``apply_to``).

    Parameters
    ----------
    result : fogdrift.pipeline.AnalysisResult
    calib_s, step_s : float
        Calibration window before each rolling origin and the origins' spacing [s].  The default spacing, 60 s,
        is the shortest horizon: the 60-s error windows do not overlap (the 300-s calibration windows do), so a
        held-out block of 30 min gives about 25 independent 60-s origins; the verdicts count only origins with
        non-overlapping horizons (:func:`~fogdrift.evaluation.verdicts.independent_origins`).
    horizons_s : sequence of float
        Free-run forecast horizons [s] (those the test block cannot hold are dropped, with a note).
    artefacts : bool
        Also run the filtering-artefact check (injected step, ramp, sinusoids).

    Returns
    -------
    fogdrift.pipeline.AnalysisResult
        The evaluated result; ``[ax.evaluation for ax in out.axes]`` are the evaluations of the fitted
        recording, ``out.apply_to.axes`` those of the ``apply_to`` recording.
    """
    if result is None:
        return None
    axes = [replace(ax, evaluation=_evaluate_one(ax, result.config, calib_s=calib_s, step_s=step_s,
                                                 horizons_s=horizons_s, artefacts=artefacts))
            for ax in result.axes]
    other = getattr(result, "apply_to", None)
    apply_to = evaluated_analysis(other, calib_s=calib_s, step_s=step_s, horizons_s=horizons_s,
                                  artefacts=artefacts)
    return replace(result, axes=axes, apply_to=apply_to) if other is not None else replace(result, axes=axes)


def evaluations(result) -> list:
    """The evaluations an :func:`evaluated_analysis` result carries: the fitted recording's axes, then ``apply_to``'s."""
    out = [ax.evaluation for ax in result.axes]
    if getattr(result, "apply_to", None) is not None:
        out += [ax.evaluation for ax in result.apply_to.axes]
    return out


def _evaluate_one(ax, cfg, *, calib_s, step_s, horizons_s, artefacts) -> AxisEvaluation:
    checkpoint("heading-error and artefact evaluation", axis=ax.name)
    t0 = time.perf_counter()
    ev = evaluate_axis(ax.models, cfg, artefacts=artefacts, calib_s=calib_s, step_s=step_s,
                       horizons_s=tuple(horizons_s))
    reason = "; ".join(n for n in ev["notes"] if "heading" in n) or ""
    headline = headline_verdict(ev["heading"], ev["artefacts"], axis=ax.name, reason=reason)
    flag = table2_verdict(getattr(ax, "table2", None) or [], ev["artefacts"], axis=ax.name)
    verdicts = list(ev["verdicts"])
    if flag is not None:  # Table 2's practical rows that the artefact check flags (the HTML marks them too)
        verdicts.append(flag)
    return AxisEvaluation(
        axis=ax.name, heading=ev["heading"], artefacts=ev["artefacts"], verdicts=verdicts,
        headline=headline, notes=list(ev["notes"]),
        settings={"calibration_window_s": float(calib_s), "origin_step_s": float(step_s),
                  "horizons_s": [float(h) for h in horizons_s], "artefacts": bool(artefacts)},
        wall_s=time.perf_counter() - t0)


def evaluate_axis(model_axis, cfg, *, heading=True, artefacts=True, calib_s=300.0, step_s=300.0,
                  horizons_s=HORIZONS_S):
    """Heading error and artefact check on the test block of one pipeline axis, with the verdicts in order.

    Parameters
    ----------
    model_axis : fogdrift.pipeline.ModelAxis
        From :func:`~fogdrift.pipeline.run_models` / ``run_analysis(...).axes[i].models``.
    cfg : fogdrift.pipeline.AnalysisConfig
        The settings of that run (wavelet, level, mode, causal window).

    Returns
    -------
    dict
        ``{"heading": HeadingResult or None, "artefacts": ArtefactResult or None, "verdicts": [Verdict, ...],
        "notes": [str]}``; an evaluation the test block is too short for is None with a note.
    """
    level = int(model_axis.level)  # decided once by the pipeline and stored on the ModelAxis
    window = int(model_axis.causal_window)
    e, f = model_axis.split["test"]
    z = model_axis.rate_dph[e:f]
    opts = dict(causal_window=window, wavelet=cfg.wavelet, level=level, mode=cfg.mode, axis=model_axis.name)
    out = {"heading": None, "artefacts": None, "notes": []}
    if heading:
        try:
            out["heading"] = heading_errors(z, model_axis.dt_s, model_axis.fitted, calib_s=calib_s, step_s=step_s,
                                            horizons_s=horizons_s, **opts)
        except FogdriftError as exc:
            out["notes"].append(f"{model_axis.name}: heading evaluation skipped ({exc})")
    if artefacts:
        try:
            out["artefacts"] = artefact_check(z, model_axis.dt_s, model_axis.fitted, **opts)
        except FogdriftError as exc:
            out["notes"].append(f"{model_axis.name}: artefact check skipped ({exc})")
    out["verdicts"] = compensation_verdicts(heading=out["heading"], artefacts=out["artefacts"], model_axis=model_axis)
    return out
