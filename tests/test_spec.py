"""Datasheet comparison (issue 22 item 5): units parsed explicitly, judged with the interval."""

from __future__ import annotations

import json
from pathlib import Path
from types import SimpleNamespace

import pytest

from fogdrift.errors import ConfigError
from fogdrift.spec import (G0, B_COMPARED, Reading, compare, convert, judge, parse_quantity, parse_spec, read_spec,
                           readings_from_noise_fit)

ROOT = Path(__file__).resolve().parents[1]


def _lim(kind, item, text):
    return parse_spec({kind: {item: text}})["limits"][0]


# -- conversions, by hand ------------------------------------------------------------------------------------------
def test_conversions_by_hand():
    assert parse_quantity("0.007 deg/s", "gyro", "bias_instability")[0] == pytest.approx(25.2, rel=1e-12)
    assert parse_quantity("0.2 mg", "accel", "bias_instability")[0] == pytest.approx(1.96133e-3, rel=1e-12)
    assert parse_quantity("200 µg", "accel", "bias_instability")[0] == pytest.approx(1.96133e-3, rel=1e-12)
    assert parse_quantity("2 °/√hr", "gyro", "arw")[0] == 2.0
    # 0.15 deg/sqrt(h) = 0.15/60 deg/sqrt(s) = 4.363e-5 rad/s/sqrt(Hz)
    assert convert(4.3633e-5, "rad/s/sqrt(Hz)", "gyro", "arw") == pytest.approx(0.15, rel=1e-4)
    assert convert(9.0, "deg/h/sqrt(Hz)", "gyro", "arw") == pytest.approx(0.15)
    # 1 m/s^2/sqrt(Hz) = 1 m/s/sqrt(s) = 60 m/s/sqrt(h); 100 ug/sqrt(Hz) = 100e-6 g0 * 60
    assert convert(1.0, "m/s²/√Hz", "accel", "vrw") == pytest.approx(60.0)
    assert convert(100.0, "ug/sqrt(Hz)", "accel", "vrw") == pytest.approx(100e-6 * G0 * 60)
    assert G0 == 9.80665


@pytest.mark.parametrize("text, match", [
    (2, "has no unit"), ("2", "has no unit"), ("2 furlongs", "unknown unit 'furlongs'"),
    ("2 m/s/sqrt(h)", "unknown unit"), ("-1 deg/sqrt(h)", ">= 0"), ("fast", "not a number"),
])
def test_unitless_or_unknown_unit_is_one_line_error(text, match):
    with pytest.raises(ConfigError, match=match) as exc:
        parse_spec({"gyro": {"arw": text}})
    assert "\n" not in str(exc.value)


def test_unknown_section_and_item():
    with pytest.raises(ConfigError, match="unknown section 'magnetometer'"):
        parse_spec({"magnetometer": {"x": "1 uT"}})
    with pytest.raises(ConfigError, match="unknown gyro item 'vrw'; expected one of arw, bias_instability"):
        parse_spec({"gyro": {"vrw": "0.2 m/s/sqrt(h)"}})
    with pytest.raises(ConfigError, match="no limits"):
        parse_spec({"sensor": "x"})


# -- the judge -------------------------------------------------------------------------------------------------
def test_limit_inside_interval_cannot_tell():
    j = judge(_lim("gyro", "arw", "2 deg/sqrt(h)"), Reading(2.1, 1.9, 2.3, "deg/sqrt(h)"))
    assert j.verdict == "cannot tell" and "inside the 95 % interval" in j.reason


def test_pass_and_fail_use_the_whole_interval():
    lim = _lim("gyro", "bias_instability", "0.007 deg/s")  # 25.2 deg/h
    assert judge(lim, Reading(20.0, 15.0, 25.0, "deg/h")).verdict == "pass"
    assert judge(lim, Reading(30.0, 25.3, 35.0, "deg/h")).verdict == "fail"
    # the value alone is below the limit, but the interval reaches beyond it: not a pass
    assert judge(lim, Reading(24.0, 20.0, 26.0, "deg/h")).verdict == "cannot tell"
    # the same numbers in deg/s are judged identically (units converted, not assumed)
    assert judge(lim, Reading(20 / 3600, 15 / 3600, 25 / 3600, "deg/s")).verdict == "pass"


def test_bounds_say_which_way_they_can_tell():
    lim = _lim("gyro", "bias_instability", "25 deg/h")
    assert judge(lim, Reading(20.0, None, None, "deg/h", "upper")).verdict == "pass"
    j = judge(lim, Reading(30.0, None, None, "deg/h", "upper"))
    assert j.verdict == "cannot tell" and "never a fail" in j.reason and j.estimate.startswith("< 30")
    assert judge(lim, Reading(30.0, None, None, "deg/h", "lower")).verdict == "fail"
    j = judge(lim, Reading(20.0, None, None, "deg/h", "lower"))
    assert j.verdict == "cannot tell" and "never a pass" in j.reason
    assert judge(lim, None).verdict == "cannot tell"
    assert judge(lim, Reading(20.0, None, None, "deg/h")).verdict == "cannot tell"  # no interval


def test_accelerometer_entry_on_an_accel_channel_hand_built():
    spec = parse_spec({"gyro": {"arw": "2 deg/sqrt(h)"},
                       "accel": {"vrw": "0.2 m/s/sqrt(h)", "bias_instability": "0.2 mg"}})
    # VRW 0.35 [0.34, 0.36] m/s/sqrt(h): fail; B 1.5e-3 [1.2e-3, 1.8e-3] m/s^2 (0.153-0.184 mg): pass
    acc = {"vrw": Reading(0.35, 0.34, 0.36, "m/s/sqrt(h)"), "bias_instability": Reading(150.0, 120.0, 180.0, "ug")}
    js = compare(spec, {"ax": ("accel", acc), "gx": ("gyro", {"arw": Reading(1.5, 1.4, 1.6, "deg/sqrt(h)")})})
    got = {(j.channel, j.limit.item): j.verdict for j in js}
    assert got == {("ax", "vrw"): "fail", ("ax", "bias_instability"): "pass", ("gx", "arw"): "pass"}
    # ug -> m/s^2 conversion visible in the estimate
    b = next(j for j in js if j.limit.item == "bias_instability")
    assert b.estimate.startswith("0.00147 [0.00118, 0.00177] m/s^2")
    assert json.dumps([j.to_dict() for j in js])


def test_readings_from_allan_fit_use_b_min():
    n = SimpleNamespace(value=2.4, lo95=2.37, hi95=2.42, unit="deg/sqrt(h)", status="resolved", estimable=True)
    fit = SimpleNamespace(terms={"N": n}, no_fit=None,
                          b_min={"value": 28.0, "unit": "deg/h", "tau_s": 1310.7, "bound_only": True, "lo95": None,
                                 "hi95": 58.0})
    r = readings_from_noise_fit(fit)
    assert r["arw"].value == 2.4 and r["arw"].bound is None
    assert r["bias_instability"].bound == "upper" and "B_min" in r["bias_instability"].label
    fit.no_fit = {"best_candidate": "N+B"}
    assert readings_from_noise_fit(fit)["arw"].bound == "upper"
    assert "B_min" in B_COMPARED and "0.664" in B_COMPARED


def test_adis_spec_file_reads():
    spec = read_spec(ROOT / "data" / "specs" / "adis16405.yaml")
    vals = {(l.kind, l.item): l.value for l in spec["limits"]}
    assert vals[("gyro", "arw")] == 2.0 and vals[("gyro", "bias_instability")] == pytest.approx(25.2)
    assert vals[("accel", "vrw")] == 0.2 and vals[("accel", "bias_instability")] == pytest.approx(1.96133e-3)


def test_spec_file_errors(tmp_path):
    p = tmp_path / "s.json"
    p.write_text('{"gyro": {"arw": 2}}')
    with pytest.raises(ConfigError, match="has no unit"):
        read_spec(p)
    p.write_text("{oops")
    with pytest.raises(ConfigError, match=r"s\.json:1: not valid JSON"):
        read_spec(p)
    y = tmp_path / "s.yaml"
    y.write_text("gyro:\n  arw: [unclosed\n")
    with pytest.raises(ConfigError, match="not valid YAML"):
        read_spec(y)
    with pytest.raises(ConfigError, match="no such file"):
        read_spec(tmp_path / "missing.yaml")


def test_summary_columns_and_line_for_batch_and_first_screen():
    from fogdrift.spec import judge_noise_fit, judgement_line, spec_columns

    spec = parse_spec({"gyro": {"arw": "2 deg/sqrt(h)", "bias_instability": "0.007 deg/s"}})
    n = SimpleNamespace(value=2.4, lo95=2.37, hi95=2.42, unit="deg/sqrt(h)", status="resolved", estimable=True)
    fit = SimpleNamespace(terms={"N": n}, no_fit=None,
                          b_min={"value": 20.0, "unit": "deg/h", "tau_s": 100.0, "bound_only": False, "lo95": 15.0,
                                 "hi95": 24.0})
    js = judge_noise_fit(spec, "gx", fit)
    cols = spec_columns(js)
    assert cols["spec_arw"] == "fail" and cols["spec_bias_instability"] == "pass"
    assert judgement_line(js[0]).startswith("gx arw: fail: 2.4 [2.37, 2.42] deg/sqrt(h) against 2 deg/sqrt(h)")


def test_estimate_in_a_foreign_unit_is_cannot_tell_not_a_crash():
    lim = _lim("accel", "vrw", "0.2 m/s/sqrt(h)")
    j = judge(lim, Reading(2.4, 2.3, 2.5, "deg/sqrt(h)"))
    assert j.verdict == "cannot tell" and "not a accel vrw unit" in j.reason
    assert convert(0.3, "(m/s)/sqrt(h)", "accel", "vrw") == pytest.approx(0.3)


def test_readings_from_a_real_gmwm_fit():
    """GMWM on simulated white noise of N = 1 deg/sqrt(h): the N reading holds 1 within its interval, and B_min is
    a reading (a value or an upper bound), judged without error."""
    import numpy as np

    from fogdrift.gmwm.analysis import analyse_gmwm
    from fogdrift.spec import readings_from_gmwm

    dt = 0.1
    y = np.random.default_rng(5).normal(0.0, 60.0 / dt**0.5, 50_000)
    r = readings_from_gmwm(analyse_gmwm("gx", y, dt))
    assert r["arw"].lo95 < 1.0 < r["arw"].hi95 and r["arw"].unit == "deg/sqrt(h)"
    spec = parse_spec({"gyro": {"arw": "1.5 deg/sqrt(h)", "bias_instability": "1000 deg/h"}})
    got = {j.limit.item: j.verdict for j in compare(spec, {"gx": ("gyro", r)})}
    assert got["arw"] == "pass" and got["bias_instability"] in ("pass", "cannot tell")


def test_accel_fit_with_gyro_labels_is_read_in_place_of_deg_h():
    """An accelerometer fit whose terms carry deg/sqrt(h) and deg/h labels holds m/s^2 in place of deg/h:
    N 1e-4 '(deg/h) sqrt(h)' = 1e-4 (m/s^2) sqrt(h) = 0.36 m/s/sqrt(h); B 0.003 'deg/h' = 0.003 m/s^2 = 0.306 mg."""
    n = SimpleNamespace(value=1e-4, lo95=0.9e-4, hi95=1.1e-4, unit="deg/sqrt(h)", status="resolved", estimable=True)
    fit = SimpleNamespace(terms={"N": n}, no_fit=None,
                          b_min={"value": 0.003, "unit": "deg/h", "tau_s": 20.0, "bound_only": False,
                                 "lo95": 0.0025, "hi95": 0.0035})
    r = readings_from_noise_fit(fit, "accel")
    assert r["vrw"].unit == "m/s/sqrt(h)" and r["vrw"].value == pytest.approx(0.36)
    assert r["bias_instability"].unit == "m/s^2" and r["bias_instability"].hi95 == pytest.approx(0.0035)
    spec = parse_spec({"accel": {"vrw": "0.2 m/s/sqrt(h)", "bias_instability": "0.2 mg"}})
    got = {j.limit.item: j.verdict for j in compare(spec, {"ax": ("accel", r)})}
    assert got == {"vrw": "fail", "bias_instability": "fail"}  # 0.32-0.40 > 0.2; 0.25-0.36 mg > 0.2 mg
    # already accelerometer units: kept as they are
    n2 = SimpleNamespace(value=0.3, lo95=0.25, hi95=0.35, unit="m/s/sqrt(h)", status="resolved", estimable=True)
    fit2 = SimpleNamespace(terms={"N": n2}, no_fit=None, b_min={})
    assert readings_from_noise_fit(fit2, "accel")["vrw"].value == 0.3


# --------------------------------------------------------------------------------------------------------------
# Rules first pinned against the surviving mutants of ``fogdrift.spec`` (docs/testing-rounds.md)
# --------------------------------------------------------------------------------------------------------------
from fogdrift.spec import _accel_in_place_of_deg_h, judge_noise_fit, spec_columns  # noqa: E402


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
    with pytest.raises(ConfigError, match=r"spec file: cannot read"):
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
