"""Tests added for the surviving mutants of ``fogdrift.spec`` (issue 24 item 2, docs/testing.md "Round 2: new
modules (issues 21-23)"): the accelerometer re-reading of gyro-labelled readings (every reading, bounds and
missing values kept, the label saying what was done), the ``_why`` summary column, and ``judge_noise_fit`` on an
accelerometer channel."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from fogdrift.spec import Reading, _accel_in_place_of_deg_h, judge_noise_fit, parse_spec, spec_columns


def test_accel_re_reading_keeps_missing_readings_and_reads_every_item():
    # first item already in an accelerometer unit (kept), the second gyro-labelled (re-read): order matters for a
    # loop that stops at the first kept item
    r = {"vrw": Reading(0.3, 0.25, 0.35, "m/s/sqrt(h)", None, "N"),
         "bias_instability": Reading(0.003, None, 0.0035, "deg/h", "upper", "B_min"),
         "other": None}
    out = _accel_in_place_of_deg_h(r)
    assert out["vrw"] is r["vrw"] and out["other"] is None
    b = out["bias_instability"]
    assert b.unit == "m/s^2" and b.value == pytest.approx(0.003) and b.lo95 is None
    assert b.hi95 == pytest.approx(0.0035) and b.bound == "upper"
    assert b.label == "B_min (fit labelled deg/h: m/s^2 in place of deg/h)"


def test_accel_re_reading_of_the_white_term_is_3600_times():
    out = _accel_in_place_of_deg_h({"vrw": Reading(1e-4, None, None, "deg/sqrt(h)", "lower", "N")})
    assert out["vrw"].value == pytest.approx(0.36, rel=1e-12) and out["vrw"].bound == "lower"
    assert out["vrw"].unit == "m/s/sqrt(h)" and out["vrw"].lo95 is None and out["vrw"].hi95 is None


def test_spec_columns_carry_the_reason():
    spec = parse_spec({"gyro": {"arw": "2 deg/sqrt(h)"}})
    n = SimpleNamespace(value=2.4, lo95=2.37, hi95=2.42, unit="deg/sqrt(h)", status="resolved", estimable=True)
    fit = SimpleNamespace(terms={"N": n}, no_fit=None, b_min={})
    cols = spec_columns(judge_noise_fit(spec, "gx", fit))
    assert cols == {"spec_arw": "fail",
                    "spec_arw_why": "the whole 95 % interval exceeds the limit 2 deg/sqrt(h)"}


def test_judge_noise_fit_on_an_accelerometer_channel_reads_the_velocity_random_walk():
    # N 1e-4 "(deg/h) sqrt(h)" on an accelerometer = 0.36 m/s/sqrt(h) [0.324, 0.396]: a fail against 0.2
    spec = parse_spec({"accel": {"vrw": "0.2 m/s/sqrt(h)"}})
    n = SimpleNamespace(value=1e-4, lo95=0.9e-4, hi95=1.1e-4, unit="deg/sqrt(h)", status="resolved", estimable=True)
    fit = SimpleNamespace(terms={"N": n}, no_fit=None, b_min={})
    js = judge_noise_fit(spec, "ax", fit, "accel")
    assert [(j.channel, j.limit.item, j.verdict) for j in js] == [("ax", "vrw", "fail")]
    assert js[0].estimate == "0.36 [0.324, 0.396] m/s/sqrt(h)"
