"""Accelerometers as a first-class quantity: reading (quantity from the unit, name rule, refusals), the
accelerometer term table and its conversions, a seeded simulation read back, plausibility (1 g)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fogdrift.errors import ConfigError
from fogdrift.export.conversions import to_si
from fogdrift.io import from_array, load
from fogdrift.io.channel_quantity import parse_unit_choice, quantity_of_name
from fogdrift.noise.quantity import restate_text, unit_factor
from fogdrift.noise.terms import TERM_TABLE, TERMS, term_table
from fogdrift.plausibility import check_record

G0 = 9.80665


def _csv(tmp_path, name, header, rows):
    p = tmp_path / name
    p.write_text(header + "\n" + "\n".join(",".join(repr(float(v)) for v in r) for r in rows) + "\n")
    return p


def _triad(n=400, seed=0, level=(0.0, 0.0, -1.0), noise=1e-3):
    rng = np.random.default_rng(seed)
    return np.asarray(level) + rng.normal(0.0, noise, (n, 3))


# ---------------------------------------------------------------------------------------------- reading
@pytest.mark.parametrize("name,expected", [
    ("ax", "specific_force"), ("a_y", "specific_force"), ("AZ", "specific_force"), ("acc_x", "specific_force"),
    ("accel", "specific_force"), ("accelerometer_z", "specific_force"), ("linear_acceleration.x", "specific_force"),
    ("gx", "angular_rate"), ("g_y", "angular_rate"), ("gyro_z", "angular_rate"), ("wx", "angular_rate"),
    ("omega_z", "angular_rate"), ("angular_velocity.x", "angular_rate"),
    ("x", None), ("z", None), ("ch0", None), ("temp", None), ("t_s", None), ("alpha", None),
])
def test_name_rule(name, expected):
    assert quantity_of_name(name) == expected


def test_unit_g_reads_an_accelerometer_in_m_s2(tmp_path):
    x = _triad()
    p = _csv(tmp_path, "a.csv", "t_s,ax,ay,az", [[0.01 * i, *r] for i, r in enumerate(x)])
    rec = load(p, unit="g")
    assert rec.quantities == ("specific_force",) * 3
    assert rec.signal.channels[2].internal_unit == "m/s^2"
    np.testing.assert_allclose(rec.data_internal, x * G0, rtol=1e-14)   # 1 g = 9.80665 m/s^2, by hand
    with pytest.raises(AttributeError, match=r"ax, ay, az of .*a\.csv hold a specific force in m/s\^2, not an "
                                             r"angular rate in deg/h: read \.data_internal"):
        rec.rate_dph                                                   # no deg/h name on m/s^2 numbers
    gyro = load(_csv(tmp_path, "g.csv", "t_s,gx", [[0.0, 1.0], [0.01, 2.0]]), unit="deg/s")
    assert gyro.rate_dph is gyro.data_internal and gyro.rate_dph[1, 0] == 7200.0


def test_unit_mg_factor(tmp_path):
    p = _csv(tmp_path, "a.csv", "t_s,ax", [[0.0, 1000.0], [0.01, 1000.0]])
    np.testing.assert_allclose(load(p, unit="mg").data_internal[:, 0], 9.80665, rtol=1e-14)
    np.testing.assert_allclose(load(p, unit="ug").data_internal[:, 0], 9.80665e-3, rtol=1e-14)


def test_header_declares_the_quantity_per_column(tmp_path):
    p = _csv(tmp_path, "m.csv", "t_s,gx[deg/s],gy[deg/s],ax[g],ay[g]", [[0.0, 1.0, 2.0, 0.5, -1.0],
                                                                         [0.01, 1.0, 2.0, 0.5, -1.0]])
    rec = load(p)
    assert rec.quantities == ("angular_rate", "angular_rate", "specific_force", "specific_force")
    np.testing.assert_allclose(rec.data_internal[0], [3600.0, 7200.0, 0.5 * G0, -G0], rtol=1e-14)
    assert rec.input_unit == "gx=deg/s,gy=deg/s,ax=g,ay=g"
    sub = rec.select("ax,ay")   # one unit again: the legacy fields are that unit's
    assert sub.input_unit == "g" and sub.scale_to_internal == G0
    with pytest.raises(AttributeError, match=r"ax, ay of .* read \.scale_to_internal"):
        sub.scale_to_dph                                    # the factor to m/s^2 is no factor to deg/h
    assert rec.select("gx").scale_to_dph == 3600.0 and rec.scale_to_internal == 1.0   # several units: no one factor


def test_per_quantity_unit_option(tmp_path):
    p = _csv(tmp_path, "m.csv", "t_s,gx,ax", [[0.0, 1.0, 1.0], [0.01, 1.0, 1.0]])
    rec = load(p, unit="gyro=deg/s,accel=mg")
    assert rec.quantities == ("angular_rate", "specific_force")
    np.testing.assert_allclose(rec.data_internal[0], [3600.0, G0 * 1e-3], rtol=1e-14)
    # a column's own entry wins; a neutral name needs one
    rec = load(p, unit="gyro=deg/s,accel=mg,ax=m/s^2")
    np.testing.assert_allclose(rec.data_internal[0, 1], 1.0)
    q = _csv(tmp_path, "n.csv", "t_s,x,ax", [[0.0, 1.0, 1.0], [0.01, 1.0, 1.0]])
    with pytest.raises(ConfigError, match=r"channel 'x' has a name that says neither gyro nor accelerometer"):
        load(q, unit="gyro=deg/s,accel=g")
    assert load(q, unit="x=deg/h,accel=g").quantities == ("angular_rate", "specific_force")


@pytest.mark.parametrize("header,unit,msg", [
    ("t_s,ax,ay,az", "deg/s", r"channel 'ax' is named as a specific-force \(accelerometer\) channel but unit= "
                              r"'deg/s' is an angular-rate \(gyro\) unit"),
    ("t_s,gx,gy,gz", "g", r"channel 'gx' is named as an angular-rate \(gyro\) channel but unit= 'g' is a "
                          r"specific-force \(accelerometer\) unit"),
    ("t_s,ax,ay,az", "gyro=deg/s", r"channel 'ax' is named as a specific-force \(accelerometer\) channel but "
                                   r"unit= 'gyro=deg/s' gives no accel= unit"),
    ("t_s,gx[g],gy[g],gz[g]", None, r"channel 'gx' is named as an angular-rate \(gyro\) channel but the unit 'g' "
                                    r"declared in the header"),
])
def test_never_silently_the_other_quantity(tmp_path, header, unit, msg):
    p = _csv(tmp_path, "a.csv", header, [[0.0, 1.0, 1.0, 1.0], [0.01, 1.0, 1.0, 1.0]])
    with pytest.raises(ConfigError, match=msg) as ei:
        load(p, unit=unit)
    assert "\n" not in str(ei.value)


def test_cli_flag_named_in_the_refusal(tmp_path):
    from fogdrift.cli._app import FLAGS

    p = _csv(tmp_path, "a.csv", "t_s,ax,ay,az", [[0.0, 1.0, 1.0, 1.0], [0.01, 1.0, 1.0, 1.0]])
    with pytest.raises(ConfigError) as ei:
        load(p, unit="deg/s")
    assert "--unit 'deg/s'" in ei.value.render(FLAGS)
    assert "--unit gyro=deg/s,accel=g" in ei.value.render(FLAGS)


def test_bad_unit_choice():
    with pytest.raises(ConfigError, match="accel= given twice"):
        parse_unit_choice("accel=g,accel=mg")
    with pytest.raises(ConfigError, match="unknown unit"):
        parse_unit_choice("accel=deg/s")          # accel= takes a specific-force unit only
    with pytest.raises(ConfigError, match="is not KEY=UNIT"):
        parse_unit_choice("gyro=deg/s,g")


# ---------------------------------------------------------------------------------------------- terms
def test_accel_factors_by_hand():
    t = term_table("specific_force")
    assert t["N"].to_unit == 60.0             # m/s/sqrt(s) -> m/s/sqrt(h): sqrt(h) = 60 sqrt(s)
    assert t["K"].to_unit == 60.0             # (m/s^2)/sqrt(s) -> m/s^2/sqrt(h)
    assert t["R"].to_unit == 3600.0           # (m/s^2)/s -> m/s^2/h
    assert t["Q"].to_unit == 1.0              # (m/s^2) s = m/s
    assert t["B"].to_unit == pytest.approx(1.0 / 9.80665e-6, rel=1e-14)  # m/s^2 -> ug
    assert [t[k].unit for k in TERMS] == ["m/s", "m/s/sqrt(h)", "ug", "m/s^2/sqrt(h)", "m/s^2/h"]
    assert t["N"].long_name == "velocity random walk" and t["K"].long_name == "acceleration random walk"
    # the Allan laws are the gyro's
    for k in TERMS:
        assert (t[k].avar_power, t[k].avar_coefficient, t[k].alpha) == \
            (TERM_TABLE[k].avar_power, TERM_TABLE[k].avar_coefficient, TERM_TABLE[k].alpha)


@pytest.mark.parametrize("term", TERMS)
def test_accel_units_agree_with_the_export_si_table(term):
    """Independent table (fogdrift.export.conversions, another author): reported unit -> SI is the law unit."""
    spec = term_table("specific_force")[term]
    x_law = 0.37
    si, si_unit, _ = to_si(spec.to_unit * x_law, term, spec.unit)
    assert si == pytest.approx(x_law, rel=1e-12), si_unit


def test_unit_factor_gyro_to_accel():
    assert unit_factor("N", "specific_force") == pytest.approx(3600.0)   # 60 / (1/60)
    assert unit_factor("B", "specific_force") == pytest.approx(1 / 9.80665e-6)
    assert unit_factor("N", "angular_rate") == 1.0
    assert restate_text("N = 0.01 deg/√h sits at its bound", "specific_force") == "N = 36 m/s/√h sits at its bound"
    assert restate_text("falls to 0.003 deg/h at tau", "specific_force") == "falls to 0.003 m/s^2 at tau"


def test_seeded_accelerometer_vrw_and_bias_instability_come_back():
    """VRW 0.2 m/s/sqrt(h) and B 0.2 mg (the ADIS16405 datasheet's typical values) simulated in m/s^2.

    Hand conversion: white noise of sigma per sample at dt has N = sigma sqrt(dt) [(m/s^2) sqrt(s)], so
    VRW [m/s/sqrt(h)] = 60 sigma sqrt(dt); 0.2 mg = 200 ug = 1.96133e-3 m/s^2 (the flat ADEV 0.664 B)."""
    from fogdrift.pipeline import AnalysisConfig, run_allan
    from fogdrift.simulate import simulate

    dt, n = 0.01, 2**20
    vrw, b_ug = 0.2, 200.0
    sigma = vrw / 60.0 / math.sqrt(dt)
    rng = np.random.default_rng(11)
    y = sigma * rng.standard_normal(n) + simulate(n, dt, bias_instability_dph=b_ug * 9.80665e-6, seed=12)
    rec = from_array(y, dt_s=dt, unit="m/s^2", axis_names=["az"])
    (a,) = run_allan(rec, AnalysisConfig().validate())
    assert a.noise.quantity == "specific_force"
    tn, tb = a.noise.terms["N"], a.noise.terms["B"]
    assert tn.unit == "m/s/sqrt(h)" and tb.unit == "ug"
    assert tn.lo95 <= vrw <= tn.hi95, (tn.lo95, tn.value, tn.hi95)
    assert abs(tn.value / vrw - 1) < 0.05
    assert tb.lo95 <= b_ug <= tb.hi95, (tb.lo95, tb.value, tb.hi95)
    d = a.noise.to_dict()
    assert d["quantity"] == "specific_force"
    assert d["terms"]["B"]["si"]["value"] == pytest.approx(tb.value * 9.80665e-6, rel=1e-12)
    assert d["b_min"]["unit"] == "ug"


# ---------------------------------------------------------------------------------------------- plausibility
def test_static_triad_reads_one_g():
    x = _triad(2000)
    assert [f for f in check_record(from_array(x, dt_s=0.01, unit="g", axis_names=["ax", "ay", "az"]))
            if f.rule == "gravity"] == []
    bad = [f for f in check_record(from_array(x, dt_s=0.01, unit="mg", axis_names=["ax", "ay", "az"]))
           if f.rule == "gravity"]
    assert len(bad) == 1 and bad[0].likely_units == ("g",) and "0.001 g" in bad[0].message


def test_a_gyro_reading_gravity_is_flagged():
    x = _triad(2000, level=(0.0, 0.0, 9.81))
    found = [f for f in check_record(from_array(x, dt_s=0.01, unit="deg/s", axis_names=["x", "y", "z"]))
             if f.rule == "gravity"]
    assert len(found) == 1 and found[0].likely_units == ("m/s^2",)
    # a MEMS gyro's turn-on bias (ADIS16405: 0.40, -0.42, -0.29 deg/s) is not gravity
    y = _triad(2000, level=(0.40, -0.42, -0.29), noise=0.04)
    assert [f for f in check_record(from_array(y, dt_s=0.01, unit="deg/s", axis_names=["gx", "gy", "gz"]))
            if f.rule == "gravity"] == []


def test_gmwm_reading_restated_for_an_accelerometer():
    """White noise of sigma [m/s^2] per sample at dt: N = sigma sqrt(dt) (m/s^2) sqrt(s) = 60 sigma sqrt(dt) m/s/sqrt(h)."""
    from fogdrift.gmwm.analysis import analyse_gmwm
    from fogdrift.gmwm.quantity import accel_rows, express_gmwm
    from fogdrift.gmwm.analysis import ieee_rows

    dt, sigma = 0.01, 0.0333
    y = sigma * np.random.default_rng(3).standard_normal(2**15)
    gyro = analyse_gmwm("az", y, dt, model="WN")
    acc = express_gmwm(gyro, "specific_force")
    n_g, n_a = gyro.selection.ieee.terms["N_dprh"], acc.selection.ieee.terms["N_dprh"]
    assert n_a.unit == "m/s/sqrt(h)" and n_a.value == pytest.approx(3600.0 * n_g.value, rel=1e-12)
    assert n_a.lo95 <= 60.0 * sigma * math.sqrt(dt) <= n_a.hi95
    assert "Q_arcsec" not in acc.selection.ieee.terms
    assert express_gmwm(gyro, "angular_rate") is gyro
    b = [r for r in accel_rows(ieee_rows(acc)) if r[0] == "B"][0]
    assert b[4] == "µg"


def test_allan_outputs_of_an_accelerometer_say_m_s2(tmp_path):
    from fogdrift.pipeline import AnalysisConfig, run_allan
    from fogdrift.report import write_allan_outputs

    y = 0.01 * np.random.default_rng(2).standard_normal((4096, 2))
    acc = from_array(y, dt_s=0.01, unit="m/s^2", axis_names=["ax", "ay"])
    write_allan_outputs(run_allan(acc, AnalysisConfig(terms=["N"]).validate()), acc, tmp_path)
    head = (tmp_path / "allan.csv").read_text().splitlines()[0]
    assert head.startswith("axis,tau_s,m,adev_mps2,avar_m2ps4,") and "dph" not in head
    gyro = from_array(y, dt_s=0.01, unit="deg/h", axis_names=["gx", "gy"])
    write_allan_outputs(run_allan(gyro, AnalysisConfig(terms=["N"]).validate()), gyro, tmp_path)
    assert (tmp_path / "allan.csv").read_text().splitlines()[0].startswith("axis,tau_s,m,adev_dph,avar_dph2,")


def test_gyro_only_commands_refuse_accelerometer_channels(tmp_path):
    from fogdrift.cli._app import gyro_only
    from fogdrift.compensate.sources import open_log

    p = _csv(tmp_path, "a.csv", "t_s,ax,ay,az", [[0.01 * i, *r] for i, r in enumerate(_triad(300))])
    with pytest.raises(ConfigError, match="compensate applies a gyro drift model; ax, ay, az are accelerometer"):
        open_log(p, unit="g")
    with pytest.raises(ConfigError, match="fogdrift analyze models gyro drift and its heading error; ax, ay, az are "
                                          "accelerometer channels"):
        gyro_only(load(p, unit="g"), "analyze")
    gyro_only(from_array(np.zeros((4, 1)), dt_s=0.01, unit="deg/s", axis_names=["gz"]), "analyze")  # a gyro passes


def _keys_and_texts(doc, path=""):
    """Every key path and every string value of a JSON document."""
    if isinstance(doc, dict):
        for k, v in doc.items():
            yield "key", f"{path}/{k}"
            yield from _keys_and_texts(v, f"{path}/{k}")
    elif isinstance(doc, list):
        for i, v in enumerate(doc):
            yield from _keys_and_texts(v, f"{path}[{i}]")
    elif isinstance(doc, str):
        yield "text", f"{path}: {doc}"


def test_allan_json_of_an_accelerometer_names_m_s2_everywhere(tmp_path):
    """No key or text of an accelerometer's allan.json says deg/h (dph, deg/...): the curve's keys are the CSV's
    columns, the record names its internal unit, the shaped terms' descriptions and the outliers are in m/s^2."""
    import json

    from fogdrift.pipeline import AnalysisConfig, run_allan
    from fogdrift.report import write_allan_outputs

    rng = np.random.default_rng(5)
    n, dt = 2**15, 0.01
    y = 0.01 * rng.standard_normal((n, 2)) + 0.004 * np.sin(2 * np.pi * 5.0 * dt * np.arange(n))[:, None]
    y[[100, 9000, 20000], 0] += 0.5                                   # outliers: their sigma is written too
    acc = from_array(y, dt_s=dt, unit="m/s^2", axis_names=["ax", "ay"])
    axes = run_allan(acc, AnalysisConfig().validate())
    write_allan_outputs(axes, acc, tmp_path)
    doc = json.loads((tmp_path / "allan.json").read_text())
    found = list(_keys_and_texts(doc))
    assert [p for kind, p in found if kind == "key" and ("dph" in p.rsplit("/", 1)[1])] == []
    assert [p for kind, p in found if kind == "text" and "deg" in p.split(": ", 1)[1]] == []
    assert any(p.endswith("/shaped/S/description") for kind, p in found if kind == "key")   # the tone was there
    assert any(p.endswith("/outliers/robust_sigma_mps2") for kind, p in found if kind == "key")
    chans = doc["record"]["signal"]["channels"]
    assert {(c["internal_unit"], c["scale_to_internal"]) for c in chans} == {("m/s^2", 1.0)}
    head = (tmp_path / "allan.csv").read_text().splitlines()[0].split(",")
    curve = doc["axes"][0]["allan"]
    assert set(head[1:]) <= set(curve)                                  # the JSON's keys are the CSV's columns
    np.testing.assert_array_equal(curve["adev_mps2"], axes[0].allan.dev)
    np.testing.assert_array_equal(curve["avar_m2ps4"], axes[0].allan.var)
    gyro = from_array(y, dt_s=dt, unit="deg/h", axis_names=["gx", "gy"])     # a gyro's keys stay deg/h
    write_allan_outputs(run_allan(gyro, AnalysisConfig().validate()), gyro, tmp_path)
    g = json.loads((tmp_path / "allan.json").read_text())
    assert g["record"]["signal"]["channels"][0]["internal_unit"] == "deg/h" and "adev_dph" in g["axes"][0]["allan"]
    assert "robust_sigma_dph" in g["axes"][0]["outliers"]
