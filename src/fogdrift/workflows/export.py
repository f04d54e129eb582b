"""The ``export`` workflow: the noise model of gyro and accelerometer channels written in the estimators' own files
(Kalibr, OpenVINS, VINS-Fusion, ORB-SLAM3, KF-GINS, MATLAB imuSensor, gnss-ins-sim, a complete JSON;
:mod:`fogdrift.export`), from saved ``allan``/``noise`` results or from a record whose Allan fit is made first.

>>> from fogdrift.io import from_array
>>> from fogdrift.simulate import simulate
>>> rec = from_array(simulate(2**14, 0.01, arw_dprh=0.1, seed=1), dt_s=0.01, axis_names=["gz"])
>>> run = run_export(rec, targets="kalibr")
>>> sorted(run.texts), run.context.rate_hz
(['kalibr'], 100.0)
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..export import build_context, parse_targets, render
from ..export.model import channels_from_result
from ..export.targets import TARGETS
from ..output import atomic_path
from ..pipeline import AnalysisConfig, run_allan

from .allan import AllanRun, write_allan

__all__ = ["ExportRun", "run_export", "write_export"]


@dataclass
class ExportRun:
    """What ``fogdrift export`` computed.

    Attributes
    ----------
    context : fogdrift.export.ExportContext
        The channels, the filter's rate, the ``missing`` policy, the notes and each target's to-do list.
    texts : dict
        Target name -> the text of its file (every target rendered before any file is written).
    fit : AllanRun or None
        The Allan fit of the record when one was given (written as ``allan.json`` beside the exports).
    """

    context: object
    texts: dict
    fit: AllanRun | None = None

    @property
    def targets(self) -> list:
        return list(self.texts)


def run_export(record=None, *, gyro=(), accel=(), results=(), targets="all", rate_hz=None, missing="bound",
               topic="/imu0", progress=None) -> ExportRun:
    """Run ``fogdrift export``.

    Parameters
    ----------
    record : GyroRecord, optional
        A log of gyro and/or accelerometer channels: its Allan fit (the default fit of ``fogdrift allan`` on the
        whole record, no segments) is made and exported.
    gyro, accel, results : sequence of path
        Saved results (``allan.json``/``noise.json``) of gyro channels, accelerometer channels, or either (each axis
        taken as what its units say).
    targets : str
        Comma-separated target names or ``"all"`` (:data:`fogdrift.export.targets.TARGETS`).
    rate_hz : float, optional
        The filter's IMU rate [Hz] for the discrete values (default: the records' rate).
    missing : str
        A term the record does not resolve: ``"bound"`` (its 95 % upper bound, said as a bound), ``"refuse"`` or
        ``"zero"``.
    topic : str
        The IMU topic written into Kalibr / OpenVINS files.
    progress : callable, optional
        Called after each axis of the record's Allan fit.

    Raises
    ------
    ConfigError
        Nothing to export, an unknown target or policy, channels at different rates without ``rate_hz``.
    """
    chosen = parse_targets(targets)
    fit = None
    channels = []
    if record is not None:
        cfg = AnalysisConfig()
        fit = AllanRun(record, cfg, run_allan(record, cfg, progress=progress))  # the whole record: no screen
        channels = channels_from_result(fit, str(record.source))
    ctx = build_context(gyro, accel, results=results, channels=channels, rate_hz=rate_hz, missing=missing,
                        topic=topic)
    return ExportRun(ctx, {n: render(n, ctx) for n in chosen}, fit)


def write_export(run: ExportRun, out_dir) -> dict:
    """Each target's file (and ``allan.json``, ``allan.csv``, ``allan.png`` of a record's fit) in ``out_dir``;
    returns the paths by target name (and ``"allan"``)."""
    out = Path(out_dir)
    files = {}
    if run.fit is not None:
        files["allan"] = write_allan(run.fit, out)["json"]
    for n, text in run.texts.items():
        with atomic_path(out / TARGETS[n].filename) as tmp:
            Path(tmp).write_text(text, encoding="utf-8")
        files[n] = out / TARGETS[n].filename
    return files
