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

from dataclasses import dataclass

from ..pipeline import run_separation
from ..report import write_separation_outputs
from ._modelled import ModelledRun, modelling, plausibility_findings

__all__ = ["SeparateRun", "run_separate", "write_separate"]


@dataclass
class SeparateRun(ModelledRun):
    """What ``fogdrift separate`` computed for one record (the fields of :class:`ModelledRun`).

    Attributes
    ----------
    axes : list of fogdrift.pipeline.SeparationAxis
        One per axis: the bias-removed rate, its drift and noise [deg/h] and their Allan tables.
    findings : list
        Plausibility findings (:func:`fogdrift.plausibility.check_record`): a wrong unit or time unit.
    """


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
    cfg, factor = modelling(record, config)
    found = plausibility_findings(record, findings)
    return SeparateRun(record, cfg, factor, run_separation(record, cfg, factor=factor), found)


def write_separate(run: SeparateRun, out_dir) -> dict:
    """``separation.npz``, ``separation.csv``, ``separation_table.csv``, ``separation.json`` and the figures in
    ``out_dir`` (:func:`fogdrift.report.write_separation_outputs`); returns the paths by kind."""
    return write_separation_outputs(run.axes, out_dir)
