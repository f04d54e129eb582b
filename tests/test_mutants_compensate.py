"""``fogdrift compensate`` pieces pinned rule by rule (issue 24, mutation round 3): the streaming engine, the log
source and its matching to a bundle, the streamed output writers and the compensated test block of ``analyze``.

Independent references, written out here: the Haar causal drift of a 2-sample window is the mean of the pair, so
with persistence the drift removed from modelling interval ``j`` is ``(z[j-2] + z[j-1]) / 2`` with
``z = block mean - bias - earth``; the Earth rate is Omega sin(phi) with Omega = 15.041067 deg/h (7.2921150e-5
rad/s) computed here; every result must be the same for input chunks of 1, 7, 64 samples and whole.
"""

from __future__ import annotations

import math
import os
import warnings
from types import SimpleNamespace

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from fogdrift.compensate.engine import BIAS_ONLY, AxisPlan, StreamCompensator, _block_means, segment_blocks
from fogdrift.errors import ConfigError, DataFormatError, InsufficientDataError
from fogdrift.models import Persistence

#: Omega sin(30 deg) [deg/h], by hand: 7.2921150e-5 rad/s x 180/pi x 3600 = 15.041067 deg/h
EARTH_30 = 7.2921150e-5 * 180.0 / math.pi * 3600.0 * 0.5
CHUNKS = (1, 7, 64, None)  # None: the whole log in one push


def _axis(name="gz", bias=1.5, earth=0.0, model=True):
    models = {"persistence": Persistence().fit([0.0])} if model else {}
    return SimpleNamespace(name=name, bias_dph=bias, earth_rate_dph=earth, causal_window=2, level=1, models=models)


def _engine(axes, factor=3, model="persistence", **kw):
    plans = [AxisPlan(a.name, a, model) for a in axes]
    return StreamCompensator(plans, factor=factor, model_dt_s=kw.pop("model_dt_s", 1.0), wavelet="haar",
                             mode="periodization", **kw)


def _run(eng, x, chunk):
    x = np.asarray(x, dtype=float).reshape(len(x), -1)
    t = np.arange(x.shape[0]) * 0.25
    blocks = []
    step = x.shape[0] if chunk is None else chunk
    for lo in range(0, x.shape[0], step):
        blocks += eng.push(t[lo:lo + step], x[lo:lo + step])
    blocks += eng.finish()
    cat = {k: np.concatenate([getattr(b, k) for b in blocks]) for k in ("t_s", "rate_dph", "compensated_dph",
                                                                         "drift_dph")}
    cat["sigma"] = None if blocks[0].sigma_dph is None else np.concatenate([b.sigma_dph for b in blocks])
    assert_array_equal(cat["t_s"], t)
    assert_array_equal(cat["rate_dph"], x)
    return cat


def _persistence_reference(x, m, bias_total, extra=True):
    """Held drift [deg/h] per native sample: p[j] = (z[j-2] + z[j-1]) / 2, 0 where j < 2."""
    x = np.asarray(x, dtype=float)
    nb = x.size // m
    z = x[: nb * m].reshape(nb, m).mean(axis=1) - bias_total
    p = np.zeros(nb + 1)
    for j in range(2, nb + 1):
        p[j] = 0.5 * (z[j - 2] + z[j - 1])
    return np.repeat(p, m)[: x.size] if extra else np.repeat(p[:nb], m)[: x.size]


def _log(n=61, seed=0):
    rng = np.random.default_rng(seed)
    return 40.0 + np.cumsum(rng.normal(0.0, 0.3, n)) + 3.0 * np.sin(np.arange(n) / 5.0)


# ---------------------------------------------------------------------------------------------------------------
# the engine


def test_block_means_and_segment_sizes_by_hand():
    x = np.array([[1.0, 10.0], [2.0, 20.0], [3.0, 30.0], [4.0, 40.0], [5.0, 50.0], [6.0, 60.0], [7.0, 70.0]])
    assert_array_equal(_block_means(x, 2, 3), [[2.0, 20.0], [5.0, 50.0]])  # the 7th row is left out
    assert_array_equal(_block_means(x, 3, 2), [[1.5, 15.0], [3.5, 35.0], [5.5, 55.0]])
    assert_array_equal(_block_means(x, 7, 1), x)
    assert _block_means(x, 0, 4).shape == (0, 2)
    assert segment_blocks(1) == 262144 and segment_blocks(3) == 87381 and segment_blocks(1000) == 262
    assert segment_blocks(1024) == 256 and segment_blocks(1025) == 256 and segment_blocks(4096) == 256
    assert segment_blocks(np.int64(2)) == 131072 and segment_blocks(2.0) == 131072


def test_the_haar_window_is_the_mean_of_the_pair():
    from fogdrift.models.causal_predictor import causal_weights

    assert_allclose(causal_weights(2, "haar", 1, "periodization"), [0.5, 0.5], rtol=1e-12)


@pytest.mark.parametrize("chunk", CHUNKS)
@pytest.mark.parametrize("segment", (None, 4, 5))
def test_persistence_output_by_hand_with_the_earth_rate(chunk, segment):
    """z removes bias AND Earth rate; the output removes the bias and the drift only (the Earth rate stays)."""
    x = _log(61) + EARTH_30
    bias = 1.5
    eng = _engine([_axis(bias=bias, earth=EARTH_30)], factor=3, segment=segment)
    out = _run(eng, x, chunk)
    drift = _persistence_reference(x, 3, bias + EARTH_30)
    assert_allclose(out["drift_dph"][:, 0], drift, rtol=1e-12, atol=1e-9)
    assert_allclose(out["compensated_dph"][:, 0], x - bias - drift, rtol=1e-12, atol=1e-9)
    assert out["sigma"] is None and eng.has_sigma is False
    assert eng.n_in == 61 and eng.n_out == 61 and eng.n_axes == 1
    assert eng.first_active() == [6]  # interval 2 (native samples 6, 7, 8) is the first with a prediction
    assert eng.biases() == [(bias, bias + EARTH_30)]
    assert eng.re_estimated_bias_dph is None
    assert_allclose(eng.model_rate_series()[:, 0], x[:60].reshape(20, 3).mean(axis=1), rtol=1e-12)
    assert EARTH_30 == pytest.approx(15.041067 * 0.5, rel=1e-6)


def test_output_is_the_same_for_any_chunking_bit_for_bit():
    x = np.column_stack([_log(200, 1), _log(200, 2) - 7.0])
    runs = []
    for chunk in CHUNKS:
        eng = _engine([_axis("gx", 2.0, EARTH_30), _axis("gz", -1.0, -3.0)], factor=4, segment=3)
        runs.append(_run(eng, x, chunk))
    for r in runs[1:]:
        for k in ("compensated_dph", "drift_dph"):
            assert_array_equal(r[k], runs[0][k])
    for k, (bias, earth) in enumerate(((2.0, EARTH_30), (-1.0, -3.0))):
        d = _persistence_reference(x[:, k], 4, bias + earth)
        assert_allclose(runs[0]["drift_dph"][:, k], d, rtol=1e-12, atol=1e-9)
        assert_allclose(runs[0]["compensated_dph"][:, k], x[:, k] - bias - d, rtol=1e-12, atol=1e-9)


def test_bias_only_removes_the_bias_and_keeps_the_earth_rate():
    x = _log(20) + EARTH_30
    for model in (BIAS_ONLY, "persistence"):
        eng = _engine([_axis(bias=2.0, earth=EARTH_30)], factor=2, model=model)
        out = _run(eng, x, 7)
        if model == BIAS_ONLY:
            assert_array_equal(out["drift_dph"], 0.0)
            assert_allclose(out["compensated_dph"][:, 0], x - 2.0, rtol=1e-12)
            assert eng.first_active() == [0]
    assert AxisPlan("gz", _axis(), BIAS_ONLY).model is None
    ax = _axis()
    assert AxisPlan("gz", ax, "persistence").model is ax.models["persistence"]


@pytest.mark.parametrize("chunk", CHUNKS)
def test_last_incomplete_interval_gets_the_prediction_after_the_log(chunk):
    x = _log(23)  # 7 intervals of 3 and 2 samples more
    eng = _engine([_axis(bias=0.5)], factor=3)
    out = _run(eng, x, chunk)
    z = x[:21].reshape(7, 3).mean(axis=1) - 0.5
    assert_allclose(out["drift_dph"][21:, 0], 0.5 * (z[5] + z[6]), rtol=1e-12)
    assert_allclose(out["drift_dph"][:21, 0], _persistence_reference(x[:21], 3, 0.5), rtol=1e-12, atol=1e-12)
    assert eng.model_rate_series().shape == (7, 1)


@pytest.mark.parametrize("chunk", CHUNKS)
@pytest.mark.parametrize("segment", (None, 2, 3))
def test_bias_re_estimated_by_hand(chunk, segment):
    """bias=4 s at 1-s intervals: the mean of the first 4 block means minus the Earth rate; the bundle's bias and no
    drift model until then; the drift model's history starts at the log's first sample."""
    x = np.column_stack([_log(40, 3), _log(40, 4) + 20.0])
    axes = [_axis("gx", bias=9.0, earth=EARTH_30), _axis("gz", bias=-2.0, earth=0.0)]
    eng = _engine(axes, factor=2, bias=4.0, segment=segment)
    assert eng.n_cal == 4
    out = _run(eng, x, chunk)
    for k, (a, earth) in enumerate(zip(axes, (EARTH_30, 0.0))):
        means = x[:, k].reshape(20, 2).mean(axis=1)
        level = means[:4].mean()
        assert eng.re_estimated_bias_dph[k] == pytest.approx(level - earth, rel=1e-12)
        assert eng.biases()[k] == pytest.approx((level - earth, level), rel=1e-12)
        drift = _persistence_reference(x[:, k], 2, level)
        drift[:8] = 0.0  # calibrating
        assert_allclose(out["drift_dph"][:, k], drift, rtol=1e-12, atol=1e-9)
        expected = x[:, k] - np.where(np.arange(40) < 8, a.bias_dph, level - earth) - drift
        assert_allclose(out["compensated_dph"][:, k], expected, rtol=1e-12, atol=1e-9)
    assert eng.first_active() == [8, 8]


def test_bias_window_rounding_and_bias_only_first_active():
    assert _engine([_axis()], bias=2.4).n_cal == 2
    assert _engine([_axis()], bias=2.6).n_cal == 3
    assert _engine([_axis()], bias=0.2).n_cal == 1  # at least one interval
    assert _engine([_axis()], bias=6.0, model_dt_s=2.0).n_cal == 3
    assert _engine([_axis()], bias="3").n_cal == 3
    assert _engine([_axis()]).n_cal == 0
    eng = _engine([_axis(bias=5.0)], factor=2, model=BIAS_ONLY, bias=3.0)
    out = _run(eng, np.arange(20.0), 7)
    level = np.arange(20.0).reshape(10, 2).mean(axis=1)[:3].mean()
    assert eng.first_active() == [6]
    assert_allclose(out["compensated_dph"][:, 0], np.arange(20.0) - np.where(np.arange(20) < 6, 5.0, level))


def test_a_log_shorter_than_the_bias_window_is_refused_in_one_line():
    for n, chunk in ((9, None), (9, 2), (10, 3)):
        eng = _engine([_axis()], factor=2, bias=6.0)
        with pytest.raises(InsufficientDataError) as info:
            _run(eng, np.arange(float(n)), chunk)
        got = n // 2
        assert str(info.value) == (f"re-estimating the bias needs 6 s of the log; it has only {got} s (pass bias= "
                                   "keep or a shorter window)")
        assert info.value.needed == 6 and info.value.got == got
    eng = _engine([_axis()], factor=2, bias=5.0, model_dt_s=0.5)  # 10 intervals of 0.5 s
    with pytest.raises(InsufficientDataError, match="needs 5 s of the log; it has only 4.5 s"):
        _run(eng, np.arange(18.0), 4)
    eng = _engine([_axis()], factor=2, bias=6.0)  # exactly the window: fine
    _run(eng, np.arange(12.0), 5)
    assert eng.first_active() == [None]  # never past the window: the model never acts


@pytest.mark.parametrize("bad", ["abc", 0, -1.0, None, float("nan"), "re-estimate", [1]])
def test_bad_bias_is_one_line(bad):
    with pytest.raises(ConfigError) as info:
        _engine([_axis()], bias=bad)
    assert str(info.value) == (f"bias must be 'keep' or a re-estimation window > 0 s; got {bad!r}; pass bias= keep "
                               "or re-estimate:SECONDS")


@pytest.mark.parametrize("bad", [0, -2, 2.0, True, "3", None])
def test_bad_factor_and_segment_are_one_line(bad):
    with pytest.raises(ConfigError) as info:
        _engine([_axis()], factor=bad)
    assert str(info.value) == f"factor must be an integer >= 1; got {bad!r}"
    eng = _engine([_axis()], factor=np.int32(2))
    assert eng.factor == 2 and type(eng.factor) is int and eng.seg_blocks == 131072 and eng.seg_native == 262144
    assert _engine([_axis()], factor=1).seg_blocks == 262144
    assert _engine([_axis()], factor=3, segment=5).seg_native == 15
    assert _engine([_axis()], factor=3, segment=1).seg_blocks == 1
    for seg in (0, -1):
        with pytest.raises(ConfigError, match=rf"^segment must be >= 1 modelling interval; got {seg}$"):
            _engine([_axis()], segment=seg)


def test_push_checks_the_shape_and_counts():
    eng = _engine([_axis("gx"), _axis("gz")], factor=2, segment=2)
    for bad in (np.zeros(4), np.zeros((4, 1)), np.zeros((4, 3)), np.zeros((2, 2, 2))):
        with pytest.raises(ConfigError, match=r"^rate_dph must have shape \(n, 2\); got \("):
            eng.push(np.arange(4.0), bad)
    assert eng.push(np.arange(3.0), np.ones((3, 2))) == []  # less than a segment: held
    assert eng.n_in == 3 and eng.n_out == 0
    out = eng.push(np.arange(3.0, 9.0), np.ones((6, 2)))  # 9 samples: two segments of 4 out, 1 held
    assert [b.t_s.tolist() for b in out] == [[0, 1, 2, 3], [4, 5, 6, 7]]
    assert eng.n_in == 9 and eng.n_out == 8
    last = eng.finish()
    assert [b.t_s.tolist() for b in last] == [[8.0]] and eng.n_out == 9
    assert eng.finish() == []  # nothing left
    fresh = _engine([_axis()], factor=2)
    assert fresh.finish() == [] and fresh.model_rate_series().shape == (0, 1) and fresh.first_active() == [None]
    quiet = _engine([_axis()], factor=2, keep_model_rate=False)
    _run(quiet, np.arange(10.0), 3)
    assert quiet.block_means_dph == [] and quiet.model_rate_series().shape == (0, 1)


def test_finish_with_only_held_calibration_segments():
    """Segments held for the bias window, the log ending exactly at a segment boundary: finish emits them."""
    eng = _engine([_axis(bias=0.0)], factor=2, bias=4.0, segment=2)
    x = np.arange(8.0)
    blocks = eng.push(np.arange(8.0), x.reshape(-1, 1))  # two segments of 2 intervals: 4 intervals = the window
    blocks += eng.finish()
    comp = np.concatenate([b.compensated_dph for b in blocks])[:, 0]
    assert_allclose(comp, x - np.where(np.arange(8) < 8, 0.0, 0.0))  # all calibrating: the bundle's bias (0)
    assert eng.re_estimated_bias_dph == [pytest.approx(3.5)]
    eng = _engine([_axis(bias=0.0)], factor=2, bias=6.0, segment=2)
    eng.push(np.arange(8.0), x.reshape(-1, 1))
    with pytest.raises(InsufficientDataError):
        eng.finish()


class _RateModel:
    """A rate-input model (the Kalman filter's interface): predicts the previous sample, sigma 0.5 + j / 10."""

    input_kind = "rate"

    def filter(self, z, state=None):
        prev = 0.0 if state is None else state[0]
        j0 = 0 if state is None else state[1]
        pred = np.concatenate([[prev], z[:-1]]) if z.size else np.empty(0)
        sigma = 0.5 + (j0 + np.arange(z.size)) / 10.0
        return pred, sigma, (z[-1] if z.size else prev, j0 + z.size)

    def forecast_with_uncertainty(self, steps, state=None):
        return np.array([state[0]]), np.array([0.5 + state[1] / 10.0]), state


@pytest.mark.parametrize("chunk", (1, 7, None))
def test_rate_input_model_drift_and_sigma_are_held(chunk):
    ax = _axis(bias=1.0, earth=2.0)
    ax.models = {"kalman": _RateModel()}
    x = _log(17)
    eng = _engine([ax], factor=2, model="kalman", bias=2.0, segment=3)
    assert eng.has_sigma is True
    out = _run(eng, x, chunk)
    means = x[:16].reshape(8, 2).mean(axis=1)
    level = means[:2].mean()
    z = means - level
    p = np.r_[0.0, z]  # previous sample; the 9th is the prediction after the log
    sig = 0.5 + np.arange(9) / 10.0
    drift = np.repeat(p, 2)[:17]
    sigma = np.repeat(sig, 2)[:17]
    drift[:4], sigma[:4] = 0.0, np.nan  # calibrating (2 intervals)
    assert_allclose(out["drift_dph"][:, 0], drift, rtol=1e-12, atol=1e-12)
    assert_allclose(out["sigma"][:, 0], sigma, rtol=1e-12)
    assert_allclose(out["compensated_dph"][:, 0], x - np.where(np.arange(17) < 4, 1.0, level - 2.0) - drift,
                    rtol=1e-12, atol=1e-9)
    assert eng.first_active() == [4]


def test_sigma_is_nan_for_axes_without_a_rate_model():
    ax = _axis("gx")
    ax.models = {"kalman": _RateModel()}
    eng = StreamCompensator([AxisPlan("gx", ax, "kalman"), AxisPlan("gz", _axis("gz"), "persistence")], factor=1,
                            model_dt_s=1.0, wavelet="haar", mode="periodization")
    out = _run(eng, np.column_stack([_log(10), _log(10, 5)]), 3)
    assert np.isfinite(out["sigma"][:, 0]).all() and np.isnan(out["sigma"][:, 1]).all()
