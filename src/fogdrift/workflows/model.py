"""The ``model`` workflow: every configured drift model fitted on the training block of every axis and compared on
the test block (:func:`fogdrift.pipeline.run_models`), and its files: the saved models, ``metrics.json``, Fig. 8 and 9
and the self-describing model ``bundle/`` that ``fogdrift compensate`` applies to other logs."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from ..bundle import write_bundle
from ..pipeline import run_models
from ..report import write_model_outputs
from ._modelled import ModelledRun, modelling, plausibility_findings

__all__ = ["ModelRun", "run_model", "write_model"]


@dataclass
class ModelRun(ModelledRun):
    """What ``fogdrift model`` computed for one record (the fields of :class:`ModelledRun`).

    Attributes
    ----------
    axes : list of fogdrift.pipeline.ModelAxis
        One per axis: the fitted models, their predictions and metrics on the test block.
    """


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
    cfg, factor = modelling(record, config)
    found = plausibility_findings(record, findings)
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
