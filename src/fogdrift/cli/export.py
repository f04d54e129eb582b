"""``fogdrift export``: write the noise model for Kalibr, OpenVINS, VINS-Fusion, ORB-SLAM3, KF-GINS, MATLAB
imuSensor, gnss-ins-sim and a complete JSON (:mod:`fogdrift.export`), from saved ``allan`` / ``noise`` results
(``--gyro`` / ``--accel``) or from a log (its Allan fit is run first and saved as ``allan.json`` beside the exports)."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Annotated, Optional

import typer

from ..errors import ConfigError
from ._app import FLAGS, app, check_plausible, echo_record, progress, run, say, warn, with_load_options

FLAGS.update({"missing": "--missing", "gyro": "--gyro", "accel": "--accel", "result": "--result",
              "rate": "--update-rate", "target": "--target"})

DEFAULT_OUT = Path("out/export")


def _targets_help() -> str:
    from ..export.targets import TARGETS  # light: the table

    return ("Targets, comma-separated, or 'all': " + "; ".join(f"{t.name} ({t.filename})" for t in TARGETS.values())
            + ".")


@app.command("export")
@with_load_options(file="none")
def export(
    log: Annotated[Optional[Path], typer.Argument(
        help="A gyro or accelerometer log to fit first (its unit says which); or give saved results with "
             "--gyro / --accel.")] = None,
    load=None,
    gyro: Annotated[Optional[list[Path]], typer.Option(
        "--gyro", help="A saved gyro result: allan.json or noise.json of a fogdrift run (repeatable).")] = None,
    accel: Annotated[Optional[list[Path]], typer.Option(
        "--accel", help="A saved accelerometer result (allan.json / noise.json), repeatable.")] = None,
    result: Annotated[Optional[list[Path]], typer.Option(
        "--result", help="A saved result whose axes are gyros and/or accelerometers (a six-channel log's): each axis "
                         "is taken as what its units say (repeatable).")] = None,
    target: Annotated[str, typer.Option("--target", help=_targets_help())] = "all",
    update_rate: Annotated[Optional[float], typer.Option(
        "--update-rate", help="The filter's IMU rate [Hz] for the discrete values (default: the record's rate).")]
    = None,
    missing: Annotated[str, typer.Option(
        "--missing", help="A term the record does not resolve (not in the selected model, or no model fits): "
                          "bound (default: its 95 % upper bound, said as a bound), refuse (stop with the reason) or "
                          "zero (write 0, with a warning).")] = "bound",
    rostopic: Annotated[str, typer.Option("--rostopic", help="IMU topic written into Kalibr / OpenVINS files.")]
    = "/imu0",
    out: Annotated[Path, typer.Option("--out", help="Output folder.")] = DEFAULT_OUT,
):
    """Export the noise model to the estimators' own files, every number with its source, interval, continuous and
    discrete value and conversion in a comment."""
    from ..export import parse_targets
    from ..export.targets import TARGETS
    from ..workflows.export import run_export, write_export

    gyro, accel, result = list(gyro or []), list(accel or []), list(result or [])
    names = [t.name for t in TARGETS.values()]
    with run("export", out, default_out=DEFAULT_OUT, inputs=[p for p in [log, *gyro, *accel, *result] if p is not None],
             expect=[TARGETS[n].filename for n in names]) as r:
        parse_targets(target)  # an unknown target: one line before the log is read
        if log is None and not gyro and not accel and not result:
            raise ConfigError("nothing to export: give a log, or saved results with --gyro / --accel / --result")
        record = None
        if log is not None:
            opts = dataclasses.replace(load, file=log)
            record = opts.load()
            echo_record(opts, record)
            check_plausible(record)
        options = dict(gyro=gyro, accel=accel, results=result, targets=target, rate_hz=update_rate, missing=missing,
                       topic=rostopic)
        if record is None:
            done = run_export(None, **options)
        else:
            with progress("export", record.axis_names) as (allan_cb, _):  # the whole record: no screen, no segments
                done = run_export(record, progress=allan_cb, **options)
        write_export(done, r.out.path)  # everything was rendered before any file is written
        ctx = done.context
        chans = ", ".join(f"{c.label} ({c.method})" for c in ctx.gyro + ctx.accel)
        say(f"exported {chans} at {ctx.rate_hz:g} Hz, --missing {ctx.missing}")
        for n in done.targets:  # per target: the time convention written, and what the user must still fill in
            conv, items = ctx.todo.get(n, ("", []))
            say(f"{n} ({TARGETS[n].filename}): time convention: {conv}; fill in: {'; '.join(items) or 'nothing'}")
        for line in ctx.notes:
            warn(line)
        r.wrote()
