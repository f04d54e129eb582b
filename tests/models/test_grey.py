"""Grey theory: AGO/IAGO (R13), GM(1,1) (R12), class ratio, the shift and the GM11 model.

Reference values: method notes §3 and §7 (R12, R13), each computed there by a script that was run.
R12 tolerance 1e-4 abs (the published values have 4-6 decimals). R13 is exact in exact arithmetic;
the float check allows 1e-15 (one rounding of the partial sums in ``np.diff``).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from fogdrift.errors import ConfigError, DataFormatError, FogdriftWarning, InsufficientDataError, NotFittedError
from fogdrift.models.grey import (
    GM11,
    GM11Fit,
    ago,
    auto_shift,
    class_ratio_check,
    gm11_fit,
    gm11_predict,
    grade,
    iago,
    mean_relative_error_pct,
    posterior_variance_ratio,
    small_error_probability,
)
from fogdrift.models import load_model, save_model

R12_X0 = [2.874, 3.278, 3.337, 3.390, 3.679]
TOY = np.array([-0.02, 0.01, 0.03, -0.01, 0.02, 0.04])  # method notes §3.3


# -- R13: AGO / IAGO -------------------------------------------------------------------------------
def test_r13_ago_iago_and_one_step_restore():
    x = [0.5, -0.2, 0.1, 0.3]
    x1 = ago(x)
    assert x1.tolist() == [0.5, 0.3, 0.4, 0.7]  # exact
    assert_allclose(iago(x1), x, rtol=0, atol=1e-15)
    # one-step restore with the MEASURED x1(3) = 0.4 and a predicted x1_hat(4) = 0.75 (notes §4.1)
    x1_hat_4 = 0.75
    assert x1_hat_4 - x1[2] == 0.35
    # the restored error equals the AGO-domain error: 0.35 - 0.3 == 0.75 - 0.7
    assert (x1_hat_4 - x1[2]) - x[3] == pytest.approx(x1_hat_4 - x1[3], abs=1e-15)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(-1e3, 1e3, allow_nan=False), min_size=1, max_size=60))
def test_ago_iago_round_trip(values):
    x = np.array(values)
    assert_allclose(iago(ago(x)), x, rtol=0, atol=1e-12 * (1 + np.abs(np.cumsum(x)).max()))
    assert_allclose(ago(iago(x)), x, rtol=0, atol=1e-12 * (1 + np.abs(x).max()))


def test_ago_rejects_nan_and_2d():
    with pytest.raises(DataFormatError, match=r"x\[1\]"):
        ago([1.0, np.nan])
    with pytest.raises(DataFormatError):
        iago(np.ones((2, 2)))


# -- R12: GM(1,1) ------------------------------------------------------------------------------------
def test_r12_gm11_reference_values():
    fit = gm11_fit(R12_X0)
    assert fit.a == pytest.approx(-0.037204, abs=1e-6)
    assert fit.b == pytest.approx(3.065363, abs=1e-6)
    assert (fit.n, fit.shift, fit.x0_first) == (5, 0.0, 2.874)
    x0_hat = gm11_predict(fit, 6)
    assert_allclose(x0_hat[:5], [2.874, 3.2320, 3.3545, 3.4817, 3.6137], atol=1e-4)
    assert x0_hat[5] == pytest.approx(3.7507, abs=1e-4)
    # x1_hat of the notes (AGO of the restored values)
    assert_allclose(ago(x0_hat[:5]), [2.874, 6.1060, 9.4606, 12.9423, 16.5560], atol=1e-4)
    C = posterior_variance_ratio(R12_X0, x0_hat[:5])
    P = small_error_probability(R12_X0, x0_hat[:5])
    assert C == pytest.approx(0.2125, abs=1e-4)
    assert P == 1.0
    assert mean_relative_error_pct(R12_X0, x0_hat[:5]) == pytest.approx(1.602, abs=1e-3)
    assert grade(C, P) == "good"


def test_gm11_fit_matches_normal_equations():
    """Independent solve: (BᵀB)⁻¹BᵀY written out by hand (notes §3.2 step 3)."""
    x = np.array(R12_X0)
    x1 = np.cumsum(x)
    z = 0.5 * (x1[1:] + x1[:-1])
    B = np.column_stack([-z, np.ones(4)])
    a, b = np.linalg.solve(B.T @ B, B.T @ x[1:])
    fit = gm11_fit(x)
    assert fit.a == pytest.approx(a, rel=1e-10)
    assert fit.b == pytest.approx(b, rel=1e-10)
    # closed-form time response with explicit b/a (a is far from 0 here)
    k = np.arange(1, 8)
    ref = (1 - np.exp(a)) * (x[0] - b / a) * np.exp(-a * k)
    assert_allclose(gm11_predict(fit, 8)[1:], ref, rtol=1e-12)


def test_gm11_fit_to_dict_is_json_ready():
    import json

    d = gm11_fit(R12_X0).to_dict()
    assert set(d) == {"a", "b", "x0_first", "n", "shift"}
    json.dumps(d)


def test_gm11_fit_errors():
    with pytest.raises(InsufficientDataError) as info:
        gm11_fit([1.0, 2.0, 3.0])
    assert (info.value.needed, info.value.got) == (4, 3)
    with pytest.raises(DataFormatError, match="not identifiable"):
        gm11_fit([3.0, 0.0, 0.0, 0.0])
    with pytest.raises(ConfigError, match="shift"):
        gm11_fit(R12_X0, shift=math.inf)
    with pytest.raises(ConfigError, match="n_total"):
        gm11_predict(gm11_fit(R12_X0), -1)


@settings(max_examples=60, deadline=None)
@given(st.floats(-1e4, 1e4, allow_nan=False).filter(lambda c: c == 0 or abs(c) > 1e-6), st.integers(4, 60))
def test_constant_series_forecasts_the_constant(c0, n):
    """a -> 0 must not divide by zero; GM(1,1) of a constant is that constant (model, auto shift)."""
    y = np.full(n, c0)
    model = GM11(mode="whole").fit(y)
    assert abs(model.a_) < 1e-9
    tol = 1e-9 * max(1.0, abs(c0))
    assert_allclose(model.forecast(5), c0, atol=tol)
    assert_allclose(GM11(mode="rolling", window=4).fit(y).forecast(5), c0, atol=tol)
    if c0 > 0:  # plain functions, no shift
        assert_allclose(gm11_predict(gm11_fit(y), n + 3), c0, atol=tol)


def test_exact_zero_a_has_no_division():
    fit = GM11Fit(a=0.0, b=2.5, x0_first=2.5, n=4, shift=0.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert_allclose(gm11_predict(fit, 10), 2.5, rtol=0, atol=0)


# -- class ratio, precision tests, grading ----------------------------------------------------------
def test_class_ratio_interval_and_pass():
    ok, sigma, (lo, hi) = class_ratio_check(R12_X0)
    assert ok
    assert (lo, hi) == pytest.approx((math.exp(-2 / 6), math.exp(2 / 6)))
    assert (round(lo, 4), round(hi, 4)) == (0.7165, 1.3956)
    assert_allclose(sigma, np.array(R12_X0[:-1]) / np.array(R12_X0[1:]))


def test_class_ratio_fails_for_signed_drift_and_passes_after_shift():
    ok, sigma, _ = class_ratio_check(TOY)
    assert not ok
    assert class_ratio_check(TOY + 10.0)[0]
    ok0, sigma0, _ = class_ratio_check([1.0, 0.0, 1.0, 1.0])
    assert not ok0 and np.isinf(sigma0[0])


def test_grade_table_boundaries():
    assert grade(0.34, 0.96) == "good"
    assert grade(0.35, 0.96) == "qualified"  # C must be < 0.35
    assert grade(0.2, 0.95) == "qualified"  # P must be > 0.95
    assert grade(0.64, 0.71) == "barely"
    assert grade(0.65, 0.99) == "unqualified"
    assert grade(math.nan, 1.0) == "unqualified"


def test_precision_tests_hand_values():
    x = np.array([1.0, 2.0, 3.0, 4.0])  # std (ddof=0) = sqrt(1.25)
    xh = np.array([1.0, 2.5, 3.0, 3.0])  # eps = [0, -0.5, 0, 1]; mean 0.125, var 1.1875/4
    assert posterior_variance_ratio(x, xh) == pytest.approx(math.sqrt(0.296875 / 1.25))
    # |eps - 0.125| = [0.125, 0.625, 0.125, 0.875] < 0.6745*1.118034 = 0.75411 -> 3 of 4
    assert small_error_probability(x, xh) == 0.75
    assert mean_relative_error_pct(x, xh) == pytest.approx(100 * (0.25 + 0 + 0.25) / 3)
    assert math.isnan(posterior_variance_ratio([2.0, 2.0, 2.0], [2.0, 2.0, 2.0]))
    with pytest.raises(DataFormatError, match="same length"):
        posterior_variance_ratio(x, xh[:3])


# -- the shift --------------------------------------------------------------------------------------
@pytest.mark.parametrize("c, expected", [(0.1, 0.0347), (1.0, 0.0332), (10.0, 0.0330)])
def test_shift_sensitivity_toy_series(c, expected):
    """Notes §3.3: the next-step forecast depends on c; a -> 0 as c grows."""
    model = GM11(mode="whole", shift=c).fit(TOY)
    assert model.shift_ == c
    assert model.forecast(1)[0] == pytest.approx(expected, abs=5e-5)
    assert gm11_predict(gm11_fit(TOY, shift=c), 7)[6] == pytest.approx(expected, abs=5e-5)


def test_sensitivity_to_shift_helper_and_a_shrinks():
    model = GM11(mode="whole")
    table = model.sensitivity_to_shift(TOY, [0.1, 1.0, 10.0], h=1)
    assert_allclose(table[:, 0], [0.0347, 0.0332, 0.0330], atol=5e-5)
    a = [abs(gm11_fit(TOY, shift=c).a) for c in (0.1, 1.0, 10.0, 100.0)]
    assert a == sorted(a, reverse=True) and a[-1] < 1e-4
    assert "shift_" not in vars(model)  # helper does not fit self


def test_auto_shift_uses_training_block_only():
    y = TOY
    assert auto_shift(y) == pytest.approx(0.08)  # -min + 1.0 * range = 0.02 + 0.06
    assert auto_shift(y, margin=0.5) == pytest.approx(0.05)
    assert auto_shift([5.0, 6.0, 7.0]) == 0.0  # already >= margin * range above zero
    assert auto_shift([0.0, 0.0]) == 1.0
    model = GM11(mode="rolling", window=4).fit(y)
    assert model.shift_ == pytest.approx(0.08)
    assert model.class_ratio_pass_ == class_ratio_check(y + model.shift_)[0]


# -- GM11 model --------------------------------------------------------------------------------------
def _rolling_reference(full, w, shift, first):
    """Independent rolling one-step GM(1,1): normal equations per window (notes §3.2)."""
    out = []
    for j in range(first, full.size):
        x = full[j - w : j] + shift
        x1 = np.cumsum(x)
        z = 0.5 * (x1[1:] + x1[:-1])
        B = np.column_stack([-z, np.ones(w - 1)])
        a, b = np.linalg.solve(B.T @ B, B.T @ x[1:])
        out.append((1 - np.exp(a)) * (x[0] - b / a) * np.exp(-a * w) - shift)
    return np.array(out)


def test_rolling_predict_matches_per_window_fits():
    rng = np.random.default_rng(3)
    y = 1.0 + np.cumsum(rng.normal(0, 0.05, 120))
    model = GM11(mode="rolling", window=8).fit(y[:80])
    pred = model.predict(y[80:], history=y[:80])
    assert_allclose(pred, _rolling_reference(y, 8, model.shift_, 80), rtol=1e-9, atol=1e-12)
    # without history: NaN warm-up of `window` samples, then the same estimator
    pred0 = model.predict(y[80:])
    assert np.isnan(pred0[:8]).all()
    assert_allclose(pred0[8:], _rolling_reference(y[80:], 8, model.shift_, 8), rtol=1e-9, atol=1e-12)
    # partial history
    pred3 = model.predict(y[80:], history=y[77:80])
    assert np.isnan(pred3[:5]).all() and np.isfinite(pred3[5:]).all()
    assert_allclose(pred3[5:], pred[5:], rtol=1e-12)


def test_rolling_forecast_feeds_back():
    rng = np.random.default_rng(4)
    y = 2.0 + np.cumsum(rng.normal(0, 0.05, 40))
    model = GM11(mode="rolling", window=6).fit(y)
    fc = model.forecast(3)
    buf = list(y[-6:])
    for i in range(3):
        nxt = model.predict(np.array([0.0]), history=np.array(buf))[0]
        assert fc[i] == pytest.approx(nxt, rel=1e-12)
        buf.append(nxt)
    # history overrides the training tail: first step is the one-step prediction after y[:30]
    fc_h = model.forecast(3, history=y[:30])
    assert fc_h[0] == pytest.approx(model.predict(y[30:31], history=y[:30])[0], rel=1e-12)
    assert fc_h[0] != pytest.approx(fc[0])
    with pytest.raises(InsufficientDataError):
        model.forecast(2, history=y[:5])


def test_whole_mode_is_the_continued_time_response():
    y = np.array(R12_X0 + [3.75, 3.80, 3.95])
    model = GM11(mode="whole", shift=0.0).fit(y[:5])
    assert model.a_ == pytest.approx(-0.037204, abs=1e-6)
    assert model.C_ == pytest.approx(0.2125, abs=1e-4) and model.P_ == 1.0 and model.grade_ == "good"
    ref = gm11_predict(gm11_fit(R12_X0), 8)
    assert_allclose(model.predict(y[5:]), ref[5:])
    # it ignores the measured values: the same for any y of that length
    assert_allclose(model.predict(np.zeros(3)), ref[5:])
    assert_allclose(model.predict(y[5:], history=y[:5]), ref[5:])
    assert_allclose(model.forecast(3), ref[5:])


def test_gm11_param_validation():
    y = np.linspace(1, 2, 20)
    for bad in ({"mode": "x"}, {"window": 3}, {"window": 8.0}, {"shift": "big"}, {"shift": math.nan},
                {"shift_margin": -1.0}):
        with pytest.raises(ConfigError):
            GM11(**bad).fit(y)
    with pytest.raises(InsufficientDataError):
        GM11(window=8).fit(y[:7])
    with pytest.raises(NotFittedError):
        GM11().predict(y)
    with pytest.raises(ConfigError):
        GM11().fit(y).forecast(-1)


def test_gm11_save_load_identical(tmp_path):
    rng = np.random.default_rng(5)
    y = np.cumsum(rng.normal(0, 0.01, 100))
    for mode in ("rolling", "whole"):
        model = GM11(mode=mode, window=5).fit(y[:70])
        save_model(model, tmp_path / mode)
        back = load_model(tmp_path / mode)
        assert isinstance(back, GM11) and back.get_params() == model.get_params()
        assert_allclose(back.predict(y[70:], history=y[:70]), model.predict(y[70:], history=y[:70]), rtol=0, atol=0)
        assert_allclose(back.forecast(7), model.forecast(7), rtol=0, atol=0)
        for k in ("shift_", "a_", "b_", "C_", "P_", "grade_", "n_train_", "class_ratio_pass_"):
            assert getattr(back, k) == getattr(model, k)


def test_overflowing_time_response_warns():
    fit = GM11Fit(a=-0.5, b=1.0, x0_first=1.0, n=5, shift=0.0)
    with pytest.warns(FogdriftWarning, match="overflows"):
        out = gm11_predict(fit, 3000)
    assert np.isfinite(out[:100]).all() and np.isinf(out[-1])


def _free_run_reference(model, hist, h):
    """Rolling free run written out step by step: each next value is GM(1,1) fitted by gm11_fit (least squares
    with lstsq, an estimator independent of the batched kernel) on the last ``window`` values, then fed back."""
    w = model.window
    buf = list(np.asarray(hist[-w:], dtype=np.float64) + model.shift_)
    out = []
    for _ in range(h):
        fit = gm11_fit(np.array(buf[-w:]))
        nxt = float(gm11_predict(fit, w + 1)[-1])
        out.append(nxt)
        buf.append(nxt)
    return np.array(out) - model.shift_


@pytest.mark.parametrize("window", [4, 8, 13])
def test_forecast_many_equals_forecast_per_origin(window):
    """Issue 25: the heading evaluation's rolling origins in one call; every row equals the per-origin forecast
    (same operations per row) and an independent step-by-step lstsq free run."""
    rng = np.random.default_rng(25)
    y = 3.0 + np.cumsum(rng.normal(0, 0.02, 900)) + rng.normal(0, 0.05, 900)
    model = GM11(mode="rolling", window=window).fit(y[:400])
    origins = np.arange(100, 880, 61)
    hists = np.array([y[t - 100:t] for t in origins])
    many = model.forecast_many(25, hists)
    assert many.shape == (origins.size, 25)
    for row, hist in zip(many, hists):
        assert_allclose(row, model.forecast(25, history=hist), rtol=1e-12, atol=0)
        assert_allclose(row[:5], _free_run_reference(model, hist, 5), rtol=1e-8)
    # shifted windows: a row-offset bug (window taken one sample late) would show against the reference
    assert_allclose(model.forecast_many(1, hists)[:, 0], [_free_run_reference(model, h_, 1)[0] for h_ in hists],
                    rtol=1e-8)
    assert model.forecast_many(0, hists).shape == (origins.size, 0)


def test_forecast_many_whole_mode_and_bad_input():
    rng = np.random.default_rng(5)
    y = 2.0 + np.cumsum(rng.normal(0, 0.05, 60))
    whole = GM11(mode="whole").fit(y)
    hists = np.stack([y[:40], y[10:50]])
    assert_allclose(whole.forecast_many(4, hists), np.tile(whole.forecast(4, history=y[:40]), (2, 1)), rtol=1e-12)
    rolling = GM11(mode="rolling", window=6).fit(y)
    with pytest.raises(InsufficientDataError):
        rolling.forecast_many(2, y[None, :5])
    with pytest.raises(DataFormatError):
        rolling.forecast_many(2, y[:10])
    with pytest.raises(DataFormatError):
        rolling.forecast_many(2, np.full((2, 8), np.nan))
    with pytest.raises(NotFittedError):
        GM11().forecast_many(2, hists)
