"""ROS 1 and ROS 2 bag reader: bags written by rosbags' own writers (rosbag1.Writer, rosbag2.Writer with
sqlite3 and mcap storage), the bulk decoding against the written values, topic choice, header vs receive
stamps, gaps, a temperature topic, and corrupt bags.

Independent checks: the values and stamps the test serialised; 1 rad/s = 180/pi * 3600 deg/h by hand.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from fogdrift.errors import DataFormatError
from fogdrift.io import load, load_segments

rosbags = pytest.importorskip("rosbags")
from rosbags.rosbag1 import Writer as Writer1  # noqa: E402
from rosbags.rosbag2 import StoragePlugin, Writer as Writer2  # noqa: E402
from rosbags.typesys import Stores, get_typestore  # noqa: E402

RAD = 180.0 / math.pi * 3600.0
T0_NS = 1_700_000_000_123_456_789


def _imu(ts, i, w, stamp_ns, frame="imu_link", a=(0.0, 0.0, 9.81)):
    T = ts.types
    stamp = T["builtin_interfaces/msg/Time"](sec=stamp_ns // 10**9, nanosec=stamp_ns % 10**9)
    kw = {"stamp": stamp, "frame_id": frame}
    if "seq" in T["std_msgs/msg/Header"].__dataclass_fields__:
        kw["seq"] = i
    V = T["geometry_msgs/msg/Vector3"]
    return T["sensor_msgs/msg/Imu"](
        header=T["std_msgs/msg/Header"](**kw), orientation=T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
        orientation_covariance=np.zeros(9), angular_velocity=V(x=w[0], y=w[1], z=w[2]),
        angular_velocity_covariance=np.full(9, 0.5), linear_acceleration=V(x=a[0], y=a[1], z=a[2]),
        linear_acceleration_covariance=np.full(9, 0.25))


def _temp(ts, i, stamp_ns, value):
    T = ts.types
    kw = {"stamp": T["builtin_interfaces/msg/Time"](sec=stamp_ns // 10**9, nanosec=stamp_ns % 10**9),
          "frame_id": "imu_link"}
    if "seq" in T["std_msgs/msg/Header"].__dataclass_fields__:
        kw["seq"] = i
    return T["sensor_msgs/msg/Temperature"](header=T["std_msgs/msg/Header"](**kw), temperature=value, variance=0.0)


def write_bag(path, ros, w, stamps_ns, *, receive_ns=None, frames=None, extra_imu=False, temps=None,
              storage=None, a=None):
    """A bag with /imu/data (and optionally a second Imu topic and /imu/temperature).

    ``w``: angular velocity [rad/s] per message; ``a``: linear acceleration [m/s^2] per message (default
    (0, 0, 9.81) in every message)."""
    if ros == 1:
        ts = get_typestore(Stores.ROS1_NOETIC)
        writer, ser = Writer1(path), ts.serialize_ros1
    else:
        ts = get_typestore(Stores.ROS2_HUMBLE)
        writer = Writer2(path, version=9, storage_plugin=storage or StoragePlugin.SQLITE3)
        ser = ts.serialize_cdr
    receive_ns = stamps_ns if receive_ns is None else receive_ns
    with writer:
        c = writer.add_connection("/imu/data", "sensor_msgs/msg/Imu", typestore=ts)
        c2 = writer.add_connection("/imu/raw", "sensor_msgs/msg/Imu", typestore=ts) if extra_imu else None
        ct = writer.add_connection("/imu/temperature", "sensor_msgs/msg/Temperature", typestore=ts) if temps else None
        events = [(int(receive_ns[i]), 0, i) for i in range(len(w))]
        if temps:
            events += [(int(t), 1, k) for k, (t, _) in enumerate(temps)]
        for t, kind, i in sorted(events):
            if kind == 1:
                writer.write(ct, t, ser(_temp(ts, i, temps[i][0], temps[i][1]), "sensor_msgs/msg/Temperature"))
                continue
            frame = frames[i] if frames else "imu_link"
            acc = (0.0, 0.0, 9.81) if a is None else tuple(float(v) for v in a[i])
            raw = ser(_imu(ts, i, w[i], int(stamps_ns[i]), frame, acc), "sensor_msgs/msg/Imu")
            writer.write(c, t, raw)
            if c2 is not None:
                writer.write(c2, t, raw)


@pytest.fixture
def rng():
    return np.random.default_rng(2024)


@pytest.mark.parametrize("ros, storage", [(1, None), (2, "sqlite3"), (2, "mcap")])
def test_bag_values_stamps_and_units(tmp_path, rng, ros, storage, monkeypatch):
    import fogdrift.io.readers.rosbag as rosbag_reader

    monkeypatch.setattr(rosbag_reader, "_BATCH", 64)           # several decoding batches
    n = 400
    w = rng.normal(scale=1e-3, size=(n, 3))
    stamps = T0_NS + np.arange(n, dtype=np.int64) * 5_000_000          # 200 Hz
    frames = ["imu" + "x" * (i % 9) for i in range(n)]                   # every CDR alignment of frame_id
    path = tmp_path / ("a.bag" if ros == 1 else "a")
    plugin = {"sqlite3": StoragePlugin.SQLITE3, "mcap": StoragePlugin.MCAP, None: None}[storage]
    write_bag(path, ros, w, stamps, frames=frames, storage=plugin)
    rec = load(path)
    assert rec.axis_names == ("gx", "gy", "gz") and rec.input_unit == "rad/s"
    assert rec.dt_s == 0.005 and rec.t0_s == 0.0
    assert_allclose(rec.rate_dph, w * RAD, rtol=1e-15)
    assert rec.declared_units == ("rad/s",) * 3
    assert any("1700000000123456789 ns (2023-11-14T22:13:20.123456789Z)" in s for s in rec.notes)
    assert rec.sha256 and len(rec.sha256) == 64
    if ros == 2:   # a storage file inside the directory opens the bag
        storage_file = next(p for p in path.iterdir() if p.suffix in (".db3", ".mcap"))
        assert_allclose(load(storage_file).rate_dph, rec.rate_dph)


def test_topic_choice_and_listing(tmp_path, rng):
    w = rng.normal(size=(50, 3))
    stamps = T0_NS + np.arange(50, dtype=np.int64) * 10_000_000
    path = tmp_path / "two.bag"
    write_bag(path, 1, w, stamps, extra_imu=True)
    with pytest.raises(DataFormatError, match=r"two\.bag: 2 sensor_msgs/Imu topics in the bag; expected exactly one "
                                              r"or topic=, got: /imu/data \(sensor_msgs/msg/Imu, 50 messages\), "
                                              r"/imu/raw \(sensor_msgs/msg/Imu, 50 messages\)"):
        load(path)
    assert load(path, reader_options={"topic": "/imu/raw"}).n_samples == 50
    with pytest.raises(DataFormatError, match=r"two\.bag:/nope: no topic '/nope' in the bag"):
        load(path, reader_options={"topic": "/nope"})


def test_header_gap_is_reported_and_split_and_receive_time_option(tmp_path, rng):
    n = 300
    w = rng.normal(size=(n, 3))
    stamps = T0_NS + np.arange(n, dtype=np.int64) * 10_000_000
    stamps[200:] += 50_000_000                                          # 5 lost messages at 100 Hz
    receive = T0_NS + 3_000_000 + np.arange(n, dtype=np.int64) * 10_000_000
    path = tmp_path / "gap.bag"
    write_bag(path, 1, w, stamps, receive_ns=receive)
    with pytest.raises(DataFormatError, match=r"gap\.bag: gap in time at message 200 of 0\.06 s \(6 sample "
                                              r"intervals\) between t=1\.99 s and t=2\.05 s"):
        load(path)
    segs = load_segments(path)
    assert [s.n_samples for s in segs] == [200, 100] and segs[1].t0_s == pytest.approx(2.05)
    rec = load(path, reader_options={"stamp": "receive"})                 # the recorder saw no gap
    assert rec.n_samples == n and rec.dt_s == 0.01


def test_unset_header_stamps_point_to_receive_time(tmp_path, rng):
    n = 20
    path = tmp_path / "zero.bag"
    write_bag(path, 1, rng.normal(size=(n, 3)), np.zeros(n, dtype=np.int64),
              receive_ns=T0_NS + np.arange(n, dtype=np.int64) * 10_000_000)
    with pytest.raises(DataFormatError, match=r"zero\.bag:/imu/data: every header stamp of topic '/imu/data' is 0 ns"
                                              r".*pass stamp= receive"):
        load(path)


def test_temperature_topic_is_interpolated(tmp_path, rng):
    n = 1000
    stamps = T0_NS + np.arange(n, dtype=np.int64) * 10_000_000          # 10 s at 100 Hz
    temps = [(T0_NS + k * 1_000_000_000, 20.0 + 0.5 * k) for k in range(11)]   # 1 Hz, +0.5 deg C/s
    path = tmp_path / "temp"
    write_bag(path, 2, rng.normal(size=(n, 3)), stamps, temps=temps)
    rec = load(path, temperature="/imu/temperature")
    assert rec.axis_names == ("gx", "gy", "gz")
    assert_allclose(rec.temperature_c, 20.0 + 0.5 * np.arange(n) * 0.01, rtol=0, atol=1e-12)
    assert rec.metadata()["temperature"]["slope_c_per_h"] == pytest.approx(1800.0)
    with pytest.raises(DataFormatError, match=r"topic '/imu/data' carries sensor_msgs/msg/Imu; expected "
                                              r"sensor_msgs/msg/Temperature"):
        load(path, temperature="/imu/data")


def test_corrupt_bags_are_located_errors(tmp_path, rng):
    n = 200
    w = rng.normal(size=(n, 3))
    stamps = T0_NS + np.arange(n, dtype=np.int64) * 10_000_000
    path = tmp_path / "ok.bag"
    write_bag(path, 1, w, stamps)
    raw = path.read_bytes()
    (tmp_path / "cut.bag").write_bytes(raw[: len(raw) // 2])
    with pytest.raises(DataFormatError, match=r"cut\.bag: unreadable or corrupt bag"):
        load(tmp_path / "cut.bag")
    d = tmp_path / "ros2"
    write_bag(d, 2, w, stamps)
    db = next(d.glob("*.db3"))
    db.write_bytes(db.read_bytes()[:4096] + b"\x00" * 4096)
    with pytest.raises(DataFormatError, match=r"ros2: unreadable or corrupt bag"):
        load(d)


def test_a_ros1_imu_defined_with_float32_is_one_line_naming_the_definition(tmp_path):
    """A ROS 1 bag whose sensor_msgs/Imu definition uses float32 vectors (its own md5sum in the connection
    header): rosbags refuses the definition's hash, and the reader says so in one line that names the definition,
    never decoding the float32 bytes as the standard float64 layout (issue 36)."""
    import hashlib
    import struct

    ts = get_typestore(Stores.ROS1_NOETIC)
    msgdef, _ = ts.generate_msgdef("sensor_msgs/msg/Imu")
    msgdef32 = msgdef.replace("float64 x\nfloat64 y\nfloat64 z", "float32 x\nfloat32 y\nfloat32 z")
    assert msgdef32 != msgdef
    path = tmp_path / "imu32.bag"
    with Writer1(path) as writer:
        c = writer.add_connection("/imu/data", "sensor_msgs/msg/Imu", msgdef=msgdef32,
                                  md5sum=hashlib.md5(msgdef32.encode()).hexdigest())
        for i in range(200):
            t = T0_NS + i * 10_000_000
            head = struct.pack("<IIII", i, t // 10**9, t % 10**9, 3) + b"imu"
            body = struct.pack("<13d", 0, 0, 0, 1, *[0.0] * 9)
            body += struct.pack("<3f", 0.01, 0.02, 0.03) + struct.pack("<9d", *[0.5] * 9)
            body += struct.pack("<3f", 0.0, 0.0, 9.81) + struct.pack("<9d", *[0.25] * 9)
            writer.write(c, t, head + body)
    with pytest.raises(DataFormatError) as info:
        load(path, unit="rad/s")
    text = str(info.value)
    assert "imu32.bag" in text and "not the standard one" in text and "float32" in text and "\n" not in text
