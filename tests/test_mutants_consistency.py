"""Tests added for the surviving mutants of ``fogdrift.evaluation.consistency`` (issue 24 item 2, docs/testing-rounds.md
"Round 2: new modules (issues 21-23)"): the closed forms where the existing by-hand cases sit on a symmetric point
(quantization at h != T; the Gauss-Markov small-x series branch), the origin-step validator at 0, and the keys and
units of the returned records."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fogdrift.errors import ConfigError
from fogdrift.evaluation.consistency import (ConsistencyResult, angle_error_variance_deg2, check_consistency,
                                             coverage_rows, observed_angle_errors_deg, random_walk_covering)

DEG_PER_URAD = 1e-6 * 180.0 / math.pi


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
    with pytest.raises(ConfigError, match=r"^the held-out rate has non-finite samples$"):
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
