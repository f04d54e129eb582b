"""Temperature carried with a log: the CSV column into GyroRecord.temperature_c (kept through slice, select,
block averaging and segments), its summary (range, start/end drift, least-squares slope) and the figure.

Independent checks: a linear ramp whose slope and range are known by hand; scipy.stats.linregress for the slope
of a noisy series; block means computed by hand.
"""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal
from scipy.stats import linregress

from fogdrift.errors import ConfigError, DataFormatError
from fogdrift.io import load, load_segments
from fogdrift.temperature import summary_line, temperature_summary
from fogdrift.report.temperature import plot_rate_and_temperature


def _csv(tmp_path, temp, t=None, header="t_s,gx[deg/h],gy[deg/h],temp"):
    n = len(temp)
    t = np.arange(n) * 0.1 if t is None else t
    rows = [f"{t[i]:.1f},{i},{-i},{float(temp[i])!r}" for i in range(n)]
    p = tmp_path / "log.csv"
    p.write_text(header + "\n" + "\n".join(rows) + "\n")
    return p


def test_csv_temperature_column_kept_through_record_operations(tmp_path):
    temp = 20.0 + 0.01 * np.arange(100)
    p = _csv(tmp_path, temp)
    rec = load(p, temperature="temp")
    assert rec.axis_names == ("gx", "gy")                 # not a rate column
    assert_array_equal(rec.temperature_c, temp)
    assert not rec.temperature_c.flags.writeable
    assert_array_equal(rec.slice(10, 20).temperature_c, temp[10:20])
    assert_array_equal(rec.select("gy").temperature_c, temp)
    assert_allclose(rec.to_rate(2.5).temperature_c, temp[:100].reshape(25, 4).mean(axis=1))
    assert rec.to_rate(2.5).metadata()["temperature"]["n_samples"] == 25
    plain = load(p, columns="gx,gy")
    assert plain.temperature_c is None and plain.metadata()["temperature"] is None
    with pytest.raises(ConfigError, match=r"column 'temp' is the temperature column"):
        load(p, temperature="temp", columns="gx,temp")
    with pytest.raises(DataFormatError, match=r"unknown column 'tmp'.*in temperature="):
        load(p, temperature="tmp")


def test_declared_kelvin_is_converted_and_other_units_refused(tmp_path):
    p = _csv(tmp_path, 300.0 + np.zeros(10), header="t_s,gx[deg/h],gy[deg/h],temp[K]")
    assert_allclose(load(p, temperature="temp").temperature_c, 26.85)
    p = _csv(tmp_path, np.zeros(10), header="t_s,gx[deg/h],gy[deg/h],temp[degF]")
    with pytest.raises(DataFormatError, match=r"log\.csv:1:temp: unknown temperature unit 'degF'"):
        load(p, temperature="temp")


def test_nan_temperature_is_located_and_segments_carry_their_part(tmp_path):
    temp = np.arange(10.0)
    temp[4] = np.nan
    with pytest.raises(DataFormatError, match=r"log\.csv:6:temp: non-finite value"):
        load(_csv(tmp_path, temp), temperature="temp")
    t = np.r_[np.arange(5) * 0.1, 2.0 + np.arange(5) * 0.1]
    segs = load_segments(_csv(tmp_path, np.arange(10.0), t=t), temperature="temp")
    assert [s.temperature_c.tolist() for s in segs] == [[0, 1, 2, 3, 4], [5, 6, 7, 8, 9]]


def test_summary_against_linregress_and_by_hand():
    rng = np.random.default_rng(5)
    n, dt = 36_000, 1.0                                  # 10 h at 1 Hz
    x = 25.0 + 0.3 * np.arange(n) / 3600.0 + rng.normal(scale=0.05, size=n)
    s = temperature_summary(x, dt)
    assert s.slope_c_per_h == pytest.approx(linregress(np.arange(n) * dt / 3600.0, x).slope, rel=1e-10)
    assert s.range_c == pytest.approx(x.max() - x.min())
    assert s.start_c == pytest.approx(x[:360].mean()) and s.end_c == pytest.approx(x[-360:].mean())
    assert s.change_c == pytest.approx(0.3 * (n - 360) / 3600.0, abs=0.01)   # edge means 9.9 h apart
    assert "deg C" in summary_line(s) and "over 10 h" in summary_line(s)
    with pytest.raises(ConfigError):
        temperature_summary([], 1.0)


def test_plot_rate_and_temperature(tmp_path):
    temp = 20.0 + 0.01 * np.arange(100)
    rec = load(_csv(tmp_path, temp), temperature="temp")
    png = plot_rate_and_temperature(rec, tmp_path / "t.png")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 5_000
    with pytest.raises(ConfigError, match=r"carries no temperature; load it with temperature="):
        plot_rate_and_temperature(load(_csv(tmp_path, temp), columns="gx,gy"), tmp_path / "u.png")
