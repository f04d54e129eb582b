"""Reading the log to compensate in chunks, and matching it to the bundle (unit, rate, axes).

* ``.npy`` files are read **chunk by chunk from the file** (the header is parsed, rows are read with
  ``numpy.fromfile``): memory stays bounded by the chunk size whatever the file size (a 10^8-sample log
  works in well under 2 GB).  Columns are ``col0, col1, ...`` as for :func:`fogdrift.io.load`; a time column
  is used only when named (``time_column``); otherwise the sample rate must be given.
* Every other format is read by :func:`fogdrift.io.load` (the whole file; text logs are parsed in memory) and
  handed on in chunks.

Matching (:func:`match_log`), each refusal one line naming the option that maps it:

* **unit**: the log's unit is ``apply_unit`` if given, else the unit its header declares, else the bundle's
  (said in a note).  A declared unit that differs from the bundle's is refused unless ``apply_unit`` is given.
* **rate**: a native rate different from the bundle's is refused unless ``accept_rate`` (then the log is
  block-averaged to the bundle's modelling rate by its own integer factor).
* **axes** are matched **by name**; ``axis_map`` (``{"col0": "gz"}``) maps others.  A log axis with no bundle
  axis is refused (choose columns with ``columns``); bundle axes absent from the log are listed in a note.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import ConfigError, DataFormatError, FogdriftError
from ..units import INCREMENT_UNITS, RATE_UNITS, TIME_UNITS, increment_scale_to_dph, rate_scale_to_dph

__all__ = ["LogSource", "open_log", "match_log", "LogMatch", "unit_scale_to_dph"]

#: Rows per chunk when a caller gives none.
DEFAULT_CHUNK = 1 << 20


def unit_scale_to_dph(unit: str, dt_s: float) -> float:
    """Factor from ``unit`` (rate unit or ``inc:<angle>`` per sample of ``dt_s``) to deg/h."""
    u = unit.strip()
    if u in RATE_UNITS:
        return rate_scale_to_dph(u)
    if u.startswith("inc:") and u[4:].strip() in INCREMENT_UNITS:
        return increment_scale_to_dph(u[4:].strip(), dt_s)
    valid = list(RATE_UNITS) + [f"inc:{k}" for k in INCREMENT_UNITS]
    raise ConfigError(f"unknown unit {unit!r}; expected one of {valid}; pass {{opt:apply_unit}}")


@dataclass
class LogSource:
    """A log opened for chunked reading (numbers in the file's unit until :meth:`chunks` scales them).

    Attributes
    ----------
    path : Path
    axis_names : tuple of str
    declared_unit : str or None
        Unit the file declares for its rate columns (None: none).
    dt_s, t0_s : float
    n_samples : int
    sha256 : str or None
    notes : list of str
    """

    path: Path
    axis_names: tuple
    declared_unit: str | None
    dt_s: float
    t0_s: float
    n_samples: int
    sha256: str | None
    notes: list = field(default_factory=list)
    _reader: object = None

    def chunks(self, scale_to_dph: float, chunk_samples: int = DEFAULT_CHUNK):
        """Yield ``(t_s (n,), rate_dph (n, n_axes))`` in order, ``chunk_samples`` rows at a time."""
        if isinstance(chunk_samples, bool) or not isinstance(chunk_samples, (int, np.integer)) or chunk_samples < 1:
            raise ConfigError(f"chunk_samples must be an integer >= 1; got {chunk_samples!r}")
        yield from self._reader(float(scale_to_dph), int(chunk_samples))


# ----------------------------------------------------------------------------------------------------------
# .npy, streamed
# ----------------------------------------------------------------------------------------------------------
def _npy_header(path: Path):
    try:
        with open(path, "rb") as fh:
            major, _ = np.lib.format.read_magic(fh)
            if major == 1:
                shape, fortran, dtype = np.lib.format.read_array_header_1_0(fh)
            else:
                shape, fortran, dtype = np.lib.format.read_array_header_2_0(fh)
            offset = fh.tell()
    except (ValueError, OSError, EOFError) as exc:
        raise DataFormatError(f"unreadable .npy header; expected a NumPy array file, got {exc}", path=path) from None
    if dtype.kind not in "biuf" or len(shape) not in (1, 2) or dtype.hasobject:
        raise DataFormatError(f"array of dtype {dtype} and shape {shape}; expected a real numeric 1-D or 2-D array",
                              path=path)
    rows = int(shape[0])
    cols = 1 if len(shape) == 1 else int(shape[1])
    if path.stat().st_size < offset + rows * cols * dtype.itemsize:
        raise DataFormatError(f"file is shorter than its header says ({rows} x {cols} {dtype}); expected the whole "
                              "array, got a truncated file", path=path)
    return rows, cols, dtype, bool(fortran) and cols > 1, offset


def _column_index(key, cols, option, path):
    if isinstance(key, (int, np.integer)) and not isinstance(key, bool) and -cols <= int(key) < cols:
        return int(key) % cols
    if isinstance(key, str):
        k = key.strip()
        if k.isdigit() and int(k) < cols:
            return int(k)
        if k.startswith("col") and k[3:].isdigit() and int(k[3:]) < cols:
            return int(k[3:])
    raise DataFormatError(f"unknown column {key!r}; expected one of col0..col{cols - 1} or an index in "
                          f"{{opt:{option}}}", path=path, column=key)


def _open_npy(path: Path, columns, time_column, rate_hz, time_unit) -> LogSource:
    from ..io import file_sha256

    rows, cols, dtype, fortran, offset = _npy_header(path)
    t_idx = None
    if time_column is not None and not (isinstance(time_column, str) and time_column.strip().lower() == "auto"):
        t_idx = _column_index(time_column, cols, "time_column", path)
    if columns is None:
        r_idx = [j for j in range(cols) if j != t_idx]
    else:
        keys = [c.strip() for c in columns.split(",")] if isinstance(columns, str) else list(columns)
        r_idx = [_column_index(k, cols, "columns", path) for k in keys]
    if not r_idx or len(set(r_idx)) != len(r_idx) or t_idx in r_idx:
        raise ConfigError(f"{path}: choose distinct rate columns other than the time column; got columns={columns!r}")
    if time_unit and time_unit not in TIME_UNITS:
        raise ConfigError(f"unknown time unit {time_unit!r}; expected one of {list(TIME_UNITS)}")
    t_scale = TIME_UNITS[time_unit] if time_unit else 1.0

    def read(lo, hi):
        if fortran:
            mm = np.load(path, mmap_mode="r")
            return np.array(mm[lo:hi], dtype=np.float64).reshape(hi - lo, cols)
        with open(path, "rb") as fh:
            fh.seek(offset + lo * cols * dtype.itemsize)
            a = np.fromfile(fh, dtype=dtype, count=(hi - lo) * cols)
        return a.reshape(hi - lo, cols).astype(np.float64, copy=False)

    notes = [f"npy array, {rows} samples x {cols} columns, read in chunks"]
    if t_idx is None:
        if rate_hz is None:
            raise ConfigError(f"{path}: cannot tell the sample interval: a .npy file has no time column unless "
                              "one is named with {opt:time_column}; pass the sample rate in Hz as {opt:rate_hz}")
        dt, t0 = 1.0 / float(rate_hz), 0.0
        notes.append(f"sample interval {dt:.10g} s from the given rate (no time column)")
    else:
        head = read(0, min(rows, 65537))[:, t_idx] * t_scale
        if head.size < 2:
            raise DataFormatError("fewer than 2 samples; expected at least 2 to take the sample interval", path=path)
        dt = float(f"{float(np.median(np.diff(head))):.10g}")
        t0 = float(head[0])
        if rate_hz is not None:
            if abs(dt * float(rate_hz) - 1.0) > 0.01:
                raise DataFormatError(f"time column disagrees with the given rate; expected steps of "
                                      f"{1 / float(rate_hz):.10g} s, got {dt:.10g} s", path=path, column=f"col{t_idx}")
            dt = 1.0 / float(rate_hz)
        notes.append(f"sample interval {dt:.10g} s from the time column col{t_idx} (median of the first steps)")
    if not (math.isfinite(dt) and dt > 0):
        raise DataFormatError(f"sample interval {dt!r} s; expected a finite interval > 0", path=path)

    def reader(scale, chunk):
        prev_t = None
        for lo in range(0, rows, chunk):
            hi = min(rows, lo + chunk)
            a = read(lo, hi)
            x = a[:, r_idx]
            bad = ~np.isfinite(x)
            if bad.any():
                i, j = np.argwhere(bad)[0]
                raise DataFormatError(f"non-finite value at sample {lo + i}; expected a finite number, got "
                                      f"{float(x[i, j])!r}", path=path, column=f"col{r_idx[j]}")
            if t_idx is None:
                t = t0 + np.arange(lo, hi) * dt
            else:
                t = a[:, t_idx] * t_scale
                steps = np.diff(np.concatenate([[prev_t], t]) if prev_t is not None else t)
                first = lo if prev_t is None else lo - 1
                bad = ~(steps > 0) | (steps > 1.5 * dt)
                if bad.any():
                    i = int(np.argmax(bad)) + first + 1
                    raise DataFormatError(f"time step at sample {i} is {float(steps[np.argmax(bad)])!r} s; expected "
                                          f"increasing time without gaps (steps of {dt:.10g} s)", path=path,
                                          column=f"col{t_idx}")
                prev_t = t[-1]
            with np.errstate(over="ignore"):
                yield t, np.multiply(x, scale, dtype=np.float64)

    return LogSource(path=path, axis_names=tuple(f"col{j}" for j in r_idx), declared_unit=None, dt_s=dt, t0_s=t0,
                     n_samples=rows, sha256=file_sha256(path), notes=notes, _reader=reader)


# ----------------------------------------------------------------------------------------------------------
# everything else, via fogdrift.io.load
# ----------------------------------------------------------------------------------------------------------
def _open_loaded(path: Path, columns, time_column, rate_hz, time_unit) -> LogSource:
    from ..io import load

    tc = None if isinstance(time_column, str) and time_column.strip().lower() == "none" else time_column
    try:
        rec = load(path, columns=columns, time_column=tc, rate_hz=rate_hz, time_unit=time_unit)
    except ConfigError as exc:
        # a log that declares no unit: read its numbers as they are (deg/h = factor 1); match_log then takes
        # --apply-unit or the bundle's unit and says so.  Any other configuration error stands.
        try:
            rec = load(path, columns=columns, time_column=tc, rate_hz=rate_hz, time_unit=time_unit, unit="deg/h")
        except FogdriftError:
            raise exc from None
        if any(u is not None for u in rec.declared_units):
            raise exc from None
    declared = {u for u in rec.declared_units}
    if len(declared) > 1:
        raise DataFormatError(f"rate columns declare different units {sorted(map(str, declared))}; expected one "
                              "unit (choose columns with {opt:columns})", path=path)
    declared_unit = next(iter(declared))
    # load() converted a declared unit to deg/h; undo it so that chunks() applies the unit finally chosen
    raw_scale = rec.scale_to_dph

    def reader(scale, chunk):
        for lo in range(0, rec.n_samples, chunk):
            hi = min(rec.n_samples, lo + chunk)
            x = rec.rate_dph[lo:hi]
            if scale != raw_scale:
                x = np.multiply(x / raw_scale if raw_scale != 1.0 else x, scale, dtype=np.float64)
            yield rec.t0_s + np.arange(lo, hi) * rec.dt_s, np.array(x, dtype=np.float64)

    return LogSource(path=path, axis_names=rec.axis_names, declared_unit=declared_unit, dt_s=rec.dt_s, t0_s=rec.t0_s,
                     n_samples=rec.n_samples, sha256=rec.sha256, notes=list(rec.notes), _reader=reader)


def open_log(path, *, columns=None, time_column="auto", rate_hz=None, time_unit=None) -> LogSource:
    """Open a gyro log for chunked reading (see the module docstring).

    Raises
    ------
    ConfigError, DataFormatError, InsufficientDataError
        As :func:`fogdrift.io.load`.
    """
    from ..io._checks import check_path

    p = check_path(path)
    with open(p, "rb") as fh:
        magic = fh.read(6)
    if magic == b"\x93NUMPY":
        return _open_npy(p, columns, time_column, rate_hz, time_unit)
    return _open_loaded(p, columns, time_column, rate_hz, time_unit)


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


def match_log(source: LogSource, bundle, *, apply_unit=None, axis_map=None, accept_rate=False) -> LogMatch:
    """Check a log against a bundle (unit, rate, axes) and say how it maps; see the module docstring.

    Raises
    ------
    ConfigError
        A mismatch that was not mapped, in one line naming the option that maps it.
    """
    from ..io import decimation_factor

    notes = []
    if apply_unit is not None:
        unit = apply_unit.strip()
        unit_scale_to_dph(unit, source.dt_s)  # validates
        if unit != bundle.input_unit:
            notes.append(f"unit: the log is read as {unit} (apply_unit) and converted; the bundle was trained on "
                         f"{bundle.input_unit}")
    elif source.declared_unit is not None:
        unit = source.declared_unit.strip()
        if unit != bundle.input_unit:
            raise ConfigError(f"{source.path}: the log declares unit {unit} but the bundle was trained on "
                              f"{bundle.input_unit}; pass {{opt:apply_unit}} {unit} to convert it")
    else:
        unit = bundle.input_unit
        notes.append(f"unit: the log declares none; taking the bundle's {unit} (pass {{opt:apply_unit}} to override)")
    scale = unit_scale_to_dph(unit, source.dt_s)

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
