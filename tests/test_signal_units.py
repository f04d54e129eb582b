"""The one unit parser (units.parse_unit) and the one sample-interval validator (units.check_dt_s).

Reference values are computed here by hand from the unit definitions, not from the tables under test:
1 deg/s = 3600 deg/h; 1 rad/s = 180/pi * 3600 deg/h; 1 arcsec per sample of dt s = 1/3600 deg / dt s
= 1/dt deg/h; 1 g = 9.80665 m/s^2 (standard gravity, exact by definition); 1 mg = 9.80665e-3 m/s^2.
"""

import math

import pytest

from fogdrift import units
from fogdrift.errors import ConfigError


@pytest.mark.parametrize("text, quantity, kind, scale", [
    ("deg/h", "angular_rate", "rate", 1.0),
    ("deg/s", "angular_rate", "rate", 3600.0),
    (" rad/s ", "angular_rate", "rate", 180.0 / math.pi * 3600.0),
    ("rad/h", "angular_rate", "rate", 180.0 / math.pi),
    ("arcsec/s", "angular_rate", "rate", 1.0),
    ("m/s^2", "specific_force", "rate", 1.0),
    ("g", "specific_force", "rate", 9.80665),
    ("mg", "specific_force", "rate", 9.80665e-3),
    ("ug", "specific_force", "rate", 9.80665e-6),
])
def test_rate_units_scale_by_hand(text, quantity, kind, scale):
    spec = units.parse_unit(text, None)
    assert (spec.quantity, spec.kind, spec.text) == (quantity, kind, text.strip())
    assert spec.scale_to_internal() == pytest.approx(scale, rel=1e-15)
    assert spec.internal_unit == {"angular_rate": "deg/h", "specific_force": "m/s^2"}[quantity]


@pytest.mark.parametrize("text, dt, scale", [
    ("inc:arcsec", 0.01, 100.0),                               # 1 arcsec / 10 ms = 100 deg/h
    ("inc:deg", 0.002, 3600.0 / 0.002),                        # 1 deg / 2 ms = 1800 deg/s
    ("inc:rad", 0.01, 180.0 / math.pi * 3600.0 / 0.01),
    ("inc:m/s", 0.005, 200.0),                                 # 1 m/s per 5 ms = 200 m/s^2
])
def test_increment_units_divide_by_dt(text, dt, scale):
    spec = units.parse_unit(text, None)
    assert spec.kind == "increment" and spec.needs_dt
    assert spec.scale_to_internal(dt) == pytest.approx(scale, rel=1e-15)
    with pytest.raises(ConfigError, match="needs the sample interval"):
        spec.scale_to_internal()


def test_quantity_restricts_the_units():
    assert units.parse_unit("deg/s").quantity == "angular_rate"          # the default: a gyro channel
    with pytest.raises(ConfigError, match=r"'mg'.*rate unit or an angle increment"):
        units.parse_unit("mg")
    with pytest.raises(ConfigError, match="expected a specific-force unit or a velocity increment"):
        units.parse_unit("deg/s", "specific_force")
    with pytest.raises(ConfigError, match="unknown quantity"):
        units.parse_unit("deg/s", "pressure")


@pytest.mark.parametrize("bad", ["DEG/S", "deg/min", "inc:", "inc:furlong", "", None, 3600, "m/s2"])
def test_unknown_units_refused_listing_the_valid_ones(bad):
    with pytest.raises(ConfigError, match=r"unknown unit .*'deg/s'.*'inc:arcsec'"):
        units.parse_unit(bad)


def test_valid_units_per_quantity():
    assert units.valid_units() == ["deg/h", "deg/s", "rad/s", "rad/h", "arcsec/s", "inc:deg", "inc:rad", "inc:arcsec"]
    assert units.valid_units("specific_force") == ["m/s^2", "g", "mg", "ug", "inc:m/s"]
    assert set(units.valid_units(None)) == set(units.valid_units()) | set(units.valid_units("specific_force"))


def test_there_is_one_unit_parser():
    import pathlib

    import fogdrift
    from fogdrift.io import _checks

    assert not hasattr(_checks, "parse_unit") and not hasattr(_checks, "unit_scale")
    assert _checks.valid_units() == units.valid_units()
    src = pathlib.Path(fogdrift.__file__).parent
    defs = [p.relative_to(src).as_posix() for p in src.rglob("*.py") if "def parse_unit(" in p.read_text()]
    assert defs == ["units.py"]


@pytest.mark.parametrize("dt", [0.01, 1e-9, 1e9, "0.5"])
def test_dt_validator_accepts(dt):
    assert units.check_dt_s(dt) == float(dt)


@pytest.mark.parametrize("dt", [1e-300, 1e300, 0.0, -0.01, float("nan"), float("inf"), "fast", None, True, 10**400])
def test_dt_validator_refuses_absurd_values_in_one_line(dt):
    with pytest.raises(ConfigError) as ei:
        units.check_dt_s(dt, "{opt:rate_hz}")
    msg = str(ei.value)
    assert "\n" not in msg and msg.startswith("rate_hz= must be")


@pytest.mark.parametrize("fs", [1e-300, 1e300, 0.0, float("nan"), "x"])
def test_rate_validator_refuses(fs):
    with pytest.raises(ConfigError, match="rate_hz must be"):
        units.check_rate_hz(fs)
    assert units.check_rate_hz(100.0) == 100.0
