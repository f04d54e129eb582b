"""miniSEED reader (ObsPy, extra ``[seismo]``): channels as axes, e.g. a rotational seismometer's HJZ/HJN/HJE.

Every channel (SEED id ``NET.STA.LOC.CHA``) of the file is a column, named by its channel code
(``HJZ``), or by the full id when two stations share a code.  All rate channels must have one
sample rate and cover the same times (the same samples per contiguous segment, starts within
half a sample); segments of a channel are joined in time order, so a gap between records is a
gap in the time vector (an error naming the sample, or split with ``gaps``), an overlap is time
going backwards.  Time is relative to the first sample; the absolute start (UTC) is in the notes.

Gain (``gain`` option, CLI ``--gain``): miniSEED data records carry numbers, not physical units.

* a number: counts per unit (the sensitivity); values are divided by it and are then in the
  ``unit`` you give;
* a response file that ObsPy reads (StationXML, dataless SEED, RESP): the sensitivity and input
  unit of each channel at the start time come from it (RAD/S, NRAD/S, DEG/S ... are converted to
  rad/s or deg/s and declared, so no ``unit`` is needed); this is "the gain from the file".

Without a gain, integer data (counts: STEIM1/2, INT16/32) are refused, and float data are taken
as they are, in the ``unit`` you must give (blueSeis-type FOG seismometers record rad/s).

``temperature``: a channel code or id holding deg C, interpolated linearly onto the rate times
when its rate differs; it is scaled by its own response when a response file is given, never by
a numeric gain.  A corrupt record (bad Steim frame) or a trailing partial record is an error
naming the channel or byte offset.  The SHA-256 is of the file's bytes.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from ...errors import ConfigError, DataFormatError
from ..hashing import file_sha256
from .base import PARSER_ERRORS, Table, describe_exception, require

__all__ = ["open_table", "MSeedTable", "RESPONSE_UNITS", "looks_like_mseed"]

#: Response input units (upper case) -> (declared unit, factor to it).
RESPONSE_UNITS = {
    "RAD/S": ("rad/s", 1.0), "RAD/SEC": ("rad/s", 1.0), "RADIAN/S": ("rad/s", 1.0), "RADIANS/S": ("rad/s", 1.0),
    "MRAD/S": ("rad/s", 1e-3), "URAD/S": ("rad/s", 1e-6), "NRAD/S": ("rad/s", 1e-9),
    "DEG/S": ("deg/s", 1.0), "DEG/SEC": ("deg/s", 1.0), "DEG/H": ("deg/h", 1.0),
    "C": ("degC", 1.0), "DEGC": ("degC", 1.0), "CELSIUS": ("degC", 1.0), "K": ("K", 1.0),
}
_INTEGER_ENCODINGS = ("STEIM1", "STEIM2", "INT16", "INT24", "INT32", "ASCII")


def looks_like_mseed(head: bytes) -> bool:
    """miniSEED 2 fixed header: 6 sequence digits (or spaces), a quality code D/R/Q/M, a space or NUL.

    Examples
    --------
    >>> looks_like_mseed(b"000001D " + bytes(40)), looks_like_mseed(b"t,gx,gy\\n" + bytes(40))
    (True, False)
    """
    return (len(head) >= 48 and all(c in b"0123456789 " for c in head[:6]) and head[6:7] in (b"D", b"R", b"Q", b"M")
            and head[7:8] in (b" ", b"\x00"))


class MSeedTable(Table):
    """Channels of a miniSEED file; ``time_s`` from the record start times and the sample rate."""

    format = "mseed"

    def __init__(self, path, *, names, units, data, time_s, sha256, what):
        super().__init__(path, names=names, named=True, units=units, data=data, time_s=time_s, sha256=sha256)
        self.what = what

    def describe(self, n_rows: int) -> str:
        return f"{self.what}, {n_rows} samples"


def _gain_source(gain):
    """("number", value), ("file", path) or None."""
    if gain is None:
        return None
    if isinstance(gain, (int, float, np.integer, np.floating)) and not isinstance(gain, bool):
        value = float(gain)
    else:
        text = str(gain).strip()
        try:
            value = float(text)
        except ValueError:
            if not Path(text).is_file():
                raise ConfigError(f"gain must be counts per unit (a number) or a response file (StationXML, "
                                  f"dataless SEED, RESP); got {gain!r}, which is neither, in {{opt:gain}}") from None
            return ("file", Path(text))
    if not (np.isfinite(value) and value != 0):
        raise ConfigError(f"gain must be a finite non-zero number of counts per unit; got {gain!r} in {{opt:gain}}")
    return ("number", value)


def _segments(traces):
    """A channel's traces (contiguous segments) in time order."""
    return sorted(traces, key=lambda tr: tr.stats.starttime)


def _response(inv, seed_id, start, p):
    try:
        resp = inv.get_response(seed_id, start)
        sens = resp.instrument_sensitivity
        value, unit = float(sens.value), str(sens.input_units or "").strip().upper()
    except Exception as exc:  # noqa: BLE001 -- ObsPy raises plain Exception for a missing channel
        raise DataFormatError(f"no response for channel {seed_id} at {start} in the gain file; expected one, got "
                              f"{describe_exception(exc)}", path=p, column=seed_id) from exc
    if unit not in RESPONSE_UNITS:
        raise DataFormatError(f"response of {seed_id} has input unit {unit!r}; expected one of "
                              f"{sorted(RESPONSE_UNITS)}", path=p, column=seed_id)
    declared, factor = RESPONSE_UNITS[unit]
    return value, declared, factor


def open_table(path: Path, *, gain=None, temperature=None) -> Table:
    """Read every channel of a miniSEED file (see the module docstring).

    Raises
    ------
    ConfigError
        Invalid ``gain``; integer counts without a gain.
    DataFormatError
        Unreadable or corrupt records, a trailing partial record, channels with different
        rates or not covering the same times, an unknown temperature channel, a response file
        without the channel.
    MissingDependencyError
        ObsPy is not installed (``pip install 'fogdrift[seismo]'``).
    """
    obspy = require("obspy", "seismo", "reading miniSEED files")
    p = Path(path)
    gsrc = _gain_source(gain)
    try:
        from obspy.io.mseed import InternalMSEEDWarning

        with warnings.catch_warnings():
            warnings.simplefilter("error", InternalMSEEDWarning)   # ObsPy warns and skips broken records: refuse
            stream = obspy.read(str(p), format="MSEED")
    except Exception as exc:  # noqa: BLE001 -- ObsPy raises its own, ValueError, TypeError, warnings
        text = describe_exception(exc)
        sid = next((w for w in text.replace(":", " ").split() if w.count("_") >= 4), None)
        raise DataFormatError(
            f"unreadable or corrupt miniSEED; expected valid data records, got {text}", path=p,
            column=sid.rsplit("_", 1)[0].replace("_", ".") if sid else None,   # NET_STA_LOC_CHA_Q -> NET.STA.LOC.CHA
        ) from exc
    size = p.stat().st_size
    used_bytes = sum(int(tr.stats.mseed.number_of_records) * int(tr.stats.mseed.record_length) for tr in stream)
    if used_bytes != size:
        raise DataFormatError(
            f"{size - used_bytes} bytes at byte {used_bytes} are not whole miniSEED records; expected records of "
            f"{stream[0].stats.mseed.record_length if len(stream) else 512} bytes to fill the file (truncated?)",
            path=p,
        )
    by_id = {}
    for tr in stream:
        by_id.setdefault(tr.id, []).append(tr)
    if not by_id:
        raise DataFormatError("no data records; expected at least one channel", path=p)
    codes = [sid.split(".")[-1] for sid in by_id]
    names = {sid: (sid.split(".")[-1] if codes.count(sid.split(".")[-1]) == 1 else sid) for sid in by_id}
    temp_id = None
    if temperature is not None:
        key = str(temperature).strip()
        temp_id = next((sid for sid in by_id if key in (sid, names[sid])), None)
        if temp_id is None:
            raise DataFormatError(f"no channel {key!r} for {{opt:temperature}}; expected one of "
                                  f"{[names[s] for s in by_id]}", path=p, column=key)
    rate_ids = [sid for sid in by_id if sid != temp_id]
    if not rate_ids:
        raise DataFormatError("no rate channel besides the temperature channel; expected at least one", path=p)
    rates = {sid: float(by_id[sid][0].stats.sampling_rate) for sid in rate_ids}
    for sid in rate_ids:
        for tr in by_id[sid]:
            if abs(tr.stats.sampling_rate - rates[rate_ids[0]]) > 1e-9 * rates[rate_ids[0]]:
                listing = {names[s]: float(by_id[s][0].stats.sampling_rate) for s in rate_ids}
                raise DataFormatError(f"channels have different sample rates; expected one rate for all rate "
                                      f"channels (choose the temperature channel with {{opt:temperature}}), got "
                                      f"{listing} Hz", path=p, column=names[sid])
    fs = rates[rate_ids[0]]
    t_ref = min(by_id[sid][0].stats.starttime for sid in rate_ids)
    for sid in by_id:
        by_id[sid] = _segments(by_id[sid])

    def times(sid):
        return np.concatenate([(tr.stats.starttime - t_ref) + np.arange(tr.stats.npts) / tr.stats.sampling_rate
                               for tr in by_id[sid]])

    first = rate_ids[0]
    t_s = times(first)
    notes = [f"time 0 = {t_ref.isoformat()} (first sample, UTC); {fs:g} Hz"]
    inv = None
    if gsrc is not None and gsrc[0] == "file":
        try:
            inv = obspy.read_inventory(str(gsrc[1]))
        except Exception as exc:  # noqa: BLE001
            raise DataFormatError(f"unreadable response file; expected StationXML, dataless SEED or RESP, got "
                                  f"{describe_exception(exc)}", path=gsrc[1]) from exc
    cols, units = [], []
    for sid in rate_ids:
        segs = by_id[sid]
        if [tr.stats.npts for tr in segs] != [tr.stats.npts for tr in by_id[first]] or any(
                abs((a.stats.starttime - b.stats.starttime) * fs) > 0.5 for a, b in zip(segs, by_id[first])):
            raise DataFormatError(
                f"channel {names[sid]} covers other times than {names[first]}; expected the same samples per "
                f"segment, got {[(str(tr.stats.starttime), tr.stats.npts) for tr in segs]} against "
                f"{[(str(tr.stats.starttime), tr.stats.npts) for tr in by_id[first]]}", path=p, column=names[sid],
            )
        values, unit = _scaled(sid, segs, gsrc, inv, p, names[sid], notes)
        cols.append(values)
        units.append(unit)
    out_names = [names[s] for s in rate_ids]
    if temp_id is not None:
        values, unit = _scaled(temp_id, by_id[temp_id], None if gsrc and gsrc[0] == "number" else gsrc, inv, p,
                               names[temp_id], notes, temperature=True)
        values = np.interp(t_s, times(temp_id), values)
        cols.append(values)
        units.append(unit or "degC")
        out_names.append(names[temp_id])
        notes.append(f"temperature channel {names[temp_id]} interpolated onto the {fs:g} Hz times")
    what = f"miniSEED, channels {', '.join(out_names)}"
    table = MSeedTable(p, names=out_names, units=units, data=np.column_stack(cols), time_s=t_s,
                       sha256=file_sha256(p), what=what)
    table.extra_notes = notes
    if not any(units[: len(rate_ids)]):
        table.unit_hint = ("miniSEED carries no physical unit; pass {opt:unit} for the numbers (rad/s for a blueSeis-"
                           "type rotational sensor) or a response file as {opt:gain}")
    return table


def _scaled(sid, segs, gsrc, inv, p, name, notes, temperature=False):
    raw = np.concatenate([np.asarray(tr.data) for tr in segs])
    enc = str(segs[0].stats.mseed.get("encoding", "")).upper()
    if gsrc is None:
        if enc in _INTEGER_ENCODINGS and not temperature:
            raise ConfigError(f"{p}: channel {name} holds integer counts ({enc}); pass {{opt:gain}} as counts per "
                              "unit or a response file (StationXML, dataless SEED, RESP)")
        return raw.astype(np.float64), None
    if gsrc[0] == "number":
        notes.append(f"{name}: divided by gain {gsrc[1]:g} counts per unit")
        return raw.astype(np.float64) / gsrc[1], None
    value, declared, factor = _response(inv, sid, segs[0].stats.starttime, p)
    notes.append(f"{name}: sensitivity {value:g} counts per {declared if factor == 1 else f'{factor:g} {declared}'} "
                 "from the response file")
    return raw.astype(np.float64) * (factor / value), declared
