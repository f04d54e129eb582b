"""Loading a gyro log into :class:`~fogdrift.io.GyroRecord` objects, for every format.

The reader (chosen by :mod:`fogdrift.io.registry`) turns the file into named numeric columns;
this module does what is the same for all formats: it chooses the rate and time columns,
checks the values (finite), the time (increasing, matching ``dt_s``/``rate_hz``, gaps),
resolves units (given, or declared by the file), converts to deg/h and builds the records.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from .. import units
from .channel_quantity import UnitChoice, check_name, parse_unit_choice
from ..errors import ConfigError, DataFormatError, FogdriftWarning, InsufficientDataError
from ..signal import Channel, Sampling, SignalDescription, channel_unit
from ._checks import (
    check_path,
    first_nonfinite,
    split_keys,
    take_columns,
    to_dph,
    valid_units,
)
from .hashing import file_sha256
from .readers.base import Table, split_unit_label
from .record import GyroRecord
from .registry import reader_by_name, select_reader
from .timebase import check_time

__all__ = ["load", "load_segments", "time_unit_of_name", "TIME_COLUMN_NAMES",
           "check_load_options"]

#: Column names (compared case-insensitively) that ``time_column="auto"`` takes as time; so does one of the
#: first, third or last with a time-unit suffix (``t_ms``, ``time_us``, ``timestamp_ns``).
TIME_COLUMN_NAMES = ("t", "t_s", "time", "time_s", "timestamp")
#: A unit the file states, in words, by ``Table.format`` (else "declared by the file": HDF5/.mat attributes, miniSEED).
_SAID = {"text": "declared in the header", "bag": "declared by the message definition"}.get


def load(
    path,
    *,
    columns=None,
    time_column="auto",
    dt_s=None,
    rate_hz=None,
    unit=None,
    time_unit=None,
    delimiter=None,
    gaps="error",
    min_samples=2,
    format=None,
    reader_options=None,
    temperature=None,
) -> GyroRecord:
    """Load a gyro log into a :class:`~fogdrift.io.GyroRecord` in deg/h.

    Parameters
    ----------
    path : str or Path
        Text (CSV/TXT, optionally gzip), ``.npy``, ``.npz``, HDF5, MATLAB ``.mat``, ROS 1 bag,
        ROS 2 bag (directory), miniSEED or raw binary file; the format is detected from the
        first bytes, then the extension (see :mod:`fogdrift.io.registry`), or implied by a
        reader option only one format accepts (``layout`` = raw binary).
    columns : None, int, str or sequence of int/str
        Rate columns: names or 0-based indices (ints or digit strings; a string may list
        several separated by commas, e.g. ``"gx,gz"`` or ``"1,2"``).  Default: every column
        except the time column.  Header-less text and arrays name columns ``col0, col1, ...``.
        A header cell ``gz[deg/s]`` names the column ``gz``.
    time_column : "auto", None, int or str
        ``"auto"`` uses the format's own time vector if it has one, else a column named t,
        t_s, time, time_s or timestamp (any case) if there is one; ``None`` means no time
        column.
    dt_s, rate_hz : float, optional
        Sample interval in s, or sample rate in Hz.  Required without a time column; with
        one, they must agree with its median step within 1 % and then take precedence.
    unit : str, optional
        Unit of the numbers: a rate unit from :data:`fogdrift.units.RATE_UNITS`
        (``"deg/h"``, ``"deg/s"``, ``"rad/s"``, ``"rad/h"``, ``"arcsec/s"``) or an angle increment
        per sample ``"inc:deg"``, ``"inc:rad"``, ``"inc:arcsec"``.  Default: the unit the
        file declares for the rate columns (``gz[deg/s]``); a file that declares none needs
        ``unit`` (ConfigError otherwise: a unit is never guessed).  A given unit takes
        precedence over a declared one (a note records the difference).
    time_unit : {"s", "ms", "us", "ns"}, optional
        Unit of the time column (:data:`fogdrift.units.TIME_UNITS`).  Default: the unit the
        header declares for it, in brackets (``t[ms]``) or by a name suffix (``t_s``,
        ``time_ms``); a time column that declares none needs ``time_unit``.  Not needed
        without a time column or for a format's own time stamps (always in s).
    delimiter : None or str
        Text only.  ``None`` detects it from the first non-comment lines (tab, comma,
        semicolon, else whitespace); or one of ``","``, ``";"``, ``"\\t"``, ``" "``
        (whitespace) or the words comma, semicolon, tab, whitespace.
    gaps : {"error", "split"}
        A time step > 1.5 sample intervals is a gap.  ``"error"`` raises, naming the line,
        time and size of the first gap; ``"split"`` returns the longest gap-free segment with
        a :class:`~fogdrift.errors.FogdriftWarning` (use :func:`load_segments` to get all).
    min_samples : int
        Fewest samples accepted (>= 1).
    format : str, optional
        Force a reader by its name in :data:`fogdrift.io.registry.READERS` (``"text"``,
        ``"npy"``, ``"npz"``) instead of detecting it.
    reader_options : mapping, optional
        Options for the reader, e.g. ``{"delimiter": ";"}`` for text, ``{"dataset": "/imu"}``
        for HDF5, ``{"topic": "/imu/data"}`` for a bag; each reader lists the ones it accepts
        in its registry line (:data:`fogdrift.io.registry.READERS`).
    temperature : None, int or str
        Column (name or 0-based index) holding the temperature, carried into
        ``GyroRecord.temperature_c`` in deg C (a declared unit ``K`` is converted; other
        units are refused).  It is never a rate column.  For formats whose temperature lives
        apart from the rates (a ``sensor_msgs/Temperature`` topic in a bag, a miniSEED
        channel at its own rate) the reader interpolates it linearly onto the rate times.

    Returns
    -------
    GyroRecord
        ``data_internal`` is a read-only view; for a float64 ``.npy`` in deg/h it is a view of the
        memory map (no copy).  ``sha256`` is the hash of the file's bytes, computed while
        they were read.

    Raises
    ------
    ConfigError
        Invalid option (unit, time_unit, dt_s/rate_hz, delimiter, gaps, min_samples,
        format, reader_options), a column selected twice, no way to know the sample
        interval, or a rate unit / time unit neither given nor declared by the file.
    DataFormatError
        Missing/empty/unknown-format file, header only, non-numeric cell, NaN/inf (also
        after conversion to deg/h), ragged row, unsorted or duplicate time, gap, unknown
        column, time column contradicting dt_s/rate_hz, unknown or mixed declared units.
    InsufficientDataError
        Fewer than ``min_samples`` samples.

    Notes
    -----
    Text is parsed by :func:`numpy.loadtxt`; only if that fails is the file re-read line by
    line to report the exact line and column.  The interval from a time column is the
    median step rounded to 10 significant digits (removes the float noise of decimal time
    stamps: steps of 0.01 s stay 0.01 s).

    Examples
    --------
    >>> import tempfile, os
    >>> d = tempfile.mkdtemp(); p = os.path.join(d, "g.csv")
    >>> with open(p, "w") as fh:
    ...     _ = fh.write("t_s,gx,gy\\n0.00,1,2\\n0.01,3,4\\n0.02,5,6\\n")
    >>> rec = load(p, columns="gy", unit="deg/h")
    >>> rec.dt_s, rec.axis_names, rec.rate_dph[:, 0].tolist()
    (0.01, ('gy',), [2.0, 4.0, 6.0])

    Units declared in the header are used when no ``unit`` is given:

    >>> with open(p, "w") as fh:
    ...     _ = fh.write("t[ms],gz[deg/s]\\n0,0.001\\n10,0.002\\n20,0.003\\n")
    >>> rec = load(p)
    >>> rec.dt_s, rec.input_unit, rec.rate_dph[:, 0].round(9).tolist()
    (0.01, 'deg/s', [3.6, 7.2, 10.8])

    A unit is never guessed: without ``unit`` a file that declares none is refused.

    >>> with open(p, "w") as fh:
    ...     _ = fh.write("t_s,gz\\n0,1\\n0.01,2\\n")
    >>> load(p)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    fogdrift.errors.ConfigError: ...g.csv: no rate unit: the file declares none for gz; pass unit= (deg/h, ...
    """
    if gaps not in ("error", "split"):
        raise ConfigError(f"gaps must be 'error' or 'split'; got {gaps!r}")
    opts = check_load_options(columns, time_column, dt_s, rate_hz, unit, time_unit, delimiter, gaps, min_samples,
                              format, reader_options, temperature)
    records = _load_records(path, opts)
    if len(records) == 1:
        return records[0]
    best = max(records, key=lambda r: r.n_samples)
    warnings.warn(
        f"{path}: data have {len(records)} gap-free segments; returning the longest "
        f"({best.n_samples} of {sum(r.n_samples for r in records)} samples, {best.notes[-1]}); "
        "use load_segments() to get all",
        FogdriftWarning,
        stacklevel=2,
    )
    return best


def load_segments(
    path,
    *,
    columns=None,
    time_column="auto",
    dt_s=None,
    rate_hz=None,
    unit=None,
    time_unit=None,
    delimiter=None,
    gaps="split",
    min_samples=2,
    format=None,
    reader_options=None,
    temperature=None,
) -> list[GyroRecord]:
    """Load a gyro log split at time gaps into gap-free :class:`~fogdrift.io.GyroRecord` segments.

    Takes the keyword arguments of :func:`load`; ``gaps`` defaults to ``"split"`` here
    (``"error"`` raises at the first gap as in :func:`load`).  Each segment's ``t0_s`` is
    its first time stamp and its last note reads
    ``"segment k of m: samples a-b (lines c-d)"`` (sample indices are 0-based data rows of
    the file; lines are physical lines, text only).  Segments shorter than ``min_samples``
    are dropped with a :class:`~fogdrift.errors.FogdriftWarning`.

    Returns
    -------
    list of GyroRecord
        In time order; a single element when the data have no gap.  All share the file's
        ``sha256``.

    Raises
    ------
    ConfigError, DataFormatError
        As :func:`load`.
    InsufficientDataError
        If no segment has ``min_samples`` samples.
    """
    if gaps not in ("error", "split"):
        raise ConfigError(f"gaps must be 'error' or 'split'; got {gaps!r}")
    opts = check_load_options(columns, time_column, dt_s, rate_hz, unit, time_unit, delimiter, gaps, min_samples,
                              format, reader_options, temperature)
    return _load_records(path, opts)


# --------------------------------------------------------------------------------------------
# Options
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class _Options:
    columns: object
    time_column: object
    dt_s: float | None          # from dt_s or rate_hz
    unit: UnitChoice | None  # parsed once here (one unit, or one per quantity / column)
    time_unit: str | None
    split: bool
    min_samples: int
    format: str | None
    reader_options: dict
    temperature: object = None


def check_load_options(columns, time_column, dt_s, rate_hz, unit, time_unit, delimiter, gaps, min_samples, format,
             reader_options, temperature=None) -> _Options:
    """Validate every option before the file is touched."""
    spec = None if unit is None else parse_unit_choice(unit)
    if time_unit is not None and time_unit not in units.TIME_UNITS:
        raise ConfigError(f"unknown time unit {time_unit!r}; expected one of {list(units.TIME_UNITS)}")
    if isinstance(min_samples, bool) or not isinstance(min_samples, (int, np.integer)) or min_samples < 1:
        raise ConfigError(f"min_samples must be an integer >= 1; got {min_samples!r}")
    if format is not None:
        reader_by_name(format)
    if reader_options is None:
        ropts = {}
    elif isinstance(reader_options, Mapping):
        ropts = dict(reader_options)
    else:
        raise ConfigError(f"reader_options must be a mapping of option names to values; got {reader_options!r}")
    if delimiter is not None:
        if "delimiter" in ropts:
            raise ConfigError("delimiter given twice; expected it as delimiter= or in reader_options, not both")
        ropts["delimiter"] = delimiter
    if temperature is not None and not (isinstance(temperature, str) and temperature.strip()) and (
            isinstance(temperature, bool) or not isinstance(temperature, (int, np.integer))):
        raise ConfigError(f"temperature must be a column name or a 0-based index; got {temperature!r}")
    return _Options(columns=columns, time_column=time_column, dt_s=_interval_option(dt_s, rate_hz), unit=spec,
                    time_unit=time_unit, split=gaps == "split", min_samples=int(min_samples), format=format,
                    reader_options=ropts, temperature=temperature)


def _interval_option(dt_s, rate_hz):
    dt = None if dt_s is None else units.check_dt_s(dt_s, "dt_s")
    fs = None if rate_hz is None else units.check_rate_hz(rate_hz, "{opt:rate_hz}")
    if dt is not None and fs is not None and abs(dt * fs - 1.0) > 1e-6:
        raise ConfigError(
            f"dt_s and rate_hz disagree; expected dt_s = 1/rate_hz, got dt_s={dt_s!r}, rate_hz={rate_hz!r}"
        )
    if dt is not None:
        return dt
    return None if fs is None else 1.0 / fs


# --------------------------------------------------------------------------------------------
# Loading
# --------------------------------------------------------------------------------------------
def _open(path, opts: _Options) -> Table:
    p = check_path(path, allow_dir=True)
    ropts = dict(opts.reader_options)
    spec = reader_by_name(opts.format) if opts.format else (_implied_reader(ropts) or select_reader(p))
    if "delimiter" in ropts and "delimiter" not in spec.options:
        del ropts["delimiter"]  # the top-level text option is ignored for other formats
    if isinstance(opts.temperature, str) and "temperature" in spec.options:
        ropts["temperature"] = opts.temperature.strip()  # the reader brings it onto the rate times
    return spec.open_table(p, ropts)


def _implied_reader(ropts: dict):
    """The format that cannot be detected from the file and is the only one to accept every given option, or None.

    Raw binary has no magic bytes, extension or content to recognise it by: giving its ``layout``
    chooses it, whatever the file's name.  Detectable formats are always detected (a wrong option
    for them stays an "unknown reader option" error).
    """
    from .registry import READERS

    given = set(ropts) - {"delimiter"}
    if not given:
        return None
    fits = [r for r in READERS if given <= set(r.options)]
    if len(fits) == 1 and not (fits[0].magic or fits[0].sniff or fits[0].directory_marker or fits[0].extensions):
        return fits[0]
    return None


def _load_records(path, opts: _Options) -> list[GyroRecord]:
    table = _open(path, opts)
    p = table.path
    t_idx, r_idx, table_time, tm_idx = _resolve_columns(table, opts.columns, opts.time_column, opts.temperature)
    if t_idx is None and not table_time and opts.dt_s is None:
        if table.time_ticks is not None:
            raise ConfigError(
                f"{p}: the sequence counter counts samples, not seconds; pass the sample rate in Hz as {{opt:rate_hz}}"
            )
        raise ConfigError(
            f"{p}: cannot tell the sample interval: no time column (none named {' / '.join(TIME_COLUMN_NAMES)}; "
            "name one with {opt:time_column}) and no sample rate given; pass the sample rate in Hz as {opt:rate_hz}"
        )
    notes = []
    specs, unit_source = _rate_unit(table, r_idx, opts.unit, notes)
    unit = _unit_text(table, r_idx, specs)
    t_scale, time_unit = _time_scale(table, t_idx, opts.time_unit, notes)
    temp_offset = _temperature_offset(table, tm_idx, notes)

    # values: finite in every used column
    used = [j for j in [t_idx, *r_idx, tm_idx] if j is not None]
    data = table.read(used)
    n = data.shape[0]
    if n == 0:
        if table.header_line:
            raise DataFormatError(
                f"no data rows after the header on line {table.header_line}; expected at least one "
                "numeric row, got only the header", path=p,
            )
        raise DataFormatError("no data; expected at least one sample, got an empty table", path=p)
    bad = first_nonfinite(data, used)
    if bad is not None:
        i, j = bad
        raise table.error(
            f"non-finite value{table.at(i)}; expected a finite number, got {float(data[i, j])!r}", row=i, col=j
        )

    # sample interval and segments
    notes.insert(0, table.describe(n))
    notes[1:1] = list(table.extra_notes)
    t = _time_vector(table, data, t_idx, table_time, t_scale, opts.dt_s)
    if t is not None:
        if t_idx is not None:
            tname = f"time column {table.names[t_idx]!r}"
        else:
            tname = "the file's time stamps" if table_time else "the sequence counter"
        if n < 2 and opts.dt_s is None:
            raise InsufficientDataError(
                f"{n} sample; expected at least 2 to take the sample interval from {tname}", needed=2, got=n, path=p,
            )
        t_col = t_idx if t_idx is not None or table_time else table.tick_column
        dt, seg_bounds, gap_info = check_time(table, t, t_col, opts.dt_s, opts.split)
        if opts.dt_s is None:
            notes.insert(1, f"sample interval {dt:.10g} s from the median step of {tname}")
        else:
            notes.insert(1, f"sample interval {dt:.10g} s as given ({tname} agrees within 1 %)")
    else:
        dt, seg_bounds, gap_info = opts.dt_s, [(0, n)], []
        notes.insert(1, f"dt_s {dt:.10g} from dt_s/rate_hz (no time column)")
    if opts.dt_s is not None:
        dt_source = "rate option"
    elif t_idx is not None:
        dt_source = "time column"
    else:
        dt_source = "time stamps"
    sampling = Sampling(dt_s=dt, dt_source=dt_source, time_column=None if t_idx is None else table.names[t_idx],
                        time_unit=time_unit,
                        time_unit_source=None if time_unit is None else ("option" if opts.time_unit else "header"))
    scales = [sp.scale_to_internal(dt) for sp in specs]
    if len({(sp.text, sc) for sp, sc in zip(specs, scales)}) == 1:
        if scales[0] != 1.0:
            notes.append(f"input unit {unit!r} scaled by {scales[0]:.10g} to {specs[0].internal_unit}")
    else:
        for j, sp, sc in zip(r_idx, specs, scales):
            notes.append(f"input unit {sp.text!r} of {table.names[j]} scaled by {sc:.10g} to {sp.internal_unit}")
    signal = SignalDescription(sampling, tuple(
        Channel(name=table.names[j], unit=sp, unit_source=unit_source, declared_unit=table.units[j],
                scale_to_internal=sc) for j, sp, sc in zip(r_idx, specs, scales)))
    scale = scales[0] if len(set(scales)) == 1 else np.asarray(scales, dtype=np.float64)
    temp = None if tm_idx is None else (tm_idx, temp_offset)
    return _records(table, data, t, r_idx, dt, seg_bounds, gap_info, unit, scale, notes, opts.min_samples, temp,
                    signal)


def _records(table, data, t, r_idx, dt, seg_bounds, gap_info, unit, scale, notes, min_samples, temp=None,
             signal=None):
    p = table.path
    n = data.shape[0]
    m = len(seg_bounds)
    if m == 1 and n < min_samples:
        raise InsufficientDataError(
            f"{n} samples; expected at least {min_samples}", needed=min_samples, got=n, path=p
        )
    names = tuple(table.names[j] for j in r_idx)
    declared = tuple(table.units[j] for j in r_idx)
    sha256 = table.sha256
    if sha256 is None and p.is_file():
        sha256 = file_sha256(p)  # only for a reader that did not hash what it read
    records, dropped = [], []
    for k, (a, b) in enumerate(seg_bounds, start=1):
        seg_notes = list(notes)
        if m > 1:
            where = f"samples {a}-{b - 1}"
            if table.line_of(a) is not None:
                where += f" (lines {table.line_of(a)}-{table.line_of(b - 1)})"
            if k > 1:
                where += f", after a gap of {gap_info[k - 2]:.6g} s"
            seg_notes.append(f"segment {k} of {m}: {where}")
            if b - a < min_samples:
                dropped.append(f"segment {k} ({where}, {b - a} samples)")
                continue
        raw = take_columns(data[a:b], r_idx)
        rate = to_dph(raw, scale)
        if np.any(np.asarray(scale) != 1.0):
            bad = first_nonfinite(rate)
            if bad is not None:
                i, j = bad
                raise table.error(
                    f"value{table.at(a + i)} overflows in deg/h; expected |value| * {scale:.6g} below "
                    f"{np.finfo(np.float64).max:.3g}, got {float(raw[i, j])!r} {unit}", row=a + i, col=r_idx[j],
                )
        temp_c = None
        if temp is not None:
            temp_c = np.asarray(data[a:b, temp[0]], dtype=np.float64)
            temp_c = temp_c + temp[1] if temp[1] else temp_c.copy()
        records.append(GyroRecord(
            data_internal=rate, dt_s=dt, axis_names=names, source=str(p), input_unit=unit,
            scale_to_internal=float(scale) if np.ndim(scale) == 0 else 1.0,
            t0_s=float(t[a]) if t is not None else 0.0, notes=tuple(seg_notes), sha256=sha256,
            declared_units=declared, temperature_c=temp_c, signal=signal,
        ))
    if dropped:
        if not records:
            longest = max(b - a for a, b in seg_bounds)
            raise InsufficientDataError(
                f"all {m} gap-free segments are shorter than {min_samples} samples; longest has {longest}",
                needed=min_samples, got=longest, path=p,
            )
        warnings.warn(
            f"{p}: dropped {len(dropped)} segment(s) shorter than {min_samples} samples: " + "; ".join(dropped),
            FogdriftWarning, stacklevel=4,
        )
    return records


# --------------------------------------------------------------------------------------------
# Columns and units
# --------------------------------------------------------------------------------------------
def _resolve_columns(table: Table, columns, time_column, temperature=None):
    """(time column index or None, rate column indices, use the table's own time vector, temperature index or None)."""
    names = table.names
    ncol = len(names)

    def resolve(key, option):
        if isinstance(key, (int, np.integer)) and not isinstance(key, bool):
            if -ncol <= int(key) < ncol:
                return int(key) % ncol
        elif isinstance(key, str):
            for k in dict.fromkeys((key.strip(), split_unit_label(key)[0])):
                hits = [j for j, a in enumerate(names) if a == k]
                if not hits and k.isdigit() and int(k) < ncol:
                    return int(k)
                if not hits:
                    hits = [j for j, a in enumerate(names) if a.lower() == k.lower()]
                if len(hits) == 1:
                    return hits[0]
                if len(hits) > 1:
                    raise DataFormatError(
                        f"column name {key!r} is ambiguous; expected a unique name or an index, "
                        f"got columns {hits}", path=table.path, column=key,
                    )
        raise DataFormatError(
            f"unknown column {key!r}; expected one of {names} or an index 0..{ncol - 1} "
            f"in {{opt:{option}}}, got {key!r}", path=table.path, column=key,
        )

    table_time = False
    if time_column is None:
        t_idx = None
    elif isinstance(time_column, str) and time_column.strip().lower() == "auto":
        t_idx = None
        if table.time_s is not None:
            table_time = True
        elif table.named:
            t_idx = next((j for j, a in enumerate(names) if _is_time_name(a)), None)
    else:
        t_idx = resolve(time_column, "time_column")

    tm_idx = None if temperature is None else resolve(
        temperature.strip() if isinstance(temperature, str) else temperature, "temperature")
    if tm_idx is not None and tm_idx == t_idx:
        raise ConfigError(f"column {names[tm_idx]!r} is the time column; expected another column for "
                          "{opt:temperature}")
    if columns is None:
        r_idx = [j for j in range(ncol) if j not in (t_idx, tm_idx) and names[j] not in table.non_rate]
    else:
        r_idx = [resolve(k, "columns") for k in split_keys(columns, "columns")]
        if len(set(r_idx)) != len(r_idx):
            raise ConfigError(f"the same column is selected twice; expected distinct columns, got {columns!r}")
        if t_idx is not None and t_idx in r_idx:
            raise ConfigError(
                f"column {names[t_idx]!r} is the time column; expected rate columns only, got {columns!r} "
                "(to read it as rate data, pass {opt:time_column} none)"
            )
        if tm_idx is not None and tm_idx in r_idx:
            raise ConfigError(f"column {names[tm_idx]!r} is the temperature column; expected rate columns only, "
                              f"got {columns!r}")
    if not r_idx:
        raise DataFormatError(
            f"no rate columns; expected at least one column besides the time column, got {names}",
            path=table.path,
        )
    return t_idx, r_idx, table_time, tm_idx


def _header_error(table: Table, message: str, col: int) -> DataFormatError:
    return DataFormatError(message, path=table.path, line=table.header_line or None, column=table.label(col))


def _rate_unit(table: Table, r_idx, unit, notes: list):
    """([UnitSpec per rate column], "option" or "header"): the given unit, else the declared ones; never a guess.

    ``unit`` is the option already parsed by :func:`fogdrift.io.channel_quantity.parse_unit_choice` (or None); a
    declared unit is parsed here, once, for any quantity.  Each channel's quantity is its unit's, checked against
    what its name says (:mod:`fogdrift.io.channel_quantity`: an accelerometer-named channel in an angular-rate unit,
    or the reverse, is refused in one line).
    """
    declared = {j: table.units[j] for j in r_idx}
    if unit is None and table.unit_hint and set(declared.values()) == {None}:
        raise ConfigError(f"{table.path}: {table.unit_hint} ({', '.join(valid_units())}; units are never guessed)")
    if unit is not None:
        specs = [unit.for_channel(table.names[j], str(table.path)) for j in r_idx]
        other = {table.names[j]: declared[j] for j, sp in zip(r_idx, specs)
                 if declared[j] is not None and declared[j].strip() != sp.text}
        if other:
            notes.append(f"the file declares {other}; unit {unit.text!r} given takes precedence")
        return specs, "option"
    kinds = set(declared.values())
    if kinds == {None}:
        cols = [table.names[j] for j in r_idx]
        raise ConfigError(
            f"{table.path}: no rate unit: the file declares none for {', '.join(cols)}; pass {{opt:unit}} "
            f"({', '.join(valid_units())}; accelerometers: {', '.join(units.valid_units('specific_force'))}; both: "
            f"gyro=deg/s,accel=g), or declare it in the header as {cols[0]}[deg/s] (units are never guessed)"
        )
    listing = {table.names[j]: u for j, u in declared.items()}
    different = ("rate columns declare different units; expected one unit for all rate columns (choose them "
                 f"with {{opt:columns}} or pass {{opt:unit}}), got {listing}")
    missing = next((j for j in r_idx if declared[j] is None), None)
    if missing is not None:
        raise _header_error(table, different, missing)
    specs, first_of = [], {}
    for j in r_idx:
        try:
            spec = channel_unit(declared[j].strip(), None)
        except ConfigError:
            raise _header_error(
                table, f"unknown unit {declared[j]!r} {_SAID(table.format, 'declared by the file')}; expected one "
                       f"of {valid_units()} (or pass {{opt:unit}}), got {declared[j]!r}", j,
            ) from None
        check_name(table.names[j], spec, f"the unit {declared[j]!r} {_SAID(table.format, 'declared by the file')}",
                   str(table.path))
        # one unit per quantity: a gyro+accelerometer log may declare gx[deg/s] and ax[g], not gx[deg/s], gy[rad/s]
        if first_of.setdefault(spec.quantity, spec.text) != spec.text:
            raise _header_error(table, different, j)
        specs.append(spec)
    if len(kinds) == 1:
        notes.append(f"unit {declared[r_idx[0]]!r} declared in the file")
    else:
        notes.append(f"units {', '.join(f'{table.names[j]}[{declared[j]}]' for j in r_idx)} declared in the file")
    return specs, "header"


def _unit_text(table: Table, r_idx, specs) -> str:
    """The record's ``input_unit``: the one unit, or ``name=unit,...`` when the channels differ."""
    texts = [sp.text for sp in specs]
    if len(set(texts)) == 1:
        return texts[0]
    return ",".join(f"{table.names[j]}={t}" for j, t in zip(r_idx, texts))


def _temperature_offset(table: Table, tm_idx, notes: list) -> float:
    """Offset from the temperature column's declared unit to deg C (no unit declared: deg C)."""
    if tm_idx is None:
        return 0.0
    declared = table.units[tm_idx]
    if declared is None:
        notes.append(f"temperature from column {table.names[tm_idx]!r} in deg C")
        return 0.0
    try:
        offset = units.temperature_offset_to_c(declared)
    except ConfigError:
        raise _header_error(
            table, f"unknown temperature unit {declared!r} declared in the file; expected deg C or K "
                   f"({sorted(units.TEMPERATURE_UNITS)}), got {declared!r}", tm_idx,
        ) from None
    notes.append(f"temperature from column {table.names[tm_idx]!r} ({declared}"
                 + (", converted to deg C)" if offset else ")"))
    return offset


def _is_time_name(name: str) -> bool:
    low = name.strip().lower()
    return low in TIME_COLUMN_NAMES or (time_unit_of_name(low) is not None
                                        and low.rpartition("_")[0] in ("t", "time", "timestamp"))


def time_unit_of_name(name: str) -> str | None:
    """The time unit a column name declares by its suffix (``t_s``, ``time_ms``, ``stamp_us``), else None.

    Examples
    --------
    >>> time_unit_of_name("t_s"), time_unit_of_name("Time_MS"), time_unit_of_name("time"), time_unit_of_name("gz_s2")
    ('s', 'ms', None, None)
    """
    stem, sep, suffix = name.strip().rpartition("_")
    suffix = suffix.lower()
    return suffix if sep and stem and suffix in units.TIME_UNITS else None


def _time_scale(table: Table, t_idx, time_unit, notes: list) -> tuple[float, str | None]:
    """(factor to s, unit) of the time column: the given time_unit, else the declared one; never a guess.

    A column declares its unit in brackets (``t[ms]``) or by a suffix of its name (``t_s``, ``time_ms``).
    Without a time column: ``(1.0, None)``.
    """
    if t_idx is None:
        return 1.0, None
    declared = table.units[t_idx]
    name = table.names[t_idx]
    if time_unit is not None:
        if declared is not None and declared.strip() != time_unit:
            notes.append(f"the file declares time unit {declared!r}; time_unit {time_unit!r} given takes precedence")
        unit = time_unit
    elif declared is not None:
        unit = declared.strip()
        if unit not in units.TIME_UNITS:
            raise _header_error(
                table, f"unknown time unit {unit!r} {_SAID(table.format, 'declared by the file')}; expected one of "
                       f"{list(units.TIME_UNITS)} (or pass {{opt:time_unit}}), got {unit!r}", t_idx,
            )
    elif time_unit_of_name(name) is not None:
        unit = time_unit_of_name(name)
    else:
        raise ConfigError(
            f"{table.path}: time column {name!r} declares no unit; pass {{opt:time_unit}} "
            f"({', '.join(units.TIME_UNITS)}), or name it {name}[s] or {name}_s in the header, or leave it out "
            "with {opt:time_column} none and give the sample rate as {opt:rate_hz} (units are never guessed)"
        )
    notes.append(f"time column {name!r} in {unit}")
    return units.time_scale_to_s(unit), unit


# --------------------------------------------------------------------------------------------
# Time
# --------------------------------------------------------------------------------------------
def _time_vector(table: Table, data, t_idx, table_time: bool, t_scale: float, dt_s=None):
    """Time in s (float64), or None without time (a sequence counter gives ``ticks * dt_s``)."""
    if t_idx is not None:
        t = np.asarray(data[:, t_idx], dtype=np.float64)
        return t if t_scale == 1.0 else t * t_scale
    if not table_time:
        if table.time_ticks is not None and dt_s is not None:
            return np.asarray(table.time_ticks, dtype=np.float64) * dt_s
        return None
    t = np.asarray(table.time_s, dtype=np.float64)
    if t.shape != (data.shape[0],):
        raise DataFormatError(
            f"time vector has shape {t.shape}; expected ({data.shape[0]},), one time per row", path=table.path
        )
    bad = first_nonfinite(t.reshape(-1, 1))
    if bad is not None:
        raise table.error(f"non-finite time{table.at(bad[0])}; expected a finite number, got {float(t[bad[0]])!r}",
                          row=bad[0])
    return t
