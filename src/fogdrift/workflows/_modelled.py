"""What the commands that work at the modelling rate (``separate``, ``model``, ``analyze``) decide before any work,
and the run object ``separate`` and ``model`` share.

The configuration is validated and the block-average factor from the record's rate to the modelling rate is decided
here, once (:func:`modelling`); a modelling rate that does not divide the record's rate is refused before any work.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..pipeline import AnalysisConfig, model_factor
from ..plausibility import check_record

__all__ = ["ModelledRun", "modelling", "plausibility_findings"]


@dataclass
class ModelledRun:
    """One result per axis at the modelling rate, beside the inputs it was made from.

    Attributes
    ----------
    record : GyroRecord
    config : fogdrift.pipeline.AnalysisConfig
    factor : int
        The block-average factor from the record's rate to the modelling rate (decided once, by :func:`modelling`).
    axes : list
        One per axis, the command's result.
    findings : list
        Plausibility findings (:func:`fogdrift.plausibility.check_record`).
    """

    record: object
    config: object
    factor: int
    axes: list
    findings: list = field(default_factory=list)


def modelling(record, config=None) -> tuple:
    """``(config, factor)``: the validated configuration (default :class:`~fogdrift.pipeline.AnalysisConfig`) and
    the block-average factor of ``record`` to its modelling rate (ConfigError when it is not an integer)."""
    cfg = (config or AnalysisConfig()).validate()
    return cfg, model_factor(record, cfg)


def plausibility_findings(record, findings=None) -> list:
    """The findings the caller made already (the CLI prints them before the work), or the record's own check."""
    return list(check_record(record)) if findings is None else list(findings)
