"""Command-line interface: ``fogdrift allan | separate | model | analyze``.

Commands only declare options, call the library (:mod:`fogdrift.pipeline`) and the renderer
(:mod:`fogdrift.report`), and print rich tables. A :class:`~fogdrift.errors.FogdriftError` is printed as one red
line and exits 1 (``--traceback`` re-raises it); usage errors keep typer's exit 2.
"""

from __future__ import annotations

import contextlib
import sys
from pathlib import Path
from typing import Annotated, Optional

import typer
from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn
from rich.table import Table
from rich.text import Text

from . import __version__
from .errors import ConfigError, FogdriftError

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    context_settings={"help_option_names": ["-h", "--help"]},
    help="Characterise, separate, model and compensate optical-gyro drift (rates in deg/h, tau in s).",
)
# Tables are wide: when output goes to a file or pipe (logs, CI), do not wrap them at rich's 80 columns.
console = Console(width=None if sys.stdout.isatty() else 220)
err_console = Console(stderr=True, width=None if sys.stderr.isatty() else 220)
_state = {"traceback": False}


def _version(value: bool):
    if value:
        console.print(f"fogdrift {__version__}")
        raise typer.Exit()


@app.callback()
def _main(
    traceback: Annotated[bool, typer.Option("--traceback", help="Show the full traceback of an error.")] = False,
    version: Annotated[Optional[bool], typer.Option("--version", callback=_version, is_eager=True,
                                                    help="Print the version and exit.")] = None,
):
    _state["traceback"] = traceback


# -- shared options ---------------------------------------------------------------------------------------------
FileArg = Annotated[Path, typer.Argument(help="Gyro log: CSV/TXT (optionally .gz), .npy or .npz.")]
RateOpt = Annotated[Optional[float], typer.Option("--rate", help="Sample rate [Hz] (if the file has no time column).")]
UnitOpt = Annotated[str, typer.Option(
    "--unit", help="Input unit: deg/h, deg/s, rad/s, rad/h, arcsec/s, or angle increments inc:deg, inc:rad, inc:arcsec.")]
ColsOpt = Annotated[Optional[str], typer.Option("--columns", help="Comma-separated column names or 0-based indices.")]
TimeOpt = Annotated[str, typer.Option("--time-column", help="Time column name/index, 'auto' or 'none'.")]
GapsOpt = Annotated[str, typer.Option("--gaps", help="Time gaps > 1.5 intervals: 'error' or 'longest' segment.")]
OutOpt = Annotated[Path, typer.Option("--out", help="Output directory.")]
ModelRateOpt = Annotated[float, typer.Option(
    "--model-rate", help="Modelling rate [Hz]: block-average to it before separation/modelling (0 = native).")]
WaveletOpt = Annotated[str, typer.Option("--wavelet", help="Lifting wavelet (haar, db2, …).")]
LevelOpt = Annotated[str, typer.Option("--level", help="Decomposition level or 'auto'.")]
ModeOpt = Annotated[str, typer.Option("--mode", help="Boundary mode: symmetric or periodization.")]
TausOpt = Annotated[str, typer.Option("--taus", help="Tau grid: octave, decade, all, or a number of log-spaced taus.")]
FitTausOpt = Annotated[str, typer.Option("--fit-taus", help="Tau range of the noise fit MIN:MAX [s], "
                                                                "either side may be empty, e.g. '1:'.")]
EstOpt = Annotated[str, typer.Option("--estimator", help="overlapping, non-overlapping or fast.")]


def _load(path, rate, unit, columns, time_column, gaps):
    from .io import load, load_segments

    cols = _csv_list(columns)
    tcol = None if time_column.lower() == "none" else time_column
    kwargs = dict(columns=cols, time_column=tcol, rate_hz=rate, unit=unit)
    if gaps == "error":
        return load(path, **kwargs)
    if gaps == "longest":
        segs = load_segments(path, **kwargs)
        longest = max(segs, key=lambda s: s.n_samples)
        err_console.print(f"[yellow]{path}: {len(segs)} segments between gaps; analysing the longest "
                          f"({longest.n_samples} samples, {', '.join(longest.notes)})[/yellow]")
        return longest
    raise ConfigError(f"--gaps must be 'error' or 'longest', got {gaps!r}")


def _csv_list(text: str | None) -> list[str] | None:
    """'a, b,,c' -> ['a', 'b', 'c'] (None stays None)."""
    return None if text is None else [t.strip() for t in text.split(",") if t.strip()]


def _level(text: str):
    if text == "auto":
        return "auto"
    try:
        return int(text)
    except ValueError:
        raise ConfigError(f"--level must be an integer >= 1 or 'auto', got {text!r}") from None


def _fit_taus(text: str):
    lo, sep, hi = text.partition(":")
    try:
        if not sep:
            raise ValueError
        return (float(lo) if lo.strip() else None, float(hi) if hi.strip() else None)
    except ValueError:
        raise ConfigError(f"--fit-taus must look like MIN:MAX in seconds (e.g. '1:' or '0.1:300'), got {text!r}") from None


def _taus(text: str):
    return int(text) if text.isdigit() else text


@contextlib.contextmanager
def _errors():
    try:
        yield
    except FogdriftError as exc:
        if _state["traceback"]:
            raise
        err_console.print(Text("error: ", style="bold red") + Text(str(exc)), highlight=False, soft_wrap=True)
        raise typer.Exit(code=1) from None


@contextlib.contextmanager
def _progress(description: str):
    """Yield (allan_cb, epoch_cb) callbacks that drive one rich progress bar."""
    with Progress(TextColumn("{task.description}"), BarColumn(), TextColumn("{task.completed}/{task.total}"),
                  TimeElapsedColumn(), console=err_console, transient=True) as bar:
        task = bar.add_task(description, total=None)

        def allan_cb(done, total):
            bar.update(task, description=f"{description}: Allan", completed=done, total=total)

        def epoch_cb(epoch, n_epochs, train_loss, val_loss):
            bar.update(task, description=f"{description}: epoch, loss {train_loss:.3g} / val {val_loss:.3g}",
                       completed=epoch, total=n_epochs)

        yield allan_cb, epoch_cb


def _noise_table(title, rows) -> Table:
    from .report import NOISE_HEADERS

    return _table(title, ("signal",) + NOISE_HEADERS, rows)


def _table(title, headers, rows) -> Table:
    """A rich table of plain text (units such as [deg/h] must not be read as rich markup)."""
    table = Table(title=Text(title), title_justify="left")
    for i, h in enumerate(headers):
        table.add_column(Text(h), justify="left" if i == 0 else "right")
    for row in rows:
        table.add_row(*(Text(str(c)) for c in row))
    return table


def _print_noise_notes(label, noise):
    from .report import not_estimable_notes, readout_text

    for note in not_estimable_notes(noise):
        console.print(Text(f"  {label} {note}", style="dim"), highlight=False)
    console.print(Text(f"  {label} slope read-outs (cross-check): {readout_text(noise)}"), highlight=False)


def _metrics_table(title, rows) -> Table:
    from .report import METRICS_HEADERS

    return _table(title, METRICS_HEADERS, rows)


# -- commands ---------------------------------------------------------------------------------------------------
@app.command()
def allan(
    file: FileArg,
    rate: RateOpt = None,
    unit: UnitOpt = "deg/h",
    columns: ColsOpt = None,
    time_column: TimeOpt = "auto",
    gaps: GapsOpt = "error",
    estimator: EstOpt = "overlapping",
    taus: TausOpt = "octave",
    terms: Annotated[str, typer.Option("--terms", help="Noise terms to fit, e.g. Q,N,B,K,R.")] = "Q,N,B,K,R",
    fit_taus: FitTausOpt = ":",
    out: OutOpt = Path("out/allan"),
):
    """Allan variance and IEEE-952 noise coefficients Q, N, B, K, R of every axis."""
    from .pipeline import AnalysisConfig, run_allan
    from .report import noise_row, write_allan_outputs

    with _errors():
        record = _load(file, rate, unit, columns, time_column, gaps)
        cfg = AnalysisConfig(taus=_taus(taus), estimator=estimator, fit_tau_s=_fit_taus(fit_taus),
                             terms=tuple(t.upper() for t in _csv_list(terms)))
        with _progress("allan") as (allan_cb, _):
            results = run_allan(record, cfg, progress=allan_cb)
        console.print(_noise_table(
            f"{file.name}: {record.n_samples} samples at {record.fs_hz:g} Hz ({record.duration_s:.1f} s), "
            f"{estimator} ADEV, 95 % intervals in brackets",
            [[a.name] + noise_row(a.noise) for a in results]))
        for a in results:
            _print_noise_notes(a.name, a.noise)
        files = write_allan_outputs(results, record, out)
        console.print(f"wrote {files['json']}, {files['csv']}, {files['png']}")


@app.command()
def separate(
    file: FileArg,
    rate: RateOpt = None,
    unit: UnitOpt = "deg/h",
    columns: ColsOpt = None,
    time_column: TimeOpt = "auto",
    gaps: GapsOpt = "error",
    wavelet: WaveletOpt = "db2",
    level: LevelOpt = "4",
    mode: ModeOpt = "symmetric",
    model_rate: ModelRateOpt = 1.0,
    taus: TausOpt = "octave",
    out: OutOpt = Path("out/separate"),
):
    """Lifting-wavelet separation into drift (approximation) and white noise (details)."""
    from .pipeline import AnalysisConfig, run_separation
    from .report import noise_row, write_separation_outputs

    with _errors():
        record = _load(file, rate, unit, columns, time_column, gaps)
        cfg = AnalysisConfig(wavelet=wavelet, level=_level(level), mode=mode,
                             model_rate_hz=model_rate or None, taus=_taus(taus))
        seps = run_separation(record, cfg)
        for s in seps:
            console.print(_noise_table(
                f"axis {s.name}: {wavelet} level {s.level}, {mode}, dt {s.dt_s:g} s "
                f"(max |drift + noise - input| = {abs(s.drift_dph + s.noise_dph - s.rate_dph).max():.2e} deg/h)",
                [[label] + noise_row(aa.noise) for label, aa in s.rows]))
            if s.level_scan:
                console.print("  level scan: " + "; ".join(
                    f"L{d.level}: noise slope {d.noise_adev_slope:+.2f}" for d in s.level_scan))
        write_separation_outputs(seps, out)
        console.print(f"wrote drift/noise series, figures and tables to {out}")


@app.command()
def model(
    file: FileArg,
    rate: RateOpt = None,
    unit: UnitOpt = "deg/h",
    columns: ColsOpt = None,
    time_column: TimeOpt = "auto",
    gaps: GapsOpt = "error",
    models: Annotated[str, typer.Option("--models", help="Comma-separated: grey-elman, elman, gm11, ar, persistence.")]
    = "grey-elman,elman,gm11,ar,persistence",
    hidden: Annotated[int, typer.Option("--hidden", help="Elman hidden units.")] = 16,
    lags: Annotated[int, typer.Option("--lags", help="Input lags p of Elman/grey-Elman, order of AR.")] = 4,
    epochs: Annotated[int, typer.Option("--epochs", help="Maximum training epochs (early stopping on validation).")]
    = 2000,
    seed: Annotated[int, typer.Option("--seed", help="Random seed.")] = 0,
    training: Annotated[str, typer.Option("--training", help="bptt (Adam) or bp (classic traingdx).")] = "bptt",
    wavelet: WaveletOpt = "db2",
    level: LevelOpt = "4",
    mode: ModeOpt = "symmetric",
    model_rate: ModelRateOpt = 1.0,
    out: OutOpt = Path("out/model"),
):
    """Fit drift models on the training block and compare them on the test block."""
    from .pipeline import AnalysisConfig, run_models
    from .report import causal_metrics_rows, metrics_rows, verdict, write_model_outputs

    with _errors():
        record = _load(file, rate, unit, columns, time_column, gaps)
        cfg = AnalysisConfig(models=tuple(_csv_list(models)), hidden=hidden,
                             lags=lags, epochs=epochs, seed=seed, training=training, wavelet=wavelet,
                             level=_level(level), mode=mode, model_rate_hz=model_rate or None)
        with _progress("model") as (_, epoch_cb):
            results = run_models(record, cfg, progress=epoch_cb)
        for ma in results:
            console.print(_metrics_table(f"axis {ma.name}: one-step metrics on the test block "
                                         f"(target: wavelet drift), dt {ma.dt_s:g} s", metrics_rows(ma)))
            console.print(_metrics_table(f"axis {ma.name}: target = causal drift", causal_metrics_rows(ma)))
            for line in verdict(ma):
                console.print("  " + line, highlight=False)
        write_model_outputs(results, out)
        console.print(f"wrote models, metrics.json and figures to {out}")


@app.command()
def analyze(
    file: FileArg,
    rate: RateOpt = None,
    unit: UnitOpt = "deg/h",
    columns: ColsOpt = None,
    time_column: TimeOpt = "auto",
    gaps: GapsOpt = "error",
    latitude: Annotated[Optional[float], typer.Option("--latitude", help="Latitude [deg] for Earth-rate removal.")]
    = None,
    earth_axis: Annotated[Optional[list[str]], typer.Option(
        "--earth-axis", help="AXIS=ORIENTATION (up, down, north, south, east, west), repeatable.")] = None,
    apply_to: Annotated[Optional[Path], typer.Option("--apply-to", help="Second recording: apply the fitted "
                                                     "models unchanged to it.")] = None,
    models: Annotated[str, typer.Option("--models", help="Comma-separated: grey-elman, elman, gm11, ar, persistence.")]
    = "grey-elman,elman,gm11,ar,persistence",
    hidden: Annotated[int, typer.Option("--hidden")] = 16,
    lags: Annotated[int, typer.Option("--lags")] = 4,
    epochs: Annotated[int, typer.Option("--epochs")] = 2000,
    seed: Annotated[int, typer.Option("--seed")] = 0,
    wavelet: WaveletOpt = "db2",
    level: LevelOpt = "4",
    mode: ModeOpt = "symmetric",
    model_rate: ModelRateOpt = 1.0,
    taus: TausOpt = "octave",
    fit_taus: FitTausOpt = ":",
    out: OutOpt = Path("out/analyze"),
):
    """The whole method: Allan analysis, separation, drift models, compensation, Table 2 and an HTML report."""
    from .pipeline import AnalysisConfig, run_analysis
    from .report import metrics_rows, noise_row, verdict, write_report

    with _errors():
        record = _load(file, rate, unit, columns, time_column, gaps)
        other = _load(apply_to, rate, unit, columns, time_column, gaps) if apply_to else None
        earth = {}
        for item in earth_axis or []:
            name, sep, orient = item.partition("=")
            if not sep:
                raise ConfigError(f"--earth-axis must look like AXIS=ORIENTATION (e.g. gz=up), got {item!r}")
            earth[name.strip()] = orient.strip()
        cfg = AnalysisConfig(models=tuple(_csv_list(models)), hidden=hidden,
                             lags=lags, epochs=epochs, seed=seed, wavelet=wavelet, level=_level(level), mode=mode,
                             model_rate_hz=model_rate or None, taus=_taus(taus), latitude_deg=latitude,
                             earth_axes=earth, fit_tau_s=_fit_taus(fit_taus))
        with _progress("analyze") as (_, epoch_cb):
            result = run_analysis(record, cfg, apply_to=other, progress=epoch_cb)
        for res, title in ((result, file.name), (result.apply_to, apply_to.name if apply_to else "")):
            if res is None:
                continue
            for ax in res.axes:
                console.print(_noise_table(f"{title} axis {ax.name}: Table 2 (test block, {ax.models.dt_s:g} s "
                                           "samples; 95 % intervals)",
                                           [["original (whole record, native rate)"] + noise_row(ax.original.noise)]
                                           + [[r.label] + noise_row(r.analysis.noise) for r in ax.table2]))
                console.print(_metrics_table(f"{title} axis {ax.name}: one-step metrics on the test block",
                                             metrics_rows(ax.models)))
                for line in verdict(ax.models):
                    console.print("  " + line, highlight=False)
        path = write_report(result, record, out)
        console.print(f"report: {path.resolve()}  ({result.wall_s:.1f} s)")


def main():  # console-script entry point
    app()


if __name__ == "__main__":
    main()
