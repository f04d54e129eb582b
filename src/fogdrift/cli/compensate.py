"""``fogdrift compensate BUNDLE FILE``: apply a saved bundle causally to a new log and judge it in heading error."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Optional

import typer
from rich.text import Text

from ..errors import ConfigError, render_options
from ..signal import record_sampling, record_units
from ._app import (FLAGS, LoadOptions, OutOpt, app, console, csv_list, fitted_table, progress_count, run,
                   warn, with_load_options)

DEFAULT_OUT = Path("out/compensate")

#: Output files of a complete run (the figure only when an axis has enough samples).
EXPECTED = ("compensated.csv", "compensated.npz", "compensation.json")


@app.command()
@with_load_options(file="after")
def compensate(
    bundle: Annotated[Path, typer.Argument(help="Bundle directory written by 'analyze' or 'model' (OUT/bundle).")],
    load: LoadOptions,
    model: Annotated[Optional[str], typer.Option(
        "--model", help="Model of the bundle to apply (registry name, e.g. kalman, ar, grey-elman) or 'bias' for "
                        "constant-bias compensation only; default: kalman if the bundle has it, else bias.")] = None,
    bias: Annotated[str, typer.Option(
        "--bias", help="'keep' the bundle's bias, or 're-estimate:SECONDS' on the first SECONDS of the log.")] = "keep",
    apply_unit: Annotated[Optional[str], typer.Option(
        "--apply-unit", hidden=True, help="Deprecated spelling of --unit.")] = None,
    axis_map: Annotated[Optional[str], typer.Option(
        "--axis-map", help="LOG_AXIS=BUNDLE_AXIS pairs, comma-separated, for axes whose names differ "
                           "(e.g. col0=gz).")] = None,
    accept_rate: Annotated[bool, typer.Option(
        "--accept-rate", help="Accept a native rate other than the training log's (block-averaged to the "
                              "bundle's modelling rate).")] = False,
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
    out: OutOpt = DEFAULT_OUT,
):
    """Apply a bundle causally to FILE (each output sample uses only past input) at FILE's native rate, write the
    compensated rate and the subtracted drift (CSV/NPZ), a JSON summary and before/after Allan figures, and print
    the heading-error table.  FILE is read with the same options as every command (a .npy is streamed in chunks);
    a FILE that declares no unit needs --unit."""
    from ..compensate import compensate_file

    fmts = tuple(csv_list(formats) or ())
    with run("compensate", out, default_out=DEFAULT_OUT, inputs=[bundle, load.file],
             expect=tuple(n for n in EXPECTED if n.rsplit(".", 1)[-1] in fmts or n.endswith(".json"))):
        try:
            hs = tuple(float(h) for h in csv_list(horizons))
        except ValueError:
            raise ConfigError(f"--horizons must be numbers of seconds separated by commas; got {horizons!r}") from None
        unit = load.unit
        if apply_unit is not None:
            warn("--apply-unit is deprecated; use --unit (the same meaning)")
            if unit is not None and unit.strip() != apply_unit.strip():
                raise ConfigError(f"--unit {unit} and --apply-unit {apply_unit} disagree; pass --unit only")
            unit = apply_unit
        if load.gaps not in ("error", "longest"):
            raise ConfigError(f"--gaps must be 'error' or 'longest', got {load.gaps!r}")
        kwargs = load.load_kwargs()
        kwargs.update(unit=unit, gaps="split" if load.gaps == "longest" else "error")
        with progress_count("compensate", "samples") as update:
            result = compensate_file(
                bundle, load.file, out, model=model, bias=bias, axis_map=axis_map, accept_rate=accept_rate,
                chunk_samples=chunk, formats=fmts, heading=heading, artefacts=artefacts, calib_s=calibration,
                step_s=origin_step, horizons_s=hs, flags=FLAGS, progress=update, **kwargs)
        s = result.summary
        # the log's rate and unit: its signal description's
        log_hz = record_sampling(s, "compensation.json").rate_hz
        log_unit = record_units(s, "compensation.json").input_unit
        console.print(Text(f"compensated {s['n_samples']} samples of {load.file.name} with {s['model_label']} "
                           f"(unit {log_unit}, {log_hz:g} Hz, models at {1 / s['model_dt_s']:g} Hz)"),
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
