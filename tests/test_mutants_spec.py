"""Tests added for the surviving mutants of ``fogdrift.spec`` (issue 24 item 2, docs/testing-rounds.md "Round 2: new
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


def test_lower_bound_at_exactly_the_limit_cannot_tell_and_says_so():
    from fogdrift.spec import judge

    lim = parse_spec({"gyro": {"arw": "2 deg/sqrt(h)"}})["limits"][0]
    j = judge(lim, Reading(2.0, None, None, "deg/sqrt(h)", "lower"))
    assert j.verdict == "cannot tell" and j.estimate == "> 2 deg/sqrt(h)"
    j = judge(lim, Reading(2.5, None, None, "deg/sqrt(h)", "lower"))
    assert j.verdict == "fail" and j.estimate == "> 2.5 deg/sqrt(h)"


def test_reading_labels_say_where_they_come_from():
    from fogdrift.spec import readings_from_noise_fit

    n = SimpleNamespace(value=2.4, lo95=2.37, hi95=2.42, unit="deg/sqrt(h)", status="resolved", estimable=True)
    fit = SimpleNamespace(terms={"N": n}, no_fit=None,
                          b_min={"value": 20.0, "unit": "deg/h", "tau_s": 100.0, "bound_only": False, "lo95": 15.0,
                                 "hi95": 24.0})
    r = readings_from_noise_fit(fit)
    assert r["arw"].label == "N from the Allan fit"
    assert r["bias_instability"].label == "B_min at τ = 100 s"


@pytest.mark.parametrize("text", ["0.007 deg/sec", "0.007 deg/second", "0.007 °/s"])
def test_seconds_spelled_out_are_seconds(text):
    from fogdrift.spec import parse_quantity

    assert parse_quantity(text, "gyro", "bias_instability")[0] == pytest.approx(25.2, rel=1e-12)


def test_b_min_reading_keeps_the_unit_the_fit_wrote():
    from fogdrift.spec import judge, readings_from_noise_fit

    fit = SimpleNamespace(terms={}, no_fit=None,
                          b_min={"value": 0.005, "unit": "deg/s", "tau_s": 0, "lo95": 0.004, "hi95": 0.006})
    r = readings_from_noise_fit(fit)["bias_instability"]
    assert r.unit == "deg/s" and r.label == "B_min"            # tau 0: no "at τ"
    lim = parse_spec({"gyro": {"bias_instability": "20 deg/h"}})["limits"][0]
    assert judge(lim, r).estimate == "18 [14.4, 21.6] deg/h"   # 0.005 deg/s = 18 deg/h


def test_bracketed_rad_per_s_is_read():
    from fogdrift.spec import convert

    assert convert(1.0, "(rad/s)/sqrt(Hz)", "gyro", "arw") == pytest.approx(60.0 * 180.0 / 3.141592653589793)


def test_gmwm_readings_of_an_accelerometer_are_vrw_and_m_per_s2():
    from fogdrift.spec import readings_from_gmwm

    n = SimpleNamespace(value=1e-4, lo95=0.9e-4, hi95=1.1e-4, unit="deg/sqrt(h)")
    b = SimpleNamespace(value_dph=0.003, lo95_dph=0.0025, hi95_dph=0.0035, tau_s=20.0, bound_dph=None, reason="")
    axis = SimpleNamespace(selection=SimpleNamespace(ieee=SimpleNamespace(terms={"N_dprh": n}, b_min=b)))
    r = readings_from_gmwm(axis, "accel")
    assert set(r) == {"vrw", "bias_instability"}
    assert r["vrw"].value == pytest.approx(0.36) and r["vrw"].unit == "m/s/sqrt(h)"
    assert r["bias_instability"].unit == "m/s^2" and r["bias_instability"].label.startswith("B_min at τ = 20 s (GMWM)")
    assert (r["bias_instability"].lo95, r["bias_instability"].hi95) == (pytest.approx(0.0025), pytest.approx(0.0035))
    assert set(readings_from_gmwm(axis)) == {"arw", "bias_instability"}


def test_sensor_name_and_judgement_without_a_reading_to_dict():
    from fogdrift.spec import judge

    spec = parse_spec({"sensor": "ADIS16405", "gyro": {"arw": "2 deg/sqrt(h)"}})
    assert spec["sensor"] == "ADIS16405"
    assert parse_spec({"gyro": {"arw": "2 deg/sqrt(h)"}})["sensor"] is None
    d = judge(spec["limits"][0], None, "gx").to_dict()
    assert d["reading"] is None and d["verdict"] == "cannot tell" and d["channel"] == "gx"
    assert d["limit"] == "2 deg/sqrt(h)" and d["limit_canonical"] == 2.0 and d["unit"] == "deg/sqrt(h)"


def test_upper_bound_label_of_a_term_that_is_not_estimable_gives_its_status():
    from fogdrift.spec import readings_from_noise_fit

    n = SimpleNamespace(value=None, lo95=0.0, hi95=0.5, unit="deg/sqrt(h)", status="absent", estimable=False)
    r = readings_from_noise_fit(SimpleNamespace(terms={"N": n}, no_fit=None, b_min={}))["arw"]
    assert r.label == "N: only its 95 % upper bound (absent)" and r.bound == "upper" and r.value == 0.5
    r = readings_from_noise_fit(SimpleNamespace(terms={"N": n}, no_fit=True, b_min={}))["arw"]
    assert r.label == "N: only its 95 % upper bound (no model fits)"


def test_bound_only_readings_keep_unit_and_direction():
    from fogdrift.spec import readings_from_gmwm, readings_from_noise_fit

    fit = SimpleNamespace(terms={}, no_fit=None, b_min={"value": 0.01, "unit": "deg/s", "tau_s": 50.0,
                                                        "bound_only": True})
    r = readings_from_noise_fit(fit)["bias_instability"]
    assert (r.unit, r.bound, r.label) == ("deg/s", "upper", "B_min at τ = 50 s, an upper bound")
    r = readings_from_noise_fit(SimpleNamespace(terms={}, no_fit=None, b_min={"value": 5.0, "bound_only": True}))
    assert r["bias_instability"].unit == "deg/h"
    n = SimpleNamespace(value=1.0, lo95=0.9, hi95=1.1, unit="deg/sqrt(h)")
    b = SimpleNamespace(value_dph=None, bound_dph=3.0, reason="still falling", tau_s=None)
    g = readings_from_gmwm(SimpleNamespace(selection=SimpleNamespace(ieee=SimpleNamespace(terms={"N_dprh": n},
                                                                                          b_min=b))))
    assert g["arw"].label == "N from GMWM"
    assert (g["bias_instability"].bound, g["bias_instability"].value, g["bias_instability"].unit) == ("upper", 3.0,
                                                                                                      "deg/h")
    assert g["bias_instability"].label == "B_min, an upper bound (still falling)"


def test_judgement_dict_has_reason_and_the_reading_label():
    from fogdrift.spec import judge

    lim = parse_spec({"gyro": {"arw": "2 deg/sqrt(h)"}})["limits"][0]
    d = judge(lim, Reading(1.0, 0.9, 1.1, "deg/sqrt(h)", None, "N from GMWM")).to_dict()
    assert d["reading"] == "N from GMWM" and d["reason"] == "the whole 95 % interval is within the limit 2 deg/sqrt(h)"


def test_spec_file_errors_name_the_yaml_line_and_an_unreadable_path(tmp_path):
    from fogdrift.errors import ConfigError
    from fogdrift.spec import read_spec

    p = tmp_path / "s.yaml"
    p.write_text("gyro:\n  arw: \"2 deg/sqrt(h)\"\n  b: [unclosed\n", encoding="utf-8")
    with pytest.raises(ConfigError, match=r"s\.yaml:4: not valid YAML"):
        read_spec(p)
    with pytest.raises(ConfigError, match=r"^spec file: cannot read .* \(.*\)$"):
        read_spec(tmp_path)   # a directory


def test_channel_kind_channel_and_limit_kept_and_greek_mu():
    from fogdrift.spec import channel_kind, judge, parse_quantity

    assert (channel_kind("specific_force"), channel_kind("angular_rate"), channel_kind(None)) == ("accel", "gyro",
                                                                                                   "gyro")
    lim = parse_spec({"gyro": {"arw": "2 deg/sqrt(h)"}})["limits"][0]
    j = judge(lim, Reading(2.5, None, None, "deg/sqrt(h)"), "gx")          # no interval
    assert (j.channel, j.limit, j.verdict) == ("gx", lim, "cannot tell")
    j = judge(lim, Reading(2.0, 1.5, 2.5, "deg/sqrt(h)"), "gy")            # the limit inside the interval
    assert (j.channel, j.limit, j.verdict) == ("gy", lim, "cannot tell")
    assert parse_quantity("200 \u03bcg", "accel", "bias_instability")[0] == pytest.approx(1.96133e-3, rel=1e-12)


def test_no_estimate_judgement_keeps_its_limit():
    from fogdrift.spec import judge

    lim = parse_spec({"gyro": {"arw": "2 deg/sqrt(h)"}})["limits"][0]
    j = judge(lim, None, "gx")
    assert (j.channel, j.limit, j.verdict, j.estimate) == ("gx", lim, "cannot tell", "–")


def test_foreign_unit_judgement_keeps_channel_and_limit():
    from fogdrift.spec import judge

    lim = parse_spec({"accel": {"vrw": "0.2 m/s/sqrt(h)"}})["limits"][0]
    j = judge(lim, Reading(2.4, 2.3, 2.5, "deg/sqrt(h)"), "ax")
    assert (j.channel, j.limit, j.verdict, j.estimate) == ("ax", lim, "cannot tell", "–")
