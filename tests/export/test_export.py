"""fogdrift export: conversions by hand, the --missing policy, every target read back by the parser its project uses
(OpenCV's FileStorage for OpenVINS / VINS-Fusion / ORB-SLAM3, PyYAML for Kalibr and KF-GINS, the MATLAB name-value
pairs, gnss-ins-sim's dictionary executed), and the CLI's one-line errors."""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from fogdrift.cli import app
from fogdrift.errors import ConfigError, DataFormatError
from fogdrift.export import build_context, parse_targets, render
from fogdrift.export.conversions import (arw_to_density, density_to_arw, gm_discrete, rrw_to_density,
                                         single_gm_from_flicker, to_si, vrw_to_density, walk_discrete,
                                         white_discrete)
from fogdrift.export.model import channels_from_result, resolve
from fogdrift.models.statespace import gm_avar_dph2

D = math.pi / 180.0
G = 9.80665
runner = CliRunner()


# ------------------------------------------------------------------------------------------------------------------
# result files built by hand (the shapes fogdrift allan writes)
# ------------------------------------------------------------------------------------------------------------------
def _record(fs_hz, **extra):
    """A result's record block as fogdrift writes it, reduced to what export reads: the sampling in
    ``signal.sampling`` (its one home in a result) and ``extra`` (``sha256``)."""
    return {"signal": {"sampling": {"dt_s": 1.0 / fs_hz, "dt_source": "argument"}}, **extra}


def _term(name, value, lo, hi, unit, status, reason=""):
    return {"name": name, "value": value, "unit": unit, "lo95": lo, "hi95": hi, "status": status,
            "estimable": status in ("resolved", "unresolved"), "reason": reason}


def _allan_axis(name, terms, *, b_tau=100.0, selected=("N", "B", "K"), no_fit=None, units=None):
    units = units or {"Q": "urad", "N": "deg/sqrt(h)", "B": "deg/h", "K": "deg/h^1.5", "R": "deg/h^2"}
    t = {}
    for k in ("Q", "N", "B", "K", "R"):
        spec = terms.get(k)
        if spec is None:
            t[k] = _term(k, None, 0.0, 0.3, units[k], "absent", "not in the model: the curve shows no sign of it")
        else:
            t[k] = _term(k, *spec[:3], units[k], spec[3], spec[4] if len(spec) > 4 else "")
    return {"name": name, "noise": {
        "statistic": "adev", "dt_s": 0.01, "selected": list(selected), "terms": t, "A": [0, 0, 0, 0, 0],
        "fit": {"tau_min_s": 0.1, "tau_max_s": 1000.0, "chi2_red": 1.1, "quality": "good"},
        "b_min": {"value": None, "unit": units["B"], "tau_s": b_tau, "bound_only": False, "lo95": None, "hi95": None,
                  "rule": "min of the fitted ADEV / 0.664"},
        "shaped": {}, "no_fit": no_fit}}


def _gyro_result(tmp_path, name="gyro.json", **kw):
    axes = [_allan_axis("gx", {"N": (0.15, 0.14, 0.16, "resolved"), "B": (2.0, 1.5, 2.5, "resolved"),
                               "K": (0.5, 0.3, 0.7, "resolved")}, **kw),
            _allan_axis("gy", {"N": (0.20, 0.19, 0.21, "resolved"), "B": (3.0, 2.5, 3.5, "resolved"),
                               "K": (0.4, 0.2, 0.6, "resolved")}, **kw),
            _allan_axis("gz", {"N": (0.10, 0.09, 0.11, "resolved"), "B": (1.0, 0.5, 1.5, "resolved")},
                        selected=("N", "B"), **kw)]
    doc = {"source": "sim", "record": _record(100.0, sha256="ab" * 32), "axes": axes}
    p = tmp_path / name
    p.write_text(json.dumps(doc))
    return p


_ACC_UNITS = {"Q": "m/s", "N": "m/s/sqrt(h)", "B": "ug", "K": "m/s^2/sqrt(s)", "R": "m/s^3"}


def _accel_result(tmp_path):
    axes = [_allan_axis(a, {"N": (0.06 * (i + 1), 0.05, 0.2, "resolved"), "B": (50.0 * (i + 1), 40.0, 200.0, "resolved"),
                            "K": (1e-4 * (i + 1), 5e-5, 4e-4, "resolved")}, units=_ACC_UNITS)
            for i, a in enumerate(("ax", "ay", "az"))]
    p = tmp_path / "accel.json"
    p.write_text(json.dumps({"source": "sim", "record": _record(100.0), "axes": axes}))
    return p


# ------------------------------------------------------------------------------------------------------------------
# conversions (hand-computed)
# ------------------------------------------------------------------------------------------------------------------
def test_arw_density_hand_values():
    # 0.15 deg/sqrt(h) = 0.15 * (pi/180) rad / sqrt(3600 s) = 0.15 * 0.01745329 / 60 = 4.3633e-5 rad/s/sqrt(Hz)
    assert arw_to_density(0.15) == pytest.approx(4.3633e-5, rel=1e-4, abs=0)
    assert density_to_arw(4.3633e-5) == pytest.approx(0.15, rel=1e-4, abs=0)
    assert vrw_to_density(0.06) == pytest.approx(0.001, rel=1e-12, abs=0)          # 0.06 m/s/sqrt(h) / 60
    # 1 deg/h^1.5 = (pi/180) / 3600^1.5 rad/s^1.5 = 0.01745329 / 216000 = 8.0802e-8
    assert rrw_to_density(1.0) == pytest.approx(8.0802e-8, rel=1e-4, abs=0)


def test_to_si_units_and_unknown_unit():
    assert to_si(0.2, "B", "mg")[0] == pytest.approx(0.2e-3 * G, rel=1e-12, abs=0)
    assert to_si(50.0, "B", "ug")[0] == pytest.approx(50e-6 * G, rel=1e-12, abs=0)
    assert to_si(1.0, "B", "mGal")[0] == pytest.approx(1e-5, rel=1e-12, abs=0)
    assert to_si(3.6, "B", "deg/h")[0] == pytest.approx(1e-3 * D, rel=1e-12, abs=0)   # 3.6 deg/h = 0.001 deg/s
    assert to_si(2.0, "N", "deg/√h")[0] == pytest.approx(2 * D / 60, rel=1e-12, abs=0)
    with pytest.raises(ConfigError, match="not one fogdrift can convert; expected one of"):
        to_si(1.0, "N", "furlong/fortnight")


def test_continuous_to_discrete_directions():
    # white noise grows with the rate, a random walk's per-sample step shrinks with it (Kalibr wiki)
    assert white_discrete(1e-3, 400.0) == pytest.approx(0.02)
    assert walk_discrete(1e-3, 400.0) == pytest.approx(5e-5)
    phi, q = gm_discrete(2.0, 10.0, 10.0)   # dt = 0.1 s, T_c = 10 s
    assert phi == pytest.approx(math.exp(-0.01))
    assert q == pytest.approx(2.0 * math.sqrt(1 - math.exp(-0.02)))


def test_single_gm_peak_is_the_flicker_floor():
    b, tau_b = 5.0, 300.0
    sigma, tc = single_gm_from_flicker(b, tau_b)
    taus = np.geomspace(tau_b / 10, tau_b * 10, 2001)
    adev = np.sqrt(gm_avar_dph2(taus, tc, sigma))
    assert adev.max() == pytest.approx(0.664282 * b, rel=1e-4, abs=0)     # flicker ADEV floor sqrt(2 ln2 / pi) B
    assert taus[adev.argmax()] == pytest.approx(tau_b, rel=5e-3, abs=0)


# ------------------------------------------------------------------------------------------------------------------
# targets read back by their projects' parsers
# ------------------------------------------------------------------------------------------------------------------
@pytest.fixture
def ctx(tmp_path):
    return build_context([_gyro_result(tmp_path)], [_accel_result(tmp_path)])


def test_kalibr_pyyaml(ctx):
    d = yaml.safe_load(render("kalibr", ctx))
    # one value for all axes: the largest (gy N 0.20 deg/sqrt(h), gx K 0.5 deg/h^1.5; az VRW 0.18, az K 3e-4)
    assert d["gyroscope_noise_density"] == pytest.approx(0.20 * D / 60, rel=1e-5, abs=0)
    assert d["gyroscope_random_walk"] == pytest.approx(0.5 * D / 216000, rel=1e-5, abs=0)
    assert d["accelerometer_noise_density"] == pytest.approx(0.18 / 60, rel=1e-5, abs=0)
    assert d["accelerometer_random_walk"] == pytest.approx(3e-4, rel=1e-5, abs=0)
    assert d["update_rate"] == 100.0 and d["rostopic"] == "/imu0"


def _cv(text, tmp_path, name):
    cv2 = pytest.importorskip("cv2")  # opencv-python-headless, in the test extras
    p = tmp_path / name
    p.write_text(text)
    fs = cv2.FileStorage(str(p), cv2.FILE_STORAGE_READ)
    assert fs.isOpened()
    return fs


def test_openvins_vins_orbslam3_read_by_opencv(ctx, tmp_path):
    fs = _cv(render("openvins", ctx), tmp_path, "ov.yaml")
    imu0 = fs.getNode("imu0")
    assert imu0.getNode("gyroscope_noise_density").real() == pytest.approx(0.20 * D / 60, rel=1e-5, abs=0)
    assert imu0.getNode("accelerometer_random_walk").real() == pytest.approx(3e-4, rel=1e-5, abs=0)
    assert imu0.getNode("update_rate").real() == 100.0
    assert imu0.getNode("T_i_b").size() == 4
    fs.release()
    fs = _cv(render("vins-fusion", ctx), tmp_path, "vins.yaml")
    # per IMU step at 100 Hz (integration_base.h): white x sqrt(2 f) = x sqrt(200), walk x sqrt(f) = x 10
    assert fs.getNode("gyr_n").real() == pytest.approx(0.20 * D / 60 * math.sqrt(200), rel=1e-5, abs=0)
    assert fs.getNode("acc_n").real() == pytest.approx(0.18 / 60 * math.sqrt(200), rel=1e-5, abs=0)
    assert fs.getNode("gyr_w").real() == pytest.approx(0.5 * D / 216000 * 10, rel=1e-5, abs=0)
    assert fs.getNode("acc_w").real() == pytest.approx(3e-4 * 10, rel=1e-5, abs=0)
    fs.release()
    fs = _cv(render("orbslam3", ctx), tmp_path, "orb.yaml")
    assert fs.getNode("IMU.NoiseGyro").real() == pytest.approx(0.20 * D / 60, rel=1e-5, abs=0)
    assert fs.getNode("IMU.NoiseAcc").real() == pytest.approx(0.18 / 60, rel=1e-5, abs=0)
    assert fs.getNode("IMU.GyroWalk").real() == pytest.approx(0.5 * D / 216000, rel=1e-5, abs=0)
    assert fs.getNode("IMU.AccWalk").real() == pytest.approx(3e-4, rel=1e-5, abs=0)
    assert fs.getNode("IMU.Frequency").real() == 100.0
    fs.release()


def test_kfgins_units(ctx):
    d = yaml.safe_load(render("kf-gins", ctx))["imunoise"]
    assert d["arw"] == pytest.approx([0.15, 0.20, 0.10], rel=1e-5, abs=0)            # deg/sqrt(h), per axis
    assert d["vrw"] == pytest.approx([0.06, 0.12, 0.18], rel=1e-5, abs=0)            # m/s/sqrt(h)
    # one GM per bias matched to B: sigma = 1.0760 B [deg/h]; abstd in mGal (1 ug = 0.980665 mGal)
    assert d["gbstd"] == pytest.approx([1.0760 * 2.0, 1.0760 * 3.0, 1.0760 * 1.0], rel=1e-4, abs=0)
    assert d["abstd"] == pytest.approx([1.0760 * 50 * 0.980665, 1.0760 * 100 * 0.980665, 1.0760 * 150 * 0.980665],
                                       rel=1e-4, abs=0)
    assert d["corrtime"] == pytest.approx(100.0 / 1.8926 / 3600.0, rel=1e-4, abs=0)  # hours
    assert d["gsstd"] == [300.0] * 3 and d["asstd"] == [300.0] * 3          # not measured: KF-GINS's example value


def test_matlab_name_value_pairs(ctx):
    text = render("matlab", ctx)

    def vec(obj, key):
        block = text[text.index(f"{obj} = "):]
        m = re.search(rf"'{key}', \[([^\]]*)\]", block)
        return [float(v) for v in m.group(1).split()]

    assert vec("gyro", "NoiseDensity") == pytest.approx([0.15 * D / 60, 0.20 * D / 60, 0.10 * D / 60], rel=1e-5, abs=0)
    assert vec("gyro", "BiasInstability") == pytest.approx([2.0 * D / 3600, 3.0 * D / 3600, 1.0 * D / 3600], rel=1e-5, abs=0)
    assert vec("accel", "BiasInstability") == pytest.approx([50e-6 * G, 100e-6 * G, 150e-6 * G], rel=1e-5, abs=0)
    assert vec("accel", "RandomWalk") == pytest.approx([1e-4, 2e-4, 3e-4], rel=1e-5, abs=0)
    assert "imuSensor('accel-gyro', 'SampleRate', 100.0, 'Gyroscope', gyro, 'Accelerometer', accel)" in text


def test_gnss_ins_sim_dictionary(ctx):
    ns = {}
    exec(render("gnss-ins-sim", ctx), ns)  # noqa: S102 - our own generated file
    err = ns["imu_err"]
    assert err["gyro_arw"] == pytest.approx([0.15, 0.20, 0.10], rel=1e-5, abs=0)            # deg/sqrt(h)
    assert err["gyro_b_stability"] == pytest.approx([1.0760 * 2, 1.0760 * 3, 1.0760], rel=1e-4, abs=0)  # deg/h
    assert err["gyro_b_corr"] == pytest.approx([100 / 1.8926] * 3, rel=1e-4, abs=0)          # s
    assert err["accel_vrw"] == pytest.approx([0.06, 0.12, 0.18], rel=1e-5, abs=0)
    assert err["accel_b_stability"][0] == pytest.approx(1.0760 * 50e-6 * G, rel=1e-4, abs=0)  # m/s^2
    assert list(err["gyro_b"]) == [0.0, 0.0, 0.0]


def test_every_number_carries_its_provenance(ctx):
    text = render("kalibr", ctx)
    i = text.index("gyroscope_noise_density:")
    before = text[:i]
    assert "gy: N = 0.2 [0.19, 0.21] deg/sqrt(h) [resolved]" in before
    assert "continuous 5.81776e-05 rad/s/sqrt(Hz)" in before                 # 0.2 * pi/180 / 60
    assert "discrete 0.000581776 rad/s per sample at 100.0 Hz" in before     # x sqrt(100)
    assert "x 0.000290888 (deg/sqrt(h) -> rad/s/sqrt(Hz))" in before


def test_json_has_terms_and_van_loan_state_space(ctx):
    d = json.loads(render("json", ctx))
    gx = next(c for c in d["channels"] if c["name"] == "gx")
    assert gx["export_values"]["N"]["si"] == pytest.approx(0.15 * D / 60, rel=1e-9, abs=0)
    assert gx["export_values"]["N"]["discrete_sigma"] == pytest.approx(0.15 * D / 60 * 10, rel=1e-9, abs=0)
    ss = gx["state_space"]
    assert ss["check_max_abs"] < 1e-12
    white = next(t for t in ss["continuous_terms"] if t["kind"] == "white")
    assert white["density"] == pytest.approx(0.15 * D / 60, rel=1e-9, abs=0) and white["unit"] == "rad/s/sqrt(Hz)"
    rw = next(t for t in ss["continuous_terms"] if t["kind"] == "random_walk")
    assert rw["density"] == pytest.approx(0.5 * D / 216000, rel=1e-9, abs=0)
    states = ss["discrete"]["states"]
    assert states[:2] == ["bias", "random_walk"]
    i = states.index("random_walk")
    k = 0.5 * D / 216000                                                     # K in rad/s^2/sqrt(Hz)
    assert ss["discrete"]["Qd"][i][i] == pytest.approx(k * k * 0.01, rel=1e-9, abs=0)
    assert ss["discrete"]["r"] == pytest.approx((0.15 * D / 60) ** 2 / 0.01, rel=1e-9, abs=0)
    for j, s in enumerate(states):
        if s.startswith("gm_"):
            tc = -1.0 / ss["continuous"]["F"][j][j]
            assert ss["discrete"]["Phi"][j][j] == pytest.approx(math.exp(-0.01 / tc), rel=1e-12, abs=0)


# ------------------------------------------------------------------------------------------------------------------
# the --missing policy, missing quantities, no model fits
# ------------------------------------------------------------------------------------------------------------------
def test_missing_policies(tmp_path):
    chans = channels_from_result(json.loads(_gyro_result(tmp_path).read_text()), "g")
    gz = next(c for c in chans if c.name == "gz")                 # K absent, 95 % upper bound 0.3 deg/h^1.5
    r = resolve(gz, "K", "bound")
    assert r.how == "bound" and r.si == pytest.approx(0.3 * D / 216000)
    assert "95 % upper bound" in r.note
    assert resolve(gz, "K", "zero").si == 0.0
    with pytest.raises(ConfigError, match=r"gyro gz: K is not resolved by the record: not in the model.*upper bound is 0.3"):
        resolve(gz, "K", "refuse")
    ctx = build_context([_gyro_result(tmp_path)], missing="zero")
    d = yaml.safe_load(render("kalibr", ctx))
    assert d["gyroscope_random_walk"] == pytest.approx(0.5 * D / 216000)   # the largest axis, not gz's 0
    assert any("gz: K written as 0" in n for n in ctx.notes)


def test_no_accel_result_writes_the_programs_default_said_as_not_measured(tmp_path):
    ctx = build_context([_gyro_result(tmp_path)])
    text = render("kalibr", ctx)
    d = yaml.safe_load(text)
    # Kalibr requires both accelerometer keys (> 0): OpenVINS's own default is written, said as NOT MEASURED
    assert d["accelerometer_noise_density"] == 2.0e-3 and d["accelerometer_random_walk"] == 3.0e-3
    assert "NOT MEASURED: no accelerometer result was given" in text
    assert any("no accelerometer result given" in n and "NOT MEASURED" in n for n in ctx.notes)
    assert "no accelerometer result" in "; ".join(ctx.todo["kalibr"][1])
    text = render("matlab", ctx)          # MATLAB's imuSensor has an ideal default: the object is left out
    assert "accelparams(" not in text and "ideal default" in text


def test_no_model_fits_makes_every_term_missing(tmp_path):
    p = _gyro_result(tmp_path, no_fit={"best_candidate": "N+B+K"})
    chans = channels_from_result(json.loads(p.read_text()), "g")
    with pytest.raises(ConfigError, match="no model fits the record"):
        resolve(chans[0], "N", "refuse")
    assert resolve(chans[0], "N", "bound").si == pytest.approx(0.16 * D / 60)   # its upper end, said as a bound


# ------------------------------------------------------------------------------------------------------------------
# errors: one line each
# ------------------------------------------------------------------------------------------------------------------
def test_errors(tmp_path):
    with pytest.raises(ConfigError, match="unknown export target 'kalibur'; expected one of kalibr, openvins"):
        parse_targets("kalibur")
    assert parse_targets("all")[0] == "kalibr" and len(parse_targets("all")) == 8
    with pytest.raises(DataFormatError, match="no such result file"):
        build_context([tmp_path / "nope.json"])
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    with pytest.raises(DataFormatError, match="not a JSON file"):
        build_context([bad])
    bad.write_text('{"hello": 1}')
    with pytest.raises(DataFormatError, match="not a fogdrift allan or noise result"):
        build_context([bad])
    with pytest.raises(DataFormatError, match="--accel was given a gyro result"):
        build_context(accel=[_gyro_result(tmp_path)])
    with pytest.raises(ConfigError, match="--missing must be one of bound, refuse, zero|missing= must be one of"):
        build_context([_gyro_result(tmp_path)], missing="maybe")


def test_cli_errors_are_one_line(tmp_path):
    g = _gyro_result(tmp_path)
    res = runner.invoke(app, ["export", "--gyro", str(g), "--target", "kalibur", "--out", str(tmp_path / "o")])
    assert res.exit_code == 1
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and "unknown export target 'kalibur'; expected one of kalibr" in lines[0]
    res = runner.invoke(app, ["export", "--gyro", str(tmp_path / "x.json"), "--out", str(tmp_path / "o")])
    assert res.exit_code == 1 and "no such result file" in res.output and "Traceback" not in res.output
    res = runner.invoke(app, ["export", "--gyro", str(g), "--missing", "refuse", "--out", str(tmp_path / "o")])
    assert res.exit_code == 1 and "pass --missing bound or zero" in res.output
    assert not (tmp_path / "o" / "imu.yaml").exists()              # refused before any file was written


def test_cli_writes_every_target(tmp_path):
    res = runner.invoke(app, ["export", "--gyro", str(_gyro_result(tmp_path)), "--accel", str(_accel_result(tmp_path)),
                              "--update-rate", "200", "--out", str(tmp_path / "o")])
    assert res.exit_code == 0, res.output
    names = sorted(p.name for p in (tmp_path / "o").iterdir() if not p.name.startswith("."))
    assert names == sorted(["imu.yaml", "kalibr_imu_chain.yaml", "vins_imu.yaml", "orbslam3_imu.yaml",
                            "kf-gins_imunoise.yaml", "imu_params.m", "gnss_ins_sim_imu_err.py", "noise_model.json"])
    d = yaml.safe_load((tmp_path / "o" / "imu.yaml").read_text())
    assert d["update_rate"] == 200.0
    assert "K is its 95 % upper bound" in res.output                   # gz: the bound is said, not hidden


def test_six_channel_result_split_by_units(tmp_path):
    g = json.loads(_gyro_result(tmp_path).read_text())
    a = json.loads(_accel_result(tmp_path).read_text())
    six = tmp_path / "six.json"
    six.write_text(json.dumps({"record": _record(100.0), "axes": g["axes"] + a["axes"]}))
    ctx = build_context(results=[six])
    assert [c.name for c in ctx.gyro] == ["gx", "gy", "gz"] and [c.name for c in ctx.accel] == ["ax", "ay", "az"]
    d = yaml.safe_load(render("kalibr", ctx))
    assert d["accelerometer_noise_density"] == pytest.approx(0.18 / 60, rel=1e-5, abs=0)
    res = runner.invoke(app, ["export", "--result", str(six), "--target", "orbslam3", "--out", str(tmp_path / "o")])
    assert res.exit_code == 0, res.output
    fs = _cv((tmp_path / "o" / "orbslam3_imu.yaml").read_text(), tmp_path, "orb_back.yaml")
    assert fs.getNode("IMU.NoiseAcc").real() == pytest.approx(0.18 / 60, rel=1e-5, abs=0)
    fs.release()


def _gmwm_axis(name, n, k, gms):
    terms = {"N_dprh": {"name": "N_dprh", "value": n, "lo95": n * 0.9, "hi95": n * 1.1, "unit": "deg/sqrt(h)",
                        "component": "WN"}}
    if k is not None:
        terms["K_dphrh"] = {"name": "K_dphrh", "value": k, "lo95": 0.0, "hi95": 2 * k, "unit": "deg/h/sqrt(h)",
                            "component": "RW"}
    gm = [{"component": f"GM{i + 1}",
           "tc_s": {"name": "tc_s", "value": tc, "lo95": tc / 2, "hi95": tc * 2, "unit": "s"},
           "sigma_gm_dph": {"name": "sigma_gm_dph", "value": s, "lo95": s / 2, "hi95": s * 2, "unit": "deg/h"}}
          for i, (tc, s) in enumerate(gms)]
    b = {"rule": "min-avar", "value_dph": None, "lo95_dph": None, "hi95_dph": None, "tau_s": 1000.0,
         "bound_dph": 9.0, "reason": "95 % upper bound", "label": "min of the model's ADEV / 0.664"}
    return {"name": name, "method": "gmwm", "selected": "WN+RW+2GM",
            "selection": {"ieee": {"model": "WN+RW+2GM", "terms": terms, "gm": gm, "b_headline": b,
                                   "tau_range_s": [0.1, 1000.0], "dt_s": 0.01}}}


def test_gmwm_result_slowest_gm_is_the_bias(tmp_path):
    p = tmp_path / "noise.json"
    p.write_text(json.dumps({"fogdrift_result": "noise", "method": "gmwm", "record": _record(100.0),
                             "axes": [_gmwm_axis("gx", 0.3, 2.0, [(0.2, 50.0), (150.0, 4.0)]),
                                      _gmwm_axis("gy", 0.3, None, [(80.0, 3.0)])]}))
    ctx = build_context([p], missing="zero")
    d = yaml.safe_load(render("kf-gins", ctx))["imunoise"]
    # the slow GMs (gx 4 deg/h at 150 s, not the 0.2-s one; gy 3 deg/h at 80 s); KF-GINS takes ONE corrtime: the
    # geometric mean sqrt(150 * 80) s, each sigma re-matched so that its Allan variance at its own peak
    # (tau = 1.8926 T_c) is kept: sigma' = sigma sqrt(g(1.8926) / g(1.8926 T_c / T)), g(x) = (2x-3+4e^-x-e^-2x)/x^2
    tc = math.sqrt(150.0 * 80.0)

    def g(x):
        return (2 * x - 3 + 4 * math.exp(-x) - math.exp(-2 * x)) / x ** 2

    hand = [s * math.sqrt(g(1.8926) / g(1.8926 * t / tc)) for s, t in ((4.0, 150.0), (3.0, 80.0))]
    assert d["gbstd"][:2] == pytest.approx(hand, rel=1e-4, abs=0)
    assert d["gbstd"][2] == d["gbstd"][0]                                  # two axes: the third copies the largest
    assert d["corrtime"] == pytest.approx(tc / 3600.0, rel=1e-5, abs=0)
    k = yaml.safe_load(render("kalibr", ctx))["gyroscope_random_walk"]
    assert k == pytest.approx(2.0 * D / 216000, rel=1e-5, abs=0)             # gy has no RW: 0 under --missing zero
    with pytest.raises(ConfigError, match="gyro gy: K is not resolved by the record: not in the GMWM model"):
        render("kalibr", build_context([p]))                           # no bound from GMWM: refused, not guessed
    # with the wavelet variance in the result, K is bounded by its longest scale: tau = 2^17 samples at dt 0.01 s,
    # WV 95 % upper end 3.0 (deg/h)^2: gamma^2 = 3 * 12 tau / (tau^2 + 2), K = 60 sqrt(gamma^2 / dt) deg/h^1.5
    doc = json.loads(p.read_text())
    doc["axes"][1]["wvar"] = {"tau_samples": [2, 2 ** 17], "ci_hi95_dph2": [9.0, 3.0], "dt_s": 0.01,
                              "scale_s": [0.02, 1310.72]}
    p.write_text(json.dumps(doc))
    ctx = build_context([p])
    gy = ctx.gyro[1]
    tau = 2.0 ** 17
    k_bound = 60 * math.sqrt(3.0 * 12 * tau / (tau * tau + 2) / 0.01)
    assert gy.terms["K"].hi95 == pytest.approx(k_bound, rel=1e-12, abs=0)
    assert resolve(gy, "K", "bound").si == pytest.approx(k_bound * D / 216000, rel=1e-12, abs=0)
    assert "longest scale (1311 s)" in gy.terms["K"].reason


@pytest.mark.parametrize("cut", ["noise", "terms", "N", "unit", "fit", "record", "value", "selection"])
def test_damaged_results_give_one_line_errors(tmp_path, cut):
    def strip(obj):
        if isinstance(obj, dict):
            return {k: strip(v) for k, v in obj.items() if k != cut}
        if isinstance(obj, list):
            return [strip(v) for v in obj]
        return obj

    doc = strip(json.loads(_gyro_result(tmp_path).read_text()))
    p = tmp_path / "damaged.json"
    p.write_text(json.dumps(doc))
    try:
        ctx = build_context([p])
        for t in ("kalibr", "kf-gins", "json"):
            render(t, ctx)
    except (ConfigError, DataFormatError) as exc:
        assert "\n" not in str(exc)


@pytest.mark.parametrize("field, bad", [("value", -0.1), ("lo95", -1e-9), ("hi95", float("inf")), ("value", "0.15"),
                                        ("value", True)])
def test_a_negative_or_non_finite_coefficient_is_refused_naming_file_axis_and_term(tmp_path, field, bad):
    """A result edited by hand or written by another tool: N = -0.1 (or an infinite bound, a string) never reaches
    a filter's configuration; the one-line error names the file, the axis, the term and the field."""
    doc = json.loads(_gyro_result(tmp_path).read_text())
    doc["axes"][1]["noise"]["terms"]["N"][field] = bad
    p = tmp_path / "edited.json"
    p.write_text(json.dumps(doc).replace("Infinity", "1e999"))  # strict JSON has no infinity: a huge number
    with pytest.raises(DataFormatError, match=r"edited\.json: axis 'gy': N " + field) as exc:
        build_context([p])
    assert "\n" not in str(exc.value) and ">= 0" in str(exc.value)
    res = runner.invoke(app, ["export", "--gyro", str(p), "--target", "kalibr", "--out", str(tmp_path / "k")])
    assert res.exit_code != 0 and not (tmp_path / "k").exists()  # nothing written


def test_a_zero_coefficient_and_zero_lower_bound_are_accepted(tmp_path):
    doc = json.loads(_gyro_result(tmp_path).read_text())
    doc["axes"][1]["noise"]["terms"]["K"].update(value=0.0, lo95=0.0)
    p = tmp_path / "zero.json"
    p.write_text(json.dumps(doc))
    assert build_context([p]).gyro[1].terms["K"].value == 0.0


@pytest.mark.parametrize("term, unit, quantity, factor", [
    ("N", "deg/√h", "gyro", D / 60), ("N", "(deg/h)·sqrt(s)", "gyro", D / 3600), ("N", "µg/√Hz", "accel", G * 1e-6),
    ("N", "(m/s^2)/sqrt(Hz)", "accel", 1.0), ("N", "m/s/√hr", "accel", 1 / 60), ("K", "deg/h/√h", "gyro", D / 216000),
    ("K", "m/s/h^1.5", "accel", 1 / 216000), ("B", "µg", "accel", G * 1e-6), ("B", "mGal", "accel", 1e-5),
    ("Q", "arcsec", "gyro", D / 3600), ("R", "m/s^2/h", "accel", 1 / 3600)])
def test_unit_spellings(term, unit, quantity, factor):
    v, _, _ = to_si(1.0, term, unit)
    assert v == pytest.approx(factor, rel=1e-12, abs=0)
    from fogdrift.export.conversions import quantity_of_unit

    assert quantity_of_unit(term, unit) == quantity


def test_accelerometer_only_and_duplicate_axes(tmp_path):
    ctx = build_context(accel=[_accel_result(tmp_path)])
    for t in parse_targets("all"):
        render(t, ctx)                                                # every target writes without a gyro
    d = yaml.safe_load(render("kalibr", ctx))
    assert d["gyroscope_noise_density"] == 1.6968e-4                      # not measured: the default, said so
    assert d["accelerometer_random_walk"] == pytest.approx(3e-4, rel=1e-5, abs=0)
    kf = yaml.safe_load(render("kf-gins", ctx))["imunoise"]
    assert kf["arw"] == [0.003] * 3 and kf["corrtime"] == pytest.approx(100.0 / 1.8926 / 3600.0, rel=1e-4, abs=0)
    g = _gyro_result(tmp_path)
    with pytest.raises(ConfigError, match="two gyro channels are called 'gx'"):
        build_context([g, g])


def test_bias_gm_is_the_slowest_of_flicker_and_markov(tmp_path):
    from fogdrift.export.model import bias_gm

    doc = json.loads(_gyro_result(tmp_path).read_text())
    ax = doc["axes"][0]                                   # gx: flicker B = 2 deg/h read at tau_B = 100 s
    ax["noise"]["selected"] = ["N", "B", "K", "M"]
    ax["noise"]["terms"]["M"] = _term("M", 0.5, 0.3, 0.7, "deg/h/sqrt(s)", "resolved")
    ax["noise"]["shaped"] = {"M": {"tc_s": 3.0, "tc_lo95_s": 2.0, "tc_hi95_s": 4.5, "sigma_dph": 0.6124,
                                   "q_unit": "deg/h/sqrt(s)"}}
    gx = channels_from_result(doc, "g")[0]
    assert len(gx.gms) == 1 and gx.gms[0].tc_s == 3.0
    g, how = bias_gm(gx, "bound")                         # flicker GM T_c = 100/1.8926 = 52.8 s > 3 s
    assert g.tc_s == pytest.approx(100.0 / 1.8926, rel=1e-4, abs=0) and "matched to B" in how
    ax["noise"]["shaped"]["M"]["tc_s"] = 500.0
    g, how = bias_gm(channels_from_result(doc, "g")[0], "bound")
    assert g.tc_s == 500.0 and g.sigma_si == pytest.approx(0.6124 * D / 3600) and "slowest" in how
    # a flicker term not resolved from zero does not displace the fitted Markov term, however slow its GM
    ax["noise"]["shaped"]["M"]["tc_s"] = 3.0
    ax["noise"]["terms"]["B"].update(lo95=0.0, status="unresolved")
    g, how = bias_gm(channels_from_result(doc, "g")[0], "bound")
    assert g.tc_s == 3.0 and "slowest" in how
    ax["noise"]["selected"] = ["N", "B", "K"]  # without the Markov term, the unresolved flicker is the bias
    g, how = bias_gm(channels_from_result(doc, "g")[0], "bound")
    assert g.tc_s == pytest.approx(100.0 / 1.8926, rel=1e-4, abs=0) and "matched to B" in how


def test_gmwm_accelerometer_result(tmp_path):
    ax = _gmwm_axis("ax", 0.1, None, [(300.0, 2e-4)])
    ax["selection"]["ieee"]["terms"]["N_dprh"]["unit"] = "m/s/sqrt(h)"
    ax["selection"]["ieee"]["gm"][0]["sigma_gm_dph"]["unit"] = "m/s^2"
    ax["selection"]["ieee"]["b_headline"]["bound_dph"] = None
    p = tmp_path / "acc_noise.json"
    p.write_text(json.dumps({"record": _record(100.0), "axes": [ax]}))
    ctx = build_context(accel=[p], missing="zero")
    assert ctx.accel[0].quantity == "accel"
    d = yaml.safe_load(render("kf-gins", ctx))["imunoise"]
    assert d["vrw"] == pytest.approx([0.1] * 3) and d["abstd"] == pytest.approx([2e-4 / 1e-5] * 3)   # mGal


def test_export_of_what_fogdrift_allan_writes_for_an_accelerometer(tmp_path):
    # the fixtures above write K in m/s^2/sqrt(s); `fogdrift allan` writes an accelerometer's K in m/s^2/sqrt(h)
    # (and N in m/s/sqrt(h)): this goes through the file it really writes (issue 36).  Simulated in m/s^2: white
    # noise of density 0.002 m/s^2/sqrt(Hz) (0.12 m/s/sqrt(h)) and a random walk of 1e-3 m/s^2.5 (0.06
    # m/s^2/sqrt(h)), 2000 s at 100 Hz, three axes.
    fs, n, dens, walk = 100.0, 200_000, 2e-3, 1e-3
    rng = np.random.default_rng(36)
    x = dens * math.sqrt(fs) * rng.standard_normal((n, 3)) \
        + np.cumsum(walk / math.sqrt(fs) * rng.standard_normal((n, 3)), axis=0)
    log = tmp_path / "acc.csv"
    np.savetxt(log, np.column_stack([np.arange(n) / fs, x]), delimiter=",", header="t_s,ax,ay,az", comments="",
               fmt="%.12g")
    res = runner.invoke(app, ["allan", str(log), "--unit", "m/s^2", "--out", str(tmp_path / "a")])
    assert res.exit_code == 0, res.output
    axes = json.loads((tmp_path / "a" / "allan.json").read_text())["axes"]
    terms = [ax["noise"]["terms"] for ax in axes]
    assert {t["N"]["unit"] for t in terms} == {"m/s/sqrt(h)"} and {t["K"]["unit"] for t in terms} == {"m/s^2/sqrt(h)"}
    assert all(t["K"]["status"] == "resolved" for t in terms)
    n_max = max(t["N"]["value"] for t in terms)      # m/s/sqrt(h)
    k_max = max(t["K"]["value"] for t in terms)      # m/s^2/sqrt(h)
    assert 0.10 < n_max < 0.14 and 0.04 < k_max < 0.08  # the simulation's 0.12 and 0.06, as allan read them
    res = runner.invoke(app, ["export", "--accel", str(tmp_path / "a" / "allan.json"), "--target", "kalibr",
                              "--out", str(tmp_path / "e")])
    assert res.exit_code == 0, res.output
    d = yaml.safe_load((tmp_path / "e" / "imu.yaml").read_text())
    # by hand: sqrt(h) = 60 sqrt(s), so m/s/sqrt(h) / 60 = m/s^2/sqrt(Hz) and m/s^2/sqrt(h) / 60 = m/s^3/sqrt(Hz)
    assert d["accelerometer_noise_density"] == pytest.approx(n_max / 60.0, rel=1e-5, abs=0)
    assert d["accelerometer_random_walk"] == pytest.approx(k_max / 60.0, rel=1e-5, abs=0)
    assert d["accelerometer_random_walk"] == pytest.approx(walk, rel=0.35)  # the simulated one, in SI


def test_export_reads_an_allan_run_in_memory_as_the_round_trip_of_its_document_did():
    """``fogdrift export LOG`` hands its Allan fit to export as the result object (``AllanRun.to_dict()``, the
    allan.json document), with no JSON round trip: the channels are those the round-tripped document gave, and
    numpy numbers count as numbers."""
    from fogdrift._util import json_default
    from fogdrift.io import from_array
    from fogdrift.pipeline import AnalysisConfig, run_allan
    from fogdrift.simulate import simulate
    from fogdrift.workflows.allan import AllanRun

    rec = from_array(simulate(2**14, 0.01, arw_dprh=0.1, seed=1), dt_s=0.01, axis_names=["gz"])
    cfg = AnalysisConfig()
    run = AllanRun(rec, cfg, run_allan(rec, cfg))
    want = channels_from_result(json.loads(json.dumps(run.to_dict(), default=json_default)), "log.csv")
    assert channels_from_result(run, "log.csv") == want
    doc = run.to_dict()
    doc["axes"][0]["noise"]["terms"]["N"]["value"] = np.float32(doc["axes"][0]["noise"]["terms"]["N"]["value"])
    assert channels_from_result(doc, "log.csv")[0].terms["N"].value == pytest.approx(want[0].terms["N"].value)
