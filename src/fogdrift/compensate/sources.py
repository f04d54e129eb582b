"""Reading the log to compensate, through :mod:`fogdrift.io`, and matching it to the bundle (unit, rate, axes).

* ``.npy`` files are streamed **chunk by chunk from the file** by the io chunked source
  (:func:`fogdrift.io.chunked.open_rows`): memory stays bounded by the chunk size whatever the file size.
  Columns are ``col0, col1, ...`` as for :func:`fogdrift.io.load`; a time column is used only when named.
* Every other format (and a ``.npy`` read with options only :func:`fogdrift.io.load` has: a forced format, reader
  options, a temperature column, gap splitting) is read **once** by :func:`fogdrift.io.load`, with the same
  options as every other command, and handed on in chunks.

Either way the numbers are converted to deg/h once, by the reader, with the scale it records
(:attr:`LogSource.scale_to_dph`); the outputs divide by that same scale to write the log's own unit.

The unit (:func:`open_log`): ``unit`` if given (it takes precedence over a unit the file declares, as for every
command), else the unit the file declares.  A log that declares none, read without ``unit``, is **refused** with
one line suggesting the bundle's unit: units are never guessed, not even from the bundle.

Matching (:func:`match_log`), each refusal one line naming the option that maps it:

* **unit**: a declared unit that differs from the bundle's is refused unless ``unit`` is given (then converted).
* **rate**: a native rate different from the bundle's is refused unless ``accept_rate`` (then the log is
  block-averaged to the bundle's modelling rate by its own integer factor).
* **axes** are matched **by name**; ``axis_map`` (``{"col0": "gz"}``) maps others.  A log axis with no bundle
  axis is refused (choose columns with ``columns``); bundle axes absent from the log are listed in a note.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import ConfigError, DataFormatError, FogdriftWarning
from ..io import decimation_factor, load, load_segments
from ..io._checks import check_path
from ..io.chunked import open_rows
from ..signal import SignalDescription

__all__ = ["LogSource", "open_log", "match_log", "LogMatch", "DEFAULT_CHUNK"]

#: Rows per chunk when a caller gives none.
DEFAULT_CHUNK = 1 << 20


@dataclass
class LogSource:
    """A log opened for chunked reading, its numbers converted to deg/h once by the reader.

    The facts about its numbers are the reader's :class:`~fogdrift.signal.SignalDescription` (made once by
    :func:`fogdrift.io.load` or :func:`fogdrift.io.chunked.open_rows`); the properties below read them back.

    Attributes
    ----------
    path : Path
    signal : fogdrift.signal.SignalDescription
        Sampling (interval, where it came from) and channels (unit as read, where it came from, the unit the file
        declares, the factor to deg/h).
    t0_s : float
    n_samples : int
    sha256 : str or None
    notes : list of str
    """

    path: Path
    signal: SignalDescription
    t0_s: float
    n_samples: int
    sha256: str | None
    notes: list = field(default_factory=list)
    _chunks: object = None

    @property
    def axis_names(self) -> tuple:
        return self.signal.names

    @property
    def dt_s(self) -> float:
        """Sample interval [s]."""
        return self.signal.sampling.dt_s

    @property
    def unit(self) -> str:
        """Unit of the file's numbers: the one given, else the one the file declares."""
        return self.signal.channels[0].unit_as_read

    @property
    def unit_given(self) -> bool:
        """True when the unit came from the ``unit`` option (not from the file)."""
        return self.signal.channels[0].unit_source == "option"

    @property
    def declared_unit(self) -> str | None:
        """Unit the file declares for its rate columns (None: none)."""
        return _one_declared([c.declared_unit for c in self.signal.channels], self.path)

    @property
    def scale_to_dph(self) -> float:
        """Factor the reader applied to the file's numbers (unit to deg/h)."""
        return self.signal.channels[0].scale_to_internal

    def chunks(self, chunk_samples: int = DEFAULT_CHUNK):
        """Yield ``(t_s (n,), rate_dph (n, n_axes))`` in order, ``chunk_samples`` rows at a time."""
        if isinstance(chunk_samples, bool) or not isinstance(chunk_samples, (int, np.integer)) or chunk_samples < 1:
            raise ConfigError(f"{{opt:chunk_samples}} must be an integer >= 1 (rows read at a time); got "
                              f"{chunk_samples!r}")
        yield from self._chunks(int(chunk_samples))


def _one_declared(units, path) -> str | None:
    declared = set(units)
    if len(declared) > 1:
        raise DataFormatError(f"rate columns declare different units {sorted(map(str, declared))}; expected one "
                              "unit (choose columns with {opt:columns})", path=path)
    return next(iter(declared), None)


def _gyro_only(src: LogSource) -> LogSource:
    """Refuse accelerometer channels (a bundle models gyro drift; docs/accelerometers.md): one line naming them."""
    acc = [c.name for c in src.signal.channels if c.quantity == "specific_force"]
    if acc:
        raise ConfigError(f"{src.path}: compensate applies a gyro drift model; {', '.join(acc)} "
                          f"{'is an accelerometer channel' if len(acc) == 1 else 'are accelerometer channels'} "
                          "(specific force, from its unit): leave them out with {opt:columns}")
    return src


def _streamed(path, load_kwargs) -> LogSource:
    src = open_rows(path, columns=load_kwargs.get("columns"), time_column=load_kwargs.get("time_column", "auto"),
                    rate_hz=load_kwargs.get("rate_hz"), time_unit=load_kwargs.get("time_unit"),
                    unit=load_kwargs.get("unit"))
    return LogSource(path=src.path, signal=src.signal, t0_s=src.t0_s, n_samples=src.n_samples, sha256=src.sha256,
                     notes=list(src.notes), _chunks=src.chunks)


def _loaded(path, load_kwargs) -> LogSource:
    if load_kwargs.get("gaps") == "split":  # the longest gap-free segment, said in one warning line
        kwargs = {k: v for k, v in load_kwargs.items() if k != "gaps"}
        segs = load_segments(path, **kwargs)
        rec = max(segs, key=lambda r: r.n_samples)
        if len(segs) > 1:
            warnings.warn(f"{path}: {len(segs)} segments between gaps; compensating the longest ({rec.n_samples} "
                          f"samples, {rec.notes[-1]})", FogdriftWarning, stacklevel=3)
    else:
        rec = load(path, **load_kwargs)
    _one_declared(rec.declared_units, rec.source)

    def chunks(chunk):
        for lo in range(0, rec.n_samples, chunk):
            hi = min(rec.n_samples, lo + chunk)
            yield rec.t0_s + np.arange(lo, hi) * rec.dt_s, rec.data_internal[lo:hi]

    return LogSource(path=Path(rec.source), signal=rec.signal, t0_s=rec.t0_s, n_samples=rec.n_samples,
                     sha256=rec.sha256, notes=list(rec.notes), _chunks=chunks)


#: Options of :func:`fogdrift.io.load` the streamed ``.npy`` path takes; any other set option reads the file
#: with :func:`fogdrift.io.load`.
_STREAM_OPTIONS = ("columns", "time_column", "rate_hz", "unit", "time_unit")


def open_log(path, *, unit=None, columns=None, time_column="auto", rate_hz=None, time_unit=None, format=None,
             reader_options=None, temperature=None, gaps="error", bundle_unit=None) -> LogSource:
    """Open a gyro log for chunked reading (see the module docstring); the file is parsed once.

    Parameters
    ----------
    path : str or Path
    unit, columns, time_column, rate_hz, time_unit, format, reader_options, temperature, gaps
        As for :func:`fogdrift.io.load` (``gaps="split"`` keeps the longest gap-free segment, with a warning).
    bundle_unit : str, optional
        The bundle's unit, suggested in the refusal of a log that declares no unit.

    Raises
    ------
    ConfigError
        No unit given and none declared (one line suggesting ``bundle_unit``); as :func:`fogdrift.io.load`.
    DataFormatError, InsufficientDataError
        As :func:`fogdrift.io.load`.
    """
    p = check_path(path)
    kwargs = dict(unit=unit, columns=columns, time_column=time_column, rate_hz=rate_hz, time_unit=time_unit,
                  format=format, reader_options=reader_options or None, temperature=temperature, gaps=gaps)
    with open(p, "rb") as fh:
        magic = fh.read(6)
    stream = magic == b"\x93NUMPY" and format in (None, "npy") and not reader_options and temperature is None \
        and gaps == "error"
    try:
        if stream:
            return _gyro_only(_streamed(p, {k: kwargs[k] for k in _STREAM_OPTIONS}))
        return _gyro_only(_loaded(p, {k: v for k, v in kwargs.items() if v is not None}))
    except ConfigError as exc:
        if unit is not None or bundle_unit is None or "{opt:unit}" not in str(exc.args[0] if exc.args else ""):
            raise
        raise ConfigError(f"{p}: the log declares no rate unit and none was given; pass {{opt:unit}} {bundle_unit} "
                          f"(the bundle was trained on {bundle_unit}) or the unit of its numbers (units are never "
                          "guessed)") from None


# ----------------------------------------------------------------------------------------------------------
# matching
# ----------------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class LogMatch:
    """How a log is mapped onto a bundle.

    Attributes
    ----------
    unit : str
        Unit of the log's numbers (also the unit of the output files).
    scale_to_dph : float
    factor : int
        Native samples per modelling interval for this log.
    axes : tuple of (str, str)
        (log axis, bundle axis), in log column order.
    notes : tuple of str
        What was assumed or mapped, one sentence each.
    """

    unit: str
    scale_to_dph: float
    factor: int
    axes: tuple
    notes: tuple


def parse_axis_map(text) -> dict:
    """``"col0=gz, col1=gx"`` (or a dict) -> ``{"col0": "gz", "col1": "gx"}``."""
    if text is None:
        return {}
    if isinstance(text, dict):
        return {str(k): str(v) for k, v in text.items()}
    out = {}
    for item in str(text).split(","):
        if not item.strip():
            continue
        log, sep, bundle = item.partition("=")
        if not sep or not log.strip() or not bundle.strip():
            raise ConfigError(f"axis map entries look like LOG_AXIS=BUNDLE_AXIS (e.g. col0=gz); got {item.strip()!r} "
                              "in {opt:axis_map}")
        out[log.strip()] = bundle.strip()
    return out


def match_log(source: LogSource, bundle, *, axis_map=None, accept_rate=False) -> LogMatch:
    """Check a log against a bundle (unit, rate, axes) and say how it maps; see the module docstring.

    Raises
    ------
    ConfigError
        A mismatch that was not mapped, in one line naming the option that maps it.
    """
    notes = []
    unit = source.unit
    if source.unit_given:
        if source.declared_unit is None:
            notes.append(f"unit: the log declares none; its numbers are read as {unit} ({{opt:unit}})")
        elif source.declared_unit.strip() != unit:
            notes.append(f"unit: the log declares {source.declared_unit.strip()}; its numbers are read as {unit} "
                         "({opt:unit} takes precedence)")
        if unit != bundle.input_unit:
            notes.append(f"unit: the log is read as {unit} ({{opt:unit}}) and converted; the bundle was trained on "
                         f"{bundle.input_unit}")
    elif unit != bundle.input_unit:
        raise ConfigError(f"{source.path}: the log declares unit {unit} but the bundle was trained on "
                          f"{bundle.input_unit}; pass {{opt:unit}} {unit} to convert it")
    scale = source.scale_to_dph

    rel = abs(source.dt_s - bundle.native_dt_s) / bundle.native_dt_s
    if rel <= 1e-6:
        factor = bundle.block_average_factor
    elif not accept_rate:
        raise ConfigError(
            f"{source.path}: the log is sampled at {1 / source.dt_s:.6g} Hz, the bundle's training log at "
            f"{1 / bundle.native_dt_s:.6g} Hz (models at {1 / bundle.model_dt_s:.6g} Hz); pass {{opt:accept_rate}} to "
            "block-average it to the bundle's modelling rate")
    else:
        try:
            factor = decimation_factor(source.dt_s, 1.0 / bundle.model_dt_s)
        except ConfigError:
            raise ConfigError(f"{source.path}: the log's {1 / source.dt_s:.6g} Hz cannot be block-averaged to the "
                              f"bundle's modelling rate {1 / bundle.model_dt_s:.6g} Hz by an integer factor") from None
        notes.append(f"rate: the log ({1 / source.dt_s:.6g} Hz) differs from the training log "
                     f"({1 / bundle.native_dt_s:.6g} Hz); block-averaged x{factor} to the modelling rate")

    mapping = parse_axis_map(axis_map)
    unknown = [k for k in mapping if k not in source.axis_names]
    if unknown:
        raise ConfigError(f"axis map names {unknown}, not axes of the log {list(source.axis_names)}; "
                          "check {opt:axis_map}")
    pairs, used = [], {}
    for name in source.axis_names:
        target = mapping.get(name, name)
        if target not in bundle.axis_names:
            hint = "" if name in mapping else f" (pass {{opt:axis_map}} {name}=AXIS, or choose columns with {{opt:columns}})"
            raise ConfigError(f"{source.path}: log axis {name!r} has no model in the bundle, whose axes are "
                              f"{list(bundle.axis_names)}{hint}")
        if target in used:
            raise ConfigError(f"log axes {used[target]!r} and {name!r} both map to bundle axis {target!r}; "
                              "check {opt:axis_map}")
        used[target] = name
        pairs.append((name, target))
        if target != name:
            notes.append(f"axis: log {name} -> bundle {target}")
    missing = [a for a in bundle.axis_names if a not in used]
    if missing:
        notes.append(f"axes of the bundle not in the log (not compensated): {', '.join(missing)}")
    return LogMatch(unit=unit, scale_to_dph=scale, factor=int(factor), axes=tuple(pairs), notes=tuple(notes))
