"""ROS bags: sensor_msgs/Imu ``linear_acceleration`` read with ``angular_velocity``.

A six-channel record (gx, gy, gz [rad/s] -> angular_rate; ax, ay, az [m/s^2] -> specific_force), each channel
with the unit its message definition declares, so no unit option is needed; the default selection stays the
gyro (what a bag gave before); the ``fields`` reader option and ``columns`` choose the accelerometer.

Independent references: the values the test serialised (read back exactly in m/s^2, the internal unit of
specific force); 1 rad/s = 180/pi * 3600 deg/h by hand; a white noise of sigma per sample at interval dt has
N = sigma sqrt(dt) (IEEE 952 / 1293), i.e. VRW = 60 sigma sqrt(dt) m/s/sqrt(h) and ARW = sigma sqrt(dt) / 60
deg/sqrt(h) for sigma in deg/h.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from fogdrift.errors import ConfigError, DataFormatError
from fogdrift.io import load

pytest.importorskip("rosbags")
sys.path.insert(0, str(Path(__file__).parent))
from test_io_rosbag import T0_NS, write_bag  # noqa: E402

import fogdrift.io.readers.rosbag as rosbag_reader  # noqa: E402
from fogdrift.io import registry  # noqa: E402

RAD = 180.0 / math.pi * 3600.0
SIX = ("gx", "gy", "gz", "ax", "ay", "az")


def _values(n, seed=7):
    """Angular velocity [rad/s] and linear acceleration [m/s^2], every axis distinguishable from the others."""
    rng = np.random.default_rng(seed)
    w = rng.normal(scale=1e-3, size=(n, 3)) + np.array([1e-2, -2e-2, 3e-2])
    a = rng.normal(scale=2e-3, size=(n, 3)) + np.array([0.31, -0.17, 9.79])
    return w, a


def _bag(tmp_path, ros, storage=None, n=400, name="six", **kw):
    from rosbags.rosbag2 import StoragePlugin

    w, a = _values(n)
    stamps = T0_NS + np.arange(n, dtype=np.int64) * 5_000_000          # 200 Hz
    path = tmp_path / (f"{name}.bag" if ros == 1 else name)
    plugin = {"sqlite3": StoragePlugin.SQLITE3, "mcap": StoragePlugin.MCAP, None: None}[storage]
    write_bag(path, ros, w, stamps, a=a, storage=plugin, **kw)
    return path, w, a


@pytest.mark.parametrize("varied", [True, False], ids=["frame_id-varies", "one-frame_id"])
@pytest.mark.parametrize("ros, storage", [(1, None), (2, "sqlite3"), (2, "mcap")])
def test_six_channels_read_back_with_their_quantities(tmp_path, ros, storage, varied, monkeypatch):
    """Both bulk paths: messages of one length (a strided view) and of varying length (every CDR alignment)."""
    monkeypatch.setattr(rosbag_reader, "_BATCH", 64)           # several decoding batches
    frames = ["imu" + "x" * (i % 9) for i in range(400)] if varied else None
    path, w, a = _bag(tmp_path, ros, storage, frames=frames)
    rec = load(path, columns=list(SIX))                          # no unit given: each channel declares its own
    assert rec.axis_names == SIX
    assert rec.quantities == ("angular_rate",) * 3 + ("specific_force",) * 3
    assert rec.declared_units == ("rad/s",) * 3 + ("m/s^2",) * 3
    assert_array_equal(rec.data_internal[:, 3:], a)                   # m/s^2 is the internal unit: exactly the values
    assert_allclose(rec.data_internal[:, :3], w * RAD, rtol=1e-15)
    assert rec.dt_s == 0.005
    # the default selection is the gyro, as before linear acceleration was read
    gyro = load(path)
    assert gyro.axis_names == SIX[:3] and gyro.quantities == ("angular_rate",) * 3
    assert_array_equal(gyro.rate_dph, rec.data_internal[:, :3])
    acc = load(path, columns="az,ax")
    assert acc.axis_names == ("az", "ax") and acc.quantities == ("specific_force",) * 2
    assert_array_equal(acc.data_internal, a[:, [2, 0]])


@pytest.mark.parametrize("fields, names", [("gyro", SIX[:3]), ("accel", SIX[3:]), ("both", SIX), (" Both ", SIX)])
def test_fields_option_decides_the_default_selection(tmp_path, fields, names):
    path, w, a = _bag(tmp_path, 2)
    rec = load(path, reader_options={"fields": fields})
    assert rec.axis_names == names
    got = dict(zip(rec.axis_names, rec.data_internal.T))
    for k, name in enumerate(SIX):
        if name in got:
            assert_array_equal(got[name], a[:, k - 3] if k >= 3 else w[:, k] * RAD)
    # columns still choose any channel, whatever the default selection
    assert load(path, reader_options={"fields": fields}, columns="gy,ay").axis_names == ("gy", "ay")


def test_fields_option_refuses_other_values(tmp_path):
    path, _, _ = _bag(tmp_path, 1, n=20)
    with pytest.raises(ConfigError, match=r"fields must be one of \('gyro', 'accel', 'both'\).*got 'accels'"):
        rosbag_reader.open_table(path, fields="accels")
    table = rosbag_reader.open_table(path, fields="accel")
    assert table.names[:6] == list(SIX) and table.units[:6] == ["rad/s"] * 3 + ["m/s^2"] * 3
    assert table.non_rate == {"gx", "gy", "gz"}


@pytest.mark.parametrize("offset", [8 * 3, 8 * 11, 8 * 13, 8 * 15], ids=["no-cov", "short", "long", "cov-field"])
def test_a_wrong_linear_acceleration_offset_is_caught(tmp_path, monkeypatch, offset):
    """One-line bugs in the bulk decoding (the covariance forgotten, off by one double, the covariance read
    instead of the field) disagree with rosbags' own deserialiser on the first message: a located error."""
    path, _, _ = _bag(tmp_path, 1, n=50)
    monkeypatch.setattr(rosbag_reader, "_LA_AFTER_AV", offset)
    with pytest.raises(DataFormatError, match=r"Imu message 0 decodes differently in bulk than through rosbags"):
        load(path)


def test_swapped_axes_are_caught(tmp_path, monkeypatch):
    """ax/ay swapped (or gz/ax: a wrong field) in the bulk decoding: caught by the deserialiser check."""
    path, _, _ = _bag(tmp_path, 2, n=50)
    real = rosbag_reader._decode_imu
    for perm in ([0, 1, 2, 4, 3, 5], [0, 1, 3, 2, 4, 5]):
        def swapped(*args, _perm=perm, **kw):
            stamps, vals, no_acc = real(*args, **kw)
            return stamps, vals[:, _perm], no_acc

        monkeypatch.setattr(rosbag_reader, "_decode_imu", swapped)
        with pytest.raises(DataFormatError, match=r"decodes differently in bulk"):
            load(path, columns=list(SIX))


def test_driver_without_linear_acceleration_is_refused_only_when_used(tmp_path):
    """sensor_msgs/Imu: covariance[0] = -1 means no estimate; the gyro channels read, the accelerometer's refuse."""
    from rosbags.rosbag1 import Writer as Writer1
    from rosbags.typesys import Stores, get_typestore

    import test_io_rosbag as base

    ts = get_typestore(Stores.ROS1_NOETIC)
    path = tmp_path / "gyro_only.bag"
    w, _ = _values(40)
    with Writer1(path) as writer:
        c = writer.add_connection("/imu", "sensor_msgs/msg/Imu", typestore=ts)
        for i in range(40):
            msg = base._imu(ts, i, w[i], T0_NS + i * 10_000_000, a=(0.0, 0.0, 0.0))
            if i >= 3:
                msg.linear_acceleration_covariance[0] = -1.0
            writer.write(c, T0_NS + i * 10_000_000, ts.serialize_ros1(msg, "sensor_msgs/msg/Imu"))
    assert_allclose(load(path).rate_dph, w * RAD, rtol=1e-15)
    with pytest.raises(DataFormatError, match=r"gyro_only\.bag:ax: message 3 has linear_acceleration_covariance\[0\] "
                                              r"= -1 .*expected measured values for ax, az"):
        load(path, columns="gx,ax,az")


def _ok(result):
    assert result.exit_code == 0, result.output + repr(result.exception)
    return result.output


def _long_bag(tmp_path, sw=1e-4, sa=2e-3, n=6000):
    """60 s at 100 Hz: white noise of sw rad/s and sa m/s^2 per sample, gravity on z."""
    rng = np.random.default_rng(11)
    w = rng.normal(scale=sw, size=(n, 3))
    a = np.array([0.05, -0.1, 9.80665]) + rng.normal(scale=sa, size=(n, 3))
    path = tmp_path / "imu.bag"
    write_bag(path, 1, w, T0_NS + np.arange(n, dtype=np.int64) * 10_000_000, a=a)
    return path


def test_cli_allan_prints_gyro_and_accelerometer_tables_without_unit(tmp_path):
    from typer.testing import CliRunner

    from fogdrift.cli import app

    runner = CliRunner()
    path = _long_bag(tmp_path)
    out = _ok(runner.invoke(app, ["allan", str(path), "--columns", ",".join(SIX), "--out", str(tmp_path / "o")],
                            env={"COLUMNS": "220"}))
    assert "N [deg/√h]" in out and "N [m/s/√h]" in out and "B [µg]" in out
    assert "ax=m/s^2" in out and "gx=rad/s" in out
    doc = json.loads((tmp_path / "o" / "allan.json").read_text())
    assert [x["name"] for x in doc["axes"]] == list(SIX)
    n_gyro = 1e-4 * RAD * math.sqrt(0.01) / 60.0          # deg/sqrt(h): 0.0344
    n_acc = 60.0 * 2e-3 * math.sqrt(0.01)                  # m/s/sqrt(h): 0.012
    for ax in doc["axes"]:
        term = ax["noise"]["terms"]["N"]
        acc = ax["name"].startswith("a")
        assert term["unit"] == ("m/s/sqrt(h)" if acc else "deg/sqrt(h)")
        assert term["value"] == pytest.approx(n_acc if acc else n_gyro, rel=0.1)
    # the default is the gyro alone (what the command printed for a bag before)
    out = _ok(runner.invoke(app, ["allan", str(path), "--out", str(tmp_path / "g")], env={"COLUMNS": "220"}))
    assert "N [deg/√h]" in out and "m/s/√h" not in out


def test_cli_fields_flag(tmp_path):
    from typer.testing import CliRunner

    from fogdrift.cli import app
    from fogdrift.cli._app import FLAGS

    assert {"rosbag1", "rosbag2"} <= {s.name for s in registry.READERS if "fields" in s.options}
    assert FLAGS["fields"] == "--fields"                               # one table row, no CLI edit
    path = _long_bag(tmp_path)
    out = _ok(CliRunner().invoke(app, ["allan", str(path), "--fields", "both", "--out", str(tmp_path / "o")],
                                 env={"COLUMNS": "220"}))
    assert "N [deg/√h]" in out and "N [m/s/√h]" in out
    assert "(declared by the message definition)" in out and "in the header" not in out
    out = _ok(CliRunner().invoke(app, ["allan", str(path), "--fields", "accel", "--out", str(tmp_path / "a")],
                                 env={"COLUMNS": "220"}))
    assert "N [m/s/√h]" in out and "deg/√h" not in out
    bad = CliRunner().invoke(app, ["allan", str(path), "--fields", "accels", "--out", str(tmp_path / "b")],
                             env={"COLUMNS": "220"})
    assert bad.exit_code == 1 and "Traceback" not in bad.output
    assert "fields must be one of" in bad.output and "got 'accels' in --fields" in " ".join(bad.output.split())


def test_cli_analyze_refuses_accelerometer_channels_and_says_how_to_leave_them_out(tmp_path):
    from typer.testing import CliRunner

    from fogdrift.cli import app

    path = _long_bag(tmp_path, n=3000)
    result = CliRunner().invoke(app, ["analyze", str(path), "--columns", "gz,ax,ay", "--out", str(tmp_path / "o")],
                                env={"COLUMNS": "220"})
    assert result.exit_code == 1
    text = " ".join(result.output.split())
    assert "ax, ay are accelerometer channels" in text and "--columns" in text
    assert "Traceback" not in result.output


def test_cli_export_kalibr_from_a_six_channel_bag(tmp_path):
    """What allan_variance_ros does, from the bag directly: Kalibr's noise densities are sigma sqrt(dt) in SI
    (white noise of sigma per sample at dt = 0.01 s: 1e-5 rad/s/sqrt(Hz) and 2e-4 m/s^2/sqrt(Hz))."""
    yaml = pytest.importorskip("yaml")
    from typer.testing import CliRunner

    from fogdrift.cli import app

    path = _long_bag(tmp_path)
    _ok(CliRunner().invoke(app, ["export", str(path), "--columns", ",".join(SIX), "--target", "kalibr",
                                 "--out", str(tmp_path / "x")], env={"COLUMNS": "220"}))
    doc = yaml.safe_load((tmp_path / "x" / "imu.yaml").read_text())
    assert doc["gyroscope_noise_density"] == pytest.approx(1e-4 * math.sqrt(0.01), rel=0.1)
    assert doc["accelerometer_noise_density"] == pytest.approx(2e-3 * math.sqrt(0.01), rel=0.1)
    assert doc["update_rate"] == pytest.approx(100.0)
