"""Consistency check (issue 22 item 4): closed forms by hand, against an exact discrete covariance, and coverage
counted on seeded simulations whose truth is known."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.signal import lfilter

from fogdrift.errors import ConfigError, InsufficientDataError
from fogdrift.evaluation.consistency import (BANDS, angle_error_variance_deg2, check_consistency,
                                             components_from_noise_fit, coverage_rows, inflation_factor,
                                             observed_angle_errors_deg, random_walk_covering, reduced_model)

DEG_PER_URAD = 1e-6 * 180.0 / math.pi


# --------------------------------------------------------------------------------------------------------------
# closed forms, by hand
# --------------------------------------------------------------------------------------------------------------
def test_white_closed_form_by_hand():
    # N = 0.6 deg/sqrt(h) = 0.01 deg/sqrt(s); T = 100 s, h = 100 s: 1e-4 (100 + 100^2/100) = 0.02 deg^2
    v = angle_error_variance_deg2([{"kind": "white", "arw_dprh": 0.6}], [100.0, 25.0], 100.0)
    assert v[0] == pytest.approx(0.02, rel=1e-12)
    assert v[1] == pytest.approx(1e-4 * (25 + 625 / 100), rel=1e-12)


def test_random_walk_closed_form_by_hand():
    # K = 216000 deg/h^1.5 = 1 deg/s^1.5; h = 3, T = 6: h^3/3 + h^2 T/3 = 9 + 18 = 27 deg^2
    v = angle_error_variance_deg2([{"kind": "random_walk", "rrw_dphrh": 216000.0}], 3.0, 6.0)
    assert v[0] == pytest.approx(27.0, rel=1e-12)


def test_gauss_markov_closed_form_by_hand():
    # sigma = 1 deg/s, Tc = h = T = 1 s: 2 (2/e) - 2 (1 - 1/e)^2 = 0.672365
    v = angle_error_variance_deg2([{"kind": "gauss_markov", "tc_s": 1.0, "sigma_dph": 3600.0}], 1.0, 1.0)
    e = math.exp(-1.0)
    assert v[0] == pytest.approx(4 * e - 2 * (1 - e) ** 2, rel=1e-12)
    assert v[0] == pytest.approx(0.672365, abs=1e-6)


def test_quantization_and_ramp_closed_forms_by_hand():
    # angle white noise of 1 deg: 1 + (1 + h/T)^2 + (h/T)^2 = 6 at h = T
    q = angle_error_variance_deg2([{"kind": "quantization", "q_urad": 1.0 / DEG_PER_URAD}], 5.0, 5.0)
    assert q[0] == pytest.approx(6.0, rel=1e-12)
    # ramp slope 1 deg/s^2: error rate s (t + T/2), angle s (h^2/2 + h T/2) = 4 at h = T = 2
    r = angle_error_variance_deg2([{"kind": "ramp", "ramp_dph2": 3600.0**2}], 2.0, 2.0)
    assert r[0] == pytest.approx(16.0, rel=1e-12)


def test_ramp_closed_form_by_hand_at_a_slope_other_than_one():
    # at 1 deg/s^2 (above) the slope and its square are equal: a variance linear in R would pass there.
    # R = 36 deg/h^2 = 36 / 3600^2 deg/s^2 = 1/360000 deg/s^2; h = 100 s, T = 50 s: h^2/2 + h T/2 = 5000 + 2500
    # = 7500 s^2, so the angle error is 7500/360000 = 1/48 deg and its variance (1/48)^2 = 1/2304 deg^2
    r = angle_error_variance_deg2([{"kind": "ramp", "ramp_dph2": 36.0}], [100.0, 50.0], 50.0)
    assert r[0] == pytest.approx(1.0 / 2304.0, rel=1e-12)
    # h = T = 50 s: 1250 + 1250 = 2500 s^2 -> 2500/360000 = 1/144 deg -> 1/20736 deg^2
    assert r[1] == pytest.approx(1.0 / 20736.0, rel=1e-12)
    # an accelerometer's velocity error: R = 36 m/s^2 per hour = 0.01 m/s^3 (only the hour goes: m/s^2 stands where
    # deg/h stood); h = 100 s, T = 50 s: 0.01 * 7500 = 75 m/s, variance 5625 (m/s)^2
    a = angle_error_variance_deg2([{"kind": "ramp", "ramp_dph2": 36.0}], 100.0, 50.0, quantity="accel")
    assert a[0] == pytest.approx(5625.0, rel=1e-12)


def test_variance_is_sum_of_components_and_linear_in_parameter_variance():
    comps = [{"kind": "white", "arw_dprh": 0.3}, {"kind": "random_walk", "rrw_dphrh": 5.0},
             {"kind": "gauss_markov", "tc_s": 30.0, "sigma_dph": 2.0}]
    h = [1.0, 10.0, 100.0]
    total, parts = angle_error_variance_deg2(comps, h, 20.0, by_component=True)
    assert np.allclose(total, np.sum(parts, axis=0))
    scaled = [{"kind": "white", "arw_dprh": 0.6}, {"kind": "random_walk", "rrw_dphrh": 10.0},
              {"kind": "gauss_markov", "tc_s": 30.0, "sigma_dph": 4.0}]
    assert np.allclose(angle_error_variance_deg2(scaled, h, 20.0), 4.0 * total, rtol=1e-12)


def _exact_discrete_var(cov_fn, n_cal, n_h, dt):
    """Var of dt * sum_{horizon}(y - mean_cal(y)) from the full covariance matrix of the samples (deg/s, deg)."""
    n = n_cal + n_h
    t = np.arange(n) * dt
    C = cov_fn(t[:, None], t[None, :])
    w = np.r_[np.full(n_cal, -dt * n_h / n_cal), np.full(n_h, dt)]
    return float(w @ C @ w)


@pytest.mark.parametrize("h_s", [2.0, 10.0, 40.0])
def test_closed_forms_match_exact_discrete_covariance(h_s):
    """Independent reference: the covariance matrix of the sampled processes (deg/s) and the linear weights of
    'sum over the horizon minus h/T times the calibration sum'."""
    dt, T = 0.02, 10.0
    n_cal, n_h = int(round(T / dt)), int(round(h_s / dt))
    ns, ks, s, tc = 0.01, 0.002, 0.05, 7.0  # deg/sqrt(s), deg/s^1.5, deg/s, s
    white = _exact_discrete_var(lambda a, b: (a == b) * ns**2 / dt, n_cal, n_h, dt)
    # random walk observed at the sample times, reference zero at t = T (only differences matter)
    rw = _exact_discrete_var(lambda a, b: ks**2 * np.where((a - T) * (b - T) > 0,
                                                           np.minimum(np.abs(a - T), np.abs(b - T)), 0.0),
                             n_cal, n_h, dt)
    gm = _exact_discrete_var(lambda a, b: s**2 * np.exp(-np.abs(a - b) / tc), n_cal, n_h, dt)
    got = angle_error_variance_deg2([{"kind": "white", "arw_dprh": 60 * ns}], h_s, T)[0]
    assert got == pytest.approx(white, rel=1e-9)  # white: exact in discrete time too
    got = angle_error_variance_deg2([{"kind": "random_walk", "rrw_dphrh": 216000 * ks}], h_s, T)[0]
    assert got == pytest.approx(rw, rel=0.01)
    got = angle_error_variance_deg2([{"kind": "gauss_markov", "tc_s": tc, "sigma_dph": 3600 * s}], h_s, T)[0]
    assert got == pytest.approx(gm, rel=0.01)


def test_white_matches_statespace_forecast_with_a_diffuse_bias():
    """Second independent route: the Kalman filter of models.statespace on the calibration window with a diffuse
    bias prior estimates the window mean; its free-run angle variance is N^2 h + N^2 h^2 / T."""
    from fogdrift.models.statespace import forecast_uncertainty, kalman_filter, state_space

    dt, T, h = 0.1, 20.0, 30.0
    comps = [{"kind": "white", "arw_dprh": 0.5}]
    ss = state_space(comps, dt_s=dt, bias_prior_dph=1e7)
    _, _, state = kalman_filter(ss, np.zeros(int(round(T / dt))))
    _, _, ang = forecast_uncertainty(ss, int(round(h / dt)), state)
    assert float(ang[-1]) ** 2 == pytest.approx(angle_error_variance_deg2(comps, h, T)[0], rel=1e-6)


# --------------------------------------------------------------------------------------------------------------
# measured errors, inflation factor
# --------------------------------------------------------------------------------------------------------------
def test_observed_errors_by_hand_ramp():
    # rate = t deg/h at dt 1 s, T = 4, h = 2: origin 4: bias = mean(0..3) = 1.5; sum(4, 5) - 2*1.5 = 6 -> 6/3600
    y = np.arange(12, dtype=float)
    origins, e = observed_angle_errors_deg(y, 1.0, 4.0, [2.0])
    assert origins.tolist() == [4.0, 10.0]  # step T + h = 6 s: non-overlapping
    assert e[0, 0] == pytest.approx(6.0 / 3600.0)


def test_observed_errors_refuses_short_log():
    with pytest.raises(InsufficientDataError, match="calibration window plus the longest horizon"):
        observed_angle_errors_deg(np.zeros(10), 1.0, 8.0, [5.0])
    with pytest.raises(ConfigError, match="horizons"):
        observed_angle_errors_deg(np.zeros(10), 1.0, 2.0, [-1.0])


def test_inflation_factor_by_hand():
    r = np.array([0.5, 1.0, 2.0, 4.0])
    assert inflation_factor(r, 0.5, 1.0)[0] == 1.0  # 2nd smallest
    assert inflation_factor(r, 0.75, 1.0)[0] == 4.0  # 3rd smallest, squared
    assert inflation_factor(r, 0.75, 2.0)[0] == 1.0  # z = 2
    lam, lo, hi = inflation_factor(np.linspace(0.01, 3, 1000), 0.68, 1.0)
    assert lo < lam < hi


# --------------------------------------------------------------------------------------------------------------
# coverage on seeded simulations
# --------------------------------------------------------------------------------------------------------------
def _simulate(seed, n, dt, n_dprh, sigma_dph=0.0, tc_s=1.0):
    rng = np.random.default_rng(seed)
    y = rng.normal(0.0, 60.0 * n_dprh / math.sqrt(dt), n)
    if sigma_dph > 0:
        phi = math.exp(-dt / tc_s)
        w = rng.normal(0.0, sigma_dph * math.sqrt(1 - phi * phi), n)
        w[0] = rng.normal(0.0, sigma_dph)
        y += lfilter([1.0], [1.0, -phi], w)
    return y + 123.0  # a constant bias the calibration removes


TRUE = [{"kind": "white", "arw_dprh": 0.2}, {"kind": "gauss_markov", "tc_s": 15.0, "sigma_dph": 4.0}]
DT, T_CAL, H = 0.1, 20.0, [5.0, 30.0]


@pytest.fixture(scope="module")
def sim_logs():
    return [({"x": _simulate(seed, 200_000, DT, 0.2, 4.0, 15.0)}, DT) for seed in range(6)]


def test_correct_model_covers_nominal(sim_logs):
    res = check_consistency("truth", {"x": TRUE}, sim_logs, t_cal_s=T_CAL, horizons_s=H)
    for row in res.axes["x"]["rows"]:
        n = row.n_origins
        assert n > 1000
        for name, p, _ in BANDS:
            tol = 4.0 * math.sqrt(p * (1 - p) / n)  # binomial, 4 sigma
            assert abs(row.coverage[name] - p) < tol, (row.horizon_s, name, row.coverage[name])
            lam, lo, hi = row.inflation[name]
            assert lo < 1.0 < hi or abs(lam - 1) < 0.15


def test_halved_white_noise_needs_inflation_four(sim_logs):
    white_only = [({"x": _simulate(seed, 100_000, DT, 0.2)}, DT) for seed in range(3)]
    half = [{"kind": "white", "arw_dprh": 0.1}]
    res = check_consistency("N halved", {"x": half}, white_only, t_cal_s=T_CAL, horizons_s=H)
    for row in res.axes["x"]["rows"]:
        # predicted sigma is half the truth: the 68 % band holds |Z| <= 0.5, i.e. 38.3 %
        assert abs(row.coverage["68 %"] - 0.3829) < 4 * math.sqrt(0.38 * 0.62 / row.n_origins)
        for name, _, _ in BANDS:
            lam, lo, hi = row.inflation[name]
            assert lam == pytest.approx(4.0, rel=0.15)
            assert lo < 4.0 < hi
    lam, _, _ = res.worst_inflation("x")
    assert lam > 3.0


def test_white_plus_rw_target_undercovers_bias_wander_and_the_covering_rw_fixes_it(sim_logs):
    """A Gauss-Markov wander dropped by a white+RW target: under-coverage at 30 s; the random walk that covers the
    wander at 30 s brings the 30 s coverage back within tolerance."""
    reduced = reduced_model(TRUE)
    assert reduced == [TRUE[0]]
    res = check_consistency("white+RW", {"x": reduced}, sim_logs, t_cal_s=T_CAL, horizons_s=H)
    row = res.axes["x"]["rows"][1]
    assert row.coverage["68 %"] < 0.6 and row.inflation["68 %"][1] > 1.5
    cover = random_walk_covering(TRUE, 30.0, T_CAL)
    assert cover["ratio"] is None and "no random walk of its own" in cover["sentence"]
    model = reduced + [{"kind": "random_walk", "rrw_dphrh": cover["k_eff_dphrh"]}]
    # same predicted variance at the covered horizon, by construction
    assert angle_error_variance_deg2(model, 30.0, T_CAL)[0] == pytest.approx(
        angle_error_variance_deg2(TRUE, 30.0, T_CAL)[0], rel=1e-9)
    res = check_consistency("covering", {"x": model}, sim_logs, t_cal_s=T_CAL, horizons_s=[30.0])
    row = res.axes["x"]["rows"][0]
    assert abs(row.coverage["68 %"] - BANDS[0][1]) < 4 * math.sqrt(0.68 * 0.32 / row.n_origins)


def test_random_walk_covering_sentence_and_ratio():
    comps = [{"kind": "white", "arw_dprh": 0.1}, {"kind": "random_walk", "rrw_dphrh": 2.0},
             {"kind": "gauss_markov", "tc_s": 50.0, "sigma_dph": 1.0}]
    d = random_walk_covering(comps, 60.0, 60.0)
    assert d["ratio"] > 1.0 and d["k_eff_dphrh"] == pytest.approx(2.0 * d["ratio"])
    assert d["sentence"].startswith("to cover the bias wander over 60 s")
    assert "gyroscope_random_walk = " in d["sentence"] and "× the random walk alone" in d["sentence"]
    # SI: K [deg/h^1.5] / 216000 -> deg/s^1.5, * pi/180 -> rad/s^2/sqrt(Hz)
    assert d["k_eff_si"] == pytest.approx(d["k_eff_dphrh"] / 216000 * math.pi / 180)


def test_components_from_noise_fit_keeps_the_markov_term():
    fit = SimpleNamespace(statistic="adev", A=np.array([0.0, 36.0, 0.0, 0.0, 0.0]), tau_min_s=0.1, tau_max_s=100.0,
                          shaped={"M": {"tc_s": 20.0, "sigma_dph": 3.0}}, selected=("N", "M", "S"), no_fit=None)
    comps, notes = components_from_noise_fit(fit)
    assert comps == [{"kind": "white", "arw_dprh": 0.1}, {"kind": "gauss_markov", "tc_s": 20.0, "sigma_dph": 3.0}]
    assert any("periodic term S" in n for n in notes)
    with pytest.raises(ConfigError, match="Allan-variance fit"):
        components_from_noise_fit(SimpleNamespace(statistic="hdev"))


def test_coverage_rows_shapes():
    rows = coverage_rows([np.array([0.5, -1.5]), np.array([3.0])], [1.0, 2.0], [1.0, 2.0])
    assert [r.n_origins for r in rows] == [2, 1]
    assert rows[0].coverage["68 %"] == 0.5 and rows[1].coverage["68 %"] == 0.0
    assert rows[1].to_dict()["inflation"]["68 %"]["lambda"] == pytest.approx(2.25)


def test_random_walk_covering_against_the_k_bound():
    comps = [{"kind": "white", "arw_dprh": 0.1}, {"kind": "gauss_markov", "tc_s": 50.0, "sigma_dph": 1.0}]
    d = random_walk_covering(comps, 60.0, 60.0, k_bound_dphrh=2.0)
    assert d["ratio"] is None and d["ratio_to_bound"] == pytest.approx(d["k_eff_dphrh"] / 2.0)
    assert "× the random walk's 95 % upper bound (2 deg/h^1.5" in d["sentence"]


def test_components_from_gmwm_ieee_reading():
    from fogdrift.evaluation.consistency import components_from_gmwm

    v = lambda x: SimpleNamespace(value=x)  # noqa: E731
    ie = SimpleNamespace(terms={"N_dprh": v(0.2), "K_dphrh": v(3.0), "Q_urad": v(5.0)},
                         gm=[{"tc_s": v(12.0), "sigma_gm_dph": v(4.0)}], tau_range_s=(0.02, 500.0))
    comps, notes = components_from_gmwm(SimpleNamespace(selection=SimpleNamespace(ieee=ie)))
    assert comps == [{"kind": "white", "arw_dprh": 0.2}, {"kind": "quantization", "q_urad": 5.0},
                     {"kind": "random_walk", "rrw_dphrh": 3.0},
                     {"kind": "gauss_markov", "tc_s": 12.0, "sigma_dph": 4.0}]
    assert notes == []


def test_components_from_a_real_gmwm_fit_recover_the_simulated_truth():
    """GMWM on a simulated WN+GM log: the components predict the angle variance of the truth within 10 %."""
    from fogdrift.evaluation.consistency import components_from_gmwm
    from fogdrift.gmwm.analysis import analyse_gmwm

    y = _simulate(3, 200_000, DT, 0.2, 4.0, 15.0)
    comps, _ = components_from_gmwm(analyse_gmwm("x", y - y.mean(), DT, model="WN+GM"))
    got = angle_error_variance_deg2(comps, [5.0, 30.0], T_CAL)
    want = angle_error_variance_deg2(TRUE, [5.0, 30.0], T_CAL)
    np.testing.assert_allclose(got, want, rtol=0.1)


def test_accelerometer_velocity_error_by_hand_and_by_simulation():
    """Specific force in m/s^2 (components in m/s^2 in place of deg/h): velocity error in m/s, no 1/3600."""
    # arw_dprh = 1/60 -> density 60 * (1/60) = 1 (m/s^2) sqrt(s) = 1 m/s/sqrt(s); h = T = 1 s: 1 + 1 = 2 (m/s)^2
    v = angle_error_variance_deg2([{"kind": "white", "arw_dprh": 1 / 60}], 1.0, 1.0, quantity="accel")
    assert v[0] == pytest.approx(2.0, rel=1e-12)
    # a random walk of K = 60 (m/s^2)/sqrt(h) = 1 m/s^2.5: h = 3, T = 6: 27 (m/s)^2
    v = angle_error_variance_deg2([{"kind": "random_walk", "rrw_dphrh": 60.0}], 3.0, 6.0, quantity="accel")
    assert v[0] == pytest.approx(27.0, rel=1e-12)
    # observed: 0.1 m/s^2 above the calibrated mean for 10 s -> 1 m/s
    _, e = observed_angle_errors_deg(np.r_[np.zeros(10), np.full(10, 0.1)], 1.0, 10.0, [10.0], quantity="accel")
    assert e[0, 0] == pytest.approx(1.0)
    # seeded: white specific force of density 0.01 m/s/sqrt(s) (per 0.1-s sample sigma 0.01/sqrt(0.1) m/s^2)
    rng = np.random.default_rng(11)
    logs = [({"ax": rng.normal(9.8, 0.01 / math.sqrt(DT), 200_000)}, DT) for _ in range(2)]
    comps = {"ax": [{"kind": "white", "arw_dprh": 0.01 / 60}]}
    res = check_consistency("truth", comps, logs, t_cal_s=T_CAL, horizons_s=H, quantity="accel")
    for row in res.axes["ax"]["rows"]:
        n = row.n_origins
        assert abs(row.coverage["68 %"] - BANDS[0][1]) < 4 * math.sqrt(0.68 * 0.32 / n)
    d = random_walk_covering([{"kind": "white", "arw_dprh": 0.01}, {"kind": "random_walk", "rrw_dphrh": 6.0}],
                             60.0, 60.0, quantity="accel")
    assert "accelerometer_random_walk = 0.1 m/s^3/sqrt(Hz)" in d["sentence"]  # 6 / 60
    with pytest.raises(ConfigError, match="quantity must be 'gyro' or 'accel'"):
        angle_error_variance_deg2([{"kind": "white", "arw_dprh": 1.0}], 1.0, 1.0, quantity="mag")


def test_random_walk_covering_white_only_model_says_nothing_to_cover():
    d = random_walk_covering([{"kind": "white", "arw_dprh": 0.1}], 60.0, 60.0, k_bound_dphrh=3.0)
    assert d["k_eff_dphrh"] == 0.0 and "no drift beyond its white noise" in d["sentence"]


def test_short_log_gives_no_origins_at_long_horizons_and_none_reaching_is_an_error():
    comps = {"x": [{"kind": "white", "arw_dprh": 0.2}]}
    long = ({"x": _simulate(1, 2000, DT, 0.2)}, DT)  # 200 s
    short = ({"x": _simulate(2, 400, DT, 0.2)}, DT)  # 40 s: reaches h = 5 s after 20 s, not h = 30 s
    res = check_consistency("t", comps, [long, short], t_cal_s=20.0, horizons_s=[5.0, 30.0])
    n5, n30 = (r.n_origins for r in res.axes["x"]["rows"])
    assert n5 == 8 + 1 and n30 == 4  # floor((N - k - m)/s) + 1 per log; the short log adds 1 at 5 s, 0 at 30 s
    with pytest.raises(InsufficientDataError,
                       match=r"horizon\(s\) 300 s after a 20 s calibration \(the longest is 200 s\)"):
        check_consistency("t", comps, [long, short], t_cal_s=20.0, horizons_s=[5.0, 300.0])


# --------------------------------------------------------------------------------------------------------------
# Rules first pinned against the surviving mutants of ``fogdrift.evaluation.consistency`` (docs/testing-rounds.md)
# --------------------------------------------------------------------------------------------------------------
from fogdrift.evaluation.consistency import ConsistencyResult  # noqa: E402


def test_quantization_closed_form_at_a_horizon_twice_the_calibration():
    # angle white noise of 1 deg, h = 2 T: 1 + (1 + 2)^2 + 2^2 = 14 deg^2
    q = angle_error_variance_deg2([{"kind": "quantization", "q_urad": 1.0 / DEG_PER_URAD}], 10.0, 5.0)
    assert q[0] == pytest.approx(14.0, rel=1e-12)


def test_gauss_markov_on_the_small_x_series_branch():
    # Tc = 1e7 s, h = 600 s, T = 300 s: x = L/Tc < 1e-4, where the code switches to the series of x - 1 + e^-x.
    # Reference: the same closed form, V(L) = 2 s^2 Tc^2 (x - 1 + e^-x), with that core summed to 6 terms here.
    tc, h, T, sigma = 1e7, 600.0, 300.0, 3600.0  # sigma 1 deg/s
    s2 = (sigma / 3600.0) ** 2

    def core(x):
        return sum((-x) ** k / math.factorial(k) for k in range(2, 8))

    def v(L):
        return 2.0 * s2 * tc * tc * core(L / tc)

    cross = s2 * tc * tc * (-math.expm1(-h / tc)) * (-math.expm1(-T / tc))
    ref = v(h) + (h / T) ** 2 * v(T) - 2.0 * (h / T) * cross
    got = angle_error_variance_deg2([{"kind": "gauss_markov", "tc_s": tc, "sigma_dph": sigma}], h, T)[0]
    # (the sum cancels its x^2 terms: the code's 2-term series is good to ~1e-5 of the result here)
    assert got == pytest.approx(ref, rel=1e-4)
    # and the series joins the exact form: just above the switch (x = 2e-4) the exact core gives the same law
    tc2 = h / 2e-4
    exact = angle_error_variance_deg2([{"kind": "gauss_markov", "tc_s": tc2, "sigma_dph": sigma}], h, T)[0]
    series = angle_error_variance_deg2([{"kind": "gauss_markov", "tc_s": tc2 * 2.1, "sigma_dph": sigma}], h, T)[0]
    assert series * 2.1 == pytest.approx(exact, rel=1e-3)   # the leading term is linear in 1/Tc


@pytest.mark.parametrize("step", [0.0, -60.0, math.inf, math.nan])
def test_origin_step_must_be_finite_and_positive(step):
    y = np.zeros(100)
    with pytest.raises(ConfigError, match=r"origin_step.* must be a finite number > 0 \[s\]"):
        observed_angle_errors_deg(y, 1.0, 10.0, [10.0], step_s=step)


def test_coverage_rows_default_unit_is_deg():
    rows = coverage_rows([np.array([0.5, -1.5])], [1.0], [60.0])
    assert rows[0].unit == "deg" and rows[0].to_dict()["unit"] == "deg"


def test_random_walk_covering_returns_the_bound_it_was_given():
    comps = [{"kind": "white", "arw_dprh": 0.1}, {"kind": "gauss_markov", "tc_s": 50.0, "sigma_dph": 1.0}]
    d = random_walk_covering(comps, 60.0, 30.0, k_bound_dphrh=2.0)
    assert d["k_bound_dphrh"] == 2.0 and d["horizon_s"] == 60.0 and d["t_cal_s"] == 30.0
    assert random_walk_covering(comps, 60.0, 30.0)["k_bound_dphrh"] is None


def test_consistency_result_to_dict_keys_and_values():
    rng = np.random.default_rng(3)
    logs = [({"gx": rng.normal(0.0, 60.0, 4000)}, 1.0)]   # white noise, N = 1 deg/sqrt(h) at dt = 1 s
    res = check_consistency("full", {"gx": [{"kind": "white", "arw_dprh": 1.0}]}, logs, t_cal_s=100.0,
                            horizons_s=[50.0, 100.0])
    assert isinstance(res, ConsistencyResult)
    d = res.to_dict()
    assert d["target"] == "full" and d["t_cal_s"] == 100.0 and d["horizons_s"] == [50.0, 100.0]
    assert d["notes"] == []
    ax = d["axes"]["gx"]
    assert ax["n_logs"] == 1 and ax["quantity"] == "gyro" and ax["components"][0]["kind"] == "white"
    assert [r["horizon_s"] for r in ax["rows"]] == [50.0, 100.0]
    assert ax["rows"][0]["n_origins"] == 4000 // 150 and ax["rows"][1]["n_origins"] == 4000 // 200


def test_a_one_sample_horizon_is_one_sample():
    # dt = 1 s, T = 2 s, h = 1 s: a rate 3.6 deg/h above the calibrated mean for one second = 1e-3 deg
    y = np.array([0.0, 0.0, 3.6, 7.2])
    _, e = observed_angle_errors_deg(y, 1.0, 2.0, [1.0], step_s=10.0)
    assert e.shape == (1, 1) and e[0, 0] == pytest.approx(1e-3, rel=1e-12)


def test_inflation_interval_when_the_lower_rank_is_the_first_order_statistic():
    from scipy.stats import binom

    from fogdrift.evaluation.consistency import inflation_factor

    p = 0.6826894921370859
    assert int(binom.ppf(0.025, 5, p)) == 1
    lam, lo, hi = inflation_factor([0.5, 1.0, 1.5, 2.0, 3.0], p, 1.0)
    # lambda: rank ceil(0.6827 * 5) = 4 -> 2.0^2; lower rank 1 -> 0.5^2; upper rank 5 + 1 > n -> NaN
    assert lam == pytest.approx(4.0) and lo == pytest.approx(0.25) and math.isnan(hi)


def test_inflation_interval_bounds_outside_the_sample_are_nan_and_inside_read_their_rank():
    from scipy.stats import binom

    from fogdrift.evaluation.consistency import inflation_factor

    # n = 3, p = 0.6827: P(X = 0) = 0.317^3 = 0.032 >= 0.025, so the 2.5 % rank is 0 (outside) -> NaN, not the
    # last value
    assert int(binom.ppf(0.025, 3, 0.6826894921370859)) == 0
    assert math.isnan(inflation_factor([1.0, 2.0, 3.0], 0.6826894921370859, 1.0)[1])
    # n = 40 ratios 0.1, 0.2, ..., 4.0 at p = 0.6827: upper rank = ppf(0.975) + 1, read as the rank-th smallest
    r = np.arange(1, 41) / 10.0
    p = 0.6826894921370859
    hi_rank = int(binom.ppf(0.975, 40, p)) + 1
    assert hi_rank <= 40
    assert inflation_factor(r[::-1], p, 1.0)[2] == pytest.approx((hi_rank / 10.0) ** 2, rel=1e-12)


def test_coverage_rows_from_a_2d_array_with_rms():
    e = np.array([[0.5, 1.0], [-1.5, 3.0]])
    rows = coverage_rows(e, [1.0, 2.0], [10.0, 20.0], unit="m/s")
    assert [r.n_origins for r in rows] == [2, 2] and rows[1].unit == "m/s"
    assert rows[0].rms == pytest.approx(math.sqrt((0.25 + 2.25) / 2)) and rows[1].coverage["68 %"] == 0.5
    d = rows[0].to_dict()
    assert d["horizon_s"] == 10.0 and d["rms"] == pytest.approx(rows[0].rms) and d["sigma_pred"] == 1.0


def test_accelerometer_axes_by_dict_and_the_velocity_sentence():
    rng = np.random.default_rng(4)
    logs = [({"gx": rng.normal(0.0, 60.0, 3000), "ax": rng.normal(0.0, 0.01, 3000)}, 1.0)]
    comps = {"gx": [{"kind": "white", "arw_dprh": 1.0}], "ax": [{"kind": "white", "arw_dprh": 0.6}]}
    res = check_consistency("full", comps, logs, t_cal_s=100.0, horizons_s=[100.0], quantity={"ax": "accel"})
    assert res.axes["gx"]["quantity"] == "gyro" and res.axes["gx"]["rows"][0].unit == "deg"
    assert res.axes["ax"]["quantity"] == "accel" and res.axes["ax"]["rows"][0].unit == "m/s"
    d = random_walk_covering([{"kind": "white", "arw_dprh": 0.01}, {"kind": "random_walk", "rrw_dphrh": 0.002}],
                             60.0, 60.0, quantity="accel")
    assert "(0.002 (m/s^2)/sqrt(h))" in d["sentence"] and "accelerometer_random_walk" in d["sentence"]


def test_non_finite_held_out_rate_message():
    y = np.zeros(50)
    y[7] = np.nan
    with pytest.raises(ConfigError, match=r"held-out rate.*non-finite"):
        observed_angle_errors_deg(y, 1.0, 10.0, [10.0])


def test_integer_horizons_beyond_int64_cubes():
    # h = 3e6 s as an int: h^3 = 2.7e19 overflows int64; the variance must be that of the float horizon
    k = [{"kind": "random_walk", "rrw_dphrh": 1.0}]
    assert angle_error_variance_deg2(k, [3_000_000], 100.0)[0] == pytest.approx(
        angle_error_variance_deg2(k, [3e6], 100.0)[0], rel=1e-12)


def test_an_error_exactly_on_the_band_edge_is_inside():
    rows = coverage_rows([np.array([1.0, -1.0, 3.0])], [1.0], [60.0])
    assert rows[0].coverage["68 %"] == pytest.approx(2.0 / 3.0)
    d = rows[0].to_dict()
    assert set(d["inflation"]["95 %"]) == {"lambda", "lo95", "hi95"}


@pytest.mark.parametrize("h", [[], [[60.0, 120.0]], [0.0], [math.nan]])
def test_horizons_must_be_a_non_empty_list_of_positive_numbers(h):
    with pytest.raises(ConfigError, match="horizons"):
        angle_error_variance_deg2([{"kind": "white", "arw_dprh": 1.0}], h, 100.0)


def test_a_zero_k_bound_is_no_bound():
    comps = [{"kind": "white", "arw_dprh": 0.1}, {"kind": "gauss_markov", "tc_s": 50.0, "sigma_dph": 1.0}]
    d = random_walk_covering(comps, 60.0, 60.0, k_bound_dphrh=0.0)
    assert d["k_bound_dphrh"] is None and d["ratio_to_bound"] is None and d["k_alone_dphrh"] == 0.0


def test_worst_inflation_is_the_largest_finite_lambda_and_the_first_of_ties():
    from fogdrift.evaluation.consistency import CoverageRow

    def row(h, lam68, lam95):
        return CoverageRow(horizon_s=h, n_origins=5, sigma_pred=1.0, rms=1.0, coverage={},
                           inflation={"68 %": (lam68, 0.0, 0.0), "95 %": (lam95, 0.0, 0.0)})

    res = ConsistencyResult("full", {"gx": {"rows": [row(60.0, 2.0, math.inf), row(600.0, 3.0, 3.0)]},
                                     "gy": {"rows": [row(60.0, math.nan, math.nan)]}}, 100.0, (60.0, 600.0))
    assert res.worst_inflation("gx") == (3.0, 600.0, "68 %")   # inf is skipped; a tie keeps the first
    lam, h, band = res.worst_inflation("gy")                     # nothing finite: the empty answer
    assert lam == -math.inf and math.isnan(h) and band == ""


def test_coverage_row_dict_values_and_interval_ends():
    from fogdrift.evaluation.consistency import CoverageRow

    r = CoverageRow(horizon_s=60.0, n_origins=3, sigma_pred=1.0, rms=2.0, coverage={"68 %": 0.5},
                    inflation={"68 %": (2.0, 1.5, 3.0)})
    d = r.to_dict()
    assert d["coverage"] == {"68 %": 0.5} and d["inflation"]["68 %"] == {"lambda": 2.0, "lo95": 1.5, "hi95": 3.0}


def test_check_consistency_passes_the_origin_step_on():
    rng = np.random.default_rng(5)
    logs = [({"gx": rng.normal(0.0, 60.0, 4000)}, 1.0)]
    res = check_consistency("full", {"gx": [{"kind": "white", "arw_dprh": 1.0}]}, logs, t_cal_s=100.0,
                            horizons_s=[50.0], step_s=50.0)
    assert res.axes["gx"]["rows"][0].n_origins == len(range(100, 4000 - 50 + 1, 50))   # 78, not 4000 // 150


def test_short_log_error_carries_what_it_needed():
    from fogdrift.errors import InsufficientDataError

    with pytest.raises(InsufficientDataError) as exc:
        observed_angle_errors_deg(np.zeros(50), 1.0, 40.0, [20.0])
    assert exc.value.needed == 60 and exc.value.got == 50


def test_covering_sentences_of_a_gyro_and_of_a_white_only_model():
    d = random_walk_covering([{"kind": "white", "arw_dprh": 0.1}, {"kind": "random_walk", "rrw_dphrh": 2.0}],
                             60.0, 60.0)
    assert "use gyroscope_random_walk = " in d["sentence"] and " rad/s^2/sqrt(Hz) (2 deg/h^1.5)" in d["sentence"]
    d = random_walk_covering([{"kind": "white", "arw_dprh": 0.1}], 60.0, 60.0)
    assert d["sentence"].endswith(": the model has no drift beyond its white noise, so nothing to cover (a filter may "
                                  "still want a small K)")
