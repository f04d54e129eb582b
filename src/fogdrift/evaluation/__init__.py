"""Honest evaluation of compensators (method notes §5).

* :mod:`.heading` -- heading (angle) error after a static calibration, over rolling origins and horizons;
* :mod:`.artefacts` -- injected step, ramp and sinusoids: how much real rate each compensator removes;
* :mod:`.verdicts` -- the verdict sentences and tables, headline first (heading error), the paper's one-step
  figures last and labelled;
* :mod:`.analysis` -- :func:`evaluate_axis`: both evaluations on the test block of one axis of a pipeline run;
  :func:`evaluated_analysis` returns a new analysis result whose every axis carries them
  (:class:`AxisEvaluation`), so ``analysis.json`` and the report carry them.
"""

from .analysis import AxisEvaluation, evaluate_axis, evaluated_analysis, evaluations
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
    "evaluated_analysis",
    "evaluations",
    "AxisEvaluation",
]

