"""ROS 1 and ROS 2 bag reader (rosbags, pure Python; extra ``[ros]``): ``sensor_msgs/Imu`` angular velocity and
linear acceleration.

A ROS 1 bag is one ``.bag`` file; a ROS 2 bag is a directory holding ``metadata.yaml`` and its
``.db3`` (SQLite) or ``.mcap`` storage files (a storage file inside such a directory opens the
directory).  Options (CLI ``--topic``, ``--stamp``, ``--temperature``; ``fields``):

``topic``
    The ``sensor_msgs/Imu`` topic.  Default: the only Imu topic of the bag; with none or several
    the error lists the candidates (topic, type, message count).
``stamp``
    ``"header"`` (default): time from each message's ``header.stamp``, checked like a time
    column (strictly increasing, steps matching the rate, gaps reported or split as in CSV);
    ``"receive"``: the time the recorder received the message (the bag's own time stamp), for
    drivers that leave the header stamp unset or stamp in bursts.
``temperature``
    A ``sensor_msgs/Temperature`` topic, interpolated linearly onto the Imu times (held at its
    first/last value outside its span); it becomes a column of that name.
``fields``
    Which channels are analysed when no columns are chosen: ``"gyro"`` (default, what fogdrift
    read before linear acceleration was read: a bag's commands print what they printed),
    ``"accel"`` or ``"both"`` (a six-channel record, each channel with its own quantity).

Columns ``gx, gy, gz`` are ``angular_velocity.x/.y/.z`` and declare rad/s (REP 103/145: an
angular rate); columns ``ax, ay, az`` are ``linear_acceleration.x/.y/.z`` and declare m/s^2 (the
message definition: a specific force).  Every Imu topic has all six, so all six are columns of
the table; ``fields`` only decides the default selection (the others are ``non_rate``), and
choosing columns by name (CLI ``--columns gx,gy,gz,ax,ay,az``) reads any of them whatever
``fields`` is.  No unit option is needed: each channel's quantity follows from its declared
unit (:mod:`fogdrift.io.channel_quantity`).  Time
is relative to the first message; the absolute start (UTC) is in the notes.  The Imu fields
are decoded in bulk from the serialised bytes (fixed offsets after the variable-length
``frame_id``), and the first and last messages are checked against rosbags' own deserialiser.
Rows are messages: errors say "at message 12".  The SHA-256 is of the ``.bag`` file's bytes; for
a ROS 2 directory it is the SHA-256 of its files' names and SHA-256s in sorted order
(:func:`fogdrift.io.hashing.path_sha256`).
"""

from __future__ import annotations

import datetime as _dt
import sqlite3
from pathlib import Path

import numpy as np

from ...errors import ConfigError, DataFormatError
from ..hashing import path_sha256
from .base import PARSER_ERRORS, Table, describe_exception, require

__all__ = ["open_table", "BagTable", "IMU_TYPE", "TEMPERATURE_TYPE", "STAMPS", "FIELDS", "GYRO_COLUMNS",
           "ACCEL_COLUMNS"]

IMU_TYPE = "sensor_msgs/msg/Imu"
TEMPERATURE_TYPE = "sensor_msgs/msg/Temperature"
#: Values of the ``stamp`` option.
STAMPS = ("header", "receive")
#: Values of the ``fields`` option: the channels analysed by default.
FIELDS = ("gyro", "accel", "both")
#: ``angular_velocity.x/.y/.z`` [rad/s] and ``linear_acceleration.x/.y/.z`` [m/s^2] (sensor_msgs/Imu).
GYRO_COLUMNS = ("gx", "gy", "gz")
ACCEL_COLUMNS = ("ax", "ay", "az")


class BagTable(Table):
    """Angular velocity and linear acceleration of one Imu topic; ``time_s`` from the chosen stamps."""

    format = "bag"
    row_kind = "message"

    def __init__(self, path, *, names, units, data, time_s, sha256, what, no_accel=None):
        super().__init__(path, names=names, named=True, units=units, data=data, time_s=time_s, sha256=sha256)
        self.what = what
        #: Index of the first message whose linear_acceleration_covariance[0] is -1 (None: none is).
        self.no_accel = no_accel

    def read(self, used) -> np.ndarray:
        """The numbers; DataFormatError when an accelerometer column is used from a bag that says it has none.

        sensor_msgs/Imu: "If you have no estimate for one of the data elements ... set element 0 of the
        associated covariance matrix to -1"; a gyro-only driver does so for linear_acceleration, whose
        values are then not measurements (often zeros).
        """
        acc = [self.names[j] for j in used if self.names[j] in ACCEL_COLUMNS]
        if acc and self.no_accel is not None:
            raise DataFormatError(
                f"message {self.no_accel} has linear_acceleration_covariance[0] = -1 (sensor_msgs/Imu: the driver "
                f"has no linear acceleration estimate); expected measured values for {', '.join(acc)} (leave them "
                "out: select the gyro channels with {opt:columns} gx,gy,gz)", path=self.path, column=acc[0])
        return self.data

    def describe(self, n_rows: int) -> str:
        return f"{self.what}, {n_rows} messages"


def _errors():
    """Exceptions of rosbags and its storage back ends that mean a bad bag."""
    from rosbags.highlevel import AnyReaderError
    from rosbags.rosbag1 import ReaderError as R1Error
    from rosbags.rosbag2 import ReaderError as R2Error

    return (*PARSER_ERRORS, AnyReaderError, R1Error, R2Error, sqlite3.DatabaseError, AssertionError, IndexError)


def _bag_path(p: Path) -> Path:
    """A storage file inside a ROS 2 bag directory opens the directory."""
    if p.is_file() and p.suffix.lower() in (".db3", ".mcap") and (p.parent / "metadata.yaml").is_file():
        return p.parent
    if p.is_file() and p.suffix.lower() in (".db3", ".mcap"):
        raise DataFormatError(
            "ROS 2 storage file without its bag directory; expected a directory holding metadata.yaml and this "
            "file (pass the directory)", path=p,
        )
    return p


def _topics(connections) -> str:
    seen = {}
    for c in connections:
        key = (c.topic, c.msgtype)
        seen[key] = seen.get(key, 0) + int(getattr(c, "msgcount", 0) or 0)
    return ", ".join(f"{t} ({m}, {n} messages)" for (t, m), n in sorted(seen.items())) or "none"


def _pick_imu(reader, topic, p):
    conns = list(reader.connections)
    if topic is not None:
        chosen = [c for c in conns if c.topic == topic]
        if not chosen:
            raise DataFormatError(f"no topic {topic!r} in the bag; expected one of: {_topics(conns)} "
                                  "(pass {opt:topic})", path=p, column=topic)
        bad = [c for c in chosen if c.msgtype != IMU_TYPE]
        if bad:
            raise DataFormatError(f"topic {topic!r} carries {bad[0].msgtype}; expected {IMU_TYPE}; Imu topics: "
                                  f"{_topics([c for c in conns if c.msgtype == IMU_TYPE])}", path=p, column=topic)
        return topic, chosen
    imu = sorted({c.topic for c in conns if c.msgtype == IMU_TYPE})
    if len(imu) != 1:
        what = "no sensor_msgs/Imu topic" if not imu else f"{len(imu)} sensor_msgs/Imu topics"
        listing = _topics([c for c in conns if c.msgtype == IMU_TYPE] if imu else conns)
        raise DataFormatError(f"{what} in the bag; expected exactly one or {{opt:topic}}, got: {listing}", path=p)
    return imu[0], [c for c in conns if c.topic == imu[0]]


#: Messages decoded at a time (their bytes are joined into one buffer).
_BATCH = 1 << 16


def _decode_imu(raws: list, is_ros2: bool, p: Path, first: int = 0):
    """(stamp ns int64, [angular velocity, linear acceleration] (n, 6) float64, no-accel flags (n,) bool).

    From serialised Imu messages; the flag is ``linear_acceleration_covariance[0] == -1``.

    Vectorised.  ROS 2 (CDR): 4-byte encapsulation header, then stamp (int32 sec, uint32 nanosec),
    frame_id (uint32 length incl. NUL + bytes), padding to 8 (relative to the payload), orientation
    (4 doubles), its covariance (9), angular_velocity (3): ``4 + align8(12 + L) + 104``; then its
    covariance (9 doubles) and linear_acceleration (3) at ``+ 24 + 72``, then that one's covariance.
    ROS 1: seq (uint32), stamp (uint32 secs, uint32 nsecs), frame_id (uint32 length + bytes),
    then the same doubles unaligned: ``16 + L + 104``.  Fixed-size arrays carry no length in
    either encoding, so all 37 doubles are contiguous.
    """
    n = len(raws)
    lengths = np.fromiter((len(r) for r in raws), dtype=np.int64, count=n)
    starts = np.zeros(n, dtype=np.int64)
    np.cumsum(lengths[:-1], out=starts[1:])
    buf = np.frombuffer(b"".join(raws), dtype=np.uint8)
    short = lengths < 16
    if short.any():
        i = int(np.argmax(short))
        raise DataFormatError(f"Imu message {first + i} is truncated; expected at least 16 bytes, got "
                              f"{int(lengths[i])}", path=p)
    if is_ros2:
        enc = buf[starts + 1]
        if np.any(enc != enc[0]) or enc[0] not in (0, 1):
            i = int(np.argmax(enc != enc[0])) if np.any(enc != enc[0]) else 0
            raise DataFormatError(f"Imu message {first + i} has CDR encapsulation {int(enc[i])}; expected plain CDR "
                                  "(0 big- or 1 little-endian) in every message", path=p)
        order = "<" if enc[0] == 1 else ">"
    else:
        order = "<"

    # messages of one length (one frame_id, the usual case): a (n, length) view, sliced by column
    rows = buf.reshape(n, int(lengths[0])) if n and np.all(lengths == lengths[0]) else None

    def gather(offsets, width, dtype):
        rel = offsets - starts
        if rows is not None and np.all(rel == rel[0]):
            block = rows[:, int(rel[0]):int(rel[0]) + width]
        else:
            block = buf[offsets[:, None] + np.arange(width)]
        return np.ascontiguousarray(block).view(np.dtype(dtype).newbyteorder(order)).reshape(n, -1)

    sec = gather(starts + 4, 4, "i4" if is_ros2 else "u4")[:, 0].astype(np.int64)
    nsec = gather(starts + 8, 4, "u4")[:, 0].astype(np.int64)
    flen = gather(starts + 12, 4, "u4")[:, 0].astype(np.int64)
    if is_ros2:
        av_off = 4 + ((12 + flen + 7) // 8) * 8 + 104
        need = av_off - 104 + 296
    else:
        av_off = 16 + flen + 104
        need = av_off - 104 + 296
    short = lengths < need
    if short.any():
        i = int(np.argmax(short))
        raise DataFormatError(
            f"Imu message {first + i} is truncated or not a sensor_msgs/Imu; expected {int(need[i])} bytes for its "
            f"{int(flen[i])}-byte frame_id, got {int(lengths[i])}", path=p,
        )
    av = gather(starts + av_off, 24, "f8").astype(np.float64)
    la = gather(starts + av_off + _LA_AFTER_AV, 24, "f8").astype(np.float64)
    la_cov0 = gather(starts + av_off + _LA_AFTER_AV + 24, 8, "f8")[:, 0]
    return sec * 1_000_000_000 + nsec, np.hstack([av, la]), la_cov0 == -1.0


#: Bytes from angular_velocity to linear_acceleration: the 3 doubles and the 9 of their covariance
#: (linear_acceleration_covariance follows linear_acceleration's 3 doubles).
_LA_AFTER_AV = 8 * (3 + 9)


def _check_against_deserializer(reader, conn, raws: dict, av, stamps, p, no_acc=None):
    """The first and last messages through rosbags' deserialiser must equal the bulk decoding (all six values)."""
    for i in sorted(raws):
        msg = reader.deserialize(raws[i], conn.msgtype)
        w, f = msg.angular_velocity, msg.linear_acceleration
        ref = (w.x, w.y, w.z, f.x, f.y, f.z)
        st = msg.header.stamp
        ns = int(getattr(st, "sec", getattr(st, "secs", 0))) * 1_000_000_000 + int(
            getattr(st, "nanosec", getattr(st, "nsecs", 0)))
        flag = bool(msg.linear_acceleration_covariance[0] == -1.0)
        if not np.array_equal(np.asarray(ref), av[i]) or ns != stamps[i] or (no_acc is not None
                                                                               and flag != bool(no_acc[i])):
            raise DataFormatError(f"Imu message {i} decodes differently in bulk than through rosbags; expected "
                                  f"{ref} at {ns} ns, got {tuple(av[i])} at {int(stamps[i])} ns", path=p)


def _temperature(reader, conns, topic, stamp, p):
    """(stamp ns, deg C) of a sensor_msgs/Temperature topic."""
    chosen = [c for c in conns if c.topic == topic]
    if not chosen:
        raise DataFormatError(f"no temperature topic {topic!r} in the bag; expected one of: {_topics(conns)} "
                              "(fix {opt:temperature})", path=p, column=topic)
    if chosen[0].msgtype != TEMPERATURE_TYPE:
        raise DataFormatError(f"topic {topic!r} carries {chosen[0].msgtype}; expected {TEMPERATURE_TYPE} for "
                              "{opt:temperature}", path=p, column=topic)
    t, v = [], []
    for conn, bag_ns, raw in reader.messages(connections=chosen):
        msg = reader.deserialize(raw, conn.msgtype)
        st = msg.header.stamp
        hdr = int(getattr(st, "sec", getattr(st, "secs", 0))) * 1_000_000_000 + int(
            getattr(st, "nanosec", getattr(st, "nsecs", 0)))
        t.append(hdr if stamp == "header" else int(bag_ns))
        v.append(float(msg.temperature))
    if not t:
        raise DataFormatError(f"temperature topic {topic!r} has no messages; expected at least one", path=p,
                              column=topic)
    order = np.argsort(np.asarray(t), kind="stable")
    return np.asarray(t, dtype=np.int64)[order], np.asarray(v)[order]


def open_table(path: Path, *, topic=None, stamp="header", temperature=None, fields=None) -> Table:
    """Read the angular velocity [rad/s] and linear acceleration [m/s^2] of one Imu topic (see the module docstring).

    Parameters
    ----------
    path : Path
        A ROS 1 ``.bag`` file, a ROS 2 bag directory, or a storage file inside one.
    topic : str, optional
        The ``sensor_msgs/Imu`` topic (default: the only one).
    stamp : {"header", "receive"}
        Time from the messages' header stamps or the recorder's receive time.
    temperature : str, optional
        A ``sensor_msgs/Temperature`` topic [deg C] brought onto the Imu times.
    fields : {"gyro", "accel", "both"}, optional
        The channels selected when no columns are given (default ``"gyro"``: ``gx, gy, gz`` in
        rad/s); the others stay columns of the table, selectable by name.

    Returns
    -------
    BagTable
        Columns ``gx, gy, gz`` [rad/s], ``ax, ay, az`` [m/s^2] (and the temperature topic
        [degC]), time from the chosen stamps [s].

    Raises
    ------
    ConfigError
        ``stamp`` not header/receive, ``fields`` not gyro/accel/both.
    DataFormatError
        Unreadable or corrupt bag (the message locates the message where the bag's own reader
        says), unknown or wrong-type topic, no or several Imu topics without ``topic``, a
        truncated message, header stamps all equal (unset by the driver).
    MissingDependencyError
        rosbags is not installed (``pip install 'fogdrift[ros]'``).
    """
    highlevel = require("rosbags.highlevel", "ros", "reading ROS bags")
    typesys = require("rosbags.typesys", "ros", "reading ROS bags")
    if stamp not in STAMPS:
        raise ConfigError(f"stamp must be one of {STAMPS}; got {stamp!r} in {{opt:stamp}}")
    chosen_fields = "gyro" if fields is None else str(fields).strip().lower()
    if chosen_fields not in FIELDS:
        raise ConfigError(f"fields must be one of {FIELDS} (gyro: angular_velocity, accel: linear_acceleration, "
                          f"both: the six channels); got {fields!r} in {{opt:fields}}")
    p = _bag_path(Path(path))
    errors = _errors()
    raws, bag_ns, n_read = [], [], 0
    try:
        with highlevel.AnyReader([p], default_typestore=typesys.get_typestore(typesys.Stores.ROS2_HUMBLE)) as reader:
            is_ros2 = bool(reader.is2)
            name, conns = _pick_imu(reader, None if topic is None else str(topic).strip(), p)
            parts, first_raw, last_raw = [], None, None
            for _conn, t_ns, raw in reader.messages(connections=conns):
                raws.append(bytes(raw))
                bag_ns.append(t_ns)
                n_read += 1
                if len(raws) == _BATCH:               # decode in batches: memory ~ the output arrays
                    first_raw = raws[0] if first_raw is None else first_raw
                    parts.append(_decode_imu(raws, is_ros2, p, n_read - len(raws)))
                    last_raw, raws = raws[-1], []
            if raws:
                first_raw = raws[0] if first_raw is None else first_raw
                parts.append(_decode_imu(raws, is_ros2, p, n_read - len(raws)))
                last_raw = raws[-1]
            if not parts:
                raise DataFormatError(f"Imu topic {name!r} has no messages; expected at least one", path=p,
                                      column=name)
            stamps = np.concatenate([q[0] for q in parts])
            av = np.concatenate([q[1] for q in parts])
            no_acc = np.concatenate([q[2] for q in parts])
            del parts
            _check_against_deserializer(reader, conns[0], {0: first_raw, n_read - 1: last_raw}, av, stamps, p,
                                        no_acc)
            temp = None
            if temperature is not None:
                temp = _temperature(reader, list(reader.connections), str(temperature).strip(), stamp, p)
    except DataFormatError:
        raise
    except errors as exc:
        if "hash mismatch" in str(exc):  # rosbags compares each connection's definition with the standard type's
            raise DataFormatError(
                f"a message definition in the bag is not the standard one ({describe_exception(exc)}): a "
                "sensor_msgs/Imu defined with other field types (float32 ...) cannot be decoded as the standard "
                "layout; re-record or convert the bag with the standard sensor_msgs/Imu", path=p) from exc
        where = f" after message {n_read - 1}" if n_read else ""
        raise DataFormatError(
            f"unreadable or corrupt bag{where}; expected a ROS 1 bag file or a ROS 2 bag directory, got "
            f"{describe_exception(exc)}", path=p,
        ) from exc
    del raws
    bag_ns = np.asarray(bag_ns, dtype=np.int64)
    if stamp == "header" and stamps.size > 1 and np.all(stamps == stamps[0]):
        raise DataFormatError(
            f"every header stamp of topic {name!r} is {int(stamps[0])} ns; expected increasing stamps (the driver "
            "did not set them: pass {opt:stamp} receive to use the recorder's time)", path=p, column=name,
        )
    ns = stamps if stamp == "header" else bag_ns
    t_s = (ns - ns[0]).astype(np.float64) / 1e9   # correctly rounded: 1990000000 ns -> 1.99 s
    names, units, cols = [*GYRO_COLUMNS, *ACCEL_COLUMNS], ["rad/s"] * 3 + ["m/s^2"] * 3, [av]
    if temp is not None:
        names.append(str(temperature).strip())
        units.append("degC")
        cols.append(np.interp(((ns - ns[0]).astype(np.float64)),
                              (temp[0] - ns[0]).astype(np.float64), temp[1]).reshape(-1, 1))
    what = f"ROS {'2' if is_ros2 else '1'} bag, topic {name!r} (sensor_msgs/Imu, {stamp} stamps)"
    table = BagTable(p, names=names, units=units, data=np.hstack(cols), time_s=t_s, sha256=path_sha256(p),
                     what=what, no_accel=int(np.argmax(no_acc)) if no_acc.any() else None)
    table.non_rate = {"gyro": set(ACCEL_COLUMNS), "accel": set(GYRO_COLUMNS), "both": set()}[chosen_fields]
    sec, frac = divmod(int(ns[0]), 1_000_000_000)
    start = _dt.datetime.fromtimestamp(sec, tz=_dt.timezone.utc).strftime("%Y-%m-%dT%H:%M:%S")
    table.extra_notes = [f"time 0 = first {stamp} stamp {int(ns[0])} ns ({start}.{frac:09d}Z)"]
    if temp is not None:
        table.extra_notes.append(f"temperature topic {str(temperature).strip()!r}: {temp[0].size} messages "
                                 "interpolated linearly onto the Imu times")
    return table
