"""The writers of the export targets, one function per target (the registry is :mod:`fogdrift.export.targets`).

Each writer takes an :class:`ExportContext` (the gyro and accelerometer channels, the update rate, the
``--missing`` policy) and returns the file's text.  Every number written carries, in a comment above it: the
fogdrift term and estimate with its 95 % interval and status, the continuous-time value, the discrete-time value
at the stated update rate, and the conversion used.  A quantity without a result (no ``--accel`` file) is not
written: its keys are left out and a comment says so (never a zero or a guess).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field

from .._util import fmt_number
from ..errors import FogdriftError
from ..units import RAD_PER_DEG, S_PER_H
from .conversions import MGAL, gm_discrete, gm_rematch, vins_walk, vins_white, walk_discrete, white_discrete
from .discretize import discrete_model
from .model import ChannelModel, bias_gm, describe, resolve

__all__ = ["ExportContext", "fmt", "write_kalibr", "write_openvins", "write_vins", "write_orbslam3", "write_kfgins",
           "write_matlab", "write_gnss_ins_sim", "write_json"]


@dataclass
class ExportContext:
    """What every writer gets.

    Attributes
    ----------
    gyro, accel : list of ChannelModel
        The channels of each quantity (either may be empty, not both).
    rate_hz : float
        The update rate the discrete values are given at [Hz] (the filter's IMU rate).
    missing : str
        The ``--missing`` policy (:data:`fogdrift.export.model.MISSING_POLICIES`).
    topic : str
        ROS topic written where a target has one.
    notes : list of str
        Lines for the console (bounds, zeros, unresolved estimates, left-out keys), filled by the writers.
    todo : dict
        Target -> (time convention, what the user must still fill in), one console line per target.
    """

    gyro: list
    accel: list
    rate_hz: float
    missing: str = "bound"
    topic: str = "/imu0"
    notes: list = field(default_factory=list)
    todo: dict = field(default_factory=dict)

    def channels(self, quantity: str) -> list:
        return self.gyro if quantity == "gyro" else self.accel

    def note(self, text: str) -> None:
        if text not in self.notes:
            self.notes.append(text)

    def fill(self, target: str, convention: str, items) -> None:
        """Record ``target``'s time convention and what its user must still fill in (extrinsics, rates)."""
        conv, old = self.todo.get(target, ("", []))
        self.todo[target] = (convention or conv, old + [i for i in items if i not in old])


def fmt(x: float) -> str:
    """A float that every YAML parser reads as a float (a dot in the mantissa: PyYAML reads '1e-05' as a string).

    Examples
    --------
    >>> fmt(1e-5), fmt(0.0), fmt(2.5), fmt(123456789.0)
    ('1.0e-05', '0.0', '2.5', '1.23457e+08')
    """
    return fmt_number(float(x), 6, nonfinite=None, float_literal=True)


_QWORD = {"gyro": "gyroscope", "accel": "accelerometer"}
_SI_RATE = {"gyro": "rad/s", "accel": "m/s^2"}


def _term_lines(ctx: ExportContext, ch: ChannelModel, name: str, prefix: str, out_unit: str, out_factor: float,
                kind: str) -> tuple[float, list[str]]:
    """Resolve one term of one channel; the value in the output unit and its comment lines.

    ``kind``: ``"white"`` (discrete = x sqrt(f)) or ``"walk"`` (discrete = / sqrt(f)) or ``"level"`` (no
    discretisation: a standard deviation)."""
    r = resolve(ch, name, ctx.missing)
    if r.note:
        ctx.note(f"{ch.label}: {r.note}")
    si_unit = r.term.si_unit
    lines = [f"{prefix}{ch.name}: {describe(r.term)}"]
    how = {"estimate": "the estimate", "bound": "its 95 % upper bound (--missing bound)",
           "zero": "0 (--missing zero)"}[r.how]
    cont = f"continuous {fmt(r.si)} {si_unit} ({how}; {r.term.conversion})"
    if kind == "white":
        disc = (f"discrete {fmt(white_discrete(r.si, ctx.rate_hz))} {_SI_RATE[ch.quantity]} per sample at "
                f"{fmt(ctx.rate_hz)} Hz (x sqrt(f))")
    elif kind == "walk":
        disc = (f"discrete {fmt(walk_discrete(r.si, ctx.rate_hz))} {_SI_RATE[ch.quantity]} per-sample bias step at "
                f"{fmt(ctx.rate_hz)} Hz (/ sqrt(f))")
    else:
        disc = "a standard deviation: the same in continuous and discrete time"
    lines.append(f"{prefix}  {cont}; {disc}")
    return r.si * out_factor, lines


def _scalar(ctx, quantity, name, prefix, out_unit, out_factor, kind):
    """One value for all axes (Kalibr-style targets): the largest axis, with every axis in the comments."""
    chans = ctx.channels(quantity)
    vals, lines = [], []
    for ch in chans:
        v, ls = _term_lines(ctx, ch, name, prefix, out_unit, out_factor, kind)
        vals.append((v, ch.name))
        lines += ls
    v, which = max(vals)
    if len(vals) > 1:
        lines.append(f"{prefix}written: the largest of the {len(vals)} axes ({which}) in {out_unit}: this format "
                     "takes one value for all axes")
    else:
        lines.append(f"{prefix}written in {out_unit}")
    return v, lines


def _missing_quantity(ctx, target: str, quantity: str, keys, prefix: str) -> list[str]:
    ctx.note(f"{target}: no {_QWORD[quantity]} result given (--{quantity} FILE): its {_QWORD[quantity]} is left "
             "at the program's ideal default")
    return [f"{prefix}{', '.join(keys)}: not written: no {_QWORD[quantity]} result was given "
            f"(fogdrift export --{quantity} RESULT.json); {target} then uses its own ideal default"]


def _header(ctx, target, prefix, source) -> list[str]:
    files = sorted({ch.source_file for ch in ctx.gyro + ctx.accel})
    shas = sorted({ch.sha256[:16] for ch in ctx.gyro + ctx.accel if ch.sha256})
    fits = [f"{ch.label}: {ch.method} {ch.fit}" for ch in ctx.gyro + ctx.accel]
    return ([f"{prefix}fogdrift export --target {target}: noise model for {source}",
             f"{prefix}from {', '.join(files)}" + (f" (input SHA-256 {', '.join(shas)}...)" if shas else ""),
             f"{prefix}update rate {fmt(ctx.rate_hz)} Hz; --missing {ctx.missing}"]
            + [f"{prefix}{f}" for f in fits]
            + [f"{prefix}continuous -> discrete: white sigma_d = N sqrt(f), random-walk step sigma_bd = K / sqrt(f) "
               "(Kalibr wiki 'IMU Noise Model')"])


# ------------------------------------------------------------------------------------------------------------------
# values a program requires that fogdrift does not measure
# ------------------------------------------------------------------------------------------------------------------
#: A quantity without a result (no --accel file, say) whose keys the program requires: the program's own default
#: or the value of its shipped example configuration, written with a NOT MEASURED comment (cited in docs/export.md).
_OPENVINS_DEFAULT = ({"accelerometer_noise_density": 2.0e-3, "accelerometer_random_walk": 3.0e-3,
                      "gyroscope_noise_density": 1.6968e-4, "gyroscope_random_walk": 1.9393e-5},
                     "OpenVINS's own default (ov_msckf/src/utils/NoiseManager.h)")
PLACEHOLDERS = {
    "kalibr": (_OPENVINS_DEFAULT[0], "OpenVINS's default (ov_msckf/src/utils/NoiseManager.h; Kalibr has none)"),
    "openvins": _OPENVINS_DEFAULT,
    "vins-fusion": ({"acc_n": 0.1, "gyr_n": 0.01, "acc_w": 0.001, "gyr_w": 0.0001},
                    "VINS-Fusion's config/euroc/euroc_mono_imu_config.yaml"),
    "orbslam3": ({"IMU.NoiseGyro": 1.7e-4, "IMU.NoiseAcc": 2.0e-3, "IMU.GyroWalk": 1.9393e-5, "IMU.AccWalk": 3.0e-3},
                 "ORB-SLAM3's Examples/Monocular-Inertial/EuRoC.yaml"),
    "kf-gins": ({"arw": 0.003, "vrw": 0.03, "gbstd": 0.027, "abstd": 15.0, "gsstd": 300.0, "asstd": 300.0,
                 "corrtime": 4.0}, "KF-GINS's dataset/kf-gins.yaml"),
    "gnss-ins-sim": ({"gyro_arw": 0.75, "gyro_b_stability": 10.0, "gyro_b_corr": 100.0, "accel_vrw": 0.05,
                      "accel_b_stability": 2.0e-4, "accel_b_corr": 100.0},
                     "gnss-ins-sim's default profile 'low-accuracy' (gnss_ins_sim/sim/imu_model.py)"),
}


def _placeholder(ctx, target, quantity, keys, prefix, indent=""):
    """The program's default for ``keys`` of a quantity fogdrift has no result for, said as NOT MEASURED."""
    vals, src = PLACEHOLDERS[target]
    ctx.note(f"{target}: no {_QWORD[quantity]} result given (--{quantity} FILE): {', '.join(keys)} written as "
             f"{src} values, NOT MEASURED")
    ctx.fill(target, "", [f"{', '.join(keys)} (no {_QWORD[quantity]} result: {src} values written)"])
    return ([f"{prefix}{', '.join(keys)}: NOT MEASURED: no {_QWORD[quantity]} result was given (fogdrift export "
             f"--{quantity} RESULT.json); the program requires them, so {src} values are written: replace them "
             f"with your {_QWORD[quantity]}'s"], {k: vals[k] for k in keys})


# ------------------------------------------------------------------------------------------------------------------
# Kalibr-family: one white density and one random-walk density per sensor
# ------------------------------------------------------------------------------------------------------------------
_KALIBR_KEYS = (("accel", "N", "accelerometer_noise_density", "m/s^2/sqrt(Hz)", "white"),
                ("accel", "K", "accelerometer_random_walk", "m/s^3/sqrt(Hz)", "walk"),
                ("gyro", "N", "gyroscope_noise_density", "rad/s/sqrt(Hz)", "white"),
                ("gyro", "K", "gyroscope_random_walk", "rad/s^2/sqrt(Hz)", "walk"))
_CONTINUOUS = "continuous time"


def _kalibr_body(ctx, target, keys, indent="", factor=None, written=_CONTINUOUS) -> list[str]:
    """The lines of ``keys`` (quantity, term, key, unit, kind); ``factor(kind, rate)`` scales the continuous SI
    value into the program's convention (None: continuous)."""
    out = []
    done = set()
    for quantity, name, key, unit, kind in keys:
        if not ctx.channels(quantity):
            if quantity not in done:
                qkeys = [k[2] for k in keys if k[0] == quantity]
                lines, vals = _placeholder(ctx, target, quantity, qkeys, indent + "# ")
                out += lines + [f"{indent}{k}: {fmt(vals[k])}  # [{u}] NOT MEASURED ({written})"
                                for (q, _n, k, u, _k) in keys if q == quantity]
                done.add(quantity)
            continue
        f = 1.0 if factor is None else factor(kind, ctx.rate_hz)
        v, lines = _scalar(ctx, quantity, name, indent + "# ", unit, f, kind)
        out += lines + [f"{indent}{key}: {fmt(v)}  # [{unit}] {written}"]
    return out


def write_kalibr(ctx: ExportContext) -> str:
    lines = _header(ctx, "kalibr", "# ", "Kalibr imu.yaml (continuous-time densities; Kalibr discretises at update_rate)")
    lines += _kalibr_body(ctx, "kalibr", _KALIBR_KEYS)
    lines += ["# rostopic: the IMU's ROS topic: set yours (--rostopic)", f"rostopic: {json.dumps(ctx.topic)}",
              f"update_rate: {fmt(ctx.rate_hz)}  # [Hz] the IMU rate Kalibr discretises at (--update-rate)"]
    ctx.fill("kalibr", "continuous-time densities (Kalibr ConfigReader: discrete = density / sqrt(1/update_rate))",
             [f"rostopic (written {ctx.topic})", f"update_rate (written {fmt(ctx.rate_hz)} Hz)"])
    return "\n".join(lines) + "\n"


def _matrix(name, rows, indent, why) -> list[str]:
    return ([f"{indent}# {name}: {why}", f"{indent}{name}:"]
            + [f"{indent}  - [{', '.join(fmt(v) for v in r)}]" for r in rows])


_I3 = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
_Z3 = ((0.0, 0.0, 0.0),) * 3


def write_openvins(ctx: ExportContext) -> str:
    lines = ["%YAML:1.0", ""] + _header(ctx, "openvins", "# ", "OpenVINS kalibr_imu_chain.yaml (read with cv::FileStorage)")
    lines += ["# OpenVINS reads continuous-time densities and discretises itself (ov_msckf Propagator: sigma^2 / dt for",
              "# the white noises, sigma_b^2 dt for the bias walks per IMU step)", "imu0:"]
    lines += ["  # T_i_b: NOT MEASURED: identity (fogdrift does not calibrate extrinsics; Kalibr's multi-IMU pose)",
              "  T_i_b:"] + [f"    - [{', '.join('1.0' if i == j else '0.0' for j in range(4))}]" for i in range(4)]
    lines += _kalibr_body(ctx, "openvins", _KALIBR_KEYS, indent="  ")
    lines += ["  # rostopic: the IMU's ROS topic: set yours (--rostopic); quoted, as cv::FileStorage keeps a comment "
              "after an unquoted string", f"  rostopic: {json.dumps(ctx.topic)}", "  time_offset: 0.0  # [s]",
              f"  update_rate: {fmt(ctx.rate_hz)}  # [Hz]",
              '  model: "kalibr"  # VioManagerOptions / StateOptions read kalibr, calibrated or rpng']
    why = ("NOT MEASURED: fogdrift does not calibrate IMU intrinsics; OpenVINS's neutral value (its own default in "
           "VioManagerOptions.h: an ideal IMU)")
    for name, rows in (("Tw", _I3), ("R_IMUtoGYRO", _I3), ("Ta", _I3), ("R_IMUtoACC", _I3), ("Tg", _Z3)):
        lines += _matrix(name, rows, "  ", why)
    ctx.fill("openvins", "continuous-time densities (OpenVINS Propagator discretises with the IMU dt)",
             ["Tw, R_IMUtoGYRO, Ta, R_IMUtoACC (identity), Tg (zero), T_i_b (identity): IMU intrinsics / extrinsics "
              "not measured", f"rostopic (written {ctx.topic})", "cameras: kalibr_imucam_chain.yaml"])
    return "\n".join(lines) + "\n"


_VINS_KEYS = (("accel", "N", "acc_n", "m/s^2", "white"), ("gyro", "N", "gyr_n", "rad/s", "white"),
              ("accel", "K", "acc_w", "m/s^3", "walk"), ("gyro", "K", "gyr_w", "rad/s^2", "walk"))


def _vins_factor(kind, rate):
    return vins_white(1.0, rate) if kind == "white" else vins_walk(1.0, rate)


def write_vins(ctx: ExportContext) -> str:
    f = ctx.rate_hz
    lines = ["%YAML:1.0", ""] + _header(ctx, "vins-fusion", "# ", "VINS-Fusion config (IMU block; cv::FileStorage)")
    lines += ["# merge these keys into your VINS-Fusion config (parameters.cpp readParameters reads imu, imu_topic,",
              "# acc_n, acc_w, gyr_n, gyr_w, g_norm; a missing number reads as 0 without an error).",
              f"# TIME CONVENTION: per IMU step at {fmt(f)} Hz, as VINS-Fusion's integration code applies them",
              "# (vins_estimator/src/factor/integration_base.h, midPointIntegration: covariance += V noise V^T, noise =",
              "# diag(acc_n^2, gyr_n^2, acc_n^2, gyr_n^2, acc_w^2, gyr_w^2), V = 0.5 dt on each of the two averaged samples",
              "# and dt on the bias walks): matching the continuous model per step needs",
              f"#   acc_n, gyr_n = N sqrt(2 f) = N x {fmt(vins_white(1.0, f))};  acc_w, gyr_w = K sqrt(f) = K x "
              f"{fmt(vins_walk(1.0, f))}",
              "# (continuous densities here would make VINS over-confident by sqrt(2 f) and sqrt(f)).  These values hold",
              f"# at {fmt(f)} Hz only: re-export with --update-rate for another IMU rate.",
              "imu: 1  # use the IMU", "# imu_topic: the IMU's ROS topic: set yours (--rostopic)",
              f"imu_topic: {json.dumps(ctx.topic)}"]
    lines += _kalibr_body(ctx, "vins-fusion", _VINS_KEYS, factor=_vins_factor, written=f"per IMU step at {fmt(f)} Hz")
    lines += ["# g_norm: NOT MEASURED: standard gravity (CGPM 1901); put your local gravity magnitude",
              "g_norm: 9.80665  # [m/s^2]"]
    ctx.fill("vins-fusion", f"per IMU step at {fmt(f)} Hz (N sqrt(2f), K sqrt(f): integration_base.h)",
             ["merge into your config (cameras, body_T_cam0, estimate_extrinsic, td)", "g_norm (written 9.80665 m/s^2)",
              f"imu_topic (written {ctx.topic})", f"the IMU rate: the values hold at {fmt(f)} Hz only"])
    return "\n".join(lines) + "\n"


_ORB_KEYS = (("gyro", "N", "IMU.NoiseGyro", "rad/s/sqrt(Hz)", "white"),
             ("accel", "N", "IMU.NoiseAcc", "m/s^2/sqrt(Hz)", "white"),
             ("gyro", "K", "IMU.GyroWalk", "rad/s^2/sqrt(Hz)", "walk"),
             ("accel", "K", "IMU.AccWalk", "m/s^3/sqrt(Hz)", "walk"))


def write_orbslam3(ctx: ExportContext) -> str:
    lines = ["%YAML:1.0", ""] + _header(ctx, "orbslam3", "# ", "ORB-SLAM3 settings (IMU block; cv::FileStorage)")
    lines += ["# merge into a settings file with File.version: \"1.0\" (System.cc reads Settings only then; Settings::readIMU",
              "# requires IMU.NoiseGyro, IMU.NoiseAcc, IMU.GyroWalk, IMU.AccWalk, IMU.Frequency (real) and IMU.T_b_c1)",
              "# ORB-SLAM3 reads continuous densities and discretises itself: noise x sqrt(IMU.Frequency), "
              "walk / sqrt(IMU.Frequency) (Tracking: IMU::Calib(Tbc, Ng*sf, Na*sf, Ngw/sf, Naw/sf), sf = sqrt(freq))"]
    lines += _kalibr_body(ctx, "orbslam3", _ORB_KEYS)
    lines += [f"IMU.Frequency: {fmt(ctx.rate_hz)}  # [Hz]",
              "# IMU.T_b_c1 (camera 1 to IMU body): NOT MEASURED: identity (fogdrift does not calibrate extrinsics); "
              "put your camera-IMU calibration (Kalibr's T_cam_imu, inverted)",
              "IMU.T_b_c1: !!opencv-matrix", "   rows: 4", "   cols: 4", "   dt: f",
              "   data: [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0]"]
    ctx.fill("orbslam3", "continuous-time densities (Tracking multiplies by sqrt(IMU.Frequency))",
             ["IMU.T_b_c1 (identity written)", "merge into a File.version \"1.0\" settings file (cameras, ORB, viewer)",
              f"IMU.Frequency (written {fmt(ctx.rate_hz)} Hz)"])
    return "\n".join(lines) + "\n"


# ------------------------------------------------------------------------------------------------------------------
# per-axis targets
# ------------------------------------------------------------------------------------------------------------------
def _vector(ctx, quantity, name, prefix, out_unit, out_factor, kind):
    vals, lines = [], []
    for ch in ctx.channels(quantity):
        v, ls = _term_lines(ctx, ch, name, prefix, out_unit, out_factor, kind)
        vals.append(v)
        lines += ls
    lines.append(f"{prefix}written per axis ({', '.join(c.name for c in ctx.channels(quantity))}) in {out_unit}")
    return vals, lines


def _gm_vectors(ctx, quantity, prefix, sigma_factor, sigma_unit, tc_factor, tc_unit):
    sig, tcs, lines = [], [], []
    for ch in ctx.channels(quantity):
        g, how = bias_gm(ch, ctx.missing)
        phi, qd = gm_discrete(g.sigma_si, g.tc_s, ctx.rate_hz)
        iv = ("" if g.sigma_lo95_si is None else
              f" [{fmt(g.sigma_lo95_si * sigma_factor)}, {fmt(g.sigma_hi95_si * sigma_factor)}]")
        tiv = "" if g.tc_lo95_s is None or g.tc_hi95_s is None else f" [{fmt(g.tc_lo95_s)}, {fmt(g.tc_hi95_s)}] s"
        lines += [f"{prefix}{ch.name}: bias Gauss-Markov: {how}",
                  f"{prefix}  sigma = {fmt(g.sigma_si)} {_SI_RATE[quantity]}"
                  f"{iv and ' (95 %' + iv + ' ' + sigma_unit + ')'}, "
                  f"T_c = {fmt(g.tc_s)} s{tiv}; discrete at {fmt(ctx.rate_hz)} Hz: phi = exp(-dt/T_c) = {phi:.9f}, "
                  f"driving sigma = sigma sqrt(1 - phi^2) = {fmt(qd)} {_SI_RATE[quantity]}"]
        sig.append(g.sigma_si * sigma_factor)
        tcs.append(g.tc_s * tc_factor)
    lines.append(f"{prefix}written per axis: sigma in {sigma_unit}, T_c in {tc_unit}")
    return sig, tcs, lines


def _list(vals) -> str:
    return "[" + ", ".join(fmt(v) for v in vals) + "]"


def _three(ctx, target, quantity, vals, names, prefix):
    """Programs that index three axes (KF-GINS, gnss-ins-sim): a result of fewer axes is padded with its largest
    value, said as NOT MEASURED; more than three is refused."""
    if len(vals) > 3:
        raise FogdriftError(f"{target}: takes three {_QWORD[quantity]} axes; the result has {len(vals)} "
                            f"({', '.join(names)}): export one result of three axes")
    if len(vals) == 3:
        return list(vals), []
    pad = max(vals)
    ctx.fill(target, "", [f"{_QWORD[quantity]} axes {len(vals) + 1}..3 (NOT MEASURED: the largest measured axis "
                          "copied)"])
    return (list(vals) + [pad] * (3 - len(vals)),
            [f"{prefix}NOT MEASURED: the result has {len(vals)} {_QWORD[quantity]} axis(es) ({', '.join(names)}); "
             f"the program reads three: axes {len(vals) + 1}..3 copy the largest measured value"])


def _geomean(xs) -> float:
    return math.exp(sum(math.log(x) for x in xs) / len(xs))


def write_kfgins(ctx: ExportContext) -> str:
    lines = _header(ctx, "kf-gins", "# ", "KF-GINS imunoise block (merge into kf-gins.yaml)")
    lines += ["# KF-GINS (src/kf_gins.cpp, loading the configuration) requires imunoise: arw, vrw, gbstd, abstd, gsstd,",
              "# asstd (three numbers each) and corrtime; it converts arw x (pi/180)/60, vrw / 60, gbstd x (pi/180)/3600,",
              "# abstd x 1e-5, gsstd and asstd x 1e-6, corrtime x 3600 and uses them in continuous time",
              "# (src/kf-gins/gi_engine.cpp: Qc = arw^2, vrw^2 and 2 std^2 / corrtime; F = -1/corrtime for every bias and",
              "# scale factor): each bias one first-order Gauss-Markov, ONE correlation time for all of them; a random",
              "# walk K has no place in it", "imunoise:"]
    body = []
    for quantity, key, factor, unit in (("gyro", "arw", 60.0 / RAD_PER_DEG, "deg/sqrt(h)"), ("accel", "vrw", 60.0, "m/s/sqrt(h)")):
        if ctx.channels(quantity):
            vals, ls = _vector(ctx, quantity, "N", "  # ", unit, factor, "white")
            vals, pad = _three(ctx, "kf-gins", quantity, vals, [c.name for c in ctx.channels(quantity)], "  # ")
            body += ls + pad + [f"  {key}: {_list(vals)}  # [{unit}] continuous time"]
        else:
            ls, d = _placeholder(ctx, "kf-gins", quantity, [key], "  # ")
            body += ls + [f"  {key}: {_list([d[key]] * 3)}  # [{unit}] NOT MEASURED"]
    gms = {}
    for quantity, sigma_unit, sigma_factor in (("gyro", "deg/h", S_PER_H / RAD_PER_DEG), ("accel", "mGal", 1.0 / MGAL)):
        if ctx.channels(quantity):
            _, _, ls = _gm_vectors(ctx, quantity, "  # ", sigma_factor, sigma_unit, 1.0, "s")
            gms[quantity] = ([bias_gm(ch, ctx.missing)[0] for ch in ctx.channels(quantity)], ls)
    tcs = [g.tc_s for q in gms for g in gms[q][0]]
    tc = _geomean(tcs) if tcs else None
    for quantity, key, unit, factor in (("gyro", "gbstd", "deg/h", S_PER_H / RAD_PER_DEG), ("accel", "abstd", "mGal", 1.0 / MGAL)):
        if quantity not in gms:
            ls, d = _placeholder(ctx, "kf-gins", quantity, [key], "  # ")
            body += ls + [f"  {key}: {_list([d[key]] * 3)}  # [{unit}] NOT MEASURED"]
            continue
        gs, ls = gms[quantity]
        vals = []
        for ch, g in zip(ctx.channels(quantity), gs):
            s2 = gm_rematch(g.sigma_si, g.tc_s, tc)
            vals.append(s2 * factor)
            ls.append(f"  # {ch.name}: for the one corrtime {fmt(tc)} s: sigma = {fmt(s2 * factor)} {unit} (its Allan "
                      f"variance at 1.8926 x {fmt(g.tc_s)} s, the peak of the axis's own Gauss-Markov, kept)")
        vals, pad = _three(ctx, "kf-gins", quantity, vals, [c.name for c in ctx.channels(quantity)], "  # ")
        body += ls + pad + [f"  {key}: {_list(vals)}  # [{unit}] 1-sigma of the Gauss-Markov bias"]
    d = PLACEHOLDERS["kf-gins"][0]
    body += ["  # gsstd, asstd (scale-factor instability): NOT MEASURED: a static record does not observe scale factors;",
             f"  # {PLACEHOLDERS['kf-gins'][1]} values are written: replace them with your datasheet's",
             f"  gsstd: {_list([d['gsstd']] * 3)}  # [ppm] NOT MEASURED", f"  asstd: {_list([d['asstd']] * 3)}  # [ppm] NOT MEASURED"]
    ctx.note("kf-gins: gsstd, asstd NOT MEASURED (scale factors are not observable in a static record): KF-GINS's "
             "example 300 ppm written")
    if tc is not None:
        per = "; ".join(f"{_QWORD[q]} " + ", ".join(f"{fmt(g.tc_s)}" for g in gms[q][0]) + " s" for q in gms)
        body += [f"  # corrtime: KF-GINS takes one correlation time for all six biases (and the scale factors): the "
                 f"geometric mean of the axes' T_c ({per}), each axis's sigma re-matched to it above",
                 f"  corrtime: {fmt(tc / S_PER_H)}  # [h]"]
        spread = max(tcs) / min(tcs)
        if spread > 2.0:
            ctx.note(f"kf-gins: the axes' bias correlation times span a factor {spread:.3g}; KF-GINS takes one "
                     f"({fmt(tc)} s): each sigma is re-matched at its own Allan peak")
    else:
        body += [f"  # corrtime: NOT MEASURED: {PLACEHOLDERS['kf-gins'][1]} value",
                 f"  corrtime: {fmt(d['corrtime'])}  # [h] NOT MEASURED"]
    lines += body
    ctx.fill("kf-gins", "continuous time (arw, vrw densities; biases Gauss-Markov 1-sigma with one corrtime)",
             ["gsstd, asstd (300 ppm example written)", "merge imunoise into kf-gins.yaml (antlever, initial state)"])
    return "\n".join(lines) + "\n"


def write_matlab(ctx: ExportContext) -> str:
    pre = "% "
    lines = _header(ctx, "matlab", pre, "MATLAB imuSensor (gyroparams / accelparams, Navigation / Sensor Fusion Toolbox)")
    lines += [f"{pre}Units per the gyroparams / accelparams reference pages: NoiseDensity (rad/s)/sqrt(Hz) and "
              "(m/s^2)/sqrt(Hz), RandomWalk (rad/s)*sqrt(Hz) and (m/s^2)*sqrt(Hz), BiasInstability rad/s and m/s^2",
              f"{pre}(MathWorks Answers 1631045: RandomWalk is the rate random walk K, NoiseDensity the white density N)",
              f"{pre}BiasInstability is B (the flicker floor); BiasInstabilityCoefficients is left at its default"]
    objs = []
    for quantity, fn, var in (("gyro", "gyroparams", "gyro"), ("accel", "accelparams", "accel")):
        if not ctx.channels(quantity):
            lines += _missing_quantity(ctx, "matlab", quantity, [fn], pre)
            continue
        si = _SI_RATE[quantity]
        n, ln = _vector(ctx, quantity, "N", pre, f"({si})/sqrt(Hz)", 1.0, "white")
        k, lk = _vector(ctx, quantity, "K", pre, f"({si})*sqrt(Hz)", 1.0, "walk")
        b, lb = _vector(ctx, quantity, "B", pre, si, 1.0, "level")
        lines += ln + lk + lb
        lines += [f"{var} = {fn}( ...",
                  f"    'NoiseDensity', {_list(n).replace(',', '')}, ...     % ({si})/sqrt(Hz)",
                  f"    'RandomWalk', {_list(k).replace(',', '')}, ...       % ({si})*sqrt(Hz)",
                  f"    'BiasInstability', {_list(b).replace(',', '')});     % {si}"]
        objs.append(("Gyroscope" if quantity == "gyro" else "Accelerometer", var))
    args = "".join(f", '{k}', {v}" for k, v in objs)
    lines += [f"imu = imuSensor('accel-gyro', 'SampleRate', {fmt(ctx.rate_hz)}{args});  % SampleRate [Hz]"]
    ctx.fill("matlab", "continuous-time densities (imuSensor discretises at SampleRate)",
             [f"SampleRate (written {fmt(ctx.rate_hz)} Hz)", "the other gyroparams / accelparams properties (range, "
              "resolution, misalignment) are left at MATLAB's defaults"]
             + ([] if ctx.accel else ["Accelerometer (no result: MATLAB's ideal default)"])
             + ([] if ctx.gyro else ["Gyroscope (no result: MATLAB's ideal default)"]))
    return "\n".join(lines) + "\n"


def write_gnss_ins_sim(ctx: ExportContext) -> str:
    pre = "# "
    lines = _header(ctx, "gnss-ins-sim", pre, "gnss-ins-sim imu_err dictionary (README 'Step 1.1'; imu_model.IMU)")
    lines += [f"{pre}gnss_ins_sim/sim/imu_model.py IMU(accuracy=imu_err) requires gyro_b, gyro_b_stability, gyro_arw, "
              "accel_b, accel_b_stability, accel_vrw (b_corr optional: infinite = white bias); pathgen.py applies arw and",
              f"{pre}vrw as continuous densities (per sample / sqrt(dt)); b_stability is the 1-sigma of a first-order "
              "Gauss-Markov bias with correlation time b_corr (bias_drift)", "import numpy as np", "", "imu_err = {"]
    for quantity, pfx, nunit, nfac, bunit, bfac in (("gyro", "gyro", "deg/sqrt(h)", 60.0 / RAD_PER_DEG, "deg/h", S_PER_H / RAD_PER_DEG),
                                                    ("accel", "accel", "m/s/sqrt(h)", 60.0, "m/s^2", 1.0)):
        nkey = f"{pfx}_{'arw' if pfx == 'gyro' else 'vrw'}"
        lines += ["    # constant bias: not a noise term (removed by calibration); 0 = a calibrated sensor",
                  f"    '{pfx}_b': np.array({_list([0.0] * 3)}),  # [{bunit}]"]
        if not ctx.channels(quantity):
            keys = [nkey, f"{pfx}_b_stability", f"{pfx}_b_corr"]
            ls, d = _placeholder(ctx, "gnss-ins-sim", quantity, keys, "    # ")
            lines += ls + [f"    '{k}': np.array({_list([d[k]] * 3)}),  # [{u}] NOT MEASURED"
                           for k, u in zip(keys, (nunit, bunit, "s"))]
            continue
        names = [c.name for c in ctx.channels(quantity)]
        n, ln = _vector(ctx, quantity, "N", "    # ", nunit, nfac, "white")
        sig, tcs, lg = _gm_vectors(ctx, quantity, "    # ", bfac, bunit, 1.0, "s")
        n, pn = _three(ctx, "gnss-ins-sim", quantity, n, names, "    # ")
        sig, ps = _three(ctx, "gnss-ins-sim", quantity, sig, names, "    # ")
        tcs, pt = _three(ctx, "gnss-ins-sim", quantity, tcs, names, "    # ")
        lines += ln + pn + [f"    '{nkey}': np.array({_list(n)}),  # [{nunit}] continuous time"]
        lines += lg + ps + [f"    '{pfx}_b_stability': np.array({_list(sig)}),  # [{bunit}]",
                            f"    '{pfx}_b_corr': np.array({_list(tcs)}),  # [s]"]
    lines += ["}"]
    ctx.fill("gnss-ins-sim", "continuous-time densities (pathgen: per-sample sigma = arw / sqrt(dt)); bias "
             "Gauss-Markov 1-sigma and b_corr", ["gyro_b, accel_b (0 written: a calibrated constant bias)",
                                                 "the simulation's fs and motion profile"])
    return "\n".join(lines) + "\n"


def write_json(ctx: ExportContext) -> str:
    chans = []
    for ch in ctx.gyro + ctx.accel:
        d = ch.to_dict()
        resolved = {}
        for name in ("N", "K", "B", "Q", "R"):
            if name not in ch.terms:
                continue
            try:
                r = resolve(ch, name, ctx.missing)
                entry = {"si": r.si, "si_unit": r.term.si_unit, "how": r.how, "note": r.note,
                         "conversion": r.term.conversion}
                if name == "N":
                    entry["discrete_sigma"] = white_discrete(r.si, ctx.rate_hz)
                    entry["discrete_note"] = "per-sample 1-sigma = N sqrt(f)"
                elif name == "K":
                    entry["discrete_sigma"] = walk_discrete(r.si, ctx.rate_hz)
                    entry["discrete_note"] = "per-sample bias step 1-sigma = K / sqrt(f)"
            except FogdriftError as exc:  # a refused term is reported; the JSON keeps the others
                entry = {"si": None, "how": "refused", "note": str(exc)}
            resolved[name] = entry
        d["export_values"] = resolved
        try:
            g, how = bias_gm(ch, ctx.missing)
            phi, qd = gm_discrete(g.sigma_si, g.tc_s, ctx.rate_hz)
            d["bias_gauss_markov"] = {**g.to_dict(), "how": how, "phi": phi, "driving_sigma_si": qd}
        except FogdriftError as exc:  # refused: reported in the JSON
            d["bias_gauss_markov"] = {"how": "refused", "note": str(exc)}
        d["state_space"] = discrete_model(ch, ctx.rate_hz)
        if ch.no_fit:
            d["state_space"]["caveat"] = ("no model fits this record: the state-space model uses the best candidate's "
                                          "values, which are not a result")
        chans.append(d)
    doc = {"fogdrift_export": "json", "update_rate_hz": ctx.rate_hz, "missing": ctx.missing,
           "conventions": {"si_rate_units": {"gyro": "rad/s", "accel": "m/s^2"},
                           "white": "continuous density N; discrete 1-sigma N sqrt(f)",
                           "random_walk": "continuous density K; discrete step 1-sigma K / sqrt(f)",
                           "gauss_markov": "phi = exp(-dt/T_c), driving 1-sigma = sigma sqrt(1 - phi^2)",
                           "source": "Kalibr wiki 'IMU Noise Model'; IEEE Std 952-1997 Annex C"},
           "channels": chans}
    ctx.fill("json", f"SI: continuous values and their discrete values at {fmt(ctx.rate_hz)} Hz", [])
    return json.dumps(_json_safe(doc), indent=1, allow_nan=False, default=_json_default) + "\n"


def _json_safe(x):
    """``x`` with every non-finite float replaced by None (JSON null): json.dumps never passes a float to
    ``default``, so a NaN (a GMWM result without ``tau_range_s``, say) would otherwise stop the export."""
    if isinstance(x, float) and not math.isfinite(x):
        return None
    if isinstance(x, dict):
        return {k: _json_safe(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_json_safe(v) for v in x]
    return x


def _json_default(x):
    raise TypeError(type(x).__name__)
