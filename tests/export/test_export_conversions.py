"""Tests of ``fogdrift.export.conversions`` (first written against the surviving mutants of a mutation round,
docs/testing-rounds.md).

Each test pins a rule a one-line change would break: the inverse conversions by hand, the edges of the rate and
correlation-time validators (0, a value between 0 and 1, a negative, a non-finite or non-numeric value), the
unknown-unit answers, and the listing of the known units in the message.
"""

from __future__ import annotations

import math

import pytest

from fogdrift.errors import ConfigError
from fogdrift.export.conversions import (DEG, G0, UNIT_TABLE, density_to_vrw, from_si, gm_discrete,
                                         quantity_of_unit, to_si, walk_discrete, white_discrete)


def test_density_to_vrw_by_hand():
    # 0.002 m/s^2/sqrt(Hz) = 0.002 m/s/sqrt(s) = 0.002 * 60 m/s/sqrt(h)
    assert density_to_vrw(0.002) == pytest.approx(0.12, rel=1e-12)
    assert density_to_vrw(1.0) == pytest.approx(60.0, rel=1e-12)


@pytest.mark.parametrize("value_si, term, unit, expected", [
    (0.2e-3 * G0, "B", "mg", 0.2),                    # 0.2 mg
    (0.15 * DEG / 60.0, "N", "deg/sqrt(h)", 0.15),    # 0.15 deg/sqrt(h)
    (10.0 * DEG / 216000.0, "K", "deg/h^1.5", 10.0),  # 10 deg/h^1.5
    (3.0 / 3600.0, "B", "m/s/h", 3.0),                # 3 m/s per hour
])
def test_from_si_is_the_division_by_the_factor(value_si, term, unit, expected):
    assert from_si(value_si, term, unit) == pytest.approx(expected, rel=1e-12)
    v, _, _ = to_si(expected, term, unit)
    assert v == pytest.approx(value_si, rel=1e-12)


def test_from_si_refuses_an_unknown_unit_in_one_line():
    with pytest.raises(ConfigError, match=r"'furlong'.*term N"):
        from_si(1.0, "N", "furlong")
    with pytest.raises(ConfigError, match="is not one fogdrift can convert"):
        from_si(1.0, "N", "mg")  # a unit of B, not of N


@pytest.mark.parametrize("tc", [-1.0, 0.0, math.inf, math.nan])
def test_gm_discrete_refuses_a_correlation_time_that_is_not_finite_and_positive(tc):
    with pytest.raises(ConfigError, match=r"correlation time.*> 0 s"):
        gm_discrete(1.0, tc, 100.0)


def test_gm_discrete_below_one_second_by_hand():
    # T_c = 0.5 s at 10 Hz: phi = e^-0.2, q = sigma sqrt(1 - e^-0.4)
    phi, q = gm_discrete(2.0, 0.5, 10.0)
    assert phi == pytest.approx(math.exp(-0.2), rel=1e-12)
    assert q == pytest.approx(2.0 * math.sqrt(1.0 - math.exp(-0.4)), rel=1e-12)


@pytest.mark.parametrize("rate", [0.0, -100.0, math.inf, math.nan, "fast", None])
def test_rate_validator_refuses_what_is_not_a_finite_positive_number(rate):
    with pytest.raises(ConfigError, match=r"update rate.*> 0 Hz"):
        white_discrete(1.0, rate)
    with pytest.raises(ConfigError, match="the update rate must be"):
        walk_discrete(1.0, rate)


def test_rates_below_one_hertz_are_accepted():
    # 0.25 Hz: sigma_d = N sqrt(0.25) = N / 2, random-walk increment K / sqrt(0.25) = 2 K
    assert white_discrete(3.0, 0.25) == pytest.approx(1.5, rel=1e-12)
    assert walk_discrete(3.0, 0.25) == pytest.approx(6.0, rel=1e-12)
    phi, q = gm_discrete(1.0, 8.0, 0.25)   # dt = 4 s
    assert phi == pytest.approx(math.exp(-0.5), rel=1e-12)


def test_quantity_of_an_unknown_unit_is_none():
    assert quantity_of_unit("N", "furlong") is None
    assert quantity_of_unit("B", "deg/sqrt(h)") is None   # a unit of N, not of B
    assert quantity_of_unit("sigma", "mg") == "accel"


def test_to_si_message_lists_exactly_the_units_of_that_term():
    with pytest.raises(ConfigError) as exc:
        to_si(1.0, "Q", "furlong")
    msg = str(exc.value)
    known = sorted(u for (k, u) in UNIT_TABLE if k == "Q")
    assert msg == ("unit 'furlong' of term Q is not one fogdrift can convert; expected one of " + ", ".join(known))
    assert "deg/h" not in msg  # no unit of another term


def test_to_si_of_sigma_and_markov_driving_density():
    v, u, _ = to_si(0.2, "sigma", "mg")
    assert (v, u) == (pytest.approx(0.2e-3 * G0, rel=1e-12), "m/s^2")
    v, u, _ = to_si(36.0, "q_c", "deg/h/sqrt(s)")
    assert (v, u) == (pytest.approx(0.01 * DEG, rel=1e-12), "rad/s/sqrt(s)")
