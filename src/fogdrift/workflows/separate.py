"""The ``separate`` workflow: the lifting-wavelet separation of every axis into drift and white noise at the
modelling rate, with the Allan tables of the input, the drift and the noise (:func:`fogdrift.pipeline.run_separation`).

>>> from fogdrift.io import from_array
>>> from fogdrift.simulate import simulate
>>> rec = from_array(simulate(2**14, 1.0, arw_dprh=0.1, seed=1), dt_s=1.0, axis_names=["gz"])
>>> run = run_separate(rec)
>>> run.factor, [s.name for s in run.axes], [label for label, _ in run.axes[0].rows]
(1, ['gz'], ['original', 'drift', 'noise'])
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..pipeline import AnalysisConfig, model_factor, run_separation
from ..plausibility import check_record
from ..report import write_separation_outputs

__all__ = ["SeparateRun", "run_separate", "write_separate"]


@dataclass
class SeparateRun:
    """What ``fogdrift separate`` computed for one record.

    Attributes
    ----------
    record : GyroRecord
    config : fogdrift.pipeline.AnalysisConfig
    factor : int
        The block-average factor from the record's rate to the modelling rate (decided here, once).
    axes : list of fogdrift.pipeline.SeparationAxis
        One per axis: the bias-removed rate, its drift and noise [deg/h] and their Allan tables.
    findings : list
        Plausibility findings (:func:`fogdrift.plausibility.check_record`): a wrong unit or time unit.
    """

    record: object
    config: object
    factor: int
    axes: list
    findings: list = field(default_factory=list)


def run_separate(record, config=None, *, findings=None) -> SeparateRun:
    """Run ``fogdrift separate`` on a record.

    Parameters
    ----------
    record : GyroRecord
    config : fogdrift.pipeline.AnalysisConfig, optional
        ``wavelet``, ``level``, ``mode``, ``model_rate_hz`` and ``taus`` are used (default: the paper's db2 level 4 at
        1 Hz).
    findings : list, optional
        The plausibility findings when the caller made the check already (the CLI prints them before the work).

    Raises
    ------
    ConfigError
        A modelling rate that does not divide the record's rate by an integer (before any work).
    """
    cfg = (config or AnalysisConfig()).validate()
    factor = model_factor(record, cfg)
    found = list(check_record(record)) if findings is None else list(findings)
    return SeparateRun(record, cfg, factor, run_separation(record, cfg, factor=factor), found)


def write_separate(run: SeparateRun, out_dir) -> dict:
    """``separation.npz``, ``separation.csv``, ``separation_table.csv``, ``separation.json`` and the figures in
    ``out_dir`` (:func:`fogdrift.report.write_separation_outputs`); returns the paths by kind."""
    return write_separation_outputs(run.axes, out_dir)
