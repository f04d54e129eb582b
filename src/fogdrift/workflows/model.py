"""The ``model`` workflow: every configured drift model fitted on the training block of every axis and compared on
the test block (:func:`fogdrift.pipeline.run_models`), and its files: the saved models, ``metrics.json``, Fig. 8 and 9
and the self-describing model ``bundle/`` that ``fogdrift compensate`` applies to other logs."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

from ..bundle import write_bundle
from ..pipeline import AnalysisConfig, model_factor, run_models
from ..plausibility import check_record
from ..report import write_model_outputs

__all__ = ["ModelRun", "run_model", "write_model"]


@dataclass
class ModelRun:
    """What ``fogdrift model`` computed for one record.

    Attributes
    ----------
    record : GyroRecord
    config : fogdrift.pipeline.AnalysisConfig
    factor : int
        The block-average factor from the record's rate to the modelling rate (decided here, once).
    axes : list of fogdrift.pipeline.ModelAxis
        One per axis: the fitted models, their predictions and metrics on the test block.
    findings : list
        Plausibility findings (:func:`fogdrift.plausibility.check_record`).
    """

    record: object
    config: object
    factor: int
    axes: list
    findings: list = field(default_factory=list)


def run_model(record, config=None, *, progress: Callable | None = None, findings=None) -> ModelRun:
    """Run ``fogdrift model`` on a record.

    Parameters
    ----------
    record : GyroRecord
    config : fogdrift.pipeline.AnalysisConfig, optional
        ``models`` and their settings, the separation and the modelling rate (default: every registered model).
    progress : callable, optional
        The epoch callback of the drift models.
    findings : list, optional
        The plausibility findings when the caller made the check already.

    Raises
    ------
    ConfigError
        A modelling rate that does not divide the record's rate by an integer (before any work).
    """
    cfg = (config or AnalysisConfig()).validate()
    factor = model_factor(record, cfg)
    found = list(check_record(record)) if findings is None else list(findings)
    return ModelRun(record, cfg, factor, run_models(record, cfg, progress=progress, factor=factor), found)


def write_model(run: ModelRun, out_dir) -> dict:
    """The saved models, ``metrics.json``, Fig. 8 and 9 per axis (:func:`fogdrift.report.write_model_outputs`) and
    the model ``bundle/`` (:func:`fogdrift.bundle.write_bundle`) in ``out_dir``.  Returns ``{"dir": path,
    "metrics": path, "bundle": Bundle}``."""
    out = Path(out_dir)
    files = dict(write_model_outputs(run.axes, out))
    files["metrics"] = out / "metrics.json"
    files["bundle"] = write_bundle(out / "bundle", run.axes, run.config, run.record)
    return files
