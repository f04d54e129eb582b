"""Tests of ``fogdrift.units`` beside those of the readers (test_signal_units, test_io_units, test_accel*), first
written against the mutants those never reached (docs/testing-rounds.md): the Earth-rate projection, the rate and increment scales to deg/h and the temperature offsets, each by hand."""

from __future__ import annotations

import math

import pytest

from fogdrift.errors import ConfigError
from fogdrift.units import (earth_rate_projection_dph, increment_scale_to_dph, rate_scale_to_dph,
                            temperature_offset_to_c)

W_IE = 7.2921150e-5 * 180.0 / math.pi * 3600.0   # 15.041 deg/h


@pytest.mark.parametrize("lat, axis, expected", [
    (30.0, "up", W_IE * 0.5), (30.0, "UP", W_IE * 0.5), (30.0, "down", -W_IE * 0.5),
    (60.0, "north", W_IE * 0.5), (60.0, "south", -W_IE * 0.5), (45.0, "east", 0.0), (45.0, "west", 0.0),
    (90.0, "up", W_IE), (-90.0, "up", -W_IE), (0.0, "north", W_IE),
    (30.0, (0.0, 2.0, 0.0), W_IE * math.sqrt(3.0) / 2.0),              # a vector is normalised
    (30.0, [0.0, 1.0, 1.0], W_IE * (math.sqrt(3.0) / 2.0 + 0.5) / math.sqrt(2.0)),
])
def test_earth_rate_projection_by_hand(lat, axis, expected):
    assert earth_rate_projection_dph(lat, axis) == pytest.approx(expected, rel=1e-12, abs=1e-12)


def test_earth_rate_default_axis_is_up():
    assert earth_rate_projection_dph(30.0) == pytest.approx(7.520533, abs=1e-6)


@pytest.mark.parametrize("lat, axis, match", [
    (90.5, "up", r"^latitude must be in \[-90, 90\] deg, got 90.5$"),
    (-91.0, "up", "latitude must be in"),
    (10.0, "sideways", r"^unknown axis orientation 'sideways'; expected one of \['down', 'east', 'north', 'south', "
                       r"'up', 'west'\] or an \(east, north, up\) vector$"),
    (10.0, (0.0, 0.0), "axis vector must be 3 finite numbers, not all zero"),
    (10.0, (0.0, 0.0, 0.0), "axis vector must be 3 finite numbers, not all zero"),
    (10.0, (0.0, math.nan, 1.0), "axis vector must be 3 finite numbers"),
])
def test_earth_rate_refuses_bad_input_in_one_line(lat, axis, match):
    with pytest.raises(ConfigError, match=match):
        earth_rate_projection_dph(lat, axis)


def test_rate_scales_to_deg_per_hour_by_hand():
    assert rate_scale_to_dph("deg/s") == 3600.0
    assert rate_scale_to_dph("rad/s") == pytest.approx(180.0 / math.pi * 3600.0, rel=1e-15)
    assert rate_scale_to_dph("deg/h") == 1.0
    for bad in ("DEG/S", "inc:deg", "mg", None, 3):
        with pytest.raises(ConfigError, match=r"unknown rate unit") as ei:
            rate_scale_to_dph(bad)
        assert all(f"'{u}'" in str(ei.value) for u in ("arcsec/s", "deg/h", "deg/s", "rad/h", "rad/s", "inc:arcsec",
                                                         "inc:deg", "inc:rad"))  # every accepted unit named


def test_increment_scales_to_deg_per_hour_by_hand():
    # 1 deg per 0.5 s = 2 deg/s = 7200 deg/h; 1 rad per 2 s; 1 arcsec per 10 ms = 100 deg/h
    assert increment_scale_to_dph("deg", 0.5) == pytest.approx(7200.0, rel=1e-15)
    assert increment_scale_to_dph("rad", 2.0) == pytest.approx(180.0 / math.pi * 1800.0, rel=1e-15)
    assert increment_scale_to_dph("arcsec", 0.01) == pytest.approx(100.0, rel=1e-15)
    for bad in ("deg/s", "m/s", None):
        with pytest.raises(ConfigError, match=r"unknown increment unit") as ei:
            increment_scale_to_dph(bad, 1.0)
        assert all(f"'{u}'" in str(ei.value) for u in ("arcsec", "deg", "rad"))
    with pytest.raises(ConfigError, match="dt_s"):
        increment_scale_to_dph("deg", 0.0)


@pytest.mark.parametrize("unit, offset", [("degC", 0.0), (" DEGC ", 0.0), ("°C", 0.0), ("Celsius", 0.0),
                                          ("K", -273.15), ("kelvin", -273.15), ("deg c", 0.0)])
def test_temperature_offsets(unit, offset):
    assert temperature_offset_to_c(unit) == offset


@pytest.mark.parametrize("unit", ["F", "degF", None, 1.0])
def test_unknown_temperature_unit_is_one_line(unit):
    with pytest.raises(ConfigError, match=r"unknown temperature unit.*any case"):
        temperature_offset_to_c(unit)


def test_parse_unit_records_the_base_and_names_every_quantity_when_none_is_given():
    from fogdrift.units import parse_unit

    assert parse_unit("deg/s").base == "deg/s" and parse_unit("inc:arcsec").base == "arcsec"
    with pytest.raises(ConfigError, match=r"'furlong'.*angular rate or specific force.*'deg/h'"):
        parse_unit("furlong", None)


# both ends are inside: the rate is judged by its interval 1 / rate, as check_dt_s judges it (1e9 Hz -> 1e-9 s)
@pytest.mark.parametrize("rate", [0.5, 1e-9, 5e8, 1.0 / 1e-9, 1e9])
def test_check_rate_hz_accepts_its_ends_and_rates_below_one_hertz(rate):
    from fogdrift.units import check_rate_hz

    assert check_rate_hz(rate) == rate


@pytest.mark.parametrize("rate, match", [(True, r"^rate_hz must be a number of Hz > 0, got True$"),
                                         (0.0, "must be a finite number of Hz > 0"),
                                         (2e9, r"must be a sample rate between 1e-09 Hz and 1e\+09 Hz")])
def test_check_rate_hz_messages(rate, match):
    from fogdrift.units import check_rate_hz

    with pytest.raises(ConfigError, match=match):
        check_rate_hz(rate)


def test_check_dt_s_refuses_infinity_and_time_unit_message():
    from fogdrift.units import check_dt_s, time_scale_to_s

    with pytest.raises(ConfigError, match=r"dt_s.*> 0.*inf"):
        check_dt_s(math.inf)
    with pytest.raises(ConfigError, match=r"'min'.*'s', 'ms', 'us', 'ns'"):
        time_scale_to_s("min")
