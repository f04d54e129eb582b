"""Metrics: hand-computed values, the p0 guard, and the pitfalls of method notes §5.4 as tests."""

from __future__ import annotations

import json
import math
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from fogdrift.errors import ConfigError, DataFormatError, FogdriftWarning, InsufficientDataError
from fogdrift.metrics import (
    OFFSET_CONVENTIONS,
    evaluate,
    mae,
    mase,
    max_abs_error,
    p0,
    p0_ago,
    p0_weighted,
    rmse,
    skill,
)


def test_hand_values():
    y = np.array([1.0, 2.0, 3.0, 4.0])
    yh = np.array([1.5, 2.0, 2.0, 4.0])  # errors 0.5, 0, -1, 0
    assert rmse(y, yh) == pytest.approx(math.sqrt(1.25 / 4))
    assert mae(y, yh) == pytest.approx(0.375)
    assert max_abs_error(y, yh) == 1.0
    # MASE: training persistence MAE of [0, 1, 3, 2] = (1 + 2 + 1)/3
    assert mase(y, yh, [0.0, 1.0, 3.0, 2.0]) == pytest.approx(0.375 / (4 / 3))
    # skill vs persistence [0, 1, 2, 3]: RMSE 1
    assert skill(y, yh, [0.0, 1.0, 2.0, 3.0]) == pytest.approx(1 - math.sqrt(1.25 / 4))
    # p0 = 100 (1 - mean(0.5/1, 0, 1/3, 0)) ; p0_w = 100 (1 - 1.5/10)
    assert p0(y, yh, offset_convention="as_measured") == pytest.approx(100 * (1 - (0.5 + 1 / 3) / 4))
    assert p0_weighted(y, yh) == pytest.approx(85.0)


def test_asymmetric_hand_values():
    """Hand values chosen so that each plausible slip changes the number (comments give both)."""
    y = np.array([2.0, 4.0, 8.0])
    yh = np.array([1.0, 5.0, 6.0])  # errors -1, +1, -2; |e| = 1, 1, 2
    # p0 = 100 (1 - mean(|e|/|y|)) = 100 (1 - (1/2 + 1/4 + 2/8)/3) = 100 (1 - 1/3) = 66.667 %
    # (dividing by |yhat| instead: (1/1 + 1/5 + 2/6)/3 = 0.5111 -> 48.889 %)
    assert p0(y, yh, offset_convention="as_measured") == pytest.approx(200.0 / 3.0, rel=1e-12)
    # p0_w = 100 (1 - sum|e| / sum|y|) = 100 (1 - 4/14) = 71.4286 %  (sum|yhat| = 12 would give 66.667 %)
    assert p0_weighted(y, yh) == pytest.approx(100.0 * (1.0 - 4.0 / 14.0), rel=1e-12)
    # MASE = MAE / mean|diff(y_train)|: MAE = 4/3; diffs of [0, 1, 3, 2, 6] are 1, 2, 1, 4 -> mean 2; MASE = 2/3
    # (sum/len(y_train) = 8/5 would give 0.8333; the test block's own diffs 2, 4 -> 3 would give 0.4444)
    assert mase(y, yh, [0.0, 1.0, 3.0, 2.0, 6.0]) == pytest.approx(2.0 / 3.0, rel=1e-12)
    # skill = 1 - RMSE/RMSE_p: persistence-like [0, 2, 4] has errors 2, 2, 4 -> RMSE_p = sqrt(24/3) = sqrt(8);
    # RMSE = sqrt(6/3) = sqrt(2); skill = 1 - 1/2 = 0.5  (MSE ratio: 0.75; inverted ratio: -1)
    assert skill(y, yh, [0.0, 2.0, 4.0]) == pytest.approx(0.5, rel=1e-12)
    # evaluate() reports the same numbers for the same samples
    r = evaluate(y, yh, y_train=np.array([0.0, 1.0, 3.0, 2.0, 6.0]), yhat_persistence=np.array([0.0, 2.0, 4.0]),
                 offset_convention="as_measured")
    assert (r.p0_pct, r.p0_weighted_pct, r.mase, r.skill) == pytest.approx(
        (200.0 / 3.0, 100.0 * (1.0 - 4.0 / 14.0), 2.0 / 3.0, 0.5), rel=1e-12)
    # persistence's p0 beside it: |e_p|/|y| = 2/2, 2/4, 4/8 -> mean 2/3 -> 33.333 %
    assert r.p0_persistence_pct == pytest.approx(100.0 / 3.0, rel=1e-12)


@settings(max_examples=50, deadline=None)
@given(st.lists(st.floats(0.5, 1e3), min_size=1, max_size=40), st.sampled_from(OFFSET_CONVENTIONS))
def test_metrics_zero_on_identical_inputs(values, convention):
    y = np.array(values)
    assert rmse(y, y) == mae(y, y) == max_abs_error(y, y) == 0.0
    assert p0_weighted(y, y) == 100.0
    if y.min() >= 0.1 * np.median(y):
        assert p0(y, y, offset_convention=convention) == 100.0


def test_input_validation():
    with pytest.raises(DataFormatError, match="same length"):
        rmse([1.0, 2.0], [1.0])
    with pytest.raises(DataFormatError, match=r"yhat\[1\]"):
        mae([1.0, 2.0], [1.0, np.nan])
    with pytest.raises(InsufficientDataError):
        rmse([], [])
    with pytest.raises(ConfigError, match="offset_convention"):
        p0([1.0], [1.0], offset_convention="raw")
    with pytest.raises(TypeError):
        p0([1.0], [1.0])  # the convention is required
    with pytest.warns(FogdriftWarning, match="denominator"):
        assert math.isnan(mase([1.0], [2.0], [3.0, 3.0, 3.0]))
    with pytest.warns(FogdriftWarning):
        assert math.isnan(skill([1.0, 2.0], [1.0, 1.0], [1.0, 2.0]))


# -- pitfalls (method notes §5.4) --------------------------------------------------------------------
def _positive_drift(seed=7, n=500):
    rng = np.random.default_rng(seed)
    k = np.arange(n)
    return 0.03 + 0.01 * np.sin(2 * np.pi * k / 200) + rng.normal(0, 0.001, n)


def test_persistence_p0_rises_towards_100_with_a_constant_offset():
    y = _positive_drift()
    yp = np.r_[np.nan, y[:-1]]  # persistence
    scores, errors = [], []
    for offset in (0.0, 0.02, 0.2, 7.1):
        ys, ps = y[1:] + offset, yp[1:] + offset
        scores.append(p0(ys, ps, offset_convention="as_measured"))
        errors.append(rmse(ys, ps))
    assert scores == sorted(scores) and len(set(scores)) == 4
    assert scores[0] < 97.5 and scores[-1] > 99.9
    assert_allclose(errors, errors[0], rtol=1e-9)  # same predictor, same absolute error


def test_zero_crossings_trigger_the_guard():
    rng = np.random.default_rng(1)
    k = np.arange(1000)
    y = 1e-3 * np.sin(2 * np.pi * k / 250) + rng.normal(0, 2e-5, k.size)
    yh = y + rng.normal(0, 5e-5, k.size)
    with pytest.warns(FogdriftWarning, match="unstable near zero"):
        assert math.isnan(p0(y, yh, offset_convention="demeaned_by_train_mean"))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        w = p0_weighted(y, yh)
    assert 90.0 < w < 100.0
    # guard boundary: min|y| = 0.1 * median|y| passes, just below fails
    assert p0([0.1, 1.0, 1.0], [0.1, 1.0, 1.0], offset_convention="as_measured") == 100.0
    with pytest.warns(FogdriftWarning):
        assert math.isnan(p0([0.0999, 1.0, 1.0], [0.1, 1.0, 1.0], offset_convention="as_measured"))
    with pytest.warns(FogdriftWarning):
        assert math.isnan(p0([0.0, 0.0], [0.0, 0.0], offset_convention="as_measured"))


def test_ago_domain_inflates_p0_and_is_flagged():
    y = _positive_drift()
    x1 = np.cumsum(y)
    # persistence, and a no-skill constant (training mean of the first half), in both domains
    yp = y[:-1]
    y_const = np.full(y.size - 1, y[:250].mean())
    p_orig = p0(y[1:], yp, offset_convention="as_measured")
    c_orig = p0(y[1:], y_const, offset_convention="as_measured")
    with pytest.warns(FogdriftWarning, match="paper practice"):
        p_ago = p0_ago(x1[1:], x1[:-1] + yp)  # x1_hat(k) = yhat(k) + measured x1(k-1)
    with pytest.warns(FogdriftWarning, match="paper practice"):
        c_ago = p0_ago(x1[1:], x1[:-1] + y_const)
    assert p_ago > 99.9 > p_orig
    assert c_ago > 99.5 and c_orig < 80.0


# -- evaluate ------------------------------------------------------------------------------------------
def test_evaluate_excludes_nan_consistently_and_reports_persistence():
    rng = np.random.default_rng(3)
    y_train = rng.normal(0, 1, 200)
    y_train -= y_train.mean()
    y = 5.0 + rng.normal(0, 1, 50)
    yp = np.r_[np.nan, y[:-1]]
    yh = y + rng.normal(0, 0.3, 50)
    yh[:4] = np.nan  # model warm-up longer than persistence's
    r = evaluate(y, yh, y_train=y_train, yhat_persistence=yp, offset_convention="as_measured")
    s = slice(4, None)
    assert r.n == 46
    assert r.rmse_dph == pytest.approx(rmse(y[s], yh[s]))
    assert r.mae_dph == pytest.approx(mae(y[s], yh[s]))
    assert r.max_abs_dph == pytest.approx(max_abs_error(y[s], yh[s]))
    assert r.rmse_persistence_dph == pytest.approx(rmse(y[s], yp[s]))
    assert r.mase == pytest.approx(mase(y[s], yh[s], y_train))
    assert r.skill == pytest.approx(skill(y[s], yh[s], yp[s]))
    assert r.p0_pct == pytest.approx(p0(y[s], yh[s], offset_convention="as_measured"))
    assert r.p0_persistence_pct == pytest.approx(p0(y[s], yp[s], offset_convention="as_measured"))
    assert r.p0_weighted_pct == pytest.approx(p0_weighted(y[s], yh[s]))
    assert (r.offset_convention, r.domain) == ("as_measured", "original")
    assert r.p0_pct > r.p0_persistence_pct  # the model here is better than persistence
    json.dumps(r.to_dict(), allow_nan=False)


def test_evaluate_guard_warns_once_and_to_dict_maps_nan_to_none():
    k = np.arange(100)
    y = np.sin(2 * np.pi * k / 40)
    yp = np.r_[np.nan, y[:-1]]
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        r = evaluate(y, y * 0.9, y_train=y - y.mean(), yhat_persistence=yp)
    guard = [w for w in rec if "unstable near zero" in str(w.message)]
    assert len(guard) == 1
    assert math.isnan(r.p0_pct) and math.isnan(r.p0_persistence_pct)
    d = r.to_dict()
    assert d["p0_pct"] is None and d["rmse_dph"] == pytest.approx(r.rmse_dph)
    json.dumps(d, allow_nan=False)


def test_evaluate_checks_convention_and_inputs():
    y = np.array([1.0, 2.0, 3.0])
    tr = np.array([1.0, 2.0, 3.0])
    with pytest.warns(FogdriftWarning, match="demeaned"):
        evaluate(y, y, y_train=tr, yhat_persistence=y + 0.5)
    with pytest.raises(ConfigError):
        evaluate(y, y, y_train=tr, yhat_persistence=y, offset_convention="none")
    with pytest.raises(InsufficientDataError):
        evaluate(y, np.full(3, np.nan), y_train=tr, yhat_persistence=y, offset_convention="as_measured")
    with pytest.raises(DataFormatError):
        evaluate(y, y[:2], y_train=tr, yhat_persistence=y, offset_convention="as_measured")
    with pytest.raises(DataFormatError):
        evaluate(np.r_[y[:2], np.nan], y, y_train=tr, yhat_persistence=y, offset_convention="as_measured")
