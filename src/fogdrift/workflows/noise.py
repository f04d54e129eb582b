"""The ``noise`` workflow: the record screen, then GMWM model selection on the wavelet variance of every axis (the
longest quiet segment of a disturbed axis), its N and B checked against the Allan fit of the same record."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

from ..gmwm.analysis import analyse_gmwm
from ..gmwm.compare import attach_allan_checks
from ..gmwm.quantity import express_gmwm
from ..report.gmwm import write_gmwm_outputs
from ..segments import longest_segment

from .allan import Screened, screen

__all__ = ["NoiseRun", "run_noise", "write_noise"]


@dataclass
class NoiseRun:
    """What ``fogdrift noise`` (GMWM) computed for one record.

    Attributes
    ----------
    record : GyroRecord
    axes : list of fogdrift.gmwm.analysis.GmwmAxis
        One per axis, an accelerometer's terms in its own units (:func:`fogdrift.gmwm.quantity.express_gmwm`).
    findings, segments, screens
        As :class:`fogdrift.workflows.allan.AllanRun`.
    quantities : dict
        Axis name -> the channel's quantity.
    """

    record: object
    axes: list
    findings: list = field(default_factory=list)
    segments: dict = field(default_factory=dict)
    screens: dict = field(default_factory=dict)
    quantities: dict = field(default_factory=dict)


def run_noise(record, *, model="auto", levels=None, robust=False, segments="auto", progress: Callable | None = None,
              screened: Screened | None = None) -> NoiseRun:
    """Run ``fogdrift noise`` (GMWM) on a record.

    Parameters
    ----------
    model : str
        ``"auto"`` (selection by WIC among the default candidates) or a model such as ``"WN+RW+GM"``.
    levels : int or None
        Number of wavelet scales J (default floor(log2 N) - 1).
    robust : bool
        Huber-robust wavelet variance.
    segments, screened
        As :func:`fogdrift.workflows.allan.run_allan`.
    progress : callable, optional
        Called with no argument after each axis.
    """

    sc = screened if screened is not None else screen(record, segments)
    segs, screens = sc.segments, sc.screens
    axes = []
    for name in record.axis_names:
        axes.append(analyse_gmwm(name, longest_segment(record.axis(name), segs[name]), record.dt_s, model=model,
                                 levels=levels, robust=bool(robust)))
        if progress is not None:
            progress()
    attach_allan_checks(record, axes, sums=sc.sums, segments=segs, screens=screens)
    quantities = {c.name: c.quantity for c in record.signal.channels}
    axes = [express_gmwm(a, quantities[a.name]) for a in axes]
    return NoiseRun(record, axes, sc.findings, segs, screens, quantities)


def write_noise(run: NoiseRun, out_dir) -> dict:
    """``noise.json``, ``wvar.csv`` and ``noise.png`` in ``out_dir``; returns the paths by kind."""

    return write_gmwm_outputs(run.axes, out_dir, source=str(run.record.source), record=run.record.metadata())
