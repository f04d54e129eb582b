"""Raw binary reader: records written by NumPy (``ndarray.tofile`` of a structured array), the layout
string, scale factors, increments, the wrapping sequence counter and its gaps, located errors, temperature.

Independent checks: the integers the test wrote times the scale factor by hand; 1 arcsec per second = 1 deg/h.
"""

from __future__ import annotations

import hashlib
import warnings

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from fogdrift.errors import ConfigError, DataFormatError, FogdriftWarning
from fogdrift.io import load, load_segments
from fogdrift.io.readers.binary import parse_layout

LAYOUT = "<u2 seq, <i4 gx, <i4 gy, <i4 gz, <i2 temp"


def _records(n, start=0, rng=None):
    rng = rng or np.random.default_rng(7)
    r = np.zeros(n, dtype=parse_layout(LAYOUT))
    r["seq"] = (start + np.arange(n)) % 65536
    for k in ("gx", "gy", "gz"):
        r[k] = rng.integers(-1000, 1000, size=n)
    r["temp"] = 2500 + np.arange(n) // 100      # 0.01 deg C steps
    return r


def test_binary_memmap_scale_increments_and_temperature(tmp_path):
    r = _records(70_000, start=65_000)          # the u2 counter wraps once
    p = tmp_path / "log.bin"
    p.write_bytes(b"HDR0" * 4 + r.tobytes())
    rec = load(p, rate_hz=100.0, unit="inc:arcsec", temperature="temp",
               reader_options={"layout": LAYOUT, "header_bytes": 16,
                               "scale": "gx=1e-3, gy=1e-3, gz=1e-3, temp=0.01"})
    assert rec.axis_names == ("gx", "gy", "gz")               # the counter is not a rate column
    # 1e-3 arcsec per 10 ms record = 0.1 arcsec/s = 0.1 deg/h per count
    assert_allclose(rec.rate_dph, np.column_stack([r["gx"], r["gy"], r["gz"]]) * 0.1, rtol=1e-13)
    assert_allclose(rec.temperature_c, r["temp"] * 0.01, rtol=1e-15)
    assert rec.sha256 == hashlib.sha256(p.read_bytes()).hexdigest()
    assert "raw binary, 70000 records of 16 bytes after a 16-byte header, sequence counter 'seq'" in rec.notes[0]


def test_layout_option_implies_the_binary_format(tmp_path):
    r = _records(100)
    p = tmp_path / "log.dat"                     # .dat would be text
    r.tofile(p)
    rec = load(p, rate_hz=10.0, unit="deg/s", reader_options={"layout": LAYOUT, "scale": 0.5},
               temperature="temp")
    assert_allclose(rec.rate_dph[:, 0], r["gx"] * 0.5 * 3600.0)
    assert_allclose(rec.temperature_c, r["temp"] * 0.5)


def test_sequence_gap_error_and_split(tmp_path):
    r = np.concatenate([_records(300), _records(200, start=305)])   # records 300..304 lost
    p = tmp_path / "gap.bin"
    r.tofile(p)
    opts = {"layout": LAYOUT}
    with pytest.raises(DataFormatError, match=r"gap\.bin:seq: gap in time at record 300 \(byte 4800\) of 0\.06 s "
                                              r"\(6 sample intervals\)"):
        load(p, rate_hz=100.0, unit="deg/s", reader_options=opts)
    segs = load_segments(p, rate_hz=100.0, unit="deg/s", reader_options=opts)
    assert [s.n_samples for s in segs] == [300, 200]
    assert segs[1].t0_s == pytest.approx(3.05)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FogdriftWarning)
        assert load(p, rate_hz=100.0, unit="deg/s", gaps="split", reader_options=opts).n_samples == 300
    # no counter: the same bytes load as one block
    assert load(p, rate_hz=100.0, unit="deg/s", reader_options={**opts, "sequence": "none"}).n_samples == 500


@pytest.mark.parametrize("second, word", [(299, "repeats"), (10, "goes backwards")])
def test_sequence_repeat_and_backwards_are_located(tmp_path, second, word):
    r = np.concatenate([_records(300), _records(10, start=second)])
    p = tmp_path / "bad.bin"
    r.tofile(p)
    with pytest.raises(DataFormatError, match=rf"bad\.bin:seq: sequence counter {word} at record 300 \(byte 4800\)"):
        load(p, rate_hz=100.0, unit="deg/s", reader_options={"layout": LAYOUT})


def test_truncated_file_and_bad_options(tmp_path):
    p = tmp_path / "cut.bin"
    p.write_bytes(_records(10).tobytes()[:-5])
    with pytest.raises(DataFormatError, match=r"cut\.bin: trailing partial record at byte 144 \(record 9\); expected "
                                              r"the 0-byte header plus whole 16-byte records, got 11 extra bytes"):
        load(p, rate_hz=1.0, unit="deg/s", reader_options={"layout": LAYOUT})
    _records(10).tofile(p)
    with pytest.raises(ConfigError, match=r"raw binary declares no unit; pass unit="):
        load(p, rate_hz=1.0, reader_options={"layout": LAYOUT})
    with pytest.raises(ConfigError, match=r"layout item 'gx' is not 'TYPE NAME'"):
        load(p, rate_hz=1.0, unit="deg/s", reader_options={"layout": "<u2 seq, gx"})
    with pytest.raises(ConfigError, match=r"unknown NumPy dtype '<q9'"):
        load(p, rate_hz=1.0, unit="deg/s", reader_options={"layout": "<q9 gx"})
    with pytest.raises(ConfigError, match=r"scale names field 'gw', not in the layout"):
        load(p, rate_hz=1.0, unit="deg/s", reader_options={"layout": LAYOUT, "scale": "gw=2"})
    with pytest.raises(ConfigError, match=r"the sequence counter counts samples, not seconds; pass the sample rate"):
        load(p, unit="deg/s", reader_options={"layout": LAYOUT})
    with pytest.raises(ConfigError, match=r"raw binary needs its record layout"):
        load(p, rate_hz=1.0, unit="deg/s", format="binary")


def test_float_time_field_is_a_time_column(tmp_path):
    r = np.zeros(50, dtype=[("t", "<f8"), ("gz", "<f4")])
    r["t"] = 10 + np.arange(50) * 0.25
    r["gz"] = np.arange(50)
    p = tmp_path / "t.raw"
    r.tofile(p)
    rec = load(p, unit="deg/h", time_unit="s", reader_options={"layout": "<f8 t, <f4 gz"})
    assert rec.dt_s == 0.25 and rec.t0_s == 10.0
    assert_array_equal(rec.rate_dph[:, 0], np.arange(50))
