"""miniSEED reader: files written by ObsPy (STEIM2 counts and FLOAT32 rad/s), channels as axes, gain as a
number and from a StationXML response written by ObsPy, gaps between records, a temperature channel at its
own rate, and corrupt records.

Independent checks: the samples the test wrote divided by the gain by hand; 1 rad/s = 180/pi * 3600 deg/h.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from fogdrift.errors import ConfigError, DataFormatError
from fogdrift.io import load, load_segments

obspy = pytest.importorskip("obspy")
from obspy import Stream, Trace, UTCDateTime  # noqa: E402

RAD = 180.0 / math.pi * 3600.0
T0 = UTCDateTime(2024, 3, 1, 12, 0, 0)


def _trace(data, ch, fs=100.0, start=T0):
    tr = Trace(np.ascontiguousarray(data))
    tr.stats.update(dict(network="XX", station="ROT", location="", channel=ch, sampling_rate=fs, starttime=start))
    return tr


@pytest.fixture
def rng():
    return np.random.default_rng(99)


def test_counts_with_numeric_gain_and_channels_as_axes(tmp_path, rng):
    counts = {ch: rng.integers(-50_000, 50_000, size=3000).astype(np.int32) for ch in ("HJZ", "HJN", "HJE")}
    p = tmp_path / "rot.mseed"
    Stream([_trace(v, ch) for ch, v in counts.items()]).write(p, format="MSEED", encoding="STEIM2", reclen=512)
    with pytest.raises(ConfigError, match=r"rot\.mseed: channel HJZ holds integer counts \(STEIM2\); pass gain="):
        load(p)
    rec = load(p, unit="rad/s", reader_options={"gain": 1e9})          # 1e9 counts per rad/s
    assert rec.axis_names == ("HJZ", "HJN", "HJE") and rec.dt_s == 0.01
    assert_allclose(rec.rate_dph[:, 1], counts["HJN"] / 1e9 * RAD, rtol=1e-14)
    assert any("2024-03-01T12:00:00" in s for s in rec.notes)
    with pytest.raises(ConfigError, match=r"miniSEED carries no physical unit; pass unit="):
        load(p, reader_options={"gain": 1e9})


def test_float_data_and_gain_from_a_stationxml_response(tmp_path, rng):
    from obspy.core.inventory import Channel, Inventory, Network, Response, Station
    from obspy.core.inventory.response import InstrumentSensitivity

    counts = rng.integers(-1000, 1000, size=2000).astype(np.int32)
    p = tmp_path / "z.mseed"
    Stream([_trace(counts, "HJZ", fs=50.0)]).write(p, format="MSEED", encoding="STEIM2")
    sens = InstrumentSensitivity(value=2.0e3, frequency=1.0, input_units="NRAD/S", output_units="COUNTS")
    cha = Channel("HJZ", "", 0.0, 0.0, 0.0, 0.0, sample_rate=50.0, response=Response(instrument_sensitivity=sens),
                  start_date=UTCDateTime(2020, 1, 1))
    inv = Inventory([Network("XX", [Station("ROT", 0.0, 0.0, 0.0, channels=[cha])])], source="test")
    xml = tmp_path / "resp.xml"
    inv.write(str(xml), format="STATIONXML")
    rec = load(p, reader_options={"gain": str(xml)})                     # unit from the response: rad/s
    assert rec.input_unit == "rad/s"
    assert_allclose(rec.rate_dph[:, 0], counts / 2.0e3 * 1e-9 * RAD, rtol=1e-14)

    f = tmp_path / "f.mseed"
    x = rng.normal(scale=1e-6, size=1000).astype(np.float32)
    Stream([_trace(x, "HJ1", fs=200.0)]).write(f, format="MSEED", encoding="FLOAT32")
    rec = load(f, unit="rad/s")
    assert rec.dt_s == 0.005
    assert_allclose(rec.rate_dph[:, 0], x.astype(np.float64) * RAD, rtol=1e-15)


def test_gap_between_records_as_for_csv(tmp_path, rng):
    a = rng.normal(size=1000).astype(np.float32)
    b = rng.normal(size=500).astype(np.float32)
    p = tmp_path / "gap.mseed"
    Stream([_trace(a, "HJZ"), _trace(b, "HJZ", start=T0 + 10.5)]).write(p, format="MSEED", encoding="FLOAT32")
    with pytest.raises(DataFormatError, match=r"gap\.mseed: gap in time at sample 1000 of 0\.51 s \(51 sample "
                                              r"intervals\)"):
        load(p, unit="rad/s")
    segs = load_segments(p, unit="rad/s")
    assert [s.n_samples for s in segs] == [1000, 500] and segs[1].t0_s == pytest.approx(10.5)


def test_temperature_channel_at_its_own_rate(tmp_path, rng):
    x = rng.normal(size=(1000, 2)).astype(np.float32)
    temp = (25.0 + 0.1 * np.arange(11)).astype(np.float32)            # 1 Hz over the 10 s at 100 Hz
    p = tmp_path / "t.mseed"
    Stream([_trace(x[:, 0], "HJZ"), _trace(x[:, 1], "HJN"), _trace(temp, "LKO", fs=1.0)]).write(
        p, format="MSEED", encoding="FLOAT32")
    with pytest.raises(DataFormatError, match=r"channels have different sample rates"):
        load(p, unit="rad/s")
    rec = load(p, unit="rad/s", temperature="LKO")
    assert rec.axis_names == ("HJZ", "HJN")
    assert_allclose(rec.temperature_c, 25.0 + 0.1 * np.arange(1000) * 0.01, atol=1e-5)


def test_corrupt_and_truncated_records_are_located(tmp_path, rng):
    counts = rng.integers(-50_000, 50_000, size=3000).astype(np.int32)
    p = tmp_path / "ok.mseed"
    Stream([_trace(counts, "HJZ")]).write(p, format="MSEED", encoding="STEIM2", reclen=512)
    raw = bytearray(p.read_bytes())
    bad = raw.copy()
    bad[600:700] = b"\xff" * 100
    (tmp_path / "bad.mseed").write_bytes(bytes(bad))
    with pytest.raises(DataFormatError, match=r"bad\.mseed:XX\.ROT\.\.HJZ: unreadable or corrupt miniSEED"):
        load(tmp_path / "bad.mseed", unit="rad/s", reader_options={"gain": 1.0})
    (tmp_path / "cut.mseed").write_bytes(bytes(raw[:1000]))
    with pytest.raises(DataFormatError, match=r"cut\.mseed: 488 bytes at byte 512 are not whole miniSEED records"):
        load(tmp_path / "cut.mseed", unit="rad/s", reader_options={"gain": 1.0})
