"""The typer application, shared options and the edge where errors, warnings and Ctrl-C become one line.

Commands live one per module in :mod:`fogdrift.cli` (``allan``, ``separate``, ``model``, ``analyze``, ...); each
only declares options, calls the library and prints.  Options every command that reads a gyro log shares are
declared once (:data:`LOAD_PARAMS`) and added to a command by :func:`with_load_options`, which hands the command a
:class:`LoadOptions` instead of loose arguments.  The reader options among them (``--topic``, ``--dataset``,
``--layout`` ...) are not written here: each is a :class:`fogdrift.io.registry.ReaderOption` in the ``READERS``
table (name, type, help, flag), and :data:`LOAD_PARAMS`, :class:`LoadOptions`, :data:`FLAGS` and
:meth:`LoadOptions.reader_options` are built from it; a reader with options needs no edit here.

A command's body runs inside :func:`run`, which

* checks ``--out`` before any work (:class:`fogdrift.output.OutputDir`: every file written under a temporary name
  and renamed when complete; the previous run's files in that folder replaced, never others);
* prints a :class:`~fogdrift.errors.FogdriftError` as one line with settings spelled as CLI flags and exits 1;
* prints each :class:`~fogdrift.errors.FogdriftWarning` as one ``warning:`` line;
* on Ctrl-C (:mod:`fogdrift.interrupt`) prints one line saying what was and was not written and exits 130;
* with ``--json``, keeps stdout for the result JSON alone (human lines go to stderr, tables are not printed).

Console output: tables fit the terminal (columns folded into several tables when too wide, never truncated with
an ellipsis); lines and notes are printed without hard wrapping (a pipe gets whole lines).  Off a terminal the
width is ``COLUMNS`` if set, else 220.
"""

from __future__ import annotations

import contextlib
import functools
import gc
import inspect
import math
import os
import sys
import threading
import time
import typing
import warnings
from dataclasses import dataclass, make_dataclass
from pathlib import Path
from typing import Annotated, Optional

import typer
from rich.console import Console, Group
from rich.progress import BarColumn, Progress, ProgressColumn, TextColumn, TimeElapsedColumn
from rich.table import Table
from rich.text import Text

from .. import __version__
from .. import interrupt
from ..errors import ConfigError, FogdriftError, FogdriftWarning, render_options
from ..io import load, load_segments
from ..io import load as _io_load
from ..io.registry import cli_options, reader_by_name, select_reader
from ..models.settings import SETTINGS as SETTING_ROWS
from .. import output as _output
from ..output import OutputDir, active
from ..plausibility import check_record
from ._safe import SafeConsole

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    rich_markup_mode=None,  # help texts are plain: "[s]" and "gz[deg/s]" are units, not markup
    context_settings={"help_option_names": ["-h", "--help"]},
    help="Characterise, separate, model and compensate optical-gyro drift (rates in deg/h, tau in s).",
)
# stdout (tables, the result) and stderr (progress, warnings, errors); widths are set per run by _configure().
console = SafeConsole(highlight=False)  # text from a file (a column name) cannot move the cursor or recolour
err_console = SafeConsole(stderr=True, highlight=False)
_state = {"traceback": False, "json": False, "finish": threading.Lock()}
#: Width off a terminal when COLUMNS is not set: logs and CI keep whole table rows.
PIPE_WIDTH = 220

#: Library parameter -> CLI flag, for error messages written with ``{opt:NAME}`` (see :mod:`fogdrift.errors`).
FLAGS = {
    "unit": "--unit", "rate_hz": "--rate", "dt_s": "--rate", "time_column": "--time-column", "columns": "--columns",
    "gaps": "--gaps", "time_unit": "--time-unit", "model_rate_hz": "--model-rate", "level": "--level",
    "wavelet": "--wavelet", "mode": "--mode", "terms": "--terms", "fit_taus": "--fit-taus",
    "tau_range_s": "--fit-taus", "models": "--models", "latitude_deg": "--latitude",
    "earth_axes": "--earth-axis", "model_params": "--param",
    "apply_unit": "--apply-unit", "axis_map": "--axis-map", "accept_rate": "--accept-rate", "bias": "--bias",
    "model": "--model", "chunk_samples": "--chunk", "out": "--out", "pdf": "--pdf",
    "method": "--method", "noise_method": "--noise-method", "scales": "--scales", "levels": "--scales",
    "curve": "--curve", "sensor": "--sensor", "robust": "--robust",
    "format": "--format", "horizons": "--horizons", "calibration": "--calibration",
    "origin_step": "--origin-step", "spec": "--spec", "segments": "--segments",
    "target": "--target", "length": "--length", "monte_carlo": "--monte-carlo", "workers": "--workers", "axis": "--axis",
    "fleet": "--fleet", "units": "--units", "mean_target": "--mean-target",
}

#: The reader options of the ``READERS`` table (fogdrift.io.registry), each once: every one is a flag of every
#: command that reads a log.  Those that :func:`fogdrift.io.load` takes itself (``temperature``: a column of any
#: file, handed on to a bag/miniSEED reader by ``load``) come first and are passed as that keyword; the others
#: go in ``load(..., reader_options=...)`` when set.
_LOAD_KEYWORDS = frozenset(inspect.signature(_io_load).parameters)
READER_FLAGS = tuple(sorted(cli_options(), key=lambda o: str(o) not in _LOAD_KEYWORDS))
FLAGS.update({str(o): o.flag for o in READER_FLAGS})
FLAGS.update({s.name: s.flag for s in SETTING_ROWS.values()})  # the declared settings: each flag declared once


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
OutOpt = Annotated[Path, typer.Option("--out", help="Output folder: a new folder in an existing one, or a folder a "
                                                    "fogdrift run wrote before (its files are replaced; files "
                                                    "fogdrift did not write are kept).")]
JsonOpt = Annotated[bool, typer.Option("--json", help="Print the result JSON to stdout and nothing else (human "
                                                      "output goes to stderr; the files are still written).")]
ModelRateOpt = Annotated[float, typer.Option(
    "--model-rate", help="Modelling rate [Hz]: block-average to it before separation/modelling; it must divide the "
                         "native rate by an integer (0 = native).")]
WaveletOpt = Annotated[str, typer.Option("--wavelet", help="Lifting wavelet (fogdrift.lifting.wavelist(): haar, db2, db4).")]
LevelOpt = Annotated[str, typer.Option("--level", help="Decomposition level or 'auto'.")]
ModeOpt = Annotated[str, typer.Option("--mode", help="Boundary mode: symmetric or periodization.")]
TermsOpt = Annotated[str, typer.Option(
    "--terms", help="Fix the noise model, e.g. N,K (default: the terms are selected from the data).")]
SegmentsOpt = Annotated[str, typer.Option(
    "--segments", help="What the noise fit uses: auto (default: the quiet segments where the record screen finds a "
                       "disturbance, the whole record when it finds none), whole, or ranges in s such as "
                       "'0:600,7000:' (pooled without bridging a gap).")]


@dataclass(frozen=True)
class _LoadOptionsBase:
    """The options of :func:`fogdrift.io.load` that every format shares, as the CLI spells them."""

    file: Path
    rate: Optional[float] = None
    unit: Optional[str] = None
    time_unit: Optional[str] = None
    columns: Optional[str] = None
    time_column: str = "auto"
    gaps: str = "error"
    format: Optional[str] = None

    def reader_options(self) -> dict:
        """The reader options that were set (``--topic``, ``--dataset``, ``--layout`` ...), by option name."""
        return {str(o): getattr(self, str(o)) for o in READER_FLAGS
                if str(o) not in _LOAD_KEYWORDS and getattr(self, str(o)) is not None}

    def load_kwargs(self) -> dict:
        """Keyword arguments of :func:`fogdrift.io.load` (without ``gaps``)."""
        kwargs = dict(columns=csv_list(self.columns), rate_hz=self.rate, unit=self.unit, time_unit=self.time_unit,
                      time_column=None if self.time_column.lower() == "none" else self.time_column)
        kwargs.update({str(o): getattr(self, str(o)) for o in READER_FLAGS if str(o) in _LOAD_KEYWORDS})
        return dict(kwargs, format=self.format, reader_options=self.reader_options())

    def load(self, path=None, *, unit=None, time_unit=None):
        """Load ``path`` (default: ``file``) with these options; ``--gaps longest`` keeps the longest segment.

        ``unit`` / ``time_unit`` override ``--unit`` / ``--time-unit`` (a second recording's own units)."""
        path = self.file if path is None else path
        kwargs = self.load_kwargs()
        kwargs.update(unit=unit or self.unit, time_unit=time_unit or self.time_unit)
        if self.gaps == "error":
            return load(path, **kwargs)
        if self.gaps == "longest":
            segs = load_segments(path, **kwargs)
            longest = max(segs, key=lambda s: s.n_samples)
            err_console.print(Text(f"{path}: {len(segs)} segments between gaps; analysing the longest "
                                   f"({longest.n_samples} samples, {', '.join(longest.notes)})", style="yellow"))
            return longest
        raise ConfigError(f"--gaps must be 'error' or 'longest', got {self.gaps!r}")


#: How to read a gyro log: the options of :func:`fogdrift.io.load` as the CLI spells them, with one field per reader
#: option of the ``READERS`` table (``topic``, ``dataset``, ``header_bytes`` ..., None when not given).
LoadOptions = make_dataclass(
    "LoadOptions", [(str(o), Optional[o.type], None) for o in READER_FLAGS], bases=(_LoadOptionsBase,), frozen=True,
    namespace={"__module__": __name__,
               "__doc__": "How to read a gyro log: the options of :func:`fogdrift.io.load` as the CLI spells them.\n\n"
                          "    The shared ones of :class:`_LoadOptionsBase`, then one field per reader option of "
                          "fogdrift.io.registry.READERS (None when not given): " + ", ".join(map(str, READER_FLAGS))
                          + "."})


def _reader_param(opt):
    return (str(opt), Annotated[Optional[opt.type], typer.Option(opt.flag, help=opt.help)], None)


#: (name, annotation, default) of the shared load parameters, in the order they appear in --help.
LOAD_PARAMS = (
    ("file", Annotated[Path, typer.Argument(help="Gyro log: CSV/TXT (optionally .gz), .npy, .npz, HDF5, .mat, ROS bag, "
                                                 "miniSEED or raw binary (docs/formats.md).")], inspect.Parameter.empty),
    ("rate", Annotated[Optional[float], typer.Option("--rate", help="Sample rate [Hz] (if the file has no time column).")], None),
    ("unit", Annotated[Optional[str], typer.Option(
        "--unit", help="Input unit: deg/h, deg/s, rad/s, rad/h, arcsec/s, or angle increments inc:deg, inc:rad, "
                       "inc:arcsec; accelerometers: g, mg, ug, m/s^2, inc:m/s.  A gyro+accelerometer log or folder: "
                       "gyro=deg/s,accel=g (channels assigned by name: gx, gyro*, w*, omega* gyro; ax, acc*, a_x "
                       "accelerometer; or NAME=UNIT per column; docs/accelerometers.md).  Required unless the "
                       "header declares it (e.g. 'gz[deg/s]', 'ax[g]'): never guessed.")],
     None),
    ("time_unit", Annotated[Optional[str], typer.Option(
        "--time-unit", help="Unit of the time column: s, ms, us or ns.  Required for a time column unless the header "
                            "declares it ('t[ms]', or a name suffix as in 't_s', 'time_ms'): never guessed.")], None),
    ("columns", Annotated[Optional[str], typer.Option("--columns", help="Comma-separated column names or 0-based indices.")], None),
    ("time_column", Annotated[str, typer.Option("--time-column", help="Time column name/index, 'auto' or 'none'.")], "auto"),
    ("gaps", Annotated[str, typer.Option("--gaps", help="Time gaps > 1.5 intervals: 'error' or 'longest' segment.")], "error"),
    *(_reader_param(o) for o in READER_FLAGS if str(o) in _LOAD_KEYWORDS),
    ("format", Annotated[Optional[str], typer.Option(
        "--format", help="Force a reader: text, npy, npz, hdf5, mat, rosbag1, rosbag2, mseed, binary.")], None),
    *(_reader_param(o) for o in READER_FLAGS if str(o) not in _LOAD_KEYWORDS),
)


def _clashes(params) -> list[str]:
    """Names or flags given twice in ``params`` (a reader option named like a load option, e.g. ``unit``)."""
    keys = [name for name, _, _ in params] + [decl for _, ann, _ in params
                                              for decl in getattr(ann.__metadata__[0], "param_decls", None) or ()]
    return sorted({k for k in keys if keys.count(k) > 1})


if _clashes(LOAD_PARAMS):
    raise ConfigError(f"reader option(s) of fogdrift.io.registry.READERS clash with the CLI's load options: "
                      f"{_clashes(LOAD_PARAMS)}; expected other names and flags")


def with_load_options(func=None, *, file: str = "first"):
    """Add the shared load parameters to a command; the command receives them as ``load: LoadOptions``.

    ``file``: where the FILE argument goes: ``"first"`` (``allan FILE [options]``), ``"after"`` the command's own
    positional arguments (``compensate BUNDLE FILE``), or ``"none"`` (``batch``/``export``, which name their files
    otherwise: only the reading options are added and ``load.file`` is ``.``).
    """
    if func is None:
        return functools.partial(with_load_options, file=file)
    if file not in ("first", "after", "none"):
        raise ValueError(f"file must be 'first', 'after' or 'none', got {file!r}")
    sig = inspect.signature(func)
    hints = typing.get_type_hints(func, include_extras=True)  # resolve string annotations (PEP 563)
    own = [p.replace(annotation=hints.get(p.name, p.annotation)) for p in sig.parameters.values() if p.name != "load"]
    shared = [inspect.Parameter(name, inspect.Parameter.KEYWORD_ONLY, default=default, annotation=ann)
              for name, ann, default in LOAD_PARAMS]
    file_arg, reading = shared[0].replace(kind=inspect.Parameter.POSITIONAL_OR_KEYWORD), shared[1:]
    keyword = [p.replace(kind=inspect.Parameter.KEYWORD_ONLY) for p in own]
    if file == "first":  # the file argument first, then the command's own options, then the reading options
        params = [file_arg] + keyword + reading
    elif file == "after":
        positional = [p.replace(kind=inspect.Parameter.POSITIONAL_OR_KEYWORD) for p in own
                      if p.default is inspect.Parameter.empty]
        params = positional + [file_arg] + [p for p in keyword if p.default is not inspect.Parameter.empty] + reading
    else:
        params = own[:1] + keyword[1:] + reading
    names = [name for name, _, _ in LOAD_PARAMS if file != "none" or name != "file"]

    @functools.wraps(func)
    def wrapper(**kwargs):
        given = {name: kwargs.pop(name) for name in names}
        opts = LoadOptions(**given) if file != "none" else LoadOptions(file=Path("."), **given)
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


def parse_terms(text: str):
    """'' -> None (select from the data); 'n,k' -> ('N', 'K')."""
    items = csv_list(text or "")
    return tuple(t.upper() for t in items) if items else None


# -- consoles -----------------------------------------------------------------------------------------------
def _configure(json_mode: bool = False) -> None:
    """Set the consoles for one run: widths (terminal, else COLUMNS, else PIPE_WIDTH) and the --json mode."""
    for con, stream in ((console, sys.stdout), (err_console, sys.stderr)):
        try:
            tty = stream.isatty()
        except (AttributeError, ValueError):
            tty = False
        if not tty:
            cols = os.environ.get("COLUMNS", "")
            con.width = int(cols) if cols.isdigit() and int(cols) > 20 else PIPE_WIDTH
    _state["json"] = bool(json_mode)
    console.quiet = bool(json_mode)


def human() -> Console:
    """The console for human lines: stdout, or stderr under --json (stdout is the JSON's alone)."""
    return err_console if _state["json"] else console


def say(text: str, style: str | None = None) -> None:
    """One human line, never hard-wrapped (a pipe gets it whole)."""
    human().print(Text(text, style=style or ""), soft_wrap=True)


def warn(text: str) -> None:
    """One ``warning:`` line on stderr."""
    err_console.print(Text("warning: ", style="bold yellow") + Text(text), soft_wrap=True)


# -- errors, warnings, Ctrl-C ---------------------------------------------------------------------------------
@contextlib.contextmanager
def errors():
    """Print a FogdriftError as one red line (options spelled as CLI flags) and exit 1."""
    try:
        yield
    except FogdriftError as exc:
        if interrupt.requested():
            raise
        if _state["traceback"]:
            raise
        err_console.print(Text("error: ", style="bold red") + Text(exc.render(FLAGS)), highlight=False,
                          soft_wrap=True)
        raise typer.Exit(code=1) from None


@contextlib.contextmanager
def _warning_lines():
    """FogdriftWarnings as one ``warning:`` line each (settings spelled as flags); other warnings as usual."""
    previous = warnings.showwarning

    def show(message, category, filename, lineno, file=None, line=None):
        if issubclass(category, FogdriftWarning):
            warn(render_options(str(message), FLAGS))
        else:
            previous(message, category, filename, lineno, file, line)

    with warnings.catch_warnings():
        warnings.simplefilter("default", FogdriftWarning)
        warnings.showwarning = show
        yield


def _interrupted(out: OutputDir | None):
    """Ctrl-C: one line saying what was and was not written, exit 130 (the watchdog may already be at it)."""
    if not _state["finish"].acquire(blocking=False):
        raise typer.Exit(code=130)  # fogdrift.cli.main's watchdog prints the line and ends the process
    summary = out.summary() if out is not None else "nothing was written"
    err_console.print(Text("interrupted: ", style="bold red") + Text(summary), highlight=False, soft_wrap=True)
    raise typer.Exit(code=130)


def emergency_exit() -> None:
    """The SIGINT watchdog's action when the main thread did not stop in time (fogdrift.cli.main): remove
    unfinished temporary files, print the one line, end the process with 130.  Runs in another thread."""
    if _state["finish"].acquire(timeout=0.3):
        out = active() or _state.get("out")
        for od in reversed(list(_output._active)):  # every folder of the run (a batch's and a file's)
            od.abort(timeout=0.2)
        summary = out.summary() if out is not None else "nothing was written"
        tty = sys.stderr.isatty()
        text = ("\r\x1b[2K" if tty else "") + f"interrupted: {summary}\n" + ("\x1b[?25h" if tty else "")
        with contextlib.suppress(OSError):
            os.write(2, text.encode("utf-8", "replace"))
    os._exit(130)


@dataclass
class Run:
    """What :func:`run` hands a command: the output folder and the --json switch."""

    out: OutputDir
    json_out: bool = False

    def print_json(self, path) -> None:
        """Under --json, print the JSON file the run wrote to stdout (the only thing on stdout)."""
        if self.json_out:
            sys.stdout.write(Path(path).read_text(encoding="utf-8").rstrip("\n") + "\n")
            sys.stdout.flush()

    def wrote(self) -> None:
        """One human line: the files this run wrote."""
        w = self.out.written
        shown = ", ".join(w) if len(w) <= 4 else ", ".join(w[:3]) + f" and {len(w) - 3} more"
        removed = f"; the earlier run's {len(self.out.removed)} file(s) there replaced" if self.out.removed else ""
        say(f"wrote {len(w)} file(s) to {self.out.path}: {shown}{removed}")


@contextlib.contextmanager
def run(command: str, out: Path, *, default_out: Path, inputs=(), json_out: bool = False, expect=(),
        out_class=OutputDir):
    """The frame of every command (see the module docstring): yields a :class:`Run`.

    ``--out`` is validated first, so a bad folder is refused before the file is read or anything computed.
    ``out_class``: an :class:`~fogdrift.output.OutputDir` subclass whose ``summary()`` says more on Ctrl-C
    (``batch``: which files' folders are finished).

    While the command runs, the objects that exist when it starts (the imported modules: scipy, numba, the
    analysis stack, about 10^6 objects) are frozen out of the cyclic garbage collector (:func:`gc.freeze`), and
    given back to it at the end: otherwise every full collection during the command walks them all (``fogdrift
    allan`` on ADIS imu1: 0.20 s of garbage collection, 0.07 s frozen).  What the command allocates is collected
    as before.
    """
    _configure(json_out)
    _state["finish"] = threading.Lock()
    _state["ran"] = False  # set once the block has finished: its files are all written
    outdir = _state["out"] = None
    gc.freeze()
    try:
        with errors(), _warning_lines():
            missing = [q for q in Path(out).expanduser().absolute().parents if not q.exists()]
            outdir = out_class(out, command=command, create_parents=True, protect=[p for p in inputs if p is not None])
            _state["out"] = outdir  # the watchdog's line names it even once the folder has left the active list
            if missing:  # as mkdir -p, and said (once the folder is known to be usable): a typo shows in this line
                say(f"--out {out}: creating its parent folder {missing[0]}", style="dim")
            outdir.expect(*expect)
            first_run_note(command)
            try:
                with outdir:
                    yield Run(outdir, bool(json_out))
                _state["ran"] = True
            except BaseException as exc:
                if isinstance(exc, typer.Exit) and not interrupt.requested():
                    raise
                if interrupt.requested() or isinstance(exc, KeyboardInterrupt):
                    _interrupted(outdir)
                raise
    finally:
        gc.unfreeze()


# -- what was read --------------------------------------------------------------------------------------------
def echo_record(load: "LoadOptions", record, path=None, *, unit_flag: str = "--unit",
                time_unit_flag: str = "--time-unit") -> None:
    """One line: the file, samples, axes, duration, the sample rate and where it came from, the units and theirs.

    Where the rate and the units came from is read from the record's signal description
    (:attr:`fogdrift.io.GyroRecord.signal`), made by :func:`fogdrift.io.load` while reading; a unit given as
    an option is named by ``unit_flag`` / ``time_unit_flag`` (``--apply-unit`` for a second recording).
    """
    path = Path(path or load.file)
    smp = record.signal.sampling
    chan = record.signal.channels[0]
    if smp.dt_source == "rate option":
        rate_src = f"from {FLAGS['rate_hz']}"
    elif smp.dt_source == "time column":
        rate_src = f"from time column '{smp.time_column}'"
    else:
        rate_src = "from the file's time stamps"
    declared = _declared_words(load, path)
    words = {"option": unit_flag, "header": declared}
    units = f"rate {record.input_unit} ({words.get(chan.unit_source, chan.unit_source)})"
    if smp.time_unit is not None:
        words = {"option": time_unit_flag, "header": declared}
        units += f", time {smp.time_unit} ({words.get(smp.time_unit_source, smp.time_unit_source)})"
    say(f"{path.name}: {record.n_samples} samples x {record.n_axes} {'axis' if record.n_axes == 1 else 'axes'} ({', '.join(record.axis_names)}), "
        f"{record.duration_s:.6g} s at {record.fs_hz:.6g} Hz (dt {record.dt_s:.6g} s {rate_src}); units: {units}; "
        + _converted_words(record))


def _declared_words(load, path) -> str:
    """A unit the file states, in words: "declared in the header" (text), "declared by the message definition"
    (ROS bags), else "declared by the file" (HDF5/.mat attributes, miniSEED ...)."""
    try:
        spec = reader_by_name(load.format) if load.format else select_reader(path)
    except FogdriftError:
        return "declared by the file"
    return {"text": "declared in the header", "rosbag": "declared by the message definition"}.get(
        spec.module, "declared by the file")


def _converted_words(record) -> str:
    """"rates converted to deg/h", or what each quantity was converted to (accelerometers: m/s^2)."""
    qs = list(dict.fromkeys(record.quantities))
    if qs == ["angular_rate"]:
        return "rates converted to deg/h"
    words = {"angular_rate": "rates (gyro) to deg/h", "specific_force": "specific force (accelerometer) to m/s^2"}
    return "converted: " + ", ".join(words[q] for q in qs)


def gyro_only(record, command: str) -> None:
    """Refuse accelerometer channels in a command whose models and evaluation are the gyro's (drift modelling,
    heading error): one line naming them and the commands that do take them (docs/accelerometers.md)."""
    acc = [n for n, q in zip(record.axis_names, record.quantities) if q == "specific_force"]
    if acc:
        raise ConfigError(f"{Path(str(record.source)).name}: fogdrift {command} models gyro drift and its heading "
                          f"error; {', '.join(acc)} {'is an accelerometer channel' if len(acc) == 1 else 'are accelerometer channels'} "
                          "(specific force, from its unit); analyse them with allan, noise, batch or export, or "
                          "leave them out with {opt:columns}")


def check_plausible(record, *, sums: dict | None = None) -> list:
    """Warn (one line each) when the record is implausible for any gyro (a wrong --unit or --time-unit); return them.

    ``sums``: a dict that receives the octave Allan sums of the noise floors
    (:func:`fogdrift.plausibility.check_record`), for a command that reuses them.
    """
    found = list(check_record(record, sums=sums))
    for finding in found:
        warn(f"{Path(str(record.source)).name}: {finding.render(FLAGS)}")
    return found


def precheck(*, wavelet=None, mode=None, training=None, estimator=None, terms=None) -> None:
    """Refuse bad option values before the file is read, for commands without a full analysis configuration.

    The checks are :func:`fogdrift.pipeline.check_options`, the ones :meth:`AnalysisConfig.validate` makes
    (a command that validates a config needs no precheck).
    """
    from ..pipeline import check_options

    check_options(wavelet=wavelet, mode=mode, training=training, estimator=estimator, terms=terms)


# -- progress ---------------------------------------------------------------------------------------------------
class _Counter(ProgressColumn):
    """``done/total unit`` when the total is known, nothing otherwise (no "0/None")."""

    def render(self, task):
        if task.total is None:
            return Text("")
        return Text(f"{int(task.completed)}/{int(task.total)} {task.fields.get('unit', '')}".rstrip())


def progress_label(description: str, axes, stage: str = "", axis=None, model=None, extra: str = "") -> str:
    """``analyze · axis gz (1/3) · fitting elman · loss ...``: what the progress bar says."""
    parts = [description]
    if axis is not None:
        k = f" ({list(axes).index(axis) + 1}/{len(axes)})" if axis in axes else ""
        parts.append(f"axis {axis}{k}")
    if stage:
        parts.append(stage + (f" {model}" if model else ""))
    if extra:
        parts.append(extra)
    return " · ".join(parts)


#: Off a terminal (a pipe, a log file, CI) progress is plain lines on stderr instead of a bar: each stage as it
#: starts, the count of a stage with a known total (taus, epochs, samples, files) each time it passes another
#: PROGRESS_STEP_PCT % (so at most 100 / PROGRESS_STEP_PCT + 1 lines per stage), and a "still running" line
#: after HEARTBEAT_S seconds without a line.  Nothing is printed before the first stage or count, nor during the
#: first QUIET_S seconds of a run: a run that ends sooner prints no progress (its output is the result alone), a
#: longer one prints the line it is at when QUIET_S has passed, and every line after it.
PROGRESS_STEP_PCT = 10
HEARTBEAT_S = 30.0
QUIET_S = 3.0
CLOCK = time.monotonic  # the clock of those rules (seconds; a test injects its own)


def _bar_on_terminal() -> bool:
    """True when stderr is a terminal (rich draws a live bar there; elsewhere it would draw nothing)."""
    return err_console.is_terminal


class _Bar:
    """One transient rich progress bar on stderr (a terminal)."""

    def __init__(self, description: str):
        self._progress = Progress(TextColumn("{task.description}"), BarColumn(), _Counter(), TimeElapsedColumn(),
                                  console=err_console, transient=True)
        self._task = None
        self._description = description

    def __enter__(self):
        self._progress.__enter__()
        self._task = self._progress.add_task(self._description, total=None, unit="")
        return self

    def __exit__(self, *exc):
        return self._progress.__exit__(*exc)

    def stage(self, label: str) -> None:
        self._progress.update(self._task, description=label, total=None, completed=0, unit="")

    def count(self, label: str, done, total, unit: str, note: str = "", bar_extra: str = "") -> None:
        text = " · ".join(t for t in (label, note, bar_extra) if t)
        self._progress.update(self._task, description=text, completed=done, total=total, unit=unit)


class _Lines:
    """Progress as plain lines on stderr, for a pipe or a log file (see PROGRESS_STEP_PCT, HEARTBEAT_S)."""

    def __init__(self, description: str):
        self._label = description
        self._last_stage = None
        self._count_key, self._step = None, -1
        self._lock = threading.Lock()
        self._t0 = self._t_last = CLOCK()
        self._stop = threading.Event()
        self._thread = None
        self._pending = None  # the latest line held back during the first QUIET_S seconds

    def __enter__(self):
        if HEARTBEAT_S > 0 or QUIET_S > 0:
            self._thread = threading.Thread(target=self._heartbeat, name="fogdrift-progress-heartbeat", daemon=True)
            self._thread.start()
        return self

    def __exit__(self, *exc):
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=1.0)
        return False

    def _emit(self, text: str) -> None:
        with self._lock:
            now = CLOCK()
            if now - self._t0 < QUIET_S:
                self._pending = text
                return
            self._pending = None
            self._t_last = now
            err_console.print(Text(text), soft_wrap=True, highlight=False)

    def _heartbeat(self) -> None:
        tick = min(x for x in (HEARTBEAT_S / 4, 0.25 if QUIET_S > 0 else math.inf) if x > 0)
        while not self._stop.wait(tick):
            self.beat()

    def beat(self) -> None:
        """One beat of the heartbeat thread: the held-back line once QUIET_S has passed, a "still running" line."""
        now = CLOCK()
        with self._lock:  # taken under the lock: a line printed meanwhile clears it, never printed twice
            pending, self._pending = (self._pending, None) if now - self._t0 >= QUIET_S else (None, self._pending)
        if pending is not None:
            self._emit(pending)
        elif HEARTBEAT_S > 0 and now - self._t_last >= HEARTBEAT_S and now - self._t0 >= QUIET_S:
            self._emit(f"{self._label}: still running ({now - self._t0:.0f} s since the start)")

    def stage(self, label: str) -> None:
        self._label = label
        if label != self._last_stage:
            self._last_stage, self._count_key = label, None
            self._emit(label)

    def count(self, label: str, done, total, unit: str, note: str = "", bar_extra: str = "") -> None:
        self._label = label
        if not total or total <= 0:
            return
        pct = int(100 * min(max(done, 0), total) // total)
        step = pct // PROGRESS_STEP_PCT
        if label != self._count_key:
            self._count_key, self._step = label, -1
        if step > self._step:
            self._step = step
            self._emit(f"{label}: {pct} % ({int(done)} of {int(total)} {unit})" + (f"; {note}" if note else ""))


def _display(description: str):
    return _Bar(description) if _bar_on_terminal() else _Lines(description)


@contextlib.contextmanager
def progress(description: str, axes=()):
    """Yield (allan_cb, epoch_cb) callbacks that show the progress of a run on stderr.

    On a terminal one rich bar names the stage, the axis (k/n of ``axes``) and the model that
    :func:`fogdrift.interrupt.checkpoint` announces (:func:`progress_label`); it shows a count only when the total
    is known (taus, epochs).  Off a terminal the same is printed as plain lines (:data:`PROGRESS_STEP_PCT`).  Every
    callback and checkpoint is a point where Ctrl-C stops the run.
    """
    axes = list(axes)
    where = {"stage": "", "axis": None, "model": None}

    with _display(description) as display:
        def on_stage(stage, axis, model):
            where.update(stage=stage, axis=axis, model=model)
            display.stage(progress_label(description, axes, **where))

        def allan_cb(done, total):
            interrupt.check()
            if not where["stage"]:
                where["stage"] = "Allan variance"
            display.count(progress_label(description, axes, **where), done, total, "taus")

        def epoch_cb(epoch, n_epochs, train_loss, val_loss):
            interrupt.check()
            display.count(progress_label(description, axes, **where), epoch, n_epochs, "epochs",
                          bar_extra=f"loss {train_loss:.3g} / val {val_loss:.3g}")

        with interrupt.stage_listener(on_stage):
            yield allan_cb, epoch_cb


@contextlib.contextmanager
def progress_count(description: str, unit: str):
    """Yield ``update(done, total, note="")``: the progress of one counted job (samples, files) on stderr, as
    :func:`progress` shows it.  The stages a checkpoint announces without an axis are shown too (those with an
    axis belong to one file of a batch)."""
    with _display(description) as display:
        def on_stage(stage, axis, model):
            if axis is None:
                display.stage(f"{description} · {stage}")

        def update(done, total, note: str = ""):
            interrupt.check()
            display.count(description, done, total, unit, note=note)

        with interrupt.stage_listener(on_stage):
            yield update


# -- tables -----------------------------------------------------------------------------------------------------
def table(title, headers, rows) -> Table:
    """A rich table of plain text (units such as [deg/h] must not be read as rich markup); cells fold, never
    end in an ellipsis."""
    out = Table(title=Text(title), title_justify="left")
    for i, h in enumerate(headers):
        out.add_column(Text(h), justify="left" if i == 0 else "right", overflow="fold")
    for row in rows:
        out.add_row(*(Text(str(c)) for c in row))
    return out


def column_groups(headers, rows, width: int) -> list[list[int]]:
    """Split columns 1.. into groups that fit ``width`` with column 0 repeated in each (rich's box: 3 characters
    per column plus 1).  A column too wide on its own gets a group of its own (its cells fold)."""
    cells = [[str(h)] + [str(r[j]) for r in rows] for j, h in enumerate(headers)]
    natural = [max(len(line) for c in col for line in c.splitlines() or [""]) + 3 for col in cells]
    first = natural[0] + 1
    groups, current, used = [], [], first
    for j in range(1, len(headers)):
        if current and used + natural[j] > width:
            groups.append(current)
            current, used = [], first
        current.append(j)
        used += natural[j]
    if current:
        groups.append(current)
    return groups or [[]]


def fitted_table(title, headers, rows) -> Group:
    """A table that fits the console as one renderable: too many columns are folded into several tables
    ("continued"), each repeating the first column."""
    groups = column_groups(headers, rows, console.width)
    parts = []
    for k, group in enumerate(groups):
        cols = [0] + group
        part = title if k == 0 else f"{title} (continued, {k + 1}/{len(groups)})"
        parts.append(table(part, [headers[j] for j in cols], [[row[j] for j in cols] for row in rows]))
    return Group(*parts)


def first_run_note(command: str, root: Path | None = None) -> bool:
    """Tell a user at a terminal, once, that this run compiles the numerical kernels (numba's cache holds none of
    the package yet: no ``*.nbi`` beside the modules or under ``NUMBA_CACHE_DIR``); returns whether it was said."""
    root = Path(__file__).resolve().parents[1] if root is None else Path(root)
    places = [root] + ([Path(os.environ["NUMBA_CACHE_DIR"])] if os.environ.get("NUMBA_CACHE_DIR") else [])
    if command == "export" or not err_console.is_terminal or any(next(p.glob("**/*.nbi"), None) for p in places
                                                                  if p.is_dir()):
        return False
    err_console.print(Text("first run here: compiling the numerical kernels for this machine (once, up to a minute;"
                           " later runs read them from the cache)", style="dim"), soft_wrap=True)
    return True


def print_table(title, headers, rows) -> None:
    """Print :func:`fitted_table` on stdout (nothing under --json)."""
    console.print(fitted_table(title, headers, rows))
