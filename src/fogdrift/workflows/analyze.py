"""The ``analyze`` workflow: the whole method on one recording -- plausibility and the record screen, the Allan
analysis, separation, drift models, compensation and Table 2 (:func:`fogdrift.pipeline.run_analysis`), the
heading-error and artefact evaluation on the held-out test block (:func:`fogdrift.evaluation.evaluated_analysis`),
the datasheet judgements -- and its files: the report, the model bundle and the compensated test block."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

from ..bundle import write_bundle
from ..compensate.holdout import write_compensated_test_block
from ..evaluation import evaluated_analysis
from ..evaluation import evaluations as evaluations_of
from ..io.readers.command_memory import check_records_memory
from ..pipeline import model_factor, run_analysis
from ..plausibility import check_record
from ..report import write_report
from ..spec import analysis_judgements
from ..units import S_PER_H

from ._modelled import modelling
from .allan import Screened, screen

__all__ = ["AnalyzeRun", "Prepared", "prepare_analyze", "run_analyze", "write_analyze", "HEADING_DEFAULTS"]

#: The heading evaluation's defaults: calibration window and origin spacing [s], free-run horizons [s].
HEADING_DEFAULTS = {"calib_s": 300.0, "step_s": 60.0, "horizons_s": (60.0, 600.0, S_PER_H)}


@dataclass
class AnalyzeRun:
    """What ``fogdrift analyze`` computed for one recording.

    Attributes
    ----------
    record : GyroRecord
    result : fogdrift.pipeline.AnalysisResult
        With each axis's evaluation when ``heading`` was on.
    evaluated : bool
        True if the heading-error evaluation ran.
    evaluations : list
        The evaluations (:func:`fogdrift.evaluation.evaluations`), empty without ``heading``.
    limits : dict or None
        The parsed datasheet limits, if given.
    judgements : list
        Their judgements (:func:`fogdrift.spec.analysis_judgements`), empty without limits.
    findings, segments, screens
        As :class:`fogdrift.workflows.allan.AllanRun`.
    """

    record: object
    result: object
    evaluated: bool
    evaluations: list = field(default_factory=list)
    limits: dict | None = None
    judgements: list = field(default_factory=list)
    findings: list = field(default_factory=list)
    segments: dict = field(default_factory=dict)
    screens: dict = field(default_factory=dict)

    @property
    def config(self):
        return self.result.config


@dataclass
class Prepared:
    """What ``analyze`` decides before any work: the validated configuration, the block-average factor of the record
    (and of the ``apply_to`` record) to the modelling rate, decided once here, and the record screen."""

    config: object
    factor: int
    apply_factor: int | None
    screened: Screened


def prepare_analyze(record, config=None, *, apply_to=None, segments="auto") -> Prepared:
    """Decide the modelling factors (a modelling rate that does not divide a record's rate is refused here, before
    any work) and screen the record; :func:`run_analyze` takes the result as ``prepared=``."""
    check_records_memory("analyze", record, apply_to)
    cfg, factor = modelling(record, config)
    other = None if apply_to is None else model_factor(apply_to, cfg)
    return Prepared(cfg, factor, other, screen(record, segments, command="analyze"))


def run_analyze(record, config=None, *, apply_to=None, heading=True, calib_s=HEADING_DEFAULTS["calib_s"],
                step_s=HEADING_DEFAULTS["step_s"], horizons_s=HEADING_DEFAULTS["horizons_s"], limits=None,
                segments="auto", progress: Callable | None = None, prepared: Prepared | None = None) -> AnalyzeRun:
    """Run ``fogdrift analyze`` on a recording.

    Parameters
    ----------
    record : GyroRecord
    config : fogdrift.pipeline.AnalysisConfig, optional
    apply_to : GyroRecord, optional
        A second recording the fitted models are applied to unchanged (axes by name).
    heading : bool
        The heading-error and artefact evaluation (``calib_s``, ``step_s``, ``horizons_s`` in s).
    limits : dict, optional
        Datasheet limits (:func:`fogdrift.spec.read_spec`), judged against the headline noise model.
    segments : str
        As :func:`fogdrift.workflows.allan.run_allan` (``apply_to``'s plausibility findings are added to the run's).
    prepared : Prepared, optional
        :func:`prepare_analyze` made already (for ``config``, ``apply_to`` and ``segments``).
    progress : callable, optional
        The epoch callback of the drift models.

    Raises
    ------
    ConfigError
        A modelling rate that does not divide either record's rate by an integer (before any work).
    """

    prep = prepared if prepared is not None else prepare_analyze(record, config, apply_to=apply_to, segments=segments)
    cfg, factor, other_factor, sc = prep.config, prep.factor, prep.apply_factor, prep.screened
    findings, segs, screens = list(sc.findings), sc.segments, sc.screens
    if apply_to is not None:
    
        findings += list(check_record(apply_to))
    result = run_analysis(record, cfg, apply_to=apply_to, progress=progress, factor=factor,
                          apply_to_factor=other_factor, segments=segs, screens=screens)
    evaluations = []
    if heading:
        
        result = evaluated_analysis(result, calib_s=calib_s, step_s=step_s, horizons_s=horizons_s)
        evaluations = evaluations_of(result)
    judgements = analysis_judgements(result, limits) if limits is not None else []
    return AnalyzeRun(record, result, bool(heading), evaluations, limits, judgements, list(findings), segs, screens)


def write_analyze(run: AnalyzeRun, out_dir, *, pdf=False, sensor=None, spec_source="") -> dict:
    """``analysis.json`` and ``report.html`` (``report.pdf`` with ``pdf``), the model ``bundle/`` and the compensated
    test block per axis in ``out_dir``.  Returns ``{"report": path, "bundle": Bundle, "compensated": [paths]}``."""

    out = Path(out_dir)
    spec_doc = None
    if run.limits is not None:  # the judgements on the report's first screen
        spec_doc = {"limits": run.limits, "judgements": run.judgements, "source": spec_source}
    result, record = run.result, run.record
    report = write_report(result, record, out, evaluated=run.evaluated, pdf=pdf,
                          sensor=None if sensor is None or not str(sensor).strip() else str(sensor).strip(),
                          spec=spec_doc)
    bundle = write_bundle(out / "bundle", [ax.models for ax in result.axes], result.config, record)
    comp = write_compensated_test_block([ax.models for ax in result.axes], out, t0_s=record.t0_s)
    return {"report": report, "bundle": bundle, "compensated": comp}
