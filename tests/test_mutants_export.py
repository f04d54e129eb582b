"""Tests added for the surviving mutants of ``fogdrift.export`` (writers, model, discretize, targets) in mutation
round 3 (issue 24 item 2, docs/testing.md).

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

import pytest

from fogdrift.errors import ConfigError, DataFormatError
from fogdrift.export.model import _rw_bound_from_wv, channels_from_result

D = math.pi / 180.0          # rad per deg
G0 = 9.80665                 # m/s^2 per g
DPH = D / 3600.0             # rad/s per deg/h
RRW = D / 216000.0           # rad/s^1.5 per deg/h^1.5  (3600^1.5 = 216000)


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
    ch = _one(_full_gmwm_axis(), {"fs_hz": 200.0, "sha256": "cd" * 32}, path="run/noise.json")
    assert (ch.name, ch.quantity, ch.method) == ("gx", "gyro", "gmwm")
    assert ch.fit == "GMWM model WN+RW+GM (J-test p = 0.43)"
    assert ch.rate_hz == 200.0 and ch.sha256 == "cd" * 32 and ch.source_file == "run/noise.json"
    assert ch.tau_range_s == (0.05, 500.0) and ch.b_tau_s == 300.0
    assert ch.b_is_flicker is False and ch.no_fit is False
    n = ch.terms["N"]
    assert (n.value, n.lo95, n.hi95, n.unit, n.status, n.reason) == (0.3, 0.27, 0.33, "deg/sqrt(h)", "resolved", "")
    assert n.source == "gmwm WN+RW+GM: N (component WN)"
    assert n.si == pytest.approx(0.3 * D / 60.0, rel=1e-12)
    assert n.si_lo95 == pytest.approx(0.27 * D / 60.0, rel=1e-12)
    assert n.si_hi95 == pytest.approx(0.33 * D / 60.0, rel=1e-12)
    k = ch.terms["K"]                                     # deg/h/sqrt(h) is read as deg/h^1.5
    assert k.unit == "deg/h^1.5" and k.status == "resolved" and k.si == pytest.approx(2.0 * RRW, rel=1e-12)
    r = ch.terms["R"]                                     # lo95 = 0: not resolved from zero
    assert (r.status, r.reason) == ("unresolved", "its 95 % interval reaches 0")
    assert r.si == pytest.approx(1.0 * D / 3600.0 ** 2, rel=1e-12)       # deg/h^2 -> rad/s^2
    q = ch.terms["Q"]                                     # not in the model, GMWM gives no bound
    assert (q.value, q.lo95, q.hi95, q.unit, q.status) == (None, None, None, "urad", "absent")
    assert q.reason == "not in the GMWM model WN+RW+GM (GMWM gives no upper bound for a term it leaves out)"
    assert q.source == "gmwm WN+RW+GM: Q"
    b = ch.terms["B"]                                     # the headline reading, resolved
    assert (b.value, b.lo95, b.hi95, b.unit, b.status, b.reason) == (1.5, 1.0, 2.0, "deg/h", "resolved", "")
    assert b.source == "gmwm WN+RW+GM: B, min of the model's ADEV / 0.664"
    assert b.si == pytest.approx(1.5 * DPH, rel=1e-12) and b.si_hi95 == pytest.approx(2.0 * DPH, rel=1e-12)
    assert b.has_estimate
    (g,) = ch.gms
    assert g.sigma_si == pytest.approx(4.0 * DPH, rel=1e-12) and g.tc_s == 100.0
    assert g.sigma_lo95_si == pytest.approx(2.0 * DPH, rel=1e-12)
    assert g.sigma_hi95_si == pytest.approx(8.0 * DPH, rel=1e-12)
    assert (g.tc_lo95_s, g.tc_hi95_s) == (50.0, 200.0) and g.source == "gmwm WN+RW+GM: GM1"


def test_gmwm_channel_defaults_when_fields_are_absent():
    ax = _full_gmwm_axis()
    ie = ax["selection"]["ieee"]
    del ie["model"], ie["b_headline"], ie["tau_range_s"], ax["j_statistic"]
    ax["selected"] = "WN+GM"
    ie["terms"]["K_dphrh"] = _t(2.0, 0.5, 3.0)           # no unit: the gyro default deg/h^1.5, no component: '?'
    ie["gm"] = [_gm(50.0, 3.0, unit=None, component=None, ci=False)]
    ch = _one(ax, {"fs_hz": None})
    assert ch.fit == "GMWM model WN+GM"                    # no J-test: no p in the words
    assert ch.rate_hz == pytest.approx(100.0, rel=1e-12)  # 1 / dt_s
    assert ch.sha256 == "" and ch.b_tau_s is None
    assert all(math.isnan(x) for x in ch.tau_range_s)
    assert ch.terms["K"].unit == "deg/h^1.5" and ch.terms["K"].source == "gmwm WN+GM: K (component ?)"
    assert ch.terms["K"].si == pytest.approx(2.0 * RRW, rel=1e-12)
    b = ch.terms["B"]                                     # no headline: absent, no bound
    assert (b.value, b.lo95, b.hi95, b.unit, b.status) == (None, 0.0, None, "deg/h", "absent")
    assert b.reason == "no bias-instability reading" and b.source == "gmwm WN+GM: B, "
    (g,) = ch.gms                                         # sigma without unit: deg/h; no interval, no name
    assert g.sigma_si == pytest.approx(3.0 * DPH, rel=1e-12)
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
    ch = _one(ax, {"fs_hz": 100.0})
    b = ch.terms["B"]
    assert (b.value, b.lo95, b.hi95, b.status) == (None, 0.0, 9.0, "absent")
    assert b.si_hi95 == pytest.approx(9.0 * DPH, rel=1e-12) and b.si_lo95 == 0.0
    assert b.reason == "95 % upper bound: no minimum in the range" and not b.has_estimate
    assert ch.b_is_flicker is False and ch.b_tau_s == 800.0
    # a flicker component (B_dph) in the model: B is that term, not the headline, and b_is_flicker is set
    ax["selection"]["ieee"]["terms"]["B_dph"] = _t(0.7, 0.5, 0.9, "deg/h", "FLK")
    ch = _one(ax, {"fs_hz": 100.0})
    assert ch.b_is_flicker is True
    b = ch.terms["B"]
    assert (b.value, b.status, b.source) == (0.7, "resolved", "gmwm WN+RW+GM: B (component FLK)")


def test_gmwm_accelerometer_defaults_are_specific_force_units():
    ax = _full_gmwm_axis()
    ie = ax["selection"]["ieee"]
    ie["terms"] = {"N_dprh": _t(0.06, 0.05, 0.07, "m/s/sqrt(h)", "WN")}
    ie["gm"] = [_gm(300.0, 2e-4, unit="m/s^2")]
    ie["b_headline"] = {"value_dph": None, "bound_dph": 5e-4, "tau_s": 600.0}
    ax["wvar"] = {"tau_samples": [2, 4], "ci_hi95_dph2": [1.0, 1.0], "dt_s": 0.01, "scale_s": [0.02, 0.04]}
    ch = _one(ax, {"fs_hz": 100.0})
    assert ch.quantity == "accel"                         # B's bound is read in m/s^2 (not deg/h)
    assert {k: ch.terms[k].unit for k in "NKRQB"} == {"N": "m/s/sqrt(h)", "K": "m/s^2/sqrt(s)", "R": "m/s^3",
                                                      "Q": "m/s", "B": "m/s^2"}
    assert ch.terms["B"].si_hi95 == pytest.approx(5e-4, rel=1e-12)
    assert ch.terms["N"].si == pytest.approx(0.06 / 60.0, rel=1e-12)
    k = ch.terms["K"]                                     # the wavelet-variance bound is a gyro (deg/h) reading
    assert k.hi95 is None and k.lo95 is None
    assert k.reason.endswith("(GMWM gives no upper bound for a term it leaves out)")
    assert ch.gms[0].sigma_si == pytest.approx(2e-4, rel=1e-12)
    assert ch.gms[0].sigma_hi95_si == pytest.approx(4e-4, rel=1e-12)


def test_gmwm_wavelet_bound_is_for_the_gyro_random_walk_only():
    ax = _full_gmwm_axis()
    ie = ax["selection"]["ieee"]
    del ie["terms"]["K_dphrh"]
    ax["wvar"] = {"tau_samples": [2, 8, 32], "ci_hi95_dph2": [9.0, 5.0, 3.0], "dt_s": 0.01,
                  "scale_s": [0.02, 0.08, 0.32]}
    ch = _one(ax, {"fs_hz": 100.0})
    k = ch.terms["K"]
    tau = 32.0                                            # the LAST scale, not the first or the second
    k_bound = 60.0 * math.sqrt(3.0 * 12.0 * tau / (tau * tau + 2.0) / 0.01)
    assert k.hi95 == pytest.approx(k_bound, rel=1e-12) and k.lo95 == 0.0 and k.status == "absent"
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
    assert k == pytest.approx(60.0 * math.sqrt(hi * 12.0 * tau / ((tau * tau + 2.0) * dt)), rel=1e-12)
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
