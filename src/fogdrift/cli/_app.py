"""The typer application, shared options and the edge where errors become one line.

Commands live one per module in :mod:`fogdrift.cli` (``allan``, ``separate``, ``model``, ``analyze``, ...); each
only declares options, calls the library and prints.  Options every command that reads a gyro log shares are
declared once (:data:`LOAD_PARAMS`) and added to a command by :func:`with_load_options`, which hands the command a
:class:`LoadOptions` instead of seven loose arguments.
"""

from __future__ import annotations

import contextlib
import functools
import inspect
import sys
import typing
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Optional

import typer
from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn
from rich.table import Table
from rich.text import Text

from .. import __version__
from ..errors import ConfigError, FogdriftError

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    rich_markup_mode=None,  # help texts are plain: "[s]" and "gz[deg/s]" are units, not markup
    context_settings={"help_option_names": ["-h", "--help"]},
    help="Characterise, separate, model and compensate optical-gyro drift (rates in deg/h, tau in s).",
)
# Tables are wide: when output goes to a file or pipe (logs, CI), do not wrap them at rich's 80 columns.
console = Console(width=None if sys.stdout.isatty() else 220)
err_console = Console(stderr=True, width=None if sys.stderr.isatty() else 220)
_state = {"traceback": False}

#: Library parameter -> CLI flag, for error messages written with ``{opt:NAME}`` (see :mod:`fogdrift.errors`).
FLAGS = {
    "unit": "--unit", "rate_hz": "--rate", "dt_s": "--rate", "time_column": "--time-column", "columns": "--columns",
    "gaps": "--gaps", "time_unit": "--time-unit", "model_rate_hz": "--model-rate", "level": "--level",
    "wavelet": "--wavelet", "mode": "--mode", "terms": "--terms", "fit_taus": "--fit-taus",
    "tau_range_s": "--fit-taus", "taus": "--taus", "estimator": "--estimator", "statistic": "--statistic",
    "models": "--models", "latitude_deg": "--latitude", "earth_axes": "--earth-axis", "outliers": "--outliers",
    "lags": "--lags", "hidden": "--hidden", "epochs": "--epochs", "training": "--training", "seed": "--seed",
    # reader options (fogdrift.io.registry.READERS) and the temperature column
    "temperature": "--temperature", "topic": "--topic", "stamp": "--stamp", "dataset": "--dataset",
    "variable": "--variable", "gain": "--gain", "layout": "--layout", "scale": "--scale",
    "header_bytes": "--header-bytes", "sequence": "--sequence", "format": "--format",
}

#: LoadOptions field -> reader option of fogdrift.io.load(reader_options=...); set ones are passed on.
READER_OPTIONS = {"topic": "topic", "stamp": "stamp", "dataset": "dataset", "variable": "variable", "gain": "gain",
                  "layout": "layout", "scale": "scale", "header_bytes": "header_bytes", "sequence": "sequence"}


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


# -- shared option types --------------------------------------------------------------------------------------
OutOpt = Annotated[Path, typer.Option("--out", help="Output directory.")]
ModelRateOpt = Annotated[float, typer.Option(
    "--model-rate", help="Modelling rate [Hz]: block-average to it before separation/modelling; it must divide the "
                         "native rate by an integer (0 = native).")]
WaveletOpt = Annotated[str, typer.Option("--wavelet", help="Lifting wavelet (fogdrift.lifting.wavelist(): haar, db2, db4).")]
LevelOpt = Annotated[str, typer.Option("--level", help="Decomposition level or 'auto'.")]
ModeOpt = Annotated[str, typer.Option("--mode", help="Boundary mode: symmetric or periodization.")]
TausOpt = Annotated[str, typer.Option("--taus", help="Tau grid: octave, decade, all, or a number of log-spaced taus.")]
FitTausOpt = Annotated[str, typer.Option("--fit-taus", help="Tau range of the noise fit MIN:MAX [s], "
                                                            "either side may be empty, e.g. '1:'.")]
EstOpt = Annotated[str, typer.Option("--estimator", help="overlapping, non-overlapping or fast.")]


@dataclass(frozen=True)
class LoadOptions:
    """How to read a gyro log: the options of :func:`fogdrift.io.load` as the CLI spells them."""

    file: Path
    rate: Optional[float] = None
    unit: Optional[str] = None
    time_unit: Optional[str] = None
    columns: Optional[str] = None
    time_column: str = "auto"
    gaps: str = "error"
    temperature: Optional[str] = None
    format: Optional[str] = None
    topic: Optional[str] = None
    stamp: Optional[str] = None
    dataset: Optional[str] = None
    variable: Optional[str] = None
    gain: Optional[str] = None
    layout: Optional[str] = None
    scale: Optional[str] = None
    header_bytes: Optional[int] = None
    sequence: Optional[str] = None

    def reader_options(self) -> dict:
        """The reader options that were set (``--topic``, ``--dataset``, ``--layout`` ...)."""
        return {opt: getattr(self, f) for f, opt in READER_OPTIONS.items() if getattr(self, f) is not None}

    def load_kwargs(self) -> dict:
        """Keyword arguments of :func:`fogdrift.io.load` (without ``gaps``)."""
        return dict(columns=csv_list(self.columns), rate_hz=self.rate, unit=self.unit, time_unit=self.time_unit,
                    time_column=None if self.time_column.lower() == "none" else self.time_column,
                    temperature=self.temperature, format=self.format, reader_options=self.reader_options())

    def load(self, path=None):
        """Load ``path`` (default: ``file``) with these options; ``--gaps longest`` keeps the longest segment."""
        from ..io import load, load_segments

        path = self.file if path is None else path
        kwargs = self.load_kwargs()
        if self.gaps == "error":
            return load(path, **kwargs)
        if self.gaps == "longest":
            segs = load_segments(path, **kwargs)
            longest = max(segs, key=lambda s: s.n_samples)
            err_console.print(Text(f"{path}: {len(segs)} segments between gaps; analysing the longest "
                                   f"({longest.n_samples} samples, {', '.join(longest.notes)})", style="yellow"))
            return longest
        raise ConfigError(f"--gaps must be 'error' or 'longest', got {self.gaps!r}")


#: (name, annotation, default) of the shared load parameters, in the order they appear in --help.
LOAD_PARAMS = (
    ("file", Annotated[Path, typer.Argument(help="Gyro log: CSV/TXT (optionally .gz), .npy, .npz, HDF5, .mat, ROS bag, "
                                                 "miniSEED or raw binary (docs/formats.md).")], inspect.Parameter.empty),
    ("rate", Annotated[Optional[float], typer.Option("--rate", help="Sample rate [Hz] (if the file has no time column).")], None),
    ("unit", Annotated[Optional[str], typer.Option(
        "--unit", help="Input unit: deg/h, deg/s, rad/s, rad/h, arcsec/s, or angle increments inc:deg, inc:rad, "
                       "inc:arcsec (default: the unit the header declares, e.g. 'gz[deg/s]').")], None),
    ("time_unit", Annotated[Optional[str], typer.Option(
        "--time-unit", help="Unit of the time column: s, ms, us or ns (default: declared in the header, else s).")], None),
    ("columns", Annotated[Optional[str], typer.Option("--columns", help="Comma-separated column names or 0-based indices.")], None),
    ("time_column", Annotated[str, typer.Option("--time-column", help="Time column name/index, 'auto' or 'none'.")], "auto"),
    ("gaps", Annotated[str, typer.Option("--gaps", help="Time gaps > 1.5 intervals: 'error' or 'longest' segment.")], "error"),
    ("temperature", Annotated[Optional[str], typer.Option(
        "--temperature", help="Temperature column [deg C] carried with the log (bag: a sensor_msgs/Temperature topic; "
                              "miniSEED: a channel).")], None),
    ("format", Annotated[Optional[str], typer.Option(
        "--format", help="Force a reader: text, npy, npz, hdf5, mat, rosbag1, rosbag2, mseed, binary.")], None),
    ("topic", Annotated[Optional[str], typer.Option("--topic", help="Bag: the sensor_msgs/Imu topic.")], None),
    ("stamp", Annotated[Optional[str], typer.Option("--stamp", help="Bag: time from 'header' stamps or 'receive' time.")], None),
    ("dataset", Annotated[Optional[str], typer.Option("--dataset", help="HDF5: dataset or group path, e.g. /imu.")], None),
    ("variable", Annotated[Optional[str], typer.Option("--variable", help="MATLAB .mat: variable name.")], None),
    ("gain", Annotated[Optional[str], typer.Option(
        "--gain", help="miniSEED: counts per unit, or a StationXML/dataless/RESP response file.")], None),
    ("layout", Annotated[Optional[str], typer.Option(
        "--layout", help="Raw binary record as NumPy dtype items, e.g. '<u4 seq, <i4 gx, <i4 gy, <i4 gz'.")], None),
    ("scale", Annotated[Optional[str], typer.Option(
        "--scale", help="Raw binary: LSB factor for every field, or per field 'gx=1e-4,temp=0.01'.")], None),
    ("header_bytes", Annotated[Optional[int], typer.Option("--header-bytes", help="Raw binary: bytes before the first record.")], None),
    ("sequence", Annotated[Optional[str], typer.Option(
        "--sequence", help="Raw binary: sequence-counter field (default seq/counter/...; 'none').")], None),
)


def with_load_options(func):
    """Add the shared load parameters to a command; the command receives them as ``load: LoadOptions``."""
    sig = inspect.signature(func)
    hints = typing.get_type_hints(func, include_extras=True)  # resolve string annotations (PEP 563)
    own = [p.replace(annotation=hints.get(p.name, p.annotation)) for p in sig.parameters.values() if p.name != "load"]
    shared = [inspect.Parameter(name, inspect.Parameter.KEYWORD_ONLY, default=default, annotation=ann)
              for name, ann, default in LOAD_PARAMS]
    # the file argument first, then the command's own options, then the shared reading options
    params = [shared[0].replace(kind=inspect.Parameter.POSITIONAL_OR_KEYWORD)] + \
             [p.replace(kind=inspect.Parameter.KEYWORD_ONLY) for p in own] + shared[1:]

    @functools.wraps(func)
    def wrapper(**kwargs):
        opts = LoadOptions(**{name: kwargs.pop(name) for name, _, _ in LOAD_PARAMS})
        return func(load=opts, **kwargs)

    wrapper.__signature__ = sig.replace(parameters=params)
    return wrapper


# -- small parsers --------------------------------------------------------------------------------------------
def csv_list(text: str | None) -> list[str] | None:
    """'a, b,,c' -> ['a', 'b', 'c'] (None stays None)."""
    return None if text is None else [t.strip() for t in text.split(",") if t.strip()]


def parse_level(text: str):
    if text == "auto":
        return "auto"
    try:
        return int(text)
    except ValueError:
        raise ConfigError(f"--level must be an integer >= 1 or 'auto', got {text!r}") from None


def parse_fit_taus(text: str):
    lo, sep, hi = text.partition(":")
    try:
        if not sep:
            raise ValueError
        return (float(lo) if lo.strip() else None, float(hi) if hi.strip() else None)
    except ValueError:
        raise ConfigError(f"--fit-taus must look like MIN:MAX in seconds (e.g. '1:' or '0.1:300'), got {text!r}") from None


def parse_taus(text: str):
    return int(text) if text.isdigit() else text


# -- errors and progress ---------------------------------------------------------------------------------------
@contextlib.contextmanager
def errors():
    """Print a FogdriftError as one red line (options spelled as CLI flags) and exit 1."""
    try:
        yield
    except FogdriftError as exc:
        if _state["traceback"]:
            raise
        err_console.print(Text("error: ", style="bold red") + Text(exc.render(FLAGS)), highlight=False,
                          soft_wrap=True)
        raise typer.Exit(code=1) from None


@contextlib.contextmanager
def progress(description: str):
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


def table(title, headers, rows) -> Table:
    """A rich table of plain text (units such as [deg/h] must not be read as rich markup)."""
    out = Table(title=Text(title), title_justify="left")
    for i, h in enumerate(headers):
        out.add_column(Text(h), justify="left" if i == 0 else "right")
    for row in rows:
        out.add_row(*(Text(str(c)) for c in row))
    return out
