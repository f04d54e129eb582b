"""The modelling-rate rule: records reach a model rate only by integer block averaging.

Independent checks: the valid rates are native/k written out by hand or enumerated over k;
block means are NumPy reshape-means; messages are compared in full.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from fogdrift.errors import ConfigError, InsufficientDataError
from fogdrift.io import decimation_factor, from_array


@pytest.mark.parametrize("dt_s, rate_hz, m", [
    (0.01, 100.0, 1), (0.01, 50.0, 2), (0.01, 3.125, 32), (0.01, 1.0, 100), (0.01, 0.01, 10_000),
    (1 / 400, 3.125, 128), (1 / 400, 400.0, 1), (0.005, 200 / 3, 3), (1 / 3, 3.0, 1), (1 / 3, 0.3, 10),
])
def test_valid_rates(dt_s, rate_hz, m):
    assert decimation_factor(dt_s, rate_hz) == m


@pytest.mark.parametrize("native_hz", [100.0, 400.0, 1000.0, 200 / 3, 2000.0, 0.5])
def test_every_integer_division_is_accepted(native_hz):
    # native / k computed in floating point must come back as k exactly (1e-9 tolerance absorbs rounding)
    for k in range(1, 2001):
        assert decimation_factor(1.0 / native_hz, native_hz / k) == k


def test_tolerance_is_1e_9_relative():
    assert decimation_factor(0.01, 3.125 * (1 + 1e-12)) == 32
    with pytest.raises(ConfigError, match="does not divide"):
        decimation_factor(0.01, 3.125 * (1 + 1e-7))


def test_message_names_nearest_rates_above_and_below():
    with pytest.raises(ConfigError) as ei:
        decimation_factor(0.01, 3.0)
    assert str(ei.value) == ("model rate 3 Hz does not divide the native 100 Hz by an integer; nearest valid rates: "
                             "3.03 Hz (/33), 2.941 Hz (/34); pass model_rate_hz=")
    assert ei.value.render({"model_rate_hz": "--model-rate"}).endswith("2.941 Hz (/34); pass --model-rate")


def test_named_rates_bracket_the_request():
    rng = np.random.default_rng(7)
    for native_hz in (100.0, 400.0, 1000.0):
        for rate in rng.uniform(0.01, native_hz, size=300):
            k = native_hz / rate
            if abs(k - round(k)) <= 1e-9 * k:
                continue
            with pytest.raises(ConfigError) as ei:
                decimation_factor(1.0 / native_hz, rate)
            msg = str(ei.value)
            above = msg.split("nearest valid rates: ")[1].split(" Hz (/")[0]
            lo = int(msg.split(" Hz (/")[1].split(")")[0])
            hi = int(msg.split(" Hz (/")[2].split(")")[0])
            assert hi == lo + 1 and lo == math.floor(k)
            assert native_hz / hi < rate < native_hz / lo
            assert float(above) == pytest.approx(native_hz / lo, rel=1e-3)
            assert decimation_factor(1.0 / native_hz, native_hz / lo) == lo  # named rates are valid


def test_digits_grow_until_rates_differ():
    # 1000 Hz / 0.3 Hz = 3333.3: the nearest rates 0.30003 and 0.29994 need 5 digits to differ from 0.3
    with pytest.raises(ConfigError) as ei:
        decimation_factor(0.001, 0.3)
    assert "model rate 0.3 Hz" in str(ei.value)
    assert "nearest valid rates: 0.30003 Hz (/3333), 0.29994 Hz (/3334)" in str(ei.value)


def test_rate_above_native_or_invalid():
    with pytest.raises(ConfigError) as ei:
        decimation_factor(0.01, 200.0)
    assert str(ei.value) == (
        "model rate 200 Hz is above the native 100 Hz; expected the native rate divided by an integer (block "
        "averaging cannot raise the rate): 100 Hz (/1), 50 Hz (/2), 33.33 Hz (/3) ...; pass model_rate_hz="
    )
    for bad in (0.0, -1.0, float("nan"), float("inf"), True, "fast", None):
        with pytest.raises(ConfigError, match=r"model rate must be a finite number of Hz > 0.*pass model_rate_hz="):
            decimation_factor(0.01, bad)
    with pytest.raises(ConfigError, match="native_dt_s"):
        decimation_factor(0.0, 1.0)


def test_to_rate_averages_and_records_the_factor():
    x = np.arange(2 * 1003, dtype=float).reshape(1003, 2) ** 1.5
    rec = from_array(x, dt_s=0.01, axis_names=("a", "b"))
    low = rec.to_rate(25.0)
    assert low.block_average_factor == 4 and low.fs_hz == 25.0 and low.native_fs_hz == pytest.approx(100.0)
    assert_allclose(low.rate_dph, x[:1000].reshape(250, 4, 2).mean(axis=1), rtol=1e-15)
    assert low.t0_s == rec.t0_s
    assert low.notes[-1] == "block-averaged x4 (0.01 s -> 0.04 s), dropped 3 trailing samples"
    lower = low.to_rate(5.0)  # factors multiply
    assert lower.block_average_factor == 20 and lower.fs_hz == pytest.approx(5.0, rel=1e-12)
    assert_allclose(lower.rate_dph, x[:1000].reshape(50, 20, 2).mean(axis=1), rtol=1e-12)
    smp = json.loads(json.dumps(lower.metadata()))["signal"]["sampling"]
    assert smp["block_average_factor"] == 20
    assert smp["rate_hz"] == pytest.approx(5.0) and smp["native_rate_hz"] == pytest.approx(100.0)
    assert rec.metadata()["signal"]["sampling"]["block_average_factor"] == 1
    assert rec.to_rate(100.0) is rec
    assert rec.block_average(0.02).block_average_factor == 2  # block_average by interval counts too


def test_to_rate_errors():
    rec = from_array(np.zeros(10), dt_s=0.01)
    with pytest.raises(ConfigError, match="model rate 3 Hz does not divide the native 100 Hz"):
        rec.to_rate(3.0)
    with pytest.raises(ConfigError, match="above the native 100 Hz"):
        rec.to_rate(101.0)
    with pytest.raises(InsufficientDataError) as ei:
        rec.to_rate(1.0)
    assert (ei.value.needed, ei.value.got) == (100, 10)
    assert_array_equal(rec.to_rate(10.0).rate_dph, [[0.0]])


#: The keys of a written record block: the sampling and the units are in ``signal`` only.
RECORD_KEYS = {"source", "sha256", "t0_s", "n_samples", "n_axes", "duration_s", "axis_names", "notes", "temperature",
               "signal"}


def test_metadata_writes_the_sampling_once_and_reads_back():
    """The record block holds the sampling in signal.sampling only, and it reads back as the record's."""
    from fogdrift.signal import record_sampling

    rec = from_array(np.arange(2 * 1003, dtype=float).reshape(1003, 2), dt_s=0.01, axis_names=("a", "b"))
    low = rec.to_rate(25.0)
    meta = json.loads(json.dumps(low.metadata()))
    assert set(meta) == RECORD_KEYS
    smp = record_sampling(meta)
    assert (smp.dt_s, smp.native_dt_s, smp.block_average_factor) == (low.dt_s, rec.dt_s, 4)
    assert smp == low.signal.sampling


@pytest.mark.parametrize("unit, names", [
    ("inc:arcsec", ("gx", "gz")),                 # gyro increments: the factor includes 1 / dt
    ("mg", ("ax", "ay")),                         # accelerometer: internal m/s^2
])
def test_metadata_writes_the_units_once_and_reads_back(unit, names):
    """The record block holds the units in signal.channels only; they read back as the record's own."""
    from fogdrift.signal import record_units

    rec = from_array(np.ones((40, 2)), dt_s=0.01, unit=unit, axis_names=names)
    meta = json.loads(json.dumps(rec.metadata()))
    assert set(meta) == RECORD_KEYS
    u = record_units(meta)
    assert u.input_unit == rec.input_unit == unit and u.scale_to_internal == rec.scale_to_internal
    assert u.declared_units == rec.declared_units and u.channels == rec.signal.channels
    assert u.internal_unit == rec.signal.channels[0].internal_unit and u.all_gyro == (unit == "inc:arcsec")


def test_metadata_of_a_gyro_and_accelerometer_record_writes_the_units_once(tmp_path):
    """A mixed log (each channel its own unit and factor) reads back with the record's input_unit text."""
    from fogdrift.io import load
    from fogdrift.signal import record_units

    p = tmp_path / "imu.csv"
    p.write_text("t_s,gx[deg/s],ax[g]\n" + "".join(f"{0.01 * i},0.1,1.0\n" for i in range(40)))
    rec = load(p)
    meta = json.loads(json.dumps(rec.metadata()))
    assert set(meta) == RECORD_KEYS
    u = record_units(meta)
    assert u.input_unit == rec.input_unit == "gx=deg/s,ax=g"
    assert u.scale_to_internal is None and u.internal_unit is None and not u.all_gyro
    assert [(c.quantity, c.internal_unit) for c in u.channels] == [("angular_rate", "deg/h"),
                                                                   ("specific_force", "m/s^2")]
