"""The ``noise`` workflow: the record screen, then GMWM model selection on the wavelet variance of every axis (the
longest quiet segment of a disturbed axis), its N and B checked against the Allan fit of the same record."""

from __future__ import annotations

import dataclasses

from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ..errors import InsufficientDataError
from ..evaluation.gmwm_vs_allan import compare_with_allan
from ..gmwm.analysis import analyse_gmwm, candidates_for
from ..gmwm.quantity import express_gmwm
from ..io.readers.command_memory import check_records_memory
from ..noise.spectral import analyse_spectrum
from ..report.gmwm import write_gmwm_outputs
from ..pipeline import AnalysisConfig, run_allan
from ..segments import longest_segment

from .allan import Screened, screen

__all__ = ["NoiseRun", "run_noise", "write_noise", "allan_checks"]


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

    check_records_memory("noise", record)
    sc = screened if screened is not None else screen(record, segments, command="noise")
    segs, screens = sc.segments, sc.screens
    axes, spectra = [], {}
    candidates_for(model)  # a bad model string is refused before any spectrum is computed (as analyse_gmwm does)
    for name in record.axis_names:
        rate = np.asarray(longest_segment(record.axis(name), segs[name]), dtype=np.float64)
        spectra[name] = (rate, record.dt_s, analyse_spectrum(rate, record.dt_s))  # the Allan check reuses it
        axes.append(analyse_gmwm(name, rate, record.dt_s, model=model, levels=levels, robust=bool(robust),
                                 spectrum=spectra[name][2]))
        if progress is not None:
            progress()
    checks = allan_checks(record, axes, sums=sc.sums, segments=segs, screens=screens, spectra=spectra)
    quantities = {c.name: c.quantity for c in record.signal.channels}
    axes = [express_gmwm(dataclasses.replace(a, allan_check=checks.get(a.name)), quantities[a.name]) for a in axes]
    return NoiseRun(record, axes, sc.findings, segs, screens, quantities)


def write_noise(run: NoiseRun, out_dir) -> dict:
    """``noise.json``, ``wvar.csv`` and ``noise.png`` in ``out_dir``; returns the paths by kind."""

    return write_gmwm_outputs(run.axes, out_dir, source=str(run.record.source), record=run.record.metadata())


def allan_checks(record, axes, *, sums=None, segments=None, screens=None, spectra=None) -> dict:
    """The comparison of each GMWM axis of a record with the Allan fit of the same axis (the default fit of
    ``fogdrift allan``, :func:`fogdrift.pipeline.run_allan`; :func:`fogdrift.evaluation.gmwm_vs_allan.compare_with_allan`),
    by axis name: the ``allan_check`` the workflow builds each :class:`~fogdrift.gmwm.analysis.GmwmAxis` with.

    ``sums``, ``segments``, ``screens``: what the record screen already took of each axis
    (:class:`fogdrift.workflows.allan.Screened`), handed to :func:`~fogdrift.pipeline.run_allan`, which reuses the
    octave Allan sums instead of computing them again (the same fit, field by field); ``spectra``: axis name ->
    ``(samples, dt_s, SpectrumSummary)`` the GMWM took, reused where the Allan fit analyses the same samples.  An
    axis of ``axes`` that the record does not hold gets no entry."""

    try:
        # both readings in the units of the internal unit (the GMWM's are re-stated per quantity afterwards)
        fits = {a.name: a.noise for a in run_allan(record, AnalysisConfig().validate(), own_units=False, sums=sums,
                                                   segments=segments, screens=screens, spectra=spectra)}
    except InsufficientDataError as exc:  # too short for the Allan fit: the GMWM result stands, and says so
        return {a.name: {"agree": None, "n_agree": None, "b_agree": None,
                         "lines": [f"no comparison: the Allan fit needs more data ({exc})"]} for a in axes}
    return {a.name: compare_with_allan(a, fits[a.name]) for a in axes if a.name in fits}
