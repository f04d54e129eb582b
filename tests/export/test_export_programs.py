"""fogdrift export against the target programs' own parsing rules and conventions (issue 37).

Each program's required keys, their types and shapes are written below as data, read from the program's source
(cited per rule; read, not copied; docs/export.md lists the same).  The files are read with the parser the program
uses where it runs here: OpenCV's FileStorage (cv2: the C++ parser OpenVINS, VINS-Fusion and ORB-SLAM3 call),
PyYAML's safe_load (Kalibr's ConfigReader), yaml-cpp through a small C++ reader built here when g++ and
libyaml-cpp-dev are installed (KF-GINS), and gnss-ins-sim's own IMU class when ``gnss_ins_sim`` is importable (it is
not on PyPI; the dictionary rules run always).  Each rule set is also shown to refuse a file with the bug it guards
against (a plausible one-line regression)."""

from __future__ import annotations

import json
import math
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from fogdrift.cli import app
from fogdrift.export import build_context, render

sys.path.insert(0, str(Path(__file__).parent))  # the result fixtures of tests/export/test_export.py (import mode importlib)
from test_export import _accel_result, _gyro_result  # noqa: E402

D = math.pi / 180.0

# ------------------------------------------------------------------------------------------------------------------
# the programs' rules, as data
# ------------------------------------------------------------------------------------------------------------------
#: OpenVINS (rpng/open_vins, v2.7 and master 6948812): every key read under imu0 of relative_config_imu with
#: YamlParser::parse_external, required=true (ov_core/src/utils/opencv_yaml_parse.h: a missing or unparsable
#: required node clears all_params_found_successfully, and run_subscribe_msckf / ros1_serial_msckf exit "unable to
#: parse all parameters").  Readers: ov_msckf/src/core/VioManagerOptions.h print_and_load_noise (the four noises,
#: double) and print_and_load_state (Tw, Ta, R_IMUtoACC, R_IMUtoGYRO, Tg: Eigen::Matrix3d, rows of a sequence;
#: Tw and Ta are inverted); ov_msckf/src/state/StateOptions.h (model: kalibr | calibrated | rpng);
#: ov_msckf/src/ros/ROS1Visualizer.cpp (rostopic).
OPENVINS = {"root": "imu0",
            "keys": {"gyroscope_noise_density": "real", "gyroscope_random_walk": "real",
                     "accelerometer_noise_density": "real", "accelerometer_random_walk": "real",
                     "Tw": "mat3-invertible", "Ta": "mat3-invertible", "R_IMUtoACC": "rotation", "R_IMUtoGYRO": "rotation",
                     "Tg": "mat3", "rostopic": "string", "model": ("kalibr", "calibrated", "rpng")}}

#: VINS-Fusion (HKUST-Aerial-Robotics/VINS-Fusion be55a93): vins_estimator/src/estimator/parameters.cpp
#: readParameters reads imu (int); when 1: imu_topic (string), acc_n, acc_w, gyr_n, gyr_w, g_norm (FileNode to
#: double: a missing key reads as 0, silently, so presence and a real type are the rule).
VINS = {"root": None, "keys": {"imu": "int", "imu_topic": "string", "acc_n": "real+", "acc_w": "real+",
                               "gyr_n": "real+", "gyr_w": "real+", "g_norm": "real+"}}

#: ORB-SLAM3 (UZ-SLAMLab/ORB_SLAM3 v1.0): src/Settings.cc Settings::readIMU: IMU.NoiseGyro, IMU.NoiseAcc,
#: IMU.GyroWalk, IMU.AccWalk, IMU.Frequency (readParameter<float>, required: a real or an int, else "must be a real
#: number, aborting"), IMU.T_b_c1 (readParameter<cv::Mat>, required, converted to a 4x4 pose).
ORBSLAM3 = {"root": None, "keys": {"IMU.NoiseGyro": "real", "IMU.NoiseAcc": "real", "IMU.GyroWalk": "real",
                                   "IMU.AccWalk": "real", "IMU.Frequency": "real", "IMU.T_b_c1": "cvmat4x4"}}

#: Kalibr (ethz-asl/kalibr 1f60227): aslam_offline_calibration/kalibr/python/kalibr_common/ConfigReader.py
#: ImuParameters (yaml.safe_load): getRosTopic (str), getUpdateRate (> 0), getAccelerometerStatistics /
#: getGyroStatistics (noise density and random walk each > 0; a missing key: "Field ... missing in file"); called by
#: kalibr_imu_camera_calibration/IccSensors.py IccImu.__init__.
KALIBR = {"rostopic": str, "update_rate": "positive", "accelerometer_noise_density": "positive",
          "accelerometer_random_walk": "positive", "gyroscope_noise_density": "positive",
          "gyroscope_random_walk": "positive"}

#: KF-GINS (i2Nav-WHU/KF-GINS f39bc2e): src/kf_gins.cpp loading the configuration (yaml-cpp):
#: imunoise/{arw, vrw, gbstd, abstd, gsstd, asstd}.as<std::vector<double>>() and imunoise/corrtime.as<double>() in
#: one try block ("Failed when loading configuration. Please check IMU noise!"); the vectors are indexed 0..2.
KFGINS_VECTORS = ("arw", "vrw", "gbstd", "abstd", "gsstd", "asstd")

#: gnss-ins-sim (Aceinna/gnss-ins-sim 966ff27): gnss_ins_sim/sim/imu_model.py IMU.__init__ with a dict requires
#: gyro_b, gyro_b_stability, gyro_arw, accel_b, accel_b_stability, accel_vrw (else ValueError); gyro_b_corr,
#: accel_b_corr optional (inf: white bias); gnss_ins_sim/pathgen/pathgen.py indexes each of them [0..2] per axis.
GNSS_INS_SIM = ("gyro_b", "gyro_b_stability", "gyro_arw", "accel_b", "accel_b_stability", "accel_vrw", "gyro_b_corr",
                "accel_b_corr")


# ------------------------------------------------------------------------------------------------------------------
# checkers: a list of broken rules (empty: the file passes)
# ------------------------------------------------------------------------------------------------------------------
def _cv_errors(text, rules, tmp_path, name):
    cv2 = pytest.importorskip("cv2")
    p = tmp_path / name
    p.write_text(text)
    fs = cv2.FileStorage(str(p), cv2.FILE_STORAGE_READ)
    if not fs.isOpened():
        return ["cv::FileStorage cannot open the file"]
    node = fs.getNode(rules["root"]) if rules["root"] else fs.root()
    names = set(node.keys())
    errors = []
    for key, kind in rules["keys"].items():
        if key not in names:
            errors.append(f"{key}: missing")
            continue
        n = node.getNode(key)
        if isinstance(kind, tuple):
            if not n.isString() or n.string() not in kind:
                errors.append(f"{key}: not one of {kind}")
        elif kind == "string":
            if not n.isString():
                errors.append(f"{key}: not a string")
            elif any(c in n.string() for c in " #\t"):   # FileStorage keeps a comment after an unquoted string
                errors.append(f"{key}: {n.string()!r} is not a ROS topic")
        elif kind == "int":
            if not n.isInt():
                errors.append(f"{key}: not an integer")
        elif kind in ("real", "real+"):
            if not (n.isReal() or n.isInt()):
                errors.append(f"{key}: not a number")
            elif kind == "real+" and not n.real() > 0:
                errors.append(f"{key}: not > 0 (VINS would run with a zero noise)")
        elif kind.startswith("mat3") or kind == "rotation":
            rows = [n.at(i) for i in range(n.size())] if n.isSeq() else []
            if len(rows) != 3 or any(not r.isSeq() or r.size() != 3 for r in rows):
                errors.append(f"{key}: not a 3x3 sequence of rows")
                continue
            m = np.array([[rows[i].at(j).real() for j in range(3)] for i in range(3)])
            if kind == "mat3-invertible" and abs(np.linalg.det(m)) < 1e-12:
                errors.append(f"{key}: singular (OpenVINS inverts it)")
            if kind == "rotation" and not np.allclose(m @ m.T, np.eye(3), atol=1e-9):
                errors.append(f"{key}: not a rotation")
        elif kind == "cvmat4x4":
            m = n.mat()
            if m is None or m.shape != (4, 4):
                errors.append(f"{key}: not a 4x4 !!opencv-matrix")
    fs.release()
    return errors


def _kalibr_errors(text):
    d = yaml.safe_load(text) or {}
    errors = []
    for key, kind in KALIBR.items():
        if key not in d:
            errors.append(f"{key}: missing")
        elif kind is str and not isinstance(d[key], str):
            errors.append(f"{key}: not a string")
        elif kind == "positive" and not (isinstance(d[key], (int, float)) and d[key] > 0):
            errors.append(f"{key}: not a number > 0")
    return errors


def _kfgins_errors(text):
    block = (yaml.safe_load(text) or {}).get("imunoise") or {}
    errors = [f"imunoise/{k}: missing" for k in KFGINS_VECTORS + ("corrtime",) if k not in block]
    for k in KFGINS_VECTORS:
        v = block.get(k)
        if v is not None and not (isinstance(v, list) and len(v) == 3 and all(isinstance(x, float) for x in v)):
            errors.append(f"imunoise/{k}: not three numbers")
    if "corrtime" in block and not (isinstance(block["corrtime"], float) and block["corrtime"] > 0):
        errors.append("imunoise/corrtime: not a number > 0")
    return errors


def _gnss_ins_sim_errors(text):
    ns = {}
    exec(text, ns)  # noqa: S102 - our own generated file
    err = ns.get("imu_err", {})
    errors = [f"{k}: missing" for k in GNSS_INS_SIM if k not in err]
    for k in GNSS_INS_SIM:
        if k in err and np.asarray(err[k], dtype=float).shape != (3,):
            errors.append(f"{k}: not three values")
    for k in ("gyro_b_corr", "accel_b_corr"):
        if k in err and not np.all(np.asarray(err[k]) > 0):
            errors.append(f"{k}: not > 0")
    return errors


# ------------------------------------------------------------------------------------------------------------------
# the exported files pass (gyro and accelerometer results, and a gyro result alone)
# ------------------------------------------------------------------------------------------------------------------
@pytest.fixture(params=["gyro+accel", "gyro only"])
def ctx(request, tmp_path):
    acc = [_accel_result(tmp_path)] if request.param == "gyro+accel" else []
    return build_context([_gyro_result(tmp_path)], acc)


def test_openvins_vins_orbslam3_pass_their_readers(ctx, tmp_path):
    assert _cv_errors(render("openvins", ctx), OPENVINS, tmp_path, "ov.yaml") == []
    assert _cv_errors(render("vins-fusion", ctx), VINS, tmp_path, "vins.yaml") == []
    assert _cv_errors(render("orbslam3", ctx), ORBSLAM3, tmp_path, "orb.yaml") == []


def test_kalibr_kfgins_gnss_ins_sim_pass_their_readers(ctx):
    assert _kalibr_errors(render("kalibr", ctx)) == []
    assert _kfgins_errors(render("kf-gins", ctx)) == []
    assert _gnss_ins_sim_errors(render("gnss-ins-sim", ctx)) == []


def test_the_rules_refuse_the_bugs_they_guard_against(tmp_path):
    """Each rule set refuses the file with the fault the issue found (or a plausible one-line regression)."""
    ctx = build_context([_gyro_result(tmp_path)], [_accel_result(tmp_path)])
    ov = render("openvins", ctx)
    cut = ov[:ov.index("  # Tw:")]                                           # the file before issue 37
    assert {"Tw: missing", "Ta: missing", "Tg: missing"} <= set(_cv_errors(cut, OPENVINS, tmp_path, "a.yaml"))
    assert _cv_errors(ov.replace('model: "kalibr"', 'model: "imu"'), OPENVINS, tmp_path, "b.yaml")
    assert _cv_errors(ov.replace("  Ta:\n    - [1.0", "  Ta:\n    - [0.0"), OPENVINS, tmp_path, "c.yaml")
    vins = render("vins-fusion", ctx)
    assert _cv_errors(vins.replace("imu: 1", "imu: true"), VINS, tmp_path, "d.yaml") == ["imu: not an integer"]
    assert _cv_errors(vins.replace("g_norm:", "gnorm:"), VINS, tmp_path, "e.yaml") == ["g_norm: missing"]
    orb = render("orbslam3", ctx)
    assert _cv_errors(orb[:orb.index("# IMU.T_b_c1")], ORBSLAM3, tmp_path, "f.yaml") == ["IMU.T_b_c1: missing"]
    kal = render("kalibr", ctx)
    assert _kalibr_errors(kal.replace("update_rate: 100.0", "update_rate: 1e2")) == ["update_rate: not a number > 0"]
    kf = render("kf-gins", ctx)
    assert _kfgins_errors("\n".join(ln for ln in kf.splitlines() if not ln.startswith("  gsstd"))) == [
        "imunoise/gsstd: missing"]
    gis = render("gnss-ins-sim", ctx)
    assert _gnss_ins_sim_errors(gis.replace("'accel_b'", "'accel_bias'")) == ["accel_b: missing"]


# ------------------------------------------------------------------------------------------------------------------
# the parsers themselves, where they run here
# ------------------------------------------------------------------------------------------------------------------
_YAMLCPP_READER = r"""
#include <yaml-cpp/yaml.h>
#include <iostream>
#include <vector>
int main(int argc, char** argv) {
  try {
    YAML::Node c = YAML::LoadFile(argv[1]);
    const char* keys[] = {"arw", "vrw", "gbstd", "abstd", "gsstd", "asstd"};
    for (const char* k : keys) {
      std::vector<double> v = c["imunoise"][k].as<std::vector<double>>();
      std::cout << k << " " << v.size();
      for (double x : v) std::cout << " " << x;
      std::cout << "\n";
    }
    std::cout << "corrtime 1 " << c["imunoise"]["corrtime"].as<double>() << "\n";
  } catch (YAML::Exception& e) {
    std::cout << "FAILED " << e.what() << "\n";
    return 1;
  }
  return 0;
}
"""


@pytest.fixture(scope="module")
def yamlcpp_reader(tmp_path_factory):
    """A reader doing what KF-GINS's loader does with yaml-cpp (built here; skipped without g++ / libyaml-cpp-dev)."""
    if shutil.which("g++") is None or not Path("/usr/include/yaml-cpp/yaml.h").exists():
        pytest.skip("g++ and libyaml-cpp-dev are needed to read the KF-GINS file with yaml-cpp")
    d = tmp_path_factory.mktemp("yamlcpp")
    (d / "reader.cpp").write_text(_YAMLCPP_READER)
    res = subprocess.run(["g++", "-std=c++17", "-O0", str(d / "reader.cpp"), "-o", str(d / "reader"), "-lyaml-cpp"],
                         capture_output=True, text=True, timeout=300)
    if res.returncode != 0:
        pytest.skip(f"yaml-cpp reader does not build here: {res.stderr.splitlines()[:1]}")
    return d / "reader"


def test_kfgins_read_by_yaml_cpp(yamlcpp_reader, tmp_path):
    ctx = build_context([_gyro_result(tmp_path)], [_accel_result(tmp_path)])
    p = tmp_path / "kf.yaml"
    p.write_text(render("kf-gins", ctx))
    res = subprocess.run([str(yamlcpp_reader), str(p)], capture_output=True, text=True, timeout=60)
    assert res.returncode == 0, res.stdout
    got = {ln.split()[0]: [float(x) for x in ln.split()[2:]] for ln in res.stdout.splitlines()}
    assert all(len(got[k]) == 3 for k in KFGINS_VECTORS)
    assert got["arw"] == pytest.approx([0.15, 0.20, 0.10], rel=1e-5, abs=0)          # deg/sqrt(h)
    assert got["corrtime"][0] == pytest.approx(100.0 / 1.8926 / 3600.0, rel=1e-4, abs=0)
    old = "\n".join(ln for ln in p.read_text().splitlines() if not ln.startswith("  asstd"))
    p.write_text(old)                                                                # the block before issue 37
    assert subprocess.run([str(yamlcpp_reader), str(p)], capture_output=True, timeout=60).returncode == 1


def test_gnss_ins_sim_imu_class_takes_the_dictionary(tmp_path):
    imu_model = pytest.importorskip("gnss_ins_sim.sim.imu_model")   # not on PyPI: runs where it is installed
    ctx = build_context([_gyro_result(tmp_path)], [_accel_result(tmp_path)])
    ns = {}
    exec(render("gnss-ins-sim", ctx), ns)  # noqa: S102 - our own generated file
    imu = imu_model.IMU(accuracy=ns["imu_err"], axis=6, gps=False)
    assert imu.gyro_err["arw"] == pytest.approx(np.array([0.15, 0.20, 0.10]) * D / 60, rel=1e-5, abs=0)   # SI
    assert imu.accel_err["vrw"] == pytest.approx(np.array([0.06, 0.12, 0.18]) / 60, rel=1e-5, abs=0)


# ------------------------------------------------------------------------------------------------------------------
# VINS-Fusion: its integration code's time convention, on a hand-worked case
# ------------------------------------------------------------------------------------------------------------------
#: vins_estimator/src/factor/integration_base.h, IntegrationBase::midPointIntegration, one axis at zero rate (the
#: rotations are identities): the rotation error row of F is [1, -dt] (state theta, gyro bias), V maps the noise
#: vector (gyr_0 noise, gyr_1 noise, gyr_w) with [0.5 dt, 0.5 dt, 0] to theta and [0, 0, dt] to the bias, and the
#: noise matrix is diag(gyr_n^2, gyr_n^2, gyr_w^2); covariance <- F covariance F^T + V noise V^T per IMU step.
def _vins_covariance(gyr_n, gyr_w, dt, steps):
    F = np.array([[1.0, -dt], [0.0, 1.0]])
    V = np.array([[0.5 * dt, 0.5 * dt, 0.0], [0.0, 0.0, dt]])
    Q = np.diag([gyr_n ** 2, gyr_n ** 2, gyr_w ** 2])
    P = np.zeros((2, 2))
    for _ in range(steps):
        P = F @ P @ F.T + V @ Q @ V.T
    return P


def test_vins_numbers_follow_its_integration_code(tmp_path):
    # hand-worked: a gyro of N = 0.2 deg/sqrt(h) = 5.8178e-5 rad/s/sqrt(Hz), K = 0.5 deg/h^1.5 = 4.0401e-8
    # rad/s^2/sqrt(Hz) at f = 200 Hz: gyr_n = N sqrt(2 f) = N x 20 = 1.16355e-3 rad/s,
    # gyr_w = K sqrt(f) = K x 14.1421 = 5.7136e-7 rad/s^2
    doc = json.loads(_gyro_result(tmp_path).read_text())
    doc["axes"] = doc["axes"][1:2]                                      # gy: N 0.20, K 0.4 deg/h^1.5
    doc["axes"][0]["noise"]["terms"]["K"]["value"] = 0.5
    p = tmp_path / "g.json"
    p.write_text(json.dumps(doc))
    ctx = build_context([p], rate_hz=200.0)
    cv2 = pytest.importorskip("cv2")
    (tmp_path / "v.yaml").write_text(render("vins-fusion", ctx))
    fs = cv2.FileStorage(str(tmp_path / "v.yaml"), cv2.FILE_STORAGE_READ)
    gyr_n, gyr_w = fs.getNode("gyr_n").real(), fs.getNode("gyr_w").real()
    assert gyr_n == pytest.approx(1.16355e-3, rel=1e-5, abs=0)
    assert gyr_w == pytest.approx(5.7136e-7, rel=1e-4, abs=0)
    # and VINS's own recursion with these numbers reproduces the continuous model over 1 s (200 steps):
    # var(theta) = N^2 T + K^2 T^3 / 3, var(b) = K^2 T, cov = -K^2 T^2 / 2 (to O(1/steps))
    n, k, T = 0.2 * D / 60, 0.5 * D / 216000, 1.0
    P = _vins_covariance(gyr_n, gyr_w, 1 / 200.0, 200)
    assert P[0, 0] == pytest.approx(n * n * T + k * k * T ** 3 / 3, rel=1e-3, abs=0)
    assert P[1, 1] == pytest.approx(k * k * T, rel=1e-5, abs=0)          # (the file's 6 significant digits)
    assert P[0, 1] == pytest.approx(-k * k * T ** 2 / 2, rel=1e-2, abs=0)
    # the continuous densities (the file before issue 37) make VINS over-confident by 2 f = 400 in angle variance
    assert _vins_covariance(n, k, 1 / 200.0, 200)[0, 0] == pytest.approx(n * n * T / 400, rel=1e-2, abs=0)
    text = (tmp_path / "v.yaml").read_text()
    assert "TIME CONVENTION: per IMU step at 200.0 Hz" in text


# ------------------------------------------------------------------------------------------------------------------
# the console: per target, the time convention and what to fill in
# ------------------------------------------------------------------------------------------------------------------
def test_export_prints_per_target_convention_and_what_to_fill_in(tmp_path):
    res = CliRunner().invoke(app, ["export", "--gyro", str(_gyro_result(tmp_path)), "--update-rate", "200",
                                   "--out", str(tmp_path / "o")])
    assert res.exit_code == 0, res.output
    lines = {ln.split(" (")[0]: ln for ln in res.output.splitlines() if ": time convention: " in ln}
    assert sorted(lines) == sorted(["kalibr", "openvins", "vins-fusion", "orbslam3", "kf-gins", "matlab",
                                    "gnss-ins-sim", "json"])
    assert "per IMU step at 200.0 Hz" in lines["vins-fusion"] and "g_norm (written 9.80665 m/s^2)" in lines["vins-fusion"]
    assert "Tw, R_IMUtoGYRO, Ta, R_IMUtoACC" in lines["openvins"] and "continuous-time" in lines["openvins"]
    assert "IMU.T_b_c1" in lines["orbslam3"] and "gsstd, asstd" in lines["kf-gins"]
    assert "no accelerometer result" in lines["kalibr"] and "update_rate (written 200.0 Hz)" in lines["kalibr"]
