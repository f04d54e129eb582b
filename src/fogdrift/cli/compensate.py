"""``fogdrift compensate BUNDLE FILE``: apply a saved bundle causally to a new log and judge it in heading error."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Optional

import typer
from rich.text import Text

from ..errors import render_options
from ._app import FLAGS, OutOpt, _configure, app, console, csv_list, errors, fitted_table, progress_count


@app.command()
def compensate(
    bundle: Annotated[Path, typer.Argument(help="Bundle directory written by 'analyze' or 'model' (OUT/bundle).")],
    file: Annotated[Path, typer.Argument(help="Gyro log to compensate: CSV/TXT (optionally .gz), .npy (streamed) "
                                              "or .npz.")],
    model: Annotated[Optional[str], typer.Option(
        "--model", help="Model of the bundle to apply (registry name, e.g. kalman, ar, grey-elman) or 'bias' for "
                        "constant-bias compensation only; default: kalman if the bundle has it, else bias.")] = None,
    bias: Annotated[str, typer.Option(
        "--bias", help="'keep' the bundle's bias, or 're-estimate:SECONDS' on the first SECONDS of the log.")] = "keep",
    apply_unit: Annotated[Optional[str], typer.Option(
        "--apply-unit", help="Unit of FILE's numbers (deg/h, deg/s, rad/s, ..., inc:arcsec); needed when it declares "
                             "another unit than the bundle's; default: declared, else the bundle's.")] = None,
    axis_map: Annotated[Optional[str], typer.Option(
        "--axis-map", help="LOG_AXIS=BUNDLE_AXIS pairs, comma-separated, for axes whose names differ "
                           "(e.g. col0=gz).")] = None,
    accept_rate: Annotated[bool, typer.Option(
        "--accept-rate", help="Accept a native rate other than the training log's (block-averaged to the "
                              "bundle's modelling rate).")] = False,
    rate: Annotated[Optional[float], typer.Option("--rate", help="Sample rate [Hz] (if FILE has no time column).")]
    = None,
    time_unit: Annotated[Optional[str], typer.Option("--time-unit", help="Unit of the time column: s, ms, us, ns.")]
    = None,
    columns: Annotated[Optional[str], typer.Option("--columns", help="Comma-separated column names or indices.")]
    = None,
    time_column: Annotated[str, typer.Option("--time-column", help="Time column name/index, 'auto' or 'none'.")]
    = "auto",
    chunk: Annotated[int, typer.Option("--chunk", help="Rows read at a time (memory bound; outputs do not depend "
                                                       "on it).")] = 1 << 20,
    formats: Annotated[str, typer.Option("--formats", help="Output files: csv, npz or csv,npz.")] = "csv,npz",
    heading: Annotated[bool, typer.Option("--heading/--no-heading", help="Heading-error evaluation of every model "
                                                                         "of the bundle on FILE.")] = True,
    artefacts: Annotated[bool, typer.Option("--artefacts/--no-artefacts", help="Filtering-artefact check (injected "
                                                                               "step, ramp, sinusoids); on by default, "
                                                                               "its caveat goes on the before/after "
                                                                               "figure.")] = True,
    calibration: Annotated[float, typer.Option("--calibration", help="Calibration window [s] before each origin.")]
    = 300.0,
    origin_step: Annotated[float, typer.Option("--origin-step", help="Spacing of the rolling origins [s].")] = 300.0,
    horizons: Annotated[str, typer.Option("--horizons", help="Forecast horizons [s], comma-separated.")]
    = "60,600,3600",
    out: OutOpt = Path("out/compensate"),
):
    """Apply a bundle causally to FILE (each output sample uses only past input) at FILE's native rate, write the
    compensated rate and the subtracted drift (CSV/NPZ), a JSON summary and before/after Allan figures, and print
    the heading-error table."""
    from ..compensate import compensate_file
    from ..errors import ConfigError

    _configure()  # this run's console widths (a terminal, else COLUMNS, else whole lines), as run() does
    with errors():
        try:
            hs = tuple(float(h) for h in csv_list(horizons))
        except ValueError:
            raise ConfigError(f"--horizons must be numbers of seconds separated by commas; got {horizons!r}") from None
        with progress_count("compensate", "samples") as update:
            result = compensate_file(
                bundle, file, out, model=model, bias=bias, apply_unit=apply_unit, axis_map=axis_map,
                accept_rate=accept_rate, columns=columns,
                time_column=None if time_column.lower() == "none" else time_column,
                rate_hz=rate, time_unit=time_unit, chunk_samples=chunk, formats=tuple(csv_list(formats) or ()),
                heading=heading, artefacts=artefacts, calib_s=calibration, step_s=origin_step, horizons_s=hs,
                flags=FLAGS, progress=update)
        s = result.summary
        console.print(Text(f"compensated {s['n_samples']} samples of {file.name} with {s['model_label']} "
                           f"(unit {s['unit']}, {1 / s['native_dt_s']:g} Hz, models at {1 / s['model_dt_s']:g} Hz)"),
                      soft_wrap=True)
        for line in result.messages:
            console.print(Text("  " + render_options(line, FLAGS)), highlight=False, soft_wrap=True)
        print_evaluation(result.heading, result.artefacts, result.verdicts)
        console.print(Text(f"wrote {', '.join(str(p) for p in result.files.values())}"), soft_wrap=True)


def print_evaluation(headings, artefacts, verdicts):
    """Heading-error tables, artefact tables, then the verdict lines (headline first)."""
    from ..evaluation import artefact_table, heading_table

    for h in headings:
        headers, rows = heading_table(h)
        console.print(fitted_table(f"axis {h.axis}: heading error after a {h.calib_s:g}-s calibration "
                            f"(RMS over origins every {h.step_s:g} s; ratio to constant bias)", headers, rows))
    for a in artefacts:
        headers, rows = artefact_table(a)
        console.print(fitted_table(f"axis {a.axis}: surviving fraction of injected signals "
                            f"(amplitude {a.amplitude_dph:.4g} deg/h)", headers, rows))
    for v in verdicts:
        for line in v.lines:
            console.print(Text("  " + render_options(line, FLAGS)), highlight=False, soft_wrap=True)
