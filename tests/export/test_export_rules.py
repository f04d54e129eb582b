"""Rules of ``fogdrift.export`` (writers, model, discretize, targets), pinned one by one: first written against the
surviving mutants of mutation round 3 (docs/testing-rounds.md).

Each test pins a rule a one-line change would break, against values worked out by hand: every field of a GMWM
(``noise.json``) and an Allan (``allan.json``) result read into a :class:`ChannelModel` (units, defaults, statuses,
reasons, sources), the random-walk bound from the wavelet variance, the ``--missing`` policy's messages, the
Gauss-Markov bias (sigma = 1.0760 B, T_c = tau_B / 1.8926), the values and comments of each target read back by
the parser its project uses (PyYAML, OpenCV FileStorage), and the state-space model against Van Loan by hand
(phi = exp(-dt/T), Qd = sigma^2 (1 - exp(-2 dt/T)); Kalibr units N [rad/s/sqrt(Hz)], K [rad/s^2/sqrt(Hz)]).
"""

from __future__ import annotations

import json
import math
import re

import pytest
import yaml

from fogdrift.errors import ConfigError, DataFormatError
from fogdrift.export.model import _rw_bound_from_wv, channels_from_result

D = math.pi / 180.0          # rad per deg
G0 = 9.80665                 # m/s^2 per g
DPH = D / 3600.0             # rad/s per deg/h
RRW = D / 216000.0           # rad/s^1.5 per deg/h^1.5  (3600^1.5 = 216000)


def approx(expected, rel=1e-6, abs=0.0):  # noqa: A002
    """pytest.approx without its default absolute tolerance of 1e-12, which would pass any two SI values below
    ~1e-10 (K in rad/s^2/sqrt(Hz), Qd in (rad/s)^2): a relative check must be relative."""
    return pytest.approx(expected, rel=rel, abs=abs)


# ------------------------------------------------------------------------------------------------------------------
# GMWM results (noise.json) read into a ChannelModel
# ------------------------------------------------------------------------------------------------------------------
def _t(value, lo, hi, unit=None, component=None):
    d = {"value": value, "lo95": lo, "hi95": hi}
    if unit is not None:
        d["unit"] = unit
    if component is not None:
        d["component"] = component
    return d


def _gm(tc, sigma, *, unit="deg/h", component="GM1", ci=True):
    g = {"tc_s": {"value": tc, "lo95": tc / 2 if ci else None, "hi95": tc * 2 if ci else None},
         "sigma_gm_dph": {"value": sigma}}
    if ci:
        g["sigma_gm_dph"].update(lo95=sigma / 2, hi95=sigma * 2)
    if unit is not None:
        g["sigma_gm_dph"]["unit"] = unit
    if component is not None:
        g["component"] = component
    return g


def _full_gmwm_axis():
    return {"name": "gx", "method": "gmwm", "selected": "NOT-THIS", "j_statistic": {"p_value": 0.4321},
            "selection": {"ieee": {
                "model": "WN+RW+GM",
                "terms": {"N_dprh": _t(0.3, 0.27, 0.33, "deg/sqrt(h)", "WN"),
                          "K_dphrh": _t(2.0, 0.5, 3.0, "deg/h/sqrt(h)", "RW"),
                          "R_dph2": _t(1.0, 0.0, 2.0, "deg/h^2", "DR")},
                "gm": [_gm(100.0, 4.0)],
                "b_headline": {"value_dph": 1.5, "lo95_dph": 1.0, "hi95_dph": 2.0, "tau_s": 300.0,
                               "label": "min of the model's ADEV / 0.664"},
                "tau_range_s": [0.05, 500.0], "dt_s": 0.01}}}


def _one(ax, record=None, path="noise.json"):
    chans = channels_from_result({"record": {} if record is None else record, "axes": [ax]}, path)
    assert len(chans) == 1
    return chans[0]


def test_gmwm_channel_every_field_by_hand():
    ch = _one(_full_gmwm_axis(), _record(200.0, sha256="cd" * 32), path="run/noise.json")
    assert (ch.name, ch.quantity, ch.method) == ("gx", "gyro", "gmwm")
    assert ch.fit == "GMWM model WN+RW+GM (J-test p = 0.43)"
    assert ch.rate_hz == 200.0 and ch.sha256 == "cd" * 32 and ch.source_file == "run/noise.json"
    assert ch.tau_range_s == (0.05, 500.0) and ch.b_tau_s == 300.0
    assert ch.b_is_flicker is False and ch.no_fit is False
    n = ch.terms["N"]
    assert (n.value, n.lo95, n.hi95, n.unit, n.status, n.reason) == (0.3, 0.27, 0.33, "deg/sqrt(h)", "resolved", "")
    assert n.source == "gmwm WN+RW+GM: N (component WN)"
    assert n.si == approx(0.3 * D / 60.0, rel=1e-12)
    assert n.si_lo95 == approx(0.27 * D / 60.0, rel=1e-12)
    assert n.si_hi95 == approx(0.33 * D / 60.0, rel=1e-12)
    k = ch.terms["K"]                                     # deg/h/sqrt(h) is read as deg/h^1.5
    assert k.unit == "deg/h^1.5" and k.status == "resolved" and k.si == approx(2.0 * RRW, rel=1e-12)
    r = ch.terms["R"]                                     # lo95 = 0: not resolved from zero
    assert (r.status, r.reason) == ("unresolved", "its 95 % interval reaches 0")
    assert r.si == approx(1.0 * D / 3600.0 ** 2, rel=1e-12)       # deg/h^2 -> rad/s^2
    q = ch.terms["Q"]                                     # not in the model, GMWM gives no bound
    assert (q.value, q.lo95, q.hi95, q.unit, q.status) == (None, None, None, "urad", "absent")
    assert q.reason == "not in the GMWM model WN+RW+GM (GMWM gives no upper bound for a term it leaves out)"
    assert q.source == "gmwm WN+RW+GM: Q"
    b = ch.terms["B"]                                     # the headline reading, resolved
    assert (b.value, b.lo95, b.hi95, b.unit, b.status, b.reason) == (1.5, 1.0, 2.0, "deg/h", "resolved", "")
    assert b.source == "gmwm WN+RW+GM: B, min of the model's ADEV / 0.664"
    assert b.si == approx(1.5 * DPH, rel=1e-12) and b.si_hi95 == approx(2.0 * DPH, rel=1e-12)
    assert b.has_estimate
    (g,) = ch.gms
    assert g.sigma_si == approx(4.0 * DPH, rel=1e-12) and g.tc_s == 100.0
    assert g.sigma_lo95_si == approx(2.0 * DPH, rel=1e-12)
    assert g.sigma_hi95_si == approx(8.0 * DPH, rel=1e-12)
    assert (g.tc_lo95_s, g.tc_hi95_s) == (50.0, 200.0) and g.source == "gmwm WN+RW+GM: GM1"


def test_gmwm_channel_defaults_when_fields_are_absent():
    ax = _full_gmwm_axis()
    ie = ax["selection"]["ieee"]
    del ie["model"], ie["b_headline"], ie["tau_range_s"], ax["j_statistic"]
    ax["selected"] = "WN+GM"
    ie["terms"]["K_dphrh"] = _t(2.0, 0.5, 3.0)           # no unit: the gyro default deg/h^1.5, no component: '?'
    ie["gm"] = [_gm(50.0, 3.0, unit=None, component=None, ci=False)]
    ch = _one(ax, {})
    assert ch.fit == "GMWM model WN+GM"                    # no J-test: no p in the words
    assert ch.rate_hz == approx(100.0, rel=1e-12)  # 1 / dt_s
    assert ch.sha256 == "" and ch.b_tau_s is None
    assert all(math.isnan(x) for x in ch.tau_range_s)
    assert ch.terms["K"].unit == "deg/h^1.5" and ch.terms["K"].source == "gmwm WN+GM: K (component ?)"
    assert ch.terms["K"].si == approx(2.0 * RRW, rel=1e-12)
    b = ch.terms["B"]                                     # no headline: absent, no bound
    assert (b.value, b.lo95, b.hi95, b.unit, b.status) == (None, 0.0, None, "deg/h", "absent")
    assert b.reason == "no bias-instability reading" and b.source == "gmwm WN+GM: B, "
    (g,) = ch.gms                                         # sigma without unit: deg/h; no interval, no name
    assert g.sigma_si == approx(3.0 * DPH, rel=1e-12)
    assert (g.sigma_lo95_si, g.sigma_hi95_si, g.tc_lo95_s, g.tc_hi95_s) == (None, None, None, None)
    assert g.source == "gmwm WN+GM: GM"
    ax2 = _full_gmwm_axis()
    del ax2["selection"]["ieee"]["model"], ax2["selected"]
    assert _one(ax2).terms["Q"].reason.startswith("not in the GMWM model ? (")


def test_gmwm_b_headline_bound_and_flicker_term():
    ax = _full_gmwm_axis()
    ax["selection"]["ieee"]["b_headline"] = {"value_dph": None, "bound_dph": 9.0, "tau_s": 800.0,
                                             "reason": "95 % upper bound: no minimum in the range",
                                             "label": "min of the model's ADEV / 0.664"}
    ch = _one(ax, _record(100.0))
    b = ch.terms["B"]
    assert (b.value, b.lo95, b.hi95, b.status) == (None, 0.0, 9.0, "absent")
    assert b.si_hi95 == approx(9.0 * DPH, rel=1e-12) and b.si_lo95 == 0.0
    assert b.reason == "95 % upper bound: no minimum in the range" and not b.has_estimate
    assert b.source == "gmwm WN+RW+GM: B, min of the model's ADEV / 0.664"
    assert ch.b_is_flicker is False and ch.b_tau_s == 800.0
    # a flicker component (B_dph) in the model: B is that term, not the headline, and b_is_flicker is set
    ax["selection"]["ieee"]["terms"]["B_dph"] = _t(0.7, 0.5, 0.9, "deg/h", "FLK")
    ch = _one(ax, _record(100.0))
    assert ch.b_is_flicker is True
    b = ch.terms["B"]
    assert (b.value, b.status, b.source) == (0.7, "resolved", "gmwm WN+RW+GM: B (component FLK)")


def test_gmwm_headline_without_label_and_n_without_unit():
    ax = _full_gmwm_axis()
    ie = ax["selection"]["ieee"]
    del ie["b_headline"]["label"]
    ie["terms"]["N_dprh"] = _t(0.3, 0.27, 0.33)            # no unit: deg/sqrt(h), a gyro
    ch = _one(ax)
    assert ch.terms["B"].source == "gmwm WN+RW+GM: B, " and ch.terms["B"].status == "resolved"
    assert ch.quantity == "gyro" and ch.terms["N"].unit == "deg/sqrt(h)"
    assert ch.terms["N"].si == approx(0.3 * D / 60.0, rel=1e-12)
    del ie["terms"]["N_dprh"]                                # no N at all: absent, in the gyro's unit
    n = _one(ax).terms["N"]
    assert (n.unit, n.status, n.value, n.hi95) == ("deg/sqrt(h)", "absent", None, None)


def test_gmwm_accelerometer_defaults_are_specific_force_units():
    ax = _full_gmwm_axis()
    ie = ax["selection"]["ieee"]
    ie["terms"] = {"N_dprh": _t(0.06, 0.05, 0.07, "m/s/sqrt(h)", "WN")}
    ie["gm"] = [_gm(300.0, 2e-4, unit="m/s^2")]
    ie["b_headline"] = {"value_dph": None, "bound_dph": 5e-4, "tau_s": 600.0}
    ax["wvar"] = {"tau_samples": [2, 4], "ci_hi95_dph2": [1.0, 1.0], "dt_s": 0.01, "scale_s": [0.02, 0.04]}
    ch = _one(ax, _record(100.0))
    assert ch.quantity == "accel"                         # B's bound is read in m/s^2 (not deg/h)
    assert {k: ch.terms[k].unit for k in "NKRQB"} == {"N": "m/s/sqrt(h)", "K": "m/s^2/sqrt(s)", "R": "m/s^3",
                                                      "Q": "m/s", "B": "m/s^2"}
    assert ch.terms["B"].si_hi95 == approx(5e-4, rel=1e-12)
    assert ch.terms["N"].si == approx(0.06 / 60.0, rel=1e-12)
    k = ch.terms["K"]                                     # the wavelet-variance bound is a gyro (deg/h) reading
    assert k.hi95 is None and k.lo95 is None
    assert k.reason.endswith("(GMWM gives no upper bound for a term it leaves out)")
    assert ch.gms[0].sigma_si == approx(2e-4, rel=1e-12)
    assert ch.gms[0].sigma_hi95_si == approx(4e-4, rel=1e-12)


def test_gmwm_wavelet_bound_is_for_the_gyro_random_walk_only():
    ax = _full_gmwm_axis()
    ie = ax["selection"]["ieee"]
    del ie["terms"]["K_dphrh"]
    ax["wvar"] = {"tau_samples": [2, 8, 32], "ci_hi95_dph2": [9.0, 5.0, 3.0], "dt_s": 0.01,
                  "scale_s": [0.02, 0.08, 0.32]}
    ch = _one(ax, _record(100.0))
    k = ch.terms["K"]
    tau = 32.0                                            # the LAST scale, not the first or the second
    k_bound = 60.0 * math.sqrt(3.0 * 12.0 * tau / (tau * tau + 2.0) / 0.01)
    assert k.hi95 == approx(k_bound, rel=1e-12) and k.lo95 == 0.0 and k.status == "absent"
    assert k.reason.startswith("not in the GMWM model WN+RW+GM; 95 % upper bound from the wavelet variance")
    assert "longest scale (0.32 s)" in k.reason
    assert ch.terms["Q"].hi95 is None                     # only K gets the wavelet bound


@pytest.mark.parametrize("wv", [
    None, {}, {"tau_samples": [], "ci_hi95_dph2": [], "dt_s": 0.01, "scale_s": []},
    {"tau_samples": [0], "ci_hi95_dph2": [1.0], "dt_s": 0.01, "scale_s": [1.0]},
    {"tau_samples": [4], "ci_hi95_dph2": [0.0], "dt_s": 0.01, "scale_s": [1.0]},
    {"tau_samples": [4], "ci_hi95_dph2": [1.0], "dt_s": 0.0, "scale_s": [1.0]},
    {"tau_samples": [4], "ci_hi95_dph2": [math.inf], "dt_s": 0.01, "scale_s": [1.0]},
    {"tau_samples": [4], "ci_hi95_dph2": ["x"], "dt_s": 0.01, "scale_s": [1.0]},
])
def test_rw_bound_from_wv_gives_nothing_for_an_unusable_variance(wv):
    assert _rw_bound_from_wv(wv) == (None, "")


@pytest.mark.parametrize("tau, hi, dt", [(1.0, 0.5, 0.1), (0.5, 2.0, 0.01), (64.0, 1e-4, 0.005)])
def test_rw_bound_from_wv_by_hand(tau, hi, dt):
    # K [deg/h^1.5] = 60 sqrt(hi * 12 tau / ((tau^2 + 2) dt)): Haar WV of a random walk gamma^2 (tau^2 + 2) / (12 tau)
    k, why = _rw_bound_from_wv({"tau_samples": [tau], "ci_hi95_dph2": [hi], "dt_s": dt, "scale_s": [tau * dt]})
    assert k == approx(60.0 * math.sqrt(hi * 12.0 * tau / ((tau * tau + 2.0) * dt)), rel=1e-12)
    assert why.startswith("95 % upper bound from the wavelet variance")


def test_gmwm_axis_without_ieee_terms_is_refused_in_one_line():
    ax = _full_gmwm_axis()
    del ax["selection"]["ieee"]["terms"]
    with pytest.raises(DataFormatError) as ei:
        _one(ax, path="n.json")
    msg = str(ei.value)
    assert "n.json" in msg and "axis 'gx' has no GMWM IEEE reading ('selection.ieee.terms')" in msg
    assert "\n" not in msg


def test_gmwm_units_that_say_two_quantities_are_refused():
    ax = _full_gmwm_axis()
    ax["selection"]["ieee"]["terms"]["K_dphrh"] = _t(1e-4, 5e-5, 2e-4, "m/s^2/sqrt(s)", "RW")
    with pytest.raises(DataFormatError, match=r"n\.json: axis gx: the terms' units do not say one quantity"):
        _one(ax, path="n.json")


# ------------------------------------------------------------------------------------------------------------------
# writers: what each file says beside its numbers (units, discretisation, provenance), read back
# ------------------------------------------------------------------------------------------------------------------
import sys  # noqa: E402
from pathlib import Path  # noqa: E402

sys.path.insert(0, str(Path(__file__).parent))
from test_export import _accel_result, _gyro_result, _record  # noqa: E402  (the hand-made result files of test_export)

from fogdrift.export import build_context, render  # noqa: E402


@pytest.fixture
def both(tmp_path):
    return build_context([_gyro_result(tmp_path)], [_accel_result(tmp_path)])


#: The first line of each file: the target and the reader it was written for (its project's documentation).
_HEADERS = {
    "kalibr": "# fogdrift export --target kalibr: noise model for Kalibr imu.yaml (continuous-time densities; "
              "Kalibr discretises at update_rate)",
    "openvins": "# fogdrift export --target openvins: noise model for OpenVINS kalibr_imu_chain.yaml "
                "(read with cv::FileStorage)",
    "vins-fusion": "# fogdrift export --target vins-fusion: noise model for VINS-Fusion config (IMU block; "
                   "cv::FileStorage)",
    "orbslam3": "# fogdrift export --target orbslam3: noise model for ORB-SLAM3 settings (IMU block; cv::FileStorage)",
    "kf-gins": "# fogdrift export --target kf-gins: noise model for KF-GINS imunoise block (merge into kf-gins.yaml)",
    "matlab": "% fogdrift export --target matlab: noise model for MATLAB imuSensor (gyroparams / accelparams, "
              "Navigation / Sensor Fusion Toolbox)",
    "gnss-ins-sim": "# fogdrift export --target gnss-ins-sim: noise model for gnss-ins-sim imu_err dictionary "
                    "(README 'Step 1.1'; imu_model.IMU)",
}

#: Lines each file must carry: where its conventions come from (cited source code or documentation) and what is
#: written as the program's default, NOT MEASURED (issue 37: every key the program requires is written).
_CITED = {
    "openvins": ["# OpenVINS reads continuous-time densities and discretises itself (ov_msckf Propagator: sigma^2 / dt for",
                 "# the white noises, sigma_b^2 dt for the bias walks per IMU step)",
                 "  # T_i_b: NOT MEASURED: identity (fogdrift does not calibrate extrinsics; Kalibr's multi-IMU pose)",
                 '  model: "kalibr"  # VioManagerOptions / StateOptions read kalibr, calibrated or rpng']
                + [f"  # {m}: NOT MEASURED: fogdrift does not calibrate IMU intrinsics; OpenVINS's neutral value (its own "
                   "default in VioManagerOptions.h: an ideal IMU)" for m in ("Tw", "R_IMUtoGYRO", "Ta", "R_IMUtoACC", "Tg")],
    "vins-fusion": [
        "# merge these keys into your VINS-Fusion config (parameters.cpp readParameters reads imu, imu_topic,",
        "# acc_n, acc_w, gyr_n, gyr_w, g_norm; a missing number reads as 0 without an error).",
        "# TIME CONVENTION: per IMU step at 100.0 Hz, as VINS-Fusion's integration code applies them",
        "# (vins_estimator/src/factor/integration_base.h, midPointIntegration: covariance += V noise V^T, noise =",
        "# diag(acc_n^2, gyr_n^2, acc_n^2, gyr_n^2, acc_w^2, gyr_w^2), V = 0.5 dt on each of the two averaged samples",
        "# and dt on the bias walks): matching the continuous model per step needs",
        "#   acc_n, gyr_n = N sqrt(2 f) = N x 14.1421;  acc_w, gyr_w = K sqrt(f) = K x 10.0",      # sqrt(200), sqrt(100)
        "# at 100.0 Hz only: re-export with --update-rate for another IMU rate.",
        "# g_norm: NOT MEASURED: standard gravity (CGPM 1901); put your local gravity magnitude",
        "g_norm: 9.80665  # [m/s^2]"],
    "orbslam3": ["# ORB-SLAM3 reads continuous densities and discretises itself: noise x sqrt(IMU.Frequency), "
                 "walk / sqrt(IMU.Frequency) (Tracking: IMU::Calib(Tbc, Ng*sf, Na*sf, Ngw/sf, Naw/sf), "
                 "sf = sqrt(freq))",
                 "# IMU.T_b_c1 (camera 1 to IMU body): NOT MEASURED: identity (fogdrift does not calibrate extrinsics); "
                 "put your camera-IMU calibration (Kalibr's T_cam_imu, inverted)"],
    "kf-gins": ["# KF-GINS (src/kf_gins.cpp, loading the configuration) requires imunoise: arw, vrw, gbstd, abstd, gsstd,",
                "# asstd (three numbers each) and corrtime; it converts arw x (pi/180)/60, vrw / 60, gbstd x (pi/180)/3600,",
                "# abstd x 1e-5, gsstd and asstd x 1e-6, corrtime x 3600 and uses them in continuous time",
                "# scale factor): each bias one first-order Gauss-Markov, ONE correlation time for all of them; a random",
                "# walk K has no place in it",
                "  # gsstd, asstd (scale-factor instability): NOT MEASURED: a static record does not observe scale factors;",
                "  # KF-GINS's dataset/kf-gins.yaml values are written: replace them with your datasheet's",
                "  gsstd: [300.0, 300.0, 300.0]  # [ppm] NOT MEASURED",
                "  asstd: [300.0, 300.0, 300.0]  # [ppm] NOT MEASURED"],
    "matlab": ["% Units per the gyroparams / accelparams reference pages: NoiseDensity (rad/s)/sqrt(Hz) and "
               "(m/s^2)/sqrt(Hz), RandomWalk (rad/s)*sqrt(Hz) and (m/s^2)*sqrt(Hz), BiasInstability rad/s and m/s^2",
               "% (MathWorks Answers 1631045: RandomWalk is the rate random walk K, NoiseDensity the white density N)",
               "% BiasInstability is B (the flicker floor); BiasInstabilityCoefficients is left at its default"],
    "gnss-ins-sim": ["# gnss_ins_sim/sim/imu_model.py IMU(accuracy=imu_err) requires gyro_b, gyro_b_stability, gyro_arw, "
                     "accel_b, accel_b_stability, accel_vrw (b_corr optional: infinite = white bias); pathgen.py applies "
                     "arw and",
                     "# vrw as continuous densities (per sample / sqrt(dt)); b_stability is the 1-sigma of a first-order "
                     "Gauss-Markov bias with correlation time b_corr (bias_drift)",
                     "    # constant bias: not a noise term (removed by calibration); 0 = a calibrated sensor"],
}


@pytest.mark.parametrize("target", list(_HEADERS))
def test_each_file_names_its_target_reader_and_conventions(both, target):
    lines = render(target, both).splitlines()
    pre = "% " if target == "matlab" else "# "
    body = lines[2:] if lines[0] == "%YAML:1.0" else lines
    if lines[0] == "%YAML:1.0":
        assert lines[1] == ""                                   # OpenCV wants the directive alone on line 1
    assert body[0] == _HEADERS[target]
    assert body[2] == f"{pre}update rate 100.0 Hz; --missing bound"
    assert f"{pre}gyro gx: allan model N+B+K (chi2_red 1.1, good)" in body
    assert f"{pre}accel az: allan model N+B+K (chi2_red 1.1, good)" in body
    assert (f"{pre}continuous -> discrete: white sigma_d = N sqrt(f), random-walk step sigma_bd = K / sqrt(f) "
            "(Kalibr wiki 'IMU Noise Model')") in body
    for line in _CITED.get(target, []):
        assert line in lines, line
    assert lines[-1] != "" and render(target, both).endswith("\n") and not render(target, both).endswith("\n\n")


_DISC = {"N": "(x sqrt(f))", "K": "(/ sqrt(f))", "B": "a standard deviation: the same in continuous and discrete time"}


@pytest.mark.parametrize("target", ["kalibr", "openvins", "vins-fusion", "orbslam3", "kf-gins", "matlab",
                                    "gnss-ins-sim"])
def test_every_term_comment_says_how_it_is_discretised(both, target):
    # a term's description line is followed by its continuous value and the rule that makes it discrete
    lines = render(target, both).splitlines()
    seen = set()
    for i, line in enumerate(lines):
        m = re.match(r"^\s*[#%] ([ga][xyz]): ([NKB]) = ", line)
        if m:
            nxt = lines[i + 1]
            assert nxt.lstrip("#% ").startswith("continuous "), nxt
            assert nxt.endswith(_DISC[m.group(2)]), nxt
            if m.group(2) != "B":
                assert " per sample at 100.0 Hz " in nxt or " per-sample bias step at 100.0 Hz " in nxt
            seen.add(m.group(2))
    assert seen == ({"N", "K", "B"} if target == "matlab" else {"N"} if target in ("kf-gins", "gnss-ins-sim")
                    else {"N", "K"})


#: Per target: each "written ..." comment line (the output unit of the value under it).
_WRITTEN = {
    "kf-gins": ["  # written per axis (gx, gy, gz) in deg/sqrt(h)", "  # written per axis (ax, ay, az) in m/s/sqrt(h)",
                "  # written per axis: sigma in deg/h, T_c in s", "  # written per axis: sigma in mGal, T_c in s"],
    "matlab": ["% written per axis (gx, gy, gz) in (rad/s)/sqrt(Hz)", "% written per axis (gx, gy, gz) in (rad/s)*sqrt(Hz)",
               "% written per axis (gx, gy, gz) in rad/s", "% written per axis (ax, ay, az) in (m/s^2)/sqrt(Hz)",
               "% written per axis (ax, ay, az) in (m/s^2)*sqrt(Hz)", "% written per axis (ax, ay, az) in m/s^2"],
    "gnss-ins-sim": ["    # written per axis (gx, gy, gz) in deg/sqrt(h)", "    # written per axis: sigma in deg/h, T_c in s",
                     "    # written per axis (ax, ay, az) in m/s/sqrt(h)", "    # written per axis: sigma in m/s^2, T_c in s"],
}

#: Per target: the unit in the bracket after each key (targets.py's units, from each project's documentation).
_KEY_UNITS = {
    "kf-gins": {"arw": "deg/sqrt(h)", "vrw": "m/s/sqrt(h)", "gbstd": "deg/h", "abstd": "mGal", "gsstd": "ppm",
                "asstd": "ppm", "corrtime": "h"},
    "gnss-ins-sim": {"'gyro_b'": "deg/h", "'gyro_arw'": "deg/sqrt(h)", "'gyro_b_stability'": "deg/h",
                     "'gyro_b_corr'": "s", "'accel_b'": "m/s^2", "'accel_vrw'": "m/s/sqrt(h)",
                     "'accel_b_stability'": "m/s^2", "'accel_b_corr'": "s"},
}


@pytest.mark.parametrize("target", list(_WRITTEN))
def test_per_axis_values_say_their_units(both, target):
    lines = render(target, both).splitlines()
    assert [ln for ln in lines if re.match(r"^\s*[#%] written per axis", ln)] == _WRITTEN[target]
    if target in _KEY_UNITS:
        # the bracket is the first "# [" after the value; words may follow it ("continuous time", "NOT MEASURED")
        got = {m.group(1): m.group(2) for m in (re.match(r"^\s*('?\w+'?): [^#]*# \[([^\]]+)\]", ln) for ln in lines) if m}
        assert got == _KEY_UNITS[target]


def test_gauss_markov_comment_by_hand(both, tmp_path):
    # gx: B = 2 deg/h read at tau_B = 100 s: sigma = 1.0760 * 2 deg/h, T_c = 100 / 1.8926 s; at 100 Hz
    # phi = exp(-0.01 / T_c), driving sigma = sigma sqrt(1 - phi^2)
    text = render("kf-gins", both)
    tc = 100.0 / 1.8926
    sigma = 1.0760 * 2.0 * DPH
    phi = math.exp(-0.01 / tc)
    m = re.search(r"# gx: bias Gauss-Markov: one GM matched to B \(estimate\): .*\n\s*# +sigma = (\S+) rad/s "
                  r"\(95 % \[(\S+), (\S+)\] deg/h\), T_c = (\S+) s; discrete at 100.0 Hz: phi = exp\(-dt/T_c\) = "
                  r"(\S+), driving sigma = sigma sqrt\(1 - phi\^2\) = (\S+) rad/s", text)
    assert m, text
    s, lo, hi, t, p, q = (float(v) for v in m.groups())
    assert s == approx(sigma, rel=1e-4) and t == approx(tc, rel=1e-4)
    assert lo == approx(1.0760 * 1.5, rel=1e-3) and hi == approx(1.0760 * 2.5, rel=1e-3)  # deg/h
    assert p == approx(math.exp(-0.01 / t), abs=2e-9)            # the identity, on the printed T_c
    assert q == approx(sigma * math.sqrt(1 - phi * phi), rel=1e-3)
    # one corrtime for all six biases: the geometric mean of equal T_c is that T_c, given in s per axis and written
    # in h (52.8369 s = 0.0146769 h); each sigma re-matched to it is then the axis's own 1.0760 B
    lines = text.splitlines()
    assert ("  # corrtime: KF-GINS takes one correlation time for all six biases (and the scale factors): the geometric "
            "mean of the axes' T_c (gyroscope 52.8369, 52.8369, 52.8369 s; accelerometer 52.8369, 52.8369, 52.8369 s), "
            "each axis's sigma re-matched to it above") in lines
    assert "  corrtime: 0.0146769  # [h]" in lines
    assert ("  # gx: for the one corrtime 52.8369 s: sigma = 2.152 deg/h (its Allan variance at 1.8926 x 52.8369 s, "
            "the peak of the axis's own Gauss-Markov, kept)") in lines
    d = yaml.safe_load(text)["imunoise"]
    assert d["corrtime"] == approx(tc / 3600.0, rel=1e-5)
    assert d["gbstd"] == approx([1.0760 * 2.0, 1.0760 * 3.0, 1.0760 * 1.0], rel=1e-5)   # B = 2, 3, 1 deg/h
    # the gyro's B read at tau_B = 200 s, the accelerometer's at 100 s: the one corrtime is the geometric mean over
    # all six axes, sqrt(T_g T_a), of both quantities (not the gyroscope's, not the longest)
    ctx = build_context([_gyro_result(tmp_path, name="gyro200.json", b_tau=200.0)], [_accel_result(tmp_path)])
    text = render("kf-gins", ctx)
    assert yaml.safe_load(text)["imunoise"]["corrtime"] == approx(math.sqrt(200.0 * 100.0) / 1.8926 / 3600.0, rel=1e-5)
    assert ("the geometric mean of the axes' T_c (gyroscope 105.674, 105.674, 105.674 s; accelerometer 52.8369, "
            "52.8369, 52.8369 s)") in text                                  # 200 / 1.8926, 100 / 1.8926


def test_openvins_extrinsics_identity_and_keys_read_by_opencv(both, tmp_path):
    cv2 = pytest.importorskip("cv2")
    p = tmp_path / "ov.yaml"
    p.write_text(render("openvins", both))
    fs = cv2.FileStorage(str(p), cv2.FILE_STORAGE_READ)
    imu0 = fs.getNode("imu0")
    t = imu0.getNode("T_i_b")
    rows = [[t.at(i).at(j).real() for j in range(t.at(i).size())] for i in range(t.size())]
    assert rows == [[1.0 if i == j else 0.0 for j in range(4)] for i in range(4)]
    # the IMU intrinsics OpenVINS requires, NOT MEASURED: its own ideal-IMU defaults (identity; Tg zero)
    for name, want in (("Tw", 1.0), ("R_IMUtoGYRO", 1.0), ("Ta", 1.0), ("R_IMUtoACC", 1.0), ("Tg", 0.0)):
        m = imu0.getNode(name)
        got = [[m.at(i).at(j).real() for j in range(m.at(i).size())] for i in range(m.size())]
        assert got == [[want if i == j else 0.0 for j in range(3)] for i in range(3)], name
    assert imu0.getNode("time_offset").isReal() and imu0.getNode("time_offset").real() == 0.0
    assert imu0.getNode("model").string() == "kalibr" and imu0.getNode("rostopic").string() == "/imu0"
    fs.release()


def test_matlab_file_is_comments_and_four_statements(both):
    code = [ln for ln in render("matlab", both).splitlines() if not ln.startswith("% ")]
    assert [ln.split("(")[0] for ln in code if not ln.startswith("    '")] == \
        ["gyro = gyroparams", "accel = accelparams", "imu = imuSensor"]
    assert len(code) == 9
    # each statement line, its trailing "% unit" comment set aside, continues ("( ...", ", ...") or ends (");"), and
    # that comment is one of the units of the reference pages
    units = ("(rad/s)/sqrt(Hz)", "(rad/s)*sqrt(Hz)", "rad/s", "(m/s^2)/sqrt(Hz)", "(m/s^2)*sqrt(Hz)", "m/s^2",
             "SampleRate [Hz]")
    for ln in code:
        stmt, _, comment = ln.partition("%")
        assert stmt.rstrip().endswith(("( ...", ", ...", ");")), ln
        assert comment == "" or comment.strip() in units, ln
    assert code[-1] == "imu = imuSensor('accel-gyro', 'SampleRate', 100.0, 'Gyroscope', gyro, 'Accelerometer', accel);  " \
                       "% SampleRate [Hz]"


def _gyro_only(tmp_path):
    return build_context([_gyro_result(tmp_path)])


def _accel_only(tmp_path):
    return build_context(accel=[_accel_result(tmp_path)])


#: The comment above the keys of a quantity without a result (issue 37: written as the program's default, NOT MEASURED).
_NOT_MEASURED = ("{keys}: NOT MEASURED: no {w} result was given (fogdrift export --{q} RESULT.json); the program requires "
                 "them, so {src} values are written: replace them with your {w}'s")
#: The console warning that names the missing input.
_WARNED = "{target}: no {w} result given (--{q} FILE): {keys} written as {src} values, NOT MEASURED"
#: What MATLAB's file says of a quantity it leaves out (imuSensor has an ideal default).
_LEFT_OUT = "not written: no {w} result was given (fogdrift export --{q} RESULT.json); matlab then uses its own ideal default"

#: Each program's default / shipped example, the values written for a quantity without a result (docs/export.md).
_SRC = {"kalibr": "OpenVINS's default (ov_msckf/src/utils/NoiseManager.h; Kalibr has none)",
        "openvins": "OpenVINS's own default (ov_msckf/src/utils/NoiseManager.h)",
        "vins-fusion": "VINS-Fusion's config/euroc/euroc_mono_imu_config.yaml",
        "orbslam3": "ORB-SLAM3's Examples/Monocular-Inertial/EuRoC.yaml",
        "kf-gins": "KF-GINS's dataset/kf-gins.yaml",
        "gnss-ins-sim": "gnss-ins-sim's default profile 'low-accuracy' (gnss_ins_sim/sim/imu_model.py)"}
_GNSS_DEFAULT = {"gyro_arw": 0.75, "gyro_b_stability": 10.0, "gyro_b_corr": 100.0,           # 'low-accuracy'
                 "accel_vrw": 0.05, "accel_b_stability": 2.0e-4, "accel_b_corr": 100.0}


def test_gnss_ins_sim_with_one_quantity(tmp_path):
    for ctx, have, miss, w in ((_gyro_only(tmp_path), "gyro", "accel", "accelerometer"),
                               (_accel_only(tmp_path), "accel", "gyro", "gyroscope")):
        text = render("gnss-ins-sim", ctx)
        lines = text.splitlines()
        assert lines[0] == _HEADERS["gnss-ins-sim"]
        keys = [f"{miss}_{'arw' if miss == 'gyro' else 'vrw'}", f"{miss}_b_stability", f"{miss}_b_corr"]
        src = _SRC["gnss-ins-sim"]
        assert lines.count("    # " + _NOT_MEASURED.format(keys=", ".join(keys), w=w, q=miss, src=src)) == 1
        units = ("deg/sqrt(h)", "deg/h", "s") if miss == "gyro" else ("m/s/sqrt(h)", "m/s^2", "s")
        for k, u in zip(keys, units):                           # each written once, its unit, said NOT MEASURED
            assert sum(1 for ln in lines if ln.startswith(f"    '{k}': ")) == 1
            assert [ln for ln in lines if ln.startswith(f"    '{k}': ")][0].endswith(f"  # [{u}] NOT MEASURED"), k
        assert _WARNED.format(target="gnss-ins-sim", w=w, q=miss, keys=", ".join(keys), src=src) in ctx.notes
        ns = {}
        exec(text, ns)  # noqa: S102 - our own generated file
        err = ns["imu_err"]                                     # every key IMU() requires, three values each
        assert sorted(err) == sorted(f"{q}_{k}" for q in ("gyro", "accel")
                                     for k in ("b", "arw" if q == "gyro" else "vrw", "b_stability", "b_corr"))
        assert all(len(v) == 3 for v in err.values())
        for k in keys:
            assert list(err[k]) == approx([_GNSS_DEFAULT[k]] * 3, rel=1e-12), k
        assert list(err[f"{miss}_b"]) == [0.0, 0.0, 0.0]        # a calibrated constant bias, as for a measured one
        assert list(err[f"{have}_b_corr"]) == approx([100 / 1.8926] * 3, rel=1e-4)
        assert not any("NOT MEASURED" in ln for ln in lines if ln.startswith(f"    '{have}_"))


def test_kfgins_and_matlab_with_one_quantity(tmp_path):
    g = _gyro_only(tmp_path)
    kf = render("kf-gins", g).splitlines()
    assert kf[0] == _HEADERS["kf-gins"]
    d = yaml.safe_load("\n".join(kf))["imunoise"]
    assert d["arw"] == approx([0.15, 0.20, 0.10], rel=1e-5)
    src = _SRC["kf-gins"]
    for key, val, unit in (("vrw", 0.03, "m/s/sqrt(h)"), ("abstd", 15.0, "mGal")):   # KF-GINS's example values
        assert "  # " + _NOT_MEASURED.format(keys=key, w="accelerometer", q="accel", src=src) in kf
        assert f"  {key}: [{val}, {val}, {val}]  # [{unit}] NOT MEASURED" in kf
        assert d[key] == [val] * 3
        assert _WARNED.format(target="kf-gins", w="accelerometer", q="accel", keys=key, src=src) in g.notes
    m = render("matlab", g).splitlines()
    assert m[0] == _HEADERS["matlab"]
    assert "% accelparams: " + _LEFT_OUT.format(w="accelerometer", q="accel") in m
    assert not any(ln.startswith("accel = ") for ln in m)
    assert m[-1] == "imu = imuSensor('accel-gyro', 'SampleRate', 100.0, 'Gyroscope', gyro);  % SampleRate [Hz]"
    assert "matlab: no accelerometer result given (--accel FILE): its accelerometer is left at the program's ideal " \
           "default" in g.notes
    a = _accel_only(tmp_path)
    m = render("matlab", a).splitlines()
    assert "% gyroparams: " + _LEFT_OUT.format(w="gyroscope", q="gyro") in m
    assert not any(ln.startswith("gyro = ") for ln in m)
    assert m[-1] == "imu = imuSensor('accel-gyro', 'SampleRate', 100.0, 'Accelerometer', accel);  % SampleRate [Hz]"
    kf = render("kf-gins", a).splitlines()
    d = yaml.safe_load("\n".join(kf))["imunoise"]
    for key, val, unit in (("arw", 0.003, "deg/sqrt(h)"), ("gbstd", 0.027, "deg/h")):
        assert "  # " + _NOT_MEASURED.format(keys=key, w="gyroscope", q="gyro", src=src) in kf
        assert f"  {key}: [{val}, {val}, {val}]  # [{unit}] NOT MEASURED" in kf
        assert d[key] == [val] * 3
        assert _WARNED.format(target="kf-gins", w="gyroscope", q="gyro", keys=key, src=src) in a.notes
    # the one corrtime from the accelerometer's axes alone (52.8369 s = 0.0146769 h), not KF-GINS's example 4 h
    assert ("  # corrtime: KF-GINS takes one correlation time for all six biases (and the scale factors): the geometric "
            "mean of the axes' T_c (accelerometer 52.8369, 52.8369, 52.8369 s), each axis's sigma re-matched to it "
            "above") in kf
    assert d["corrtime"] == approx(100.0 / 1.8926 / 3600.0, rel=1e-5)
    assert d["gsstd"] == d["asstd"] == [300.0] * 3
    assert "matlab: no gyroscope result given (--gyro FILE): its gyroscope is left at the program's ideal default" \
        in a.notes
    assert ("kf-gins: gsstd, asstd NOT MEASURED (scale factors are not observable in a static record): KF-GINS's "
            "example 300 ppm written") in a.notes


#: The defaults written for a missing accelerometer, per target (key -> value), from the sources in _SRC.
_ACC_DEFAULT = {"kalibr": {"accelerometer_noise_density": 2.0e-3, "accelerometer_random_walk": 3.0e-3},
                "openvins": {"accelerometer_noise_density": 2.0e-3, "accelerometer_random_walk": 3.0e-3},
                "vins-fusion": {"acc_n": 0.1, "acc_w": 0.001},
                "orbslam3": {"IMU.NoiseAcc": 2.0e-3, "IMU.AccWalk": 3.0e-3}}


@pytest.mark.parametrize("target, keys", [
    ("kalibr", "accelerometer_noise_density, accelerometer_random_walk"),
    ("openvins", "accelerometer_noise_density, accelerometer_random_walk"),
    ("vins-fusion", "acc_n, acc_w"), ("orbslam3", "IMU.NoiseAcc, IMU.AccWalk")])
def test_kalibr_family_with_the_gyro_only(tmp_path, target, keys):
    ctx = _gyro_only(tmp_path)
    text = render(target, ctx)
    ind = "  " if target == "openvins" else ""
    lines = text.splitlines()
    src = _SRC[target]
    # one NOT MEASURED comment for the quantity (not one per key), then each key once with the program's default
    assert lines.count(f"{ind}# " + _NOT_MEASURED.format(keys=keys, w="accelerometer", q="accel", src=src)) == 1
    assert sum(1 for ln in lines if "NOT MEASURED: no accelerometer result" in ln) == 1
    for k in keys.split(", "):
        body = [ln for ln in lines if ln.startswith(f"{ind}{k}: ")]
        assert len(body) == 1, (k, body)
        m = re.match(rf"^{re.escape(ind + k)}: (\S+)  # \[[^\]]+\] NOT MEASURED \(", body[0])
        assert m, body[0]
        assert float(m.group(1)) == approx(_ACC_DEFAULT[target][k], rel=1e-12), k
    assert _WARNED.format(target=target, w="accelerometer", q="accel", keys=keys, src=src) in ctx.notes
    # the gyroscope's keys are measured values, not defaults
    gyro_keys = [ln for ln in lines if re.match(r"^\s*(gyr|IMU\.(NoiseGyro|GyroWalk))", ln)]
    assert len(gyro_keys) == 2 and not any("NOT MEASURED" in ln for ln in gyro_keys)


def test_every_axis_of_a_per_axis_value_is_described(both):
    for target, n in (("kf-gins", 1), ("matlab", 1), ("gnss-ins-sim", 1)):
        lines = render(target, both).splitlines()
        for ax in ("gx", "gy", "gz", "ax", "ay", "az"):
            assert sum(1 for ln in lines if re.match(rf"^\s*[#%] {ax}: N = ", ln)) == n, (target, ax)
            assert sum(1 for ln in lines if re.match(rf"^\s*[#%] {ax}: bias Gauss-Markov: ", ln)) == \
                (0 if target == "matlab" else 1), (target, ax)


def _gmwm_file(tmp_path):
    ax1 = _full_gmwm_axis()
    ax2 = _full_gmwm_axis()
    ax2["name"] = "gy"
    ax2["selection"]["ieee"]["gm"] = [_gm(40.0, 2.0, ci=False)]
    ax3 = _full_gmwm_axis()
    ax3["name"] = "gz"
    g3 = _gm(60.0, 1.0)
    g3["tc_s"]["hi95"] = None                                  # T_c bounded on one side only: no T_c interval
    ax3["selection"]["ieee"]["gm"] = [g3]
    p = tmp_path / "noise.json"
    p.write_text(json.dumps({"record": _record(100.0), "axes": [ax1, ax2, ax3]}))
    return p


def test_gm_comment_gives_the_intervals_it_has(tmp_path):
    text = render("kf-gins", build_context([_gmwm_file(tmp_path)])).splitlines()
    sig = [ln.strip() for ln in text if ln.strip().startswith("#   sigma = ")]
    # gx: sigma 4 deg/h [2, 8], T_c 100 s [50, 200]; gy: no intervals; gz: sigma [0.5, 2], T_c without an upper end
    assert sig[0].startswith(f"#   sigma = {4.0 * DPH:.6g} rad/s (95 % [2.0, 8.0] deg/h), T_c = 100.0 s [50.0, 200.0] s; "
                             "discrete at 100.0 Hz: phi = exp(-dt/T_c) = ")
    assert sig[1].startswith(f"#   sigma = {2.0 * DPH:.6g} rad/s, T_c = 40.0 s; discrete at 100.0 Hz: ")
    assert sig[2].startswith(f"#   sigma = {1.0 * DPH:.6g} rad/s (95 % [0.5, 2.0] deg/h), T_c = 60.0 s; ")
    d = yaml.safe_load("\n".join(text))["imunoise"]
    # KF-GINS's one corrtime: the geometric mean of 100, 40 and 60 s (not the longest, not the first axis's); each
    # sigma re-matched so that the axis's Allan variance at its own peak tau = 1.8926 T_c is kept
    tc = (100.0 * 40.0 * 60.0) ** (1.0 / 3.0)                   # 62.1447 s
    assert d["corrtime"] == approx(tc / 3600.0, rel=1e-5)

    def gm_avar(tau, t):  # Allan variance of a unit first-order Gauss-Markov of correlation time t (IEEE 952)
        return 2.0 * t / tau * (1.0 - t / (2.0 * tau) * (3.0 - 4.0 * math.exp(-tau / t) + math.exp(-2.0 * tau / t)))

    want = [s * math.sqrt(gm_avar(1.8926 * t, t) / gm_avar(1.8926 * t, tc)) for s, t in ((4.0, 100.0), (2.0, 40.0),
                                                                                       (1.0, 60.0))]
    assert d["gbstd"] == approx(want, rel=1e-5)                 # 4.15325, 2.06227, 1.0002 deg/h
    assert f"  # corrtime: KF-GINS takes one correlation time for all six biases (and the scale factors): the " \
           "geometric mean of the axes' T_c (gyroscope 100.0, 40.0, 60.0 s), each axis's sigma re-matched to it " \
           "above" in text


_TERM_KEYS = {"name", "value", "lo95", "hi95", "unit", "status", "reason", "si", "si_lo95", "si_hi95", "si_unit",
              "conversion", "source"}


def test_json_target_fields_by_hand(tmp_path):
    ctx = build_context([_gyro_result(tmp_path)], [_accel_result(tmp_path)], rate_hz=400.0)
    d = json.loads(render("json", ctx))
    assert d["fogdrift_export"] == "json" and d["update_rate_hz"] == 400.0 and d["missing"] == "bound"
    assert d["conventions"] == {"si_rate_units": {"gyro": "rad/s", "accel": "m/s^2"},
                                "white": "continuous density N; discrete 1-sigma N sqrt(f)",
                                "random_walk": "continuous density K; discrete step 1-sigma K / sqrt(f)",
                                "gauss_markov": "phi = exp(-dt/T_c), driving 1-sigma = sigma sqrt(1 - phi^2)",
                                "source": "Kalibr wiki 'IMU Noise Model'; IEEE Std 952-1997 Annex C"}
    text = render("json", ctx).splitlines()                   # one key per line, one space per level
    assert text[0] == "{" and text[1] == ' "fogdrift_export": "json",' and text[-1] == "}"
    assert [c["name"] for c in d["channels"]] == ["gx", "gy", "gz", "ax", "ay", "az"]
    gx = d["channels"][0]
    assert set(gx) == {"name", "quantity", "method", "fit", "no_fit", "source_file", "sha256", "rate_hz",
                       "tau_range_s", "b_tau_s", "terms", "gauss_markov", "export_values", "bias_gauss_markov",
                       "state_space"}
    assert (gx["quantity"], gx["method"], gx["no_fit"], gx["rate_hz"]) == ("gyro", "allan", False, 100.0)
    assert gx["tau_range_s"] == [0.1, 1000.0] and gx["b_tau_s"] == 100.0 and gx["sha256"] == "ab" * 32
    assert gx["fit"] == "model N+B+K (chi2_red 1.1, good)" and gx["gauss_markov"] == []
    assert set(gx["terms"]) == {"Q", "N", "B", "K", "R"} and set(gx["terms"]["N"]) == _TERM_KEYS
    ev = gx["export_values"]
    assert list(ev) == ["N", "K", "B", "Q", "R"]
    n_si = 0.15 * D / 60.0
    assert ev["N"] == {"si": approx(n_si, rel=1e-12), "si_unit": "rad/s/sqrt(Hz)", "how": "estimate",
                       "note": "", "conversion": gx["terms"]["N"]["conversion"],
                       "discrete_sigma": approx(n_si * 20.0, rel=1e-12),                 # x sqrt(400)
                       "discrete_note": "per-sample 1-sigma = N sqrt(f)"}
    k_si = 0.5 * RRW
    assert ev["K"]["discrete_sigma"] == approx(k_si / 20.0, rel=1e-12)               # / sqrt(400)
    assert ev["K"]["discrete_note"] == "per-sample bias step 1-sigma = K / sqrt(f)"
    assert ev["K"]["si_unit"] == "rad/s^2/sqrt(Hz)"
    assert set(ev["B"]) == {"si", "si_unit", "how", "note", "conversion"}                   # a level: no discrete
    assert ev["Q"]["how"] == "bound" and ev["Q"]["si"] == approx(0.3e-6, rel=1e-12)  # 0.3 urad -> rad
    assert "95 % upper bound" in ev["Q"]["note"]
    gm = gx["bias_gauss_markov"]
    tc = 100.0 / 1.8926
    assert gm["tc_s"] == approx(tc, rel=1e-4) and gm["sigma_si"] == approx(1.0760 * 2.0 * DPH, rel=1e-4)
    assert gm["phi"] == approx(math.exp(-0.0025 / gm["tc_s"]), rel=1e-12)             # dt = 1/400 s
    assert gm["driving_sigma_si"] == approx(gm["sigma_si"] * math.sqrt(1 - gm["phi"] ** 2), rel=1e-9)
    assert gm["how"].startswith("one GM matched to B (estimate)")
    assert "caveat" not in gx["state_space"]
    ax = d["channels"][3]
    assert ax["quantity"] == "accel" and ax["export_values"]["N"]["si_unit"] == "m/s^2/sqrt(Hz)"
    assert ax["state_space"]["rate_unit"] == "m/s^2"


def test_json_target_reports_refused_terms_and_no_fit(tmp_path):
    d = json.loads(render("json", build_context([_gyro_result(tmp_path)], missing="refuse")))
    gz = d["channels"][2]
    k = gz["export_values"]["K"]
    assert set(k) == {"si", "how", "note"} and k["si"] is None and k["how"] == "refused"
    assert k["note"].startswith("gyro gz: K is not resolved by the record: not in the model")
    assert gz["export_values"]["N"]["how"] == "estimate"          # the others are kept
    p = _gyro_result(tmp_path, name="nofit.json", no_fit={"best_candidate": "N+B+K"})
    d = json.loads(render("json", build_context([p], missing="refuse")))
    gx = d["channels"][0]
    assert gx["no_fit"] is True and gx["fit"].startswith("no model fits; best candidate N+B+K")
    assert gx["bias_gauss_markov"]["how"] == "refused" and "no model fits the record" in \
        gx["bias_gauss_markov"]["note"]
    assert gx["state_space"]["caveat"] == ("no model fits this record: the state-space model uses the best "
                                           "candidate's values, which are not a result")


# ------------------------------------------------------------------------------------------------------------------
# discretize: the state-space model of a channel, by hand
# ------------------------------------------------------------------------------------------------------------------
import numpy as np  # noqa: E402

from fogdrift.export.discretize import channel_components, discrete_model  # noqa: E402
from fogdrift.export.model import ChannelModel, GaussMarkov, _term  # noqa: E402


def _chan(quantity, terms, *, gms=(), tau=(0.1, 1000.0), rate=100.0, no_fit=False):
    return ChannelModel(name="x1", quantity=quantity, method="allan",
                        terms={k: _term(k, *v, "test") for k, v in terms.items()}, gms=list(gms),
                        tau_range_s=tau, rate_hz=rate, no_fit=no_fit)


def test_gyro_state_space_by_hand():
    # Q 2 urad, N 0.15 deg/sqrt(h), K 0.5 deg/h^1.5, R 0.02 deg/h^2 (a ramp state), B not in the model
    ch = _chan("gyro", {"Q": (2.0, 1.0, 3.0, "urad", "resolved", ""), "N": (0.15, 0.14, 0.16, "deg/sqrt(h)", "resolved", ""),
                        "B": (None, 0.0, 0.3, "deg/h", "absent", "not in the model"),
                        "K": (0.5, 0.3, 0.7, "deg/h^1.5", "resolved", ""), "R": (0.02, 0.01, 0.03, "deg/h^2", "resolved", "")})
    d = discrete_model(ch, 50.0)
    n, k, q, r = 0.15 * D / 60.0, 0.5 * RRW, 2e-6, 0.02 * D / 3600.0 ** 2
    assert d["rate_unit"] == "rad/s" and d["components_rate_unit"] == "deg/h"
    assert d["components_note"] == "statespace components (fogdrift.models.statespace) in its own units (deg/h)"
    assert d["terms_left_out"] == [{"term": "B", "reason": "not in the model", "hi95": 0.3, "unit": "deg/h"}]
    ct = {t["kind"]: t for t in d["continuous_terms"]}
    assert set(ct) == {"white", "quantization", "random_walk", "ramp"}
    assert ct["white"]["density"] == approx(n, rel=1e-9) and ct["white"]["unit"] == "rad/s/sqrt(Hz)"
    assert ct["quantization"]["q"] == approx(q, rel=1e-9) and ct["quantization"]["unit"] == "rad"
    assert ct["random_walk"]["density"] == approx(k, rel=1e-9)
    assert ct["random_walk"]["unit"] == "rad/s/s/sqrt(Hz)"
    assert ct["ramp"]["slope_sigma"] == approx(r, rel=1e-9) and ct["ramp"]["unit"] == "rad/s/s"
    c = d["continuous"]
    assert c["states"] == ["bias", "random_walk", "ramp", "ramp_slope"]
    assert np.array_equal(c["F"], [[0, 0, 0, 0], [0, 0, 0, 0], [0, 0, 0, 1.0], [0, 0, 0, 0]])
    assert np.allclose(c["Qc"], np.diag([0.0, k * k, 0.0, 0.0]), rtol=1e-9, atol=0)
    assert c["H"] == [1.0, 1.0, 1.0, 0.0] and c["Qc_unit"] == "(rad/s)^2/s"
    assert c["white_density"] == approx(n, rel=1e-9) and c["white_density_unit"] == "rad/s/sqrt(Hz)"
    assert c["quantization"] == approx(q, rel=1e-9) and c["quantization_unit"] == "rad"
    assert c["ramp_slope_sigma"] == approx(r, rel=1e-9) and c["ramp_slope_unit"] == "rad/s/s"
    z = d["discrete"]
    dt = 0.02
    assert z["rate_hz"] == 50.0 and z["dt_s"] == dt and z["states"] == c["states"] and z["H"] == c["H"]
    assert np.allclose(z["Phi"], [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, dt], [0, 0, 0, 1]], rtol=0, atol=1e-15)
    assert z["Qd"][1][1] == approx(k * k * dt, rel=1e-9)
    assert z["r"] == approx(n * n / dt + 2.0 * q * q / dt ** 2, rel=1e-9)
    assert (z["Qd_unit"], z["r_unit"]) == ("(rad/s)^2", "(rad/s)^2")
    assert z["method"] == "Van Loan (1978): expm([[-F, Qc], [0, F^T]] dt); r = N^2/dt + 2 Q^2/dt^2"
    assert 0.0 <= d["check_max_abs"] < 1e-9
    assert d["check_note"] == ("largest |difference| (Phi absolute, Qd and r relative) from statespace.state_space's "
                               "closed forms")


def test_accelerometer_state_space_with_a_gauss_markov_by_hand():
    ch = _chan("accel", {"N": (0.06, 0.05, 0.07, "m/s/sqrt(h)", "resolved", "")},
               gms=[GaussMarkov(sigma_si=2e-4, tc_s=300.0)])
    d = discrete_model(ch, 10.0)
    assert set(d) == {"rate_unit", "continuous_terms", "components", "components_rate_unit", "components_note",
                      "terms_left_out", "continuous", "discrete", "check_max_abs", "check_note"}
    assert [c["kind"] for c in d["components"]] == ["white", "gauss_markov"]
    assert d["components"][1]["sigma_dph"] == approx(2e-4, rel=1e-12)     # statespace units: m/s^2 for deg/h
    q = _chan("accel", {"Q": (3e-4, 2e-4, 4e-4, "m/s", "resolved", "")})
    qt = discrete_model(q, 10.0)["continuous_terms"]
    assert qt == [{"kind": "quantization", "q": approx(3e-4, rel=1e-9), "unit": "m/s"}]
    assert d["rate_unit"] == "m/s^2" and d["components_rate_unit"] == "m/s^2"
    assert d["components_note"] == ("statespace components (fogdrift.models.statespace) in m/s^2 in place of deg/h "
                                    "(its formulas are linear in the rate unit)")
    gm = next(t for t in d["continuous_terms"] if t["kind"] == "gauss_markov")
    assert gm == {"kind": "gauss_markov", "sigma": approx(2e-4, rel=1e-12), "unit": "m/s^2", "tc_s": 300.0}
    white = next(t for t in d["continuous_terms"] if t["kind"] == "white")
    assert white["density"] == approx(0.001, rel=1e-9) and white["unit"] == "m/s^2/sqrt(Hz)"
    c, z = d["continuous"], d["discrete"]
    assert c["states"] == ["bias", "gm_300s"] and c["quantization_unit"] == "m/s" and c["Qc_unit"] == "(m/s^2)^2/s"
    assert (c["ramp_slope_sigma"], c["quantization"], c["ramp_slope_unit"]) == (0.0, 0.0, "m/s^2/s")   # no R, no Q
    assert c["F"][1][1] == approx(-1.0 / 300.0, rel=1e-12)
    assert c["Qc"][1][1] == approx(2.0 * 4e-8 / 300.0, rel=1e-12)       # 2 sigma^2 / T
    assert z["Phi"][1][1] == approx(math.exp(-0.1 / 300.0), rel=1e-12)  # Van Loan for a 1-state GM
    assert z["Qd"][1][1] == approx(4e-8 * (1.0 - math.exp(-0.2 / 300.0)), rel=1e-9)
    assert z["r"] == approx(1e-6 / 0.1, rel=1e-9) and z["r_unit"] == "(m/s^2)^2"
    assert d["check_max_abs"] < 1e-9


def test_no_white_noise_no_check_and_the_terms_that_enter():
    ch = _chan("gyro", {"K": (0.5, 0.3, 0.7, "deg/h^1.5", "resolved", ""),
                        "N": (0.0, 0.0, 0.1, "deg/sqrt(h)", "unresolved", "")})    # N = 0: not a component
    comps, left = channel_components(ch)
    assert [c["kind"] for c in comps] == ["random_walk"]
    assert left == [{"term": "N", "reason": "not in the selected model", "hi95": 0.1, "unit": "deg/sqrt(h)"}]
    assert discrete_model(ch, 100.0)["check_max_abs"] is None
    # no model fits: the best candidate's values enter (flagged by the caller), a term without a value does not
    ch = _chan("gyro", {"N": (0.15, 0.14, 0.16, "deg/sqrt(h)", "no_fit", "no model fits"),
                        "K": (None, 0.0, 0.3, "deg/h^1.5", "absent", "")}, no_fit=True)
    comps, left = channel_components(ch)
    assert [c["kind"] for c in comps] == ["white"]
    assert left == [{"term": "K", "reason": "not in the selected model", "hi95": 0.3, "unit": "deg/h^1.5"}]
    ch.no_fit = False                                      # the same values, but the record has a fit: N is missing
    assert channel_components(ch)[0] == []


@pytest.mark.parametrize("tau", [(math.nan, math.nan), (5.0, 5.0), (0.0, 100.0), (200.0, 50.0), (1.0, math.inf)])
def test_flicker_range_falls_back_to_one_sample_to_1e4_s(tau):
    b = {"B": (2.0, 1.5, 2.5, "deg/h", "resolved", "")}
    want, _ = channel_components(_chan("gyro", b, tau=(0.1, 1e4), rate=10.0))
    got, _ = channel_components(_chan("gyro", b, tau=tau, rate=10.0))
    assert got == want and len(got) == 4                  # at most 4 Gauss-Markov terms stand in for B
    other, _ = channel_components(_chan("gyro", b, tau=(1.0, 100.0), rate=10.0))
    assert other != want                                   # a valid range is used as it is


# ------------------------------------------------------------------------------------------------------------------
# Allan results (allan.json), the --missing policy and the words of the comments
# ------------------------------------------------------------------------------------------------------------------
from test_export import _allan_axis  # noqa: E402

from fogdrift.export.model import bias_gm, describe, load_result, resolve  # noqa: E402


def _allan_doc(ax, record=None):
    return {"record": _record(100.0) if record is None else record, "axes": [ax]}


def test_allan_channel_fields_by_hand():
    ax = _allan_axis("gx", {"N": (0.15, 0.14, 0.16, "resolved"), "B": (2.0, 1.5, 2.5, "resolved"),
                            "K": (0.5, 0.0, 0.7, "unresolved", "its interval reaches 0")}, b_tau=120.0)
    (ch,) = channels_from_result(_allan_doc(ax, _record(50.0, sha256="ef" * 32)), "a.json")
    assert (ch.method, ch.quantity, ch.rate_hz, ch.sha256, ch.source_file) == ("allan", "gyro", 50.0, "ef" * 32,
                                                                                "a.json")
    assert ch.fit == "model N+B+K (chi2_red 1.1, good)" and ch.no_fit is False
    assert ch.tau_range_s == (0.1, 1000.0) and ch.b_tau_s == 120.0 and ch.b_is_flicker is True
    n = ch.terms["N"]
    assert (n.status, n.reason, n.source) == ("resolved", "", "allan fit: N (selected model N+B+K, fit good)")
    k = ch.terms["K"]
    assert (k.status, k.reason, k.lo95) == ("unresolved", "its interval reaches 0", 0.0) and k.has_estimate
    r = ch.terms["R"]
    assert (r.status, r.value, r.hi95) == ("absent", None, 0.3) and not r.has_estimate
    # no sampling in the record: the rate is 1 / the fit's dt_s
    (ch,) = channels_from_result(_allan_doc(ax, {}), "a.json")
    assert ch.rate_hz == approx(100.0, rel=1e-12) and ch.sha256 == ""


def test_the_rate_is_read_from_the_records_signal_sampling_only():
    ax = _allan_axis("gx", {"N": (0.15, 0.14, 0.16, "resolved")})
    # a record block that repeats the rate as fs_hz beside signal.sampling: the signal is read
    old = {**_record(50.0), "dt_s": 0.02, "fs_hz": 50.0, "native_fs_hz": 50.0, "block_average_factor": 1}
    (ch,) = channels_from_result(_allan_doc(ax, old), "a.json")
    assert ch.rate_hz == 50.0
    old["fs_hz"] = 7.0                                                          # never read
    assert channels_from_result(_allan_doc(ax, old), "a.json")[0].rate_hz == 50.0
    # the sampling only under the old keys: refused in one line naming the file and what to do
    with pytest.raises(DataFormatError) as ei:
        channels_from_result(_allan_doc(ax, {"dt_s": 0.02, "fs_hz": 50.0}), "a.json")
    assert str(ei.value) == ("a.json: the record states its sampling only as dt_s, fs_hz, not in 'signal.sampling' "
                             "where this fogdrift reads it; re-run the fogdrift command that wrote the file")
    with pytest.raises(DataFormatError, match=r"^a\.json: the record's signal\.sampling: sampling has no 'dt_source'$"):
        channels_from_result(_allan_doc(ax, {"signal": {"sampling": {"dt_s": 0.02}}}), "a.json")


def test_allan_no_fit_reason_and_status():
    ax = _allan_axis("gx", {"N": (0.15, 0.14, 0.16, "resolved", "a reason")}, no_fit={"best_candidate": "N"})
    (ch,) = channels_from_result(_allan_doc(ax), "a.json")
    n = ch.terms["N"]
    assert ch.no_fit is True and n.status == "no_fit" and not n.has_estimate
    assert n.reason == ("no model fits the record (best candidate N+B+K, chi2_red 1.1): the coefficient is no "
                        "result; a reason")
    assert ch.fit == "no model fits; best candidate N+B+K (chi2_red 1.1, good)"
    assert ch.terms["Q"].status == "absent"                 # an absent term stays absent
    assert ch.terms["Q"].reason.startswith("no model fits the record (best candidate N+B+K, chi2_red 1.1): the "
                                           "coefficient is no result; not in the model")


def test_allan_b_min_reading_when_the_model_has_no_flicker():
    ax = _allan_axis("gx", {"N": (0.15, 0.14, 0.16, "resolved")}, selected=("N",))
    ax["noise"]["b_min"].update(value=1.2, lo95=1.0, hi95=1.5, tau_s=80.0, rule="min of the fitted ADEV / 0.664")
    (ch,) = channels_from_result(_allan_doc(ax), "a.json")
    b = ch.terms["B"]
    assert (b.value, b.lo95, b.hi95, b.unit, b.status, b.reason) == (1.2, 1.0, 1.5, "deg/h", "resolved", "")
    assert b.source == "allan fit: B_min, min of the fitted ADEV / 0.664"
    assert ch.b_is_flicker is False and ch.b_tau_s == 80.0
    g, how = bias_gm(ch, "bound")                            # one GM matched to the B reading at tau_B = 80 s
    assert g.sigma_si == approx(1.0760 * 1.2 * DPH, rel=1e-4) and g.tc_s == approx(80 / 1.8926, rel=1e-4)
    assert g.sigma_lo95_si == approx(1.0760 * 1.0 * DPH, rel=1e-4)
    assert g.sigma_hi95_si == approx(1.0760 * 1.5 * DPH, rel=1e-4)
    assert g.source == "from B at tau = 80 s"
    assert how == ("one GM matched to B (estimate): sigma = 1.0760 B, T_c = tau_B/1.8926 with tau_B = 80 s "
                   "(its Allan peak equals the flicker floor 0.664 B there)")
    # the reading is only a bound: B absent with the bound's rule as its reason; the GM has no interval
    ax["noise"]["b_min"].update(bound_only=True, value=2.0, lo95=None, hi95=3.0, rule="no minimum: a bound")
    (ch,) = channels_from_result(_allan_doc(ax), "a.json")
    b = ch.terms["B"]
    assert (b.value, b.hi95, b.status, b.reason) == (None, 3.0, "absent", "no minimum: a bound")
    g, how = bias_gm(ch, "bound")
    assert g.sigma_si == approx(1.0760 * 3.0 * DPH, rel=1e-4)
    assert g.sigma_lo95_si is None and g.sigma_hi95_si is None
    assert how.startswith("one GM matched to B (bound: B is its 95 % upper bound 3 deg/h, not an estimate")
    # no fit: the b_min reading is not used
    ax["noise"]["no_fit"] = {"best_candidate": "N"}
    ax["noise"]["b_min"].update(bound_only=False, value=1.2)
    (ch,) = channels_from_result(_allan_doc(ax), "a.json")
    assert ch.terms["B"].value is None


def test_allan_markov_term_becomes_a_gauss_markov():
    ax = _allan_axis("gx", {"N": (0.15, 0.14, 0.16, "resolved")}, selected=("N", "M"))
    ax["noise"]["terms"]["M"] = {"name": "M", "value": 0.5, "unit": "deg/h/sqrt(s)", "lo95": 0.3, "hi95": 0.7,
                                 "status": "resolved"}
    ax["noise"]["shaped"] = {"M": {"tc_s": 30.0, "tc_lo95_s": 20.0, "tc_hi95_s": 45.0, "sigma_dph": 0.6,
                                   "q_unit": "deg/h/sqrt(s)"}}
    (ch,) = channels_from_result(_allan_doc(ax), "a.json")
    (g,) = ch.gms
    assert g.sigma_si == approx(0.6 * DPH, rel=1e-12) and g.tc_s == 30.0
    assert (g.tc_lo95_s, g.tc_hi95_s) == (20.0, 45.0)
    assert g.source == "allan fit: M (exponentially correlated, IEEE-952 C.6)"
    for cut in ("tc_lo95_s", "tc_hi95_s"):                   # a T_c without its interval is not used
        ax2 = json.loads(json.dumps(ax))
        ax2["noise"]["shaped"]["M"][cut] = None
        assert channels_from_result(_allan_doc(ax2), "a.json")[0].gms == []
    ax2 = json.loads(json.dumps(ax))
    ax2["noise"]["selected"] = ["N"]                          # M not selected
    assert channels_from_result(_allan_doc(ax2), "a.json")[0].gms == []
    ax2 = json.loads(json.dumps(ax))
    ax2["noise"]["terms"]["M"]["status"] = "unresolved"
    assert channels_from_result(_allan_doc(ax2), "a.json")[0].gms == []


def test_allan_markov_term_of_an_accelerometer_reads_its_m_s2_key():
    """An accelerometer's allan.json names the Markov sigma in its unit (``sigma_mps2``, m/s^2): export reads that
    key (the gyro's ``sigma_dph`` is not there) and takes the number as m/s^2, not deg/h."""
    units = {"Q": "m/s", "N": "m/s/sqrt(h)", "B": "ug", "K": "m/s^2/sqrt(h)", "R": "m/s^2/h"}
    ax = _allan_axis("ax", {"N": (0.06, 0.05, 0.07, "resolved")}, selected=("N", "M"), units=units)
    ax["noise"]["quantity"] = "specific_force"
    ax["noise"]["terms"]["M"] = {"name": "M", "value": 5e-4, "unit": "m/s^2/sqrt(s)", "lo95": 3e-4, "hi95": 7e-4,
                                 "status": "resolved"}
    ax["noise"]["shaped"] = {"M": {"tc_s": 30.0, "tc_lo95_s": 20.0, "tc_hi95_s": 45.0, "sigma_mps2": 0.002,
                                   "q_unit": "m/s^2/sqrt(s)"}}
    (ch,) = channels_from_result(_allan_doc(ax), "a.json")
    (g,) = ch.gms
    assert ch.quantity == "accel" and g.sigma_si == approx(0.002, rel=1e-12) and g.tc_s == 30.0


def test_allan_axis_without_a_fit_and_bad_files_are_refused(tmp_path):
    with pytest.raises(DataFormatError) as ei:
        channels_from_result({"axes": [{"name": "gx", "noise": {"statistic": "adev"}}]}, "a.json")
    assert "a.json" in str(ei.value) and ("axis 'gx' has no noise fit ('noise.terms'); expected an allan result "
                                          "with the IEEE-952 fit") in str(ei.value)
    with pytest.raises(DataFormatError, match="an entry of 'axes' is not an object"):
        channels_from_result({"axes": [3]}, "a.json")
    ax = _allan_axis("gx", {"N": (0.15, 0.14, 0.16, "resolved")})
    del ax["noise"]["dt_s"]
    with pytest.raises(DataFormatError) as ei:
        channels_from_result(_allan_doc(ax, {}), "a.json")       # no rate anywhere
    assert str(ei.value) == ("a.json: the result says no sample rate (record 'signal.sampling' or the fit's 'dt_s'); "
                             "expected the allan.json or noise.json of a fogdrift run")
    assert "\n" not in str(ei.value)
    p = tmp_path / "axes.json"
    for text in ('{"axes": []}', '{"axes": {}}', "[1, 2]"):
        p.write_text(text)
        with pytest.raises(DataFormatError, match="not a fogdrift allan or noise result: no 'axes' list"):
            load_result(p)
    p.write_bytes(b"\xff\xfe{")
    with pytest.raises(DataFormatError, match=r"not a JSON file \(UnicodeDecodeError: "):
        load_result(p)
    p.write_text('{"axes": [{"name": "gx"}]}')
    assert load_result(p) == {"axes": [{"name": "gx"}]}


def test_wrong_quantity_flag_names_the_axis_and_the_unit(tmp_path):
    a = json.loads(_accel_result(tmp_path).read_text())
    with pytest.raises(DataFormatError) as ei:
        channels_from_result(a, "acc.json", expect="gyro")
    assert "--gyro was given a accel result (axis ax: N in m/s/sqrt(h)); pass it as --accel" in str(ei.value)
    assert channels_from_result(a, "acc.json", expect="accel")[0].quantity == "accel"


def test_resolve_messages_by_hand(tmp_path):
    ax = _allan_axis("gz", {"N": (0.1, 0.0, 0.2, "unresolved"), "B": (1.0, 0.5, 1.5, "resolved")}, selected=("N", "B"))
    (ch,) = channels_from_result(_allan_doc(ax), "g.json")
    r = resolve(ch, "N", "refuse")                           # an estimate is written under every policy
    assert (r.how, r.si) == ("estimate", approx(0.1 * D / 60, rel=1e-12))
    assert r.note == "N = 0.1 deg/sqrt(h) is the estimate, not resolved from zero: its 95 % interval reaches 0"
    assert resolve(ch, "B", "zero").note == "" and resolve(ch, "B", "zero").how == "estimate"
    r = resolve(ch, "K", "zero")
    assert (r.si, r.how) == (0.0, "zero")
    assert r.note == "K written as 0 (--missing zero): not in the model: the curve shows no sign of it"
    r = resolve(ch, "K", "bound")
    assert r.note == ("K is its 95 % upper bound 0.3 deg/h^1.5, not an estimate (--missing bound): not in the model: "
                      "the curve shows no sign of it")
    with pytest.raises(ConfigError) as ei:
        resolve(ch, "K", "refuse")
    assert str(ei.value) == ("gyro gz: K is not resolved by the record: not in the model: the curve shows no sign of "
                             "it; its 95 % upper bound is 0.3 deg/h^1.5; pass --missing bound or zero to write its "
                             "bound or 0, or export from a record that resolves it").replace("--missing ", "missing= ")
    ch.terms["K"] = _term("K", None, None, None, "deg/h^1.5", "absent", "", "s")   # no bound, no reason
    with pytest.raises(ConfigError) as ei:
        resolve(ch, "K", "bound")
    assert str(ei.value) == ("gyro gz: K is not resolved by the record: not in the selected model; the record gives "
                             "no upper bound either; pass missing= zero to write 0 with a warning, or export from a "
                             "record that resolves it")
    with pytest.raises(ConfigError) as ei:
        resolve(ch, "K", "refuse")
    assert str(ei.value).startswith("gyro gz: K is not resolved by the record: not in the selected model; pass ")
    ch.terms["K"] = _term("K", None, 0.0, 0.0, "deg/h^1.5", "absent", "", "s")      # a bound of 0 is no bound
    with pytest.raises(ConfigError, match="the record gives no upper bound either"):
        resolve(ch, "K", "bound")
    with pytest.raises(ConfigError, match=r"gyro gz.*no term M"):
        resolve(ch, "M", "bound")
    with pytest.raises(ConfigError) as ei:
        resolve(ch, "N", "Bound")
    assert str(ei.value) == "missing= must be one of bound, refuse, zero; got 'Bound'"


def test_describe_in_words():
    t = _term("N", 0.15, 0.14, 0.16, "deg/sqrt(h)", "resolved", "", "allan fit: N")
    assert describe(t) == "N = 0.15 [0.14, 0.16] deg/sqrt(h) [resolved]; from allan fit: N"
    t = _term("N", 0.15, None, None, "deg/sqrt(h)", "resolved", "", "gmwm: N")
    assert describe(t) == "N = 0.15 deg/sqrt(h) [resolved]; from gmwm: N"
    t = _term("K", None, 0.0, 0.3, "deg/h^1.5", "absent", "", "x")
    assert describe(t) == "K = < 0.3 deg/h^1.5 (95 % upper bound) [absent]; from x"
    t = _term("K", None, None, None, "deg/h^1.5", "absent", "", "x")
    assert describe(t) == "K = no value [absent]; from x"
    assert t.to_dict()["si_unit"] == "rad/s^2/sqrt(Hz)" and set(t.to_dict()) == _TERM_KEYS


def test_json_keeps_the_terms_after_one_the_result_lacks(tmp_path):
    doc = json.loads(_gyro_result(tmp_path).read_text())
    for ax in doc["axes"]:
        del ax["noise"]["terms"]["Q"]                        # an older allan.json without Q
    p = tmp_path / "noq.json"
    p.write_text(json.dumps(doc))
    d = json.loads(render("json", build_context([p])))
    assert list(d["channels"][0]["export_values"]) == ["N", "K", "B", "R"]
    assert d["channels"][0]["export_values"]["R"]["how"] == "bound"


def _gyro_gm_chan():
    return _chan("gyro", {"N": (0.15, 0.14, 0.16, "deg/sqrt(h)", "resolved", ""),
                          "K": (0.5, 0.3, 0.7, "deg/h^1.5", "resolved", "")},
                 gms=[GaussMarkov(sigma_si=4.0 * DPH, tc_s=100.0)])


@pytest.mark.parametrize("what, factor", [("F", 1.001), ("Q", 1.001), ("r", 1.001)])
def test_check_max_abs_catches_a_disagreement_in_each_part(monkeypatch, what, factor):
    import dataclasses

    from fogdrift.export import discretize as dz

    real = dz.state_space
    ch = _gyro_gm_chan()
    assert dz.discrete_model(ch, 100.0)["check_max_abs"] < 1e-9

    def off(*a, **k):                                        # statespace's closed forms, one part 0.1 % off
        ss = real(*a, **k)
        return dataclasses.replace(ss, **{what: getattr(ss, what) * factor})

    monkeypatch.setattr(dz, "state_space", off)
    check = dz.discrete_model(ch, 100.0)["check_max_abs"]
    # Phi ~ 1: an absolute 1e-3; Qd and r: relative 1e-3 (Qd of the largest element, values ~1e-13 (rad/s)^2)
    assert check == approx(1e-3, rel=2e-2)


def test_gyro_gauss_markov_component_in_si_and_quantization_alone():
    d = discrete_model(_gyro_gm_chan(), 100.0)
    gm = next(t for t in d["continuous_terms"] if t["kind"] == "gauss_markov")
    assert gm["sigma"] == approx(4.0 * DPH, rel=1e-12) and gm["unit"] == "rad/s"
    comps, _ = channel_components(_gyro_gm_chan())
    assert next(c for c in comps if c["kind"] == "gauss_markov")["sigma_dph"] == approx(4.0, rel=1e-12)
    q_only = _chan("gyro", {"Q": (2.0, 1.0, 3.0, "urad", "resolved", "")})
    d = discrete_model(q_only, 100.0)
    assert d["discrete"]["r"] == approx(2.0 * (2e-6) ** 2 / 0.01 ** 2, rel=1e-9)   # 2 Q^2 / dt^2
    assert d["check_max_abs"] is not None and d["check_max_abs"] < 1e-9


def test_max_flicker_terms_is_passed_on():
    b = {"B": (2.0, 1.5, 2.5, "deg/h", "resolved", "")}
    comps, _ = channel_components(_chan("gyro", b, tau=(0.1, 1e4)), max_flicker_terms=2)
    assert [c["kind"] for c in comps] == ["gauss_markov", "gauss_markov"]


def test_header_names_the_files_and_their_hashes(tmp_path):
    g, a = _gyro_result(tmp_path), _accel_result(tmp_path)
    lines = render("kalibr", build_context([g], [a])).splitlines()
    assert lines[1] == f"# from {a}, {g} (input SHA-256 {'ab' * 8}...)"        # sorted; the accel file has none
    assert render("kalibr", build_context(accel=[a])).splitlines()[1] == f"# from {a}"


def test_scalar_targets_say_which_axis_was_written(tmp_path):
    lines = render("kalibr", build_context([_gyro_result(tmp_path)])).splitlines()
    assert ("# written: the largest of the 3 axes (gy) in rad/s/sqrt(Hz): this format takes one value for all axes"
            in lines)
    assert ("# written: the largest of the 3 axes (gx) in rad/s^2/sqrt(Hz): this format takes one value for all "
            "axes") in lines
    doc = json.loads(_gyro_result(tmp_path).read_text())
    for keep, want in ((2, "# written: the largest of the 2 axes (gy) in rad/s/sqrt(Hz): this format takes one value "
                           "for all axes"), (1, "# written in rad/s/sqrt(Hz)")):
        p = tmp_path / f"g{keep}.json"
        p.write_text(json.dumps({**doc, "axes": doc["axes"][:keep]}))
        lines = render("kalibr", build_context([p])).splitlines()
        assert want in lines
        assert "None" not in "\n".join(lines)


def test_continuous_comment_says_how_the_value_was_chosen(tmp_path):
    g = _gyro_result(tmp_path)
    text = render("kalibr", build_context([g]))
    assert "#   continuous 5.81776e-05 rad/s/sqrt(Hz) (the estimate; x 0.000290888 (deg/sqrt(h) -> rad/s/sqrt(Hz))); " \
           "discrete 0.000581776 rad/s per sample at 100.0 Hz (x sqrt(f))" in text
    zero = render("kalibr", build_context([g], missing="zero"))
    assert "#   continuous 0.0 rad/s^2/sqrt(Hz) (0 (--missing zero); x 8.08023e-08 (deg/h^1.5 -> rad/s^2/sqrt(Hz))); " \
           "discrete 0.0 rad/s per-sample bias step at 100.0 Hz (/ sqrt(f))" in zero
    assert "#   continuous 2.42407e-08 rad/s^2/sqrt(Hz) (its 95 % upper bound (--missing bound); x 8.08023e-08 " \
           "(deg/h^1.5 -> rad/s^2/sqrt(Hz))); discrete 2.42407e-09 rad/s per-sample bias step at 100.0 Hz " \
           "(/ sqrt(f))" in text                               # 0.3 deg/h^1.5 x 8.08023e-08, / sqrt(100)


def test_fmt_writes_non_finite_values_as_numbers_not_a_dash():
    from fogdrift.export.writers import fmt

    assert (fmt(math.inf), fmt(-math.inf), fmt(math.nan)) == ("inf", "-inf", "nan")
    assert (fmt(1e-5), fmt(0.0), fmt(2.5), fmt(123456789.0), fmt(3)) == ("1.0e-05", "0.0", "2.5", "1.23457e+08", "3.0")


def test_allan_defaults_of_missing_fields():
    ax = _allan_axis("gx", {"N": (0.15, 0.14, 0.16, "resolved"), "K": (0.5, 0.0, 0.7, "unresolved")}, selected=())
    del ax["noise"]["terms"]["N"]["reason"], ax["noise"]["terms"]["R"]["status"]
    (ch,) = channels_from_result(_allan_doc(ax), "a.json")
    assert ch.fit == "model none (chi2_red 1.1, good)"
    assert ch.terms["N"].source == "allan fit: N (selected model none, fit good)" and ch.terms["N"].reason == ""
    assert ch.terms["R"].status == "absent"
    # no fit: resolved AND unresolved terms become no_fit; no reason of its own: nothing appended; no chi2: nan
    ax["noise"]["no_fit"] = {"best_candidate": "N"}
    del ax["noise"]["fit"]["chi2_red"]
    (ch,) = channels_from_result(_allan_doc(ax), "a.json")
    assert ch.terms["K"].status == "no_fit" and ch.terms["N"].status == "no_fit"
    assert ch.terms["N"].reason == ("no model fits the record (best candidate none, chi2_red nan): the coefficient is "
                                    "no result")
    assert ch.terms["R"].status == "absent"
    del ax["noise"]["fit"]["quality"]
    (ch,) = channels_from_result(_allan_doc(ax), "a.json")
    assert ch.terms["N"].source == "allan fit: N (selected model none, fit ?)"
    assert ch.fit == "no model fits; best candidate none (chi2_red nan, ?)"
    del ax["noise"]["terms"]["N"]["unit"]                     # a term without its unit is refused, naming it
    with pytest.raises(DataFormatError, match=r"axis 'gx' is not a complete fogdrift allan result \(ConfigError: "
                                              r"unit '' of term N is not one fogdrift can convert"):
        channels_from_result(_allan_doc(ax), "a.json")


def test_gm_from_b_without_its_tau_uses_the_end_of_the_fitted_range():
    ax = _full_gmwm_axis()
    ie = ax["selection"]["ieee"]
    ie["gm"] = []
    del ie["b_headline"]["tau_s"]                            # B read, but not where: the longest fitted tau, 500 s
    ch = _one(ax, _record(100.0))
    assert ch.b_tau_s is None
    g, how = bias_gm(ch, "bound")
    assert g.tc_s == approx(500.0 / 1.8926, rel=1e-4) and g.sigma_si == approx(1.0760 * 1.5 * DPH, rel=1e-4)
    assert g.source == "from B at tau = 500 s" and "with tau_B = 500 s" in how


def test_allan_b_min_defaults_and_markov_unit_fallback():
    ax = _allan_axis("gx", {"N": (0.15, 0.14, 0.16, "resolved")}, selected=("N",))
    ax["noise"]["b_min"].update(value=1.2, lo95=1.0, hi95=1.5, tau_s=80.0)
    del ax["noise"]["b_min"]["unit"], ax["noise"]["b_min"]["rule"]      # B's own unit; the rule's default words
    (ch,) = channels_from_result(_allan_doc(ax), "a.json")
    b = ch.terms["B"]
    assert b.unit == "deg/h" and b.si == approx(1.2 * DPH, rel=1e-12)
    assert b.source == "allan fit: B_min, min of the fitted ADEV / 0.664"
    ax["noise"]["b_min"].update(bound_only=True, value=2.0, lo95=None, hi95=3.0)
    (ch,) = channels_from_result(_allan_doc(ax), "a.json")
    assert ch.terms["B"].reason == "" and ch.terms["B"].status == "absent"
    # M: sigma in the unit of q_c; without q_unit, the M term's unit; with neither, refused
    ax = _allan_axis("gx", {"N": (0.15, 0.14, 0.16, "resolved")}, selected=("N", "M"))
    ax["noise"]["terms"]["M"] = {"name": "M", "value": 0.5, "unit": "deg/h/sqrt(s)", "lo95": 0.3, "hi95": 0.7,
                                 "status": "resolved"}
    ax["noise"]["shaped"] = {"M": {"tc_s": 30.0, "tc_lo95_s": 20.0, "tc_hi95_s": 45.0, "sigma_dph": 0.6}}
    (ch,) = channels_from_result(_allan_doc(ax), "a.json")
    assert ch.gms[0].sigma_si == approx(0.6 * DPH, rel=1e-12)
    del ax["noise"]["terms"]["M"]["unit"]
    with pytest.raises(DataFormatError, match=r"\(ConfigError: unit '' of term "):
        channels_from_result(_allan_doc(ax), "a.json")


def test_allan_units_that_say_two_quantities_are_refused():
    ax = _allan_axis("gx", {"N": (0.15, 0.14, 0.16, "resolved"), "B": (50.0, 40.0, 60.0, "resolved")},
                     units={"Q": "urad", "N": "deg/sqrt(h)", "B": "ug", "K": "deg/h^1.5", "R": "deg/h^2"})
    with pytest.raises(DataFormatError) as ei:
        channels_from_result(_allan_doc(ax), "a.json")
    assert str(ei.value).startswith("a.json: axis gx: the terms' units do not say one quantity (gyro or "
                                    "accelerometer): Q [urad], N [deg/sqrt(h)], B [ug]")


def test_header_lists_every_input_hash(tmp_path):
    g, a = _gyro_result(tmp_path), _accel_result(tmp_path)
    doc = json.loads(a.read_text())
    doc["record"]["sha256"] = "cd" * 32
    a.write_text(json.dumps(doc))
    line = render("kalibr", build_context([g], [a])).splitlines()[1]
    assert line == f"# from {a}, {g} (input SHA-256 {'ab' * 8}, {'cd' * 8}...)"   # first 16 hex digits of each


def test_allan_keys_read_as_given_b_min_unit_rule_and_q_unit():
    ax = _allan_axis("gx", {"N": (0.15, 0.14, 0.16, "resolved")}, selected=("N", "M"))
    ax["noise"]["b_min"].update(value=0.001, lo95=None, hi95=None, tau_s=80.0, unit="deg/s",
                                rule="min over the fitted range / 0.664")
    ax["noise"]["terms"]["M"] = {"name": "M", "value": 0.5, "unit": "a unit q_c has not", "lo95": 0.3, "hi95": 0.7,
                                 "status": "resolved"}
    ax["noise"]["shaped"] = {"M": {"tc_s": 30.0, "tc_lo95_s": 20.0, "tc_hi95_s": 45.0, "sigma_dph": 0.6,
                                   "q_unit": "deg/h/sqrt(s)"}}
    (ch,) = channels_from_result(_allan_doc(ax), "a.json")
    b = ch.terms["B"]                                         # b_min's own unit, not B's deg/h
    assert b.unit == "deg/s" and b.si == approx(0.001 * D, rel=1e-12)
    assert b.source == "allan fit: B_min, min over the fitted range / 0.664"
    assert ch.gms[0].sigma_si == approx(0.6 * DPH, rel=1e-12)   # q_unit, not the M term's unit


def test_quantity_is_read_from_terms_with_a_value_or_a_bound():
    units = {"Q": "urad", "N": "deg/sqrt(h)", "B": "deg/h", "K": "deg/h^1.5", "R": "m/s^3"}   # R: no value, no bound
    ax = _allan_axis("gx", {"N": (0.15, 0.14, 0.16, "resolved")}, units=units)
    ax["noise"]["terms"]["R"].update(hi95=None, lo95=None)
    assert channels_from_result(_allan_doc(ax), "a.json")[0].quantity == "gyro"
    ax["noise"]["terms"]["R"]["hi95"] = 0.3                   # a bound in an accelerometer unit: two quantities
    with pytest.raises(DataFormatError, match="the terms' units do not say one quantity"):
        channels_from_result(_allan_doc(ax), "a.json")


def test_load_and_channel_messages_name_the_file(tmp_path):
    missing = tmp_path / "none.json"
    with pytest.raises(DataFormatError) as ei:
        load_result(missing)
    assert str(ei.value) == (f"{missing}: no such result file; expected the allan.json or noise.json of a fogdrift "
                             "run (or what 'fogdrift allan --json' printed)")
    p = tmp_path / "bad.json"
    p.write_text("{\n not json")
    with pytest.raises(DataFormatError) as ei:
        load_result(p)
    assert str(ei.value).startswith(f"{p}: not a JSON file (JSONDecodeError: ") and "\n" not in str(ei.value)
    p.write_text('{"axes": []}')
    with pytest.raises(DataFormatError) as ei:
        load_result(p)
    assert str(ei.value) == (f"{p}: not a fogdrift allan or noise result: no 'axes' list; expected the allan.json or "
                             "noise.json of a fogdrift run")
    p.write_text('{"axes": [{"name": "gx"}]}', encoding="utf-8")
    assert load_result(p)["axes"][0]["name"] == "gx"
    with pytest.raises(DataFormatError) as ei:
        channels_from_result({"axes": ["gx"]})
    assert str(ei.value) == "result: an entry of 'axes' is not an object"
    ax = _allan_axis("gx", {"N": (0.15, 0.14, 0.16, "resolved")})
    del ax["noise"]["dt_s"]
    with pytest.raises(DataFormatError) as ei:
        channels_from_result(_allan_doc(ax, {}), "a.json")
    assert str(ei.value).startswith("a.json: ") and "no sample rate" in str(ei.value)
    assert str(ei.value).endswith("); expected the allan.json or noise.json of a fogdrift run")
    g = json.loads(_gyro_result(tmp_path).read_text())
    with pytest.raises(DataFormatError) as ei:
        channels_from_result(g, "g.json", expect="accel")
    assert str(ei.value) == ("g.json: --accel was given a gyro result (axis gx: N in deg/sqrt(h)); pass it as "
                             "--gyro")


def test_method_is_read_from_the_axis_or_its_shape():
    gm = _full_gmwm_axis()
    del gm["method"]                                          # no method: 'selection' says GMWM
    assert _one(gm).method == "gmwm"
    al = _allan_axis("gx", {"N": (0.15, 0.14, 0.16, "resolved")})
    al["selection"] = {"not": "used"}
    al["method"] = "allan"                                    # an explicit method wins over the shape
    assert _one(al).method == "allan"
