"""Tests of ``fogdrift.io.channel_quantity`` (the accelerometer channel / unit rule), first written against the
surviving mutants of mutation round 3 (docs/testing-rounds.md).

Each test pins a rule a one-line change would break: the ``unit`` option given as a parsed UnitSpec, refused when
it is not a string, entries that are not KEY=UNIT (an empty key, a second '='), a column given twice, and the
refusal of a channel whose name says the other quantity, naming the file, the channel and the entry that gave
the unit.  Factors are checked against 1 g = 9.80665 m/s^2 (CGPM 1901) and 1 deg/s = 3600 deg/h.
"""

from __future__ import annotations

import pytest

from fogdrift import units
from fogdrift.errors import ConfigError
from fogdrift.io.channel_quantity import (KEY_OF_QUANTITY, QUANTITY_WORDS, check_name, parse_unit_choice,
                                          quantity_of_name)

G0 = 9.80665


def approx(expected, rel=1e-6, abs=0.0):  # noqa: A002
    """pytest.approx without its default absolute tolerance of 1e-12, which would pass any two SI values below
    ~1e-10 (K in rad/s^2/sqrt(Hz), Qd in (rad/s)^2): a relative check must be relative."""
    return pytest.approx(expected, rel=rel, abs=abs)


def test_a_parsed_unit_spec_is_the_one_unit():
    spec = units.parse_unit("mg", None)
    c = parse_unit_choice(spec)
    assert c.text == "mg" and c.single is spec and c.by_quantity == {} and c.by_column == {}
    assert c.for_channel("ax", "f.csv").scale_to_internal() == approx(G0 * 1e-3, rel=1e-14)
    c = parse_unit_choice(" deg/s ")
    assert c.text == "deg/s" and c.by_quantity == {} and c.by_column == {}
    assert c.single.scale_to_internal() == approx(3600.0, rel=1e-14)      # deg/s -> deg/h


@pytest.mark.parametrize("bad", [None, 5, 9.80665, "", "   ", ["g"]])
def test_a_unit_option_that_is_not_a_string_is_refused_in_one_line(bad):
    with pytest.raises(ConfigError) as ei:
        parse_unit_choice(bad)
    assert str(ei.value) == f"unit must be a unit string (deg/s, g, ...) or gyro=U,accel=U; got {bad!r}"


@pytest.mark.parametrize("text, entry", [("=deg/s", "=deg/s"), ("gyro=deg/s, =g", "=g"), ("accel=", "accel="),
                                          ("gyro=deg/s,g", "g")])
def test_entries_that_are_not_key_equals_unit(text, entry):
    with pytest.raises(ConfigError) as ei:
        parse_unit_choice(text)
    assert str(ei.value) == (f"unit {text.strip()!r}: entry {entry!r} is not KEY=UNIT; expected e.g. "
                             "gyro=deg/s,accel=g")


def test_the_key_ends_at_the_first_equals_sign():
    # "ax==g": key "ax", unit "=g" (no such unit); split at the last '=' it would read the column "ax=" in g
    with pytest.raises(ConfigError, match="unknown unit"):
        parse_unit_choice("ax==g")
    c = parse_unit_choice("gyro = deg/h , accel = ug , ax = m/s^2")
    assert set(c.by_quantity) == {"angular_rate", "specific_force"} and set(c.by_column) == {"ax"}
    assert c.by_quantity["specific_force"].scale_to_internal() == approx(G0 * 1e-6, rel=1e-14)


def test_a_column_given_twice_is_refused():
    with pytest.raises(ConfigError) as ei:
        parse_unit_choice("gx=deg/s,gx=deg/h")
    assert str(ei.value) == "unit 'gx=deg/s,gx=deg/h': column 'gx' given twice"
    with pytest.raises(ConfigError) as ei:
        parse_unit_choice("GYRO=deg/s,gyro=deg/h")
    assert str(ei.value) == "unit 'GYRO=deg/s,gyro=deg/h': gyro= given twice"


def test_the_single_unit_refusal_names_the_file_channel_and_option():
    c = parse_unit_choice("deg/s")
    with pytest.raises(ConfigError) as ei:
        c.for_channel("ax", "run/imu.csv")
    msg = str(ei.value)
    assert msg.startswith("run/imu.csv: channel 'ax' is named as a specific-force (accelerometer) channel but "
                          "unit= 'deg/s' is an angular-rate (gyro) unit; give it a unit of its quantity "
                          "(g, mg, ug, m/s^2)")
    assert "\n" not in msg


def test_a_column_entry_is_checked_against_the_name():
    c = parse_unit_choice("gyro=deg/s,accel=g,ax=deg/h")
    with pytest.raises(ConfigError) as ei:
        c.for_channel("ax", "run/imu.csv")
    assert str(ei.value).startswith("run/imu.csv: channel 'ax' is named as a specific-force (accelerometer) channel "
                                    "but unit= entry ax=deg/h is an angular-rate (gyro) unit;")
    # a neutral name takes its column entry, whatever the quantity
    c = parse_unit_choice("gyro=deg/s,accel=g,temp_x=mg")
    assert c.for_channel("temp_x", "f").scale_to_internal() == approx(G0 * 1e-3, rel=1e-14)
    assert c.for_channel("gy", "f").scale_to_internal() == approx(3600.0, rel=1e-14)
    assert c.for_channel("a_z", "f").scale_to_internal() == approx(G0, rel=1e-14)


def test_per_quantity_option_without_the_quantity_of_a_channel():
    c = parse_unit_choice("accel=g")
    with pytest.raises(ConfigError) as ei:
        c.for_channel("omega_x", "f.csv")
    assert str(ei.value) == ("f.csv: channel 'omega_x' is named as an angular-rate (gyro) channel but unit= "
                             "'accel=g' gives no gyro= unit; add gyro=U")


def test_check_name_passes_a_neutral_name_and_the_right_quantity():
    g = units.parse_unit("g", None)
    check_name("x", g, "unit 'g'", "f")            # says nothing: accepted
    check_name("acc_y", g, "unit 'g'", "f")        # says accelerometer, g is specific force: accepted
    with pytest.raises(ConfigError) as ei:
        check_name("gyr_y", g, "the unit 'g' declared in the header", "f.csv")
    assert str(ei.value).startswith("f.csv: channel 'gyr_y' is named as an angular-rate (gyro) channel but the "
                                    "unit 'g' declared in the header is a specific-force (accelerometer) unit; give "
                                    "it a unit of its quantity (deg/s, deg/h, rad/s), e.g. unit= gyro=deg/s,accel=g")
    assert str(ei.value).endswith("(a channel is never silently read as the other quantity)")


@pytest.mark.parametrize("name, expected", [
    ("a1", "specific_force"), ("acc-2", "specific_force"), ("accel.z", "specific_force"), ("f_x", "specific_force"),
    ("fy", "specific_force"), ("sf_raw", "specific_force"), ("LINEAR_ACCELERATION_Z", "specific_force"),
    ("g1", "angular_rate"), ("gyr", "angular_rate"), ("w_z", "angular_rate"), ("omega", "angular_rate"),
    ("rate_x", "angular_rate"), ("Angular_Velocity_y", "angular_rate"), (" gx ", "angular_rate"),
    ("ax_temp", None), ("fz2", None), ("axx", None), ("g", None), ("a", None), ("wz_", None), ("f", None),
])
def test_name_rule_edges(name, expected):
    assert quantity_of_name(name) == expected


def test_the_words_of_the_messages():
    assert QUANTITY_WORDS == {"angular_rate": "an angular-rate (gyro)",
                              "specific_force": "a specific-force (accelerometer)"}
    assert KEY_OF_QUANTITY == {"angular_rate": "gyro", "specific_force": "accel"}
