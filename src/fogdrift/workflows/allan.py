"""The ``allan`` workflow: plausibility, the record screen, the Allan-family variance and noise fit of every axis.

>>> from fogdrift.io import from_array
>>> from fogdrift.simulate import simulate
>>> rec = from_array(simulate(2**14, 0.01, arw_dprh=0.1, seed=1), dt_s=0.01, axis_names=["gz"])
>>> run = run_allan(rec)
>>> [a.name for a in run.results], run.results[0].noise.terms["N"].status
(['gz'], 'resolved')
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

from ..io.readers.command_memory import check_records_memory
from ..pipeline import AnalysisConfig
from ..pipeline import run_allan as _fit
from ..plausibility import check_record
from ..report import write_allan_outputs
from ..report.files import allan_document
from ..segments import plan_segments

__all__ = ["AllanRun", "Screened", "screen", "run_allan", "write_allan"]


@dataclass
class AllanRun:
    """What ``fogdrift allan`` computed for one record.

    Attributes
    ----------
    record : GyroRecord
    config : fogdrift.pipeline.AnalysisConfig
    results : list of fogdrift.pipeline.AllanAxis
        One per axis.
    findings : list
        Plausibility findings (:func:`fogdrift.plausibility.check_record`): a wrong unit or time unit.
    segments, screens : dict
        The segment plan and the record screen of every axis (:func:`fogdrift.segments.plan_segments`).
    """

    record: object
    config: object
    results: list
    findings: list = field(default_factory=list)
    segments: dict = field(default_factory=dict)
    screens: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        """The ``allan.json`` document (:func:`fogdrift.report.files.allan_document`): what :func:`write_allan` writes
        and what :func:`fogdrift.export.model.channels_from_result` reads."""
        return allan_document(self.results, self.record)


@dataclass
class Screened:
    """The checks made before any fit (:func:`screen`): the plausibility findings, the segment plan and the record
    screen of every axis, and the octave Allan sums of the noise floors the plausibility check computed (the Allan
    fit reuses them)."""

    findings: list
    segments: dict
    screens: dict
    sums: dict = field(default_factory=dict, repr=False)


def screen(record, segments="auto", *, command: str = "allan") -> Screened:
    """The checks every workflow makes before its fit (a command may call it first to print them, then hand the
    result to the workflow's ``screened=``).  First of all, ``command``'s memory need for the record is held to
    the memory budget (:func:`fogdrift.io.readers.command_memory.check_records_memory`: one line, no work done)."""
    check_records_memory(command, record)

    sums: dict = {}
    findings = list(check_record(record, sums=sums))
    segs, screens = plan_segments(record, segments)
    return Screened(findings, segs, screens, sums)


def run_allan(record, config=None, *, segments="auto", progress: Callable | None = None,
              screened: Screened | None = None) -> AllanRun:
    """Run ``fogdrift allan`` on a record.

    Parameters
    ----------
    record : GyroRecord
    config : fogdrift.pipeline.AnalysisConfig, optional
        Default: the command's defaults.
    segments : str
        ``"auto"``, ``"whole"`` or ``"A:B,C:D"`` [s] (:func:`fogdrift.segments.parse_segments`).
    progress : callable, optional
        Per-axis progress callback of :func:`fogdrift.pipeline.run_allan`.
    screened : Screened, optional
        The checks of :func:`screen` made already for ``segments`` (the CLI prints them before the fit).
    """

    cfg = (config or AnalysisConfig()).validate()
    sc = screened if screened is not None else screen(record, segments)
    results = _fit(record, cfg, progress=progress, sums=sc.sums, segments=sc.segments, screens=sc.screens)
    return AllanRun(record, cfg, results, sc.findings, sc.segments, sc.screens)


def write_allan(run: AllanRun, out_dir) -> dict:
    """``allan.json``, ``allan.csv`` and ``allan.png`` (and ``allan_dynamic.png`` for a disturbed axis) in
    ``out_dir``; returns the paths by kind."""

    return write_allan_outputs(run.results, run.record, out_dir)
