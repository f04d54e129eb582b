"""Honest evaluation of compensators (method notes §5).

* :mod:`.heading` -- heading (angle) error after a static calibration, over rolling origins and horizons;
* :mod:`.artefacts` -- injected step, ramp and sinusoids: how much real rate each compensator removes;
* :mod:`.verdicts` -- the verdict sentences and tables, headline first (heading error), the paper's one-step
  figures last and labelled;
* :func:`evaluate_axis` -- both evaluations on the test block of one axis of a pipeline run;
* :mod:`.analysis` -- :func:`evaluate_analysis` stores them (:class:`AxisEvaluation`) in every axis of an
  analysis result, so ``analysis.json`` and the report carry them.
"""

from .analysis import AxisEvaluation, evaluate_analysis
from .artefacts import ArtefactResult, ArtefactRow, artefact_check, default_frequencies
from .heading import CONSTANT_BIAS, HORIZONS_S, HeadingResult, HeadingRow, angle_error_deg, heading_errors
from .verdicts import (OUTCOMES, Verdict, artefact_table, artefact_verdict, causal_verdict, compensation_verdicts,
                       heading_table, heading_verdict, headline_verdict, paper_measure_verdict, table2_marks)

__all__ = [
    "heading_errors",
    "HeadingResult",
    "HeadingRow",
    "angle_error_deg",
    "HORIZONS_S",
    "CONSTANT_BIAS",
    "artefact_check",
    "ArtefactResult",
    "ArtefactRow",
    "default_frequencies",
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
    "OUTCOMES",
    "evaluate_axis",
    "evaluate_analysis",
    "AxisEvaluation",
]


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
    from ..bundle import _causal_window, _level_of
    from ..errors import FogdriftError

    level = _level_of(model_axis, cfg)
    window = _causal_window(model_axis, cfg, level)
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
