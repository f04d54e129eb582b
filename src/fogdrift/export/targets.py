"""The export targets: ONE registry table (:data:`TARGETS`) of target name -> writer, file name, units, source.

The writers are in :mod:`fogdrift.export.writers`.  Field names and units were checked against each project's
documentation or code (cited per target in ``source``; read, not copied).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from ..errors import ConfigError
from .writers import (ExportContext, write_gnss_ins_sim, write_json, write_kalibr, write_kfgins, write_matlab,
                      write_openvins, write_orbslam3, write_vins)

__all__ = ["Target", "TARGETS", "ExportContext", "target_names", "get_target"]


# ------------------------------------------------------------------------------------------------------------------
# the registry
# ------------------------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Target:
    """One export target: its writer, file name, units and the documentation its fields were checked against."""

    name: str
    writer: Callable
    filename: str
    units: str
    read_by: str
    source: str


#: Target name -> :class:`Target`.  The one table of targets (docs/export.md lists it).
TARGETS: dict[str, Target] = {t.name: t for t in (
    Target("kalibr", write_kalibr, "imu.yaml",
           "noise density rad/s/sqrt(Hz), m/s^2/sqrt(Hz); random walk rad/s^2/sqrt(Hz), m/s^3/sqrt(Hz); continuous",
           "PyYAML (Kalibr)",
           "https://github.com/ethz-asl/kalibr/wiki/IMU-Noise-Model and the wiki's yaml-formats page"),
    Target("openvins", write_openvins, "kalibr_imu_chain.yaml", "as kalibr, under imu0",
           "cv::FileStorage (OpenVINS YamlParser)", "rpng/open_vins config/euroc_mav/kalibr_imu_chain.yaml"),
    Target("vins-fusion", write_vins, "vins_imu.yaml", "acc_n, gyr_n densities; acc_w, gyr_w random-walk densities",
           "cv::FileStorage (VINS-Fusion parameters.cpp)", "HKUST-Aerial-Robotics/VINS-Fusion config/*.yaml"),
    Target("orbslam3", write_orbslam3, "orbslam3_imu.yaml",
           "IMU.NoiseGyro rad/s/sqrt(Hz), IMU.NoiseAcc m/s^2/sqrt(Hz), IMU.GyroWalk rad/s^2/sqrt(Hz), "
           "IMU.AccWalk m/s^3/sqrt(Hz), IMU.Frequency Hz", "cv::FileStorage (ORB-SLAM3 Settings / Tracking)",
           "UZ-SLAMLab/ORB_SLAM3 src/Tracking.cc (Ng*sf, Ngw/sf with sf = sqrt(IMU.Frequency)), Examples/*.yaml"),
    Target("kf-gins", write_kfgins, "kf-gins_imunoise.yaml",
           "arw deg/sqrt(h), vrw m/s/sqrt(h), gbstd deg/h, abstd mGal, corrtime h (gsstd/asstd ppm not written)",
           "yaml-cpp (KF-GINS)",
           "i2Nav-WHU/KF-GINS dataset/kf-gins.yaml (imunoise block); src/kf-gins/gi_engine.cpp (Qc of a bias = "
           "2 std^2 / corr_time: a first-order Gauss-Markov of 1-sigma gbstd / abstd)"),
    Target("matlab", write_matlab, "imu_params.m",
           "NoiseDensity (rad/s)/sqrt(Hz), RandomWalk (rad/s)*sqrt(Hz), BiasInstability rad/s (and m/s^2 for accel)",
           "MATLAB", "MathWorks gyroparams / accelparams / imuSensor reference pages"),
    Target("gnss-ins-sim", write_gnss_ins_sim, "gnss_ins_sim_imu_err.py",
           "gyro_arw deg/sqrt(h), gyro_b_stability deg/h, gyro_b_corr s, accel_vrw m/s/sqrt(h), accel_b_stability "
           "m/s^2, accel_b_corr s", "Python (gnss_ins_sim.sim.imu_model.IMU(accuracy=imu_err))",
           "Aceinna/gnss-ins-sim README 'Step 1.1' and sim/imu_model.py (bias_drift: first-order GM)"),
    Target("json", write_json, "noise_model.json",
           "SI: every term with interval, continuous and discrete values, the state-space model (F, Qc, Phi, Qd)",
           "any JSON reader", "fogdrift (docs/export.md)"),
)}


def target_names() -> list[str]:
    return list(TARGETS)


def get_target(name: str) -> Target:
    """The :class:`Target` called ``name``; an unknown name is refused listing the valid ones."""
    key = str(name).strip().lower()
    if key not in TARGETS:
        raise ConfigError(f"unknown export target {name!r}; expected one of {', '.join(TARGETS)} (or 'all')")
    return TARGETS[key]
